#include "measure/surface_sampling.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "check_mesh.h"
#include "measure/point_triangle.h"
#include "measure/rng.h"
#include "qem/error.h"

namespace qem::measure_detail {

Surface make_surface(MeshView mesh, const char* what) {
  check_mesh(mesh, what);
  Surface s;
  const std::size_t nv = mesh.vertex_count();
  s.faces = mesh.face_count();
  std::vector<char> used(nv, 0);
  s.corners.reserve(9 * s.faces);
  s.cum_area.reserve(s.faces);
  const double* P = mesh.positions.data();
  for (std::size_t f = 0; f < s.faces; ++f) {
    const std::uint32_t* t = &mesh.indices[3 * f];
    used[t[0]] = used[t[1]] = used[t[2]] = 1;
    const Vec3 a{P[3 * t[0]], P[3 * t[0] + 1], P[3 * t[0] + 2]};
    const Vec3 b{P[3 * t[1]], P[3 * t[1] + 1], P[3 * t[1] + 2]};
    const Vec3 c{P[3 * t[2]], P[3 * t[2] + 1], P[3 * t[2] + 2]};
    const Vec3 n = cross(b - a, c - a);
    const double area = 0.5 * std::sqrt(dot(n, n));
    // Zero-area faces carry no surface: they can be neither sampled nor be the closest surface point.
    // An area that overflows to infinity is dropped the same way.
    if (!(area > 0) || !std::isfinite(area)) {
      ++s.degenerate;
      continue;
    }
    s.corners.insert(s.corners.end(), {a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z});
    s.area += area;
    s.cum_area.push_back(s.area);
    s.face_of.push_back(std::uint32_t(f));
  }
  for (std::size_t v = 0; v < nv; ++v)
    if (used[v]) s.vertices.insert(s.vertices.end(), {P[3 * v], P[3 * v + 1], P[3 * v + 2]});
  return s;
}

std::vector<double> sample_surface(const Surface& s, std::size_t n, std::uint64_t seed,
                                   std::vector<SamplePlace>* places) {
  std::vector<double> out;
  const std::size_t nt = s.triangle_count();
  if (nt == 0) return out;
  out.resize(3 * n);
  if (places) places->resize(n);
  Rng rng(seed);
  for (std::size_t k = 0; k < n; ++k) {
    const double r = rng.uniform() * s.area;
    std::size_t f =
        std::size_t(std::upper_bound(s.cum_area.begin(), s.cum_area.end(), r) - s.cum_area.begin());
    if (f >= nt) f = nt - 1;
    // Square-root warp: (1 - sqrt(r1), sqrt(r1)(1 - r2), sqrt(r1) r2) is uniform on the triangle.
    const double r1 = std::sqrt(rng.uniform()), r2 = rng.uniform();
    const double wa = 1 - r1, wb = r1 * (1 - r2), wc = r1 * r2;
    const double* t = &s.corners[9 * f];
    for (int i = 0; i < 3; ++i) out[3 * k + i] = wa * t[i] + wb * t[3 + i] + wc * t[6 + i];
    if (places) (*places)[k] = {std::uint32_t(f), {wa, wb, wc}};
  }
  return out;
}

}  // namespace qem::measure_detail
