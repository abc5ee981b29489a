// The pass-based order of contractions (the scheme of meshoptimizer's simplifier, with GH97's
// costs and checks): rank every candidate, make the cheapest pairs that share no vertex, repeat.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "core/context.h"

namespace qem::core {

/// What a pass keeps besides the context.
struct PassState {
  /// The vertex lists are rebuilt at the start of each pass and not written during it. A
  /// contraction renames its removed end in the faces and pairs themselves, so every list but the
  /// survivor's stays right; the survivor's is its own plus that of the vertex it absorbed,
  /// recorded here (kNoVertex: none), and it is never contracted again in the pass.
  std::vector<std::uint32_t> merged_from;
  /// A pair whose cost must be recomputed before the next ranking.
  std::vector<std::uint8_t> dirty;
  /// The pass in which each vertex was last chosen: each vertex contracts at most once a pass, so
  /// every other cost ranked in the pass stays exact.
  std::vector<std::uint32_t> touched_in_pass;
  /// Forgetting (SimplifyOptions::forget): the quadrics are renewed at the first pass that starts
  /// with at most this many faces.
  double forget_at = 0;
};

/// How a pass sees the lists and costs (see contraction.h).
struct PassLists {
  Context& c;
  PassState& s;

  template <class F>
  void for_each_pair_of(std::uint32_t v, F f) const {
    for (std::uint32_t r : c.pairs.vertex_pairs[v]) f(r);
    if (s.merged_from[v] != kNoVertex)
      for (std::uint32_t r : c.pairs.vertex_pairs[s.merged_from[v]]) f(r);
  }
  void pair_removed(std::uint32_t) {}
  void pair_changed(std::uint32_t p) {  // ranked again at the start of the next pass
    c.pairs.pairs[p].state = kCandidate;
    s.dirty[p] = 1;
  }
  void contracted(std::uint32_t a, std::uint32_t b, const std::vector<std::uint32_t>&,
                  const std::vector<std::uint32_t>&) {
    s.merged_from[a] = b;
  }
};

/// Whether pair p, chosen for this pass, is still to be made. With --inversion penalize its cost
/// depends on the neighbours, which may have moved since it was ranked: then it waits.
bool ready_to_contract(const Context& c, PassState& s, std::uint32_t p);

/// Contracts in passes until the stop criteria are met; below settings.greedy_below_faces it
/// finishes in the greedy order. `after_band` (may be empty) is called after each band.
void run_passes(Context& c, const std::function<void(const Context&, const PassState&)>& after_band);

}  // namespace qem::core
