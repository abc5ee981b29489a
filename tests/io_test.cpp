// Mesh file formats: round trips of every format and encoding, triangulation, OBJ/PLY/STL/OFF
// details, welding, vertex properties, atomic and deterministic writing, and every shared mesh.
#include "qem/gltf.h"
#include "qem/io.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "test_meshes.h"

namespace {

using qem::FileFormat;
using qem::LoadOptions;
using qem::LoadReport;
using qem::Mesh;

/// Little- or big-endian byte writer for hand-made binary test files.
struct Bytes {
  std::string s;
  bool big = false;
  template <class T>
  Bytes& put(T v) {
    unsigned char b[sizeof(T)];
    std::memcpy(b, &v, sizeof(T));
    if (big == (std::endian::native == std::endian::little)) std::reverse(b, b + sizeof(T));
    s.append(reinterpret_cast<const char*>(b), sizeof(T));
    return *this;
  }
  Bytes& text(const std::string& t) {
    s += t;
    return *this;
  }
};

Mesh sample_mesh() {
  // Coordinates that are not exactly representable in float, so precision handling is visible.
  return qem::test::transformed(qem::test::icosphere(2), 1.7, 0.1, -2.3, 3.3);
}

std::string read_bytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream f(path, std::ios::binary);
  f << bytes;
}

std::vector<double> as_float(const std::vector<double>& v) {
  std::vector<double> r(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) r[i] = static_cast<float>(v[i]);
  return r;
}

std::vector<std::string> temp_leftovers(const std::string& dir) {
  std::vector<std::string> r;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().filename().string().find("qem-tmp") != std::string::npos) r.push_back(e.path().string());
  return r;
}

// --- round trips ---------------------------------------------------------------------------------

TEST(IoRoundTrip, ObjKeepsDoublesExactly) {
  Mesh m = sample_mesh();
  Mesh r = qem::parse_mesh(qem::serialize_mesh(m, FileFormat::Obj), FileFormat::Obj, "t.obj");
  EXPECT_EQ(r.positions, m.positions);
  EXPECT_EQ(r.indices, m.indices);
}

TEST(IoRoundTrip, OffKeepsDoublesExactly) {
  Mesh m = sample_mesh();
  Mesh r = qem::parse_mesh(qem::serialize_mesh(m, FileFormat::Off), FileFormat::Off, "t.off");
  EXPECT_EQ(r.positions, m.positions);
  EXPECT_EQ(r.indices, m.indices);
}

TEST(IoRoundTrip, PlyBinaryAndAsciiFloat) {
  Mesh m = sample_mesh();
  for (bool binary : {true, false}) {
    LoadReport rep;
    Mesh r =
        qem::parse_mesh(qem::serialize_mesh(m, FileFormat::Ply, binary), FileFormat::Ply, "t.ply", {}, &rep);
    EXPECT_EQ(rep.binary, binary);
    EXPECT_FALSE(rep.double_precision);
    EXPECT_EQ(r.positions, as_float(m.positions)) << "binary=" << binary;
    EXPECT_EQ(r.indices, m.indices);
  }
}

TEST(IoRoundTrip, PlyDoublePrecision) {
  Mesh m = sample_mesh();
  for (bool binary : {true, false}) {
    qem::SaveOptions o;
    o.format = FileFormat::Ply;
    o.binary = binary;
    o.double_precision = true;
    LoadReport rep;
    Mesh r = qem::parse_mesh(qem::serialize_mesh(m, o), FileFormat::Ply, "t.ply", {}, &rep);
    EXPECT_TRUE(rep.double_precision);
    EXPECT_EQ(r.positions, m.positions);
    EXPECT_EQ(r.indices, m.indices);
  }
}

TEST(IoRoundTrip, StlBinaryAndAsciiWeldBackToTheSameMesh) {
  Mesh m = sample_mesh();
  for (bool binary : {true, false}) {
    LoadReport rep;
    Mesh r =
        qem::parse_mesh(qem::serialize_mesh(m, FileFormat::Stl, binary), FileFormat::Stl, "t.stl", {}, &rep);
    EXPECT_EQ(rep.binary, binary);
    ASSERT_EQ(r.face_count(), m.face_count());
    EXPECT_EQ(r.vertex_count(), m.vertex_count());  // welded: every corner shared again
    EXPECT_EQ(rep.vertices_welded, 3 * m.face_count() - m.vertex_count());
    for (std::size_t c = 0; c < m.indices.size(); ++c)
      for (int k = 0; k < 3; ++k)
        ASSERT_EQ(r.positions[3 * r.indices[c] + k], static_cast<float>(m.positions[3 * m.indices[c] + k]));
  }
}

