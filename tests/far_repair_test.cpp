// Tests of the repair of the far places after the run (core/far_repair.h,
// SimplifyOptions::far_repair): an edge across a groove is flipped onto it, an edge that already
// lies on the input is left, held vertices keep their edges and positions, a vertex under a
// cut-off bump moves onto it, and on real simplifications the repair never folds a face, never
// makes an edge non-manifold or changes the topology, moves no border vertex and does not raise
// the largest distance to the input.
#include "core/far_repair.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <vector>

#include "core/distance_bound.h"
#include "geometry/frame.h"
#include "mesh_checks.h"
#include "outofcore/mesh_generator.h"
#include "qem/simplify.h"
#include "test_meshes.h"

namespace qem {
namespace {

std::vector<double> corners_of(const Mesh& m) {
  std::vector<double> c;
  for (std::uint32_t v : m.indices) c.insert(c.end(), &m.positions[3 * std::size_t(v)], &m.positions[3 * std::size_t(v)] + 3);
  return c;
}

// A third of the area of each face round each vertex.
std::vector<double> areas_of(const Mesh& m) {
  std::vector<double> w(m.vertex_count(), 0.0);
  for (std::size_t f = 0; f < m.face_count(); ++f) {
    const std::uint32_t* t = &m.indices[3 * f];
    const auto p = [&](int k) {
      const double* q = &m.positions[3 * std::size_t(t[k])];
      return Vec3{q[0], q[1], q[2]};
    };
    const double area = 0.5 * length(cross(p(1) - p(0), p(2) - p(0)));
    for (int k = 0; k < 3; ++k) w[t[k]] += area / 3;
  }
  return w;
}

// The largest distance from `m`'s faces (a fine barycentric grid on each) to `surface`.
double largest_distance(const Mesh& m, const core::SurfaceDistance& surface) {
  constexpr int n = 16;
  double most = 0;
  for (std::size_t f = 0; f < m.face_count(); ++f) {
    const std::uint32_t* t = &m.indices[3 * f];
    const auto p = [&](int k) {
      const double* q = &m.positions[3 * std::size_t(t[k])];
      return Vec3{q[0], q[1], q[2]};
    };
    std::uint32_t hint = UINT32_MAX;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; i + j <= n; ++j)
        most = std::max(most, surface.distance(p(0) + (p(1) - p(0)) * (double(i) / n) + (p(2) - p(0)) * (double(j) / n), &hint));
  }
  return most;
}

bool has_edge(const Mesh& m, std::uint32_t a, std::uint32_t b) {
  return test::edge_face_counts(m).count(std::minmax(a, b)) > 0;
}

core::FarRepairResult flip(Mesh& approx, const Mesh& input, const core::FarRepairOptions& options = {}) {
  const core::SurfaceDistance surface(corners_of(input));
  const std::vector<double> w = areas_of(input);
  return core::repair_far_places(approx, Frame{}, surface, input.positions, w, options);
}

// A V-shaped groove: banks a, b at z = 0, its floor from d to c at z = -0.05 (a crease of 28
// degrees between the slopes, under max_normal_turn_degrees). The input is the
// groove's two slopes; the approximation has the same four vertices, joined across the groove.
struct Groove {
  Mesh input, approx;
  Groove() {
    const std::vector<double> p = {0.3, 0.5, 0, 0.7, 0.5, 0, 0.5, 1, -0.05, 0.5, 0, -0.05};  // a, b, c, d
    input.positions = approx.positions = p;
    input.indices = {0, 3, 2, 1, 2, 3};   // (a,d,c), (b,c,d): the slopes
    approx.indices = {0, 1, 2, 1, 0, 3};  // (a,b,c), (b,a,d): the edge a-b spans the groove
  }
};

TEST(FarRepair, AnEdgeAcrossAGrooveIsFlippedOntoItsFloor) {
  Groove g;
  const core::SurfaceDistance surface(corners_of(g.input));
  ASSERT_GT(largest_distance(g.approx, surface), 0.04);  // the middle of a-b, above the floor
  const core::FarRepairResult r = flip(g.approx, g.input);
  EXPECT_EQ(r.flips, 1u);
  EXPECT_TRUE(has_edge(g.approx, 2, 3));
  EXPECT_FALSE(has_edge(g.approx, 0, 1));
  EXPECT_LT(largest_distance(g.approx, surface), 1e-12);  // on the slopes now
  EXPECT_GT(r.largest_before, 0.04);
  EXPECT_EQ(test::validity_problem(g.approx), "");
}

TEST(FarRepair, AnEdgeOnTheInputStays) {
  Groove g;
  Mesh approx = g.input;  // already the groove's own triangulation
  const core::FarRepairResult r = flip(approx, g.input);
  EXPECT_EQ(r.flips, 0u);
  EXPECT_EQ(approx.indices, g.input.indices);
}

TEST(FarRepair, HeldVerticesAndMaterialBoundariesKeepTheirEdges) {
  for (int held = 0; held < 4; ++held) {
    Groove g;
    std::vector<std::uint8_t> mask(4, 0);
    mask[held] = 1;
    core::FarRepairOptions o;
    o.held = mask;
    const std::vector<std::uint32_t> before = g.approx.indices;
    EXPECT_EQ(flip(g.approx, g.input, o).flips, 0u) << "held vertex " << held;
    EXPECT_EQ(g.approx.indices, before);
  }
  Groove g;
  g.approx.face_materials = {0, 1};
  EXPECT_EQ(flip(g.approx, g.input).flips, 0u);
}

TEST(FarRepair, NoFlipThatFoldsOrDuplicatesAnEdge) {
  // Seen from above, b inside the triangle a, c, d: the new face (b,c,d) would face down, even
  // though it lies on the input.
  Groove g;
  for (Mesh* m : {&g.input, &g.approx}) {
    m->positions[3 * 2] = m->positions[3 * 3] = 1.0;  // c = (1, 1, -0.2), d = (1, 0, -0.2)
  }
  const std::vector<std::uint32_t> before = g.approx.indices;
  EXPECT_EQ(flip(g.approx, g.input).flips, 0u);
  EXPECT_EQ(g.approx.indices, before);
  // A tetrahedron: every flip would make an edge that exists already (c-d).
  Mesh tet = test::tetrahedron();
  Mesh bumped = tet;
  for (double& x : bumped.positions) x *= 1.5;
  EXPECT_EQ(flip(tet, bumped).flips, 0u);
  EXPECT_EQ(test::non_manifold_edges(tet), 0u);
}

// The surface of ridges and V-shaped valleys z = 0.05 |sin(3 pi x)| + 0.03 |sin(2 pi y)|: creases
// that a coarse approximation crosses.
double creased(double x, double y) {
  return 0.05 * std::abs(std::sin(3 * std::numbers::pi * x)) + 0.03 * std::abs(std::sin(2 * std::numbers::pi * y));
}

// Per undirected edge, the smallest cosine between the normals of its faces (1 on a border).
std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed_counts(const Mesh& m) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> c;
  for (std::size_t f = 0; f < m.face_count(); ++f)
    for (int k = 0; k < 3; ++k) ++c[{m.indices[3 * f + k], m.indices[3 * f + (k + 1) % 3]}];
  return c;
}
std::set<std::uint32_t> border_vertices(const Mesh& m) {
  std::set<std::uint32_t> border;
  for (const auto& [e, n] : test::edge_face_counts(m))
    if (n == 1) border.insert(e.first), border.insert(e.second);
  return border;
}
std::size_t folded_edges(const Mesh& m) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::vector<Vec3>> normals;
  for (std::size_t f = 0; f < m.face_count(); ++f) {
    const std::uint32_t* t = &m.indices[3 * f];
    const auto p = [&](int k) {
      const double* q = &m.positions[3 * std::size_t(t[k])];
      return Vec3{q[0], q[1], q[2]};
    };
    const Vec3 n = normalized(cross(p(1) - p(0), p(2) - p(0)));
    for (int k = 0; k < 3; ++k) normals[std::minmax(t[k], t[(k + 1) % 3])].push_back(n);
  }
  std::size_t folds = 0;
  for (const auto& [e, n] : normals) folds += n.size() == 2 && dot(n[0], n[1]) < 0;
  return folds;
}

