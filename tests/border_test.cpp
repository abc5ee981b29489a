// Exact borders (core/border_placement.h), the refit that fits only what survives, and the
// distance bound (SimplifyOptions::max_distance, core/distance_bound.h): issue 21.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <map>
#include <numbers>
#include <set>
#include <string>
#include <vector>

#include "qem/error.h"
#include "qem/io.h"
#include "qem/measure.h"
#include "qem/simplify.h"
#include "mesh_checks.h"
#include "test_meshes.h"

namespace qem {
namespace {

using Point = std::array<double, 3>;

Point vertex(const Mesh& m, std::size_t v) {
  return {m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]};
}

/// The vertices on an edge that one face has (or more than two).
std::set<std::uint32_t> border_vertices(const Mesh& m) {
  std::set<std::uint32_t> out;
  for (const auto& [edge, n] : test::edge_face_counts(m))
    if (n != 2) out.insert(edge.first), out.insert(edge.second);
  return out;
}

/// Bumps inside the unit square, exactly 0 on its border (the factors x (1 - x) y (1 - y) are).
double bumps(double x, double y) {
  return 4 * x * (1 - x) * y * (1 - y) * (0.05 + 0.03 * std::sin(9 * x) * std::cos(7 * y));
}

// The default options (exact borders: SimplifyOptions::exact_border) with the given refit.
SimplifyOptions defaults_with_refit(unsigned rounds, double points_per_vertex) {
  SimplifyOptions o;  // exact borders are the default
  o.refit_rounds = rounds;
  o.refit_points_per_vertex = points_per_vertex;
  return o;
}

struct RefitCase {
  const char* name;
  unsigned rounds;
  double points_per_vertex;
};

class BumpySquare : public ::testing::TestWithParam<RefitCase> {};

// Issue 21: with GH97's penalty the border moved up to 3e-4 off the plane and off the square's
// edges and no corner stayed. Exact borders: every output border vertex lies on z = 0 and on an
// edge of the square, bit for bit, and the four corners are there.
TEST_P(BumpySquare, KeepsItsBorderAndCornersExactly) {
  const Mesh in = test::height_field(40, bumps);
  SimplifyOptions o = defaults_with_refit(GetParam().rounds, GetParam().points_per_vertex);
  o.target_ratio = 0.05;
  const SimplifyResult r = simplify(in, o);
  ASSERT_LE(r.mesh.face_count(), std::size_t(0.05 * double(in.face_count())));
  const std::set<std::uint32_t> border = border_vertices(r.mesh);
  ASSERT_GE(border.size(), 4u);
  std::set<Point> corners;
  for (std::uint32_t v : border) {
    const Point p = vertex(r.mesh, v);
    EXPECT_EQ(p[2], 0.0) << "vertex " << v;
    EXPECT_TRUE(p[0] == 0 || p[0] == 1 || p[1] == 0 || p[1] == 1) << "vertex " << v << " at " << p[0] << ", " << p[1];
    if ((p[0] == 0 || p[0] == 1) && (p[1] == 0 || p[1] == 1)) corners.insert(p);
  }
  EXPECT_EQ(corners.size(), 4u);
}

INSTANTIATE_TEST_SUITE_P(Borders, BumpySquare,
                         ::testing::Values(RefitCase{"NoRefit", 0, 0}, RefitCase{"LightRefit", 1, 2},
                                           RefitCase{"FullRefit", 3, 0}),
                         [](const auto& info) { return std::string(info.param.name); });

// GH97's penalty is still there for who asks (exact_border = false): its border vertices leave the
// input's (the drift issue 21 measured), which the exact rule above forbids.
TEST(Borders, PenaltyInsteadOfExactLetsBorderVerticesMove) {
  const Mesh in = test::height_field(40, bumps);
  SimplifyOptions o;
  o.target_ratio = 0.05;
  o.exact_border = false;
  const SimplifyResult r = simplify(in, o);
  std::set<Point> inputs;
  for (std::size_t v = 0; v < in.vertex_count(); ++v) inputs.insert(vertex(in, v));
  std::size_t moved = 0;
  for (std::uint32_t v : border_vertices(r.mesh)) moved += !inputs.count(vertex(r.mesh, v));
  EXPECT_GT(moved, 0u);
}

// meshoptimizer's tiny flat square: the default refit alone moved its corners 5-6e-4 off the plane.
TEST(Borders, TinyFlatSquareKeepsItsCorners) {
  const Mesh in = test::grid(3);
  for (const RefitCase& c : {RefitCase{"", 0, 0}, RefitCase{"", 1, 2}, RefitCase{"", 3, 0}}) {
    SimplifyOptions o = defaults_with_refit(c.rounds, c.points_per_vertex);
    o.target_faces = 2;
    const SimplifyResult r = simplify(in, o);
    EXPECT_EQ(r.mesh.face_count(), 2u);
    std::set<Point> out;
    for (std::size_t v = 0; v < r.mesh.vertex_count(); ++v) {
      out.insert(vertex(r.mesh, v));
      EXPECT_EQ(vertex(r.mesh, v)[2], 0.0);
    }
    for (const Point& corner : {Point{0, 0, 0}, Point{1, 0, 0}, Point{0, 1, 0}, Point{1, 1, 0}})
      EXPECT_EQ(out.count(corner), 1u) << corner[0] << ", " << corner[1] << " (refit rounds " << c.rounds << ")";
  }
}

// A half disc: a polar grid of rings r = i / 12 over angles [0, pi], bumpy inside and flat on its
// border. The arc is finely sampled (no corner but its two ends, where it turns into the straight
// row through the centre), so its vertices are free to slide along it.
Mesh half_disc() {
  Mesh in;
  const int rings = 12, steps = 120;
  in.positions = {0.0, 0.0, 0.0};
  for (int i = 1; i <= rings; ++i)
    for (int j = 0; j <= steps; ++j) {
      const double r = double(i) / rings, a = 3.14159265358979 * j / steps;
      in.positions.insert(in.positions.end(), {r * std::cos(a), r * std::sin(a), 0.02 * std::sin(5 * r) * r * (1 - r)});
    }
  const auto id = [&](int i, int j) { return i == 0 ? 0u : std::uint32_t(1 + (i - 1) * (steps + 1) + j); };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < steps; ++j) {
      if (i == 0) {
        in.indices.insert(in.indices.end(), {id(0, 0), id(1, j), id(1, j + 1)});
        continue;
      }
      in.indices.insert(in.indices.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      in.indices.insert(in.indices.end(), {id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return in;
}

/// The edges that one face of `m` has.
std::vector<std::pair<Point, Point>> border_edges(const Mesh& m) {
  std::vector<std::pair<Point, Point>> out;
  for (const auto& [edge, n] : test::edge_face_counts(m))
    if (n == 1) out.push_back({vertex(m, edge.first), vertex(m, edge.second)});
  return out;
}

/// Distance from p to the nearest of `edges` (segments).
double distance_to_edges(const Point& p, const std::vector<std::pair<Point, Point>>& edges) {
  double best = HUGE_VAL;
  for (const auto& [a, b] : edges) {
    double ab2 = 0, t = 0;
    for (int k = 0; k < 3; ++k) ab2 += (b[k] - a[k]) * (b[k] - a[k]), t += (p[k] - a[k]) * (b[k] - a[k]);
    t = ab2 > 0 ? std::clamp(t / ab2, 0.0, 1.0) : 0;
    double d2 = 0;
    for (int k = 0; k < 3; ++k) d2 += (a[k] + t * (b[k] - a[k]) - p[k]) * (a[k] + t * (b[k] - a[k]) - p[k]);
    best = std::min(best, std::sqrt(d2));
  }
  return best;
}

// Every output border vertex of the half disc lies on the input's border polyline (to rounding:
// 1e-12 of the bounding-box diagonal, which is 2), never on a chord or off the plane, and the
// arc's two ends (corners) stay bit for bit.
TEST(Borders, CurvedBorderVerticesStayOnTheInputBorder) {
  const Mesh in = half_disc();
  const std::vector<std::pair<Point, Point>> in_border = border_edges(in);
  for (const RefitCase& c : {RefitCase{"", 0, 0}, RefitCase{"", 1, 2}}) {
    SimplifyOptions o = defaults_with_refit(c.rounds, c.points_per_vertex);
    o.target_ratio = 0.05;
    const SimplifyResult r = simplify(in, o);
    EXPECT_LE(r.mesh.face_count(), std::size_t(0.05 * double(in.face_count())));
    for (std::uint32_t v : border_vertices(r.mesh))
      EXPECT_LE(distance_to_edges(vertex(r.mesh, v), in_border), 2e-12) << "vertex " << v;
    std::set<Point> out;
    for (std::size_t v = 0; v < r.mesh.vertex_count(); ++v) out.insert(vertex(r.mesh, v));
    EXPECT_EQ(out.count(Point{1, 0, 0}), 1u);
    EXPECT_EQ(out.count(vertex(in, in.vertex_count() - 1)), 1u);  // (-1, 0, 0) as the input has it
  }
}

// A border vertex may slide along its polyline (issue 21): on the half disc some output border
// vertices are not input vertices, and each such one lies on an input border edge (within 1e-12
// of the diagonal), between its ends.
TEST(Borders, SlidBorderVertexLiesOnAnInputBorderEdge) {
  const Mesh in = half_disc();
  const std::vector<std::pair<Point, Point>> in_border = border_edges(in);
  std::set<Point> inputs;
  for (std::size_t v = 0; v < in.vertex_count(); ++v) inputs.insert(vertex(in, v));
  SimplifyOptions o;
  o.exact_border = true;
  o.target_ratio = 0.05;
  o.refit_rounds = 0;
  const SimplifyResult r = simplify(in, o);
  std::size_t slid = 0;
  for (std::uint32_t v : border_vertices(r.mesh)) {
    const Point p = vertex(r.mesh, v);
    if (inputs.count(p)) continue;
    ++slid;
    EXPECT_LE(distance_to_edges(p, in_border), 2e-12) << "vertex " << v;
  }
  EXPECT_GT(slid, 0u);
}

// A bumpy annulus around a star-shaped hole: rings from the hole's rim, r = 0.35 + 0.12 cos(5 a),
// out to the unit circle. The rim's five lobes give it concave stretches, where a border edge
// that skips rim vertices runs across the hole; both loops are smooth (no corner), so every
// border vertex may slide or go.
Mesh star_hole_annulus() {
  Mesh in;
  const int rings = 12, steps = 160;
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j < steps; ++j) {
      const double a = 2 * std::numbers::pi * j / steps, rim = 0.35 + 0.12 * std::cos(5 * a);
      const double r = rim + (1 - rim) * i / rings;
      in.positions.insert(in.positions.end(), {r * std::cos(a), r * std::sin(a), 0.03 * std::sin(7 * r) * std::cos(3 * a)});
    }
  const auto id = [&](int i, int j) { return std::uint32_t(i * steps + (j % steps)); };
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < steps; ++j) {
      in.indices.insert(in.indices.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      in.indices.insert(in.indices.end(), {id(i, j), id(i + 1, j + 1), id(i, j + 1)});
    }
  return in;
}

// The border vertices of m, as points.
std::vector<Point> border_points(const Mesh& m) {
  std::vector<Point> out;
  for (std::uint32_t v : border_vertices(m)) out.push_back(vertex(m, v));
  return out;
}

// `in` simplified to `ratio` with default (exact) borders and no refit: the border as the
// contractions left it.
SimplifyResult contracted_only(const Mesh& in, double ratio) {
  SimplifyOptions o;
  o.target_ratio = ratio;
  o.refit_rounds = 0;
  return simplify(in, o);
}

// The farthest of `points` from the nearest of `edges`.
double farthest_from_edges(const std::vector<Point>& points, const std::vector<std::pair<Point, Point>>& edges) {
  double farthest = 0;
  for (const Point& p : points) farthest = std::max(farthest, distance_to_edges(p, edges));
  return farthest;
}

// A border edge of the output is a chord across the input border between its ends: the input
// border vertices it replaces lie at most the run's error from it (core/border_placement.h,
// chord_error). GH97's boundary planes alone priced only how far the new vertex left the planes
// of the removed border edges: rim vertices of the star's lobes lay 2.1 (10 %) and 4.4 (3 %)
// times the run's largest contraction error (r.max_error) from the output border, the faces on
// those chords covering part of the hole (the bunny's base at 1 %: Hausdorff 1.31x
// meshoptimizer's). Now the bound holds and is what limits: the farthest comes within 1 % of it.
TEST(Borders, InputBorderLiesWithinTheErrorOfItsChords) {
  const Mesh in = star_hole_annulus();
  const std::vector<Point> in_border = border_points(in);
  ASSERT_EQ(in_border.size(), 320u);
  for (double ratio : {0.1, 0.03}) {
    const SimplifyResult r = contracted_only(in, ratio);
    ASSERT_LE(r.mesh.face_count(), std::size_t(ratio * double(in.face_count())));
    const std::vector<std::pair<Point, Point>> out_border = border_edges(r.mesh);
    ASSERT_LT(out_border.size(), 160u);  // the borders lost vertices
    const double farthest = farthest_from_edges(in_border, out_border);
    // 1e-9 of the diagonal (about 2) for rounding: sqrt of a quadric error is not exact.
    EXPECT_LE(farthest, r.max_error + 2e-9) << "ratio " << ratio;
    EXPECT_GT(farthest, 0.5 * r.max_error) << "ratio " << ratio;  // the chords do cut the border
  }
}

// The bumpy unit square (bumps) as a 24 x 24 grid with an L-shaped zero-width slit cut along grid
// lines: from tip (4, 12) to the bend (12, 12) and on to tip (12, 4). The slit's vertices but the
// tips are two vertices at one position, the faces inside the L on the second: one border loop of
// 32 edges whose two sides coincide (the Stanford dragon has 407 such loops, issue 21).
Mesh square_with_slit() {
  Mesh in;
  const int n = 24;
  const auto id = [&](int i, int j) { return std::uint32_t(j * (n + 1) + i); };
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double x = double(i) / n, y = double(j) / n;
      in.positions.insert(in.positions.end(), {x, y, bumps(x, y)});
    }
  // The second vertex of each slit vertex but the tips.
  std::map<std::uint32_t, std::uint32_t> twin;
  const auto add_twin = [&](int i, int j) {
    twin[id(i, j)] = std::uint32_t(in.positions.size() / 3);
    const Point p = vertex(in, id(i, j));
    in.positions.insert(in.positions.end(), p.begin(), p.end());
  };
  for (int i = 5; i <= 12; ++i) add_twin(i, 12);
  for (int j = 5; j < 12; ++j) add_twin(12, j);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const bool inside = i < 12 && j < 12;  // the cell is inside the L: its slit vertices are twins
      const auto v = [&](int a, int b) {
        const auto t = twin.find(id(a, b));
        return inside && t != twin.end() ? t->second : id(a, b);
      };
      in.indices.insert(in.indices.end(), {v(i, j), v(i + 1, j), v(i + 1, j + 1)});
      in.indices.insert(in.indices.end(), {v(i, j), v(i + 1, j + 1), v(i, j + 1)});
    }
  return in;
}

// The chord bound holds on a zero-width slit (core/border_placement.cpp, border_between's `avoid`): every
// input border vertex, the slit's tips and bend included, lies within the run's error of the
// output border. On the dragon, where few vertices of a slit's loop were left, chord_error measured
// the input border a contraction removed the shorter way round the loop, through the side it kept,
// so a slit's bend went at almost no cost (10 %: 1.8e-4 from the output, Hausdorff 1.62x CGAL's
// GH-plane). This small slit does not reach that state (it holds before the fix too): it guards
// the bound on slits, two sides at one position, with the way now chosen by direction.
TEST(Borders, SlitTipsAndBendStayWithinTheError) {
  const Mesh in = square_with_slit();
  const std::vector<Point> in_border = border_points(in);
  ASSERT_EQ(in_border.size(), 96u + 32u);
  for (double ratio : {0.2, 0.1, 0.05}) {
    const SimplifyResult r = contracted_only(in, ratio);
    ASSERT_LE(r.mesh.face_count(), std::size_t(ratio * double(in.face_count())));
    const std::vector<std::pair<Point, Point>> out_border = border_edges(r.mesh);
    ASSERT_LT(out_border.size(), 96u + 32u);  // the borders lost vertices
    const double farthest = farthest_from_edges(in_border, out_border);
    // 1e-9 of the diagonal (about 1.4) for rounding: sqrt of a quadric error is not exact.
    EXPECT_LE(farthest, r.max_error + 2e-9) << "ratio " << ratio;
    for (const Point& tip : {vertex(in, 12 * 25 + 4), vertex(in, 4 * 25 + 12), vertex(in, 12 * 25 + 12)})
      EXPECT_LE(distance_to_edges(tip, out_border), r.max_error + 2e-9) << "ratio " << ratio;
  }
}

// A border vertex contracted with an interior vertex may slide along its own polyline
// (border_placement.h, place_on_own_border), not only stay. Every other border vertex of the half
// disc is locked (a hard corner), so no border vertex can slide along a border edge: an unlocked
// one either stays, goes into a locked neighbour, or slides with an interior vertex. Some do, and
// each lies on an input border edge.
TEST(Borders, BorderVertexSlidesWithAnInteriorOne) {
  const Mesh in = half_disc();
  const std::vector<std::pair<Point, Point>> in_border = border_edges(in);
  std::set<Point> inputs;
  for (std::size_t v = 0; v < in.vertex_count(); ++v) inputs.insert(vertex(in, v));
  std::vector<std::uint8_t> lock(in.vertex_count(), 0);
  std::set<std::uint32_t> on_border;
  for (const auto& [edge, n] : test::edge_face_counts(in))
    if (n == 1) on_border.insert(edge.first), on_border.insert(edge.second);
  for (std::uint32_t v : on_border) lock[v] = v % 2;
  SimplifyOptions o;
  o.target_ratio = 0.1;
  o.refit_rounds = 0;
  o.vertex_lock = lock;
  const SimplifyResult r = simplify(in, o);
  std::size_t slid = 0;
  for (std::uint32_t v : border_vertices(r.mesh)) {
    const Point p = vertex(r.mesh, v);
    EXPECT_LE(distance_to_edges(p, in_border), 2e-12) << "vertex " << v;
    slid += !inputs.count(p);
  }
  EXPECT_GT(slid, 0u);
}

TEST(Borders, FanHubKeepsTheBorderExact) {
  // A disc fanned from one hub (a triangulated n-gon, as the readers make of a polygon): every
  // border vertex pairs with the hub, whose faces are too many to test each slide against, so
  // they stay at their input places; the border stays on the input circle's polyline and the
  // run reaches its target.
  const std::uint32_t n = 400;
  Mesh in;
  in.positions = {0, 0, 0.1};
  for (std::uint32_t i = 0; i < n; ++i) {
    const double t = 2 * std::numbers::pi * i / n;
    in.positions.insert(in.positions.end(), {std::cos(t), std::sin(t), 0});
  }
  for (std::uint32_t i = 0; i < n; ++i) in.indices.insert(in.indices.end(), {0, 1 + i, 1 + (i + 1) % n});
  const std::vector<std::pair<Point, Point>> in_border = border_edges(in);
  SimplifyOptions o;
  o.target_faces = 40;
  const SimplifyResult r = simplify(in, o);
  EXPECT_LE(r.mesh.face_count(), 40u);
  EXPECT_EQ(test::validity_problem(r.mesh), "");
  const std::set<std::uint32_t> rim = border_vertices(r.mesh);
  EXPECT_GE(rim.size(), 3u);
  for (std::uint32_t v : rim) EXPECT_LE(distance_to_edges(vertex(r.mesh, v), in_border), 2e-12) << "vertex " << v;
}

/// The bumpy square (20 x 20 cells) with two square holes: a small one (cell 4, 4) and a large one
/// (cells 10-14 in both directions).
Mesh square_with_holes() {
  const int n = 20;
  const Mesh grid = test::height_field(n, bumps);
  Mesh in;
  in.positions = grid.positions;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      if ((i == 4 && j == 4) || (i >= 10 && i < 15 && j >= 10 && j < 15)) continue;
      const std::size_t f = 2 * std::size_t(j * n + i);
      in.indices.insert(in.indices.end(), grid.indices.begin() + 3 * f, grid.indices.begin() + 3 * (f + 2));
    }
  return in;
}

