// simplify_document (qem/gltf_simplify.h): the primitives of a glTF document simplified under one
// shared error budget in world units, or each on its own.
#include "qem/gltf_simplify.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <exception>
#include <functional>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <thread>

#include "merged_primitives.h"
#include "spacing_weights.h"
#include "qem/error.h"
#include "quantized_borders.h"

namespace qem {
namespace {

/// Runs job(0) ... job(n-1) on up to `threads` threads and rethrows the exception of the lowest
/// failed job, so that which error is reported does not depend on the scheduling.
void for_each_job(std::size_t n, unsigned threads, const std::function<void(std::size_t)>& job) {
  std::vector<std::exception_ptr> failed(n);
  std::atomic<std::size_t> next{0};
  auto worker = [&] {
    for (std::size_t i = next++; i < n; i = next++) {
      try {
        job(i);
      } catch (...) {
        failed[i] = std::current_exception();
      }
    }
  };
  const std::size_t count = std::min<std::size_t>(threads, n);
  std::vector<std::thread> pool;
  for (std::size_t t = 1; t < count; ++t) pool.emplace_back(worker);
  worker();
  for (std::thread& t : pool) t.join();
  for (const std::exception_ptr& e : failed)
    if (e) std::rethrow_exception(e);
}

/// One primitive's error curve from a watched run: after each contraction, the largest error so
/// far (world units; contraction errors are not monotone, the running maximum is) and the faces
/// left. A threshold T then stands for the longest prefix of contractions that all stay within T.
class ErrorCurve : public SimplifyObserver {
 public:
  explicit ErrorCurve(double world_scale) : scale_(world_scale) {}
  bool wants_contractions() const override { return true; }
  void on_start(std::span<const std::uint32_t> input_faces) override { initial = input_faces.size(); }
  void on_contraction(const Contraction& c) override {
    const double e = c.error * scale_;
    errors.push_back(e);
    running_max.push_back(running_max.empty() ? e : std::max(running_max.back(), e));
    const std::size_t before = faces.empty() ? initial : faces.back();
    faces.push_back(before - std::min(before, c.dead_faces.size()));
  }
  /// Contractions within `threshold`.
  std::size_t contractions_within(double threshold) const {
    return static_cast<std::size_t>(std::upper_bound(running_max.begin(), running_max.end(), threshold) -
                                    running_max.begin());
  }
  std::size_t faces_within(double threshold) const {
    const std::size_t k = contractions_within(threshold);
    return k == 0 ? initial : faces[k - 1];
  }

  std::size_t initial = 0;
  std::vector<double> errors, running_max;
  StopReason stop_reason = StopReason::TargetReached;  // of the watched run
  std::vector<std::size_t> faces;

