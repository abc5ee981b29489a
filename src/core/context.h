// What a run of the contraction loop works with: the mesh, its pairs and quadrics, the settings,
// who watches, and the running totals. Only the two orders see all of it; each step takes the
// parts it touches.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/component_guard.h"
#include "core/contraction_map.h"
#include "core/distance_bound.h"
#include "core/pair_set.h"
#include "core/quadric.h"
#include "core/settings.h"
#include "core/wedges.h"
#include "core/working_mesh.h"
#include "qem/simplify.h"

namespace qem::core {

/// What one thread needs to make contractions: its own scratch space, stamps and counters (the
/// run's totals absorb them). Threads work on disjoint parts of the mesh (see regions.h), so
/// nothing else they write is shared.
struct Worker {
  std::uint32_t stamp = 0;  // last stamp used in Context::marks; every stamp is used once in a run
  std::vector<std::uint32_t> faces, pairs;  // scratch: the survivor's faces and pairs
  std::vector<std::uint32_t> dead_faces;    // input faces killed by the last contraction, if observed
  std::vector<std::pair<std::uint32_t, std::uint32_t>> wedge_map;  // removed wedge -> survivor's
  std::vector<std::uint32_t> emptied_wedges;  // wedges left without a face corner (Wedges::drop_unused)
  std::size_t faces_killed = 0, vertices_removed = 0, contractions = 0;
  std::size_t blocked_topology = 0, blocked_inversion = 0, blocked_error = 0, blocked_distance = 0;
  std::size_t blocked_component = 0;
  double max_error = 0;  // in the working frame
  std::uint32_t last_kept = 0, last_removed = 0;  // of the last contraction made
};

struct Context {
  const Settings& settings;
  MeshView input;
  WorkingMesh& mesh;
  PairSet& pairs;
  std::vector<Quadric>& quadric;
  SimplifyObserver* observer = nullptr;  // null: nobody watches
  bool observe_contractions = false;     // observer->wants_contractions(), asked once
  ContractionMap* map = nullptr;         // kept only when asked for
  /// Stamps for set membership without clearing (one array, a fresh stamp per query).
  std::vector<std::uint32_t> marks;
  Worker main;  // the worker of every contraction made on the calling thread
  SimplifyResult& totals;    // contractions, rejections, stop reason
  double max_error = 0;      // largest contraction error made, working frame
  std::size_t next_progress = 0;
  Wedges* wedges = nullptr;  // with attributes only
  const SurfaceDistance* surface = nullptr;  // the input, with max_distance only (distance_bound.h)
  ComponentGuard* components = nullptr;  // null: components may vanish (GH97 as published)

  bool done() const { return settings.reached(mesh); }

  /// Moves a worker's counts into the run's totals (after each contraction on the calling thread,
  /// after each band for the others).
  void absorb(Worker& w) {
    mesh.faces_alive -= w.faces_killed;
    mesh.vertices_alive -= w.vertices_removed;
    totals.contractions += w.contractions;
    totals.rejected_topology += w.blocked_topology;
    totals.rejected_inversion += w.blocked_inversion;
    totals.rejected_error += w.blocked_error;
    totals.rejected_distance += w.blocked_distance;
    totals.rejected_component += w.blocked_component;
    max_error = std::max(max_error, w.max_error);
    w.faces_killed = w.vertices_removed = w.contractions = 0;
    w.blocked_topology = w.blocked_inversion = w.blocked_error = w.blocked_distance = w.blocked_component = 0;
  }

  /// Tells the observer the fraction done every few thousand contractions; false if it cancelled.
  bool report_progress() {
    if (!observer || totals.contractions < next_progress) return true;
    next_progress = totals.contractions + 4096;
    const std::size_t start = totals.input_faces;
    const std::size_t span = start > settings.target_faces ? start - settings.target_faces : 1;
    if (observer->on_progress(double(start - mesh.faces_alive) / double(span))) return true;
    totals.stop_reason = StopReason::Cancelled;
    return false;
  }

  /// No candidate is left: why.
  StopReason exhausted() const {
    return totals.rejected_error > 0 ? StopReason::ErrorLimit : StopReason::NoValidPair;
  }
};

}  // namespace qem::core
