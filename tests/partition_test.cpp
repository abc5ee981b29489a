// The partitioned run (qem/partition.h): parts simplified with their cuts locked, welded, then one
// pass over the whole. It must leave no crack where parts met, reach the target, give the same
// bytes whatever the thread count, and stay close to the in-core result's error.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <set>

#include "mesh_checks.h"
#include "qem/error.h"
#include "qem/io.h"
#include "qem/measure.h"
#include "qem/partition.h"
#include "qem/simplify.h"
#include "test_meshes.h"

using namespace qem;

namespace {

// 327,680 faces, closed, with bumps at several scales so that the error differs over the surface.
const Mesh& bumpy_sphere() {
  static const Mesh mesh = [] {
    Mesh m = test::icosphere(7);
    for (std::size_t v = 0; v < m.vertex_count(); ++v) {
      double* p = &m.positions[3 * v];
      const double r = 1 + 0.06 * std::sin(9 * p[0]) * std::sin(7 * p[1]) + 0.04 * std::cos(11 * p[2]) +
                       0.01 * std::sin(31 * p[0] + 17 * p[2]);
      p[0] *= r, p[1] *= 1.3 * r, p[2] *= 0.8 * r;
    }
    return m;
  }();
  return mesh;
}

// 180,000 faces, open: a border the parts must keep, and cuts that end on it.
const Mesh& bumpy_square() {
  static const Mesh mesh = test::height_field(300, [](double x, double y) {
    const double dx = x - 0.5, dy = y - 0.5;
    return 0.08 * std::exp(-30 * (dx * dx + dy * dy)) + 0.01 * std::sin(23 * x) * std::sin(19 * y);
  });
  return mesh;
}

SimplifyOptions ratio(double r, unsigned threads = 2) {
  SimplifyOptions o;
  o.target_ratio = r;
  o.threads = threads;
  o.refit_rounds = 2;  // the command line's default refit
  o.refit_points_per_vertex = 8;
  return o;
}

PartitionOptions in_parts(unsigned parts) {
  PartitionOptions p;
  p.parts = parts;
  return p;
}

// Vertices on an edge used by one face.
std::set<std::uint32_t> border_vertices(const Mesh& m) {
  std::set<std::uint32_t> out;
  for (const auto& [e, count] : test::edge_face_counts(m))
    if (count == 1) out.insert({e.first, e.second});
  return out;
}

}  // namespace

TEST(Partition, ClosedInputGivesAClosedOutputAtTheTarget) {
  const Mesh& in = bumpy_sphere();
  PartitionReport report;
  const SimplifyResult r = simplify_partitioned(in, ratio(0.1), in_parts(4), &report);
  EXPECT_EQ(report.parts, 4u);
  EXPECT_GT(report.shared_vertices, 0u);
  EXPECT_GT(report.merged_faces, r.mesh.face_count());  // the strips along the cuts were there to remove
  EXPECT_EQ(r.mesh.face_count(), std::size_t(std::floor(0.1 * double(in.face_count()))));
  EXPECT_EQ(r.stop_reason, StopReason::TargetReached);
  EXPECT_EQ(test::boundary_edges(r.mesh), 0u);  // no crack where the parts met
  EXPECT_EQ(test::non_manifold_edges(r.mesh), 0u);
  EXPECT_EQ(test::validity_problem(r.mesh), "");
  EXPECT_EQ(r.input_faces, in.face_count());
  EXPECT_EQ(r.input_components, 1u);
  EXPECT_EQ(r.output_components, 1u);
  // Provenance in the input's numbering: an output vertex that never moved stands where its source was.
  ASSERT_EQ(r.vertex_source.size(), r.mesh.vertex_count());
  ASSERT_EQ(r.face_source.size(), r.mesh.face_count());
  for (std::uint32_t s : r.vertex_source) ASSERT_LT(s, in.vertex_count());
  for (std::uint32_t s : r.face_source) ASSERT_LT(s, in.face_count());
}

