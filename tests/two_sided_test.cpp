// Two-sided sheets (SimplifyOptions::two_sided, src/two_sided.h): a sheet made two-sided by a
// reversed copy of each face keeps its rim closed (Rims) or both sides (All) through
// simplification, inside the face target.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <set>

#include "qem/partition.h"
#include "qem/simplify.h"
#include "test_meshes.h"

using namespace qem;

namespace {

// A wavy open sheet (so that simplifying it has a cost) with every face repeated in the opposite
// turn on the same vertices, as exporters make a two-sided sheet.
Mesh two_sided_sheet(int n) {
  Mesh m = test::height_field(n, [](double x, double y) { return 0.1 * std::sin(5 * x) * std::cos(4 * y); });
  const std::size_t nf = m.face_count();
  for (std::size_t f = 0; f < nf; ++f)
    m.indices.insert(m.indices.end(), {m.indices[3 * f], m.indices[3 * f + 2], m.indices[3 * f + 1]});
  return m;
}

// The same with its back faces on vertices of their own whose normals point the other way.
Mesh two_sided_sheet_with_normals(int n) {
  Mesh m = test::height_field(n, [](double x, double y) { return 0.1 * std::sin(5 * x) * std::cos(4 * y); });
  const std::size_t nv = m.vertex_count(), nf = m.face_count();
  VertexAttribute normal{"NORMAL", AttributeKind::Normal, 3, {}};
  for (std::size_t v = 0; v < nv; ++v) normal.values.insert(normal.values.end(), {0.0, 0.0, 1.0});
  for (std::size_t v = 0; v < nv; ++v) {
    m.positions.insert(m.positions.end(), {m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]});
    normal.values.insert(normal.values.end(), {0.0, 0.0, -1.0});
  }
  for (std::size_t f = 0; f < nf; ++f) {
    const std::uint32_t b = std::uint32_t(nv);
    m.indices.insert(m.indices.end(), {m.indices[3 * f] + b, m.indices[3 * f + 2] + b, m.indices[3 * f + 1] + b});
  }
  m.attributes.push_back(std::move(normal));
  return m;
}

// The corner positions of face f, starting at its lowest, in its own turn.
std::array<std::array<double, 3>, 3> turn(const Mesh& m, std::size_t f) {
  std::array<std::array<double, 3>, 3> p;
  for (int c = 0; c < 3; ++c)
    for (int k = 0; k < 3; ++k) p[c][k] = m.positions[3 * std::size_t(m.indices[3 * f + c]) + k];
  std::rotate(p.begin(), std::min_element(p.begin(), p.end()), p.end());
  return p;
}

// Each of the last `twins` faces is another face turned round: the same positions, the other turn.
void expect_reversed_copies(const Mesh& m, std::size_t twins) {
  const std::size_t fronts = m.face_count() - twins;
  std::set<std::array<std::array<double, 3>, 3>> front;
  for (std::size_t f = 0; f < fronts; ++f) front.insert(turn(m, f));
  for (std::size_t f = fronts; f < m.face_count(); ++f) {
    std::array<std::array<double, 3>, 3> t = turn(m, f);
    std::swap(t[1], t[2]);
    EXPECT_TRUE(front.count(t)) << "face " << f << " is no front face turned round";
  }
}

}  // namespace

TEST(TwoSided, SheetKeepsItsRimClosedWithinTheTarget) {
  const Mesh in = two_sided_sheet(12);  // 288 faces a side
  EXPECT_EQ(test::open_edges_welded(in), 0u) << "the input's rim is closed by the back faces";
  SimplifyOptions o;
  o.target_faces = 80;
  const SimplifyResult r = simplify(in, o);
  EXPECT_EQ(r.dropped_duplicate_faces, 288u);
  EXPECT_GT(r.twin_faces, 0u);
  EXPECT_LE(r.mesh.face_count(), 80u) << "the twins count in the target";
  EXPECT_GE(r.mesh.face_count(), 70u);
  EXPECT_EQ(test::open_edges_welded(r.mesh), 0u) << "a crack opened along the rim";
  expect_reversed_copies(r.mesh, r.twin_faces);
  ASSERT_EQ(r.face_source.size(), r.mesh.face_count());
  // A twin's source is the input's back face of its front face's source.
  const std::size_t fronts = r.mesh.face_count() - r.twin_faces;
  for (std::size_t f = fronts; f < r.mesh.face_count(); ++f) EXPECT_GE(r.face_source[f], 288u);
  for (std::size_t f = 0; f < fronts; ++f) EXPECT_LT(r.face_source[f], 288u);
}

