// Validity checks the tests apply to every simplifier output.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <string>

#include "qem/mesh.h"

namespace qem::test {

/// Empty if `m` is a valid indexed triangle mesh: finite coordinates, indices in range, no face
/// with a repeated corner, no two faces on the same three vertices but for its last `twin_faces`
/// (SimplifyResult::twin_faces), each the reverse of an earlier face. Otherwise what is wrong.
inline std::string validity_problem(const Mesh& m, std::size_t twin_faces = 0) {
  for (double x : m.positions)
    if (!std::isfinite(x)) return "non-finite coordinate";
  if (m.indices.size() % 3) return "index count not a multiple of 3";
  std::set<std::array<std::uint32_t, 3>> seen;
  for (std::size_t f = 0; f < m.face_count(); ++f) {
    std::array<std::uint32_t, 3> t{m.indices[3 * f], m.indices[3 * f + 1], m.indices[3 * f + 2]};
    for (std::uint32_t i : t)
      if (i >= m.vertex_count()) return "face " + std::to_string(f) + " index out of range";
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2]) return "face " + std::to_string(f) + " is degenerate";
    if (f + twin_faces >= m.face_count()) {  // a twin: the same three points turning the other way
      const auto at = [&](std::uint32_t v) {
        return std::array<double, 3>{m.positions[3 * std::size_t(v)], m.positions[3 * std::size_t(v) + 1],
                                     m.positions[3 * std::size_t(v) + 2]};
      };
      const std::array<std::uint32_t, 3> reversed{t[0], t[2], t[1]};
      bool found = false;
      for (std::size_t g = 0; g + twin_faces < m.face_count() && !found; ++g)
        for (int k = 0; k < 3 && !found; ++k)
          found = at(m.indices[3 * g]) == at(reversed[k]) && at(m.indices[3 * g + 1]) == at(reversed[(k + 1) % 3]) &&
                  at(m.indices[3 * g + 2]) == at(reversed[(k + 2) % 3]);
      if (!found) return "face " + std::to_string(f) + " is a twin of no earlier face";
      continue;
    }
    std::sort(t.begin(), t.end());
    if (!seen.insert(t).second) return "face " + std::to_string(f) + " duplicates an earlier face";
  }
  return {};
}

/// How many faces use each undirected edge.
inline std::map<std::pair<std::uint32_t, std::uint32_t>, int> edge_face_counts(const Mesh& m) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> count;
  for (std::size_t f = 0; f < m.face_count(); ++f)
    for (int k = 0; k < 3; ++k) ++count[std::minmax(m.indices[3 * f + k], m.indices[3 * f + (k + 1) % 3])];
  return count;
}

/// Edges used by more than two faces.
inline std::size_t non_manifold_edges(const Mesh& m) {
  std::size_t n = 0;
  for (auto& [e, c] : edge_face_counts(m)) n += c > 2;
  return n;
}

/// Edges used by exactly one face.
inline std::size_t boundary_edges(const Mesh& m) {
  std::size_t n = 0;
  for (auto& [e, c] : edge_face_counts(m)) n += c == 1;
  return n;
}

}  // namespace qem::test
