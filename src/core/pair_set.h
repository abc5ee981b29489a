// The valid pairs (GH97 §3.2) and what the contraction orders keep about each: its state, its
// current cost, and each vertex's list of pairs.
#pragma once

#include <cstdint>
#include <vector>

#include "core/valid_pairs.h"
#include "core/vertex_lists.h"
#include "core/working_mesh.h"

namespace qem::core {

enum PairState : std::uint8_t {
  kCandidate,  // may be contracted; ranked by its cost
  kBlocked,    // rejected at its last check (topology, inversion, error limit); retried when its
               // neighbourhood changes
  kLocked,     // can never be contracted (both ends held or hard corners: never_contracts)
  kDead,       // contracted, or merged into a duplicate
};

/// One record per valid pair, packed so that a pair costs one cache line visit.
struct PairRecord {
  std::uint32_t v[2];
  std::uint8_t state;
  std::uint8_t is_virtual;  // created by the threshold t (GH97 §3.2 rule 2), not an edge
};

struct PairSet {
  std::vector<PairRecord> pairs;
  /// The current cost of each pair, rounded to float (round_key), so float storage is exact.
  std::vector<float> cost;
  VertexLists vertex_pairs;  ///< each vertex's pairs that are not dead
  /// Set on a vertex when one of its pairs is blocked: its neighbours' changes unblock them.
  std::vector<std::uint8_t> has_blocked;
  std::size_t virtual_count = 0;  ///< pairs found with the threshold t

  std::uint32_t other_end(std::uint32_t p, std::uint32_t v) const {
    return pairs[p].v[0] == v ? pairs[p].v[1] : pairs[p].v[0];
  }
  void block(std::uint32_t p) {
    pairs[p].state = kBlocked;
    has_blocked[pairs[p].v[0]] = has_blocked[pairs[p].v[1]] = 1;
  }
  /// Each vertex's pairs that are not dead, in pair order.
  void rebuild_lists(std::size_t vertex_count);
  /// Renumbering: ends renamed through vertex_to, dead pairs dropped, order kept. also(from, to)
  /// is called for every kept pair so that per-pair arrays of the caller move along in the same
  /// sweep. The lists must be rebuilt after it.
  template <class Also>
  void squeeze(const std::vector<std::uint32_t>& vertex_to, std::size_t vertex_count, Also also) {
    std::size_t next = 0;
    for (std::size_t p = 0; p < pairs.size(); ++p) {
      if (pairs[p].state == kDead) continue;
      PairRecord r = pairs[p];
      r.v[0] = vertex_to[r.v[0]], r.v[1] = vertex_to[r.v[1]];
      pairs[next] = r, cost[next] = cost[p];
      also(p, next);
      ++next;
    }
    pairs.resize(next), cost.resize(next);
    squeeze_by(vertex_to, vertex_count, has_blocked);
  }
};

/// GH97 §3.2: every edge (`edges`, from unique_edges), then the pairs of vertices closer than
/// `threshold` (in the working frame; 0 = edges only) that are not edges.
PairSet select_pairs(const WorkingMesh& mesh, std::vector<Edge> edges, double threshold);

}  // namespace qem::core
