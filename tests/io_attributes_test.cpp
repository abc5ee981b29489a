// Appearance attributes in OBJ and PLY (docs/attributes.md): OBJ face-varying vt/vn read as wedges
// and welded on write, usemtl/mtllib, `v x y z r g b` colours; PLY normals, texture coordinates
// and colours (uchar and float, with alpha), binary and ASCII; errors with file and line; every
// shared OBJ with vt/vn.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "qem/io.h"
#include "qem/mesh_info.h"
#include "test_meshes.h"

namespace {

using qem::AttributeKind;
using qem::FileFormat;
using qem::LoadOptions;
using qem::Mesh;

Mesh read_obj(const std::string& text, const LoadOptions& o = {}) {
  return qem::parse_mesh(text, FileFormat::Obj, "t.obj", o);
}

/// Each face corner as its position followed by every attribute's values: what a renderer sees,
/// independent of how vertices are numbered.
std::vector<std::vector<double>> corners(const Mesh& m) {
  std::vector<std::vector<double>> r;
  for (std::uint32_t v : m.indices) {
    std::vector<double> c(m.positions.begin() + 3 * v, m.positions.begin() + 3 * v + 3);
    for (const qem::VertexAttribute& a : m.attributes)
      c.insert(c.end(), a.values.begin() + a.components * v, a.values.begin() + a.components * (v + 1));
    r.push_back(std::move(c));
  }
  return r;
}

std::size_t count_lines(const std::string& text, const std::string& prefix) {
  std::istringstream in(text);
  std::size_t n = 0;
  for (std::string line; std::getline(in, line);)
    if (line.rfind(prefix, 0) == 0) ++n;
  return n;
}

/// True when some face corner of an OBJ text has a non-empty vt field ("1/2", not "1//2").
bool faces_index_vt(const std::string& text) {
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("f ", 0) != 0) continue;
    for (std::size_t i = line.find('/'); i != std::string::npos; i = line.find('/', i + 1))
      if (i + 1 < line.size() && line[i + 1] != '/' && line[i + 1] != ' ' && (i == 0 || line[i - 1] != '/'))
        return true;
  }
  return false;
}

