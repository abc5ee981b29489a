// Exact vertex welding: vertices with bit-identical coordinates (after folding -0 onto +0) become
// one vertex. Open addressing on the coordinate bits, one pass, deterministic: each position keeps
// the index of its first occurrence, in first-occurrence order.
#pragma once

#include <bit>
#include <cstdint>
#include <vector>

namespace qem::io {

class VertexWelder {
 public:
  /// Appends unique positions to `positions` (3 per vertex); `expected` sizes the first table.
  VertexWelder(std::vector<double>& positions, std::size_t expected) : pos_(positions) {
    std::size_t cap = 64;
    while (cap < 2 * expected) cap <<= 1;
    table_.assign(cap, kEmpty);
  }

  /// The index of (x, y, z), adding it if it is new.
  std::uint32_t add(double x, double y, double z) {
    const std::uint64_t bx = bits(x), by = bits(y), bz = bits(z);
    std::size_t mask = table_.size() - 1;
    std::size_t slot = hash(bx, by, bz) & mask;
    for (;;) {
      std::uint32_t rep = table_[slot];
      if (rep == kEmpty) break;
      const double* q = &pos_[3 * std::size_t{rep}];
      if (bits(q[0]) == bx && bits(q[1]) == by && bits(q[2]) == bz) return rep;
      slot = (slot + 1) & mask;
    }
    const auto index = static_cast<std::uint32_t>(pos_.size() / 3);
    pos_.push_back(x);
    pos_.push_back(y);
    pos_.push_back(z);
    table_[slot] = index;
    if (2 * (std::size_t{index} + 1) > table_.size()) grow();  // keep the load factor <= 1/2
    return index;
  }
  std::size_t size() const { return pos_.size() / 3; }
  /// Starts loading the table slot of (x, y, z): the lookups are random accesses into a table
  /// larger than the caches, so readers prefetch a few vertices ahead of add(). Always inlined,
  /// or GCC drops the prefetch (see core::VertexLists::prefetch_slot).
  [[gnu::always_inline]] void prefetch(double x, double y, double z) const {
    __builtin_prefetch(&table_[hash(bits(x), bits(y), bits(z)) & (table_.size() - 1)]);
  }

 private:
  static constexpr std::uint32_t kEmpty = 0xFFFFFFFFu;
  static std::uint64_t bits(double v) { return std::bit_cast<std::uint64_t>(v == 0.0 ? 0.0 : v); }
  static std::uint64_t hash(std::uint64_t x, std::uint64_t y, std::uint64_t z) {
    std::uint64_t h = x * 0x9E3779B97F4A7C15ull;
    h = (h ^ (h >> 32) ^ y) * 0xC2B2AE3D27D4EB4Full;
    h = (h ^ (h >> 32) ^ z) * 0x165667B19E3779F9ull;
    return h ^ (h >> 29);
  }
  void grow() {
    std::vector<std::uint32_t> old;
    old.swap(table_);
    table_.assign(old.size() * 2, kEmpty);
    const std::size_t mask = table_.size() - 1;
    for (std::uint32_t rep : old) {
      if (rep == kEmpty) continue;
      const double* q = &pos_[3 * std::size_t{rep}];
      std::size_t slot = hash(bits(q[0]), bits(q[1]), bits(q[2])) & mask;
      while (table_[slot] != kEmpty) slot = (slot + 1) & mask;
      table_[slot] = rep;
    }
  }

  std::vector<double>& pos_;
  std::vector<std::uint32_t> table_;
};

}  // namespace qem::io
