#include "core/fundamental_quadrics.h"

#include <cmath>

#include "core/parallel_chunks.h"
#include "core/seam_planes.h"

namespace qem::core {

namespace {

// A face's unit normal n, offset d (n.x + d = 0 on the plane) and twice its area (0: no plane).
struct FacePlane {
  Vec3 n;
  double d = 0, twice_area = 0;
};

FacePlane plane_of_face(const WorkingMesh& m, std::uint32_t f) {
  const std::uint32_t* t = m.face(f);
  Vec3 n = cross(m.pos[t[1]] - m.pos[t[0]], m.pos[t[2]] - m.pos[t[0]]);
  const double len = length(n);
  if (!(len > 0)) return {};  // zero-area face: no plane (GH97 §5 needs a unit normal)
  n = n * (1.0 / len);
  return {n, -dot(n, m.pos[t[0]]), len};
}

// The plane's quadric as face f's corner k adds it (only angle weighting depends on the corner).
Quadric corner_quadric(const WorkingMesh& m, std::uint32_t f, int k, const FacePlane& p,
                       Weighting weighting) {
  if (!(p.twice_area > 0)) return Quadric{};
  switch (weighting) {
    case Weighting::Area:
      return Quadric::plane(p.n, p.d, p.twice_area / 2);  // HG99 §2
    case Weighting::Uniform:
      return Quadric::plane(p.n, p.d, 1);  // GH97 §5
    case Weighting::Angle: break;
  }
  const std::uint32_t* t = m.face(f);
  const Vec3 e1 = m.pos[t[(k + 1) % 3]] - m.pos[t[k]], e2 = m.pos[t[(k + 2) % 3]] - m.pos[t[k]];
  return Quadric::plane(p.n, p.d, std::atan2(length(cross(e1, e2)), dot(e1, e2)));
}

}  // namespace

void face_quadrics(const WorkingMesh& m, Weighting weighting, unsigned threads, std::vector<Quadric>& quadric) {
  quadric.resize(m.pos.size());
  // Face by face, each plane made once and added to its corners: every vertex's sum runs over its
  // faces in face order. Whatever the threads: a thread owns a range of vertices and reads every
  // face, but makes and adds only the faces with a corner in its range, so every sum is the
  // serial one, bit for bit.
  for_vertex_ranges(m.pos.size(), threads, std::size_t(1) << 13, [&](std::size_t lo, std::size_t hi) {
    std::fill(quadric.begin() + std::ptrdiff_t(lo), quadric.begin() + std::ptrdiff_t(hi), Quadric{});
    const auto in_range = [&](std::uint32_t v) { return v >= lo && v < hi; };
    for (std::uint32_t f = 0; f < m.face_alive.size(); ++f) {
      if (!m.face_alive[f]) continue;
      const std::uint32_t* t = m.face(f);
      if (!in_range(t[0]) && !in_range(t[1]) && !in_range(t[2])) continue;
      const FacePlane plane = plane_of_face(m, f);
      if (weighting != Weighting::Angle) {
        const Quadric q = corner_quadric(m, f, 0, plane, weighting);
        for (int k = 0; k < 3; ++k)
          if (in_range(t[k])) quadric[t[k]] += q;
        continue;
      }
      for (int k = 0; k < 3; ++k)
        if (in_range(t[k])) quadric[t[k]] += corner_quadric(m, f, k, plane, weighting);
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
