#include "measure/spatial_order.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace qem::measure_detail {

namespace {

// Spreads the low 21 bits of x so that bit i lands on bit 3i.
std::uint64_t spread_bits(std::uint64_t x) {
  x &= 0x1fffff;
  x = (x | x << 32) & 0x1f00000000ffffULL;
  x = (x | x << 16) & 0x1f0000ff0000ffULL;
  x = (x | x << 8) & 0x100f00f00f00f00fULL;
  x = (x | x << 4) & 0x10c30c30c30c30c3ULL;
  x = (x | x << 2) & 0x1249249249249249ULL;
  return x;
}

}  // namespace

std::vector<std::uint32_t> morton_order(const std::vector<double>& xyz) {
  const std::size_t n = xyz.size() / 3;
  std::vector<std::uint32_t> order(n);
  if (n == 0) return order;
  double lo[3] = {xyz[0], xyz[1], xyz[2]}, hi[3] = {xyz[0], xyz[1], xyz[2]};
  for (std::size_t i = 0; i < xyz.size(); i += 3)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], xyz[i + k]), hi[k] = std::max(hi[k], xyz[i + k]);
  double scale[3];
  for (int k = 0; k < 3; ++k) scale[k] = hi[k] > lo[k] ? 2097151.0 / (hi[k] - lo[k]) : 0.0;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::uint64_t code = 0;
    for (int k = 0; k < 3; ++k) {
      const double t = (xyz[3 * i + k] - lo[k]) * scale[k];
      const std::uint64_t q = t > 0 ? std::uint64_t(std::min(t, 2097151.0)) : 0;  // NaN -> 0
      code |= spread_bits(q) << k;
    }
    keyed[i] = {code, std::uint32_t(i)};
  }
  std::sort(keyed.begin(), keyed.end());
  for (std::size_t i = 0; i < n; ++i) order[i] = keyed[i].second;
  return order;
}

}  // namespace qem::measure_detail