TEST(IoRoundTrip, PlyBigEndianWrittenByHand) {
  // Two triangles, double coordinates, ushort count + uint indices, big endian.
  Bytes b;
  b.big = true;
  b.text(
      "ply\nformat binary_big_endian 1.0\nelement vertex 4\nproperty double x\nproperty double y\n"
      "property double z\nelement face 1\nproperty list ushort uint vertex_indices\nend_header\n");
  const double p[4][3] = {{0, 0, 0}, {1.1, 0, 0}, {1, 1, -0.3}, {0, 1, 1e-7}};
  for (auto& v : p) b.put(v[0]).put(v[1]).put(v[2]);
  b.put<std::uint16_t>(4)
      .put<std::uint32_t>(0)
      .put<std::uint32_t>(1)
      .put<std::uint32_t>(2)
      .put<std::uint32_t>(3);
  LoadReport rep;
  Mesh m = qem::parse_mesh(b.s, FileFormat::Ply, "be.ply", {}, &rep);
  EXPECT_TRUE(rep.binary);
  EXPECT_TRUE(rep.double_precision);
  EXPECT_EQ(rep.polygons_triangulated, 1u);
  ASSERT_EQ(m.vertex_count(), 4u);
  for (int i = 0; i < 4; ++i)
    for (int k = 0; k < 3; ++k) EXPECT_EQ(m.positions[3 * i + k], p[i][k]);
  EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}));
}

TEST(IoRoundTrip, PlyLittleAndBigEndianAgree) {
  Mesh ref = qem::test::cube();
  for (bool big : {false, true}) {
    Bytes b;
    b.big = big;
    b.text(std::string("ply\nformat ") + (big ? "binary_big_endian" : "binary_little_endian") +
           " 1.0\nelement vertex 8\nproperty float x\nproperty float y\nproperty float z\n"
           "element face 12\nproperty list uchar int vertex_indices\nend_header\n");
    for (std::size_t i = 0; i < 8; ++i)
      for (int k = 0; k < 3; ++k) b.put(static_cast<float>(ref.positions[3 * i + k]));
    for (std::size_t f = 0; f < 12; ++f) {
      b.put<std::uint8_t>(3);
      for (int k = 0; k < 3; ++k) b.put(static_cast<std::int32_t>(ref.indices[3 * f + k]));
    }
    Mesh m = qem::parse_mesh(b.s, FileFormat::Ply, "cube.ply");
    EXPECT_EQ(m.positions, ref.positions) << "big=" << big;
    EXPECT_EQ(m.indices, ref.indices) << "big=" << big;
  }
}

// --- triangulation -------------------------------------------------------------------------------

const char* kQuadPentagonObj =
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 3 0 0\nv 3 1 0\nv 2.5 2 0\nv 2 1 0\n"
    "f 1 2 3 4\nf 5 6 7 8 9\n";
const std::vector<std::uint32_t> kQuadPentagonTris = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7, 4, 7, 8};

TEST(IoTriangulation, ObjQuadAndPentagonFan) {
  LoadReport rep;
  Mesh m = qem::parse_mesh(kQuadPentagonObj, FileFormat::Obj, "poly.obj", {}, &rep);
  EXPECT_EQ(m.indices, kQuadPentagonTris);
  EXPECT_EQ(rep.polygons_triangulated, 2u);
}

TEST(IoTriangulation, OffAndAsciiPlyQuadAndPentagonFan) {
  const char* off =
      "OFF\n# comment\n9 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0 0\n3 0 0\n3 1 0\n2.5 2 0\n2 1 0\n"
      "4 0 1 2 3\n5 4 5 6 7 8 255 0 0\n";
  EXPECT_EQ(qem::parse_mesh(off, FileFormat::Off, "poly.off").indices, kQuadPentagonTris);
  const char* ply =
      "ply\nformat ascii 1.0\nelement vertex 9\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 2\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n1 1 0\n0 1 0\n2 0 0\n3 0 0\n3 1 0\n2.5 2 0\n2 1 0\n4 0 1 2 3\n5 4 5 6 7 8\n";
  LoadReport rep;
  EXPECT_EQ(qem::parse_mesh(ply, FileFormat::Ply, "poly.ply", {}, &rep).indices, kQuadPentagonTris);
  EXPECT_EQ(rep.polygons_triangulated, 2u);
}

// --- OBJ -----------------------------------------------------------------------------------------

