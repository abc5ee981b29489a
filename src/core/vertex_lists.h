// Per-vertex lists (incident faces, valid pairs) in one flat arena, so the contraction loop never
// allocates per element. A list that outgrows its slot moves to the end of the arena with room to
// grow; the old slot is abandoned, and when the arena is full the lists are slid together again.
#pragma once

#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <vector>

#include "core/radix_sort.h"

namespace qem::core {

class VertexLists {
 public:
  /// Lays out one list per vertex with the given sizes (CSR); fill with push_initial.
  void layout(const std::vector<std::uint32_t>& sizes) {
    std::size_t n = sizes.size();
    begin_.resize(n);
    size_.assign(n, 0);
    capacity_.resize(n);
    std::size_t total = 0;
    for (std::size_t v = 0; v < n; ++v) {
      begin_[v] = std::uint32_t(total);
      capacity_[v] = sizes[v];
      total += sizes[v];
    }
    if (total + total / 4 + 64 >= 0xffffffffu) throw std::length_error("vertex lists beyond 32-bit offsets");
    data_.reserve(total + total / 4 + 64);
    data_.assign(total, 0);
  }
  void push_initial(std::uint32_t v, std::uint32_t item) { data_[begin_[v] + size_[v]++] = item; }

  std::span<const std::uint32_t> operator[](std::uint32_t v) const { return {data_.data() + begin_[v], size_[v]}; }
  /// Hints the cache that the list of v is about to be read: its slot, or (once the slot is
  /// cached) its items.
  void prefetch_slot(std::uint32_t v) const {
    __builtin_prefetch(&begin_[v]);
    __builtin_prefetch(&size_[v]);
  }
  void prefetch_items(std::uint32_t v) const { __builtin_prefetch(data_.data() + begin_[v]); }

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
  void assign(std::uint32_t v, const std::uint32_t* items, std::size_t n) {
    if (n > capacity_[v]) {
      const std::uint32_t room = std::uint32_t(n + n / 2 + 2);
      // The arena is full of abandoned slots: slide the lists together rather than grow it,
      // so its memory stays at its first size for the whole run.
      if (data_.size() + room > data_.capacity()) compact();
      if (data_.size() + room >= 0xffffffffu) throw std::length_error("vertex lists beyond 32-bit offsets");
      begin_[v] = std::uint32_t(data_.size());
      capacity_[v] = room;
      data_.resize(data_.size() + room);
    }
    std::uint32_t* dst = data_.data() + begin_[v];
    for (std::size_t i = 0; i < n; ++i) dst[i] = items[i];
    size_[v] = std::uint32_t(n);
  }
  void clear(std::uint32_t v) { size_[v] = 0; }

  /// Drops, from every list, the items for which keep(item) is false (order kept).
  template <class Keep>
  void filter(Keep keep) {
    for (std::size_t v = 0; v < begin_.size(); ++v) {
      std::uint32_t* items = data_.data() + begin_[v];
      std::uint32_t kept = 0;
      for (std::uint32_t i = 0; i < size_[v]; ++i)
        if (keep(items[i])) items[kept++] = items[i];
      size_[v] = kept;
    }
  }

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
  std::vector<std::uint32_t> data_;
  std::vector<std::uint32_t> begin_;
  std::vector<std::uint32_t> size_;
  std::vector<std::uint32_t> capacity_;
};

}  // namespace qem::core
