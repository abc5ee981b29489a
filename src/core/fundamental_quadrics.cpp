#include "core/fundamental_quadrics.h"

#include <cmath>

#include "core/parallel_chunks.h"
#include "core/seam_planes.h"

namespace qem::core {

namespace {

// Face f's plane quadric as its corner k adds it (only angle weighting depends on the corner).
Quadric plane_of_face(const WorkingMesh& m, std::uint32_t f, int k, Weighting weighting) {
  const std::uint32_t* t = m.face(f);
  Vec3 n = cross(m.pos[t[1]] - m.pos[t[0]], m.pos[t[2]] - m.pos[t[0]]);
  const double len = length(n);
  if (!(len > 0)) return Quadric{};  // zero-area face: no plane (GH97 §5 needs a unit normal)
  n = n * (1.0 / len);
  const double d = -dot(n, m.pos[t[0]]);
  switch (weighting) {
    case Weighting::Area: return Quadric::plane(n, d, len / 2);  // HG99 §2
    case Weighting::Uniform: return Quadric::plane(n, d, 1);     // GH97 §5
    case Weighting::Angle: break;
  }
  const Vec3 e1 = m.pos[t[(k + 1) % 3]] - m.pos[t[k]], e2 = m.pos[t[(k + 2) % 3]] - m.pos[t[k]];
  return Quadric::plane(n, d, std::atan2(length(cross(e1, e2)), dot(e1, e2)));
}

}  // namespace

void face_quadrics(const WorkingMesh& m, Weighting weighting, unsigned threads, std::vector<Quadric>& quadric) {
  quadric.resize(m.pos.size());
  // Per vertex over its face list (in face order), so every sum is made in the same order for
  // any thread count; each face's plane is computed at each of its corners.
  for_chunks(m.pos.size(), std::size_t(1) << 13, threads, [&](std::size_t, std::size_t begin, std::size_t end) {
    for (std::size_t v = begin; v < end; ++v) {
      Quadric q{};
      for (std::uint32_t f : m.vertex_faces[v]) {
        if (!m.face_alive[f]) continue;  // the greedy order's lists keep dead faces
        const std::uint32_t* t = m.face(f);
        q += plane_of_face(m, f, t[0] == v ? 0 : t[1] == v ? 1 : 2, weighting);
      }
      quadric[v] = q;
    }
  });
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

void add_constraint_planes(WorkingMesh& m, const std::vector<Edge>& edges, const Settings& s, bool seams,
                           std::vector<Quadric>& quadric) {
  add_boundary_planes(m, edges, s.boundary_weight, s.weighting, quadric);  // GH97 §6
  if (seams) add_seam_planes(m, edges, s.seam_weight, s.weighting, quadric);
}

}  // namespace qem::core