TEST(FarRepair, SimplifyFlipsWithoutFoldsTopologyChangesOrFartherPoints) {
  struct Case {
    Mesh input;
    std::size_t faces;
  };
  // (The bumpy sphere and the creased field at 1000 faces each have edges a flip brings closer.)
  const Case cases[] = {{test::height_field(60, creased), 1000}, {test::height_field(60, creased), 60},
                        {outofcore::bumpy_sphere(5000), 500}, {outofcore::bumpy_sphere(5000), 100}};
  std::size_t total_flips = 0, total_moves = 0;
  for (const Case& c : cases) {
    SimplifyOptions o;
    o.target_faces = c.faces;
    o.refit_rounds = 2;
    o.threads = 1;
    const SimplifyResult plain = simplify(c.input, o);
    o.far_repair = true;
    const SimplifyResult flipped = simplify(c.input, o);
    total_flips += flipped.edge_flips;
    const Mesh &a = plain.mesh, &b = flipped.mesh;
    EXPECT_EQ(plain.edge_flips + plain.vertex_moves, 0u);
    total_moves += flipped.vertex_moves;
    ASSERT_EQ(test::validity_problem(b), "");
    // Only interior vertices moved: the border's stay where they were.
    ASSERT_EQ(a.positions.size(), b.positions.size());
    const std::set<std::uint32_t> border = border_vertices(a);
    for (std::uint32_t v : border)
      for (int k = 0; k < 3; ++k) EXPECT_EQ(a.positions[3 * v + k], b.positions[3 * v + k]);
    EXPECT_EQ(a.face_count(), b.face_count());
    EXPECT_EQ(test::non_manifold_edges(b), 0u);
    EXPECT_EQ(test::boundary_edges(a), test::boundary_edges(b));
    EXPECT_EQ(test::edge_face_counts(a).size(), test::edge_face_counts(b).size());  // same Euler characteristic
    for (const auto& [e, n] : directed_counts(b)) EXPECT_EQ(n, 1) << "an edge used twice the same way round";
    EXPECT_LE(folded_edges(b), folded_edges(a));
    const core::SurfaceDistance surface(corners_of(c.input));
    EXPECT_LE(largest_distance(b, surface), largest_distance(a, surface) * 1.02);
    // Deterministic, whatever the threads.
    o.threads = 3;
    EXPECT_EQ(simplify(c.input, o).mesh.indices, b.indices);
  }
  EXPECT_GT(total_flips, 0u);
  EXPECT_GT(total_moves, 0u);
}

