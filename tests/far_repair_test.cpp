// Tests of the repair of the far places after the run (core/far_repair.h,
// SimplifyOptions::far_repair): an edge across a groove is flipped onto it, an edge that already
// lies on the input is left, held vertices keep their edges and positions, no flip raises the
// error of the attributes, a vertex under a cut-off bump moves onto it, and on real
// simplifications the repair never folds a face, never makes an edge non-manifold or changes the
// topology, moves no border vertex and does not raise the largest distance to the input.
#include "core/far_repair.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <vector>

#include "core/distance_bound.h"
#include "core/valid_pairs.h"
#include "geometry/frame.h"
#include "measure/bvh.h"
#include "measure/point_triangle.h"
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

// The groove with a vertex e in the middle of its floor, and colours: the approximation's banks
// a, b are green, its floor's ends c, d red; e is of the colour given. Before the flip e's colour
// is read from the middle of a-b (green), after it from the middle of c-d (red).
struct ColouredGroove : Groove {
  explicit ColouredGroove(const std::array<double, 3>& e) {
    input.positions.insert(input.positions.end(), {0.5, 0.5, -0.05});
    input.indices = {0, 3, 4, 0, 4, 2, 1, 2, 4, 1, 4, 3};
    const std::vector<double> green = {0, 1, 0}, red = {1, 0, 0};
    VertexAttribute in{"COLOR_0", AttributeKind::Color, 3, {}}, out = in;
    for (const std::vector<double>* c : {&green, &green, &red, &red}) out.values.insert(out.values.end(), c->begin(), c->end());
    in.values = out.values;
    in.values.insert(in.values.end(), e.begin(), e.end());
    input.attributes = {in};
    approx.attributes = {out};
  }
  core::FarRepairResult repair() {
    source = {0, 1, 2, 3, 4};
    core::FarRepairOptions o;
    o.input_attributes = input.attributes;
    o.point_source = source;
    o.input_faces = input.indices;
    return flip(approx, input, o);
  }
  std::vector<std::uint32_t> source;
};

