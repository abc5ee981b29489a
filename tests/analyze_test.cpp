// Tests of qem::analyze (HG99 §3.2 aspect ratio, §4-5 quadric eigen-structure and curvature) and of
// the GH97 Fig. 11 / Fig. 19 outputs, on meshes built in code (one test reads the shared ellipsoid).
#include "qem/analyze.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include "qem/error.h"
#include "qem/io.h"
#include "test_meshes.h"

namespace qem {
namespace {

// Independent check of the closed form: the Steiner circumellipse is the image of the circumcircle
// of an equilateral triangle under the affine map M taking it onto the triangle, so its axis ratio
// is the ratio of M's singular values.
double aspect_by_affine_map(const double p[3][2]) {
  const double s = std::sqrt(3.0) / 2;
  // Equilateral reference triangle (0,0), (1,0), (1/2, s): M maps its edge vectors onto ours.
  double e1[2] = {p[1][0] - p[0][0], p[1][1] - p[0][1]}, e2[2] = {p[2][0] - p[0][0], p[2][1] - p[0][1]};
  // M * (1,0) = e1, M * (1/2, s) = e2  =>  M col0 = e1, col1 = (e2 - e1/2) / s.
  double m00 = e1[0], m10 = e1[1], m01 = (e2[0] - e1[0] / 2) / s, m11 = (e2[1] - e1[1] / 2) / s;
  // Singular values from M^T M.
  double a = m00 * m00 + m10 * m10, b = m00 * m01 + m10 * m11, c = m01 * m01 + m11 * m11;
  double disc = std::sqrt((a - c) * (a - c) + 4 * b * b);
  return std::sqrt((a + c + disc) / (a + c - disc));
}

TEST(Analyze, AspectRatioOfKnownTriangles) {
  const double a[3] = {0, 0, 0}, b[3] = {1, 0, 0}, c[3] = {0.5, std::sqrt(3.0) / 2, 0};
  EXPECT_NEAR(triangle_aspect_ratio(a, b, c), 1.0, 1e-12);
  const double r[3] = {0, 1, 0};  // right isosceles: ratio sqrt(3)
  EXPECT_NEAR(triangle_aspect_ratio(a, b, r), std::sqrt(3.0), 1e-12);
  const double d[3] = {2, 0, 0};  // collinear
  EXPECT_TRUE(std::isinf(triangle_aspect_ratio(a, b, d)));
  EXPECT_TRUE(std::isinf(triangle_aspect_ratio(a, a, b)));
}

TEST(Analyze, AspectRatioMatchesAffineConstructionAndIsSimilarityInvariant) {
  std::uint64_t state = 12345;
  auto rnd = [&] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return double(state >> 11) / double(1ULL << 53) * 2 - 1;
  };
  for (int i = 0; i < 200; ++i) {
    double p[3][2];
    for (auto& q : p) q[0] = rnd(), q[1] = rnd();
    double p3[3][3];
    for (int k = 0; k < 3; ++k) p3[k][0] = p[k][0], p3[k][1] = p[k][1], p3[k][2] = 0;
    double expect = aspect_by_affine_map(p);
    double got = triangle_aspect_ratio(p3[0], p3[1], p3[2]);
    ASSERT_NEAR(got, expect, 1e-6 * expect) << "triangle " << i;
    // Rotate into 3-D, scale and translate: the ratio must not change.
    double q[3][3];
    for (int k = 0; k < 3; ++k) {
      double x = p[k][0] * 3.5, y = p[k][1] * 3.5;  // scale, then rotate about x, then translate
      q[k][0] = x + 10, q[k][1] = 0.6 * y - 5, q[k][2] = 0.8 * y + 1;
    }
    ASSERT_NEAR(triangle_aspect_ratio(q[0], q[1], q[2]), expect, 1e-6 * expect);
  }
}

TEST(Analyze, OptimalAspectRatioIsHg99Eq34) {
  EXPECT_DOUBLE_EQ(optimal_aspect_ratio(3, 0.75), 2.0);
  EXPECT_DOUBLE_EQ(optimal_aspect_ratio(0.75, 3), 2.0);
  EXPECT_DOUBLE_EQ(optimal_aspect_ratio(-4, 1), 2.0);  // saddle: magnitudes only
  EXPECT_DOUBLE_EQ(optimal_aspect_ratio(2, 2), 1.0);
  EXPECT_DOUBLE_EQ(optimal_aspect_ratio(0, 0), 1.0);
  EXPECT_TRUE(std::isinf(optimal_aspect_ratio(1, 0)));
}

// Open cylinder of radius `radius` around the z axis, height 1, `around` x `along` quads.
Mesh cylinder(double radius, int around, int along) {
  Mesh m;
  for (int j = 0; j <= along; ++j)
    for (int i = 0; i < around; ++i) {
      double a = 2 * std::numbers::pi * i / around;
      m.positions.insert(m.positions.end(), {radius * std::cos(a), radius * std::sin(a), double(j) / along});
    }
  for (int j = 0; j < along; ++j)
    for (int i = 0; i < around; ++i) {
      std::uint32_t v00 = j * around + i, v01 = j * around + (i + 1) % around;
      std::uint32_t v10 = v00 + around, v11 = v01 + around;
      m.indices.insert(m.indices.end(), {v00, v01, v11, v00, v11, v10});
    }
  return m;
}

TEST(Analyze, SphereQuadricsPointAlongTheNormalAndGiveUnitCurvature) {
  const Mesh m = test::icosphere(4);
  const Analysis a = analyze(m);
  ASSERT_EQ(a.vertex_count(), m.vertex_count());
  for (std::size_t v = 0; v < m.vertex_count(); ++v) {
    const double* p = &m.positions[3 * v];
    const double* n = &a.eigenvectors[9 * v + 6];
    double len = std::sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    EXPECT_NEAR(std::abs(n[0] * p[0] + n[1] * p[1] + n[2] * p[2]) / len, 1.0, 1e-3) << v;
    EXPECT_LE(a.eigenvalues[3 * v], a.eigenvalues[3 * v + 1]);
    EXPECT_LE(a.eigenvalues[3 * v + 1], a.eigenvalues[3 * v + 2]);
    // Unit sphere: both principal curvatures are 1 (the face-centroid lumping is first order).
    EXPECT_NEAR(a.curvature[2 * v], 1.0, 0.15) << v;
    EXPECT_NEAR(a.curvature[2 * v + 1], 1.0, 0.15) << v;
  }
}

TEST(Analyze, CylinderSeparatesTheFlatAndTheCurvedDirection) {
  const double radius = 0.5;
  const Mesh m = cylinder(radius, 64, 40);
  const Analysis a = analyze(m);
  for (std::size_t v = 0; v < m.vertex_count(); ++v) {
    double z = m.positions[3 * v + 2];
    if (z < 0.2 || z > 0.8) continue;  // away from the open ends
    const double* emin = &a.eigenvectors[9 * v];
    EXPECT_NEAR(std::abs(emin[2]), 1.0, 1e-6) << v;  // least curvature along the axis
    EXPECT_NEAR(a.curvature[2 * v], 0.0, 1e-4) << v;
    EXPECT_NEAR(a.curvature[2 * v + 1], 1 / radius, 0.1 / radius) << v;  // first-order lumping bias
    EXPECT_GT(a.quadric_ratio[2 * v], 1e3);
  }
}

TEST(Analyze, OptimalAspectFromVertexProperties) {
  Mesh m = test::icosphere(1);
  EXPECT_TRUE(analyze(m).optimal_aspect.empty());
  m.vertex_properties.push_back({"k1", std::vector<double>(m.vertex_count(), 4.0)});
  m.vertex_properties.push_back({"k2", std::vector<double>(m.vertex_count(), 1.0)});
  const Analysis a = analyze(m);
  ASSERT_EQ(a.optimal_aspect.size(), m.face_count());
  for (double r : a.optimal_aspect) EXPECT_DOUBLE_EQ(r, 2.0);
}

TEST(Analyze, RejectsOutOfRangeIndices) {
  Mesh m = test::tetrahedron();
  m.indices[4] = 99;
  EXPECT_THROW(analyze(m), Error);
  EXPECT_THROW(valid_pairs(m, 0), Error);
}

TEST(Analyze, ValidPairsAreEdgesPlusCloseVertices) {
  // Two tetrahedra 0.25 apart along x: t = 0 gives the 12 edges, a larger t adds exactly the
  // non-edge pairs closer than t (checked by brute force).
  const Mesh a = test::tetrahedron();
  double maxx = -1e9, minx = 1e9;
  for (std::size_t v = 0; v < a.vertex_count(); ++v)
    maxx = std::max(maxx, a.positions[3 * v]), minx = std::min(minx, a.positions[3 * v]);
  const Mesh m = test::concatenated(a, test::transformed(a, 1, maxx - minx + 0.25, 0, 0));
  std::size_t edges = 0;
  EXPECT_EQ(valid_pairs(m, 0, &edges).size(), 12u);
  EXPECT_EQ(edges, 12u);
  for (double t : {0.3, 1.0, 2.0}) {
    auto pairs = valid_pairs(m, t, &edges);
    std::size_t expect = 12;
    for (std::uint32_t i = 0; i < 8; ++i)
      for (std::uint32_t j = i + 1; j < 8; ++j) {
        bool same = (i < 4) == (j < 4);  // within one tetrahedron every pair is an edge
        double d2 = 0;
        for (int k = 0; k < 3; ++k) d2 += std::pow(m.positions[3 * i + k] - m.positions[3 * j + k], 2);
        if (!same && std::sqrt(d2) < t) ++expect;
      }
    EXPECT_EQ(pairs.size(), expect) << "t = " << t;
    EXPECT_TRUE(std::is_sorted(pairs.begin() + edges, pairs.end()));
  }
  const std::string path = test::temp_dir() + "/pairs.obj";
  auto pairs = valid_pairs(m, 2.0, &edges);
  save_pairs_obj(path, m, pairs, edges);
  std::ifstream in(path);
  std::size_t lines = 0, groups = 0;
  for (std::string line; std::getline(in, line);)
    lines += line.rfind("l ", 0) == 0, groups += line.rfind("g ", 0) == 0;
  EXPECT_EQ(lines, pairs.size());
  EXPECT_EQ(groups, pairs.size() > edges ? 2u : 1u);
}

TEST(Analyze, EllipsoidsAreOnePerVertexAroundIt) {
  const Mesh m = test::icosphere(2);
  const Analysis a = analyze(m);
  const Mesh e = quadric_ellipsoids(m, a, 1.0);
  ASSERT_EQ(e.face_count(), 32 * m.vertex_count());
  ASSERT_EQ(e.vertex_count(), 18 * m.vertex_count());
  // Every ellipsoid point lies near its vertex and the ellipsoid is flat along the normal.
  for (std::size_t v = 0; v < m.vertex_count(); v += 7) {
    const double* c = &m.positions[3 * v];
    double max_normal = 0, max_tangent = 0;
    for (std::size_t s = 0; s < 18; ++s) {
      const double* q = &e.positions[3 * (18 * v + s)];
      double d[3] = {q[0] - c[0], q[1] - c[1], q[2] - c[2]};
      double dn = std::abs(d[0] * c[0] + d[1] * c[1] + d[2] * c[2]);
      double dl = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      max_normal = std::max(max_normal, dn);
      max_tangent = std::max(max_tangent, std::sqrt(std::max(0.0, dl * dl - dn * dn)));
    }
    EXPECT_GT(max_tangent, 2 * max_normal) << v;
    EXPECT_LT(max_tangent, 1.0) << v;
  }
  EXPECT_THROW(quadric_ellipsoids(m, a, 0.0), Error);
}

TEST(Analyze, CurvatureEstimateTracksTheAnalyticEllipsoid) {
  const std::string path = test::shared_data("synth_ellipsoid_11k_curv.ply");
  if (path.empty()) GTEST_SKIP() << "shared data folder absent";
  LoadOptions lo;
  lo.keep_vertex_properties = true;
  const Mesh m = load_mesh(path, lo);
  const Analysis a = analyze(m);
  const VertexProperty* k1 = m.find_property("k1");
  const VertexProperty* k2 = m.find_property("k2");
  ASSERT_TRUE(k1 && k2);
  std::vector<double> r1, r2;
  for (std::size_t v = 0; v < m.vertex_count(); ++v) {
    r1.push_back(a.curvature[2 * v + 1] / k1->values[v]);  // e_mid <-> larger curvature
    r2.push_back(a.curvature[2 * v] / k2->values[v]);
  }
  std::sort(r1.begin(), r1.end());
  std::sort(r2.begin(), r2.end());
  EXPECT_NEAR(r1[r1.size() / 2], 1.0, 0.2);
  EXPECT_NEAR(r2[r2.size() / 2], 1.0, 0.2);
  ASSERT_EQ(a.optimal_aspect.size(), m.face_count());
}

}  // namespace
}  // namespace qem
