// Per-vertex lists (incident faces, valid pairs) in one flat arena, so the contraction loop never
// allocates per element. A list that outgrows its slot moves to the end of the arena with room to
// grow; the old slot is abandoned (its size is bounded by the total work, see GH97 §4's "pair sets
// merge on contraction").
#pragma once

#include <cstdint>
#include <span>
#include <vector>

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
      begin_[v] = total;
      capacity_[v] = sizes[v];
      total += sizes[v];
    }
    data_.reserve(total + total / 4);
    data_.assign(total, 0);
  }
  void push_initial(std::uint32_t v, std::uint32_t item) { data_[begin_[v] + size_[v]++] = item; }

  std::span<const std::uint32_t> operator[](std::uint32_t v) const { return {data_.data() + begin_[v], size_[v]}; }

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
      begin_[v] = data_.size();
      capacity_[v] = std::uint32_t(n + n / 2 + 2);
      data_.resize(data_.size() + capacity_[v]);
    }
    std::uint32_t* dst = data_.data() + begin_[v];
    for (std::size_t i = 0; i < n; ++i) dst[i] = items[i];
    size_[v] = std::uint32_t(n);
  }
  void clear(std::uint32_t v) { size_[v] = 0; }

  std::size_t memory_bytes() const {
    return data_.capacity() * 4 + begin_.capacity() * 8 + (size_.capacity() + capacity_.capacity()) * 4;
  }

 private:
  std::vector<std::uint32_t> data_;
  std::vector<std::size_t> begin_;
  std::vector<std::uint32_t> size_;
  std::vector<std::uint32_t> capacity_;
};

}  // namespace qem::core
