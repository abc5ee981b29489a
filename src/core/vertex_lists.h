// Per-vertex lists (incident faces, valid pairs) in one flat arena, so the contraction loop never
// allocates per element. The lists are built in one go (rebuild: a counting sort); a list that
// later outgrows its slot moves to the end of the arena with room to grow, the old slot is
// abandoned, and when the arena is full the lists are slid together again.
#pragma once

#include <cstdint>
#include <cstring>
#include <memory>
#include <span>
#include <stdexcept>
#include <utility>
#include <vector>

#include "core/default_init_allocator.h"
#include "core/radix_sort.h"

namespace qem::core {

class VertexLists {
 public:
  /// Builds every list anew, in place: for_each_item(emit) must call emit(v, item) for every item
  /// of every list, the same way both times it is called (once to count, once to fill). Each
  /// list gets the items in the order emitted. The arena's memory is reused, so a rebuild of
  /// fewer items touches no fresh page; the first build reserves a quarter more for lists that
  /// grow later (assign).
  template <class ForEachItem>
  void rebuild(std::size_t vertex_count, ForEachItem for_each_item) {
    size_.assign(vertex_count, 0);
    for_each_item([&](std::uint32_t v, std::uint32_t) { ++size_[v]; });
    begin_.resize(vertex_count);
    capacity_.resize(vertex_count);
    std::size_t total = 0;
    for (std::size_t v = 0; v < vertex_count; ++v) {
      begin_[v] = std::uint32_t(total);
      capacity_[v] = size_[v];
      total += size_[v];
      size_[v] = 0;
    }
    if (total + total / 4 + 64 >= 0xffffffffu) throw std::length_error("vertex lists beyond 32-bit offsets");
    if (data_.capacity() < total) data_.reserve(total + total / 4 + 64);
    data_.resize(total);
    for_each_item([&](std::uint32_t v, std::uint32_t item) { data_[begin_[v] + size_[v]++] = item; });
  }

  std::span<const std::uint32_t> operator[](std::uint32_t v) const { return {data_.data() + begin_[v], size_[v]}; }
  /// Hints the cache that the list of v is about to be read: its slot, or (once the slot is
  /// cached) its items. Always inlined: out of line, GCC 12 at -O3 dropped the prefetches of the
  /// simplifier's passes, apparently treating these helpers, which hold nothing else, as free of
  /// side effects; the output stays the same, so only the time shows it. tests/prefetch_test.sh
  /// counts the instructions (docs/benchmarks.md, "Measurements behind the code").
  [[gnu::always_inline]] void prefetch_slot(std::uint32_t v) const {
    __builtin_prefetch(&begin_[v]);
    __builtin_prefetch(&size_[v]);
  }
  [[gnu::always_inline]] void prefetch_items(std::uint32_t v) const {
    __builtin_prefetch(data_.data() + begin_[v]);
  }

  /// Replaces the list of v by items[0..n), which must not point into this arena. If it does not
  /// fit, it takes the slot of `donor` (a list being emptied, e.g. the contracted vertex) if that
  /// is large enough, and only otherwise moves to the end of the arena.
  void assign(std::uint32_t v, const std::uint32_t* items, std::size_t n, std::uint32_t donor) {
    if (n > capacity_[v] && n <= capacity_[donor]) {
      std::swap(begin_[v], begin_[donor]);
      std::swap(capacity_[v], capacity_[donor]);
      size_[donor] = 0;
    }
    assign(v, items, n);
  }
  /// The same without a donor. A list that moves gets half as much room again to grow; when the
  /// arena is full the lists are slid together first, so its memory stays at its first size.
  void assign(std::uint32_t v, const std::uint32_t* items, std::size_t n) {
    if (n > capacity_[v]) {
      const std::size_t room = n + n / 2 + 2;
      if (data_.size() + room > data_.capacity()) compact();
      if (data_.size() + room >= 0xffffffffu) throw std::length_error("vertex lists beyond 32-bit offsets");
      begin_[v] = std::uint32_t(data_.size());
      data_.resize(data_.size() + room);
      capacity_[v] = std::uint32_t(room);
    }
    std::uint32_t* dst = data_.data() + begin_[v];
    for (std::size_t i = 0; i < n; ++i) dst[i] = items[i];
    size_[v] = std::uint32_t(n);
  }
  void clear(std::uint32_t v) { size_[v] = 0; }

  /// Moves every list down to close the gaps left by abandoned slots, in place, in arena order;
  /// each keeps exactly its size as capacity.
  void compact() {
    std::vector<std::uint32_t> by_begin(begin_.size()), scratch;
    for (std::uint32_t v = 0; v < by_begin.size(); ++v) by_begin[v] = v;
    radix_sort_by_key(by_begin, scratch, [&](std::uint32_t v) { return begin_[v]; });
    std::uint32_t end = 0;
    for (std::uint32_t v : by_begin) {
      // begin_[v] >= end: the lists are visited in arena order, so the move only goes down.
      std::memmove(data_.data() + end, data_.data() + begin_[v], size_[v] * sizeof(std::uint32_t));
      begin_[v] = end;
      capacity_[v] = size_[v];
      end += size_[v];
    }
    data_.resize(end);
  }

 private:
  std::vector<std::uint32_t, DefaultInitAllocator<std::uint32_t>> data_;
  std::vector<std::uint32_t> begin_;
  std::vector<std::uint32_t> size_;
  std::vector<std::uint32_t> capacity_;
};

}  // namespace qem::core