TEST(IoObj, NegativeIndicesSlashesColoursContinuationAndIgnoredStatements) {
  const char* obj =
      "# header comment\nmtllib x.mtl\no thing\ng group\ns 1\nusemtl red\n"
      "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv +1 1 0\nv 0 1 \\\n 0\n"
      "vt 0 0\nvn 0 0 1\n"
      "f -4/1/1 -3/1/1 -2/1/1\n"
      "f 1//1 3//1 \\\r\n 4//1  # trailing comment\n"
      "l 1 2\np 3\n";
  LoadOptions positions_only;  // the wedges these vt/vn make are io_attributes_test.cpp's business
  positions_only.read_attributes = false;
  Mesh m = qem::parse_mesh(obj, FileFormat::Obj, "neg.obj", positions_only);
  ASSERT_EQ(m.vertex_count(), 4u);
  EXPECT_EQ(m.positions, (std::vector<double>{0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}));
  EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}));
}

TEST(IoObj, RelativeIndicesResolveAgainstVerticesReadSoFar) {
  const char* obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 5 5 5\nv 6 5 5\nf -1 -2 -3\n";
  Mesh m = qem::parse_mesh(obj, FileFormat::Obj, "rel.obj");
  EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{0, 1, 2, 4, 3, 2}));
}

TEST(IoObj, ForwardPositiveIndicesAreAccepted) {
  Mesh m = qem::parse_mesh("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n", FileFormat::Obj, "fwd.obj");
  EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{0, 1, 2}));
}

// --- STL -----------------------------------------------------------------------------------------

std::string binary_stl(const std::string& header80, const std::vector<std::array<float, 9>>& tris) {
  Bytes b;
  std::string h = header80;
  h.resize(80, ' ');
  b.text(h).put(static_cast<std::uint32_t>(tris.size()));
  for (const auto& t : tris) {
    b.put(0.0f).put(0.0f).put(1.0f);
    for (float v : t) b.put(v);
    b.put<std::uint16_t>(0);
  }
  return b.s;
}

TEST(IoStl, BinaryWithSolidHeaderIsReadAsBinary) {
  std::string s = binary_stl("solid this is really binary", {{0, 0, 0, 1, 0, 0, 0, 1, 0}});
  LoadReport rep;
  Mesh m = qem::parse_mesh(s, FileFormat::Stl, "solid.stl", {}, &rep);
  EXPECT_TRUE(rep.binary);
  EXPECT_EQ(m.face_count(), 1u);
  EXPECT_EQ(m.positions, (std::vector<double>{0, 0, 0, 1, 0, 0, 0, 1, 0}));
  // Sniffed by content as well.
  EXPECT_EQ(qem::parse_mesh(s, FileFormat::Auto, "solid.bin").face_count(), 1u);
}

TEST(IoStl, WeldingMergesExactlyCoincidentCornersInFirstOccurrenceOrder) {
  // Two triangles sharing the edge (1,0,0)-(0,1,0); -0 and +0 are the same position.
  std::string s = binary_stl("x", {{0, 0, 0, 1, 0, 0, 0, 1, 0}, {1, 0, 0, 1, 1, 0, 0, 1, -0.0f}});
  LoadReport rep;
  Mesh m = qem::parse_mesh(s, FileFormat::Stl, "w.stl", {}, &rep);
  EXPECT_EQ(m.vertex_count(), 4u);
  EXPECT_EQ(rep.vertices_welded, 2u);
  EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{0, 1, 2, 1, 3, 2}));
  EXPECT_EQ(m.positions, (std::vector<double>{0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0}));

  LoadOptions off;
  off.weld = qem::Weld::Off;
  Mesh soup = qem::parse_mesh(s, FileFormat::Stl, "w.stl", off);
  EXPECT_EQ(soup.vertex_count(), 6u);
  EXPECT_EQ(soup.indices, (std::vector<std::uint32_t>{0, 1, 2, 3, 4, 5}));

  // weld_exact on the soup gives the same mesh as welding while reading.
  EXPECT_EQ(qem::weld_exact(soup), 2u);
  EXPECT_EQ(soup.positions, m.positions);
  EXPECT_EQ(soup.indices, m.indices);
}

TEST(IoStl, WeldExactCarriesVertexPropertiesAndOtherFormatsOnRequest) {
  Mesh m;
  m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  m.indices = {0, 1, 2, 3, 4, 5};
  m.vertex_properties.push_back({"q", {10, 11, 12, 13, 14, 15}});
  EXPECT_EQ(qem::weld_exact(m), 2u);
  EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{0, 1, 2, 1, 3, 2}));
  EXPECT_EQ(m.vertex_properties[0].values, (std::vector<double>{10, 11, 12, 14}));

  LoadOptions on;
  on.weld = qem::Weld::On;
  LoadReport rep;
  Mesh o = qem::parse_mesh("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 0 0\nf 1 2 3\nf 4 2 3\n", FileFormat::Obj, "w.obj",
                           on, &rep);
  EXPECT_EQ(o.vertex_count(), 3u);
  EXPECT_EQ(rep.vertices_welded, 1u);
  EXPECT_EQ(o.indices, (std::vector<std::uint32_t>{0, 1, 2, 1, 1, 2}));
}

