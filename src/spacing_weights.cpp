#include "spacing_weights.h"

#include <algorithm>
#include <cmath>

#include "geometry/box.h"
#include "geometry/vec3.h"
#include "partition/partition_targets.h"

namespace qem {

namespace {

bool has(MeshView input, AttributeKind kind) {
  return std::any_of(input.attributes.begin(), input.attributes.end(),
                     [&](const VertexAttribute& a) { return a.kind == kind; });
}

// sqrt(area / target_faces) in diagonals of the faces' corners' box (unreferenced vertices do not
// count, as in the core's frame); NaN where there is none (no target, no area, bad indices, which
// the run refuses).
double face_spacing(MeshView input, double target_faces) {
  if (!(target_faces > 0)) return NAN;
  const std::size_t vertices = input.vertex_count();
  double twice_area = 0;
  for (std::size_t f = 0; f < input.face_count(); ++f) {
    const std::uint32_t* t = &input.indices[3 * f];
    if (t[0] >= vertices || t[1] >= vertices || t[2] >= vertices) return NAN;
    const double *a = &input.positions[3 * std::size_t(t[0])], *b = &input.positions[3 * std::size_t(t[1])],
                 *c = &input.positions[3 * std::size_t(t[2])];
    const Vec3 ab{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, ac{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    twice_area += length(cross(ab, ac));
  }
  const double diagonal = box_of_points(input.positions, input.indices).diagonal();
  return diagonal > 0 ? std::sqrt(0.5 * twice_area / target_faces) / diagonal : NAN;
}

}  // namespace

bool spacing_weights_unresolved(MeshView input, const SimplifyOptions& options) {
  const AttributeWeights& w = options.attribute_weights;
  return (w.normal_per_spacing > 0 && has(input, AttributeKind::Normal)) ||
         (w.color_per_spacing > 0 && has(input, AttributeKind::Color));
}

double normal_weight_used(MeshView input, const SimplifyOptions& options) {
  return has(input, AttributeKind::Normal) ? options.attribute_weights.normal : 0;
}

double color_weight_used(MeshView input, const SimplifyOptions& options) {
  return has(input, AttributeKind::Color) ? options.attribute_weights.color : 0;
}

double asked_faces(MeshView input, const SimplifyOptions& options) {
  const partition_detail::Targets t = partition_detail::resolve_targets(options, input.face_count());
  return t.faces > 0 ? double(t.faces) : 2 * double(t.vertices);
}

SimplifyOptions with_spacing_weights(MeshView input, SimplifyOptions options, double target_faces) {
  AttributeWeights& w = options.attribute_weights;
  // Only the kinds the mesh carries: a weight it has no values for is never read, and a glTF
  // primitive with neither needs no pass over its faces.
  const double normal_factor = has(input, AttributeKind::Normal) ? w.normal_per_spacing : 0;
  const double color_factor = has(input, AttributeKind::Color) ? w.color_per_spacing : 0;
  w.normal_per_spacing = w.color_per_spacing = 0;
  if (!(normal_factor > 0) && !(color_factor > 0)) return options;
  const double spacing = face_spacing(input, target_faces);
  if (!std::isfinite(spacing)) return options;
  if (normal_factor > 0) w.normal = std::max(w.normal, normal_factor * spacing);
  if (color_factor > 0) w.color = std::max(w.color, std::min(w.color_spacing_cap, color_factor * spacing));
  return options;
}

}  // namespace qem