/// How many border loops m has (each vertex on two border edges, as in square_with_holes' output).
std::size_t border_loops(const Mesh& m) {
  std::map<std::uint32_t, std::vector<std::uint32_t>> next;
  for (const auto& [edge, n] : test::edge_face_counts(m))
    if (n == 1) next[edge.first].push_back(edge.second), next[edge.second].push_back(edge.first);
  std::set<std::uint32_t> seen;
  std::size_t loops = 0;
  for (const auto& [start, unused] : next) {
    if (seen.count(start)) continue;
    ++loops;
    std::vector<std::uint32_t> stack{start};
    while (!stack.empty()) {
      const std::uint32_t v = stack.back();
      stack.pop_back();
      if (!seen.insert(v).second) continue;
      for (std::uint32_t w : next[v]) stack.push_back(w);
    }
  }
  return loops;
}

// Small holes close at the scale of the error (border_placement.h, hole_closed_by): with the error
// bounded by 0.1, the hole of half-diagonal 0.035 closes, the one of 0.18 stays with its four
// corners bit for bit (their size, 0.18, is above the bound too), and so do the square's.
TEST(Borders, SmallHoleClosesBelowTheErrorLargeOneStaysExact) {
  const Mesh in = square_with_holes();
  ASSERT_EQ(border_loops(in), 3u);
  SimplifyOptions o;
  o.target_faces = 0;  // as far as the checks allow
  o.max_error = 0.1;
  const SimplifyResult r = simplify(in, o);
  EXPECT_EQ(border_loops(r.mesh), 2u);
  std::set<Point> out;
  for (std::size_t v = 0; v < r.mesh.vertex_count(); ++v) out.insert(vertex(r.mesh, v));
  for (double x : {0.0, 1.0})
    for (double y : {0.0, 1.0}) EXPECT_EQ(out.count(Point{x, y, 0.0}), 1u) << x << ", " << y;
  for (int i : {10, 15})
    for (int j : {10, 15}) EXPECT_EQ(out.count(vertex(in, std::size_t(j * 21 + i))), 1u) << i << ", " << j;
  const std::vector<std::pair<Point, Point>> in_border = border_edges(in);
  for (std::uint32_t v : border_vertices(r.mesh))
    EXPECT_LE(distance_to_edges(vertex(r.mesh, v), in_border), 2e-12) << "vertex " << v;
  // Below the hole's size the hole stays: an error bound of 0.02 keeps all three loops.
  o.max_error = 0.02;
  EXPECT_EQ(border_loops(simplify(in, o).mesh), 3u);
}

