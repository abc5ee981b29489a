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

std::vector<Quadric> carried_quadrics(const WorkingMesh& m, const CarriedQuadrics& carried) {
  // Q(p - origin) with p = center + scale x: Q = scale^2 x^T A x + 2 scale x.(A t + b) + Q(t),
  // t = center - origin; the frame's quadric is that over scale^4 (weights over scale^2).
  const Vec3 t = m.frame.center - carried.origin;
  const double s = m.frame.scale, s2 = s * s, s3 = s2 * s, s4 = s2 * s2;
  std::vector<Quadric> quadric(m.pos.size());
  for (std::uint32_t v = 0; v < m.pos.size(); ++v) {
    const Quadric& q = carried.per_vertex[m.source_vertex[v]];
    const Vec3 at = q.apply_a(t);
    Quadric& f = quadric[v];
    f.a00 = q.a00 / s2, f.a01 = q.a01 / s2, f.a02 = q.a02 / s2;
    f.a11 = q.a11 / s2, f.a12 = q.a12 / s2, f.a22 = q.a22 / s2;
    f.b0 = (at.x + q.b0) / s3, f.b1 = (at.y + q.b1) / s3, f.b2 = (at.z + q.b2) / s3;
    f.c = (dot(t, at) + 2 * (q.b0 * t.x + q.b1 * t.y + q.b2 * t.z) + q.c) / s4;
    f.weight = q.weight / s2;
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
