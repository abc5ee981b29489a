// Hash tables keyed by grid cell, for the out-of-core clustering (Lindstrom 2000 §3: memory
// proportional to the occupied cells, not to the input). Open addressing over flat arrays: a key
// and an index a slot, no allocation per cell.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/quadric.h"

namespace qem::outofcore {

/// A cell (i, j, k), 21 bits an axis, plus one so that 0 marks an empty slot.
using CellKey = std::uint64_t;

inline CellKey pack_cell(std::uint64_t i, std::uint64_t j, std::uint64_t k) {
  return ((i << 42) | (j << 21) | k) + 1;
}
inline void unpack_cell(CellKey key, std::uint64_t out[3]) {
  key -= 1;
  out[0] = key >> 42, out[1] = (key >> 21) & 0x1fffff, out[2] = key & 0x1fffff;
}

/// The cell `levels` times coarser that holds `key`: each coordinate halved per level (a cell of
/// twice the side is the union of eight, so a key computed on the fine grid and coarsened equals
/// the key computed on the coarse grid with the same origin).
inline CellKey coarser_cell(CellKey key, int levels) {
  if (levels == 0) return key;
  std::uint64_t c[3];
  unpack_cell(key, c);
  return pack_cell(c[0] >> levels, c[1] >> levels, c[2] >> levels);
}

/// What a cell accumulates (Lindstrom 2000 §3): the quadric of its faces and the sum of their
/// corners in it, whose mean is where the cell's vertex is sought. Also the sums of the directed
/// edges (b - a) and of their moments (a x b, the Plücker coordinates of the line a -> b) of its
/// faces' edges with an end in it: an edge between two faces comes once in each direction and
/// cancels, so what remains is the input's border through the cell (consistently oriented faces
/// assumed), from which the cell's vertex is kept on that border.
struct CellSums {
  core::Quadric quadric;
  double sum[3] = {0, 0, 0};
  double corners = 0;
  double edge[3] = {0, 0, 0};
  double moment[3] = {0, 0, 0};
  CellSums& operator+=(const CellSums& o) {
    quadric += o.quadric;
    sum[0] += o.sum[0], sum[1] += o.sum[1], sum[2] += o.sum[2];
    corners += o.corners;
    for (int a = 0; a < 3; ++a) edge[a] += o.edge[a], moment[a] += o.moment[a];
    return *this;
  }
};

inline std::size_t slot_of(CellKey key, std::size_t mask) {
  return std::size_t((key * 0x9E3779B97F4A7C15ull) >> 20) & mask;
}

inline std::size_t table_capacity(std::size_t cells) {
  std::size_t c = 16;
  while (c < 2 * cells + 2) c *= 2;
  return c;
}

/// The set of occupied cells, for choosing the grid: counts, and coarsens to cells of twice the
/// side (each key's coordinates halved: the union of 8 cells).
class CellSet {
 public:
  explicit CellSet(std::size_t max_cells) : slots_(table_capacity(max_cells)) {}
  std::size_t size() const { return size_; }
  void insert(CellKey key) {
    const std::size_t mask = slots_.size() - 1;
    for (std::size_t s = slot_of(key, mask);; s = (s + 1) & mask) {
      if (slots_[s] == key) return;
      if (slots_[s] == 0) {
        slots_[s] = key;
        ++size_;
        return;
      }
    }
  }
  void coarsen() {
    std::vector<CellKey> old(slots_.size(), 0);
    old.swap(slots_);
    size_ = 0;
    for (CellKey k : old)
      if (k) {
        std::uint64_t c[3];
        unpack_cell(k, c);
        insert(pack_cell(c[0] >> 1, c[1] >> 1, c[2] >> 1));
      }
  }

 private:
  std::vector<CellKey> slots_;
  std::size_t size_ = 0;
};

/// The occupied cells of the clustering, numbered in the order they are met, each with the sum of
/// its faces' quadrics and of its corners' positions.
class CellTable {
 public:
  using Cell = CellSums;

  explicit CellTable(std::size_t expected_cells) : keys_(table_capacity(expected_cells)), ids_(keys_.size()) {
    cells_.reserve(expected_cells);
    cell_keys_.reserve(expected_cells);
  }
  std::uint32_t size() const { return std::uint32_t(cells_.size()); }
  Cell& cell(std::uint32_t id) { return cells_[id]; }
  CellKey key(std::uint32_t id) const { return cell_keys_[id]; }

  std::uint32_t find_or_add(CellKey key) {
    std::size_t mask = keys_.size() - 1;
    for (std::size_t s = slot_of(key, mask);; s = (s + 1) & mask) {
      if (keys_[s] == key) return ids_[s];
      if (keys_[s] == 0) {
        if (2 * (cells_.size() + 1) > keys_.size()) {  // more cells than the grid was chosen for
          grow();
          return find_or_add(key);
        }
        keys_[s] = key;
        ids_[s] = std::uint32_t(cells_.size());
        cells_.emplace_back();
        cell_keys_.push_back(key);
        return ids_[s];
      }
    }
  }
  static constexpr std::uint32_t kNoCell = 0xffffffffu;
  /// The id of the cell `key`, kNoCell when it is not in the table.
  std::uint32_t find(CellKey key) const {
    const std::size_t mask = keys_.size() - 1;
    for (std::size_t s = slot_of(key, mask);; s = (s + 1) & mask) {
      if (keys_[s] == key) return ids_[s];
      if (keys_[s] == 0) return kNoCell;
    }
  }
  /// Merges every cell into its parent on the grid of twice the side, renumbering the cells in the
  /// order of their first child: the result depends only on the table's order, never on timing.
  void coarsen() {
    CellTable parents(cells_.size() / 2 + 1);
    for (std::uint32_t i = 0; i < cells_.size(); ++i)
      parents.cell(parents.find_or_add(coarser_cell(cell_keys_[i], 1))) += cells_[i];
    *this = std::move(parents);
  }
  void release() {
    std::vector<CellKey>().swap(keys_);
    std::vector<std::uint32_t>().swap(ids_);
    std::vector<Cell>().swap(cells_);
    std::vector<CellKey>().swap(cell_keys_);
  }

 private:
  void grow() {
    std::vector<CellKey> keys(2 * keys_.size(), 0);
    std::vector<std::uint32_t> ids(keys.size());
    const std::size_t mask = keys.size() - 1;
    for (std::size_t s = 0; s < keys_.size(); ++s)
      if (keys_[s]) {
        std::size_t t = slot_of(keys_[s], mask);
        while (keys[t]) t = (t + 1) & mask;
        keys[t] = keys_[s], ids[t] = ids_[s];
      }
    keys_.swap(keys), ids_.swap(ids);
  }

  std::vector<CellKey> keys_;
  std::vector<std::uint32_t> ids_;
  std::vector<Cell> cells_;
  std::vector<CellKey> cell_keys_;
};

}  // namespace qem::outofcore