 private:
  double scale_;
};

/// What one simplification works on: a primitive, or primitives of one mesh merged (merge_parts).
struct Unit {
  std::vector<std::size_t> primitives;  // the document's primitive indices
  Mesh mesh;
  std::vector<Mesh> parts;         // when merged: the primitives as read, to split the result
  std::vector<std::uint8_t> lock;  // the vertices shared with primitives not merged with it
  double world_scale = 1;
  std::size_t faces = 0, vertices = 0;
};

/// A stop criterion in world units turned into the primitive's own units.
double local_error(double world_error, double world_scale) {
  return std::isfinite(world_error) && world_scale > 0 ? world_error / world_scale : world_error;
}

}  // namespace

const char* to_string(GltfPrimitiveOutcome::Status status) {
  switch (status) {
    case GltfPrimitiveOutcome::Status::Simplified:
      return "simplified";
    case GltfPrimitiveOutcome::Status::Unchanged:
      return "unchanged";
    case GltfPrimitiveOutcome::Status::Kept:
      break;
  }
  return "kept";
}

GltfSimplifyReport simplify_document(GltfDocument& doc, const SimplifyOptions& options,
                                     const GltfSimplifyOptions& gltf_options) {
  check_options(options);
  const std::vector<GltfPrimitiveInfo>& info = doc.primitives();
  GltfSimplifyReport report;
  std::vector<std::size_t> jobs;  // the primitives that can be simplified
  for (std::size_t i = 0; i < info.size(); ++i) {
    GltfPrimitiveOutcome o;
    o.primitive = i;
    o.faces_in = o.faces_out = info[i].face_count;
    o.world_scale = info[i].world_scale;
    if (!info[i].simplifiable)
      o.note = info[i].why_not;
    else if (info[i].face_count == 0)
      o.note = "no triangles (passed through untouched)";
    else
      o.status = GltfPrimitiveOutcome::Status::Unchanged, jobs.push_back(i);
    report.faces_in += o.faces_in;
    report.primitives.push_back(std::move(o));
  }
  const unsigned hardware = std::max(1u, std::thread::hardware_concurrency());
  const unsigned threads = gltf_options.threads == 0 ? hardware : gltf_options.threads;

  std::vector<Mesh> meshes(jobs.size());
  for (std::size_t j = 0; j < jobs.size(); ++j) meshes[j] = doc.mesh(jobs[j]);

  // The primitives of one mesh are one surface split by material (and so are those of meshes that
  // the same nodes draw, GltfPrimitiveInfo::placement). Where they meet (the same position), the
  // shared budget simplifies them as one mesh whose faces carry their primitive as their material
  // (merged_primitives.h): the common border is a seam whose sides collapse together. Per
  // primitive, or where their attributes cannot be merged, each keeps the vertices it shares with
  // another, so that the border stays closed instead of opening a crack. (Unless the caller locks
  // vertices itself: its vertex_lock then applies to every primitive as given.)
  std::vector<Unit> units;
  std::vector<std::vector<std::uint8_t>> shared(jobs.size());
  std::vector<std::size_t> group(jobs.size());  // union-find over jobs that share a position
  for (std::size_t j = 0; j < jobs.size(); ++j) group[j] = j;
  const auto root = [&](std::size_t j) {
    while (group[j] != j) j = group[j] = group[group[j]];
    return j;
  };
  if (options.vertex_lock.empty()) {
    // A Draco-compressed mesh's primitives meet at positions a quantization step apart: snapped
    // together first (quantized_borders.h).
    snap_quantized_primitives(meshes, jobs, info);
    // (placement, position) -> the first job that has it, and whether another has it too
    std::map<std::pair<std::size_t, std::array<double, 3>>, std::pair<std::size_t, bool>> owner;
    const auto at = [&](std::size_t j, std::size_t v) {
      const double* p = &meshes[j].positions[3 * v];
      return std::pair{info[jobs[j]].placement, std::array<double, 3>{p[0], p[1], p[2]}};
    };
    for (std::size_t j = 0; j < jobs.size(); ++j)
      for (std::size_t v = 0; v < meshes[j].vertex_count(); ++v) {
        auto [it, fresh] = owner.try_emplace(at(j, v), j, false);
        if (fresh || it->second.first == j) continue;
        it->second.second = true;
        group[root(j)] = root(it->second.first);
      }
    for (std::size_t j = 0; j < jobs.size(); ++j) {
      std::vector<std::uint8_t> lock(meshes[j].vertex_count(), 0);
      bool any = false;
      for (std::size_t v = 0; v < lock.size(); ++v) any |= lock[v] = owner[at(j, v)].second;
      if (any) shared[j] = std::move(lock);
    }
  }
  std::vector<std::vector<std::size_t>> members(jobs.size());
  for (std::size_t j = 0; j < jobs.size(); ++j) members[root(j)].push_back(j);
  for (std::size_t j = 0; j < jobs.size(); ++j) {
    if (members[j].empty()) continue;
    // (A caller's vertex_protect is per primitive as read: it keeps them apart.)
    if (members[j].size() > 1 && !gltf_options.per_primitive && options.vertex_protect.empty()) {
      std::vector<Mesh> parts;
      for (std::size_t k : members[j]) parts.push_back(meshes[k]);
      if (std::optional<Mesh> merged = merge_parts(parts)) {
        Unit u;
        for (std::size_t k : members[j]) u.primitives.push_back(jobs[k]);
        u.mesh = std::move(*merged);
        u.parts = std::move(parts);
        units.push_back(std::move(u));
        continue;
      }
    }
    for (std::size_t k : members[j]) {
      Unit u;
      u.primitives = {jobs[k]};
      u.mesh = std::move(meshes[k]);
      u.lock = std::move(shared[k]);
      units.push_back(std::move(u));
    }
  }
  // In document order of their first primitive, whatever the grouping.
  std::sort(units.begin(), units.end(),
            [](const Unit& a, const Unit& b) { return a.primitives[0] < b.primitives[0]; });
  for (Unit& u : units) {
    u.world_scale = info[u.primitives[0]].world_scale;  // one placement: the same nodes
    u.faces = u.mesh.face_count(), u.vertices = u.mesh.vertex_count();
  }
  // Several units at once, each on one thread; one at a time, each with the caller's threads.
  const unsigned inner_threads = threads > 1 && units.size() > 1 ? 1 : options.threads;

  // The distance bound (--max-distance) in world units, relative: of the scene's diagonal (shared
  // mode) or of each primitive's own (per primitive, as the error limit). Each primitive gets it in
  // its own units, divided by its world_scale, the largest factor by which its nodes stretch a
  // length: a distance within the local bound is within the world bound wherever the primitive is
  // drawn. Every run of a primitive (watched and final) has the same bound, so that they refuse the
  // same contractions.
  const bool relative_per_primitive = gltf_options.per_primitive && options.max_distance_is_relative;
  // The scene's diagonal, for the relative criteria of the shared mode (merging the scene is not
  // free: done once, and only when needed).
  const bool scene_relative = !gltf_options.per_primitive &&
                              ((options.max_distance_is_relative && std::isfinite(options.max_distance)) ||
                               (options.max_error_is_relative && std::isfinite(options.max_error)));
  const double scene_diagonal = scene_relative ? bounding_box(doc.scene_mesh()).diagonal() : 1;
  double world_max_distance = options.max_distance;
  if (options.max_distance_is_relative && std::isfinite(world_max_distance) && !gltf_options.per_primitive)
    world_max_distance *= scene_diagonal;
  // The options every run of primitive j starts from: its shared-vertex locks and the bound.
  const auto primitive_options = [&](SimplifyOptions o, std::size_t j) {
    if (!units[j].lock.empty()) o.vertex_lock = units[j].lock;
    if (!relative_per_primitive) {
      o.max_distance = local_error(world_max_distance, units[j].world_scale);
      o.max_distance_is_relative = false;
    }
    return o;
  };

  // The error limit in world units (relative: of the scene's diagonal, in shared mode).
  double world_max_error = options.max_error;
  if (options.max_error_is_relative && std::isfinite(world_max_error) && !gltf_options.per_primitive)
    world_max_error *= scene_diagonal;

  // Per primitive: the options of its final run, and (shared budget) its watched run's curve.
  std::vector<std::optional<SimplifyOptions>> final_options(units.size());
  std::vector<ErrorCurve> curves;
  if (gltf_options.per_primitive) {
    for (std::size_t j = 0; j < units.size(); ++j) {
      SimplifyOptions o = primitive_options(options, j);
      o.threads = inner_threads;
      if (!o.max_error_is_relative) o.max_error = local_error(o.max_error, units[j].world_scale);
      final_options[j] = o;
    }
  } else {
    // The scene's face target: the smallest that the criteria give.
    std::size_t total_faces = 0, total_vertices = 0;
    for (std::size_t j = 0; j < units.size(); ++j)
      total_faces += units[j].faces, total_vertices += units[j].vertices;
    std::size_t target = std::numeric_limits<std::size_t>::max();
    if (options.target_faces > 0) target = std::min(target, options.target_faces);
    if (options.target_ratio > 0)
      target =
          std::min(target, static_cast<std::size_t>(std::floor(options.target_ratio * double(total_faces))));
    if (options.target_vertices > 0 && total_vertices > 0)
      target = std::min(
          target, static_cast<std::size_t>(std::floor(double(total_faces) * double(options.target_vertices) /
                                                      double(total_vertices))));
    const bool face_target = target != std::numeric_limits<std::size_t>::max();
    report.target_faces = face_target ? target : options.as_far_as_possible ? 0 : total_faces;
    // Each primitive's normal and colour weights from the scene's ratio (spacing_weights.h), once:
    // its watched and final runs must contract in the same order.
    std::vector<SimplifyOptions> unit_options;
    for (const Unit& u : units)
      unit_options.push_back(with_spacing_weights(
          u.mesh, options,
          face_target && total_faces > 0 ? double(target) * double(u.faces) / double(total_faces) : 0));

    if (units.size() == 1) {
      // One primitive: the scene's target is its own, and there is nothing to share.
      SimplifyOptions o = primitive_options(unit_options[0], 0);
      o.target_ratio = 0, o.target_vertices = 0;
      o.target_faces = face_target ? std::max<std::size_t>(1, target) : 0;
      o.max_error = local_error(world_max_error, units[0].world_scale);
      o.max_error_is_relative = false;
      o.threads = inner_threads;
      final_options[0] = o;
    } else {
      // 1. Watched runs down to a floor: a quarter of the scene's ratio on every primitive, so that
      // any threshold the target needs lies on every curve unless a primitive cannot go further.
      const double floor_ratio =
          face_target && total_faces > 0 ? 0.25 * double(target) / double(total_faces) : 0;
      auto watch = [&](std::size_t j, std::size_t floor_faces) {
        curves[j] = ErrorCurve(units[j].world_scale);
        SimplifyOptions o = primitive_options(unit_options[j], j);
        o.target_ratio = 0, o.target_vertices = 0;
        o.target_faces = std::max<std::size_t>(1, floor_faces);
        o.max_error = local_error(world_max_error, units[j].world_scale);
        o.max_error_is_relative = false;
        o.refit_rounds = 0;  // the curve is the contractions'; the final run refits
        o.far_repair = false;  // and repairs
        o.threads = inner_threads;
        curves[j].stop_reason = simplify(units[j].mesh, o, &curves[j]).stop_reason;
      };
      for (std::size_t j = 0; j < units.size(); ++j) curves.emplace_back(units[j].world_scale);
      for_each_job(units.size(), threads, [&](std::size_t j) {
        watch(j, static_cast<std::size_t>(floor_ratio * double(units[j].faces)));
      });
      // When primitives that can go no further keep the scene above its target, those that stopped at
      // the floor are watched again to the end, so that they take the rest of the reduction.
      std::size_t at_floor = 0;
      for (const ErrorCurve& c : curves) at_floor += c.faces.empty() ? c.initial : c.faces.back();
      if (face_target && at_floor > target) {
        std::vector<std::size_t> again;
        for (std::size_t j = 0; j < units.size(); ++j)
          if (curves[j].stop_reason == StopReason::TargetReached) again.push_back(j);
        for_each_job(again.size(), threads, [&](std::size_t k) { watch(again[k], 1); });
      }

      // 2. The smallest world threshold at which the primitives together meet the face target
      // (their faces only fall as it grows); without a face target, the error limit itself.
      std::vector<double> candidates{0.0};
      for (const ErrorCurve& c : curves)
        for (double e : c.running_max)
          if (e <= world_max_error) candidates.push_back(e);
      std::sort(candidates.begin(), candidates.end());
      candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
      auto faces_at = [&](double t) {
        std::size_t sum = 0;
        for (const ErrorCurve& c : curves) sum += c.faces_within(t);
        return sum;
      };
      std::size_t at = candidates.size() - 1;
      if (face_target) {
        auto it = std::partition_point(candidates.begin(), candidates.end(),
                                       [&](double t) { return faces_at(t) > target; });
        if (it != candidates.end()) at = static_cast<std::size_t>(it - candidates.begin());
      }
      const double threshold = candidates[at];
      report.world_threshold = threshold;
      std::vector<std::size_t> faces(units.size());
      for (std::size_t j = 0; j < units.size(); ++j) faces[j] = curves[j].faces_within(threshold);
      // The running maximum has plateaus: the contraction that reaches the threshold is followed by
      // cheaper ones, all within it. The primitives that step at the threshold may stop anywhere on
      // that step at the same error, so the faces the whole step would remove beyond the target are
      // given back to them (in proportion, in document order): the total meets the target closely.
      if (face_target && at > 0 && faces_at(threshold) < target) {
        std::vector<std::size_t> step(units.size());
        std::size_t steps = 0;
        for (std::size_t j = 0; j < units.size(); ++j) {
          const std::size_t before = curves[j].faces_within(candidates[at - 1]);
          // Up to the faces just before the threshold's contraction, less one so that it is made.
          step[j] = before > faces[j] ? before - faces[j] - 1 : 0;
          steps += step[j];
        }
        const std::size_t slack = target - faces_at(threshold);
        std::size_t given = 0;
        for (std::size_t j = 0; j < units.size() && steps > 0; ++j) {
          const std::size_t share =
              std::min(step[j], static_cast<std::size_t>(double(slack) * double(step[j]) / double(steps)));
          faces[j] += share, given += share;
        }
        for (std::size_t j = 0; j < units.size() && given < slack; ++j) {  // what rounding left over
          const std::size_t more = std::min(
              slack - given, step[j] - std::min(step[j], faces[j] - curves[j].faces_within(threshold)));
          faces[j] += more, given += more;
        }
      }

      // 3. Each primitive's final run stops at the faces found for it. It makes the same contractions
      // as its watched run (the order depends on neither the face target nor the observer), with the
      // same error limit, which blocks the same pairs.
      for (std::size_t j = 0; j < units.size(); ++j) {
        if (faces[j] >= curves[j].initial) continue;  // nothing to do: left as it is
        SimplifyOptions o = primitive_options(unit_options[j], j);
        o.target_ratio = 0, o.target_vertices = 0;
        o.target_faces = std::max<std::size_t>(1, faces[j]);
        o.max_error = local_error(world_max_error, units[j].world_scale);
        o.max_error_is_relative = false;
        o.threads = inner_threads;
        final_options[j] = o;
      }
    }
  }

  // The final runs, then the replacements in document order (none is made if a run fails).
  std::vector<std::optional<SimplifyResult>> results(units.size());
  for_each_job(units.size(), threads, [&](std::size_t j) {
    if (!final_options[j]) return;
    results[j] = simplify(units[j].mesh, *final_options[j]);
    // A primitive of a merged unit may collapse away entirely (a small pane closed up along its
    // seams): the run is made again with its vertices locked, so that it stays as it was, as it
    // would have unmerged, and the document keeps every primitive.
    const Unit& u = units[j];
    std::vector<std::uint8_t> locked;
    for (SimplifyOptions o = *final_options[j]; !u.parts.empty();) {
      std::vector<std::size_t> faces(u.parts.size(), 0);
      for (std::uint32_t m : results[j]->mesh.face_materials) ++faces[m];
      bool again = false;
      for (std::size_t k = 0, first = 0; k < u.parts.size(); first += u.parts[k++].vertex_count()) {
        if (faces[k] > 0) continue;
        locked.resize(u.vertices, 0);
        // (A part that vanishes with its vertices locked is left so: not made again.)
        again |= locked[first] == 0;
        std::fill_n(locked.begin() + std::ptrdiff_t(first), u.parts[k].vertex_count(), std::uint8_t(1));
      }
      if (!again) break;
      o.vertex_lock = locked;
      results[j] = simplify(u.mesh, o);
    }
  });
  for (std::size_t j = 0; j < units.size(); ++j) {
    if (!results[j] || results[j]->contractions == 0) continue;
    SimplifyResult& r = *results[j];
    const Unit& u = units[j];
    for (std::size_t k = 0; k < u.primitives.size(); ++k) {
      GltfPrimitiveOutcome& o = report.primitives[u.primitives[k]];
      Mesh part = u.parts.empty() ? std::move(r.mesh) : split_part(r.mesh, std::uint32_t(k), u.parts[k]);
      o.status = GltfPrimitiveOutcome::Status::Simplified;
      o.faces_out = part.face_count();
      o.max_error = r.max_error;
      o.world_error = r.max_error * o.world_scale;
      o.world_distance = r.output_to_input_distance * o.world_scale;
      o.stop_reason = r.stop_reason;
      if (!curves.empty() && r.contractions < curves[j].errors.size())
        o.next_world_error = curves[j].errors[r.contractions];
      // A final run that made every contraction of its watched run met its face target there, but
      // it stopped because no contraction was left when the watched run did.
      if (!curves.empty() && r.contractions >= curves[j].errors.size() &&
          curves[j].stop_reason == StopReason::NoValidPair)
        o.stop_reason = StopReason::NoValidPair;
      doc.replace(u.primitives[k], std::move(part));
    }
  }
  if (!gltf_options.per_primitive && units.size() == 1)
    report.world_threshold = report.primitives[units[0].primitives[0]].world_error;
  report.faces_out = 0;
  for (const GltfPrimitiveOutcome& o : report.primitives) {
    report.faces_out += o.faces_out;
    report.max_world_error = std::max(report.max_world_error, o.world_error);
    report.max_world_distance = std::max(report.max_world_distance, o.world_distance);
    if (o.status == GltfPrimitiveOutcome::Status::Simplified) ++report.simplified;
    if (o.status == GltfPrimitiveOutcome::Status::Unchanged) ++report.unchanged;
    if (o.status == GltfPrimitiveOutcome::Status::Kept) ++report.kept;
  }
  return report;
}

}  // namespace qem
