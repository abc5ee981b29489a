// The bounding box of a set of points: the one loop behind every box in qem (the public
// bounding_box, the normalised frames of frame.h, the clustering grid, the measure's diagonal,
// the viewer's framing), so that they all agree to the bit on the same points.
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <span>

#include "geometry/vec3.h"
#include "qem/mesh.h"

namespace qem {

/// Grows a box point by point, for boxes of points that are not one array (several meshes, the
/// vertices a mask keeps). Each bound is std::min / std::max of itself and the coordinate, from an
/// empty start: a NaN coordinate is skipped, and of equal coordinates (+0 and -0) the first seen
/// stays, exactly as the loops it replaced.
class BoxOfPoints {
 public:
  /// Adds the point p[0], p[1], p[2].
  void add(const double* p) {
    for (int k = 0; k < 3; ++k) lo_[k] = std::min(lo_[k], p[k]), hi_[k] = std::max(hi_[k], p[k]);
    any_ = true;
  }
  /// Adds every point of `xyz` (x, y, z triples; a trailing partial triple is ignored).
  void add_all(std::span<const double> xyz) {
    for (std::size_t i = 0; i + 2 < xyz.size(); i += 3) add(&xyz[i]);
  }
  /// Adds the points another box was grown from: the same box as adding them here one by one
  /// after those added so far (min and max are exact; of equal bounds the earlier stays).
  void add(const BoxOfPoints& other) {
    for (int k = 0; k < 3; ++k) lo_[k] = std::min(lo_[k], other.lo_[k]), hi_[k] = std::max(hi_[k], other.hi_[k]);
    any_ = any_ || other.any_;
  }
  /// No point added yet.
  bool empty() const { return !any_; }
  /// The box of the points added; the zero box (as bounding_box gives for no vertex) if none was.
  Box box() const;

 private:
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  double lo_[3] = {kInf, kInf, kInf}, hi_[3] = {-kInf, -kInf, -kInf};
  bool any_ = false;
};

/// The box of the points of `xyz` (x, y, z triples): all of them, or those listed in `subset`
/// (indices of points, not of doubles). No point: the zero box.
Box box_of_points(std::span<const double> xyz);
Box box_of_points(std::span<const double> xyz, std::span<const std::uint32_t> subset);

/// The midpoint of the box, as lo/2 + hi/2: the same as (lo + hi)/2 (both round once) except
/// among subnormals and near the largest double, where (lo + hi) overflows and this does not.
inline Vec3 box_center(const Box& box) {
  return {box.lo[0] / 2 + box.hi[0] / 2, box.lo[1] / 2 + box.hi[1] / 2, box.lo[2] / 2 + box.hi[2] / 2};
}

}  // namespace qem
