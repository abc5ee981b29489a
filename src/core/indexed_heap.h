// A 4-ary min-heap over item ids 0..n-1 with O(log n) update and removal of any item: the "heap
// keyed on cost" of GH97 §4. Indexed rather than lazy, so memory stays at 16 + 4 bytes per pair
// however many times costs change. Each entry carries its key, so sifting touches only the heap
// array (no indirection into a cost array: that was the simplifier's main source of cache misses).
// Keys are floats: callers round costs to float precision (24 significant bits) before use, so
// a key compares exactly with the cost it came from. Ties break on the id, so the order of
// contractions is fully determined by the input. Four children of 8 bytes share one cache line, and the tree is half as deep as a binary one:
// sift-down, the heap's hot path, then costs about half the cache misses.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

namespace qem::core {

class IndexedHeap {
 public:
  static constexpr std::uint32_t kAbsent = 0xffffffffu;

  void reset(std::size_t id_count) {
    heap_.clear();
    heap_.reserve(id_count);  // every id at most once: no reallocation copies while filling
    slot_.assign(id_count, kAbsent);
  }
  bool empty() const { return heap_.empty(); }
  std::size_t size() const { return heap_.size(); }
  bool contains(std::uint32_t id) const { return slot_[id] != kAbsent; }
  std::uint32_t top() const { return heap_[0].id; }
  /// The key `id` is held at (it must be in the heap).
  double key_of(std::uint32_t id) const { return heap_[slot_[id]].key; }
  double top_key() const { return heap_[0].key; }

  /// Appends without ordering; call heapify() once after the last push (Floyd, O(n)).
  void push_unordered(std::uint32_t id, double key) {
    slot_[id] = std::uint32_t(heap_.size());
    heap_.push_back({float(key), id});
  }
  void heapify() {
    for (std::size_t i = heap_.size() / kArity + 1; i-- > 0;)
      if (i < heap_.size()) sift_down(std::uint32_t(i));
  }

  /// Inserts `id` with `key`, or moves it to its new key.
  void update(std::uint32_t id, double key) {
    std::uint32_t s = slot_[id];
    if (s == kAbsent) {
      s = std::uint32_t(heap_.size());
      heap_.push_back({float(key), id});
      slot_[id] = s;
      sift_up(s);
      return;
    }
    float old = heap_[s].key;
    heap_[s].key = float(key);
    if (key < old) sift_up(s);
    else sift_down(s);
  }

  void remove(std::uint32_t id) {
    std::uint32_t s = slot_[id];
    if (s == kAbsent) return;
    Entry last = heap_.back();
    heap_.pop_back();
    slot_[id] = kAbsent;
    if (last.id == id) return;
    heap_[s] = last;
    slot_[last.id] = s;
    sift_up(s);
    sift_down(slot_[last.id]);
  }

  std::uint32_t pop() {
    std::uint32_t id = heap_[0].id;
    remove(id);
    return id;
  }

 private:
  struct Entry {
    float key;
    std::uint32_t id;
  };
  static bool less(const Entry& a, const Entry& b) { return a.key < b.key || (a.key == b.key && a.id < b.id); }
  static constexpr std::uint32_t kArity = 4;
  void sift_up(std::uint32_t s) {
    Entry e = heap_[s];
    while (s > 0) {
      std::uint32_t parent = (s - 1) / kArity;
      if (!less(e, heap_[parent])) break;
      heap_[s] = heap_[parent];
      slot_[heap_[s].id] = s;
      s = parent;
    }
    heap_[s] = e;
    slot_[e.id] = s;
  }
  void sift_down(std::uint32_t s) {
    Entry e = heap_[s];
    const std::uint32_t n = std::uint32_t(heap_.size());
    for (;;) {
      std::uint32_t first = kArity * s + 1;
      if (first >= n) break;
      std::uint32_t last = std::min(first + kArity, n), child = first;
      for (std::uint32_t c = first + 1; c < last; ++c)
        if (less(heap_[c], heap_[child])) child = c;
      if (!less(heap_[child], e)) break;
      heap_[s] = heap_[child];
      slot_[heap_[s].id] = s;
      s = child;
    }
    heap_[s] = e;
    slot_[e.id] = s;
  }

  std::vector<Entry> heap_;
  std::vector<std::uint32_t> slot_;
};

}  // namespace qem::core
