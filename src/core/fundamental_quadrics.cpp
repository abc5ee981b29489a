#include "core/fundamental_quadrics.h"

#include <cmath>

namespace qem::core {

std::vector<Quadric> face_quadrics(const WorkingMesh& m, Weighting weighting) {
  std::vector<Quadric> quadric(m.pos.size());
  for (std::uint32_t f = 0; f < m.face_source.size(); ++f) {
    const std::uint32_t* t = m.face(f);
    Vec3 n = cross(m.pos[t[1]] - m.pos[t[0]], m.pos[t[2]] - m.pos[t[0]]);
    const double len = length(n);
    if (!(len > 0)) continue;  // zero-area face: no plane (GH97 §5 needs a unit normal)
    n = n * (1.0 / len);
    const double d = -dot(n, m.pos[t[0]]);
    switch (weighting) {
      case Weighting::Area: {  // HG99 §2
        const Quadric q = Quadric::plane(n, d, len / 2);
        for (int k = 0; k < 3; ++k) quadric[t[k]] += q;
        break;
      }
      case Weighting::Uniform: {  // GH97 §5
        const Quadric q = Quadric::plane(n, d, 1);
        for (int k = 0; k < 3; ++k) quadric[t[k]] += q;
        break;
      }
      case Weighting::Angle:  // each corner weighs its plane by its own angle
        for (int k = 0; k < 3; ++k) {
          const Vec3 e1 = m.pos[t[(k + 1) % 3]] - m.pos[t[k]], e2 = m.pos[t[(k + 2) % 3]] - m.pos[t[k]];
          const double angle = std::atan2(length(cross(e1, e2)), dot(e1, e2));
          quadric[t[k]] += Quadric::plane(n, d, angle);
        }
        break;
    }
  }
  return quadric;
}

void add_boundary_planes(WorkingMesh& m, const std::vector<Edge>& edges, double weight, Weighting weighting,
                         std::vector<Quadric>& quadric) {
  for (const Edge& e : edges) {
    if (e.faces != 1) continue;
    m.boundary[e.lo] = m.boundary[e.hi] = 1;
    if (!(weight > 0)) continue;
    std::uint32_t face = 0;
    for (std::uint32_t f : m.vertex_faces[e.lo])
      if (m.face_has(f, e.hi)) face = f;
    const std::uint32_t* t = m.face(face);
    const Vec3 n = cross(m.pos[t[1]] - m.pos[t[0]], m.pos[t[2]] - m.pos[t[0]]);
    const Vec3 edge = m.pos[e.hi] - m.pos[e.lo];
    Vec3 normal = cross(edge, n);
    const double len = length(normal);
    if (!(len > 0)) continue;
    normal = normal * (1.0 / len);
    const double w = weight * (weighting == Weighting::Area ? dot(edge, edge) : 1.0);
    Quadric q = Quadric::plane(normal, -dot(normal, m.pos[e.lo]), w);
    q.weight = 0;  // a constraint, not surface: it must not dilute the reported mean distance
    quadric[e.lo] += q;
    quadric[e.hi] += q;
  }
}

}  // namespace qem::core
