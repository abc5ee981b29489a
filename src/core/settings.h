// The options of a run, checked once and turned into the working frame: the stop criteria and
// the rules each contraction is held to.
#pragma once

#include <cstddef>
#include <string>

#include "core/working_mesh.h"
#include "qem/simplify.h"

namespace qem::core {

/// Forgetting (SimplifyOptions::forget) stops below this many faces: a coarser mesh's own faces no
/// longer stand for the surface, and GH97's remembering quadrics keep its overall shape (measured
/// on the benchmark meshes at 100 faces with floors of 0, 300, 700, 1000 and 2000:
/// docs/benchmarks.md, "Forgetting").
inline constexpr double kForgetFloorFaces = 700;

struct Settings {
  // --- stop criteria (the first reached wins) ---
  std::size_t target_faces = 0, target_vertices = 0;
  double max_error = 0;  ///< contraction error limit in the working frame (+inf: none)
  double max_distance = 0;  ///< SimplifyOptions::max_distance in the working frame (+inf: none)
  // --- the rules ---
  Weighting weighting = Weighting::Area;
  Placement placement = Placement::Optimal;
  double threshold = 0;       ///< GH97 §3.2's t in the working frame
  double boundary_weight = 1;
  bool lock_border = false;
  bool exact_border = true;   ///< border_placement.h
  InversionPolicy inversion = InversionPolicy::Forbid;
  double cos_max_turn = 0;    ///< cosine of the largest normal turn of a surviving face (GH97 §6)
  bool preserve_topology = true;
  Scheme scheme = Scheme::Passes;
  std::size_t greedy_below_faces = 0;
  double forget = 0;          ///< SimplifyOptions::forget, 0 where it does not apply
  double seam_weight = 0;     ///< AttributeWeights::seam (seam_planes.h)
  unsigned threads = 1;       ///< resolved: at least 1
  bool keep_components = true;
  double prune_size = 0;      ///< in the working frame (0: no pruning)

  /// Forgetting's schedule, on the face count alone (never the target, so every target sees one
  /// sequence of contractions): whether the quadrics are due for renewal with `faces` left; if so,
  /// `at` moves on to the next count.
  bool forget_due(std::size_t faces, double& at) const {
    if (!(forget > 0) || double(faces) > at || double(faces) < kForgetFloorFaces) return false;
    while (double(faces) <= at) at *= forget;
    return true;
  }
  /// The face count of the first renewal in a run that starts with `faces`.
  double first_forget_at(std::size_t faces) const { return forget * double(faces); }

  bool reached(const WorkingMesh& m) const {
    return m.faces_alive <= target_faces || m.vertices_alive <= target_vertices;
  }
};

/// Throws qem::Error, naming the option, for any option out of its range or a missing target.
/// Checks only the options themselves: the core's one place for them (the command line relies on it).
void validate(const SimplifyOptions& options);

/// The validated options in the frame of `mesh` (targets from its face count after dropping
/// degenerate and duplicate faces); `attributes`: the run carries wedges (Hoppe 1999).
Settings resolve(const SimplifyOptions& options, const WorkingMesh& mesh, bool attributes);

/// The human-readable reason a run stopped.
std::string stop_detail(StopReason reason, const SimplifyResult& totals, bool lock_border);

}  // namespace qem::core
