#include "core/seam_planes.h"

#include <cmath>

namespace qem::core {

namespace {

// The wedge at vertex v in face f.
std::uint32_t wedge_at(const WorkingMesh& m, std::uint32_t f, std::uint32_t v) {
  const std::uint32_t* t = m.face(f);
  for (int k = 0; k < 3; ++k)
    if (t[k] == v) return m.corner_wedge[3 * std::size_t(f) + k];
  return kNoVertex;
}

}  // namespace

void add_seam_planes(const WorkingMesh& m, const std::vector<Edge>& edges, double weight, Weighting weighting,
                     std::vector<Quadric>& quadric) {
  if (!(weight > 0) || m.corner_wedge.empty()) return;
  for (const Edge& e : edges) {
    if (e.faces != 2) continue;
    std::uint32_t face[2], found = 0;
    for (std::uint32_t f : m.vertex_faces[e.lo])
      if (found < 2 && m.face_has(f, e.hi)) face[found++] = f;
    if (found != 2) continue;
    if (wedge_at(m, face[0], e.lo) == wedge_at(m, face[1], e.lo) && wedge_at(m, face[0], e.hi) == wedge_at(m, face[1], e.hi))
      continue;  // the same wedges on both sides: not a seam
    const Vec3 edge = m.pos[e.hi] - m.pos[e.lo];
    const double w = weight * (weighting == Weighting::Area ? dot(edge, edge) : 1.0);
    for (std::uint32_t f : face) {
      const std::uint32_t* t = m.face(f);
      Vec3 normal = cross(edge, cross(m.pos[t[1]] - m.pos[t[0]], m.pos[t[2]] - m.pos[t[0]]));
      const double len = length(normal);
      if (!(len > 0)) continue;
      normal = normal * (1.0 / len);
      Quadric q = Quadric::plane(normal, -dot(normal, m.pos[e.lo]), w / 2);  // two planes: half each
      q.weight = 0;  // a constraint, not surface (as the boundary planes)
      quadric[e.lo] += q;
      quadric[e.hi] += q;
    }
  }
}

}  // namespace qem::core