TEST(IoStl, AsciiWithNamesAndMultipleSolids) {
  const char* s =
      "solid a b c\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 0 1 0\n"
      "  endloop\n endfacet\nendsolid a\nsolid second\nfacet normal 0 0 1\nouter loop\nvertex 1 0 0\n"
      "vertex 1 1 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid\n";
  LoadReport rep;
  Mesh m = qem::parse_mesh(s, FileFormat::Auto, "ascii.stl", {}, &rep);
  EXPECT_FALSE(rep.binary);
  EXPECT_EQ(m.vertex_count(), 4u);
  EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{0, 1, 2, 1, 3, 2}));
}

// --- PLY -----------------------------------------------------------------------------------------

TEST(IoPly, ExtraPropertiesListsAndElementsAreSkipped) {
  const char* ply =
      "ply\r\nformat ascii 1.0\r\ncomment made by hand\r\nobj_info nothing\r\n"
      "element material 1\r\nproperty list uchar float weights\r\nproperty uchar id\r\n"
      "element vertex 4\r\nproperty uchar red\r\nproperty float x\r\nproperty list int int8 junk\r\n"
      "property float32 y\r\nproperty float64 z\r\nproperty float nx\r\n"
      "element edge 2\r\nproperty int vertex1\r\nproperty int vertex2\r\n"
      "element face 2\r\nproperty uchar flags\r\nproperty list uint8 uint32 vertex_index\r\n"
      "property list uchar float texcoord\r\nproperty uchar red\r\nend_header\r\n"
      "3 0.5 0.25 0.125 7\r\n"
      "255 0 2 -1 5 0 0 0.1\r\n1 1 0 0 0 0.2\r\n2 1 0 1 0 0.3\r\n3 0 3 1 2 3 1 1 0.4\r\n"
      "0 1\r\n1 2\r\n"
      "9 3 0 1 2 6 0 0 1 0 0 1 200\r\n9 3 0 2 3 0 201\r\n";
  LoadOptions keep;
  keep.keep_vertex_properties = true;
  Mesh m = qem::parse_mesh(ply, FileFormat::Ply, "extra.ply", keep);
  EXPECT_EQ(m.positions, (std::vector<double>{0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 1}));
  EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}));
  ASSERT_EQ(m.vertex_properties.size(), 2u);
  EXPECT_EQ(m.vertex_properties[0].name, "red");
  EXPECT_EQ(m.vertex_properties[0].values, (std::vector<double>{255, 1, 2, 3}));
  ASSERT_NE(m.find_property("nx"), nullptr);
  EXPECT_EQ(m.find_property("nx")->values[3], static_cast<double>(0.4f));  // declared float
  // Without the option no property is kept.
  EXPECT_TRUE(qem::parse_mesh(ply, FileFormat::Ply, "extra.ply").vertex_properties.empty());
}

TEST(IoPly, BinaryExtraPropertiesAndElementsBothEndiannesses) {
  for (bool big : {false, true}) {
    Bytes b;
    b.big = big;
    b.text(std::string("ply\nformat ") + (big ? "binary_big_endian" : "binary_little_endian") +
           " 1.0\nelement vertex 3\nproperty short s\nproperty float x\nproperty float y\nproperty float z\n"
           "property list uchar double junk\nproperty double q\n"
           "element other 2\nproperty int a\nproperty list char ushort b\n"
           "element face 1\nproperty char c\nproperty list char uint vertex_indices\nproperty ushort "
           "d\nend_header\n");
    const float p[3][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    for (int i = 0; i < 3; ++i) {
      b.put<std::int16_t>(-7).put(p[i][0]).put(p[i][1]).put(p[i][2]);
      b.put<std::uint8_t>(static_cast<std::uint8_t>(i));
      for (int j = 0; j < i; ++j) b.put(1.5);
      b.put(0.25 * i);
    }
    b.put<std::int32_t>(1).put<std::int8_t>(2).put<std::uint16_t>(1).put<std::uint16_t>(2);
    b.put<std::int32_t>(1).put<std::int8_t>(0);
    b.put<std::int8_t>(5).put<std::int8_t>(3).put<std::uint32_t>(2).put<std::uint32_t>(1).put<std::uint32_t>(
        0);
    b.put<std::uint16_t>(9);
    LoadOptions keep;
    keep.keep_vertex_properties = true;
    Mesh m = qem::parse_mesh(b.s, FileFormat::Ply, "bin.ply", keep);
    EXPECT_EQ(m.positions, (std::vector<double>{0, 0, 0, 1, 0, 0, 0, 1, 0})) << "big=" << big;
    EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{2, 1, 0}));
    ASSERT_NE(m.find_property("q"), nullptr);
    EXPECT_EQ(m.find_property("q")->values, (std::vector<double>{0, 0.25, 0.5}));
    EXPECT_EQ(m.find_property("s")->values, (std::vector<double>{-7, -7, -7}));
  }
}

