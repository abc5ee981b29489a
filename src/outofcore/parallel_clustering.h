// The clustering pass of Lindstrom 2000 spread over threads: the triangles, in file order, are cut
// into blocks of a fixed size (never depending on the number of threads); each block is clustered
// on its own into a small table of the cells it touches, on whichever thread is free; the blocks'
// tables are then added into the run's table strictly in block order. Every floating-point sum is
// therefore made in the same order whatever the number of threads, and the output bytes do not
// depend on --threads.
//
// The grid need not be chosen before the pass: blocks are clustered on a fine grid, and when the
// run's table holds more cells than allowed it is coarsened to cells of twice the side (each the
// union of eight, so sums stay exact); later blocks are coarsened as they are added. The faces
// that span three cells are written to a temporary file with their fine cells' keys, and mapped to
// the final cells when read back (read_clustered_faces).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <functional>
#include <memory>
#include <vector>

#include "outofcore/cell_table.h"
#include "outofcore/temp_file.h"

namespace qem::outofcore {

/// Cubic cells of side `size` from the corner `lo` (the box's low corner).
struct Grid {
  double lo[3] = {0, 0, 0};
  double size = 1;
  CellKey key(double x, double y, double z) const {
    const double c[3] = {x, y, z};
    std::uint64_t k[3];
    for (int a = 0; a < 3; ++a) {
      // floor() as a truncation of a non-negative value, clamped to the keys' 21 bits.
      const double t = (c[a] - lo[a]) / size;
      k[a] = t <= 0 ? 0 : t >= double((1u << 21) - 1) ? (1u << 21) - 1 : std::uint64_t(t);
    }
    return pack_cell(k[0], k[1], k[2]);
  }
};

/// Where the indexed triangles' corners are: float x, y, z at `at` in rows of `row` bytes from
/// `base` (a mapped PLY vertex block, or packed floats).
struct PositionSource {
  const unsigned char* base = nullptr;
  std::size_t row = 12;
  std::size_t at[3] = {0, 4, 8};
  void get(std::uint64_t v, double out[3]) const {
    const unsigned char* p = base + v * row;
    for (int a = 0; a < 3; ++a) {
      float f;
      std::memcpy(&f, p + at[a], 4);
      out[a] = f;
    }
  }
};

class ParallelClustering {
 public:
  /// Triangles a block holds: enough that a block's own table is small beside its work (the
  /// faces of a mesh in file order are mostly near each other), few enough to keep threads busy.
  static constexpr std::size_t kBlockTriangles = std::size_t(1) << 16;

  /// `fine`: the grid blocks are clustered on; `max_cells`: the run's table is coarsened whenever
  /// it holds more; `threads`: 0 or 1 cluster the blocks on the calling thread; `faces`: the
  /// temporary file of the triples.
  ParallelClustering(const Grid& fine, std::uint64_t max_cells, unsigned threads, TempFile& faces);
  ~ParallelClustering();
  ParallelClustering(const ParallelClustering&) = delete;
  ParallelClustering& operator=(const ParallelClustering&) = delete;

  /// Indexed triangles (3 vertex indices each) whose corners `positions` gives.
  void add_indexed(const std::uint32_t* corners, std::size_t n, const PositionSource& positions);
  /// A triangle soup: 9 coordinates a triangle, kept as float like the indexed positions.
  void add_soup(const double* xyz, std::size_t n);
  /// After the last triangle: clusters and adds the remaining blocks.
  void finish();

  /// Called on the calling thread after each block is added (to check memory, report progress).
  std::function<void()> after_block;

  /// The cells on the final grid (valid after finish()).
  CellTable& cells() { return cells_; }
  /// Times the fine grid was coarsened: the final cells have side fine.size * 2^levels.
  int levels() const { return levels_; }
  /// Triples written to the faces file (fine keys; some collapse on the final grid).
  std::uint64_t triples() const { return triples_; }

 private:
  struct Block;
  struct Workers;
  void start_block();
  void submit();
  void add_block(Block& block);
  void merge_ready(bool wait_all);

  Grid fine_;
  std::uint64_t max_cells_;
  TempFile& faces_;
  CellTable cells_;
  int levels_ = 0;
  std::uint64_t triples_ = 0;
  std::unique_ptr<Block> filling_;
  std::vector<std::unique_ptr<Block>> spare_;  // blocks added, their buffers reused
  std::unique_ptr<Workers> workers_;
  std::uint64_t submitted_ = 0, merged_ = 0;
};

/// Reads the triples of `clustering` back as faces of the final cells' ids, dropping those whose
/// corners fell into fewer than three final cells; `shapes` gets each kept face's input triangle's
/// shape (a hash of its corners in no order: a triangle and its reversed copy have the same).
std::vector<std::uint32_t> read_clustered_faces(ParallelClustering& clustering, TempFile& faces,
                                                std::vector<std::uint64_t>& shapes);

/// Clustering maps a closed input surface onto one closed in the mod-2 sense: every edge of the
/// cell triples is used an even number of times (the image of a cycle is a cycle). Where a thin
/// part or a fold collapses, the same three cells come out twice (or four times...); the in-core
/// simplifier would keep one of them and open a crack. So a triple that comes out an even number
/// of times is dropped, and one that comes out an odd number is kept once: every edge's count
/// stays even, no boundary edge the input did not have.
/// The exception, copies of one input triangle (`shapes`: the same corners; a sheet made
/// two-sided by a reversed copy of each face): a two-sided sheet is one surface, not a fold, and
/// dropping its pairs dropped the whole sheet. Its copies are all kept, for phase 2, whose core
/// keeps one and puts the reversed twins back along the rims (SimplifyOptions::two_sided). All
/// kept, their count is the triple's, so the parity holds there too; a triple shared by copies and
/// other triangles (a sheet folded onto a surface) is counted face by face: counted as one
/// triangle, each twin pair opened a crack along the fold (the Stanford dragon at res4, 87
/// boundary edges under a tight limit).
void drop_paired_faces(std::vector<std::uint32_t>& indices, const std::vector<std::uint64_t>& shapes);

}  // namespace qem::outofcore
