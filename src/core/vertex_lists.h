// Per-vertex lists (incident faces, valid pairs) in one flat arena, so the contraction loop never
// allocates per element. A list that outgrows its slot moves to the end of the arena (or to a
// stretch of it set aside for one thread, see carve) with room to grow; the old slot is abandoned,
// and when the arena is full the lists are slid together again.
#pragma once

#include <cstdint>
#include <cstring>
#include <memory>
#include <span>
#include <stdexcept>
#include <utility>
#include <vector>

#include "core/radix_sort.h"

namespace qem::core {

/// std::allocator whose resize() leaves new elements uninitialised: the arena below grows by
/// stretches that are always written before they are read, and zero-filling them first was a
/// measurable share of each pass.
template <class T>
struct DefaultInitAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = DefaultInitAllocator<U>;
  };
  DefaultInitAllocator() = default;
  template <class U>
  DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}
  template <class U>
  void construct(U* p) noexcept {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

class VertexLists {
 public:
  /// A stretch of the arena set aside for one thread's moved lists, so that threads working on
  /// disjoint vertices can grow lists without touching shared state (see carve).
  struct Tail {
    std::uint32_t next = 0, end = 0;
  };

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
  /// is large enough, and only otherwise moves: to `tail` if given, else to the end of the arena.
  void assign(std::uint32_t v, const std::uint32_t* items, std::size_t n, std::uint32_t donor,
              Tail* tail = nullptr) {
    if (n > capacity_[v] && n <= capacity_[donor]) {
      std::swap(begin_[v], begin_[donor]);
      std::swap(capacity_[v], capacity_[donor]);
      size_[donor] = 0;
    }
    write(v, items, n, tail);
  }
  void assign(std::uint32_t v, const std::uint32_t* items, std::size_t n) { write(v, items, n, nullptr); }
  void clear(std::uint32_t v) { size_[v] = 0; }

  /// The room a list of n items takes when it moves (assign), so callers can size a Tail.
  static std::size_t room_for(std::size_t n) { return n + n / 2 + 2; }
  /// The most room assign(v, ..., donor, tail) can take from a tail for a list built from the
  /// items of v and donor (at most their two sizes together): with the capacities as they are
  /// (`as_now`), or as they will be after compact() (which shrinks every capacity to its size).
  std::size_t growth_bound(std::uint32_t v, std::uint32_t donor, bool as_now) const {
    const std::size_t n = std::size_t(size_[v]) + size_[donor];
    if (!as_now) return n > size_[v] && n > size_[donor] ? room_for(n) : 0;
    return n > capacity_[v] && n > capacity_[donor] ? room_for(n) : 0;
  }
  /// Appends one stretch per entry of `now` to the arena and returns them in `tails`. The sizes
  /// are growth bounds with the capacities as they are (`now`) and as they will be after
  /// compact() (`compacted`): if the first do not fit, the lists are slid together and the
  /// second are used.
  void carve(const std::vector<std::size_t>& now, const std::vector<std::size_t>& compacted,
             std::vector<Tail>& tails) {
    std::size_t total = 0;
    for (std::size_t s : now) total += s;
    const std::vector<std::size_t>* sizes = &now;
    if (data_.size() + total > data_.capacity()) {
      compact();
      sizes = &compacted;
    }
    total = 0;
    for (std::size_t s : *sizes) total += s;
    if (data_.size() + total >= 0xffffffffu) throw std::length_error("vertex lists beyond 32-bit offsets");
    tails.resize(sizes->size());
    for (std::size_t i = 0; i < sizes->size(); ++i) {
      tails[i].next = std::uint32_t(data_.size());
      data_.resize(data_.size() + (*sizes)[i]);
      tails[i].end = std::uint32_t(data_.size());
    }
  }
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
  // The list of v becomes items[0..n); if it does not fit its slot, it moves to new room with
  // space to grow, taken from `tail` (sized by growth_bound: an overrun is a logic error) or from
  // the end of the arena (sliding the lists together first if the arena is full, so its memory
  // stays at its first size for the whole run).
  void write(std::uint32_t v, const std::uint32_t* items, std::size_t n, Tail* tail) {
    if (n > capacity_[v]) {
      const std::uint32_t room = std::uint32_t(room_for(n));
      if (tail) {
        if (tail->end - tail->next < room) throw std::logic_error("vertex list tail too small");
        begin_[v] = tail->next;
        tail->next += room;
      } else {
        if (data_.size() + room > data_.capacity()) compact();
        if (data_.size() + room >= 0xffffffffu) throw std::length_error("vertex lists beyond 32-bit offsets");
        begin_[v] = std::uint32_t(data_.size());
        data_.resize(data_.size() + room);
      }
      capacity_[v] = room;
    }
    std::uint32_t* dst = data_.data() + begin_[v];
    for (std::size_t i = 0; i < n; ++i) dst[i] = items[i];
    size_[v] = std::uint32_t(n);
  }

  std::vector<std::uint32_t, DefaultInitAllocator<std::uint32_t>> data_;
  std::vector<std::uint32_t> begin_;
  std::vector<std::uint32_t> size_;
  std::vector<std::uint32_t> capacity_;
};

}  // namespace qem::core