TEST(Partition, OpenInputKeepsItsBorderAndGainsNone) {
  const Mesh& in = bumpy_square();  // x, y in [0, 1] on a 300 x 300 grid
  const SimplifyResult r = simplify_partitioned(in, ratio(0.05), in_parts(8));
  EXPECT_LE(r.mesh.face_count(), std::size_t(std::floor(0.05 * double(in.face_count()))));
  EXPECT_GE(r.mesh.face_count(), std::size_t(std::floor(0.05 * double(in.face_count()))) - 1);
  // Every border vertex of the output lies on the square's outline (within half a grid step): no
  // border opened along a cut, whose vertices would lie inside.
  std::size_t border = 0;
  for (std::uint32_t v : border_vertices(r.mesh)) {
    ++border;
    const double x = r.mesh.positions[3 * std::size_t(v)], y = r.mesh.positions[3 * std::size_t(v) + 1];
    const double to_outline = std::min({x, 1 - x, y, 1 - y});
    EXPECT_LT(to_outline, 0.5 / 300) << "border vertex " << v << " at " << x << ", " << y << " is inside the square";
  }
  EXPECT_GT(border, 0u);
  EXPECT_EQ(test::boundary_edges(r.mesh), border);  // one loop: as many border edges as border vertices
  EXPECT_EQ(test::non_manifold_edges(r.mesh), 0u);
}

TEST(Partition, SameBytesForAnyThreadCount) {
  const Mesh& in = bumpy_sphere();
  const SimplifyResult one = simplify_partitioned(in, ratio(0.02, 1), in_parts(4));
  const SimplifyResult two = simplify_partitioned(in, ratio(0.02, 2), in_parts(4));
  const SimplifyResult again = simplify_partitioned(in, ratio(0.02, 2), in_parts(4));
  const SimplifyResult many = simplify_partitioned(in, ratio(0.02, 5), in_parts(4));
  for (const SimplifyResult* r : {&two, &again, &many}) {
    EXPECT_EQ(r->mesh.positions, one.mesh.positions);
    EXPECT_EQ(r->mesh.indices, one.mesh.indices);
    EXPECT_EQ(r->vertex_source, one.vertex_source);
  }
  // Another number of parts is another cut, so another result (at about the same error).
  const SimplifyResult other = simplify_partitioned(in, ratio(0.02, 2), in_parts(3));
  EXPECT_NE(other.mesh.positions, one.mesh.positions);
}

// finish_partitioned taking the parts over (simplify_partitioned's: they are freed once welded,
// before the refit and the repair against the whole input) gives what the form that only reads
// them gives: nothing after the weld reads the parts.
TEST(Partition, FinishingWithThePartsTakenOverGivesTheSameResult) {
  const Mesh& in = bumpy_sphere();
  SimplifyOptions o = ratio(0.05, 2);
  o.refit_rounds = 2, o.refit_points_per_vertex = 8, o.refit_by_reduction = true, o.far_repair = true;
  std::vector<MeshPart> parts = split_mesh(in, o, 4);
  std::vector<MeshPartResult> results;
  for (const MeshPart& part : parts) results.push_back(simplify_part(part, o));
  const SimplifyResult read = finish_partitioned(in, o, std::span<const MeshPart>(parts), results);
  const SimplifyResult taken = finish_partitioned(in, o, std::move(parts), std::move(results));
  EXPECT_GT(read.refit_rounds, 0u);
  EXPECT_EQ(taken.mesh.positions, read.mesh.positions);
  EXPECT_EQ(taken.mesh.indices, read.mesh.indices);
  EXPECT_EQ(taken.vertex_source, read.vertex_source);
  EXPECT_EQ(taken.face_source, read.face_source);
  EXPECT_EQ(taken.output_vertex_of_input, read.output_vertex_of_input);
  EXPECT_EQ(taken.input_vertices, read.input_vertices);
  // And simplify_partitioned's own run is that one.
  const SimplifyResult whole = simplify_partitioned(in, o, in_parts(4));
  EXPECT_EQ(whole.mesh.positions, read.mesh.positions);
  EXPECT_EQ(whole.mesh.indices, read.mesh.indices);
}