// The Stanford bunny (5 jagged scan holes) to 100 faces with the default exact borders: before the
// corners went at the scale of the error it stopped at 126 faces (issue 21). Every output border
// vertex lies on an input border edge.
TEST(Borders, ScanWithJaggedHolesReachesACoarseTarget) {
  const std::string path = test::shared_data("gh_bunny_zipper.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/data not found";
  const Mesh in = load_mesh(path);
  SimplifyOptions o;
  o.target_faces = 100;
  const SimplifyResult r = simplify(in, o);
  EXPECT_LE(r.mesh.face_count(), 100u);
  EXPECT_GE(r.mesh.face_count(), 98u);
  const std::vector<std::pair<Point, Point>> in_border = border_edges(in);
  double diag2 = 0;
  for (int k = 0; k < 3; ++k) {
    double lo = HUGE_VAL, hi = -HUGE_VAL;
    for (std::size_t v = 0; v < in.vertex_count(); ++v) lo = std::min(lo, in.positions[3 * v + k]), hi = std::max(hi, in.positions[3 * v + k]);
    diag2 += (hi - lo) * (hi - lo);
  }
  for (std::uint32_t v : border_vertices(r.mesh))
    EXPECT_LE(distance_to_edges(vertex(r.mesh, v), in_border), 1e-12 * std::sqrt(diag2)) << "vertex " << v;
}

// The command line: exact borders by default and with --exact-borders; --penalty-borders, or
// --boundary-weight given alone, asks for GH97's penalty; the two border flags together are refused.
TEST(Borders, CommandLineChoosesExactOrPenalty) {
  const std::string dir = test::temp_dir() + "/border_cli";
  std::filesystem::create_directories(dir);
  const std::string in = dir + "/in.obj";
  save_mesh(in, test::height_field(20, bumps));
  const auto out = [&](const std::string& name, const std::string& flags) {
    EXPECT_EQ(test::run_qem_quietly("simplify " + in + " " + dir + "/" + name + ".obj --faces 40 " + flags), 0) << flags;
    return test::slurp(dir + "/" + name + ".obj");
  };
  const std::string exact = out("default", ""), penalty = out("penalty", "--penalty-borders");
  EXPECT_FALSE(exact.empty());
  EXPECT_NE(exact, penalty);
  EXPECT_EQ(out("exact", "--exact-borders"), exact);
  EXPECT_EQ(out("weight", "--boundary-weight 1"), penalty);
  EXPECT_EQ(out("both", "--exact-borders --boundary-weight 1"), exact);
  EXPECT_NE(test::run_qem_quietly("simplify " + in + " " + dir + "/x.obj --faces 40 --exact-borders --penalty-borders"), 0);
}

/// A closed unit cube whose sides are n x n grids, and a small sphere (radius 0.05) floating
/// 0.15 above the middle of its top: simplified to a few faces, the sphere contracts away (or,
/// kept as a component, stays on its own), and the cube's top is what survives above it.
Mesh cube_and_floating_sphere(int n) {
  Mesh m;
  std::map<std::array<int, 3>, std::uint32_t> index;
  const auto at = [&](std::array<int, 3> p) {
    auto [it, fresh] = index.try_emplace(p, std::uint32_t(m.vertex_count()));
    if (fresh) m.positions.insert(m.positions.end(), {double(p[0]) / n, double(p[1]) / n, double(p[2]) / n});
    return it->second;
  };
  for (int axis = 0; axis < 3; ++axis)
    for (int side = 0; side <= 1; ++side) {
      const int u = (axis + 1) % 3, w = (axis + 2) % 3;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          std::array<int, 3> p[4];
          for (int k = 0; k < 4; ++k) {
            p[k][axis] = side * n;
            p[k][u] = i + (k == 1 || k == 2);
            p[k][w] = j + (k >= 2);
          }
          std::uint32_t q[4] = {at(p[0]), at(p[1]), at(p[2]), at(p[3])};
          if (side == 0) std::swap(q[1], q[3]);  // outward on both sides
          m.indices.insert(m.indices.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
        }
    }
  return test::concatenated(m, test::transformed(test::icosphere(2), 0.05, 0.5, 0.5, 1.2));
}

// Issue 21's vanished surface: the refit fitted the survivor to the input vertices of faces that
// were contracted away and moved it off the input. Here the sphere's points do not pull the
// cube's top: every vertex of the cube stays on the input surface after the refit.
TEST(Refit, VanishedSurfaceDoesNotPullTheSurvivor) {
  const Mesh in = cube_and_floating_sphere(8);
  for (const RefitCase& c : {RefitCase{"", 1, 2}, RefitCase{"", 3, 0}}) {
    SimplifyOptions o = defaults_with_refit(c.rounds, c.points_per_vertex);
    o.target_faces = 16;
    const SimplifyResult r = simplify(in, o);
    MeasureOptions mo;
    mo.samples = 20000;
    mo.per_vertex = true;
    const MeasureResult m = measure(in, r.mesh, mo);
    std::size_t on_cube = 0;
    for (std::size_t v = 0; v < r.mesh.vertex_count(); ++v) {
      const Point p = vertex(r.mesh, v);
      if (p[2] > 1.01) continue;  // what is left of the sphere
      ++on_cube;
      EXPECT_LT(m.vertex_distance[v], 1e-9) << "vertex " << v << " at " << p[0] << ", " << p[1] << ", " << p[2]
                                             << " (refit rounds " << c.rounds << ")";
    }
    EXPECT_GE(on_cube, 8u);
  }
}

// The distance bound holds: the measured one-sided Hausdorff distance (output to input) never
// exceeds D, with and without the refit, absolute and relative; the result reports the
// distance it reached and the contractions it refused.
TEST(MaxDistance, HoldsWithAndWithoutRefit) {
  const Mesh in = test::height_field(40, bumps);
  for (const double d : {0.002, 0.005, 0.02})
    for (const RefitCase& c : {RefitCase{"", 0, 0}, RefitCase{"", 1, 2}, RefitCase{"", 3, 0}}) {
      SimplifyOptions o = defaults_with_refit(c.rounds, c.points_per_vertex);
      o.max_distance = d;
      const SimplifyResult r = simplify(in, o);
      EXPECT_LT(r.mesh.face_count(), in.face_count() / 8) << "d " << d;
      EXPECT_GT(r.rejected_distance, 0u);
      EXPECT_LE(r.output_to_input_distance, d);
      EXPECT_GT(r.output_to_input_distance, 0.0);
      MeasureOptions mo;
      mo.samples = 200000;
      const MeasureResult m = measure(in, r.mesh, mo);
      EXPECT_LE(m.h_approx_to_original, d) << "d " << d << ", refit rounds " << c.rounds;
    }
}

TEST(MaxDistance, RelativeToTheDiagonalAtAnyScale) {
  const Mesh in = test::height_field(30, bumps);
  const Mesh big = test::transformed(in, 1000, 5e4, -3e4, 7);
  SimplifyOptions o;
  o.max_distance = 0.004;
  o.max_distance_is_relative = true;
  const SimplifyResult small = simplify(in, o), large = simplify(big, o);
  // (The face counts can differ: a certificate on the bound's edge can go either way with the last
  // bit of the coordinates, and the contractions after it differ. The bound holds at both scales.)
  EXPECT_GT(small.mesh.face_count(), 0u);
  EXPECT_GT(large.mesh.face_count(), 0u);
  MeasureOptions mo;
  mo.samples = 100000;
  const MeasureResult ms = measure(in, small.mesh, mo), ml = measure(big, large.mesh, mo);
  EXPECT_LE(ms.h_approx_to_original, 0.004 * ms.bbox_diag);
  EXPECT_LE(ml.h_approx_to_original, 0.004 * ml.bbox_diag);
}

TEST(MaxDistance, RefusesANonPositiveBound) {
  SimplifyOptions o;
  o.target_ratio = 0.5;
  o.max_distance = 0;
  EXPECT_THROW(simplify(test::grid(4), o), Error);
}

}  // namespace
}  // namespace qem

