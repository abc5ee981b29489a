#include "core/border_placement.h"

#include <cmath>
#include <numbers>

namespace qem::core {

void mark_border_corners(WorkingMesh& m, const std::vector<Edge>& edges) {
  const std::size_t n = m.vertex_count();
  m.corner.assign(n, 0);
  // Per vertex: its border edges (up to two other ends kept) and whether it has more.
  std::vector<std::uint8_t> count(n, 0);
  std::vector<std::uint32_t> other(2 * n, kNoVertex);
  const auto add = [&](std::uint32_t v, std::uint32_t o) {
    if (count[v] < 2) other[2 * std::size_t(v) + count[v]] = o;
    if (count[v] < 255) ++count[v];
  };
  for (const Edge& e : edges) {
    if (e.faces > 2) m.corner[e.lo] = m.corner[e.hi] = 1;  // non-manifold: where sheets meet
    if (e.faces != 1) continue;
    add(e.lo, e.hi), add(e.hi, e.lo);
  }
  const double cos_corner = std::cos(kCornerDegrees * std::numbers::pi / 180);
  for (std::uint32_t v = 0; v < n; ++v) {
    if (count[v] == 0 || m.corner[v]) continue;
    if (count[v] != 2) {  // a border that ends, or two borders through one vertex
      m.corner[v] = 1;
      continue;
    }
    const Vec3 in = m.pos[v] - m.pos[other[2 * std::size_t(v)]], out = m.pos[other[2 * std::size_t(v) + 1]] - m.pos[v];
    const double scale = std::sqrt(dot(in, in) * dot(out, out));
    // The turn between the incoming and outgoing directions (0 on a straight border).
    if (!(dot(in, out) >= cos_corner * scale)) m.corner[v] = 1;
  }
}

}  // namespace qem::core
