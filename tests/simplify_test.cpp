// Behaviour of qem::simplify on small meshes built in code: stop criteria, boundaries, inversion,
// topology, messy input, scale invariance, determinism, aggregation (GH97 §3-§6). Every test runs
// under both orders of contraction: the greedy heap and the pass-based scheme (passes to the very
// end, so these small meshes exercise it too).
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>
#include <vector>

#include "mesh_checks.h"
#include "qem/error.h"
#include "qem/simplify.h"
#include "test_meshes.h"

using namespace qem;
using qem::test::validity_problem;

namespace {

double bump(double x, double y) { return 0.15 * std::sin(6 * x) * std::cos(5 * y) + 0.05 * x * x; }

Mesh bumpy_sphere(int level) {
  Mesh m = test::icosphere(level);
  for (std::size_t v = 0; v < m.vertex_count(); ++v) {
    double* p = &m.positions[3 * v];
    double r = 1 + 0.1 * std::sin(5 * p[0]) * std::sin(4 * p[1]) * std::cos(3 * p[2]);
    p[0] *= r, p[1] *= 1.3 * r, p[2] *= 0.8 * r;
  }
  return m;
}

Scheme current_scheme = Scheme::Greedy;

/// Default options under the scheme of the running test.
SimplifyOptions options() {
  SimplifyOptions o;
  o.scheme = current_scheme;
  o.greedy_below_faces = 0;
  return o;
}

class Simplify : public ::testing::TestWithParam<Scheme> {
 protected:
  void SetUp() override { current_scheme = GetParam(); }
};

SimplifyOptions faces(std::size_t n) {
  SimplifyOptions o = options();
  o.target_faces = n;
  return o;
}

TEST_P(Simplify, ReachesFaceTargetAndKeepsClosedManifoldClosed) {
  Mesh in = bumpy_sphere(4);  // 5120 faces
  SimplifyResult r = simplify(in, faces(500));
  EXPECT_EQ(r.stop_reason, StopReason::TargetReached);
  EXPECT_LE(r.mesh.face_count(), 500u);
  EXPECT_GE(r.mesh.face_count(), 498u);  // a closed mesh loses faces in pairs
  EXPECT_EQ(validity_problem(r.mesh), "");
  EXPECT_EQ(test::boundary_edges(r.mesh), 0u);
  EXPECT_EQ(test::non_manifold_edges(r.mesh), 0u);
  // Euler characteristic of a sphere survives: V - E + F = 2 with E = 3F/2.
  EXPECT_EQ(2 * r.mesh.vertex_count(), r.mesh.face_count() + 4);
}

TEST_P(Simplify, RatioAndVertexTargets) {
  Mesh in = bumpy_sphere(3);  // 1280 faces, 642 vertices
  SimplifyOptions o = options();
  o.target_ratio = 0.25;
  SimplifyResult r = simplify(in, o);
  EXPECT_LE(r.mesh.face_count(), 320u);
  EXPECT_GE(r.mesh.face_count(), 318u);

  SimplifyOptions v = options();
  v.target_vertices = 100;
  SimplifyResult rv = simplify(in, v);
  EXPECT_LE(rv.mesh.vertex_count(), 100u);
  EXPECT_GE(rv.mesh.vertex_count(), 99u);

  // Combined: the first target reached wins.
  SimplifyOptions both = options();
  both.target_faces = 1000;
  both.target_vertices = 50;
  SimplifyResult rb = simplify(in, both);
  EXPECT_LE(rb.mesh.face_count(), 1000u);
  EXPECT_GT(rb.mesh.vertex_count(), 50u);
}

TEST_P(Simplify, MaxErrorBoundsEveryContraction) {
  Mesh in = test::height_field(30, bump);
  SimplifyOptions o = options();
  o.max_error = 0.002;
  SimplifyResult r = simplify(in, o);
  EXPECT_EQ(r.stop_reason, StopReason::ErrorLimit);
  EXPECT_LE(r.max_error, 0.002);
  EXPECT_GT(r.max_error, 0);
  EXPECT_LT(r.mesh.face_count(), in.face_count());
  // A looser limit simplifies further.
  o.max_error = 0.02;
  SimplifyResult loose = simplify(in, o);
  EXPECT_LT(loose.mesh.face_count(), r.mesh.face_count());
  // Relative to the diagonal: the same limit expressed both ways gives the same result.
  SimplifyOptions rel = options();
  Box box = bounding_box(in);
  rel.max_error = 0.002 / box.diagonal();
  rel.max_error_is_relative = true;
  SimplifyResult rr = simplify(in, rel);
  EXPECT_EQ(rr.mesh.indices, r.mesh.indices);
}

TEST_P(Simplify, FlatGridCollapsesWithZeroError) {
  Mesh in = test::grid(10);
  SimplifyOptions o = options();
  o.max_error = 1e-9;
  SimplifyResult r = simplify(in, o);
  EXPECT_LE(r.mesh.face_count(), 4u);
  for (std::size_t v = 0; v < r.mesh.vertex_count(); ++v) EXPECT_NEAR(r.mesh.positions[3 * v + 2], 0, 1e-12);
}

TEST_P(Simplify, UnreachableTargetStopsCleanly) {
  // A tetrahedron cannot lose a face without becoming non-manifold: the target is unreachable.
  SimplifyResult r = simplify(test::tetrahedron(), faces(1));
  EXPECT_EQ(r.stop_reason, StopReason::NoValidPair);
  EXPECT_EQ(r.mesh.face_count(), 4u);
  EXPECT_FALSE(r.stop_detail.empty());
  // A closed sphere stops at the tetrahedron as well, never loops, never goes non-manifold.
  SimplifyResult s = simplify(bumpy_sphere(2), faces(1));
  EXPECT_EQ(s.stop_reason, StopReason::NoValidPair);
  EXPECT_EQ(s.mesh.face_count(), 4u);
  EXPECT_EQ(validity_problem(s.mesh), "");
}

TEST_P(Simplify, BoundaryPlanesKeepTheBorderOnTheSquare) {
  // GH97 §6: constraint planes along boundary edges hold the border in place. They are a penalty,
  // not a hard constraint, so measure how far boundary vertices drift from the square's border
  // with and without them.
  Mesh in = test::height_field(24, bump);
  auto max_drift = [](const Mesh& m) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> count;
    for (std::size_t f = 0; f < m.face_count(); ++f)
      for (int k = 0; k < 3; ++k) ++count[std::minmax(m.indices[3 * f + k], m.indices[3 * f + (k + 1) % 3])];
    double drift = 0;
    for (auto& [e, c] : count)
      if (c == 1)
        for (std::uint32_t v : {e.first, e.second}) {
          const double* p = &m.positions[3 * v];
          drift = std::max(drift, std::min({std::fabs(p[0]), std::fabs(p[0] - 1), std::fabs(p[1]), std::fabs(p[1] - 1)}));
        }
    return drift;
  };
  SimplifyOptions o = faces(150);
  o.exact_border = false;  // GH97's penalty (exact borders, the default, are tested in border_test.cpp)
  SimplifyResult kept = simplify(in, o);  // default boundary weight
  o.boundary_weight = 0;
  SimplifyResult eroded = simplify(in, o);
  EXPECT_LT(max_drift(kept.mesh), 0.01);
  EXPECT_GT(max_drift(eroded.mesh), 5 * max_drift(kept.mesh)) << "without constraint planes the border erodes";
  o.boundary_weight = 100;
  EXPECT_LT(max_drift(simplify(in, o).mesh), max_drift(kept.mesh) + 1e-12) << "a larger weight holds it tighter";
}