TEST(TwoSided, NoneLeavesTheRimOpen) {
  const Mesh in = two_sided_sheet(12);
  SimplifyOptions o;
  o.target_faces = 80;
  o.two_sided = TwoSided::None;
  const SimplifyResult r = simplify(in, o);
  EXPECT_EQ(r.twin_faces, 0u);
  EXPECT_GT(test::open_edges_welded(r.mesh), 0u);
  EXPECT_GE(r.mesh.face_count(), 79u);
  EXPECT_LE(r.mesh.face_count(), 80u);
}

TEST(TwoSided, ClosedTwoSidedSurfaceGetsNoTwins) {
  Mesh in = test::icosphere(2);
  const std::size_t nf = in.face_count();
  for (std::size_t f = 0; f < nf; ++f)
    in.indices.insert(in.indices.end(), {in.indices[3 * f + 1], in.indices[3 * f], in.indices[3 * f + 2]});
  SimplifyOptions o;
  o.target_faces = 60;
  const SimplifyResult two = simplify(in, o);
  o.two_sided = TwoSided::None;
  const SimplifyResult one = simplify(in, o);
  EXPECT_EQ(two.twin_faces, 0u);
  EXPECT_EQ(two.mesh.indices, one.mesh.indices);
  EXPECT_EQ(two.mesh.positions, one.mesh.positions);
}

TEST(TwoSided, SameDuplicateTurnIsNoTwin) {
  Mesh in = test::height_field(8, [](double x, double y) { return 0.1 * x * y; });
  const std::size_t nf = in.face_count();
  for (std::size_t f = 0; f < nf; ++f)  // the same turn again: a plain duplicate, not a back side
    in.indices.insert(in.indices.end(), {in.indices[3 * f + 1], in.indices[3 * f + 2], in.indices[3 * f]});
  SimplifyOptions o;
  o.target_faces = 40;
  const SimplifyResult r = simplify(in, o);
  EXPECT_EQ(r.dropped_duplicate_faces, nf);
  EXPECT_EQ(r.twin_faces, 0u);
}

TEST(TwoSided, BackVerticesTurnTheirNormals) {
  const Mesh in = two_sided_sheet_with_normals(10);
  const std::size_t input_vertices = in.vertex_count();
  SimplifyOptions o;
  o.target_faces = 60;
  o.target_vertices = 70;
  const SimplifyResult r = simplify(in, o);
  ASSERT_GT(r.twin_faces, 0u);
  EXPECT_LE(r.mesh.face_count(), 60u);
  EXPECT_LE(r.mesh.vertex_count(), 70u) << "the back vertices count in the vertex target";
  EXPECT_EQ(test::open_edges_welded(r.mesh), 0u);
  const VertexAttribute& n = test::attribute(r.mesh, AttributeKind::Normal);
  const std::size_t fronts = r.mesh.face_count() - r.twin_faces;
  for (std::size_t f = 0; f < r.mesh.face_count(); ++f)
    for (int c = 0; c < 3; ++c) {
      const std::uint32_t v = r.mesh.indices[3 * f + c];
      const double z = n.values[3 * std::size_t(v) + 2];
      // The front normals are those of the front's input vertices, up; the back's turn down.
      EXPECT_GT(f < fronts ? z : -z, 0.9) << "face " << f << " corner " << c;
    }
  ASSERT_EQ(r.vertex_source.size(), r.mesh.vertex_count());
  for (std::uint32_t s : r.vertex_source) EXPECT_LT(s, input_vertices);
}

TEST(TwoSided, ConsumedInputRunsAgainAsAView) {
  const Mesh in = two_sided_sheet(12);
  SimplifyOptions o;
  o.target_ratio = 0.25;  // of the 288 faces kept: 72, twins included
  const SimplifyResult viewed = simplify(MeshView(in), o);
  Mesh copy = in;
  const SimplifyResult consumed = simplify(std::move(copy), o);
  EXPECT_GT(viewed.twin_faces, 0u);
  EXPECT_LE(viewed.mesh.face_count(), 72u);
  EXPECT_EQ(consumed.mesh.indices, viewed.mesh.indices);
  EXPECT_EQ(consumed.mesh.positions, viewed.mesh.positions);
  EXPECT_EQ(consumed.face_source, viewed.face_source);
}