namespace qem {
namespace {

// The corpus side of the distance bound, on a few small meshes of ../shared/data (a wall with a hole,
// a closed model, a multi-part one) at three bounds: the measured one-sided Hausdorff distance
// (output to input, as `qem measure`) never exceeds D, with the command line's default refit.
class MaxDistanceCorpus : public ::testing::TestWithParam<std::string> {};

TEST_P(MaxDistanceCorpus, MeasuredDistanceNeverExceedsTheBound) {
  const std::string path = test::shared_data(GetParam());
  if (path.empty()) GTEST_SKIP() << "../shared/data not found";
  const Mesh in = load_mesh(path);
  for (const double d : {0.001, 0.003, 0.01}) {
    SimplifyOptions o;
    o.max_distance = d;
    o.max_distance_is_relative = true;
    o.refit_rounds = 2;
    o.refit_points_per_vertex = 8;
    const SimplifyResult r = simplify(in, o);
    MeasureOptions mo;
    mo.samples = 300000;
    const MeasureResult m = measure(in, r.mesh, mo);
    EXPECT_LT(r.mesh.face_count(), in.face_count()) << "d " << d;
    EXPECT_LE(m.h_approx_to_original, d * m.bbox_diag) << GetParam() << " d " << d << ": " << r.mesh.face_count() << " faces";
  }
}

INSTANTIATE_TEST_SUITE_P(SharedData, MaxDistanceCorpus,
                         ::testing::Values("tiny_wallhole_linecont.obj", "gh_cow.obj", "gh_foot_bones.off"),
                         [](const auto& info) {
                           std::string name = info.param;
                           for (char& ch : name)
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           return name;
                         });

}  // namespace
}  // namespace qem