// A bump cut off: the input is a 5x5 grid with its middle vertex raised, the approximation the
// same grid flat. The middle vertex moves up onto the bump's top; the border stays.
TEST(FarRepair, AVertexUnderACutOffBumpMovesOntoIt) {
  Mesh input = test::grid(4), approx = test::grid(4);
  input.positions[3 * 12 + 2] = 0.1;  // vertex 12: (0.5, 0.5), the middle
  const core::SurfaceDistance surface(corners_of(input));
  ASSERT_GT(largest_distance(approx, surface), 0.05);
  core::FarRepairOptions no_moves;
  no_moves.move_vertices = false;
  Mesh unmoved = approx;
  EXPECT_EQ(flip(unmoved, input, no_moves).moves, 0u);
  EXPECT_EQ(unmoved.positions, approx.positions);
  const core::FarRepairResult r = flip(approx, input);
  EXPECT_GE(r.moves, 1u);
  EXPECT_NEAR(approx.positions[3 * 12 + 2], 0.1, 1e-12);
  EXPECT_LT(largest_distance(approx, surface), 1e-9);
  for (std::uint32_t v : border_vertices(approx))
    for (int k = 0; k < 3; ++k) EXPECT_EQ(approx.positions[3 * v + k], input.positions[3 * v + k]);
  // Held, it stays.
  Mesh held = test::grid(4);
  std::vector<std::uint8_t> mask(held.vertex_count(), 0);
  mask[12] = 1;
  core::FarRepairOptions o;
  o.held = mask;
  flip(held, input, o);
  EXPECT_EQ(held.positions[3 * 12 + 2], 0.0);
}

}  // namespace
}  // namespace qem
