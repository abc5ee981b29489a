// The contractions of a pass are known in advance, so the memory they will touch is requested a
// few contractions ahead, in stages (a pair's ends must be in cache before their data can be
// located): the loop then waits far less on memory (docs/benchmarks.md, "Prefetches that run").
// Always inlined, or GCC drops them (see VertexLists::prefetch_slot); tests/prefetch_test.sh
// checks that they reach the object that makes the bands (regions.cpp).
#pragma once

#include <cstddef>
#include <cstdint>

#include "core/context.h"

namespace qem::core {

[[gnu::always_inline]] inline void prefetch_for_contraction(const Context& c, const std::uint32_t* pairs,
                                                            std::size_t count, std::size_t i) {
  constexpr std::size_t kRecord = 12, kSlots = 8, kItems = 4, kNeighbours = 2;
  const std::vector<PairRecord>& records = c.pairs.pairs;
  const WorkingMesh& m = c.mesh;
  if (i + kRecord < count) __builtin_prefetch(&records[pairs[i + kRecord]]);
  if (i + kSlots < count) {
    for (std::uint32_t v : records[pairs[i + kSlots]].v) {
      m.vertex_faces.prefetch_slot(v);
      c.pairs.vertex_pairs.prefetch_slot(v);
      __builtin_prefetch(&m.pos[v]);
      __builtin_prefetch(&c.quadric[v]);
      __builtin_prefetch(reinterpret_cast<const char*>(&c.quadric[v]) + 64);
    }
  }
  if (i + kItems < count) {
    for (std::uint32_t v : records[pairs[i + kItems]].v) {
      m.vertex_faces.prefetch_items(v);
      c.pairs.vertex_pairs.prefetch_items(v);
    }
  }
  // Last, the records the checks and contract() read through those lists: the pairs and faces
  // around both ends.
  if (i + kNeighbours < count) {
    for (std::uint32_t v : records[pairs[i + kNeighbours]].v) {
      for (std::uint32_t r : c.pairs.vertex_pairs[v]) __builtin_prefetch(&records[r]);
      for (std::uint32_t f : m.vertex_faces[v]) {
        __builtin_prefetch(&m.face_alive[f]);
        __builtin_prefetch(&m.tri[3 * std::size_t(f)]);
      }
    }
  }
}

}  // namespace qem::core
