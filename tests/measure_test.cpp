// Tests of `qem measure` (GH97 §6.1 metric): exact closed forms, BVH against brute force,
// determinism across seeds and thread counts.
#include "qem/measure.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "core/distance_bound.h"
#include "measure/bvh.h"
#include "measure/point_triangle.h"
#include "measure/rng.h"
#include "measure/surface_sampling.h"
#include "qem/cluster.h"
#include "qem/error.h"
#include "qem/io.h"
#include "test_meshes.h"

namespace qem {
namespace {

using measure_detail::closest_point_on_triangle;
using measure_detail::Vec3;

MeasureOptions with_samples(std::size_t n, unsigned threads = 1) {
  MeasureOptions o;
  o.samples = n;
  o.threads = threads;
  return o;
}

bool bit_equal(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(Measure, PointTriangleRegions) {
  const Vec3 a{0, 0, 0}, b{1, 0, 0}, c{0, 1, 0};
  auto cp = [&](Vec3 p) { return closest_point_on_triangle(p, a, b, c); };
  Vec3 q = cp({0.25, 0.25, 2});  // above the interior: straight down
  EXPECT_DOUBLE_EQ(q.x, 0.25);
  EXPECT_DOUBLE_EQ(q.y, 0.25);
  EXPECT_DOUBLE_EQ(q.z, 0);
  q = cp({-1, -1, 1});  // vertex region of a
  EXPECT_EQ(q.x, 0);
  EXPECT_EQ(q.y, 0);
  q = cp({0.5, -3, 0});  // edge ab
  EXPECT_DOUBLE_EQ(q.x, 0.5);
  EXPECT_DOUBLE_EQ(q.y, 0);
  q = cp({1, 1, 0});  // edge bc, at its midpoint
  EXPECT_DOUBLE_EQ(q.x, 0.5);
  EXPECT_DOUBLE_EQ(q.y, 0.5);
  q = cp({3, -1, 0});  // vertex region of b
  EXPECT_EQ(q.x, 1);
  EXPECT_EQ(q.y, 0);
}

// The closest of the triangles (9 doubles each) to p, testing them all: its squared distance and
// index (of two as close, the lower).
std::pair<double, std::uint32_t> brute_force_closest(const std::vector<double>& corners, const double p[3]) {
  double best = INFINITY;
  std::uint32_t best_t = UINT32_MAX;
  for (std::size_t t = 0; t < corners.size() / 9; ++t) {
    const double* c = &corners[9 * t];
    const Vec3 q =
        closest_point_on_triangle({p[0], p[1], p[2]}, {c[0], c[1], c[2]}, {c[3], c[4], c[5]}, {c[6], c[7], c[8]});
    const double d2 = measure_detail::squared_distance({p[0], p[1], p[2]}, q);
    if (d2 < best) best = d2, best_t = std::uint32_t(t);
  }
  return {best, best_t};
}
double brute_force_d2(const std::vector<double>& corners, const double p[3]) {
  return brute_force_closest(corners, p).first;
}

TEST(Measure, BvhMatchesBruteForce) {
  const Mesh sphere = test::icosphere(3);
  const measure_detail::Surface s = measure_detail::make_surface(sphere, "sphere");
  const measure_detail::TriangleBvh bvh(s.corners);
  ASSERT_EQ(bvh.triangle_count(), sphere.face_count());
  measure_detail::Rng rng(7);
  for (int i = 0; i < 2000; ++i) {
    const double p[3] = {3 * rng.uniform() - 1.5, 3 * rng.uniform() - 1.5, 3 * rng.uniform() - 1.5};
    const double best = brute_force_d2(s.corners, p);
    const auto hit = bvh.closest(p);
    ASSERT_EQ(hit.d2, best) << "query " << i;  // same primitive test: the minimum is bit-identical
    const double dx = hit.point[0] - p[0], dy = hit.point[1] - p[1], dz = hit.point[2] - p[2];
    EXPECT_NEAR(dx * dx + dy * dy + dz * dz, best, 1e-15);
  }
}

// The tree's boxes are floats rounded outward: far from the origin, where a float cannot hold the
// corners (1e7 + 1e-3 steps: floats are 1 apart there), a box rounded to nearest would lie inside
// the triangles and prune the closest one. The answers stay the brute force's, the triangle too.
TEST(Measure, BvhFloatBoxesKeepExactAnswersFarFromTheOrigin) {
  std::vector<double> corners;
  measure_detail::Rng rng(3);
  const double base = 1e7;
  for (int i = 0; i < 2000; ++i) {
    const double x = base + 1e-3 * (i % 50), y = base + 1e-3 * (i / 50), z = base + 1e-4 * rng.uniform();
    corners.insert(corners.end(), {x, y, z, x + 1e-3, y, z + 1e-5, x, y + 1e-3, z - 1e-5});
  }
  const measure_detail::TriangleBvh bvh(corners);
  for (int i = 0; i < 1000; ++i) {
    const double p[3] = {base + 0.05 * rng.uniform(), base + 0.04 * rng.uniform(), base + 1e-4 * (rng.uniform() - 0.5)};
    const auto [best, best_t] = brute_force_closest(corners, p);
    const auto hit = bvh.closest(p);
    ASSERT_EQ(hit.d2, best) << "query " << i;
    ASSERT_EQ(hit.triangle, best_t) << "query " << i;
  }
}

// The build runs in fixed chunks on the threads (65,536 triangles a chunk): a tree built on one,
// two or three threads over more than one chunk is the same tree, with the brute force's answers.
TEST(Measure, BvhBuiltOnThreadsIsTheSameTree) {
  const Mesh sphere = test::icosphere(6);  // 81,920 triangles: two chunks
  const measure_detail::Surface s = measure_detail::make_surface(sphere, "sphere");
  const measure_detail::TriangleBvh one(s.corners, 1), two(s.corners, 2), three(s.corners, 3);
  ASSERT_EQ(two.node_count(), one.node_count());
  ASSERT_EQ(three.node_count(), one.node_count());
  measure_detail::Rng rng(11);
  for (int i = 0; i < 40; ++i) {
    const double p[3] = {3 * rng.uniform() - 1.5, 3 * rng.uniform() - 1.5, 3 * rng.uniform() - 1.5};
    const double best = brute_force_d2(s.corners, p);
    const auto a = one.closest(p), b = two.closest(p), c = three.closest(p);
    ASSERT_EQ(a.d2, best) << "query " << i;
    ASSERT_EQ(b.triangle, a.triangle) << "query " << i;
    ASSERT_EQ(c.triangle, a.triangle) << "query " << i;
    ASSERT_TRUE(bit_equal(b.d2, a.d2) && bit_equal(c.d2, a.d2)) << "query " << i;
    for (std::uint32_t t : {0u, 40000u, 81919u})  // the stored triangles, each where its index says
      ASSERT_EQ(one.triangle(t), two.triangle(t));
  }
  for (std::size_t i = 0; i < one.node_count(); ++i) {  // node for node (slot 1 is unused)
    if (i == 1) continue;
    for (const measure_detail::TriangleBvh* other : {&two, &three}) {
      const auto &a = one.node(i), &b = other->node(i);
      ASSERT_TRUE(a.first == b.first && a.count == b.count) << "node " << i;
      for (int k = 0; k < 3; ++k) ASSERT_TRUE(a.lo[k] == b.lo[k] && a.hi[k] == b.hi[k]) << "node " << i;
    }
  }
}

// The subtrees split on the threads (ranges of 32,768 triangles and fewer) are laid out as one
// depth-first pass lays out the whole tree: each inner node's children are the next free pair of
// slots when it is reached, left subtree before right; the leaves cover the stored triangles in
// order; every box holds its children's.
TEST(Measure, BvhKeepsTheDepthFirstLayout) {
  const Mesh sphere = test::icosphere(7);  // 327,680 triangles: ten ranges and more split on the threads
  const measure_detail::Surface s = measure_detail::make_surface(sphere, "sphere");
  const measure_detail::TriangleBvh tree(s.corners, 2);
  std::size_t next_pair = 2, next_triangle = 0, leaves = 0;
  std::vector<std::size_t> stack{0};
  while (!stack.empty()) {
    const std::size_t i = stack.back();
    stack.pop_back();
    const auto& node = tree.node(i);
    if (node.count > 0) {
      ASSERT_EQ(node.first, next_triangle) << "leaf " << i;
      ASSERT_LE(node.count, 4u);
      next_triangle += node.count, ++leaves;
      continue;
    }
    ASSERT_EQ(node.first, next_pair) << "inner node " << i;
    next_pair += 2;
    for (std::size_t c : {std::size_t(node.first), std::size_t(node.first) + 1})
      for (int k = 0; k < 3; ++k)
        ASSERT_TRUE(node.lo[k] <= tree.node(c).lo[k] && tree.node(c).hi[k] <= node.hi[k]) << "node " << i;
    stack.push_back(node.first + 1);  // the right child after the whole left subtree
    stack.push_back(node.first);
  }
  EXPECT_EQ(next_triangle, s.corners.size() / 9);
  EXPECT_EQ(next_pair, tree.node_count());
  EXPECT_GT(leaves, s.corners.size() / 9 / 4);
  // Each pair of children on one 64-byte line: the array is so aligned (pairs start at even slots).
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(&tree.node(0)) % 64, 0u);
}

// A tree of an indexed mesh (TriangleBvh's second form: it keeps the vertices and each face's
// indices, as the refit's surface does) is the tree of the same corners given as an array: the
// same nodes, the same stored triangles, and bit for bit the same answers, also on a mesh whose
// faces share no vertex order with their positions (shuffled) and with unreferenced vertices.
TEST(Measure, BvhOfAnIndexedMeshIsTheSameTree) {
  Mesh sphere = test::icosphere(6);
  // Faces in a shuffled order, and a vertex no face has (the tree must not need every vertex).
  measure_detail::Rng shuffle(9);
  const std::size_t nf = sphere.face_count();
  for (std::size_t f = nf - 1; f > 0; --f) {
    const std::size_t g = std::size_t(shuffle.uniform() * double(f + 1)) % (f + 1);
    for (int k = 0; k < 3; ++k) std::swap(sphere.indices[3 * f + k], sphere.indices[3 * g + k]);
  }
  sphere.positions.insert(sphere.positions.end(), {5.0, 5.0, 5.0});
  const measure_detail::Surface s = measure_detail::make_surface(sphere, "sphere");
  const measure_detail::TriangleBvh from_array(s.corners, 2);
  const measure_detail::TriangleBvh indexed(
      core::UnzeroedVector<double>(sphere.positions.begin(), sphere.positions.end()), sphere.indices, 2);
  ASSERT_EQ(indexed.node_count(), from_array.node_count());
  ASSERT_EQ(indexed.triangle_count(), from_array.triangle_count());
  for (std::uint32_t t = 0; t < from_array.triangle_count(); t += 97)
    ASSERT_EQ(indexed.triangle(t), from_array.triangle(t)) << "triangle " << t;
  measure_detail::Rng rng(5);
  std::uint32_t hint_a = UINT32_MAX, hint_b = UINT32_MAX;
  for (int i = 0; i < 400; ++i) {
    const double p[3] = {3 * rng.uniform() - 1.5, 3 * rng.uniform() - 1.5, 3 * rng.uniform() - 1.5};
    const auto a = from_array.closest(p), b = indexed.closest(p);
    ASSERT_TRUE(bit_equal(a.d2, b.d2) && a.triangle == b.triangle) << "query " << i;
    ASSERT_TRUE(bit_equal(a.d2, brute_force_d2(s.corners, p))) << "query " << i;
    const auto c = from_array.closest(p, &hint_a), d = indexed.closest(p, &hint_b);
    ASSERT_TRUE(bit_equal(c.d2, d.d2) && c.triangle == d.triangle && hint_a == hint_b) << "query " << i;
    std::vector<std::uint32_t> near_a, near_b;
    from_array.within(p, 0.01, near_a);
    indexed.within(p, 0.01, near_b);
    std::sort(near_a.begin(), near_a.end());
    std::sort(near_b.begin(), near_b.end());
    ASSERT_EQ(near_a, near_b) << "query " << i;
  }
}

// The Morton-ordered build splits a range of equal codes in half: many triangles with one centre
// (stacked copies), a dense cluster beside a far triangle, and exact ties all give the brute
// force's answer, ties to the lowest index.
TEST(Measure, BvhStackedAndClusteredTrianglesMatchBruteForce) {
  std::vector<double> corners;
  const auto add = [&](Vec3 a, Vec3 b, Vec3 c) {
    for (const Vec3& v : {a, b, c}) corners.insert(corners.end(), {v.x, v.y, v.z});
  };
  add({1e3, 1e3, 1e3}, {1e3 + 1, 1e3, 1e3}, {1e3, 1e3 + 1, 1e3});               // far away
  for (int copy = 0; copy < 300; ++copy) add({0, 0, 0}, {1, 0, 0}, {0, 1, 0});  // stacked: exact ties
  measure_detail::Rng rng(5);
  for (int i = 0; i < 500; ++i) {  // a cluster of tiny triangles
    const Vec3 o{1e-6 * rng.uniform(), 2 + 1e-6 * rng.uniform(), 1e-6 * rng.uniform()};
    add(o, o + Vec3{1e-8, 0, 0}, o + Vec3{0, 0, 1e-8});
  }
  const measure_detail::TriangleBvh bvh(corners);
  for (int i = 0; i < 500; ++i) {
    const double p[3] = {3 * rng.uniform() - 1, 3 * rng.uniform() - 1, 3 * rng.uniform() - 1};
    const auto [best, best_t] = brute_force_closest(corners, p);
    std::uint32_t hint = 17;  // a stacked copy: the answer must still be the lowest index
    const auto cold = bvh.closest(p), warm = bvh.closest(p, &hint);
    ASSERT_EQ(cold.d2, best) << i;
    ASSERT_EQ(cold.triangle, best_t) << i;
    ASSERT_EQ(warm.triangle, best_t) << i;
  }
}

// SurfaceDistance::within decides from the start face when it can: the same answer as comparing
// the distance, whatever face it starts from.
TEST(Measure, SurfaceWithinAgreesWithDistance) {
  const Mesh sphere = test::icosphere(3);
  const measure_detail::Surface s = measure_detail::make_surface(sphere, "sphere");
  const core::SurfaceDistance surface(s.corners);
  measure_detail::Rng rng(13);
  int inside = 0;
  for (int i = 0; i < 2000; ++i) {
    const Vec3 p{2.4 * rng.uniform() - 1.2, 2.4 * rng.uniform() - 1.2, 2.4 * rng.uniform() - 1.2};
    const double d = 0.3 * rng.uniform();
    std::uint32_t none = UINT32_MAX,
                  start = std::min(std::uint32_t(rng.uniform() * double(s.triangle_count())),
                                   std::uint32_t(s.triangle_count() - 1));
    const double exact = surface.distance(p, &none);
    EXPECT_EQ(surface.within(p, d, start), exact <= d) << i;
    EXPECT_GE(surface.distance_to(p, start), exact);
    inside += exact <= d;
  }
  EXPECT_GT(inside, 100);  // both answers occur
  EXPECT_LT(inside, 1900);
}

TEST(Measure, BvhWarmStartGivesSameAnswer) {
  const Mesh sphere = test::icosphere(4);
  const measure_detail::Surface s = measure_detail::make_surface(sphere, "sphere");
  const measure_detail::TriangleBvh bvh(s.corners);
  measure_detail::Rng rng(11);
  std::uint32_t hint = UINT32_MAX;
  for (int i = 0; i < 2000; ++i) {
    // A random walk, so consecutive queries are close (the case the hint is for), with jumps.
    const double p[3] = {1.2 * std::cos(i * 0.01), 1.2 * std::sin(i * 0.013), 0.8 * rng.uniform() - 0.4};
    const auto cold = bvh.closest(p);
    const auto warm = bvh.closest(p, &hint);
    ASSERT_EQ(warm.d2, cold.d2) << i;
    EXPECT_EQ(hint, warm.triangle);
  }
}

TEST(Measure, BvhBoundedWarmStartGivesTheBoundedAnswer) {
  // closest(p, max_d2, hint), as the distance certificate calls it: the same triangle as the cold
  // bounded search whatever the hint (near, far beyond the bound, or none), none beyond the bound.
  const Mesh sphere = test::icosphere(4);
  const measure_detail::Surface s = measure_detail::make_surface(sphere, "sphere");
  const measure_detail::TriangleBvh bvh(s.corners);
  measure_detail::Rng rng(5);
  int found = 0, beyond = 0;
  for (int i = 0; i < 3000; ++i) {
    const double r = 0.8 + 0.4 * rng.uniform(), a = 6.3 * rng.uniform(), b = 3.1 * rng.uniform();
    const double p[3] = {r * std::sin(b) * std::cos(a), r * std::sin(b) * std::sin(a), r * std::cos(b)};
    const double max_d2 = 0.01 * rng.uniform();
    const auto hint = static_cast<std::uint32_t>(rng.uniform() * double(s.triangle_count() + 1));  // may be none
    const auto cold = bvh.closest(p, max_d2);
    const auto warm = bvh.closest(p, max_d2, hint);
    ASSERT_EQ(warm.d2, cold.d2) << i;
    ASSERT_EQ(warm.triangle, cold.triangle) << i;
    (cold.d2 <= max_d2 ? found : beyond) += 1;
  }
  EXPECT_GT(found, 300);  // both cases are exercised
  EXPECT_GT(beyond, 300);
}

TEST(Measure, SamplesAreUniformByArea) {
  // Two triangles of areas 1/8 and 7/8 (split of the unit square at x = 1/4 on the bottom edge):
  // the mean x of area-uniform samples is the square's centroid, 1/2, only if faces are picked by area.
  Mesh m;
  m.positions = {0, 0, 0, 0.25, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  m.indices = {0, 1, 4, 1, 2, 3, 1, 3, 4};
  const auto s = measure_detail::make_surface(m, "m");
  EXPECT_DOUBLE_EQ(s.area, 1.0);
  const std::vector<double> x = measure_detail::sample_surface(s, 200000, 3);
  double mx = 0, my = 0, mxx = 0;
  for (std::size_t i = 0; i < x.size(); i += 3) mx += x[i], my += x[i + 1], mxx += x[i] * x[i];
  const double n = double(x.size() / 3);
  EXPECT_NEAR(mx / n, 0.5, 3e-3);
  EXPECT_NEAR(my / n, 0.5, 3e-3);
  EXPECT_NEAR(mxx / n, 1.0 / 3.0, 3e-3);
}

TEST(Measure, IdenticalMeshesGiveZero) {
  const Mesh m = test::icosphere(2);
  const MeasureResult r = measure(m, m, with_samples(20000));
  EXPECT_LT(r.E, 1e-28);
  EXPECT_LT(r.hausdorff, 1e-13);
  EXPECT_LT(r.mean, 1e-14);
  EXPECT_EQ(r.samples_original, 10000u);  // equal areas: an even split
  EXPECT_EQ(r.samples_approx, 10000u);
  EXPECT_NEAR(r.bbox_diag, 2 * std::sqrt(3.0), 0.2);  // icosphere bbox is inside the sphere's cube
}

// Unit cube C vs the same cube shifted by d along x (C'). Per unit of area on C (6 faces):
//  - face x=0: distance d everywhere                                   -> int d^2   = d^2
//  - face x=1 lies inside C': distance to the nearest face of C' is min(d, y, 1-y, z, 1-z);
//    with m = min(y, 1-y, z, 1-z) (area density of {m = s} is 4(1-2s)):
//      int = d^2 (1-2d)^2 + int_0^d s^2 4(1-2s) ds = d^2 (1-2d)^2 + 4d^3/3 - 2d^4
//  - the 4 side faces are shared with C' except a strip of width d at x<d: int_0^d (d-x)^2 = d^3/3 each
// I = d^2 + d^2(1-2d)^2 + 4d^3/3 - 2d^4 + 4d^3/3, the same from C' to C by symmetry, and
// E = 2I / (6 + 6) = I / 6 = 0.00314444 for d = 0.1 (bench README: closed form 0.0031444).
// The mean distance: (d + d(1-2d)^2 + 2d^2 - 8d^3/3 + 2d^2) / 6 = 0.0335556.
// Hausdorff: the corner (0,0,0) is d from C', and nothing is farther: exactly d.
TEST(Measure, ShiftedCubeMatchesClosedForm) {
  const double d = 0.1;
  const double I =
      d * d + d * d * (1 - 2 * d) * (1 - 2 * d) + 4 * d * d * d / 3 - 2 * d * d * d * d + 4 * d * d * d / 3;
  const double E_exact = I / 6;
  ASSERT_NEAR(E_exact, 0.0031444, 1e-7);
  const double mean_exact =
      (d + d * (1 - 2 * d) * (1 - 2 * d) + 2 * d * d - 8 * d * d * d / 3 + 2 * d * d) / 6;
  const Mesh c = test::cube();
  const Mesh shifted = test::transformed(c, 1, d, 0, 0);
  const MeasureResult r = measure(c, shifted, with_samples(400000, 2));
  EXPECT_NEAR(r.E, E_exact, 0.01 * E_exact);
  EXPECT_NEAR(r.mean, mean_exact, 0.01 * mean_exact);
  EXPECT_NEAR(r.hausdorff, d, 1e-12);
  EXPECT_NEAR(r.h_original_to_approx, d, 1e-12);
  EXPECT_NEAR(r.h_approx_to_original, d, 1e-12);
  EXPECT_DOUBLE_EQ(r.rms, std::sqrt(r.E));
  EXPECT_NEAR(r.bbox_diag, std::sqrt(3.0), 1e-15);
  EXPECT_DOUBLE_EQ(r.E_rel, r.E / 3.0);
  EXPECT_DOUBLE_EQ(r.hausdorff_rel, r.hausdorff / std::sqrt(3.0));
  EXPECT_DOUBLE_EQ(r.area_original, 6.0);
}

// Every point of a fine icosphere is within 1 - r of the icosahedron (r its inradius, 0.794654 for
// circumradius 1), with equality only at the sphere point above a face centre; the icosphere lies
// inside the sphere, so 1 - r is a strict upper bound and a fine sampling gets close to it.
TEST(Measure, IcosphereVsIcosahedronHausdorff) {
  const double inradius = std::sqrt((5 + 2 * std::sqrt(5.0)) / 15);  // r / R of the icosahedron
  const double bound = 1 - inradius;
  ASSERT_NEAR(bound, 0.205346, 1e-6);
  const MeasureResult r = measure(test::icosphere(5), test::icosphere(0), with_samples(200000, 2));
  EXPECT_LE(r.hausdorff, bound + 1e-12);
  EXPECT_NEAR(r.hausdorff, bound, 2e-3);
  EXPECT_EQ(r.hausdorff, r.h_original_to_approx);
  // The other way, the icosahedron's face centres are the farthest: 1 - r minus the icosphere's sag.
  EXPECT_LT(r.h_approx_to_original, bound);
  EXPECT_GT(r.h_approx_to_original, bound - 5e-3);
}

TEST(Measure, DeterministicAcrossRunsAndThreads) {
  const Mesh a = test::icosphere(4);
  const Mesh b = test::transformed(test::icosphere(2), 1.02, 0.01, 0, 0);
  const MeasureResult r1 = measure(a, b, with_samples(50000, 1));
  for (unsigned threads : {1u, 2u, 3u, 8u}) {
    const MeasureResult r = measure(a, b, with_samples(50000, threads));
    EXPECT_TRUE(bit_equal(r.E, r1.E)) << threads;
    EXPECT_TRUE(bit_equal(r.mean, r1.mean)) << threads;
    EXPECT_TRUE(bit_equal(r.hausdorff, r1.hausdorff)) << threads;
    EXPECT_TRUE(bit_equal(r.rms_approx_to_original, r1.rms_approx_to_original)) << threads;
  }
  MeasureOptions other = with_samples(50000, 2);
  other.seed = 2;
  const MeasureResult r2 = measure(a, b, other);
  EXPECT_NE(r2.E, r1.E);                 // a different sample set...
  EXPECT_NEAR(r2.E, r1.E, 0.05 * r1.E);  // ...estimating the same integral
}

TEST(Measure, PerVertexDistances) {
  const double d = 0.1;
  MeasureOptions o = with_samples(1000);
  o.per_vertex = true;
  const MeasureResult r = measure(test::cube(), test::transformed(test::cube(), 1, d, 0, 0), o);
  ASSERT_EQ(r.vertex_distance.size(), 8u);
  const Mesh shifted = test::transformed(test::cube(), 1, d, 0, 0);
  for (std::size_t v = 0; v < 8; ++v) {
    // Vertices at x = d lie on C's side faces (distance 0), those at x = 1 + d are d outside.
    const double expected = shifted.positions[3 * v] > 1 ? d : 0.0;
    EXPECT_NEAR(r.vertex_distance[v], expected, 1e-15) << v;
  }
}

TEST(Measure, DegenerateFacesIgnoredAndBadInputRejected) {
  Mesh m = test::cube();
  m.positions.insert(m.positions.end(), {5, 5, 5});
  m.indices.insert(m.indices.end(), {0, 8, 8});  // zero-area needle far away: no surface there
  const MeasureResult r = measure(test::cube(), m, with_samples(10000));
  EXPECT_EQ(r.degenerate_approx, 1u);
  EXPECT_LT(r.E, 1e-28);
  // Its vertex still counts for the one-sided Hausdorff (vertices are surface points in the bench).
  EXPECT_NEAR(r.h_approx_to_original, std::sqrt(3 * 16.0), 1e-12);

  Mesh flat;
  flat.positions = {0, 0, 0, 1, 0, 0, 2, 0, 0};
  flat.indices = {0, 1, 2};
  EXPECT_THROW(measure(test::cube(), flat), Error);
  Mesh bad = test::cube();
  bad.indices[5] = 99;
  EXPECT_THROW(measure(bad, test::cube()), Error);
}

// The CLI prints the library's numbers (one JSON line) and writes the per-vertex distances.
TEST(Measure, CliJsonAndPerVertex) {
  const std::string dir = test::temp_dir();
  const std::string a = dir + "/measure_cube.ply", b = dir + "/measure_shifted.ply",
                    pv = dir + "/measure_pv.ply";
  save_mesh(a, test::cube());
  save_mesh(b, test::transformed(test::cube(), 1, 0.1, 0, 0));
  const std::string cmd = std::string(QEM_CLI_PATH) + " measure " + a + " " + b +
                          " --samples 20000 --json --per-vertex " + pv + " > " + dir + "/measure_out.json";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  std::FILE* f = std::fopen((dir + "/measure_out.json").c_str(), "rb");
  ASSERT_NE(f, nullptr);
  char buf[4096] = {};
  const std::size_t len = std::fread(buf, 1, sizeof buf - 1, f);
  std::fclose(f);
  const std::string out(buf, len);
  EXPECT_EQ(out.find('\n'), out.size() - 1);  // exactly one line
  MeasureOptions o;
  o.samples = 20000;
  const MeasureResult r = measure(load_mesh(a), load_mesh(b), o);  // as stored (PLY may round to float)
  const std::size_t at = out.find("\"E\":");
  ASSERT_NE(at, std::string::npos) << out;
  EXPECT_EQ(std::strtod(out.c_str() + at + 4, nullptr), r.E) << out;  // round-trip formatting
  for (const char* key :
       {"\"E_rel\":", "\"rms\":", "\"hausdorff\":", "\"mean_rel\":", "\"bbox_diag\":", "\"h_o2a\":"})
    EXPECT_NE(out.find(key), std::string::npos) << key;
  LoadOptions lo;
  lo.keep_vertex_properties = true;
  const Mesh m = load_mesh(pv, lo);
  const VertexProperty* d = m.find_property("distance");
  ASSERT_NE(d, nullptr);
  ASSERT_EQ(d->values.size(), 8u);
  for (std::size_t v = 0; v < 8; ++v) EXPECT_NEAR(d->values[v], m.positions[3 * v] > 1 ? 0.1 : 0.0, 1e-6);
}

// On a real mesh: swapping the arguments exchanges the one-sided values and keeps E (up to
// sampling), and a finer clustering is closer than a coarser one.
TEST(Measure, RealMeshSymmetryAndMonotonicity) {
  const std::string path = test::shared_data("gh_cow.obj");
  if (path.empty()) GTEST_SKIP() << "shared data not found";
  const Mesh cow = load_mesh(path);
  ClusterOptions co;
  co.cell = 0.02;
  co.cell_relative = true;
  const Mesh coarse = cluster(cow, co);
  co.cell = 0.01;
  const Mesh fine = cluster(cow, co);
  MeasureOptions o;
  o.samples = 200000;
  const MeasureResult rc = measure(cow, coarse, o), rf = measure(cow, fine, o);
  const MeasureResult swapped = measure(coarse, cow, o);
  EXPECT_NEAR(swapped.E, rc.E, 0.05 * rc.E);
  EXPECT_NEAR(swapped.mean_approx_to_original, rc.mean_original_to_approx, 0.05 * rc.mean_original_to_approx);
  EXPECT_LT(rf.E, rc.E);
  EXPECT_LT(rf.hausdorff, rc.hausdorff);
  EXPECT_GT(rf.E, 0);
  EXPECT_LE(rc.rms, rc.hausdorff);
  EXPECT_LE(rc.mean, rc.rms);
}

}  // namespace
}  // namespace qem