TEST(FarRepair, NoFlipRaisesTheErrorOfAppearance) {
  // e green: the flip onto the floor would paint it red; refused, though it brings the surface
  // onto the input.
  ColouredGroove green({0, 1, 0});
  EXPECT_EQ(green.repair().flips, 0u);
  EXPECT_TRUE(has_edge(green.approx, 0, 1));
  // e red: the flip lowers both errors; made.
  ColouredGroove red({1, 0, 0});
  EXPECT_EQ(red.repair().flips, 1u);
  EXPECT_TRUE(has_edge(red.approx, 2, 3));
  // Without the input's attributes, geometry alone judges: made.
  ColouredGroove blind({0, 1, 0});
  EXPECT_EQ(flip(blind.approx, blind.input).flips, 1u);
  // A channel the metric does not weigh (skin joints) judges nothing.
  ColouredGroove joints({0, 1, 0});
  joints.input.attributes[0].kind = joints.approx.attributes[0].kind = AttributeKind::JointIndices;
  EXPECT_EQ(joints.repair().flips, 1u);
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

// The distance from p to the input's border (its edges with one face).
double to_border(const Mesh& input, const double* p) {
  const auto at = [&](std::uint32_t v) { return Vec3{input.positions[3 * v], input.positions[3 * v + 1], input.positions[3 * v + 2]}; };
  double best = HUGE_VAL;
  const Vec3 q{p[0], p[1], p[2]};
  for (const auto& [e, n] : test::edge_face_counts(input)) {
    if (n != 1) continue;
    const Vec3 a = at(e.first), d = at(e.second) - a;
    const double t = std::clamp(dot(q - a, d) / dot(d, d), 0.0, 1.0);
    best = std::min(best, length(q - (a + d * t)));
  }
  return best;
}

TEST(FarRepair, SimplifyFlipsWithoutFoldsTopologyChangesOrFartherPoints) {
  struct Case {
    Mesh input;
    std::size_t faces;
  };
  // (The bumpy sphere and the creased field at 1000 faces each have edges a flip brings closer.)
  const Case cases[] = {{test::height_field(60, creased), 1000}, {test::height_field(60, creased), 60},
                        {outofcore::bumpy_sphere(5000), 500}, {outofcore::bumpy_sphere(5000), 100}};
  std::size_t total_flips = 0, total_moves = 0, total_relocations = 0;
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
    // Only interior vertices moved: the border's stay where they were (without relocations, which
    // may take a border vertex along the border and put a new one on the input's border); every
    // border vertex is on the input's border.
    ASSERT_EQ(a.positions.size(), b.positions.size());
    if (flipped.vertex_relocations == 0) {
      for (std::uint32_t v : border_vertices(a))
        for (int k = 0; k < 3; ++k) EXPECT_EQ(a.positions[3 * v + k], b.positions[3 * v + k]);
    }
    for (std::uint32_t v : border_vertices(b)) EXPECT_LT(to_border(c.input, &b.positions[3 * std::size_t(v)]), 1e-12);
    // A relocation keeps the faces' count, or gives one up (a border split paired with an interior
    // collapse, at most one in 256).
    EXPECT_LE(b.face_count(), a.face_count());
    EXPECT_GE(b.face_count() + a.face_count() / 256, a.face_count());
    total_relocations += flipped.vertex_relocations;
    // Provenance follows: a source for every vertex and face, each face's an input face.
    EXPECT_EQ(flipped.vertex_source.size(), b.vertex_count());
    EXPECT_EQ(flipped.face_source.size(), b.face_count());
    for (std::uint32_t f : flipped.face_source) EXPECT_LT(f, c.input.face_count());
    EXPECT_EQ(test::non_manifold_edges(b), 0u);
    // Same Euler characteristic (V - E + F).
    const auto euler = [](const Mesh& m) {
      return std::ptrdiff_t(m.vertex_count()) - std::ptrdiff_t(test::edge_face_counts(m).size()) + std::ptrdiff_t(m.face_count());
    };
    EXPECT_EQ(euler(a), euler(b));
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
  EXPECT_GT(total_relocations, 0u);
}

// The faces a local search gave each point (FarRepairOptions::point_faces) stand in for the tree's
// only near the output: given the tree's own answers, or for every point its farthest face (which
// sends each one back to the tree), the repair makes what it makes without them.
TEST(FarRepair, GivenFacesStandInForTheTreeOnlyNearTheOutput) {
  const Mesh input = outofcore::bumpy_sphere(5000);
  SimplifyOptions o;
  o.target_faces = 300;
  o.refit_rounds = 2;
  o.threads = 1;
  const Mesh start = simplify(input, o).mesh;
  const measure_detail::TriangleBvh tree(corners_of(start));
  std::vector<std::uint32_t> exact, farthest;
  for (std::size_t p = 0; p < input.vertex_count(); ++p) {
    const double* q = &input.positions[3 * p];
    exact.push_back(tree.closest(q).triangle);
    std::uint32_t far = 0;
    for (std::uint32_t f = 1; f < start.face_count(); ++f)
      if (tree.triangle_d2(q, f) > tree.triangle_d2(q, far)) far = f;
    farthest.push_back(far);
  }
  Mesh plain = start;
  const core::FarRepairResult r = flip(plain, input);
  EXPECT_GT(r.flips + r.moves, 0u);
  for (const std::vector<std::uint32_t>* given : {&exact, &farthest}) {
    core::FarRepairOptions options;
    options.point_faces = *given;
    Mesh repaired = start;
    const core::FarRepairResult g = flip(repaired, input, options);
    EXPECT_EQ(g.flips, r.flips);
    EXPECT_EQ(g.moves, r.moves);
    EXPECT_EQ(repaired.indices, plain.indices);
    EXPECT_EQ(repaired.positions, plain.positions);
  }
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

// Relocations: a tent over the middle of an interior edge of a coarse flat grid (no flip or move
// of that edge's corners brings the grid nearer its top without lifting flat ground), or a bulge
// of the border between two border vertices. A vertex from the flat part of the grid goes to the
// far place: the counts of faces and vertices stay, the largest distance falls, the mesh stays
// valid with its border where it was, and the new vertex stands on the input.
double tent(double x, double y) { return 0.03 * std::max(0.0, 1 - std::hypot(x - 0.3125, y - 0.5) / 0.1); }

core::FarRepairResult relocate(Mesh& approx, const Mesh& input, std::size_t relocations, bool add_vertices = false) {
  std::vector<std::uint32_t> source(input.vertex_count());
  for (std::uint32_t v = 0; v < source.size(); ++v) source[v] = v;
  const std::vector<std::uint8_t> on_border = core::points_on_border(input.indices, source, 1);
  core::FarRepairOptions o;
  o.relocations = relocations;
  o.point_on_border = on_border;
  o.add_vertices = add_vertices;
  return flip(approx, input, o);
}

// The larger of the largest distances from a's faces to the input's and from the input's to a's.
double both_ways(const Mesh& a, const Mesh& input) {
  return std::max(largest_distance(a, core::SurfaceDistance(corners_of(input))),
                  largest_distance(input, core::SurfaceDistance(corners_of(a))));
}

// `grid` relocated against `input`: the far distance falls by a fifth, the counts, the borders and
// the validity stay, the new vertices lie on the input and the border vertices on its border.
void expect_relocated(const Mesh& input, const Mesh& grid) {
  const core::SurfaceDistance surface(corners_of(input));
  Mesh without = grid, with = grid;
  EXPECT_TRUE(relocate(without, input, 0).relocations.empty());
  const core::FarRepairResult r = relocate(with, input, 8);
  ASSERT_GE(r.relocations.size(), 1u);
  EXPECT_EQ(with.face_count(), grid.face_count());
  EXPECT_EQ(with.vertex_count(), grid.vertex_count());
  EXPECT_LT(both_ways(with, input), 0.8 * both_ways(without, input));
  EXPECT_EQ(test::validity_problem(with), "");
  EXPECT_EQ(test::non_manifold_edges(with), 0u);
  EXPECT_EQ(test::boundary_edges(with), test::boundary_edges(grid));
  EXPECT_EQ(folded_edges(with), 0u);
  for (const auto& [e, n] : directed_counts(with)) EXPECT_EQ(n, 1) << "an edge used twice the same way round";
  for (const core::Relocation& rel : r.relocations) {
    EXPECT_NE(rel.removed, rel.kept);
    const double* p = &with.positions[3 * std::size_t(rel.removed)];
    std::uint32_t hint = UINT32_MAX;
    EXPECT_LT(surface.distance({p[0], p[1], p[2]}, &hint), 1e-12);
  }
  // Every border vertex of the result lies on the input's border (the square's outline, or the
  // bulge's), and the corners stay.
  for (std::uint32_t v : border_vertices(with)) {
    const double* p = &with.positions[3 * std::size_t(v)];
    bool on_input = false;
    for (std::uint32_t u : border_vertices(input))
      on_input = on_input || (input.positions[3 * u] == p[0] && input.positions[3 * u + 1] == p[1] && input.positions[3 * u + 2] == p[2]);
    EXPECT_TRUE(on_input) << "border vertex " << v << " at " << p[0] << " " << p[1];
  }
}

TEST(FarRepair, ATentOverAnEdgeGetsAVertexFromTheFlat) {
  const Mesh grid = test::grid(8);
  expect_relocated(test::height_field(64, tent), grid);
  // Without relocations the tent's top stays as far as the moves and flips leave it.
  Mesh kept = grid;
  const core::FarRepairResult r = relocate(kept, test::height_field(64, tent), 0);
  EXPECT_GT(largest_distance(kept, core::SurfaceDistance(corners_of(test::height_field(64, tent)))), 0.01) << r.moves;
}

TEST(FarRepair, ABorderBulgeGetsABorderVertexFromAStraightBorder) {
  // The input's border y = 0 bulges out (in the plane) between the grid's border vertices at
  // x = 0.25 and 0.375; the grid's border edge there is a chord of the bulge.
  Mesh input = test::grid(64);
  for (std::size_t v = 0; v < input.vertex_count(); ++v) {
    double* p = &input.positions[3 * v];
    if (p[1] == 0) p[1] = -0.03 * std::max(0.0, 1 - std::abs(p[0] - 0.3125) / 0.0625);
  }
  expect_relocated(input, test::grid(8));
  // The border points found by the repair when it needs them (find_border_points), as simplify
  // leaves it to do, are those given: the same relocations.
  Mesh given = test::grid(8), found = test::grid(8);
  const core::FarRepairResult r = relocate(given, input, 8);
  std::vector<std::uint32_t> source(input.vertex_count());
  for (std::uint32_t v = 0; v < source.size(); ++v) source[v] = v;
  core::FarRepairOptions o;
  o.relocations = 8;
  o.find_border_points = true;
  o.input_faces = input.indices;
  o.point_source = source;
  EXPECT_EQ(flip(found, input, o).relocations.size(), r.relocations.size());
  EXPECT_EQ(found.indices, given.indices);
  EXPECT_EQ(found.positions, given.positions);
  // Neither given nor to be found: no relocation at the border.
  Mesh none = test::grid(8);
  o.find_border_points = false;
  EXPECT_LT(flip(none, input, o).relocations.size(), r.relocations.size());
}

// A small part kept as one face, as a loose piece of a scan becomes: triangle A, B, C 0.01 above
// the square, over an input patch (the same triangle, divided in 4 a side) that dips toward the
// square along AB. The patch's points near AB are nearer the square's faces than the lone face, so
// the lone face has none of the input's border points of AB among its own.
TEST(FarRepair, ALoneFaceOverADippingPartGetsABorderVertexFromItsPart) {
  constexpr int n = 4;
  const Vec3 a{0.40, 0.40, 0.01}, b{0.48, 0.40, 0.01}, c{0.44, 0.46, 0.01};
  Mesh patch;
  std::vector<std::vector<std::uint32_t>> at(n + 1, std::vector<std::uint32_t>(n + 1));
  for (int i = 0; i <= n; ++i)
    for (int j = 0; i + j <= n; ++j) {
      const double la = double(n - i - j) / n, lb = double(i) / n, lc = double(j) / n;
      const Vec3 p = a * la + b * lb + c * lc;
      at[i][j] = std::uint32_t(patch.vertex_count());
      patch.positions.insert(patch.positions.end(), {p.x, p.y, 0.01 * (1 - 0.95 * 4 * la * lb)});
    }
  for (int i = 0; i < n; ++i)
    for (int j = 0; i + j < n; ++j) {
      patch.indices.insert(patch.indices.end(), {at[i][j], at[i + 1][j], at[i][j + 1]});
      if (i + j + 1 < n) patch.indices.insert(patch.indices.end(), {at[i + 1][j], at[i + 1][j + 1], at[i][j + 1]});
    }
  const Mesh input = test::concatenated(test::grid(64), patch);
  Mesh lone;
  lone.positions = {a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z};
  lone.indices = {0, 1, 2};
  const Mesh approx = test::concatenated(test::grid(8), lone);
  expect_relocated(input, approx);
  // The new vertex is the patch's border vertex at the middle of AB, where the patch dips most.
  Mesh with = approx;
  const core::FarRepairResult r = relocate(with, input, 8);
  ASSERT_GE(r.relocations.size(), 1u);
  const double* p = &with.positions[3 * std::size_t(r.relocations.front().removed)];
  EXPECT_DOUBLE_EQ(p[0], 0.44);
  EXPECT_DOUBLE_EQ(p[1], 0.40);
  EXPECT_NEAR(p[2], 0.0005, 1e-12);
}

// With attributes and materials: the tent again, coloured by a linear field (red = x, green = y,
// blue = 1/2) and of two materials (x below and above 1/2, the boundary's vertices held, as
// simplify holds seams). The new vertex takes the values of the place it divides; each new face is
// of its parent's material; the vertex the relocation takes away is one whose values the others
// interpolate (in a linear field, any; not a spot of another colour).
TEST(FarRepair, RelocationsCarryValuesAndMaterials) {
  const auto paint = [](Mesh& m) {
    VertexAttribute colour{"COLOR_0", AttributeKind::Color, 3, {}};
    for (std::size_t v = 0; v < m.vertex_count(); ++v)
      colour.values.insert(colour.values.end(), {m.positions[3 * v], m.positions[3 * v + 1], 0.5});
    m.attributes = {colour};
    for (std::size_t f = 0; f < m.face_count(); ++f) {
      const std::uint32_t* t = &m.indices[3 * f];
      const double x = (m.positions[3 * t[0]] + m.positions[3 * t[1]] + m.positions[3 * t[2]]) / 3;
      m.face_materials.push_back(x < 0.5 ? 0 : 1);
    }
  };
  Mesh input = test::height_field(64, tent), with = test::grid(8);
  paint(input), paint(with);
  std::vector<std::uint32_t> source(input.vertex_count());
  for (std::uint32_t v = 0; v < source.size(); ++v) source[v] = v;
  const std::vector<std::uint8_t> on_border = core::points_on_border(input.indices, source, 1);
  std::vector<std::uint8_t> held(with.vertex_count(), 0);
  for (std::size_t v = 0; v < held.size(); ++v) held[v] = with.positions[3 * v] == 0.5;
  core::FarRepairOptions o;
  o.relocations = 8;
  o.point_on_border = on_border;
  o.held = held;
  o.input_attributes = input.attributes;
  o.point_source = source;
  o.input_faces = input.indices;
  const double before = both_ways(with, input);
  const core::FarRepairResult r = flip(with, input, o);
  ASSERT_GE(r.relocations.size(), 1u);
  EXPECT_LT(both_ways(with, input), 0.8 * before);
  ASSERT_EQ(with.attributes.size(), 1u);
  ASSERT_EQ(with.attributes[0].values.size(), 3 * with.vertex_count());
  // Each vertex's colour is the field's at its foot on the faces it divided: where earlier splits
  // tilted them over the tent, the foot is off the vertex's own (x, y) by a fraction of the tent's
  // height (0.03); far less than the distance any vertex came from the flat (0.1 and more).
  for (std::size_t v = 0; v < with.vertex_count(); ++v) {
    const double* c = &with.attributes[0].values[3 * v];
    EXPECT_NEAR(c[0], with.positions[3 * v], 0.01) << "vertex " << v;
    EXPECT_NEAR(c[1], with.positions[3 * v + 1], 0.01) << "vertex " << v;
    EXPECT_NEAR(c[2], 0.5, 1e-12);
  }
  ASSERT_EQ(with.face_materials.size(), with.face_count());
  for (std::size_t f = 0; f < with.face_count(); ++f) {
    const std::uint32_t* t = &with.indices[3 * f];
    const double x = (with.positions[3 * t[0]] + with.positions[3 * t[1]] + with.positions[3 * t[2]]) / 3;
    EXPECT_EQ(with.face_materials[f], x < 0.5 ? 0u : 1u) << "face " << f;
  }
  // The vertex the first relocation took away, of another colour in the output, and the input's
  // colours those the output interpolates (so the output has them right, and without the vertex
  // would not): it stays, and another goes.
  Mesh spotted = test::grid(8);
  paint(spotted);
  const std::uint32_t spot = r.relocations.front().removed;
  const double sx = spotted.positions[3 * spot], sy = spotted.positions[3 * spot + 1];
  spotted.attributes[0].values[3 * spot + 2] = 1;
  Mesh spotted_input = input;
  for (std::size_t v = 0; v < spotted_input.vertex_count(); ++v) {
    const double x = spotted_input.positions[3 * v], y = spotted_input.positions[3 * v + 1];
    for (std::size_t f = 0; f < spotted.face_count(); ++f) {
      const std::uint32_t* t = &spotted.indices[3 * f];
      const auto at = [&](int k) { return Vec3{spotted.positions[3 * t[k]], spotted.positions[3 * t[k] + 1], 0}; };
      const std::array<double, 3> w = measure_detail::closest_point_weights({x, y, 0}, at(0), at(1), at(2));
      const Vec3 q = at(0) * w[0] + at(1) * w[1] + at(2) * w[2];
      if (std::hypot(q.x - x, q.y - y) > 1e-12) continue;
      double blue = 0;
      for (int k = 0; k < 3; ++k) blue += w[k] * spotted.attributes[0].values[3 * t[k] + 2];
      spotted_input.attributes[0].values[3 * v + 2] = blue;
      break;
    }
  }
  o.input_attributes = spotted_input.attributes;
  const core::FarRepairResult s = flip(spotted, spotted_input, o);
  ASSERT_GE(s.relocations.size(), 1u);
  EXPECT_NE(s.relocations.front().removed, spot);
  EXPECT_EQ(spotted.positions[3 * spot], sx);
  EXPECT_EQ(spotted.positions[3 * spot + 1], sy);
  EXPECT_EQ(spotted.attributes[0].values[3 * spot + 2], 1);
}

// The repair, relocations only, of the flat grid(8) over `input` (grid(32) with a spike `height`
// high at (0.3125, 0.3125)): the largest distance falls by a fifth, the counts, validity and border
// stay, and the first new vertex stands over the spike's foot, above `low` and below the tip (not
// on the input). Returns the repaired grid.
Mesh expect_spike_lifted_part_of_the_way(const Mesh& input, double height, double low) {
  const Mesh grid = test::grid(8);
  Mesh with = grid;
  std::vector<std::uint32_t> source(input.vertex_count());
  for (std::uint32_t v = 0; v < source.size(); ++v) source[v] = v;
  const std::vector<std::uint8_t> on_border = core::points_on_border(input.indices, source, 1);
  core::FarRepairOptions o;
  o.relocations = 8;
  o.point_on_border = on_border;
  o.move_vertices = false;
  o.relocation_budget = 1;  // a share of the E the grid has, which is the spike's alone
  const double before = both_ways(grid, input);
  EXPECT_NEAR(before, height, 1e-12);
  const core::FarRepairResult r = flip(with, input, o);
  EXPECT_LT(both_ways(with, input), 0.8 * before);
  EXPECT_EQ(with.face_count(), grid.face_count());
  EXPECT_EQ(test::validity_problem(with), "");
  EXPECT_EQ(test::boundary_edges(with), test::boundary_edges(grid));
  if (r.relocations.empty()) {
    ADD_FAILURE() << "no relocation";
    return with;
  }
  const core::Relocation& first = r.relocations.front();
  EXPECT_FALSE(first.at_point);
  const double* p = &with.positions[3 * std::size_t(first.removed)];
  EXPECT_NEAR(p[0], 0.3125, 1e-12);
  EXPECT_NEAR(p[1], 0.3125, 1e-12);
  EXPECT_GT(p[2], low);
  EXPECT_LT(p[2], height);
  return with;
}

// A lone spike: one vertex of a fine flat grid 0.4 above the others (an outlier pixel), under the
// diagonal of a cell of a coarse flat grid. Faces from that cell's corners up to the tip would
// turn by 81 degrees, past the limit of 75, so no vertex stands at the tip; one goes part of the
// way up (half: 73 degrees), which still cuts the largest distance. No vertex moves here (each
// corner of the cell is too far from the tip to lift it without lifting flat ground).
TEST(FarRepair, ALoneSpikeGetsAVertexPartOfTheWayUp) {
  Mesh input = test::grid(32);
  input.positions[3 * (10 * 33 + 10) + 2] = 0.4;  // (0.3125, 0.3125)
  const Mesh with = expect_spike_lifted_part_of_the_way(input, 0.4, 0.05);
  // No face turns past the limit from the flat grid (nor, so, over: the output stays a height
  // field), however many splits were made round the spike. (Its faces may meet at ridges as sharp
  // as the spike's own, so folded_edges, which counts any two faces more than 90 degrees apart,
  // does not apply.)
  for (std::size_t f = 0; f < with.face_count(); ++f) {
    const std::uint32_t* t = &with.indices[3 * f];
    const auto at = [&](int k) { return Vec3{with.positions[3 * t[k]], with.positions[3 * t[k] + 1], with.positions[3 * t[k] + 2]}; };
    const Vec3 n = normalized(cross(at(1) - at(0), at(2) - at(0)));
    EXPECT_GE(n.z, std::cos(75 * std::numbers::pi / 180) - 1e-12) << "face " << f;
  }
}

// A lone spike beside a pit: the spike (0.05 high) is low enough that the faces up to its tip
// would not turn past the limit, but across the cell a 2 x 2 block of the fine grid lies 0.04
// deep, and the faces from the cell's corners to the tip would pass farther above the pit than
// the spike is high: a split to the tip mends nothing, and before part of the way was tried for
// it no relocation was made and the largest distance stayed 0.05 (the terrain's spike by parts,
// docs/benchmarks.md "By parts"). Part of the way up, the faces stay nearer.
TEST(FarRepair, ASpikeBesideAPitGetsAVertexPartOfTheWayUp) {
  Mesh input = test::grid(32);
  input.positions[3 * (10 * 33 + 10) + 2] = 0.05;  // (0.3125, 0.3125)
  for (int j = 8; j <= 9; ++j)
    for (int i = 11; i <= 12; ++i) input.positions[3 * (j * 33 + i) + 2] = -0.04;
  expect_spike_lifted_part_of_the_way(input, 0.05, 0.01);
}

// height_field(n, f) cut along x = 0.5: the faces right of the cut use copies of the vertices on
// it (a crack the mesh never welded).
Mesh cracked(int n, double (*f)(double, double)) {
  Mesh m = test::height_field(n, f);
  std::vector<std::uint32_t> copy(m.vertex_count(), UINT32_MAX);
  const auto column = [&](std::uint32_t v) { return int(v % std::uint32_t(n + 1)); };
  for (std::size_t t = 0; t < m.face_count(); ++t) {
    std::uint32_t* c = &m.indices[3 * t];
    if (std::max({column(c[0]), column(c[1]), column(c[2])}) <= n / 2) continue;
    for (int k = 0; k < 3; ++k) {
      if (column(c[k]) != n / 2) continue;
      if (copy[c[k]] == UINT32_MAX) {
        copy[c[k]] = std::uint32_t(m.vertex_count());
        m.positions.insert(m.positions.end(), {m.positions[3 * c[k]], m.positions[3 * c[k] + 1], m.positions[3 * c[k] + 2]});
      }
      c[k] = copy[c[k]];
    }
  }
  return m;
}
double flat(double, double) { return 0; }
double cone_on_the_cut(double x, double y) { return 0.03 * std::max(0.0, 1 - std::hypot(x - 0.5, y - 0.3125) / 0.0625); }

// The places of the cut's vertices as each side has them.
std::pair<std::vector<std::array<double, 3>>, std::vector<std::array<double, 3>>> sides_of_the_cut(const Mesh& m) {
  std::set<std::uint32_t> left, right;
  for (std::size_t t = 0; t < m.face_count(); ++t) {
    const std::uint32_t* c = &m.indices[3 * t];
    const double x = (m.positions[3 * c[0]] + m.positions[3 * c[1]] + m.positions[3 * c[2]]) / 3;
    for (int k = 0; k < 3; ++k)
      if (m.positions[3 * c[k]] == 0.5) (x < 0.5 ? left : right).insert(c[k]);
  }
  const auto places = [&](const std::set<std::uint32_t>& side) {
    std::vector<std::array<double, 3>> p;
    for (std::uint32_t v : side) p.push_back({m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]});
    std::sort(p.begin(), p.end());
    return p;
  };
  return {places(left), places(right)};
}

TEST(FarRepair, ACracksTwoSidesSplitTogether) {
  // A cone whose top is on the cut, between two of the grid's vertices on it: the far place is an
  // edge of the cut, which both sides have.
  const Mesh input = cracked(64, cone_on_the_cut), grid = cracked(8, flat);
  Mesh without = grid, alone = grid, with = grid;
  EXPECT_TRUE(relocate(without, input, 0).relocations.empty());
  // Without adding a vertex, neither side splits alone: the crack stays closed.
  for (const core::Relocation& r : relocate(alone, input, 8).relocations) EXPECT_EQ(r.added, UINT32_MAX);
  const auto [left_alone, right_alone] = sides_of_the_cut(alone);
  EXPECT_EQ(left_alone, right_alone);
  const core::FarRepairResult r = relocate(with, input, 8, true);
  std::size_t added = 0;
  for (const core::Relocation& rel : r.relocations) added += rel.added != UINT32_MAX;
  ASSERT_GE(added, 1u);
  EXPECT_EQ(with.face_count(), grid.face_count());
  EXPECT_EQ(with.vertex_count(), grid.vertex_count() + added);
  EXPECT_LT(both_ways(with, input), 0.8 * both_ways(without, input));
  EXPECT_EQ(test::validity_problem(with), "");
  const auto [left, right] = sides_of_the_cut(with);
  EXPECT_EQ(left, right);
  EXPECT_GT(left.size(), sides_of_the_cut(grid).first.size());
}

}  // namespace
// The input's border vertices (core::border_vertices, what points_on_border reads) are the ends of
// the edges unique_edges counts once, on any number of threads: on a sphere with holes cut into it
// (several chunks of vertices), a fin on a shared edge (three faces), a face with a repeated
// vertex, a face given twice and a vertex no face uses.
TEST(FarRepair, BorderVerticesAreTheEndsOfSingleFaceEdgesOnAnyThreads) {
  Mesh m = test::icosphere(6);  // 40,962 vertices
  std::vector<std::uint32_t> kept;
  for (std::size_t f = 0; f < m.face_count(); ++f)
    if (f % 97 != 5) kept.insert(kept.end(), &m.indices[3 * f], &m.indices[3 * f] + 3);
  const std::uint32_t a = kept[0], b = kept[1], c = kept[2], n = std::uint32_t(m.vertex_count());
  m.positions.insert(m.positions.end(), {0, 0, 2, 0, 0, 3});  // vertices n (a fin's tip) and n + 1 (unused)
  kept.insert(kept.end(), {a, b, n});  // a third face on edge (a, b)
  kept.insert(kept.end(), {c, c, n});  // a repeated vertex: edge (c, n) counted twice by it
  kept.insert(kept.end(), &kept[30], &kept[33]);  // a face given twice: its edges have 3 faces
  m.indices = kept;
  const std::size_t count = m.vertex_count();
  std::vector<std::uint8_t> expected(count, 0);
  for (const core::Edge& e : core::unique_edges(m.indices, count))
    if (e.faces == 1) expected[e.lo] = expected[e.hi] = 1;
  ASSERT_GT(std::count(expected.begin(), expected.end(), 1), 1000);
  ASSERT_EQ(expected[n + 1], 0);
  for (unsigned threads : {1u, 2u, 3u}) EXPECT_EQ(core::border_vertices(m.indices, count, threads), expected);
}

}  // namespace qem
