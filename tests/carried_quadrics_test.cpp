// Garland & Shaffer 2002's second phase (src/simplify_carried.h): simplify and the partitioned run
// starting from quadrics carried in from outside instead of those of the faces they see, and the
// out-of-core run handing its cells' quadrics to its phase 2 (docs/out-of-core.md).
#include "simplify_carried.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "core/quadric.h"
#include "mesh_checks.h"
#include "qem/io.h"
#include "qem/measure.h"
#include "qem/out_of_core.h"
#include "test_meshes.h"

using namespace qem;
namespace fs = std::filesystem;

namespace {

/// Each vertex's area-weighted plane quadrics of its faces (HG99 §2), in model units, evaluated at
/// p - origin: what the core computes itself, but outside its frame.
std::vector<core::Quadric> own_face_quadrics(const Mesh& m, const Vec3& origin) {
  std::vector<core::Quadric> q(m.vertex_count());
  const auto at = [&](std::uint32_t v) {
    return Vec3(m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]) - origin;
  };
  for (std::size_t f = 0; f < m.face_count(); ++f) {
    const std::uint32_t* t = &m.indices[3 * f];
    const Vec3 n = cross(at(t[1]) - at(t[0]), at(t[2]) - at(t[0]));
    const double len = length(n);
    const core::Quadric k = core::Quadric::plane(n / len, -dot(n / len, at(t[0])), len / 2);
    for (int c = 0; c < 3; ++c) q[t[c]] += k;
  }
  return q;
}

double bump(double x, double y) { return 0.2 * std::sin(3 * x) * std::cos(2 * y) + 0.1 * x * y; }

}  // namespace

// The carried quadrics are taken into the core's frame (centre, diagonal): a mesh's own face
// quadrics, given in model units about another origin, far from the model and at another scale,
// must drive the run as the core's own do: the same error reported (in model units), the same
// faces kept up to the last bits' ties. Checked on an open height field too, whose border planes
// (GH97 §6) the core adds in its frame beside the carried quadrics: a transform that got the
// scale wrong would change their balance.
TEST(CarriedQuadrics, OwnFaceQuadricsCarriedGiveTheCoreResult) {
  for (const Mesh& base : {test::icosphere(5), test::height_field(60, bump)}) {
    const Mesh m = test::transformed(base, 1000, 3e4, -2e4, 5e3);
    SimplifyOptions o;
    o.target_faces = m.face_count() / 20;
    const SimplifyResult plain = simplify(m, o);
    const Vec3 origin(3e4 - 500, -2e4 + 250, 5e3);
    const std::vector<core::Quadric> q = own_face_quadrics(m, origin);
    const SimplifyResult carried = detail::simplify_carrying(MeshView(m), o, core::CarriedQuadrics{q, origin});
    EXPECT_EQ(carried.mesh.face_count(), plain.mesh.face_count());
    EXPECT_NEAR(carried.max_error, plain.max_error, 1e-6 * plain.max_error);
    MeasureOptions mo;
    mo.samples = 100000;
    const double e_plain = measure(m, plain.mesh, mo).E, e_carried = measure(m, carried.mesh, mo).E;
    EXPECT_NEAR(e_carried, e_plain, 0.02 * e_plain);
  }
}

// The quadrics decide: a flat grid carrying the quadrics of a rippled surface (planes z = +-h on
// the left half) keeps its vertices where the carried error is, and reports that error; its own
// faces (flat) would report none.
TEST(CarriedQuadrics, CarriedQuadricsDecideWhatIsContracted) {
  const Mesh flat = test::grid(40);
  std::vector<core::Quadric> q = own_face_quadrics(flat, Vec3(0, 0, 0));
  const double h = 0.01;
  std::size_t left = 0;
  for (std::uint32_t v = 0; v < flat.vertex_count(); ++v)
    if (flat.positions[3 * v] < 0.5) {
      q[v] += core::Quadric::plane(Vec3(0, 0, 1), -h, 1e-3) + core::Quadric::plane(Vec3(0, 0, 1), h, 1e-3);
      ++left;
    }
  SimplifyOptions o;
  o.target_faces = flat.face_count() / 4;
  const SimplifyResult plain = simplify(flat, o);
  const SimplifyResult carried = detail::simplify_carrying(MeshView(flat), o, core::CarriedQuadrics{q, Vec3(0, 0, 0)});
  EXPECT_LT(plain.max_error, 1e-9);
  EXPECT_GT(carried.max_error, 0.1 * h);
  std::size_t kept_left = 0;
  for (std::size_t v = 0; v < carried.mesh.vertex_count(); ++v) kept_left += carried.mesh.positions[3 * v] < 0.5 - 1e-9;
  // The right half (no error) is contracted first: the vertices kept are nearly all on the left,
  // where the plain run keeps about half of them.
  EXPECT_GT(kept_left, carried.mesh.vertex_count() * 9 / 10) << left << " on the left in the input";
  std::size_t plain_left = 0;
  for (std::size_t v = 0; v < plain.mesh.vertex_count(); ++v) plain_left += plain.mesh.positions[3 * v] < 0.5 - 1e-9;
  EXPECT_LT(plain_left, plain.mesh.vertex_count() * 7 / 10);
}

