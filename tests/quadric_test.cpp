// GH97 §4-§5 quadric maths and §4 placement, against hand-computed values.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "core/placement.h"
#include "core/quadric.h"

using namespace qem;
using namespace qem::core;

namespace {

TEST(Quadric, PlaneQuadricMeasuresSquaredDistance) {
  // Plane z = 2 (n = (0,0,1), d = -2): Q(v) = (v_z - 2)^2.
  Quadric q = Quadric::plane({0, 0, 1}, -2, 1);
  EXPECT_DOUBLE_EQ(q.a22, 1);
  EXPECT_DOUBLE_EQ(q.b2, -2);
  EXPECT_DOUBLE_EQ(q.c, 4);
  EXPECT_DOUBLE_EQ(q.evaluate({5, -3, 2}), 0);
  EXPECT_DOUBLE_EQ(q.evaluate({0, 0, 5}), 9);
  EXPECT_DOUBLE_EQ(q.evaluate({1, 1, -1}), 9);
}

TEST(Quadric, WeightsScaleErrorAndAccumulate) {
  // x + y + z = 1, unit normal (1,1,1)/sqrt3, d = -1/sqrt3; the origin is 1/sqrt3 away.
  const double s = 1 / std::sqrt(3.0);
  Quadric q = Quadric::plane({s, s, s}, -s, 2.5);
  EXPECT_NEAR(q.evaluate({0, 0, 0}), 2.5 / 3, 1e-15);
  EXPECT_DOUBLE_EQ(q.weight, 2.5);
  // Sum of the three coordinate planes through (1,2,3): Q(v) = |v - (1,2,3)|^2.
  Quadric sum = Quadric::plane({1, 0, 0}, -1, 1) + Quadric::plane({0, 1, 0}, -2, 1) + Quadric::plane({0, 0, 1}, -3, 1);
  EXPECT_DOUBLE_EQ(sum.evaluate({0, 0, 0}), 14);
  EXPECT_DOUBLE_EQ(sum.evaluate({1, 2, 4}), 1);
  EXPECT_DOUBLE_EQ(sum.weight, 3);
  // scaled() scales the error but not the represented weight (used for constraint planes).
  Quadric k = sum.scaled(10);
  EXPECT_DOUBLE_EQ(k.evaluate({0, 0, 0}), 140);
  EXPECT_DOUBLE_EQ(k.weight, 3);
}

TEST(Placement, OptimalIsTheCornerOfThreePlanes) {
  Quadric q = Quadric::plane({1, 0, 0}, -1, 1) + Quadric::plane({0, 1, 0}, -2, 1) + Quadric::plane({0, 0, 1}, -3, 1);
  Vec3 v;
  ASSERT_TRUE(place_optimal(q, v));
  EXPECT_NEAR(v.x, 1, 1e-12);
  EXPECT_NEAR(v.y, 2, 1e-12);
  EXPECT_NEAR(v.z, 3, 1e-12);
  Placed p = place(q, {0, 0, 0}, {5, 5, 5}, Placement::Optimal);
  EXPECT_NEAR(p.error, 0, 1e-12);
}

TEST(Placement, OptimalIsScaleRelative) {
  // The same configuration at scales 1e-3 and 1e3 (area weighting scales A by s^2) must make the
  // same decision: QSlim's absolute determinant test fails this.
  for (double scale : {1e-3, 1.0, 1e3}) {
    double w = scale * scale;
    Quadric q = Quadric::plane({1, 0, 0}, -1 * scale, w) + Quadric::plane({0, 1, 0}, -2 * scale, w) +
                Quadric::plane({0, 0.6, 0.8}, -3 * scale, w);
    Vec3 v;
    ASSERT_TRUE(place_optimal(q, v)) << "scale " << scale;
    EXPECT_NEAR(v.x / scale, 1, 1e-9);
    EXPECT_NEAR(v.y / scale, 2, 1e-9);
  }
}

TEST(Placement, NearlyParallelPlanesMeetAtTheirCornerUntilSingular) {
  // Three planes through (1, 2, 3) whose normals are theta apart: A's eigenvalue ratio falls like
  // theta^2 / 9. From 0.3 to 0.05 the determinant bound proves A well conditioned (closed form);
  // at 0.03 and 0.003 it does not and the eigenvalues decide (ratios 1e-4, 1e-6: still solved).
  // At 1e-5 (ratio 1e-11) there is no unique optimum. The closed form keeps ~9 digits here;
  // Eigen's direct eigensolver, fewer as the ratio falls (~1e-6 at 1e-6).
  const Vec3 corner{1, 2, 3};
  const auto through_corner = [&](double theta) {
    Quadric q;
    for (const Vec3& n : {Vec3{0, 0, 1}, Vec3{std::sin(theta), 0, std::cos(theta)}, Vec3{0, std::sin(theta), std::cos(theta)}})
      q += Quadric::plane(n, -dot(n, corner), 1);
    return q;
  };
  for (auto [theta, tolerance] : {std::pair{0.3, 1e-9}, {0.1, 1e-9}, {0.05, 1e-9}, {0.03, 1e-7}, {0.003, 1e-5}}) {
    Vec3 v;
    ASSERT_TRUE(place_optimal(through_corner(theta), v)) << theta;
    EXPECT_NEAR(v.x, 1, tolerance) << theta;
    EXPECT_NEAR(v.y, 2, tolerance) << theta;
    EXPECT_NEAR(v.z, 3, tolerance) << theta;
  }
  Vec3 v;
  EXPECT_FALSE(place_optimal(through_corner(1e-5), v));
}

// Below the determinant bound, place_optimal decides on bounds of the eigenvalue ratio from det
// and the principal minors, and asks the eigen-decomposition only between them: its decision is
// the eigen test's for every conditioning, across the threshold, and where it solves it finds the
// corner (the closed form is the more accurate of the two; see the test above).
TEST(Placement, RatioBoundsDecideAsTheEigenTest) {
  const Vec3 corner{0.3, -2, 5};
  int solved = 0, refused = 0, solved_by_bounds = 0;
  for (int step = 0; step <= 120; ++step) {
    const double theta = std::pow(10.0, -1.0 - 5.0 * step / 120);  // 1e-1 down to 1e-6
    for (double stretch : {1.0, 0.1, 0.01}) {  // the two small eigenvalues alike, or apart
      Quadric q;
      for (const Vec3& n : {Vec3{0, 0, 1}, Vec3{std::sin(theta), 0, std::cos(theta)},
                            Vec3{0, std::sin(stretch * theta), std::cos(stretch * theta)}})
        q += Quadric::plane(n, -dot(n, corner), 1);
      Vec3 fast, eigen;
      const bool by_bounds = place_optimal(q, fast), by_eigen = place_optimal_near_singular(q, eigen);
      ASSERT_EQ(by_bounds, by_eigen) << "theta " << theta << " stretch " << stretch;
      if (!by_bounds) {
        ++refused;
        continue;
      }
      ++solved;
      if (fast.x == eigen.x && fast.y == eigen.y && fast.z == eigen.z) continue;  // the band: the eigen solve
      ++solved_by_bounds;
      // At the corner, to the rounding over the eigenvalue ratio (~theta^2); the eigen solve
      // is off by up to ~100 times more here.
      const double tolerance = std::max(1e-12, 1e-14 / (stretch * stretch * theta * theta));
      EXPECT_NEAR(fast.x, corner.x, tolerance) << theta;
      EXPECT_NEAR(fast.y, corner.y, tolerance) << theta;
      EXPECT_NEAR(fast.z, corner.z, tolerance) << theta;
    }
  }
  EXPECT_GT(solved, 50);  // both sides of the threshold were reached
  EXPECT_GT(refused, 50);
  EXPECT_GT(solved_by_bounds, 50);
}

TEST(Placement, FallsBackToSegmentWhenSingular) {
  // Two parallel planes (z = 0 counted twice): A is rank 1, no unique optimum. The best point on
  // the segment from (0,0,1) to (2,0,-1) is where it crosses z = 0: (1, 0, 0).
  Quadric q = Quadric::plane({0, 0, 1}, 0, 1) + Quadric::plane({0, 0, 1}, 0, 1);
  Vec3 v;
  EXPECT_FALSE(place_optimal(q, v));
  Placed p = place(q, {0, 0, 1}, {2, 0, -1}, Placement::Optimal);
  EXPECT_NEAR(p.position.x, 1, 1e-12);
  EXPECT_NEAR(p.position.z, 0, 1e-12);
  EXPECT_NEAR(p.error, 0, 1e-12);
  // The segment's best point is clamped to the segment.
  Placed c = place(q, {0, 0, 3}, {0, 0, 1}, Placement::Segment);
  EXPECT_NEAR(c.position.z, 1, 1e-12);
  EXPECT_NEAR(c.error, 2, 1e-12);
}

TEST(Placement, FallsBackToEndpointsWhenFlatAlongSegment) {
  // Plane z = 0; segment parallel to it at z = 1 and z = 1: Q is constant along the segment, so
  // the segment step fails too and the endpoints/midpoint rule picks the first endpoint (ties).
  Quadric q = Quadric::plane({0, 0, 1}, 0, 1);
  Placed p = place(q, {0, 0, 1}, {4, 0, 1}, Placement::Optimal);
  EXPECT_NEAR(p.error, 1, 1e-12);
  EXPECT_NEAR(p.position.x, 0, 1e-12);
}

TEST(Placement, FixedPoliciesNeverSolve) {
  Quadric q = Quadric::plane({1, 0, 0}, -1, 1) + Quadric::plane({0, 1, 0}, -2, 1) + Quadric::plane({0, 0, 1}, -3, 1);
  Placed mid = place(q, {0, 0, 0}, {2, 4, 6}, Placement::Midpoint);
  EXPECT_DOUBLE_EQ(mid.position.x, 1);
  EXPECT_DOUBLE_EQ(mid.position.y, 2);
  EXPECT_DOUBLE_EQ(mid.position.z, 3);
  Placed ends = place(q, {0, 0, 0}, {1, 2, 2}, Placement::Endpoints);  // (1,2,2) is 1 away
  EXPECT_DOUBLE_EQ(ends.position.z, 2);
  EXPECT_DOUBLE_EQ(ends.error, 1);
}

}  // namespace
