// The normalised frame: centred on the bounding box of a set of points, with the box's diagonal
// as the unit. The simplifier and the refit work in it, so every tolerance is relative and a
// result does not depend on the model's position or scale.
//
// Use: `const Frame f = frame_of_box(box_of_points(xyz, used));` then f.to_frame(p) for each
// point read and f.to_model(q) for each point written back (box.h has box_of_points; a caller
// that refuses some boxes, such as bounds beyond 1e300, checks the box in between).
#pragma once

#include <cmath>

#include "geometry/box.h"
#include "geometry/vec3.h"
#include "qem/mesh.h"

namespace qem {

struct Frame {
  Vec3 center;       ///< the box's midpoint (box_center)
  double scale = 1;  ///< the box's diagonal; 1 when that is 0 (no point, or one) or not finite

  /// Model to frame coordinates: (p - center) / scale, correctly rounded per component (the refit).
  Vec3 to_frame(const Vec3& p) const { return (p - center) / scale; }
  /// (p - center) * (1 / scale), as the simplifier has always normalised its input. A component
  /// can differ from to_frame's in the last bit, and the simplifier's output bytes
  /// (tests/golden_checksums.txt) change if it uses to_frame instead.
  Vec3 to_frame_by_reciprocal(const Vec3& p) const { return (p - center) * (1.0 / scale); }
  /// Frame to model coordinates: center + q * scale.
  Vec3 to_model(const Vec3& q) const { return center + q * scale; }
};

/// The frame of a box (from box_of_points, or qem::bounding_box). The zero box gives center 0,
/// scale 1: the identity.
inline Frame frame_of_box(const Box& box) {
  Frame f;
  f.center = box_center(box);
  const double diagonal = box.diagonal();
  if (diagonal > 0 && std::isfinite(diagonal)) f.scale = diagonal;
  return f;
}

}  // namespace qem
