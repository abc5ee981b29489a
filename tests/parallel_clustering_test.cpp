// The out-of-core clustering pass (src/outofcore/parallel_clustering.h): a grid coarsened while
// the pass runs gives the cells and faces of the coarse grid itself, and the threads change nothing.
#include "outofcore/parallel_clustering.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>

#include "outofcore/mesh_generator.h"
#include "test_meshes.h"

using namespace qem;
using namespace qem::outofcore;

namespace {

struct Clustered {
  std::map<CellKey, CellSums> cells;
  std::vector<std::array<CellKey, 3>> faces;  // as the final cells' keys
  int levels = 0;
};

Clustered cluster(const Mesh& mesh, const Grid& grid, std::uint64_t max_cells, unsigned threads) {
  std::vector<float> xyz(mesh.positions.begin(), mesh.positions.end());
  PositionSource positions;
  positions.base = reinterpret_cast<const unsigned char*>(xyz.data());
  TempFile faces(test::temp_dir(), "clustering_test");
  Clustered out;
  {
    ParallelClustering c(grid, max_cells, threads, faces);
    // Uneven pieces, as a reader hands them over: the blocks do not depend on them.
    std::size_t at = 0, piece = 1000;
    while (at < mesh.face_count()) {
      const std::size_t n = std::min(piece, mesh.face_count() - at);
      c.add_indexed(mesh.indices.data() + 3 * at, n, positions);
      at += n, piece = piece * 3 % 70001 + 1;
    }
    c.finish();
    out.levels = c.levels();
    for (std::uint32_t i = 0; i < c.cells().size(); ++i) out.cells[c.cells().key(i)] = c.cells().cell(i);
    std::vector<std::uint64_t> shapes;
    const std::vector<std::uint32_t> ids = read_clustered_faces(c, faces, shapes);
    EXPECT_EQ(shapes.size() * 3, ids.size());
    for (std::size_t f = 0; f < ids.size(); f += 3)
      out.faces.push_back({c.cells().key(ids[f]), c.cells().key(ids[f + 1]), c.cells().key(ids[f + 2])});
  }
  return out;
}

const Mesh& sphere() {
  static const Mesh m = bumpy_sphere(300000);
  return m;
}

Grid grid_of(double size) {
  Grid g;
  for (int a = 0; a < 3; ++a) g.lo[a] = -1.2;
  g.size = size;
  return g;
}

TEST(ParallelClustering, CoarsenedWhileRunningEqualsTheCoarseGrid) {
  // Bounded by the cells of the grid 4x coarser, the fine grid must be halved twice during the
  // pass, and lands on that grid's cells exactly.
  const Clustered coarse_direct = cluster(sphere(), grid_of(2.4 / 16), 1 << 20, 1);
  const Clustered fine_then_coarsened = cluster(sphere(), grid_of(2.4 / 64), coarse_direct.cells.size(), 2);
  ASSERT_EQ(coarse_direct.levels, 0);
  EXPECT_EQ(fine_then_coarsened.levels, 2);
  ASSERT_EQ(fine_then_coarsened.cells.size(), coarse_direct.cells.size());
  for (const auto& [key, sums] : coarse_direct.cells) {
    const auto it = fine_then_coarsened.cells.find(key);
    ASSERT_NE(it, fine_then_coarsened.cells.end());
    const CellSums& other = it->second;
    EXPECT_EQ(other.corners, sums.corners);
    // The same terms added in another order: equal to rounding.
    const double scale = sums.quadric.weight;
    EXPECT_NEAR(other.quadric.weight, sums.quadric.weight, 1e-12 * scale);
    EXPECT_NEAR(other.quadric.a00, sums.quadric.a00, 1e-12 * scale);
    EXPECT_NEAR(other.quadric.b1, sums.quadric.b1, 1e-11 * scale);
    EXPECT_NEAR(other.sum[2], sums.sum[2], 1e-11 * sums.corners);
  }
  // The faces (as cells) are the same, in the same order: a triple of the fine grid that
  // collapses on the coarse one is dropped when read back.
  EXPECT_EQ(fine_then_coarsened.faces, coarse_direct.faces);
}

TEST(ParallelClustering, SameBitsOnAnyNumberOfThreads) {
  const Clustered one = cluster(sphere(), grid_of(2.4 / 256), 20000, 1);
  EXPECT_GT(one.levels, 0);
  for (unsigned threads : {2u, 4u}) {
    const Clustered many = cluster(sphere(), grid_of(2.4 / 256), 20000, threads);
    ASSERT_EQ(many.cells.size(), one.cells.size()) << threads;
    for (const auto& [key, sums] : one.cells) {
      const CellSums& other = many.cells.at(key);
      EXPECT_EQ(std::memcmp(&other, &sums, sizeof sums), 0) << threads;
    }
    EXPECT_EQ(many.faces, one.faces) << threads;
  }
}

}  // namespace

// The triples that come out of the clustering, their input triangles' shapes, and what stays: a
// face alone; a fold (a triple twice, from two triangles) drops out; a two-sided sheet's face
// and its reversed copy (one shape) stay both; such a pair folded onto a third triangle, and three
// triangles on one triple, leave one face, the first. Each edge's count stays even.
TEST(ParallelClustering, PairedTriplesDropOutAndEveryEdgeKeepsItsParity) {
  std::vector<std::uint32_t> ids = {
      0,  1,  2,                           // alone
      3,  4,  5,  5,  4,  3,               // a fold: two triangles
      6,  7,  8,  8,  7,  6,               // a two-sided sheet's face and its back
      9,  10, 11, 11, 10, 9,  9,  11, 10,  // the sheet folded onto another triangle
      12, 13, 14, 14, 13, 12, 12, 13, 14,  // three triangles
  };
  const std::vector<std::uint64_t> shapes = {1, 2, 3, 4, 4, 5, 5, 6, 7, 8, 9, 10};
  const auto edge_parity = [](const std::vector<std::uint32_t>& f) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> n;
    for (std::size_t i = 0; i < f.size(); i += 3)
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t a = f[i + k], b = f[i + (k + 1) % 3];
        n[{std::min(a, b), std::max(a, b)}] ^= 1;
      }
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> odd;
    for (const auto& [e, p] : n)
      if (p) odd[e] = 1;
    return odd;
  };
  const auto before = edge_parity(ids);
  drop_paired_faces(ids, shapes);
  const std::vector<std::uint32_t> expected = {0, 1, 2, 6, 7, 8, 8, 7, 6, 9, 10, 11, 12, 13, 14};
  EXPECT_EQ(ids, expected);
  EXPECT_EQ(edge_parity(ids), before);
}