TEST_P(Simplify, LockBorderKeepsBoundaryVerticesExactly) {
  Mesh in = test::height_field(16, bump);
  SimplifyOptions o = faces(100);
  o.lock_border = true;
  SimplifyResult r = simplify(in, o);
  EXPECT_EQ(validity_problem(r.mesh), "");
  // Every original border vertex is still there, at its exact input position.
  std::size_t border_in = 0, found = 0;
  for (std::size_t v = 0; v < in.vertex_count(); ++v) {
    const double* p = &in.positions[3 * v];
    if (!(p[0] == 0 || p[0] == 1 || p[1] == 0 || p[1] == 1)) continue;
    ++border_in;
    for (std::size_t w = 0; w < r.mesh.vertex_count(); ++w) {
      const double* q = &r.mesh.positions[3 * w];
      if (q[0] == p[0] && q[1] == p[1] && q[2] == p[2]) {
        ++found;
        break;
      }
    }
  }
  EXPECT_EQ(found, border_in);
  EXPECT_GT(r.mesh.face_count(), 0u);
}

TEST_P(Simplify, InversionCheckKeepsHeightFieldFacingUp) {
  Mesh in = test::height_field(30, [](double x, double y) { return 0.3 * std::sin(9 * x) * std::sin(7 * y); });
  SimplifyResult r = simplify(in, faces(60));
  for (std::size_t f = 0; f < r.mesh.face_count(); ++f) {
    const std::uint32_t* t = &r.mesh.indices[3 * f];
    const double* a = &r.mesh.positions[3 * t[0]];
    const double* b = &r.mesh.positions[3 * t[1]];
    const double* c = &r.mesh.positions[3 * t[2]];
    double nz = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    EXPECT_GT(nz, 0) << "face " << f << " flipped";
  }
}