std::string expect_error(const std::string& text, FileFormat format) {
  try {
    qem::parse_mesh(text, format, "bad", {});
  } catch (const qem::Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no error for:\n" << text;
  return "";
}

/// A cube with the classic 14-vertex UV unwrap: a strip of the four sides (5 columns, the last
/// repeating the first) with the top and the bottom hung on the first side. Optionally one normal
/// per face (then every corner of every face is its own wedge: 24).
std::string unwrapped_cube(bool normals) {
  const double corner[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  std::string s = "# cube\n";
  for (int z = 0; z < 2; ++z)
    for (const auto& c : corner)
      s += "v " + std::to_string(c[0]) + " " + std::to_string(c[1]) + " " + std::to_string(z) + "\n";
  // vt 1..10: strip columns 0..4, bottom row then top row; 11, 12: top face; 13, 14: bottom face.
  for (int i = 0; i <= 4; ++i) s += "vt " + std::to_string(i / 4.0) + " 0.333333\n";
  for (int i = 0; i <= 4; ++i) s += "vt " + std::to_string(i / 4.0) + " 0.666667\n";
  s += "vt 0.25 1\nvt 0 1\nvt 0.25 0\nvt 0 0\n";
  s += "vn 0 -1 0\nvn 1 0 0\nvn 0 1 0\nvn -1 0 0\nvn 0 0 1\nvn 0 0 -1\n";
  auto corner_text = [&](int v, int vt, int vn) {
    std::string c = std::to_string(v) + "/" + std::to_string(vt);
    if (normals) {
      c += '/';  // appended, not "/" + string: GCC 12 warns (-Wrestrict) on the latter
      c += std::to_string(vn);
    }
    return c;
  };
  for (int i = 0; i < 4; ++i) {  // side i: b_i b_i+1 t_i+1 t_i
    const int b0 = 1 + i, b1 = 1 + (i + 1) % 4, t0 = 5 + i, t1 = 5 + (i + 1) % 4;
    s += "f " + corner_text(b0, 1 + i, 1 + i) + " " + corner_text(b1, 2 + i, 1 + i) + " " +
         corner_text(t1, 7 + i, 1 + i) + " " + corner_text(t0, 6 + i, 1 + i) + "\n";
  }
  s += "f " + corner_text(5, 6, 5) + " " + corner_text(6, 7, 5) + " " + corner_text(7, 11, 5) + " " +
       corner_text(8, 12, 5) + "\n";
  s += "f " + corner_text(1, 1, 6) + " " + corner_text(4, 14, 6) + " " + corner_text(3, 13, 6) + " " +
       corner_text(2, 2, 6) + "\n";
  return s;
}

// --- OBJ -----------------------------------------------------------------------------------------

TEST(IoAttributesObj, CubeUvSeamGives14Wedges) {
  Mesh m = read_obj(unwrapped_cube(false));
  EXPECT_EQ(m.vertex_count(), 14u);
  EXPECT_EQ(m.face_count(), 12u);
  ASSERT_EQ(m.attributes.size(), 1u);
  EXPECT_EQ(m.attributes[0].name, "TEXCOORD_0");
  EXPECT_EQ(m.attributes[0].kind, AttributeKind::TexCoord);
  EXPECT_EQ(m.attributes[0].components, 2u);
  qem::MeshInfo info = qem::mesh_info(m);
  EXPECT_EQ(info.seam_vertices, 6u);  // b0, t0 (strip ends), b2, b3, t2, t3 (top and bottom)
  // Wedges of one position are consecutive, positions in v order.
  EXPECT_EQ(m.positions[0], 0.0);
  EXPECT_EQ(m.positions[3], 0.0);  // b0 has two wedges (columns 0 and 4)
}

TEST(IoAttributesObj, CubeWithFaceNormalsGives24Wedges) {
  Mesh m = read_obj(unwrapped_cube(true));
  EXPECT_EQ(m.vertex_count(), 24u);
  ASSERT_NE(m.find_attribute(AttributeKind::Normal), nullptr);
  EXPECT_EQ(m.find_attribute(AttributeKind::Normal)->name, "NORMAL");
  EXPECT_EQ(qem::mesh_info(m).seam_vertices, 8u);
  // Every corner's normal is its face's.
  const qem::VertexAttribute& n = *m.find_attribute(AttributeKind::Normal);
  for (std::size_t f = 0; f < m.face_count(); ++f)
    for (int k = 1; k < 3; ++k)
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(n.values[3 * m.indices[3 * f + k] + c], n.values[3 * m.indices[3 * f] + c]);
}

TEST(IoAttributesObj, FaceVaryingRoundTripIsExactAndWelded) {
  for (bool normals : {false, true}) {
    Mesh m = read_obj(unwrapped_cube(normals));
    const std::string text = qem::serialize_mesh(m, FileFormat::Obj);
    EXPECT_EQ(count_lines(text, "v "), 8u) << "positions are written once";
    EXPECT_EQ(count_lines(text, "vt "), 14u);
    EXPECT_EQ(count_lines(text, "vn "), normals ? 6u : 0u);
    Mesh r = read_obj(text);
    EXPECT_EQ(r.positions, m.positions);
    EXPECT_EQ(r.indices, m.indices);
    ASSERT_EQ(r.attributes.size(), m.attributes.size());
    for (std::size_t a = 0; a < m.attributes.size(); ++a) {
      EXPECT_EQ(r.attributes[a].name, m.attributes[a].name);
      EXPECT_EQ(r.attributes[a].values, m.attributes[a].values);
    }
  }
}

TEST(IoAttributesObj, WithoutAttributesVerticesAreTheVLines) {
  LoadOptions o;
  o.read_attributes = false;
  Mesh m = read_obj(unwrapped_cube(true), o);
  EXPECT_EQ(m.vertex_count(), 8u);
  EXPECT_TRUE(m.attributes.empty());
}

TEST(IoAttributesObj, CornerWithoutVtGetsZeroAndItsOwnWedge) {
  Mesh m = read_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0.5 0.5\nf 1/1 2/1 3\nf 1 3 2\n");
  // (1, vt 1), (1, none), (2, vt 1), (2, none), (3, none)
  EXPECT_EQ(m.vertex_count(), 5u);
  const qem::VertexAttribute* t = m.find_attribute(AttributeKind::TexCoord);
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->values, (std::vector<double>{0.5, 0.5, 0, 0, 0.5, 0.5, 0, 0, 0, 0}));
  Mesh r = read_obj(qem::serialize_mesh(m, FileFormat::Obj));
  EXPECT_EQ(corners(r), corners(m));
  EXPECT_EQ(r.vertex_count(), m.vertex_count());
}

TEST(IoAttributesObj, NegativeAndVnOnlyIndices) {
  Mesh m = read_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf -3//-1 -2//-1 -1//1\n");
  EXPECT_EQ(m.vertex_count(), 3u);
  ASSERT_EQ(m.attributes.size(), 1u);
  EXPECT_EQ(m.attributes[0].values, (std::vector<double>{0, 0, 1, 0, 0, 1, 0, 0, 1}));
}

TEST(IoAttributesObj, UsemtlAndMtllibKept) {
  const std::string text =
      "mtllib my materials.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nusemtl red\nf 2 4 3\n"
      "usemtl blue\nf 1 3 2\nusemtl red\nf 3 4 2 1\n";
  Mesh m = read_obj(text);
  EXPECT_EQ(m.material_library, "my materials.mtl");
  EXPECT_EQ(m.material_names, (std::vector<std::string>{"", "red", "blue"}));
  EXPECT_EQ(m.face_materials, (std::vector<std::uint32_t>{0, 1, 2, 1, 1}));
  EXPECT_EQ(qem::mesh_info(m).materials, 3u);
  const std::string written = qem::serialize_mesh(m, FileFormat::Obj);
  EXPECT_EQ(count_lines(written, "usemtl"), 3u);  // the leading unnamed group needs none
  Mesh r = read_obj(written);
  EXPECT_EQ(r.material_library, m.material_library);
  EXPECT_EQ(r.material_names, m.material_names);
  EXPECT_EQ(r.face_materials, m.face_materials);
  EXPECT_EQ(r.positions, m.positions);
}

TEST(IoAttributesObj, VertexColoursReadAndWritten) {
  Mesh m = read_obj("v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 0 0 0.25\nv 1 1 0\nf 1 2 3\nf 2 4 3\n");
  const qem::VertexAttribute* c = m.find_attribute(AttributeKind::Color);
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->name, "COLOR_0");
  EXPECT_EQ(c->components, 3u);
  EXPECT_EQ(c->values, (std::vector<double>{1, 0, 0, 0, 1, 0, 0, 0, 0.25, 1, 1, 1}));  // no colour: white
  Mesh r = read_obj(qem::serialize_mesh(m, FileFormat::Obj));
  EXPECT_EQ(r.positions, m.positions);
  EXPECT_EQ(r.attributes[0].values, c->values);
  // `v x y z w` is a weight, not a colour.
  EXPECT_TRUE(read_obj("v 0 0 0 1\nv 1 0 0 1\nv 0 1 0 1\nf 1 2 3\n").attributes.empty());
}

