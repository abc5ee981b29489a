#include "core/pair_set.h"

#include "qem/error.h"

namespace qem::core {

void PairSet::rebuild_lists(std::size_t vertex_count) {
  vertex_pairs.rebuild(vertex_count, [&](auto emit) {
    for (std::uint32_t p = 0; p < pairs.size(); ++p)
      if (pairs[p].state != kDead) emit(pairs[p].v[0], p), emit(pairs[p].v[1], p);
  });
}

PairSet select_pairs(const WorkingMesh& mesh, std::vector<Edge> edges, double threshold) {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> virtual_pairs;
  if (threshold > 0) {
    std::vector<std::uint32_t> candidates;
    for (std::uint32_t v = 0; v < mesh.pos.size(); ++v) candidates.push_back(v);
    virtual_pairs = close_pairs(mesh.pos, candidates, threshold, edges, kMaxThresholdPairsPerVertex);
  }
  PairSet set;
  set.virtual_count = virtual_pairs.size();
  const std::size_t np = edges.size() + virtual_pairs.size();
  if (np >= 0xffffffffu) throw Error("too many pairs for 32-bit pair ids");
  set.pairs.resize(np);
  for (std::size_t i = 0; i < edges.size(); ++i) set.pairs[i] = {{edges[i].lo, edges[i].hi}, kCandidate, 0};
  for (std::size_t i = 0; i < virtual_pairs.size(); ++i)
    set.pairs[edges.size() + i] = {{virtual_pairs[i].first, virtual_pairs[i].second}, kCandidate, 1};
  std::vector<Edge>().swap(edges);
  set.cost.assign(np, 0);
  set.has_blocked.assign(mesh.pos.size(), 0);
  set.rebuild_lists(mesh.pos.size());
  return set;
}

}  // namespace qem::core
