#include "normal_weight.h"

#include <algorithm>
#include <cmath>

#include "geometry/box.h"
#include "geometry/vec3.h"
#include "partition/partition_targets.h"

namespace qem {

namespace {

bool has_normals(MeshView input) {
  return std::any_of(input.attributes.begin(), input.attributes.end(),
                     [](const VertexAttribute& a) { return a.kind == AttributeKind::Normal; });
}

}  // namespace

bool normal_weight_unresolved(MeshView input, const SimplifyOptions& options) {
  return options.attribute_weights.normal_per_spacing > 0 && has_normals(input);
}

double normal_weight_used(MeshView input, const SimplifyOptions& options) {
  return has_normals(input) ? options.attribute_weights.normal : 0;
}

double asked_faces(MeshView input, const SimplifyOptions& options) {
  const partition_detail::Targets t = partition_detail::resolve_targets(options, input.face_count());
  return t.faces > 0 ? double(t.faces) : 2 * double(t.vertices);
}

SimplifyOptions with_normal_weight(MeshView input, SimplifyOptions options, double target_faces) {
  const double per_spacing = options.attribute_weights.normal_per_spacing;
  options.attribute_weights.normal_per_spacing = 0;
  if (!(per_spacing > 0) || !(target_faces > 0)) return options;
  const std::size_t vertices = input.vertex_count();
  double twice_area = 0;
  for (std::size_t f = 0; f < input.face_count(); ++f) {
    const std::uint32_t* t = &input.indices[3 * f];
    if (t[0] >= vertices || t[1] >= vertices || t[2] >= vertices) return options;  // the run refuses it
    const double *a = &input.positions[3 * std::size_t(t[0])], *b = &input.positions[3 * std::size_t(t[1])],
                 *c = &input.positions[3 * std::size_t(t[2])];
    const Vec3 ab{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, ac{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    twice_area += length(cross(ab, ac));
  }
  // In diagonals of the faces' corners' box (unreferenced vertices do not count, as in the core's frame).
  const double diagonal = box_of_points(input.positions, input.indices).diagonal();
  const double spacing = std::sqrt(0.5 * twice_area / target_faces) / diagonal;
  if (std::isfinite(spacing) && diagonal > 0)
    options.attribute_weights.normal = std::max(options.attribute_weights.normal, per_spacing * spacing);
  return options;
}

}  // namespace qem