TEST(Partition, ErrorStaysNearTheInCoreRun) {
  const Mesh& in = bumpy_sphere();
  for (double r : {0.1, 0.01}) {
    const SimplifyResult whole = simplify(in, ratio(r));
    const SimplifyResult parts = simplify_partitioned(in, ratio(r), in_parts(4));
    ASSERT_EQ(parts.mesh.face_count(), whole.mesh.face_count());
    const MeasureResult e_whole = measure(in, whole.mesh), e_parts = measure(in, parts.mesh);
    EXPECT_LE(e_parts.E, 1.1 * e_whole.E) << "ratio " << r;
    EXPECT_LE(e_parts.hausdorff, 1.2 * e_whole.hausdorff) << "ratio " << r;
  }
}

TEST(Partition, VertexTargetIsSharedToo) {
  const Mesh& in = bumpy_sphere();
  SimplifyOptions o;
  o.target_vertices = 5000;
  o.threads = 2;
  const SimplifyResult r = simplify_partitioned(in, o, in_parts(4));
  EXPECT_EQ(r.mesh.vertex_count(), 5000u);
  EXPECT_EQ(test::boundary_edges(r.mesh), 0u);
}

TEST(Partition, CallerLocksHold) {
  const Mesh& in = bumpy_square();
  std::vector<std::uint8_t> lock(in.vertex_count(), 0);
  for (std::size_t v = 0; v < lock.size(); v += 97) lock[v] = 1;
  SimplifyOptions o = ratio(0.05);
  o.vertex_lock = lock;
  const SimplifyResult r = simplify_partitioned(in, o, in_parts(4));
  std::set<std::uint32_t> kept(r.vertex_source.begin(), r.vertex_source.end());
  for (std::uint32_t v = 0; v < lock.size(); ++v) {
    if (!lock[v]) continue;
    ASSERT_TRUE(kept.count(v)) << "locked vertex " << v << " was removed";
  }
  for (std::size_t u = 0; u < r.mesh.vertex_count(); ++u) {
    const std::uint32_t s = r.vertex_source[u];
    if (!lock[s]) continue;
    for (int k = 0; k < 3; ++k) ASSERT_EQ(r.mesh.positions[3 * u + k], in.positions[3 * std::size_t(s) + k]);
  }
}

TEST(Partition, TheCutLocksExactlyTheSharedVertices) {
  const Mesh& in = bumpy_square();
  PartitionReport report;
  const std::vector<MeshPart> parts = split_mesh(in, ratio(0.1), 5, &report);
  ASSERT_EQ(parts.size(), 5u);
  std::vector<int> uses(in.vertex_count(), 0);
  std::size_t faces = 0;
  for (const MeshPart& p : parts) {
    // Equal face counts, to within the quantiles of a sample of the faces.
    EXPECT_NEAR(double(p.mesh.face_count()), double(in.face_count()) / 5, 0.02 * double(in.face_count()) / 5);
    faces += p.mesh.face_count();
    for (std::uint32_t g : p.input_vertex) ++uses[g];
  }
  EXPECT_EQ(faces, in.face_count());
  std::size_t shared = 0;
  for (int u : uses) shared += u > 1;
  EXPECT_EQ(shared, report.shared_vertices);
  for (const MeshPart& p : parts)
    for (std::size_t l = 0; l < p.input_vertex.size(); ++l) EXPECT_EQ(p.locked[l] != 0, uses[p.input_vertex[l]] > 1);
}

TEST(Partition, RefusesWhatThePartsCannotDo) {
  Mesh with_normals = test::icosphere(3);
  VertexAttribute normals{"NORMAL", AttributeKind::Normal, 3, with_normals.positions};
  with_normals.attributes.push_back(normals);
  EXPECT_TRUE(partition_refusal(with_normals, ratio(0.1)).empty());  // the parts carry them (partition_attributes_test)
  SimplifyOptions pruned = ratio(0.1);
  pruned.prune_size = 0.01;  // judges whole components, which the cuts divide
  EXPECT_FALSE(partition_refusal(with_normals, pruned).empty());
  EXPECT_THROW(simplify_partitioned(with_normals, pruned, in_parts(2)), Error);
  SimplifyOptions limit;
  limit.max_error = 0.01;
  EXPECT_FALSE(partition_refusal(test::icosphere(3), limit).empty());
  EXPECT_THROW(simplify_partitioned(test::icosphere(3), limit, in_parts(2)), Error);
  SimplifyOptions bounded = ratio(0.1);
  bounded.max_distance = 0.01;  // certified against the whole input, which the final pass lacks
  EXPECT_FALSE(partition_refusal(test::icosphere(3), bounded).empty());
  EXPECT_THROW(simplify_partitioned(test::icosphere(3), bounded, in_parts(2)), Error);
  EXPECT_TRUE(partition_refusal(test::icosphere(3), ratio(0.1)).empty());
}

