#include "core/settings.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/parallel_chunks.h"
#include "qem/error.h"

namespace qem::core {

void validate(const SimplifyOptions& o) {
  const bool any = o.target_faces > 0 || o.target_ratio > 0 || o.target_vertices > 0 || std::isfinite(o.max_error) ||
                   std::isfinite(o.max_distance) || o.as_far_as_possible;
  if (o.target_ratio < 0 || o.target_ratio > 1 || std::isnan(o.target_ratio))
    throw Error("target ratio must be in [0, 1] (0: unused)");
  if (std::isfinite(o.max_error) && o.max_error < 0) throw Error("max error must not be negative");
  if (std::isnan(o.max_error)) throw Error("max error must be a number");
  if (!(o.max_distance > 0)) throw Error("max distance must be positive");
  if (!any)
    throw Error(
        "no stop criterion: give a face, ratio, vertex or error target (a face, ratio or vertex target of 0: as far "
        "as the checks allow)");
  if (!(o.max_normal_turn_degrees > 0 && o.max_normal_turn_degrees < 90))
    throw Error("the inversion angle limit must be in (0, 90) degrees");
  if (!(o.threshold >= 0)) throw Error("threshold must not be negative");
  if (!(o.boundary_weight >= 0)) throw Error("boundary weight must not be negative");
  if (!(o.prune_size >= 0) || std::isinf(o.prune_size)) throw Error("prune size must be a finite distance >= 0");
  if (!(o.forget >= 0 && o.forget < 1)) throw Error("the forgetting factor must be in [0, 1) (0: never)");
}

Settings resolve(const SimplifyOptions& o, const WorkingMesh& mesh, bool attributes) {
  validate(o);
  Settings s;
  bool any = false;
  if (o.target_faces > 0) s.target_faces = o.target_faces, any = true;
  if (o.target_ratio > 0) {
    const std::size_t t = std::size_t(std::floor(o.target_ratio * double(mesh.faces_alive)));
    s.target_faces = any ? std::max(s.target_faces, t) : t;
  }
  s.target_vertices = o.target_vertices;
  s.max_error = std::numeric_limits<double>::infinity();
  if (std::isfinite(o.max_error)) s.max_error = o.max_error_is_relative ? o.max_error : o.max_error / mesh.frame.scale;
  s.max_distance = std::numeric_limits<double>::infinity();
  if (std::isfinite(o.max_distance))
    s.max_distance = o.max_distance_is_relative ? o.max_distance : o.max_distance / mesh.frame.scale;
  s.weighting = o.weighting;
  s.placement = o.placement;
  s.threshold = o.threshold_is_relative ? o.threshold : o.threshold / mesh.frame.scale;
  s.boundary_weight = o.boundary_weight;
  s.lock_border = o.lock_border;
  s.exact_border = o.exact_border;
  s.inversion = o.inversion;
  s.cos_max_turn = std::cos(o.max_normal_turn_degrees * 3.14159265358979323846 / 180.0);
  s.preserve_topology = o.preserve_topology;
  s.scheme = o.scheme;
  s.greedy_below_faces = o.greedy_below_faces;
  // Renewed quadrics measure the distance to the current surface, not to the input: an error
  // limit needs the whole quadrics (GH97 §4's bound). With attributes only when asked
  // (SimplifyOptions::forget_attributes).
  s.forget = std::isfinite(o.max_error) || (attributes && !o.forget_attributes) ? 0 : o.forget;
  s.seam_weight = o.attribute_weights.seam;
  s.threads = resolve_threads(o.threads);
  s.keep_components = o.keep_components;
  s.prune_size = o.prune_size_is_relative ? o.prune_size : o.prune_size / mesh.frame.scale;
  return s;
}

std::string stop_detail(StopReason reason, const SimplifyResult& r, bool lock_border) {
  switch (reason) {
    case StopReason::TargetReached: return "target reached";
    case StopReason::ErrorLimit: return "every remaining contraction exceeds the error limit";
    case StopReason::NoValidPair:
      return "no valid contraction left (" + std::to_string(r.rejected_topology) + " rejected for topology, " +
             std::to_string(r.rejected_inversion) + " for face inversion" +
             (r.rejected_distance > 0 ? ", " + std::to_string(r.rejected_distance) + " for the distance bound" : "") +
             (r.rejected_component > 0 ? ", " + std::to_string(r.rejected_component) + " to keep components" : "") +
             (lock_border ? ", border locked" : "") + ")";
    case StopReason::AlreadyBelowTarget: return "the input already meets the target";
    default: return to_string(reason);
  }
}

}  // namespace qem::core