TEST(IoPly, FirstBinaryByteMayBeANewline) {
  // x of the first vertex is a float whose first little-endian byte is 0x0A.
  float x;
  std::uint32_t bits = 0x3F80000Au;
  std::memcpy(&x, &bits, 4);
  Bytes b;
  b.text(
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n");
  b.put(x).put(0.0f).put(0.0f).put(0.0f).put(1.0f).put(0.0f).put(1.0f).put(1.0f).put(0.0f);
  b.put<std::uint8_t>(3).put<std::int32_t>(0).put<std::int32_t>(1).put<std::int32_t>(2);
  Mesh m = qem::parse_mesh(b.s, FileFormat::Ply, "nl.ply");
  EXPECT_EQ(m.positions[0], static_cast<double>(x));
}

TEST(IoPly, TristripsWithRestarts) {
  const char* ply =
      "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\nproperty float z\n"
      "element tristrips 1\nproperty list int int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n1 1 0\n0 2 0\n1 2 0\n"
      "9 0 1 2 3 -1 2 3 4 5\n";
  Mesh m = qem::parse_mesh(ply, FileFormat::Ply, "strip.ply");
  // Strip 0 1 2 3 -> (0 1 2), (2 1 3); strip 2 3 4 5 -> (2 3 4), (4 3 5).
  EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{0, 1, 2, 2, 1, 3, 2, 3, 4, 4, 3, 5}));
}

// The header of Blender 2.4x's PLY exporter, whose credit line lacks the `comment` keyword; assimp
// and MeshLab read such files (issue 21). A quad, so the body is read past the skipped line.
std::string blender_head(const std::string& format) {
  return "ply\nformat " + format +
         " 1.0\nCreated by Blender3D 247 - www.blender.org, source file: 'x.blend'\n"
         "element vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\n"
         "property float ny\nproperty float nz\nelement face 1\nproperty list uchar uint vertex_indices\n"
         "end_header\n";
}

TEST(IoPly, HeaderLineWithAnUnknownKeywordIsSkippedWithAWarning) {
  const std::vector<double> pos = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  const std::string ascii =
      blender_head("ascii") + "0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n0 1 0 0 0 1\n4 0 1 2 3\n";
  Bytes bin;
  bin.text(blender_head("binary_little_endian"));
  for (std::size_t i = 0; i < 4; ++i) {
    for (int k = 0; k < 3; ++k) bin.put(static_cast<float>(pos[3 * i + k]));
    bin.put(0.0f).put(0.0f).put(1.0f);
  }
  bin.put<std::uint8_t>(4)
      .put<std::uint32_t>(0)
      .put<std::uint32_t>(1)
      .put<std::uint32_t>(2)
      .put<std::uint32_t>(3);
  for (const std::string& bytes : {ascii, bin.s}) {
    LoadReport rep;
    Mesh m = qem::parse_mesh(bytes, FileFormat::Ply, "blender.ply", {}, &rep);
    EXPECT_EQ(m.positions, pos);
    EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}));
    EXPECT_EQ(rep.polygons_triangulated, 1u);
    EXPECT_EQ(rep.warnings, (std::vector<std::string>{
                                "blender.ply, line 3: unknown PLY header keyword 'Created', line skipped"}));
    // A report reused for the next file starts empty.
    qem::parse_mesh(qem::serialize_mesh(m, FileFormat::Ply), FileFormat::Ply, "clean.ply", {}, &rep);
    EXPECT_TRUE(rep.warnings.empty());
  }
  // `comment` and `obj_info` are part of the format: no warning.
  LoadReport rep;
  std::string commented = ascii;
  commented.replace(commented.find("Created"), 7, "comment Created");
  commented.replace(commented.find("element vertex"), 0, "obj_info made by hand\n");
  EXPECT_EQ(qem::parse_mesh(commented, FileFormat::Ply, "c.ply", {}, &rep).positions, pos);
  EXPECT_TRUE(rep.warnings.empty());
}

TEST(IoPly, ManySkippedHeaderLinesAreCountedNotListed) {
  std::string junk;
  for (int i = 0; i < 12; ++i) junk += "junk " + std::to_string(i) + "\n";
  const std::string ply = "ply\nformat ascii 1.0\n" + junk +
                          "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                          "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                          "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  LoadReport rep;
  EXPECT_EQ(qem::parse_mesh(ply, FileFormat::Ply, "j.ply", {}, &rep).face_count(), 1u);
  ASSERT_EQ(rep.warnings.size(), 9u);
  EXPECT_EQ(rep.warnings[0], "j.ply, line 3: unknown PLY header keyword 'junk', line skipped");
  EXPECT_EQ(rep.warnings[7], "j.ply, line 10: unknown PLY header keyword 'junk', line skipped");
  EXPECT_EQ(rep.warnings[8], "j.ply: 4 more header lines with an unknown keyword skipped");
}