TEST_P(Simplify, ScaleAndPositionDoNotChangeTheResult) {
  Mesh in = bumpy_sphere(3);
  SimplifyResult base = simplify(in, faces(200));
  for (double scale : {1e-3, 1e3}) {
    Mesh moved = test::transformed(in, scale, 1e3, -2e3, 5e2);
    SimplifyResult r = simplify(moved, faces(200));
    ASSERT_EQ(r.mesh.indices, base.mesh.indices) << "scale " << scale;
    for (std::size_t i = 0; i < base.mesh.positions.size(); ++i) {
      const double offset = i % 3 == 0 ? 1e3 : (i % 3 == 1 ? -2e3 : 5e2);
      EXPECT_NEAR((r.mesh.positions[i] - offset) / scale, base.mesh.positions[i], 1e-6);
    }
    EXPECT_NEAR(r.max_error / scale, base.max_error, 1e-6 * base.max_error + 1e-12);
  }
}

TEST_P(Simplify, DeterministicOutput) {
  Mesh in = bumpy_sphere(4);
  SimplifyResult a = simplify(in, faces(777));
  SimplifyResult b = simplify(in, faces(777));
  EXPECT_EQ(a.mesh.positions, b.mesh.positions);
  EXPECT_EQ(a.mesh.indices, b.mesh.indices);
}

TEST_P(Simplify, UnmovedVerticesKeepExactInputCoordinates) {
  Mesh in = bumpy_sphere(3);
  SimplifyResult r = simplify(in, faces(1200));  // a few contractions only
  std::size_t exact = 0;
  for (std::size_t w = 0; w < r.mesh.vertex_count(); ++w)
    for (std::size_t v = 0; v < in.vertex_count(); ++v)
      if (std::equal(&in.positions[3 * v], &in.positions[3 * v] + 3, &r.mesh.positions[3 * w])) {
        ++exact;
        break;
      }
  EXPECT_GE(exact, r.mesh.vertex_count() - 2 * (in.face_count() - r.mesh.face_count()));
}

TEST_P(Simplify, MessyInputIsCleanedNotCrashedOn) {
  Mesh in = bumpy_sphere(2);
  const std::size_t nv = in.vertex_count();
  in.positions.insert(in.positions.end(), {9, 9, 9, -9, -9, -9});  // unreferenced vertices
  in.indices.insert(in.indices.end(), {0, 0, 1});                  // repeated corner
  in.indices.insert(in.indices.end(), {in.indices[0], in.indices[1], in.indices[2]});  // duplicate face
  in.indices.insert(in.indices.end(), {in.indices[5], in.indices[4], in.indices[3]});  // reversed duplicate
  in.positions.insert(in.positions.end(), {0, 0, 0, 1, 0, 0, 2, 0, 0});  // zero-area face
  in.indices.insert(in.indices.end(), {std::uint32_t(nv + 2), std::uint32_t(nv + 3), std::uint32_t(nv + 4)});
  SimplifyResult r = simplify(in, faces(60));
  EXPECT_EQ(r.input_faces, 320u + 1);  // degenerate and duplicates dropped, zero-area kept
  EXPECT_EQ(validity_problem(r.mesh), "");
  EXPECT_LE(r.mesh.face_count(), 60u);
}

