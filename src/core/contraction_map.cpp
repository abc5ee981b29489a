#include "core/contraction_map.h"

namespace qem::core {

void ContractionMap::renumber(const std::vector<std::uint32_t>& to, std::size_t vertex_count) {
  for (std::uint32_t& home : home_) {
    if (home == kNoVertex) continue;
    std::uint32_t v = home;
    while (absorbed_into_[v] != kNoVertex) {
      const std::uint32_t next = absorbed_into_[v];
      if (absorbed_into_[next] != kNoVertex) absorbed_into_[v] = absorbed_into_[next];
      v = next;
    }
    home = to[v];
  }
  absorbed_into_.assign(vertex_count, kNoVertex);
}

}  // namespace qem::core