// The partitioned run's final pass starts from the sums of the carried quadrics of what each merged
// vertex took in, not from the merged faces' own: carrying a mesh's own face quadrics, the run
// reports the error one in-core run does (the same accumulated quadrics), where the plain
// partitioned run, whose final pass starts afresh from the merged faces, reports another.
TEST(CarriedQuadrics, PartitionedFinalPassStartsFromTheSums) {
  const Mesh m = test::icosphere(6);
  SimplifyOptions o;
  o.target_faces = 2000;
  PartitionOptions po;
  po.parts = 4;
  const std::vector<core::Quadric> q = own_face_quadrics(m, Vec3(0, 0, 0));
  const SimplifyResult whole = simplify(m, o);
  const SimplifyResult plain = simplify_partitioned(m, o, po);
  PartitionReport report;
  const SimplifyResult carried =
      detail::simplify_partitioned_carrying(m, o, po, core::CarriedQuadrics{q, Vec3(0, 0, 0)}, &report);
  EXPECT_EQ(report.parts, 4u);
  EXPECT_EQ(carried.mesh.face_count(), plain.mesh.face_count());
  std::printf("max error: in core %.4g, partitioned %.4g, partitioned carrying %.4g\n", whole.max_error,
              plain.max_error, carried.max_error);
  EXPECT_NEAR(carried.max_error, whole.max_error, 0.05 * whole.max_error);
  EXPECT_GT(std::abs(plain.max_error / whole.max_error - 1), 0.2);
  Mesh welded = carried.mesh;
  weld_exact(welded);
  EXPECT_EQ(test::boundary_edges(welded), 0u);
}

namespace {

constexpr int kRipples = 250;
/// A checkerboard of spikes: every other vertex of the grid raised by about its spacing.
double spikes(double x, double y) {
  const long i = std::lround(x * kRipples), j = std::lround(y * kRipples);
  return (i + j) % 2 ? 1.0 / kRipples : 0.0;
}

}  // namespace

// Phase 2 of the out-of-core run receives the cells' quadrics (Garland & Shaffer 2002 §3): on a
// surface whose spikes are far finer than the cells, the clustered mesh is nearly flat, but the
// cells' quadrics hold the spikes' planes, so phase 2 reports contraction errors of the spikes'
// size; from the clustered faces alone (carry_quadrics = false) it sees only the flat mesh. In
// one run and in parts.
TEST(CarriedQuadrics, OutOfCorePhase2ReceivesTheCellQuadrics) {
  const std::string dir = test::temp_dir() + "/carried_ooc";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string path = dir + "/spikes.ply";
  save_mesh(path, test::height_field(kRipples, spikes));
  const double spike = 1.0 / kRipples;
  SimplifyOptions o;
  o.target_faces = 2000;
  OutOfCoreOptions ooc;
  ooc.memory_limit = std::uint64_t(256) << 20;
  ooc.temp_dir = dir;
  ooc.phase2_faces_per_target = 4;
  for (unsigned parts : {1u, 2u}) {
    ooc.parts = parts;
    OutOfCoreReport report, plain_report;
    ooc.carry_quadrics = true;
    const SimplifyResult carried = simplify_out_of_core(path, o, ooc, &report);
    ooc.carry_quadrics = false;
    const SimplifyResult plain = simplify_out_of_core(path, o, ooc, &plain_report);
    EXPECT_EQ(report.parts, parts);
    EXPECT_LT(report.clustered_vertices * 16, std::uint64_t(kRipples + 1) * (kRipples + 1));  // cells of many spikes
    std::printf("%u parts: max error carried %.4g, from the clustered faces %.4g (spike %.4g)\n", parts,
                carried.max_error, plain.max_error, spike);
    EXPECT_GT(carried.max_error, 0.2 * spike);
    EXPECT_LT(plain.max_error, 0.05 * spike);
    EXPECT_LE(carried.mesh.face_count(), o.target_faces);
  }
  fs::remove(path);
  EXPECT_TRUE(fs::is_empty(dir));
}