TEST(IoAttributesObj, WriterSharesPositionsButKeepsEveryVertex) {
  Mesh m;
  // Vertices 0 and 1: same position, different uv (a seam). Vertex 3 repeats vertex 2 exactly.
  m.positions = {0, 0, 0, 0, 0, 0, 1, 0, 0, 1, 0, 0, 0, 1, 0};
  m.indices = {0, 2, 4, 1, 4, 3};
  m.attributes.push_back({"TEXCOORD_0", AttributeKind::TexCoord, 2, {0, 0, 1, 1, 0.5, 0, 0.5, 0, 0, 1}});
  const std::string text = qem::serialize_mesh(m, FileFormat::Obj);
  EXPECT_EQ(count_lines(text, "v "), 4u);
  EXPECT_EQ(count_lines(text, "vt "), 4u);
  Mesh r = read_obj(text);
  EXPECT_EQ(r.vertex_count(), m.vertex_count());
  EXPECT_EQ(corners(r), corners(m));
}

TEST(IoAttributesObj, WeldingKeepsTheWedgesOfASeam) {
  LoadOptions o;
  o.weld = qem::Weld::On;
  // Two v lines at the same place: the corners with the same vt merge, the seam stays.
  Mesh m = read_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 0\nvt 0 0\nvt 1 1\nf 1/1 2/1 3/1\nf 4/1 3/1 2/2\n", o);
  EXPECT_EQ(m.vertex_count(), 4u);  // (0,0,0)/vt1 once, (1,0,0) twice (vt1, vt2), (0,1,0)
  EXPECT_EQ(m.attributes[0].values.size(), 8u);
  EXPECT_EQ(corners(m),
            corners(read_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 1\nf 1/1 2/1 3/1\nf 1/1 3/1 2/2\n")));
}

TEST(IoAttributesObj, Errors) {
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  EXPECT_EQ(expect_error(tri + "vt nan 0\nf 1/1 2/1 3/1\n", FileFormat::Obj),
            "bad, line 4: texture coordinate is not finite");
  EXPECT_EQ(expect_error(tri + "vt 0 0\nf 1/1 2/2 3/1\n", FileFormat::Obj),
            "bad, line 5: texture coordinate index 2 out of range (file has 1 texture coordinates)");
  EXPECT_EQ(expect_error(tri + "vt 0 0\nf 1/-2 2/1 3/1\n", FileFormat::Obj),
            "bad, line 5: relative texture coordinate index -2 refers before the first texture coordinate");
  EXPECT_EQ(expect_error(tri + "vn 0 0 inf\nf 1//1 2//1 3//1\n", FileFormat::Obj),
            "bad, line 4: normal is not finite");
  EXPECT_EQ(expect_error(tri + "vn 0 0 1\nf 1//0 2//1 3//1\n", FileFormat::Obj),
            "bad, line 5: normal index 0 (OBJ indices start at 1)");
  EXPECT_EQ(expect_error(tri + "f 1/x 2 3\n", FileFormat::Obj),
            "bad, line 4: expected a texture coordinate index, found 'x 2 3'");
  EXPECT_EQ(expect_error("v 0 0 0 1 nan 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", FileFormat::Obj),
            "bad, line 1: vertex colour is not finite");
}

TEST(IoAttributesInfo, JsonListsAttributesSeamsAndMaterialsAndTheTopologyOfPositions) {
  const std::string path = qem::test::temp_dir() + "/cube.obj";
  std::ofstream(path) << "mtllib c.mtl\nusemtl wood\n" << unwrapped_cube(true);
  std::string out;
  FILE* pipe = popen((std::string(QEM_CLI_PATH) + " info --json " + path).c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::array<char, 4096> buf;
  while (std::size_t n = std::fread(buf.data(), 1, buf.size(), pipe)) out.append(buf.data(), n);
  ASSERT_EQ(pclose(pipe), 0) << out;
  const nlohmann::json j = nlohmann::json::parse(out);  // throws on invalid JSON
  // The topology is of the 8 positions (a closed cube), the wedges are listed apart.
  EXPECT_EQ(j["vertices"], 8);
  EXPECT_EQ(j["boundary_edges"], 0);
  EXPECT_EQ(j["genus"], 0);
  EXPECT_EQ(j["wedges"], 24);
  EXPECT_EQ(j["seam_vertices"], 8);
  EXPECT_EQ(j["materials"], 1);
  EXPECT_EQ(j["material_names"], nlohmann::json::array({"wood"}));
  EXPECT_EQ(j["material_library"], "c.mtl");
  ASSERT_EQ(j["attributes"].size(), 2u);
  EXPECT_EQ(j["attributes"][0]["name"], "TEXCOORD_0");
  EXPECT_EQ(j["attributes"][0]["kind"], "texcoord");
  EXPECT_EQ(j["attributes"][1]["components"], 3);
}

// --- PLY -----------------------------------------------------------------------------------------

Mesh attributed_mesh() {
  Mesh m = qem::test::icosphere(1);
  const std::size_t nv = m.vertex_count();
  qem::VertexAttribute n{"NORMAL", AttributeKind::Normal, 3, m.positions};
  qem::VertexAttribute t{"TEXCOORD_0", AttributeKind::TexCoord, 2, {}};
  qem::VertexAttribute c{"COLOR_0", AttributeKind::Color, 4, {}};
  for (std::size_t v = 0; v < nv; ++v) {
    t.values.insert(t.values.end(), {0.5 + 0.5 * m.positions[3 * v], 0.25 * double(v % 4)});
    // Colours on the byte grid, so uchar colours are exact.
    for (int k = 0; k < 4; ++k) c.values.push_back(double((v * 37 + 50 * k) % 256) / 255);
  }
  m.attributes = {n, t, c};
  return m;
}

TEST(IoAttributesPly, NormalsUvAndColoursRoundTripBinaryAndAscii) {
  const Mesh m = attributed_mesh();
  for (bool binary : {true, false})
    for (bool dbl : {false, true}) {
      SCOPED_TRACE(std::string(binary ? "binary" : "ascii") + (dbl ? " double" : " float"));
      qem::SaveOptions o;
      o.format = FileFormat::Ply;
      o.binary = binary;
      o.double_precision = dbl;
      const std::string bytes = qem::serialize_mesh(m, o);
      EXPECT_NE(bytes.find("property uchar alpha\n"), std::string::npos);
      EXPECT_NE(bytes.find(" s\n"), std::string::npos);
      Mesh r = qem::parse_mesh(bytes, FileFormat::Ply, "t.ply");
      EXPECT_EQ(r.indices, m.indices);
      ASSERT_EQ(r.attributes.size(), 3u);
      for (std::size_t a = 0; a < 3; ++a) {
        EXPECT_EQ(r.attributes[a].name, m.attributes[a].name);
        EXPECT_EQ(r.attributes[a].kind, m.attributes[a].kind);
        EXPECT_EQ(r.attributes[a].components, m.attributes[a].components);
        ASSERT_EQ(r.attributes[a].values.size(), m.attributes[a].values.size());
        for (std::size_t i = 0; i < m.attributes[a].values.size(); ++i) {
          const double want = m.attributes[a].values[i];
          const double tolerance = m.attributes[a].kind == AttributeKind::Color ? 1e-12 : dbl ? 0 : 1e-7;
          ASSERT_NEAR(r.attributes[a].values[i], want, tolerance) << "attribute " << a << " value " << i;
        }
      }
    }
}

TEST(IoAttributesPly, FloatColoursReadAsIsAndWrittenAsBytes) {
  const std::string text =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "property float red\nproperty float green\nproperty float blue\nproperty float alpha\n"
      "property float texture_u\nproperty float texture_v\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0 0.1 0.2 0.3 1 0 0\n1 0 0 1 1 1 0.5 1 0\n0 1 0 0 0 0 0 0 1\n3 0 1 2\n";
  Mesh m = qem::parse_mesh(text, FileFormat::Ply, "t.ply");
  const qem::VertexAttribute* c = m.find_attribute(AttributeKind::Color);
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->components, 4u);
  EXPECT_EQ(c->values[0], 0.1f);
  EXPECT_EQ(c->values[7], 0.5f);
  const qem::VertexAttribute* t = m.find_attribute(AttributeKind::TexCoord);
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->values, (std::vector<double>{0, 0, 1, 0, 0, 1}));
  for (bool binary : {true, false}) {
    Mesh r = qem::parse_mesh(qem::serialize_mesh(m, FileFormat::Ply, binary), FileFormat::Ply, "t.ply");
    const qem::VertexAttribute* rc = r.find_attribute(AttributeKind::Color);
    ASSERT_NE(rc, nullptr);
    for (std::size_t i = 0; i < c->values.size(); ++i) EXPECT_NEAR(rc->values[i], c->values[i], 0.5 / 255);
  }
}

TEST(IoAttributesPly, UcharColoursWithoutAlphaAndUvNames) {
  const std::string text =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\nproperty float u\nproperty float v\n"
      "property float quality\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0 255 0 51 0 0 7\n1 0 0 0 255 0 1 0 8\n0 1 0 0 0 255 0 1 9\n3 0 1 2\n";
  LoadOptions o;
  o.keep_vertex_properties = true;
  Mesh m = qem::parse_mesh(text, FileFormat::Ply, "t.ply", o);
  const qem::VertexAttribute* c = m.find_attribute(AttributeKind::Color);
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->components, 3u);
  EXPECT_EQ(c->values[0], 1.0);
  EXPECT_EQ(c->values[2], 51.0 / 255);
  ASSERT_NE(m.find_attribute(AttributeKind::TexCoord), nullptr);
  // Properties that became attributes are not also kept as vertex properties.
  ASSERT_EQ(m.vertex_properties.size(), 1u);
  EXPECT_EQ(m.vertex_properties[0].name, "quality");
  Mesh r = qem::parse_mesh(qem::serialize_mesh(m, FileFormat::Ply, true), FileFormat::Ply, "t.ply", o);
  EXPECT_EQ(r.find_attribute(AttributeKind::Color)->values, c->values);
  EXPECT_EQ(r.vertex_properties.size(), 1u);
  LoadOptions plain;
  plain.read_attributes = false;
  EXPECT_TRUE(qem::parse_mesh(text, FileFormat::Ply, "t.ply", plain).attributes.empty());
}

