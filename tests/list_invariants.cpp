#include "list_invariants.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

namespace qem::test {

using namespace core;

void check_vertex_lists(const Context& c, const PassState& s) {
  const WorkingMesh& m = c.mesh;
  const PairSet& ps = c.pairs;
  const std::size_t n = m.vertex_count();
  std::vector<std::vector<std::uint32_t>> faces(n), pairs(n);
  for (std::uint32_t f = 0; f < m.face_alive.size(); ++f)
    if (m.face_alive[f])
      for (int k = 0; k < 3; ++k) faces[m.tri[3 * std::size_t(f) + k]].push_back(f);
  for (std::uint32_t p = 0; p < ps.pairs.size(); ++p)
    if (ps.pairs[p].state != kDead) pairs[ps.pairs[p].v[0]].push_back(p), pairs[ps.pairs[p].v[1]].push_back(p);
  const bool in_pass = !s.merged_from.empty();
  std::vector<std::uint8_t> removed(n, 0), survivor(n, 0);
  if (in_pass)
    for (std::uint32_t v = 0; v < n; ++v)
      if (s.merged_from[v] != kNoVertex) survivor[v] = 1, removed[s.merged_from[v]] = 1;
  auto sorted = [](std::vector<std::uint32_t> items) {
    std::sort(items.begin(), items.end());
    return items;
  };
  for (std::uint32_t v = 0; v < n; ++v) {
    if (removed[v]) continue;
    std::vector<std::uint32_t> read;
    auto add = [&](std::uint32_t p) {
      if (ps.pairs[p].state != kDead) read.push_back(p);
    };
    for (std::uint32_t p : ps.vertex_pairs[v]) add(p);
    if (in_pass && s.merged_from[v] != kNoVertex)
      for (std::uint32_t p : ps.vertex_pairs[s.merged_from[v]]) add(p);
    if (sorted(read) != pairs[v]) throw std::logic_error("pair list out of step at vertex " + std::to_string(v));
    if (survivor[v]) continue;
    read.clear();
    for (std::uint32_t f : m.vertex_faces[v])
      if (m.face_alive[f]) read.push_back(f);
    if (sorted(read) != faces[v]) throw std::logic_error("face list out of step at vertex " + std::to_string(v));
  }
}

}  // namespace qem::test
