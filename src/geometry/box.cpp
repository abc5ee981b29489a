#include "geometry/box.h"

namespace qem {

Box BoxOfPoints::box() const {
  Box box;
  if (!any_) return box;
  std::copy(lo_, lo_ + 3, box.lo);
  std::copy(hi_, hi_ + 3, box.hi);
  return box;
}

Box box_of_points(std::span<const double> xyz) {
  BoxOfPoints points;
  points.add_all(xyz);
  return points.box();
}

Box box_of_points(std::span<const double> xyz, std::span<const std::uint32_t> subset) {
  BoxOfPoints points;
  for (std::uint32_t i : subset) points.add(&xyz[3 * std::size_t(i)]);
  return points.box();
}

}  // namespace qem