TEST(IoAttributesPly, FaceColoursBecomeMaterialsAndAreWrittenBack) {
  const std::string text =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 3\nproperty list uchar int vertex_indices\nproperty uchar red\nproperty uchar green\n"
      "property uchar blue\nend_header\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2 255 0 0\n4 1 3 2 0 0 0 0\n"
      "3 0 2 1 255 0 0\n";
  qem::LoadReport report;
  Mesh m = qem::parse_mesh(text, FileFormat::Ply, "t.ply", {}, &report);
  EXPECT_TRUE(report.warnings.empty());
  EXPECT_EQ(m.material_names, (std::vector<std::string>{"rgb(255,0,0)", "rgb(0,0,0)"}));
  EXPECT_EQ(m.face_materials, (std::vector<std::uint32_t>{0, 1, 1, 0}));  // the quad is two triangles
  for (bool binary : {true, false}) {
    const std::string bytes = qem::serialize_mesh(m, FileFormat::Ply, binary);
    EXPECT_NE(bytes.find("property uchar blue\nend_header"), std::string::npos);
    Mesh r = qem::parse_mesh(bytes, FileFormat::Ply, "t.ply");
    EXPECT_EQ(r.material_names, m.material_names);
    EXPECT_EQ(r.face_materials, m.face_materials);
  }
  // Named materials (OBJ usemtl) have no PLY form: not written.
  Mesh named = m;
  named.material_names = {"wood", "steel"};
  EXPECT_EQ(qem::serialize_mesh(named, FileFormat::Ply, false).find("red"), std::string::npos);
}

