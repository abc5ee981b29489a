// Whether one contraction is legal: the link condition (the surface's topology) and GH97 §6's
// inversion check. Inline: both run for every contraction tried, inside its loop.
#pragma once

#include <cstdint>
#include <vector>

#include "core/working_mesh.h"

namespace qem::core {

/// GH97 §6 "preventing mesh inversion": a face around a or b (that survives the contraction) whose
/// normal turns by more than the limit (cos_max_turn), or that would lose its area, forbids the
/// contraction; so does one that would face away (more than 90 degrees) from the input face it
/// descends from, which the per-contraction limit alone lets happen over several contractions.
inline bool flips(const WorkingMesh& m, std::uint32_t a, std::uint32_t b, const Vec3& target, double cos_max_turn) {
  for (std::uint32_t end = 0; end < 2; ++end) {
    const std::uint32_t v = end == 0 ? a : b, other = end == 0 ? b : a;
    for (std::uint32_t f : m.vertex_faces[v]) {
      if (!m.face_alive[f] || m.face_has(f, other)) continue;
      const std::uint32_t* t = m.face(f);
      const Vec3 before = m.face_normal(t, v, m.pos[v]);
      const Vec3 after = m.face_normal(t, v, target);
      const double lb = dot(before, before), la = dot(after, after);
      if (!(lb > 0)) continue;  // a face that was already flat cannot flip
      if (!(la > 1e-24 * lb)) return true;
      const double d = dot(before, after);
      if (d <= 0 || d * d < cos_max_turn * cos_max_turn * la * lb) return true;
      // Against its input face too: turns within the limit add up, contraction after
      // contraction, until a face has folded over (a height field's face tilted past vertical).
      if (!m.input_normal[f].none() && !(dot(after, m.input_normal[f].unpack()) > 0)) return true;
    }
  }
  return false;
}

/// Whether (a, b) is an edge, and if so whether collapsing it keeps the surface's topology (the
/// link condition of Dey et al.; the check GH97 leaves to the implementer): the vertices adjacent
/// to both a and b must be exactly the opposite corners of the faces on edge ab, the collapse must
/// not stack two faces onto the same three vertices, and an interior edge whose two ends both lie
/// on a border must not pinch the border. Skipped (true) at aggregation joints and when the
/// topology need not be kept. `marks` are per-vertex stamps; two fresh ones are taken from `stamp`.
/// `closes`: the third vertex of a hole down to three vertices that this contraction closes
/// (border_placement.h, hole_closed_by), the one common neighbour allowed; kNoVertex otherwise.
inline bool link_condition_ok(const WorkingMesh& m, std::uint32_t a, std::uint32_t b, bool preserve_topology,
                              bool& is_edge, std::vector<std::uint32_t>& marks, std::uint32_t& stamp,
                              std::uint32_t closes = kNoVertex) {
  const std::uint32_t s_nbr = ++stamp, s_opp = ++stamp;
  std::size_t shared = 0;
  for (std::uint32_t f : m.vertex_faces[a]) {
    if (!m.face_alive[f]) continue;
    const std::uint32_t* t = m.face(f);
    if (m.face_has(f, b)) {
      ++shared;
      for (int k = 0; k < 3; ++k)
        if (t[k] != a && t[k] != b) marks[t[k]] = s_opp;
    } else {
      for (int k = 0; k < 3; ++k)
        if (t[k] != a && marks[t[k]] != s_opp) marks[t[k]] = s_nbr;
    }
  }
  is_edge = shared > 0;
  if (!is_edge || !preserve_topology || m.aggregated[a] || m.aggregated[b]) return true;
  if (shared == 2 && m.boundary[a] && m.boundary[b]) return false;  // would pinch the border
  // Neighbours of b that are also neighbours of a but not opposite corners break the link condition.
  for (std::uint32_t f : m.vertex_faces[b]) {
    if (!m.face_alive[f] || m.face_has(f, a)) continue;
    const std::uint32_t* t = m.face(f);
    int opp_corners = 0;
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t x = t[k];
      if (x == b) continue;
      if (marks[x] == s_nbr && x != closes) return false;
      if (marks[x] == s_opp) ++opp_corners;
    }
    // Closing a hole: b's face (b, closes, x) becomes (a, closes, x); a must not have that face
    // already (a hole whose three faces meet at one apex would fold onto itself).
    if (closes != kNoVertex && m.face_has(f, closes)) {
      const std::uint32_t x = t[0] != b && t[0] != closes ? t[0] : t[1] != b && t[1] != closes ? t[1] : t[2];
      for (std::uint32_t g : m.vertex_faces[a])
        if (m.face_alive[g] && m.face_has(g, closes) && m.face_has(g, x)) return false;
    }
    // A face (b, x, y) with x, y both opposite corners: if a also has a face (a, x, y), the
    // collapse would stack two faces on the same vertices (the tetrahedron case).
    if (opp_corners == 2) {
      const std::uint32_t x = t[0] == b ? t[1] : t[0], y = t[2] == b ? t[1] : t[2];
      for (std::uint32_t g : m.vertex_faces[a])
        if (m.face_alive[g] && m.face_has(g, x) && m.face_has(g, y)) return false;
    }
  }
  return true;
}

}  // namespace qem::core
