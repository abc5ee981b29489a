// Union-find over dense integer ids, for the connectivity counts of mesh_info (components, boundary
// loops, fans around a vertex). Path halving keeps find() near-constant without recursion.
#pragma once

#include <cstdint>
#include <numeric>
#include <vector>

namespace qem::analysis {

class DisjointSets {
 public:
  explicit DisjointSets(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0u); }

  std::uint32_t find(std::uint32_t x) {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];
      x = parent_[x];
    }
    return x;
  }

  /// Joins the sets of a and b; the smaller root survives, so results do not depend on call order
  /// beyond the partition itself.
  void unite(std::uint32_t a, std::uint32_t b) {
    a = find(a), b = find(b);
    if (a == b) return;
    if (a < b)
      parent_[b] = a;
    else
      parent_[a] = b;
  }

 private:
  std::vector<std::uint32_t> parent_;
};

}  // namespace qem::analysis