TEST(IoAttributesPly, Errors) {
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
  const std::string tail = "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  EXPECT_EQ(expect_error(head + "property int red\nproperty int green\nproperty int blue\n" + tail +
                             "0 0 0 1 1 1\n1 0 0 1 1 1\n0 1 0 1 1 1\n3 0 1 2\n",
                         FileFormat::Ply),
            "bad, line 7: vertex colour property 'red' has an integer type other than uchar or ushort (its "
            "scale is unknown; uchar, ushort, float or double expected)");
  EXPECT_EQ(
      expect_error(head + "element face 1\nproperty list uchar int vertex_indices\nproperty short red\n"
                          "property short green\nproperty short blue\nend_header\n0 0 0\n1 0 0\n0 1 0\n"
                          "3 0 1 2 1 1 1\n",
                   FileFormat::Ply),
      "bad, line 9: face colour property 'red' has an integer type other than uchar (uchar, float or double "
      "expected)");
  EXPECT_EQ(expect_error(head + "property float nx\nproperty float ny\nproperty float nz\n" + tail +
                             "0 0 0 0 0 1\n1 0 0 0 nan 1\n0 1 0 0 0 1\n3 0 1 2\n",
                         FileFormat::Ply),
            "bad, line 14: normal is not finite");
}

TEST(IoAttributesPly, SharedVertexColourSphere) {
  const std::string path = qem::test::shared_data("tiny_sphere_vcolor.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/data not found";
  Mesh m = qem::load_mesh(path);
  const qem::VertexAttribute* c = m.find_attribute(AttributeKind::Color);
  ASSERT_NE(c, nullptr);
  EXPECT_EQ(c->components, 4u);
  Mesh r = qem::parse_mesh(qem::serialize_mesh(m, FileFormat::Ply), FileFormat::Ply, "t.ply");
  EXPECT_EQ(r.find_attribute(AttributeKind::Color)->values, c->values);
}

// --- the shared OBJ files with vt / vn ------------------------------------------------------------

TEST(IoAttributesCorpus, EverySharedObjReadsItsAttributesAndRoundTrips) {
  const std::string probe = qem::test::shared_data("spot.obj");
  if (probe.empty()) GTEST_SKIP() << "../shared/data not found";
  std::size_t checked = 0;
  for (const char* name :
       {"spot.obj", "beast.obj", "boat.obj", "pizza.obj", "human_neutral.obj", "trimesh_chair.obj",
        "beetle.obj", "suzanne.obj", "trimesh_fuze.obj", "trimesh_quadknot.obj", "tiny_wallhole_linecont.obj",
        "tiny_joined_tetrahedra.obj", "trimesh_reference_vcolor.obj"}) {
    const std::string path = qem::test::shared_data(name);
    if (path.empty()) continue;
    SCOPED_TRACE(name);
    const std::string text = qem::test::slurp(path);
    const std::size_t v_lines = count_lines(text, "v "), vt_lines = count_lines(text, "vt "),
                      vn_lines = count_lines(text, "vn ");
    Mesh m = qem::load_mesh(path);
    EXPECT_GE(m.vertex_count(), v_lines);
    // Each attribute holds at most as many distinct values as the file has lines of it.
    for (const qem::VertexAttribute& a : m.attributes) {
      std::set<std::vector<double>> distinct;
      for (std::size_t v = 0; v < m.vertex_count(); ++v)
        distinct.insert(std::vector<double>(a.values.begin() + a.components * v,
                                            a.values.begin() + a.components * (v + 1)));
      // + 1: the 0 of corners without one.
      if (a.kind == AttributeKind::TexCoord) {
        EXPECT_LE(distinct.size(), vt_lines + 1);
      }
      if (a.kind == AttributeKind::Normal) {
        EXPECT_LE(distinct.size(), vn_lines + 1);
      }
    }
    EXPECT_EQ(m.find_attribute(AttributeKind::TexCoord) != nullptr, faces_index_vt(text));
    EXPECT_EQ(m.find_attribute(AttributeKind::Normal) != nullptr,
              text.find("//") != std::string::npos || vn_lines > 0);
    EXPECT_EQ(m.material_library.empty(), text.find("\nmtllib") == std::string::npos);

    const std::string written = qem::serialize_mesh(m, FileFormat::Obj);
    EXPECT_LE(count_lines(written, "v "), v_lines) << "welded on write";
    Mesh r = read_obj(written);
    EXPECT_EQ(r.vertex_count(), m.vertex_count());
    EXPECT_EQ(r.face_count(), m.face_count());
    EXPECT_TRUE(corners(r) == corners(m)) << "corner values changed";
    EXPECT_EQ(r.face_materials, m.face_materials);
    EXPECT_EQ(r.material_names, m.material_names);
    EXPECT_EQ(r.material_library, m.material_library);
    ++checked;
  }
  EXPECT_GT(checked, 5u);
}

}  // namespace