TEST_P(Simplify, NonManifoldInputSupported) {
  // Two cubes sharing an edge (a non-manifold edge) and a fin glued on a sphere's edge.
  Mesh cubes = test::concatenated(test::cube(), test::transformed(test::cube(), 1, 1, 1, 0));
  // Weld the shared edge: cube 2's (0,0,z) corners are cube 1's (1,1,z) corners.
  for (std::uint32_t& i : cubes.indices)
    if (i >= 8) {
      const double* p = &cubes.positions[3 * i];
      for (std::uint32_t j = 0; j < 8; ++j)
        if (std::equal(p, p + 3, &cubes.positions[3 * j])) i = j;
    }
  ASSERT_EQ(test::non_manifold_edges(cubes), 1u);
  SimplifyResult r = simplify(cubes, faces(8));
  EXPECT_EQ(validity_problem(r.mesh), "");
  EXPECT_LE(test::non_manifold_edges(r.mesh), 1u);
  EXPECT_GT(r.mesh.face_count(), 0u);
}

TEST_P(Simplify, ThresholdPairsJoinSeparateParts) {
  // Two tetrahedra facing each other across a gap of 0.05 (GH97 §3.2, Fig. 3). Edges only: each
  // is stuck at 4 faces. With pairs closer than t, the facing corners contract, the two facing
  // triangles land on the same vertices with opposite orientations and cancel: one closed
  // 6-face bipyramid.
  Mesh a;
  a.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0.3, 0.3, -1};
  a.indices = {0, 1, 2, 0, 3, 1, 1, 3, 2, 2, 3, 0};  // face (0,1,2) faces +z
  Mesh b;  // mirror image across z = 0.025
  b.positions = {0, 0, 0.05, 1, 0, 0.05, 0, 1, 0.05, 0.3, 0.3, 1.05};
  b.indices = {0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3};
  Mesh two = test::concatenated(a, b);
  SimplifyResult edges_only = simplify(two, faces(6));
  EXPECT_EQ(edges_only.virtual_pairs, 0u);
  EXPECT_EQ(edges_only.mesh.face_count(), 8u);
  EXPECT_EQ(edges_only.stop_reason, StopReason::NoValidPair);
  SimplifyOptions o = faces(6);
  o.threshold = 0.1;
  SimplifyResult joined = simplify(two, o);
  EXPECT_EQ(joined.virtual_pairs, 3u);
  EXPECT_EQ(joined.mesh.face_count(), 6u);
  EXPECT_EQ(validity_problem(joined.mesh), "");
  EXPECT_EQ(test::boundary_edges(joined.mesh), 0u);
  EXPECT_EQ(test::non_manifold_edges(joined.mesh), 0u);
  // Relative threshold: the same pairs as the absolute one of equal length.
  SimplifyOptions rel = faces(6);
  rel.threshold = 0.1 / bounding_box(two).diagonal();
  rel.threshold_is_relative = true;
  EXPECT_EQ(simplify(two, rel).virtual_pairs, 3u);
}

TEST_P(Simplify, AggregatedCubesSimplifyPastTheirSeparateLimit) {
  // GH97 Fig. 3: a 3 x 3 grid of unit cubes 0.1 apart. Alone, each cube stops at a tetrahedron
  // (36 faces in all); aggregated through threshold pairs, the joints may go non-manifold and the
  // whole simplifies further.
  Mesh cubes;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) cubes = test::concatenated(cubes, test::transformed(test::cube(), 1, 1.1 * i, 1.1 * j, 0));
  SimplifyResult alone = simplify(cubes, faces(12));
  EXPECT_EQ(alone.mesh.face_count(), 36u);
  SimplifyOptions o = faces(12);
  o.threshold = 0.15;
  SimplifyResult joined = simplify(cubes, o);
  EXPECT_EQ(joined.stop_reason, StopReason::TargetReached);
  EXPECT_LE(joined.mesh.face_count(), 12u);
  EXPECT_EQ(validity_problem(joined.mesh), "");
}