TEST(IoPly, VertexPropertiesRoundTripInEveryPlyEncoding) {
  Mesh m = qem::test::tetrahedron();
  m.vertex_properties.push_back({"k1", {0.5, -1.25, 3.0, 1e-3}});
  m.vertex_properties.push_back({"k2", {1.0 / 3, 2.0, -0.0, 7.0}});
  LoadOptions keep;
  keep.keep_vertex_properties = true;
  for (bool binary : {true, false})
    for (bool dbl : {false, true}) {
      qem::SaveOptions o;
      o.format = FileFormat::Ply;
      o.binary = binary;
      o.double_precision = dbl;
      Mesh r = qem::parse_mesh(qem::serialize_mesh(m, o), FileFormat::Ply, "props.ply", keep);
      ASSERT_EQ(r.vertex_properties.size(), 2u);
      for (int p = 0; p < 2; ++p) {
        EXPECT_EQ(r.vertex_properties[p].name, m.vertex_properties[p].name);
        EXPECT_EQ(r.vertex_properties[p].values,
                  dbl ? m.vertex_properties[p].values : as_float(m.vertex_properties[p].values))
            << "binary=" << binary << " double=" << dbl;
      }
    }
}

TEST(IoPly, CurvatureFileKeepsK1K2) {
  std::string path = qem::test::shared_data("synth_ellipsoid_11k_curv.ply");
  if (path.empty()) GTEST_SKIP() << "shared data not available";
  LoadOptions keep;
  keep.keep_vertex_properties = true;
  Mesh m = qem::load_mesh(path, keep);
  ASSERT_NE(m.find_property("k1"), nullptr);
  ASSERT_NE(m.find_property("k2"), nullptr);
  EXPECT_EQ(m.find_property("k1")->values.size(), m.vertex_count());
  for (std::size_t i = 0; i < m.vertex_count(); ++i)
    EXPECT_GE(m.find_property("k1")->values[i], m.find_property("k2")->values[i]);
}

// --- formats, dispatch ---------------------------------------------------------------------------

TEST(IoFormat, FromExtensionAndContent) {
  EXPECT_EQ(qem::format_from_extension("a/b.OBJ"), FileFormat::Obj);
  EXPECT_EQ(qem::format_from_extension("x.Ply"), FileFormat::Ply);
  EXPECT_EQ(qem::format_from_extension("x.stl"), FileFormat::Stl);
  EXPECT_EQ(qem::format_from_extension("x.off"), FileFormat::Off);
  EXPECT_EQ(qem::format_from_extension("x.glb"), FileFormat::Gltf);
  EXPECT_EQ(qem::format_from_extension("x.GLTF"), FileFormat::Gltf);
  EXPECT_EQ(qem::format_from_extension("x.fbx"), FileFormat::Auto);
  EXPECT_EQ(qem::format_from_extension("dir.ply/file"), FileFormat::Auto);
  Mesh m = qem::test::cube();
  for (FileFormat f : {FileFormat::Obj, FileFormat::Ply, FileFormat::Stl, FileFormat::Off}) {
    LoadReport rep;
    Mesh r = qem::parse_mesh(qem::serialize_mesh(m, f), FileFormat::Auto, "noext", {}, &rep);
    EXPECT_EQ(rep.format, f);
    EXPECT_EQ(r.face_count(), m.face_count());
  }
}

TEST(IoFormat, OffVariantsAndCountsOnTheHeaderLine) {
  const char* coff = "COFF 3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n0 1 0 0 0 255 255\n3 0 1 2\n";
  EXPECT_EQ(qem::parse_mesh(coff, FileFormat::Off, "c.off").face_count(), 1u);
  const char* noff =
      "# lead comment\nNOFF\n3 1\n0 0 0 0 0 1\n1 0 0 0 0 1 # c\n0 1 0 0 0 1\n3 0 1 2 0.5 0.5 0.5\n";
  EXPECT_EQ(qem::parse_mesh(noff, FileFormat::Off, "n.off").vertex_count(), 3u);
  const char* off4 = "4OFF\n3 1 0\n0 0 0 2\n2 0 0 2\n0 4 0 2\n3 0 1 2\n";
  EXPECT_EQ(qem::parse_mesh(off4, FileFormat::Off, "4.off").positions,
            (std::vector<double>{0, 0, 0, 1, 0, 0, 0, 2, 0}));
}

