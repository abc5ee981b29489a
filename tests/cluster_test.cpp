// Tests of `qem cluster` (uniform vertex clustering, Rossignac & Borrel 1993, with the quadric
// placement of Lindstrom 2000) on meshes built in code.
#include "qem/cluster.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "qem/error.h"
#include "qem/measure.h"
#include "test_meshes.h"

namespace qem {
namespace {

ClusterOptions grid_options(int nx, int ny, int nz, ClusterPlacement p = ClusterPlacement::Quadric) {
  ClusterOptions o;
  o.grid[0] = nx, o.grid[1] = ny, o.grid[2] = nz;
  o.placement = p;
  return o;
}

// The unit cube with every face an n x n grid of quads, faces not welded to each other
// (clustering merges the coincident vertices anyway). Outward orientation.
Mesh tessellated_cube(int n) {
  Mesh out;
  const Mesh g = test::grid(n);  // z = 0, normal +z
  // Map (u, v, w=0) of the grid to each face; `flip` swaps u and v to turn the normal around.
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side < 2; ++side) {
      Mesh f = g;
      for (std::size_t i = 0; i < f.positions.size(); i += 3) {
        double u = g.positions[i], v = g.positions[i + 1];
        // Orientation: (u, v) -> axes (axis+1, axis+2) gives normal +axis; swap for the -axis side.
        if (side == 0) std::swap(u, v);
        f.positions[i + axis] = side;
        f.positions[i + (axis + 1) % 3] = u;
        f.positions[i + (axis + 2) % 3] = v;
      }
      out = test::concatenated(out, f);
    }
  return out;
}

// A grid of 2k x 2k quads clustered into k x k cells: the representatives form a k x k lattice whose
// (k-1)^2 quads each keep both triangles (the ones spanning four cells); the rest collapse.
TEST(Cluster, FineGridIntoCoarseGridFaceCount) {
  for (int k : {2, 4, 8}) {
    const Mesh m = test::grid(2 * k);
    const Mesh c = cluster(m, grid_options(k, k, 1));
    EXPECT_EQ(c.face_count(), std::size_t(2 * (k - 1) * (k - 1))) << k;
    EXPECT_EQ(c.vertex_count(), std::size_t(k * k)) << k;
  }
}

TEST(Cluster, CellSizeMatchesGrid) {
  const Mesh m = test::grid(16);
  const Mesh by_grid = cluster(m, grid_options(4, 4, 1));
  ClusterOptions o;
  o.cell = 0.25;  // ceil(1 / 0.25) = 4 cells per axis, flat z: 1 cell
  const Mesh by_cell = cluster(m, o);
  EXPECT_EQ(by_cell.indices, by_grid.indices);
  EXPECT_EQ(by_cell.positions, by_grid.positions);
  o.cell = 0.25 / std::sqrt(2.0);  // relative to the diagonal sqrt(2): the same cell
  o.cell_relative = true;
  EXPECT_EQ(cluster(m, o).face_count(), by_grid.face_count());
}

TEST(Cluster, QuadricPlacementKeepsPlaneExact) {
  const Mesh plane = test::height_field(20, [](double x, double y) { return 0.3 * x - 0.2 * y + 0.1; });
  const Mesh c = cluster(plane, grid_options(5, 5, 5));
  ASSERT_GT(c.face_count(), 0u);
  for (std::size_t v = 0; v < c.vertex_count(); ++v) {
    const double* p = &c.positions[3 * v];
    EXPECT_NEAR(p[2], 0.3 * p[0] - 0.2 * p[1] + 0.1, 1e-12) << v;
  }
}

// At a cube corner the cluster's quadric holds the three face planes, whose only common point is
// the corner: quadric placement puts the representative there exactly; the mean of the corner
// cell's vertices lies inside the cube. The whole approximation is closer too (GH97 Fig. 15 shows
// the clustering baseline; Lindstrom 2000 the gain of quadric placement).
TEST(Cluster, QuadricPlacementKeepsCubeCornersSharp) {
  const Mesh cube = tessellated_cube(10);
  const Mesh q = cluster(cube, grid_options(4, 4, 4, ClusterPlacement::Quadric));
  const Mesh m = cluster(cube, grid_options(4, 4, 4, ClusterPlacement::Mean));
  auto corner_error = [](const Mesh& mesh) {
    double worst = 0;
    for (int c = 0; c < 8; ++c) {
      const double corner[3] = {double(c & 1), double((c >> 1) & 1), double((c >> 2) & 1)};
      double best = INFINITY;
      for (std::size_t v = 0; v < mesh.vertex_count(); ++v) {
        double d2 = 0;
        for (int k = 0; k < 3; ++k) d2 += std::pow(mesh.positions[3 * v + k] - corner[k], 2);
        best = std::min(best, d2);
      }
      worst = std::max(worst, std::sqrt(best));
    }
    return worst;
  };
  EXPECT_LT(corner_error(q), 1e-9);
  EXPECT_GT(corner_error(m), 0.05);
  MeasureOptions mo;
  mo.samples = 50000;
  mo.threads = 1;
  const double e_quadric = measure(cube, q, mo).E, e_mean = measure(cube, m, mo).E;
  EXPECT_LT(e_quadric, 0.5 * e_mean);
}

TEST(Cluster, DuplicateFacesRemoved) {
  // A thin slab: two parallel planes 1e-3 apart, the top one facing the other way. Cells much
  // thicker than the slab merge both sheets into the same triangles, which must appear once.
  Mesh top = test::transformed(test::grid(8), 1, 0, 0, 1e-3);
  for (std::size_t f = 0; f < top.indices.size(); f += 3) std::swap(top.indices[f + 1], top.indices[f + 2]);
  const Mesh slab = test::concatenated(test::grid(8), top);
  const Mesh one = cluster(test::grid(8), grid_options(4, 4, 1));
  const Mesh both = cluster(slab, grid_options(4, 4, 1));
  EXPECT_EQ(both.face_count(), one.face_count());
  EXPECT_EQ(both.vertex_count(), one.vertex_count());
}

TEST(Cluster, Deterministic) {
  const Mesh m = test::transformed(test::icosphere(4), 1.3, 0.1, -0.2, 0.05);
  const ClusterOptions o = grid_options(7, 6, 5);
  const Mesh a = cluster(m, o), b = cluster(m, o);
  EXPECT_EQ(a.positions, b.positions);
  EXPECT_EQ(a.indices, b.indices);
  EXPECT_GT(a.face_count(), 50u);
  EXPECT_LT(a.face_count(), m.face_count() / 4);
  for (std::uint32_t i : a.indices) EXPECT_LT(i, a.vertex_count());
}

TEST(Cluster, RejectsBadOptions) {
  const Mesh m = test::cube();
  EXPECT_THROW(cluster(m, ClusterOptions{}), Error);  // neither grid nor cell
  EXPECT_THROW(cluster(m, grid_options(4, 0, 4)), Error);
  ClusterOptions o;
  o.cell = -1;
  EXPECT_THROW(cluster(m, o), Error);
  o.cell = 1e-9;  // 1e9 cells per axis
  EXPECT_THROW(cluster(m, o), Error);
  Mesh bad = test::cube();
  bad.indices[0] = 8;
  EXPECT_THROW(cluster(bad, grid_options(2, 2, 2)), Error);
}

}  // namespace
}  // namespace qem
