#include "core/spatial_order.h"

#include <algorithm>
#include <limits>

namespace qem::core {

namespace {
// Spreads the low 21 bits of x so that there are two zero bits between each (for 3D interleaving).
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

std::vector<std::uint32_t> morton_order(const std::vector<Vec3>& positions, const std::vector<std::uint32_t>& vertices) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  Vec3 lo{kInf, kInf, kInf}, hi{-kInf, -kInf, -kInf};
  for (std::uint32_t v : vertices) {
    const Vec3& p = positions[v];
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  // One scale for all axes keeps cells cubic.
  double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  double scale = extent > 0 ? double((1 << 21) - 1) / extent : 0;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed;
  keyed.reserve(vertices.size());
  for (std::uint32_t v : vertices) {
    const Vec3& p = positions[v];
    std::uint64_t x = std::uint64_t((p.x - lo.x) * scale), y = std::uint64_t((p.y - lo.y) * scale),
                  z = std::uint64_t((p.z - lo.z) * scale);
    keyed.push_back({spread_bits(x) | spread_bits(y) << 1 | spread_bits(z) << 2, v});
  }
  std::sort(keyed.begin(), keyed.end());
  std::vector<std::uint32_t> order(keyed.size());
  for (std::size_t i = 0; i < keyed.size(); ++i) order[i] = keyed[i].second;
  return order;
}

}  // namespace qem::core
