// Where each input vertex went: the vertex of the current mesh it was contracted into. The refit
// starts its search for an input vertex's closest output face there, and callers with their own
// per-vertex data use it to carry that data across (SimplifyOptions::map_input_vertices).
#pragma once

#include <cstdint>
#include <vector>

#include "core/working_mesh.h"

namespace qem::core {

class ContractionMap {
 public:
  /// Every input vertex at its working vertex (`source_vertex`: the input vertex of each).
  ContractionMap(std::size_t input_vertex_count, const std::vector<std::uint32_t>& source_vertex)
      : home_(input_vertex_count, kNoVertex), absorbed_into_(source_vertex.size(), kNoVertex) {
    for (std::uint32_t v = 0; v < source_vertex.size(); ++v) home_[source_vertex[v]] = v;
  }
  /// Working vertex `removed` was contracted into `kept`.
  void contracted(std::uint32_t kept, std::uint32_t removed) { absorbed_into_[removed] = kept; }
  /// The working vertices were renumbered (or numbered for the output): vertex v is now `to[v]`
  /// (kNoVertex: gone). Each home first follows the contractions made since the last renumbering
  /// (path halving keeps the chains of a greedy run short).
  void renumber(const std::vector<std::uint32_t>& to, std::size_t vertex_count);
  /// Per input vertex, its vertex in the last numbering (kNoVertex: none). Ends the map.
  std::vector<std::uint32_t> take() { return std::move(home_); }

 private:
  std::vector<std::uint32_t> home_, absorbed_into_;
};

}  // namespace qem::core
