#include "core/order_greedy.h"

#include "core/contraction.h"
#include "core/forgetting.h"
#include "core/indexed_heap.h"

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
  const auto fill_heap = [&](const std::vector<std::uint8_t>* stale) {
    heap.reset(ps.pairs.size());
    if (!stale) ps.cost.assign(ps.pairs.size(), 0);
    for (std::uint32_t p = 0; p < ps.pairs.size(); ++p) {
      if (ps.pairs[p].state != kCandidate) continue;
      if (stale && !(*stale)[p]) {  // pair_cost would give the same key (rounded to float already)
        heap.push_unordered(p, ps.cost[p]);
        continue;
      }
      double cost;
      if (pair_cost(c, p, cost)) heap.push_unordered(p, cost), ps.cost[p] = float(cost);
      else refuse(c, p);
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