TEST(TwoSided, AllKeepsBothSidesWithinTheTarget) {
  const Mesh in = two_sided_sheet(12);  // 288 faces a side
  SimplifyOptions o;
  o.target_faces = 80;
  o.two_sided = TwoSided::All;
  const SimplifyResult r = simplify(in, o);
  ASSERT_GT(r.twin_faces, 0u);
  EXPECT_EQ(2 * r.twin_faces, r.mesh.face_count()) << "every front face has its back";
  EXPECT_LE(r.mesh.face_count(), 80u) << "the twins count in the target";
  EXPECT_GE(r.mesh.face_count(), 70u);
  EXPECT_EQ(test::open_edges_welded(r.mesh), 0u);
  expect_reversed_copies(r.mesh, r.twin_faces);
  ASSERT_EQ(r.face_source.size(), r.mesh.face_count());
  for (std::size_t f = 0; f < r.mesh.face_count(); ++f)
    EXPECT_EQ(r.face_source[f] >= 288u, f >= r.twin_faces) << "fronts from the front faces, backs from the backs";
}

TEST(TwoSided, AllTakesTheRatioOfBothSides) {
  const Mesh in = two_sided_sheet(12);  // 576 faces, both sides
  SimplifyOptions o;
  o.target_ratio = 0.25;
  o.two_sided = TwoSided::All;
  const SimplifyResult r = simplify(in, o);
  EXPECT_EQ(2 * r.twin_faces, r.mesh.face_count());
  EXPECT_LE(r.mesh.face_count(), 144u);
  EXPECT_GE(r.mesh.face_count(), 136u);
}

TEST(TwoSided, AllWithNormalsWithinTheVertexTarget) {
  const Mesh in = two_sided_sheet_with_normals(10);
  SimplifyOptions o;
  o.target_faces = 0;
  o.target_vertices = 60;
  o.two_sided = TwoSided::All;
  const SimplifyResult r = simplify(in, o);
  ASSERT_GT(r.twin_faces, 0u);
  EXPECT_EQ(2 * r.twin_faces, r.mesh.face_count());
  EXPECT_LE(r.mesh.vertex_count(), 60u) << "the back vertices count in the vertex target";
  EXPECT_GE(r.mesh.vertex_count(), 50u);
  const VertexAttribute& n = test::attribute(r.mesh, AttributeKind::Normal);
  for (std::size_t f = 0; f < r.mesh.face_count(); ++f) {
    const double z = n.values[3 * std::size_t(r.mesh.indices[3 * f]) + 2];
    EXPECT_GT(f < r.twin_faces ? z : -z, 0.9) << "face " << f;
  }
}

TEST(TwoSided, NamesAreTheCommandLines) {
  for (TwoSided t : {TwoSided::Rims, TwoSided::All, TwoSided::None}) {
    TwoSided back = TwoSided::None == t ? TwoSided::Rims : TwoSided::None;
    ASSERT_TRUE(from_string(to_string(t), back));
    EXPECT_EQ(back, t);
  }
  EXPECT_EQ(option_names<TwoSided>(), (std::vector<std::string>{"rims", "all", "none"}));
}

TEST(TwoSided, PartitionedRunWithDuplicatesRunsWhole) {
  const Mesh in = two_sided_sheet(16);
  SimplifyOptions o;
  o.target_faces = 120;
  PartitionOptions partition;
  partition.parts = 2;
  PartitionReport report;
  const SimplifyResult parted = simplify_partitioned(in, o, partition, &report);
  const SimplifyResult whole = simplify(in, o);
  EXPECT_EQ(report.parts, 1u) << "the twins are put back by the whole run only";
  EXPECT_GT(parted.twin_faces, 0u);
  EXPECT_EQ(parted.mesh.indices, whole.mesh.indices);
  EXPECT_EQ(parted.mesh.positions, whole.mesh.positions);
  EXPECT_EQ(test::open_edges_welded(parted.mesh), 0u);
  o.two_sided = TwoSided::None;  // one side: the parts stand
  const SimplifyResult one = simplify_partitioned(in, o, partition, &report);
  EXPECT_EQ(report.parts, 2u);
  EXPECT_EQ(one.twin_faces, 0u);
  // A ratio is of the faces left once the duplicates are dropped, as in a whole run.
  o.target_faces = 0;
  o.target_ratio = 0.25;
  const SimplifyResult ratio = simplify_partitioned(in, o, partition, &report);
  EXPECT_EQ(report.parts, 2u);
  EXPECT_EQ(ratio.input_faces, in.face_count() / 2);
  EXPECT_LE(ratio.mesh.face_count(), in.face_count() / 8);
  EXPECT_GE(ratio.mesh.face_count(), in.face_count() / 8 - 8);
}
