// The refit's set-up on the threads (issue 20, "every core used"): the area weights, the fitted
// points and their Morton order are made in fixed chunks or vertex ranges, and must equal the
// serial result bit for bit on any number of threads, so that the output bytes of a run stay those
// of one thread.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "core/distance_bound.h"
#include "core/spatial_order.h"
#include "geometry/frame.h"
#include "geometry/vec3.h"
#include "refit/refit_points.h"
#include "test_meshes.h"

namespace qem {
namespace {

// An icosphere of 163,842 vertices (above vertex_areas' 65,536 vertices per range) whose faces are
// shuffled, so that each thread's vertex range meets faces all through the face list, and whose
// vertices are moved off the sphere, so that no two areas are alike by symmetry.
Mesh shuffled_bumpy_sphere() {
  Mesh m = test::icosphere(7);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> bump(0.98, 1.02);
  for (double& x : m.positions) x *= bump(rng);
  std::vector<std::uint32_t> order(m.face_count());
  for (std::uint32_t f = 0; f < order.size(); ++f) order[f] = f;
  std::shuffle(order.begin(), order.end(), rng);
  std::vector<std::uint32_t> faces;
  for (std::uint32_t f : order) faces.insert(faces.end(), &m.indices[3 * f], &m.indices[3 * f] + 3);
  m.indices = faces;
  return m;
}

// The serial sum as vertex_areas made it before it ran on threads: face by face.
std::vector<double> serial_areas(const Mesh& m) {
  std::vector<double> area(m.vertex_count(), 0.0);
  for (std::size_t f = 0; f < m.indices.size(); f += 3) {
    const std::uint32_t* t = &m.indices[f];
    const auto p = [&](int k) {
      const double* q = &m.positions[3 * std::size_t(t[k])];
      return Vec3{q[0], q[1], q[2]};
    };
    const Vec3 n = cross(p(1) - p(0), p(2) - p(0));
    const double third = std::sqrt(dot(n, n)) / 6;
    if (!std::isfinite(third)) continue;
    for (int k = 0; k < 3; ++k) area[t[k]] += third;
  }
  return area;
}

TEST(RefitThreads, VertexAreasAreTheSerialSumOnAnyThreads) {
  const Mesh m = shuffled_bumpy_sphere();
  ASSERT_GT(m.vertex_count(), 2u * 65536);
  const std::vector<double> serial = serial_areas(m);
  for (unsigned threads : {1u, 2u, 3u, 8u}) {
    const std::vector<double> area = refit_detail::vertex_areas(m, threads);
    ASSERT_EQ(area.size(), serial.size());
    std::size_t differing = 0;
    for (std::size_t v = 0; v < area.size(); ++v) differing += area[v] != serial[v];
    EXPECT_EQ(differing, 0u) << threads << " threads";
  }
}

TEST(RefitThreads, FitPointsAreTheSameOnAnyThreads) {
  const Mesh m = shuffled_bumpy_sphere();
  std::vector<double> weights = refit_detail::vertex_areas(m);
  // Some points without weight (left out), spread over the chunks, and one far away (the box).
  for (std::size_t v = 0; v < weights.size(); v += 7) weights[v] = 0;
  std::vector<double> points = m.positions;
  points[3 * 5000] = 40, points[3 * 5000 + 1] = -3;
  const refit_detail::FitPoints one(points, weights, 1);
  std::size_t kept = 0;
  for (double w : weights) kept += w > 0;
  ASSERT_EQ(one.weight.size(), kept);
  EXPECT_GT(one.diag, 40.0);  // the far point is in the box
  for (unsigned threads : {2u, 3u}) {
    const refit_detail::FitPoints many(points, weights, threads);
    EXPECT_EQ(many.position, one.position) << threads;
    EXPECT_EQ(many.weight, one.weight) << threads;
    EXPECT_EQ(many.source, one.source) << threads;
    EXPECT_EQ(many.order, one.order) << threads;
    EXPECT_EQ(many.total_weight, one.total_weight) << threads;
    EXPECT_EQ(many.centre.x, one.centre.x);
    EXPECT_EQ(many.centre.y, one.centre.y);
    EXPECT_EQ(many.centre.z, one.centre.z);
    EXPECT_EQ(many.diag, one.diag);
  }
  // The kept points in input order, each with its own weight.
  for (std::size_t j = 1; j < one.source.size(); ++j) ASSERT_LT(one.source[j - 1], one.source[j]);
  for (std::size_t j = 0; j < one.source.size(); j += 997) EXPECT_EQ(one.weight[j], weights[one.source[j]]);
}

TEST(RefitThreads, MortonOrderIsTheSameOnAnyThreads) {
  // Points with repeats (ties by index) and a NaN (skipped by the box), over several chunks.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Vec3> p(300000);
  for (Vec3& q : p) q = {u(rng), u(rng), 0.5 * u(rng)};
  for (std::size_t i = 0; i < p.size(); i += 101) p[i] = p[i / 2];
  p[123456].y = NAN;
  const auto at = [&](std::size_t i) { return p[i]; };
  const std::vector<std::uint32_t> one = core::morton_order(p.size(), at, 1);
  ASSERT_EQ(one.size(), p.size());
  for (unsigned threads : {2u, 5u}) EXPECT_EQ(core::morton_order(p.size(), at, threads), one) << threads;
  // A permutation of the points.
  std::vector<std::uint8_t> seen(p.size(), 0);
  for (std::uint32_t i : one) seen[i]++;
  EXPECT_EQ(std::count(seen.begin(), seen.end(), 1), std::ptrdiff_t(p.size()));
}

// The order is by the points' 63-bit Morton codes, ties by index, also where the radix sort's
// 32 top bits leave runs longer than the chunks the runs are sorted in: here 150,000 points
// jittered within 1e-5 (one run of equal top bits, mostly, different full codes) among 100,000
// others. The expected order is made here from the codes' definition.
TEST(RefitThreads, MortonOrderSortsRunsAcrossChunks) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Vec3> p(250000);
  for (std::size_t i = 0; i < p.size(); ++i)
    p[i] = i % 5 < 2 ? Vec3{u(rng), u(rng), u(rng)} : Vec3{0.25 + 1e-5 * u(rng), 0.5 + 1e-5 * u(rng), 0.125 + 1e-5 * u(rng)};
  Vec3 lo = p[0], hi = p[0];
  for (const Vec3& q : p) {
    lo = {std::min(lo.x, q.x), std::min(lo.y, q.y), std::min(lo.z, q.z)};
    hi = {std::max(hi.x, q.x), std::max(hi.y, q.y), std::max(hi.z, q.z)};
  }
  const double scale = double((1 << 21) - 1) / std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
  const auto cell = [&](double x, double l) { return std::uint64_t(std::min((x - l) * scale, double((1 << 21) - 1))); };
  std::vector<std::uint64_t> code(p.size());
  for (std::size_t i = 0; i < p.size(); ++i)
    code[i] = core::spread_bits_3d(cell(p[i].x, lo.x)) | core::spread_bits_3d(cell(p[i].y, lo.y)) << 1 |
              core::spread_bits_3d(cell(p[i].z, lo.z)) << 2;
  std::vector<std::uint32_t> expected(p.size());
  for (std::uint32_t i = 0; i < expected.size(); ++i) expected[i] = i;
  std::sort(expected.begin(), expected.end(),
            [&](std::uint32_t a, std::uint32_t b) { return code[a] != code[b] ? code[a] < code[b] : a < b; });
  std::size_t longest = 0;  // the longest run of equal top bits
  for (std::size_t k = 0, run = 0; k < expected.size(); ++k)
    longest = std::max(longest, run = k > 0 && code[expected[k]] >> 31 == code[expected[k - 1]] >> 31 ? run + 1 : 1);
  ASSERT_GT(longest, std::size_t(1) << 16);  // longer than a chunk
  const auto at = [&](std::size_t i) { return p[i]; };
  for (unsigned threads : {1u, 3u}) EXPECT_EQ(core::morton_order(p.size(), at, threads), expected) << threads;
}

// The input's surface in the refit's frame: each vertex's start face is the lowest face that has
// it, found in vertex ranges on the threads (faces shuffled: each range meets its vertices all
// through the face list), and the tree holds each face's corners mapped into the frame, as a tree
// built from an array of them would.
TEST(RefitThreads, SurfaceInFrameIsTheSameOnAnyThreads) {
  const Mesh m = shuffled_bumpy_sphere();
  const Frame frame{{0.1, -0.2, 0.3}, 2.5};
  std::vector<std::uint32_t> lowest(m.vertex_count(), UINT32_MAX);
  for (std::size_t c = 0; c < m.indices.size(); ++c) lowest[m.indices[c]] = std::min<std::uint32_t>(lowest[m.indices[c]], std::uint32_t(c / 3));
  std::vector<double> corners(3 * m.indices.size());
  for (std::size_t c = 0; c < m.indices.size(); ++c) {
    const double* p = &m.positions[3 * std::size_t(m.indices[c])];
    const Vec3 q = frame.to_frame({p[0], p[1], p[2]});
    corners[3 * c] = q.x, corners[3 * c + 1] = q.y, corners[3 * c + 2] = q.z;
  }
  const core::SurfaceDistance from_array(corners);
  for (unsigned threads : {1u, 2u, 3u}) {
    const core::SurfaceDistance surface = refit_detail::surface_in_frame(m.positions, m.indices, frame, threads);
    std::size_t wrong_start = 0, wrong_corners = 0;
    for (std::uint32_t v = 0; v < m.vertex_count(); ++v) wrong_start += surface.face_at(v) != lowest[v];
    for (std::uint32_t t = 0; t < m.face_count(); ++t) {
      const std::array<double, 9> c = surface.triangle(t);
      wrong_corners += !std::equal(c.begin(), c.end(), &corners[9 * std::size_t(t)]);
    }
    EXPECT_EQ(wrong_start, 0u) << threads << " threads";
    EXPECT_EQ(wrong_corners, 0u) << threads << " threads";
    for (const Vec3& p : {Vec3{0.3, 0.1, -0.2}, Vec3{-0.05, 0.2, 0.1}, Vec3{0.4, -0.4, 0.0}}) {
      std::uint32_t a = UINT32_MAX, b = UINT32_MAX;
      EXPECT_EQ(surface.distance(p, &a), from_array.distance(p, &b)) << threads << " threads";
      EXPECT_EQ(a, b) << threads << " threads";
    }
  }
}

}  // namespace
}  // namespace qem