// --- writing -------------------------------------------------------------------------------------

TEST(IoWrite, DeterministicBytes) {
  Mesh m = sample_mesh();
  m.vertex_properties.push_back({"w", std::vector<double>(m.vertex_count(), 0.125)});
  const std::string dir = qem::test::temp_dir();
  for (const char* ext : {"obj", "ply", "stl", "off"})
    for (bool binary : {true, false}) {
      qem::SaveOptions o;
      o.binary = binary;
      std::string a = dir + "/det_a." + ext, b = dir + "/det_b." + ext;
      qem::save_mesh(a, m, o);
      qem::save_mesh(b, m, o);
      EXPECT_EQ(read_bytes(a), read_bytes(b)) << ext;
      EXPECT_EQ(read_bytes(a), qem::serialize_mesh(m, qem::format_from_extension(a), binary)) << ext;
    }
}

TEST(IoWrite, AtomicSaveLeavesTargetUntouchedOnFailure) {
  const std::string dir = qem::test::temp_dir() + "/atomic";
  std::filesystem::create_directories(dir);
  const std::string target = dir + "/mesh.ply";
  write_bytes(target, "original");
  Mesh bad = qem::test::cube();
  bad.indices[5] = 99;  // out of range: serialisation fails before anything is written
  EXPECT_THROW(qem::save_mesh(target, bad), qem::Error);
  EXPECT_EQ(read_bytes(target), "original");
  // A missing folder.
  EXPECT_THROW(qem::save_mesh(dir + "/missing/sub/mesh.ply", qem::test::cube()), qem::Error);
  EXPECT_FALSE(std::filesystem::exists(dir + "/missing"));
  // The target is a directory: the rename fails and the temporary file must go.
  std::filesystem::create_directories(dir + "/adir.ply/inner");
  EXPECT_THROW(qem::save_mesh(dir + "/adir.ply", qem::test::cube()), qem::Error);
  EXPECT_TRUE(std::filesystem::is_directory(dir + "/adir.ply/inner"));
  // Unknown extension.
  EXPECT_THROW(qem::save_mesh(dir + "/mesh.xyz", qem::test::cube()), qem::Error);
  // A read-only folder (meaningless for root, who may write anyway).
  if (::geteuid() != 0) {
    std::filesystem::create_directories(dir + "/ro");
    write_bytes(dir + "/ro/mesh.obj", "keep");
    std::filesystem::permissions(dir + "/ro",
                                 std::filesystem::perms::owner_read | std::filesystem::perms::owner_exec);
    EXPECT_THROW(qem::save_mesh(dir + "/ro/mesh.obj", qem::test::cube()), qem::Error);
    std::filesystem::permissions(dir + "/ro", std::filesystem::perms::owner_all);
    EXPECT_EQ(read_bytes(dir + "/ro/mesh.obj"), "keep");
  }
  EXPECT_TRUE(temp_leftovers(dir).empty());
  // And a successful save replaces the target completely.
  qem::save_mesh(target, qem::test::cube());
  EXPECT_EQ(qem::load_mesh(target).face_count(), 12u);
  EXPECT_TRUE(temp_leftovers(dir).empty());
}

TEST(IoWrite, FloatWritersRefuseCoordinatesBeyondFloatAndDoublePlyKeepsThem) {
  qem::Mesh m = qem::test::cube();
  m.positions[3 * 5 + 1] = -4e38;  // just beyond FLT_MAX (3.4028e38)
  for (bool binary : {false, true}) {
    for (FileFormat f : {FileFormat::Ply, FileFormat::Stl}) {
      try {
        qem::serialize_mesh(m, f, binary);
        ADD_FAILURE() << "no error for format " << int(f) << " binary=" << binary;
      } catch (const qem::Error& e) {
        EXPECT_NE(std::string(e.what()).find("vertex 5 has coordinate -4e+38"), std::string::npos)
            << e.what();
      }
    }
    qem::SaveOptions o;
    o.format = FileFormat::Ply;
    o.binary = binary;
    o.double_precision = true;
    EXPECT_EQ(qem::parse_mesh(qem::serialize_mesh(m, o), FileFormat::Ply, "x").positions, m.positions);
  }
  // FLT_MAX itself is representable and written as is.
  m.positions[3 * 5 + 1] = -double(std::numeric_limits<float>::max());
  EXPECT_EQ(qem::parse_mesh(qem::serialize_mesh(m, FileFormat::Ply, true), FileFormat::Ply, "x").positions,
            m.positions);
  // A property value beyond float is refused by a float PLY too, an infinite one is kept.
  m.positions[3 * 5 + 1] = 1;
  m.vertex_properties.push_back({"q", std::vector<double>(m.vertex_count(), 0)});
  m.vertex_properties[0].values[2] = std::numeric_limits<double>::infinity();
  EXPECT_NO_THROW(qem::serialize_mesh(m, FileFormat::Ply, true));
  m.vertex_properties[0].values[3] = 1e39;
  EXPECT_THROW(qem::serialize_mesh(m, FileFormat::Ply, true), qem::Error);
}

