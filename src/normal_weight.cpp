#include "normal_weight.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "geometry/vec3.h"

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
  double faces = double(options.target_faces);
  if (options.target_ratio > 0)
    faces = std::max(faces, std::floor(options.target_ratio * double(input.face_count())));
  if (faces == 0 && options.target_vertices > 0) faces = 2 * double(options.target_vertices);
  return faces;
}

SimplifyOptions with_normal_weight(MeshView input, SimplifyOptions options, double target_faces) {
  const double per_spacing = options.attribute_weights.normal_per_spacing;
  options.attribute_weights.normal_per_spacing = 0;
  if (!(per_spacing > 0) || !(target_faces > 0)) return options;
  // The area and the box of the faces' corners (unreferenced vertices do not count, as in the core's frame).
  constexpr double inf = std::numeric_limits<double>::infinity();
  Vec3 lo{inf, inf, inf}, hi{-inf, -inf, -inf};
  double twice_area = 0;
  const auto at = [&](std::uint32_t v) {
    return Vec3{input.positions[3 * std::size_t(v)], input.positions[3 * std::size_t(v) + 1],
                input.positions[3 * std::size_t(v) + 2]};
  };
  const std::size_t vertices = input.vertex_count();
  for (std::size_t f = 0; f < input.face_count(); ++f) {
    const std::uint32_t* t = &input.indices[3 * f];
    if (t[0] >= vertices || t[1] >= vertices || t[2] >= vertices) return options;  // the run refuses it
    const Vec3 a = at(t[0]), b = at(t[1]), c = at(t[2]);
    twice_area += length(cross(b - a, c - a));
    for (const Vec3& p : {a, b, c}) {
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    }
  }
  const double diagonal = length(hi - lo);
  const double spacing = std::sqrt(0.5 * twice_area / target_faces) / diagonal;
  if (std::isfinite(spacing) && diagonal > 0)
    options.attribute_weights.normal = std::max(options.attribute_weights.normal, per_spacing * spacing);
  return options;
}

}  // namespace qem
