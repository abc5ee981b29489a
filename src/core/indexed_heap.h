// A binary min-heap over item ids 0..n-1 keyed by an external cost array, with O(log n) update and
// removal of any item: the "heap keyed on cost" of GH97 §4. Indexed rather than lazy, so memory
// stays at 8 bytes per pair however many times costs change. Ties break on the id, so the order
// of contractions is fully determined by the input.
#pragma once

#include <cstdint>
#include <vector>

namespace qem::core {

class IndexedHeap {
 public:
  static constexpr std::uint32_t kAbsent = 0xffffffffu;

  explicit IndexedHeap(const std::vector<double>& keys) : keys_(keys) {}

  void reset(std::size_t id_count) {
    heap_.clear();
    slot_.assign(id_count, kAbsent);
  }
  bool empty() const { return heap_.empty(); }
  std::size_t size() const { return heap_.size(); }
  bool contains(std::uint32_t id) const { return slot_[id] != kAbsent; }
  std::uint32_t top() const { return heap_[0]; }

  /// Builds the heap from all ids at once in O(n) (Floyd).
  void build(const std::vector<std::uint32_t>& ids) {
    heap_ = ids;
    for (std::uint32_t i = 0; i < heap_.size(); ++i) slot_[heap_[i]] = i;
    for (std::size_t i = heap_.size() / 2; i-- > 0;) sift_down(std::uint32_t(i));
  }

  /// Inserts `id`, or repositions it after its key changed.
  void update(std::uint32_t id) {
    std::uint32_t s = slot_[id];
    if (s == kAbsent) {
      s = std::uint32_t(heap_.size());
      heap_.push_back(id);
      slot_[id] = s;
      sift_up(s);
    } else {
      sift_up(s);
      sift_down(slot_[id]);
    }
  }

  void remove(std::uint32_t id) {
    std::uint32_t s = slot_[id];
    if (s == kAbsent) return;
    std::uint32_t last = heap_.back();
    heap_.pop_back();
    slot_[id] = kAbsent;
    if (last == id) return;
    heap_[s] = last;
    slot_[last] = s;
    sift_up(s);
    sift_down(slot_[last]);
  }

  std::uint32_t pop() {
    std::uint32_t id = heap_[0];
    remove(id);
    return id;
  }

 private:
  bool less(std::uint32_t a, std::uint32_t b) const {
    return keys_[a] < keys_[b] || (keys_[a] == keys_[b] && a < b);
  }
  void sift_up(std::uint32_t s) {
    std::uint32_t id = heap_[s];
    while (s > 0) {
      std::uint32_t parent = (s - 1) / 2;
      if (!less(id, heap_[parent])) break;
      heap_[s] = heap_[parent];
      slot_[heap_[s]] = s;
      s = parent;
    }
    heap_[s] = id;
    slot_[id] = s;
  }
  void sift_down(std::uint32_t s) {
    std::uint32_t id = heap_[s];
    const std::uint32_t n = std::uint32_t(heap_.size());
    for (;;) {
      std::uint32_t child = 2 * s + 1;
      if (child >= n) break;
      if (child + 1 < n && less(heap_[child + 1], heap_[child])) ++child;
      if (!less(heap_[child], id)) break;
      heap_[s] = heap_[child];
      slot_[heap_[s]] = s;
      s = child;
    }
    heap_[s] = id;
    slot_[id] = s;
  }

  const std::vector<double>& keys_;
  std::vector<std::uint32_t> heap_;
  std::vector<std::uint32_t> slot_;
};

}  // namespace qem::core
