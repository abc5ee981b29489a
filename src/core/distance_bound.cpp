#include "core/distance_bound.h"

#include <algorithm>
#include <limits>

#include "measure/point_triangle.h"

namespace qem::core {

bool SurfaceDistance::piece_within(const Vec3& a, const Vec3& b, const Vec3& c, double d, int depth,
                                  std::uint32_t parent) const {
  using measure_detail::squared_distance;
  const auto near = [&](std::uint32_t id) {
    const std::array<double, 9> t = tree_.triangle(id);
    const Vec3 ta{t[0], t[1], t[2]}, tb{t[3], t[4], t[5]}, tc{t[6], t[7], t[8]};
    const auto one = [&](const Vec3& p) {
      return squared_distance(p, measure_detail::closest_point_on_triangle(p, ta, tb, tc)) <= d * d;
    };
    return one(a) && one(b) && one(c);
  };
  // The parent piece's closest triangle often holds a smaller piece already (convexity, below):
  // no search then. Else it warm-starts the search, which finds the same triangle as a cold one.
  if (parent != UINT32_MAX && near(parent)) return true;
  const Vec3 m = (1.0 / 3) * (a + b + c);
  const double q[3] = {m.x, m.y, m.z};
  const auto hit = tree_.closest(q, d * d, parent);
  if (!(hit.d2 <= d * d)) return false;  // the centroid itself is too far
  const double reach = std::sqrt(std::max({squared_distance(a, m), squared_distance(b, m), squared_distance(c, m)}));
  if (std::sqrt(hit.d2) + reach <= d) return true;  // 1-Lipschitz
  if (hit.triangle != parent && near(hit.triangle)) return true;  // convexity of the distance to T
  if (depth == kMaxDepth) return false;
  const Vec3 ab = 0.5 * (a + b), bc = 0.5 * (b + c), ca = 0.5 * (c + a);
  const std::uint32_t t = hit.triangle;
  return piece_within(a, ab, ca, d, depth + 1, t) && piece_within(ab, b, bc, d, depth + 1, t) &&
         piece_within(ca, bc, c, d, depth + 1, t) && piece_within(ab, bc, ca, d, depth + 1, t);
}

double SurfaceDistance::triangle_sampled_max(const Vec3& a, const Vec3& b, const Vec3& c) const {
  // A barycentric grid of 4 subdivisions: 15 points.
  constexpr int n = 4;
  double most = 0;
  std::uint32_t hint = UINT32_MAX;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; i + j <= n; ++j)
      most = std::max(most, distance(a + (b - a) * (double(i) / n) + (c - a) * (double(j) / n), &hint));
  return most;
}

std::vector<double> live_face_corners(const WorkingMesh& m) {
  std::vector<double> corners;
  corners.reserve(9 * m.faces_alive);
  for (std::uint32_t f = 0; f < m.face_alive.size(); ++f) {
    if (!m.face_alive[f]) continue;
    for (int k = 0; k < 3; ++k) {
      const Vec3& p = m.pos[m.face(f)[k]];
      corners.insert(corners.end(), {p.x, p.y, p.z});
    }
  }
  return corners;
}

bool contraction_within(const SurfaceDistance& surface, double d, const WorkingMesh& m, std::uint32_t a,
                        std::uint32_t b, const Vec3& target) {
  for (const std::uint32_t v : {a, b})
    for (std::uint32_t f : m.vertex_faces[v]) {
      if (!m.face_alive[f] || (m.face_has(f, a) && m.face_has(f, b))) continue;  // dies
      const std::uint32_t* t = m.face(f);
      const auto at = [&](int k) { return t[k] == v ? target : m.pos[t[k]]; };
      if (!surface.triangle_within(at(0), at(1), at(2), d)) return false;
    }
  return true;
}

}  // namespace qem::core