TEST(IoWrite, NonFiniteCoordinatesAreRefusedByEveryWriter) {
  qem::Mesh m = qem::test::cube();
  m.positions[7] = std::numeric_limits<double>::quiet_NaN();
  for (FileFormat f : {FileFormat::Obj, FileFormat::Ply, FileFormat::Stl, FileFormat::Off}) {
    try {
      qem::serialize_mesh(m, f, false);
      ADD_FAILURE() << "no error for format " << int(f);
    } catch (const qem::Error& e) {
      EXPECT_NE(std::string(e.what()).find("cannot write mesh: vertex 2 has a non-finite coordinate"),
                std::string::npos)
          << e.what();
    }
  }
}

TEST(IoWrite, BinaryStlHeaderDoesNotStartWithSolid) {
  std::string s = qem::serialize_mesh(qem::test::cube(), FileFormat::Stl, true);
  EXPECT_NE(s.substr(0, 5), "solid");
  EXPECT_EQ(s.size(), 84u + 50u * 12u);
}

// --- shared meshes -------------------------------------------------------------------------------

/// Minimal reader of the per-file facts in gen/stats.jsonl: file -> (V, T).
std::map<std::string, std::pair<long, long>> read_stats(const std::string& path) {
  std::map<std::string, std::pair<long, long>> r;
  std::ifstream f(path);
  std::string line;
  auto field = [](const std::string& l, const std::string& key) -> std::string {
    std::size_t at = l.find("\"" + key + "\": ");
    if (at == std::string::npos) return "";
    at += key.size() + 4;
    std::size_t end = l.find_first_of(",}", at);
    return l.substr(at, end - at);
  };
  while (std::getline(f, line)) {
    std::string file = field(line, "file"), v = field(line, "V"), t = field(line, "T");
    if (file.size() < 2 || v.empty() || t.empty() || v == "null" || t == "null") continue;
    r[file.substr(1, file.size() - 2)] = {std::stol(v), std::stol(t)};
  }
  return r;
}

TEST(IoSharedData, EveryMeshLoadsWithTheCatalogueCounts) {
  std::string any = qem::test::shared_data("gh_cow.obj");
  if (any.empty()) GTEST_SKIP() << "shared data not available";
  const std::filesystem::path dir = std::filesystem::path(any).parent_path();
  std::map<std::string, std::pair<long, long>> stats;
  if (std::string s = qem::test::shared_data("gen/stats.jsonl"); !s.empty()) stats = read_stats(s);
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (qem::format_from_extension(e.path().string()) != FileFormat::Auto) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  ASSERT_FALSE(files.empty());
  std::size_t checked = 0;
  // The catalogue counts positions (OBJ `v` lines), not the wedges that attributes split them into
  // (io_attributes_test.cpp checks those).
  LoadOptions positions_only;
  positions_only.read_attributes = false;
  for (const auto& p : files) {
    SCOPED_TRACE(p.filename().string());
    Mesh m;
    ASSERT_NO_THROW(m = qem::load_mesh(p.string(), positions_only));
    ASSERT_NO_THROW(qem::load_mesh(p.string()));
    ASSERT_GT(m.face_count(), 0u);
    for (double c : m.positions) ASSERT_TRUE(std::isfinite(c));
    for (std::uint32_t i : m.indices) ASSERT_LT(i, m.vertex_count());
    auto it = stats.find(p.filename().string());
    if (it != stats.end()) {
      auto vertices = static_cast<long>(m.vertex_count()), faces = static_cast<long>(m.face_count());
      if (qem::format_from_extension(p.string()) == FileFormat::Gltf) {
        // The catalogue counts each glTF mesh once; the scene may place one several times
        // (CesiumMilkTruck's two wheel nodes share one mesh).
        vertices = faces = 0;
        const qem::GltfDocument document = qem::GltfDocument::load(p.string());  // outlives the loop
        for (const qem::GltfPrimitiveInfo& prim : document.primitives())
          vertices += static_cast<long>(prim.vertex_count), faces += static_cast<long>(prim.face_count);
      }
      EXPECT_EQ(vertices, it->second.first);
      EXPECT_EQ(faces, it->second.second);
      ++checked;
    }
  }
  if (!stats.empty()) {
    EXPECT_GT(checked, 50u);
  }
}

}  // namespace
