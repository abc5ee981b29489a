#include "core/order_greedy.h"

#include <cmath>
#include <limits>

#include "core/contraction.h"
#include "core/forgetting.h"
#include "core/indexed_heap.h"
#include "core/parallel_chunks.h"

namespace qem::core {

namespace {

// The greedy order keeps every vertex list exact at each contraction and re-keys the heap. A key
// may be lower than the pair's current cost: a cost that rises (as it nearly always does after a
// contraction, since quadrics only grow) is not sifted down the heap; the pair is re-keyed when it
// reaches the top. Keys are lower bounds and the popped pair's key is verified current, so the
// order is exactly GH97's at a fraction of the heap work. (Forgetting renews the quadrics: then
// every key is made again.)
struct GreedyLists {
  Context& c;
  IndexedHeap& heap;

  template <class F>
  void for_each_pair_of(std::uint32_t v, F f) const {
    for (std::uint32_t r : c.pairs.vertex_pairs[v]) f(r);
  }
  void pair_removed(std::uint32_t p) { heap.remove(p); }
  void pair_changed(std::uint32_t p) {
    double cost;
    if (!pair_cost(c, p, cost)) {  // never (locked), or not while its neighbourhood stays (blocked)
      refuse(c, p);
      heap.remove(p);
      return;
    }
    c.pairs.pairs[p].state = kCandidate;
    c.pairs.cost[p] = float(cost);
    if (!heap.contains(p) || cost < heap.key_of(p)) heap.update(p, cost);
  }
  void contracted(std::uint32_t a, std::uint32_t b, const std::vector<std::uint32_t>& faces,
                  const std::vector<std::uint32_t>& pairs) {
    c.mesh.vertex_faces.assign(a, faces.data(), faces.size(), b);
    c.mesh.vertex_faces.clear(b);
    c.pairs.vertex_pairs.assign(a, pairs.data(), pairs.size(), b);
    c.pairs.vertex_pairs.clear(b);
  }
};

}  // namespace

void run_greedy(Context& c, const std::vector<std::uint8_t>* stale, double forget_at) {
  PairSet& ps = c.pairs;
  IndexedHeap heap;
  // (A stale pair's pair_cost would give the same key as it has: rounded to float already.)
  const auto fill_heap = [&](const std::vector<std::uint8_t>* stale) {
    const std::uint32_t n = std::uint32_t(ps.pairs.size());
    const auto to_cost = [&](std::uint32_t p) {
      return ps.pairs[p].state == kCandidate && (!stale || (*stale)[p]);
    };
    // The costs on the threads (pair_cost only reads; NaN: refused), as the passes' re-costs are
    // made; then the heap and the refusals in pair order, as one thread would.
    UnzeroedVector<double> cost(n);
    constexpr std::size_t kChunk = std::size_t(1) << 12;
    for_chunks(n, kChunk, c.settings.threads, [&](std::size_t, std::size_t begin, std::size_t end) {
      for (std::uint32_t p = std::uint32_t(begin); p < end; ++p)
        if (to_cost(p) && !pair_cost(c, p, cost[p])) cost[p] = std::numeric_limits<double>::quiet_NaN();
    });
    heap.reset(n);
    if (!stale) ps.cost.assign(n, 0);
    for (std::uint32_t p = 0; p < n; ++p) {
      if (ps.pairs[p].state != kCandidate) continue;
      if (!to_cost(p))
        heap.push_unordered(p, ps.cost[p]);
      else if (!std::isnan(cost[p]))
        heap.push_unordered(p, cost[p]), ps.cost[p] = float(cost[p]);
      else
        refuse(c, p);
    }
    heap.heapify();
  };
  fill_heap(stale);

  GreedyLists lists{c, heap};
  while (!c.done()) {
    if (heap.empty()) {
      c.totals.stop_reason = c.exhausted();
      return;
    }
    if (!c.report_progress()) return;
    if (c.settings.forget_due(c.mesh.faces_alive, forget_at)) {
      // The renewed quadrics are smaller, so every key is made again: exact, not lower bounds.
      c.mesh.rebuild_face_lists();  // live faces only: the border edges are counted from them
      renew_quadrics(c);
      fill_heap(nullptr);
    }
    const std::uint32_t top = heap.top();
    if (ps.cost[top] > heap.top_key()) {  // stale key: re-key and look again
      heap.update(top, ps.cost[top]);
      continue;
    }
    try_contract(c, lists, heap.pop(), c.main);
    c.absorb(c.main);
  }
}

}  // namespace qem::core