TEST_P(Simplify, EveryPolicyGivesAValidMesh) {
  Mesh in = bumpy_sphere(3);
  for (Weighting w : {Weighting::Area, Weighting::Uniform, Weighting::Angle})
    for (Placement p : {Placement::Optimal, Placement::Segment, Placement::Midpoint, Placement::Endpoints})
      for (InversionPolicy inv : {InversionPolicy::Forbid, InversionPolicy::Penalize, InversionPolicy::Ignore}) {
        SimplifyOptions o = faces(100);
        o.weighting = w, o.placement = p, o.inversion = inv;
        SimplifyResult r = simplify(in, o);
        EXPECT_EQ(validity_problem(r.mesh), "") << to_string(w) << " " << to_string(p);
        EXPECT_LE(r.mesh.face_count(), 100u);
      }
}

TEST_P(Simplify, OptimalPlacementBeatsFixedPlacement) {
  // GH97 Fig. 6: optimal placement has lower error than endpoints/midpoint.
  Mesh in = bumpy_sphere(4);
  SimplifyOptions o = faces(300);
  SimplifyResult optimal = simplify(in, o);
  o.placement = Placement::Endpoints;
  SimplifyResult fixed = simplify(in, o);
  EXPECT_LT(optimal.max_error, fixed.max_error);
}

TEST_P(Simplify, InvalidInputAndOptionsThrow) {
  Mesh bad = test::tetrahedron();
  bad.indices[5] = 99;
  EXPECT_THROW(simplify(bad, faces(2)), Error);
  Mesh nan = test::tetrahedron();
  nan.positions[4] = std::nan("");
  EXPECT_THROW(simplify(nan, faces(2)), Error);
  EXPECT_THROW(simplify(test::tetrahedron(), SimplifyOptions{}), Error);  // no stop criterion
  // Found by fuzz_simplify: coordinates near the top of the double range overflowed the frame.
  EXPECT_THROW(simplify(test::transformed(test::tetrahedron(), 1e307, 0, 0, 0), faces(2)), Error);
  SimplifyOptions o = faces(2);
  o.max_normal_turn_degrees = 95;
  EXPECT_THROW(simplify(test::tetrahedron(), o), Error);
}

TEST_P(Simplify, EmptyAndTinyInputs) {
  SimplifyResult empty = simplify(Mesh{}, faces(10));
  EXPECT_EQ(empty.mesh.face_count(), 0u);
  EXPECT_EQ(empty.stop_reason, StopReason::AlreadyBelowTarget);
  SimplifyResult one = simplify(test::tetrahedron(), faces(10));
  EXPECT_EQ(one.mesh.face_count(), 4u);
}

TEST_P(Simplify, ProgressRisesToOneAndCancelStops) {
  const Mesh in = bumpy_sphere(6);  // 81920 faces: several thousand contractions between reports
  SimplifyOptions o = faces(2000);
  o.greedy_below_faces = 20000;  // under Passes: passes, then the greedy tail, as by default
  std::vector<double> seen;
  ProgressCallback watch([&](double f) {
    seen.push_back(f);
    return true;
  });
  SimplifyResult r = simplify(in, o, &watch);
  ASSERT_GE(seen.size(), 3u);
  EXPECT_EQ(seen.back(), 1.0);
  for (std::size_t i = 1; i < seen.size(); ++i) {
    EXPECT_GE(seen[i], seen[i - 1]) << "report " << i;
    EXPECT_LE(seen[i], 1.0);
  }
  EXPECT_EQ(r.stop_reason, StopReason::TargetReached);

  int calls = 0;
  ProgressCallback cancel([&](double) { return ++calls < 3; });
  SimplifyResult cancelled = simplify(in, o, &cancel);
  EXPECT_EQ(cancelled.stop_reason, StopReason::Cancelled);
  EXPECT_GT(cancelled.mesh.face_count(), 2000u);
  EXPECT_EQ(validity_problem(cancelled.mesh), "");
}

}  // namespace

INSTANTIATE_TEST_SUITE_P(Schemes, Simplify, ::testing::Values(Scheme::Greedy, Scheme::Passes),
                         [](const ::testing::TestParamInfo<Scheme>& info) { return std::string(to_string(info.param)); });