TEST(Partition, AutomaticPartsFollowTheFaceCountOnly) {
  EXPECT_EQ(automatic_parts(999999), 1u);
  EXPECT_EQ(automatic_parts(1000000), 2u);
  EXPECT_EQ(automatic_parts(2000000), 4u);
  EXPECT_EQ(automatic_parts(10000000), 16u);
  EXPECT_EQ(automatic_parts(std::size_t(1) << 40), 64u);
}

namespace {
std::string run_cli(const std::string& args, int* exit_code) {
  const std::string cmd = std::string(QEM_CLI_PATH) + " " + args + " 2>&1";
  std::string out;
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return out;
  std::array<char, 4096> buf;
  while (std::size_t n = std::fread(buf.data(), 1, buf.size(), pipe)) out.append(buf.data(), n);
  const int status = pclose(pipe);
  *exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return out;
}
}  // namespace

TEST(Partition, CommandLineSaysHowManyParts) {
  const std::string in = test::temp_dir() + "/partition_square.ply", out = test::temp_dir() + "/partition_out.ply";
  save_mesh(in, bumpy_square());
  int code = -1;
  std::string r = run_cli("simplify " + in + " " + out + " --ratio 0.1 --partition 4 --json --quiet", &code);
  ASSERT_EQ(code, 0) << r;
  EXPECT_NE(r.find("\"parts\":4"), std::string::npos) << r;
  const Mesh four = load_mesh(out);
  // At the target, or one below where the last contraction took two faces of an odd remainder.
  EXPECT_LE(four.face_count(), bumpy_square().face_count() / 10);
  EXPECT_GE(four.face_count(), bumpy_square().face_count() / 10 - 1);
  // The same parts on one thread: the same file.
  const std::string out1 = test::temp_dir() + "/partition_out1.ply";
  r = run_cli("simplify " + in + " " + out1 + " --ratio 0.1 --partition 4 --threads 1 --quiet", &code);
  ASSERT_EQ(code, 0) << r;
  EXPECT_EQ(test::slurp(out), test::slurp(out1));
  // Below a million faces, auto keeps the run in core.
  r = run_cli("simplify " + in + " " + out + " --ratio 0.1 --json --quiet", &code);
  ASSERT_EQ(code, 0) << r;
  EXPECT_NE(r.find("\"parts\":1"), std::string::npos) << r;
  r = run_cli("simplify " + in + " " + out + " --ratio 0.1 --partition many", &code);
  EXPECT_NE(code, 0);
  EXPECT_NE(r.find("--partition must be auto, off or a number"), std::string::npos) << r;
  r = run_cli("simplify " + in + " " + out + " --max-error 0.01 --partition 2", &code);
  EXPECT_NE(code, 0);
  EXPECT_NE(r.find("cannot simplify part by part"), std::string::npos) << r;
}

TEST(Partition, MorePartsThanFacesAndEmptyParts) {
  // Four faces into 8 parts; two copies of a face at one centroid put no face in a range.
  Mesh tet = test::tetrahedron();
  SimplifyOptions o;
  o.target_faces = 2;
  const SimplifyResult r = simplify_partitioned(tet, o, in_parts(8));
  EXPECT_EQ(r.mesh.face_count(), 4u);  // a closed component keeps a tetrahedron
  EXPECT_EQ(test::boundary_edges(r.mesh), 0u);
  Mesh twice = test::concatenated(test::grid(1), test::grid(1));
  const SimplifyResult g = simplify_partitioned(twice, o, in_parts(3));
  EXPECT_EQ(test::validity_problem(g.mesh), "");
  EXPECT_LE(g.mesh.face_count(), 4u);
}
