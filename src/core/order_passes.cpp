#include "core/order_passes.h"

#include <algorithm>
#include <limits>

#include "core/cost_model.h"
#include "core/forgetting.h"
#include "core/order_greedy.h"
#include "core/parallel_chunks.h"
#include "core/radix_sort.h"
#include "core/regions.h"
#include "core/renumber.h"

namespace qem::core {

namespace {

// Neither constant depends on the target, so every target sees the same sequence of
// contractions, cut at a different point: a contraction record replays to exactly the mesh a
// direct run to that size gives. Other values were measured and dropped (docs/benchmarks.md).
constexpr double kPassShare = 0.25;      // of the candidates made in one pass, at the most
constexpr double kPassCostSlack = 1.5;   // times the cost at that share, at the most
// Bands of rising cost in which a pass's pairs are made. Fewer are faster (sparser sweeps cost
// cache misses) but worse: where two chosen pairs' checks interact, the cheaper should go first.
constexpr std::size_t kBands = 8;

// The cost of every pair marked dirty, on all threads (each pair is independent, so the result
// does not depend on the thread count). A pair refused a placement is locked or blocked
// (refused_state); the blocked ones' ends are marked afterwards, in one thread (two pairs of one
// vertex may sit in different chunks).
void recost_dirty_pairs(Context& c, PassState& s) {
  PairSet& ps = c.pairs;
  constexpr std::size_t kChunk = std::size_t(1) << 12;  // small meshes' passes on the threads too
  std::vector<std::vector<std::uint32_t>> blocked((ps.pairs.size() + kChunk - 1) / kChunk);
  for_chunks(ps.pairs.size(), kChunk, c.settings.threads, [&](std::size_t chunk, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const std::uint32_t p = std::uint32_t(i);
      if (ps.pairs[p].state != kCandidate || !s.dirty[p]) continue;
      s.dirty[p] = 0;
      double cost;
      if (pair_cost(c, p, cost)) {
        ps.cost[p] = float(cost);
      } else {
        ps.pairs[p].state = refused_state(c, p);
        if (ps.pairs[p].state == kBlocked) blocked[chunk].push_back(p);
      }
    }
  });
  for (const std::vector<std::uint32_t>& list : blocked)
    for (std::uint32_t p : list) ps.block(p);
}

// This pass's contractions: the candidates sorted by cost (a radix sort), then, cheapest first,
// those whose two ends have not yet been chosen this pass, up to a share of the candidates and a
// slack over the cost at that share (the rule of meshoptimizer). No two chosen pairs share a
// vertex, so each one's cost is still exact when it is made, as in the greedy order.
void choose_pairs(Context& c, PassState& s, std::uint32_t pass, std::vector<std::uint32_t>& order,
                  std::vector<std::uint32_t>& scratch, std::vector<std::uint32_t>& selected) {
  const PairSet& ps = c.pairs;
  order.clear();
  order.reserve(ps.pairs.size());
  for (std::uint32_t p = 0; p < ps.pairs.size(); ++p)
    if (ps.pairs[p].state == kCandidate) order.push_back(p);
  selected.clear();
  if (order.empty()) return;
  radix_sort_by_float_key(order, scratch, [&](std::uint32_t p) { return ps.cost[p]; });
  const std::size_t share = std::max<std::size_t>(1, std::size_t(double(order.size()) * kPassShare));
  const double cost_goal =
      share < order.size() ? kPassCostSlack * ps.cost[order[share]] : std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < order.size(); ++i) {
    const std::uint32_t p = order[i];
    if (i + 16 < order.size()) __builtin_prefetch(&ps.pairs[order[i + 16]]);  // cost order: scattered
    if (selected.size() >= share) break;
    if (ps.cost[p] > cost_goal && selected.size() > share / 10) break;
    const std::uint32_t a = ps.pairs[p].v[0], b = ps.pairs[p].v[1];
    if (s.touched_in_pass[a] == pass || s.touched_in_pass[b] == pass) continue;
    s.touched_in_pass[a] = s.touched_in_pass[b] = pass;
    selected.push_back(p);
  }
}

}  // namespace

bool ready_to_contract(const Context& c, PassState& s, std::uint32_t p) {
  if (c.pairs.pairs[p].state != kCandidate) return false;
  if (c.settings.inversion == InversionPolicy::Penalize) {
    double cost;
    if (!pair_cost(c, p, cost) || float(cost) != c.pairs.cost[p]) {
      s.dirty[p] = 1;
      return false;
    }
  }
  return true;
}

// Each pass re-costs the pairs whose ends changed, chooses its pairs (choose_pairs) and makes them
// in bands of rising cost, each band in memory order (pair ids follow the Morton order of their
// ends), so the contractions walk the mesh's arrays instead of jumping across them in cost order,
// and a run that reaches its target during a pass has made the cheapest of the pass's
// contractions, spread over the whole mesh. Each band is made region by region on all threads
// (regions.h).
void run_passes(Context& c, const std::function<void(const Context&, const PassState&)>& after_band) {
  PassState s;
  s.dirty.assign(c.pairs.pairs.size(), 1);
  s.touched_in_pass.assign(c.mesh.vertex_count(), 0);
  Regions regions;
  std::vector<std::uint32_t> order, scratch, selected;
  s.forget_at = c.settings.first_forget_at(c.mesh.faces_alive);
  for (std::uint32_t pass = 1; !c.done(); ++pass) {
    if (pass > 1) {
      // The lists as the last pass left them (see merged_from), rebuilt with live items only,
      // which also keeps each contraction's loops (and cache misses) to the live neighbourhood.
      if (2 * c.mesh.vertices_alive < c.mesh.vertex_count()) renumber_densely(c, s);
      side_by_side(c.settings.threads, [&] { c.pairs.rebuild_lists(c.mesh.vertex_count()); },
                   [&] { c.mesh.rebuild_face_lists(); });
    }
    s.merged_from.assign(c.mesh.vertex_count(), kNoVertex);
    if (c.settings.forget_due(c.mesh.faces_alive, s.forget_at)) {  // the lists were just rebuilt
      renew_quadrics(c);
      s.dirty.assign(c.pairs.pairs.size(), 1);
    }
    if (c.mesh.faces_alive <= c.settings.greedy_below_faces) {
      // The lists were just rebuilt: exact, as the greedy order needs them. A candidate not marked
      // dirty was costed after its ends last changed, and its cost depends on nothing else (the
      // two quadrics, positions and lock flags) unless inversions are penalised (its neighbours)
      // or it carries wedges (the seams around it): then every cost is computed afresh.
      const bool reuse = c.settings.inversion != InversionPolicy::Penalize && !c.wedges;
      run_greedy(c, reuse ? &s.dirty : nullptr, s.forget_at);
      if (after_band) after_band(c, PassState{});
      return;
    }
    recost_dirty_pairs(c, s);
    choose_pairs(c, s, pass, order, scratch, selected);
    if (selected.empty()) {
      c.totals.stop_reason = c.exhausted();
      return;
    }
    const std::size_t n = selected.size();
    for (std::size_t band = 0; band < kBands; ++band)
      std::sort(selected.begin() + n * band / kBands, selected.begin() + n * (band + 1) / kBands);
    PassLists lists{c, s};
    regions.find_cut(c, lists);
    for (std::size_t band = 0; band < kBands && !c.done(); ++band) {
      const std::size_t begin = n * band / kBands, end = n * (band + 1) / kBands;
      if (!regions.make_band(c, lists, selected.data() + begin, end - begin)) return;
      if (after_band) after_band(c, s);
    }
  }
}

}  // namespace qem::core
