// glTF 2.0 read and write (qem/gltf.h, and load_mesh / save_mesh on .glb / .gltf): attributes
// decoded, replaced primitives written back with everything else unchanged, bad files refused
// with messages that name the file, mesh, primitive and accessor. Small documents are built in
// code (embedded base64 buffers); the shared .glb files are used when ../shared is present.
#include "qem/gltf.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "qem/error.h"
#include "qem/io.h"
#include "test_meshes.h"

namespace {

using json = nlohmann::json;

template <class T>
void put(std::string& b, T v) {
  char c[sizeof(T)];
  std::memcpy(c, &v, sizeof(T));
  b.append(c, sizeof(T));
}

/// A unit quad (4 vertices, 2 triangles) with NORMAL, TEXCOORD_0 and COLOR_0 (normalised unsigned
/// bytes), a node translated by (10, 0, 0), a material with extras and an extension qem does not
/// know, in one embedded buffer. Tests change the JSON to make their case.
struct Tiny {
  json doc;
  std::string bin;

  Tiny() {
    const float p[] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    for (float v : p) put(bin, v);                                               // 0: POSITION, 48 bytes
    for (int k = 0; k < 4; ++k) put(bin, 0.0f), put(bin, 0.0f), put(bin, 1.0f);  // 48: NORMAL
    const float uv[] = {0, 0, 1, 0, 1, 1, 0, 1};
    for (float v : uv) put(bin, v);  // 96: TEXCOORD_0, 32 bytes
    for (int k = 0; k < 4; ++k)
      put(bin, std::uint8_t(255)), put(bin, std::uint8_t(0)), put(bin, std::uint8_t(51)),
          put(bin, std::uint8_t(255));  // 128: COLOR_0
    const std::uint16_t idx[] = {0, 1, 2, 0, 2, 3};
    for (auto v : idx) put(bin, v);  // 144: indices, 12 bytes
    doc = json::parse(R"({
      "asset": {"version": "2.0", "generator": "qem test"},
      "extensionsUsed": ["EXT_qem_unknown"],
      "scene": 0,
      "scenes": [{"nodes": [0]}],
      "nodes": [{"mesh": 0, "translation": [10, 0, 0], "extras": {"tag": "node"}}],
      "materials": [{"name": "red", "extras": {"shiny": true}, "extensions": {"EXT_qem_unknown": {"level": 3}}}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2, "COLOR_0": 3},
                                  "indices": 4, "material": 0}]}],
      "accessors": [
        {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0,0,0], "max": [1,1,0]},
        {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
        {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
        {"bufferView": 3, "componentType": 5121, "normalized": true, "count": 4, "type": "VEC4"},
        {"bufferView": 4, "componentType": 5123, "count": 6, "type": "SCALAR"}],
      "bufferViews": [
        {"buffer": 0, "byteOffset": 0, "byteLength": 48},
        {"buffer": 0, "byteOffset": 48, "byteLength": 48},
        {"buffer": 0, "byteOffset": 96, "byteLength": 32},
        {"buffer": 0, "byteOffset": 128, "byteLength": 16},
        {"buffer": 0, "byteOffset": 144, "byteLength": 12}],
      "buffers": [{"byteLength": 0}]
    })");
  }
  std::string text() const { return qem::test::gltf_text(doc, bin); }
};

/// A .glb split into its JSON and BIN chunks.
struct Glb {
  json doc;
  std::string bin;
};

Glb split_glb(const std::string& bytes) {
  Glb g;
  EXPECT_GE(bytes.size(), 20u);
  EXPECT_EQ(bytes.substr(0, 4), "glTF");
  std::uint32_t json_length;
  std::memcpy(&json_length, bytes.data() + 12, 4);
  g.doc = json::parse(bytes.substr(20, json_length));
  std::size_t at = 20 + json_length;
  if (at + 8 <= bytes.size()) {
    std::uint32_t bin_length;
    std::memcpy(&bin_length, bytes.data() + at, 4);
    g.bin = bytes.substr(at + 8, bin_length);
  }
  return g;
}

/// The bytes of buffer view `v`.
std::string view_bytes(const Glb& g, std::size_t v) {
  const json& view = g.doc["bufferViews"][v];
  return g.bin.substr(view.value("byteOffset", std::size_t(0)), view["byteLength"].get<std::size_t>());
}

std::string error_of(const std::string& bytes, const std::string& name = "tiny.gltf") {
  return qem::test::gltf_error(bytes, name);
}

/// `qem info FILE` through the shell (the CLI under test), its exit status.
int info_status(const std::string& path) {
  return std::system((std::string(QEM_CLI_PATH) + " info '" + path + "' > /dev/null").c_str());
}

const qem::VertexAttribute* attribute(const qem::Mesh& m, const std::string& name) {
  for (const auto& a : m.attributes)
    if (a.name == name) return &a;
  return nullptr;
}

TEST(Gltf, ReadsEveryAttributeOfATrianglePrimitive) {
  qem::GltfDocument doc = qem::GltfDocument::parse(Tiny().text(), "tiny.gltf");
  ASSERT_EQ(doc.primitives().size(), 1u);
  const qem::GltfPrimitiveInfo& p = doc.primitives()[0];
  EXPECT_TRUE(p.simplifiable);
  EXPECT_EQ(p.material, 0);
  EXPECT_EQ(p.vertex_count, 4u);
  EXPECT_EQ(p.face_count, 2u);
  qem::Mesh m = doc.mesh(0);
  EXPECT_EQ(m.positions, (std::vector<double>{0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}));
  EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}));
  ASSERT_EQ(m.attributes.size(), 3u);
  const qem::VertexAttribute* color = attribute(m, "COLOR_0");
  ASSERT_TRUE(color);
  EXPECT_EQ(color->kind, qem::AttributeKind::Color);
  EXPECT_EQ(color->components, 4u);
  EXPECT_DOUBLE_EQ(color->values[2], 0.2);  // 51 / 255
  EXPECT_EQ(attribute(m, "NORMAL")->kind, qem::AttributeKind::Normal);
  EXPECT_EQ(attribute(m, "TEXCOORD_0")->kind, qem::AttributeKind::TexCoord);
  EXPECT_EQ(attribute(m, "TEXCOORD_0")->components, 2u);
}

TEST(Gltf, LoadMeshMergesTheSceneInWorldSpace) {
  qem::LoadReport report;
  qem::Mesh m = qem::parse_mesh(Tiny().text(), qem::FileFormat::Auto, "tiny.gltf", {}, &report);
  EXPECT_EQ(report.format, qem::FileFormat::Gltf);
  EXPECT_FALSE(report.binary);
  EXPECT_EQ(m.positions[0], 10.0);  // the node's translation
  EXPECT_EQ(m.positions[3], 11.0);
  EXPECT_EQ(m.face_materials, (std::vector<std::uint32_t>{0, 0}));
  EXPECT_EQ(m.material_names, (std::vector<std::string>{"red"}));
  EXPECT_EQ(m.attributes.size(), 3u);
}

TEST(Gltf, SkinnedMeshIsMergedInItsBindPose) {
  // Two joints: one moved up by 5, one scaling by 2 with an inverse bind matrix that moves by -1 in
  // x. The mesh node's own translation is ignored (glTF 2.0 §3.7.3); the last vertex's weights sum
  // to 0.99 (a quantized file) and are normalised.
  Tiny t;
  for (int v = 0; v < 4; ++v) t.bin += std::string("\0\1\0\0", 4);  // 156: JOINTS_0
  const float weights[] = {1, 0, 0, 0, 0, 1, 0, 0, 0.5f, 0.5f, 0, 0, 0.495f, 0.495f, 0, 0};
  for (float w : weights) put(t.bin, w);  // 172: WEIGHTS_0
  const float ibm[] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -1, 0, 0, 1};
  for (float x : ibm) put(t.bin, x);  // 236: inverse bind matrices
  json& p = t.doc["meshes"][0]["primitives"][0];
  p["attributes"]["JOINTS_0"] = 5;
  p["attributes"]["WEIGHTS_0"] = 6;
  t.doc["accessors"].push_back({{"bufferView", 5}, {"componentType", 5121}, {"count", 4}, {"type", "VEC4"}});
  t.doc["accessors"].push_back({{"bufferView", 6}, {"componentType", 5126}, {"count", 4}, {"type", "VEC4"}});
  t.doc["accessors"].push_back({{"bufferView", 7}, {"componentType", 5126}, {"count", 2}, {"type", "MAT4"}});
  t.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 156}, {"byteLength", 16}});
  t.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 172}, {"byteLength", 64}});
  t.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 236}, {"byteLength", 128}});
  t.doc["nodes"][0]["skin"] = 0;
  t.doc["nodes"].push_back({{"translation", {0, 0, 5}}});
  t.doc["nodes"].push_back({{"scale", {2, 2, 2}}});
  t.doc["scenes"][0]["nodes"] = {0, 1, 2};
  t.doc["skins"] = {{{"joints", {1, 2}}, {"inverseBindMatrices", 7}}};
  const qem::Mesh m = qem::parse_mesh(t.text(), qem::FileFormat::Auto, "skin.gltf");
  const std::vector<double> expected = {0, 0, 5, 0, 0, 0, 0.5, 1.5, 2.5, -1, 1.5, 2.5};
  ASSERT_EQ(m.positions.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) EXPECT_NEAR(m.positions[i], expected[i], 1e-6) << i;
  // The world scale of the shared error budget is the joints' (2), not the node's (1).
  EXPECT_DOUBLE_EQ(qem::GltfDocument::parse(t.text(), "skin.gltf").primitives()[0].world_scale, 2.0);
}

TEST(Gltf, SkinnedPartMirroredByItsJointsKeepsEachFacesOutwardSide) {
  // Joint 0 is the identity, joint 1 mirrors x. Vertex 0 follows joint 0, the others joint 1: both
  // faces are mostly mirrored (the mean of their corners' matrices has a negative determinant),
  // so both turn round, whatever the first vertex's matrix says.
  Tiny t;
  for (int v = 0; v < 4; ++v) t.bin += v == 0 ? std::string("\0\0\0\0", 4) : std::string("\1\0\0\0", 4);
  for (int v = 0; v < 4; ++v)
    for (float w : {1.0f, 0.0f, 0.0f, 0.0f}) put(t.bin, w);
  json& p = t.doc["meshes"][0]["primitives"][0];
  p["attributes"]["JOINTS_0"] = 5;
  p["attributes"]["WEIGHTS_0"] = 6;
  t.doc["accessors"].push_back({{"bufferView", 5}, {"componentType", 5121}, {"count", 4}, {"type", "VEC4"}});
  t.doc["accessors"].push_back({{"bufferView", 6}, {"componentType", 5126}, {"count", 4}, {"type", "VEC4"}});
  t.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 156}, {"byteLength", 16}});
  t.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 172}, {"byteLength", 64}});
  t.doc["nodes"][0]["skin"] = 0;
  t.doc["nodes"].push_back(json::object());
  t.doc["nodes"].push_back({{"scale", {-1, 1, 1}}});
  t.doc["scenes"][0]["nodes"] = {0, 1, 2};
  t.doc["skins"] = {{{"joints", {1, 2}}}};
  // (The skin has no inverseBindMatrices, which glTF makes optional: identities, and none written.)
  const json written = json::parse(qem::GltfDocument::parse(t.text(), "skin.gltf").serialize(false));
  EXPECT_FALSE(written["skins"][0].contains("inverseBindMatrices"));
  const qem::Mesh m = qem::parse_mesh(t.text(), qem::FileFormat::Auto, "skin.gltf");
  EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{0, 2, 1, 0, 3, 2}));
  // Vertex 0 in place, the others mirrored.
  EXPECT_EQ(m.positions[0], 0.0);
  EXPECT_EQ(m.positions[3], -1.0);
  // Every vertex on joint 0: nothing turns.
  t.bin.replace(156, 16, std::string(16, '\0'));
  EXPECT_EQ(qem::parse_mesh(t.text(), qem::FileFormat::Auto, "skin.gltf").indices,
            (std::vector<std::uint32_t>{0, 1, 2, 0, 2, 3}));
}

TEST(Gltf, GpuInstancedNodeIsMergedOncePerInstance) {
  // EXT_mesh_gpu_instancing on the node (translation 10 in x): instance 0 at its place, instance 1
  // moved 5 in y and scaled by 2 (after the node's matrix). The scene has the quad twice, and the
  // primitive's world scale is the larger instance's.
  Tiny t;
  for (float v : {0.0f, 0.0f, 0.0f, 0.0f, 5.0f, 0.0f}) put(t.bin, v);  // 156: TRANSLATION
  for (float v : {1.0f, 1.0f, 1.0f, 2.0f, 2.0f, 2.0f}) put(t.bin, v);  // 180: SCALE
  t.doc["accessors"].push_back({{"bufferView", 5}, {"componentType", 5126}, {"count", 2}, {"type", "VEC3"}});
  t.doc["accessors"].push_back({{"bufferView", 6}, {"componentType", 5126}, {"count", 2}, {"type", "VEC3"}});
  t.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 156}, {"byteLength", 24}});
  t.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 180}, {"byteLength", 24}});
  t.doc["extensionsUsed"].push_back("EXT_mesh_gpu_instancing");
  t.doc["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"] = {{"TRANSLATION", 5},
                                                                              {"SCALE", 6}};
  const qem::Mesh m = qem::parse_mesh(t.text(), qem::FileFormat::Auto, "instanced.gltf");
  ASSERT_EQ(m.vertex_count(), 8u);
  ASSERT_EQ(m.face_count(), 4u);
  const std::vector<double> second = {10, 5, 0, 12, 5, 0, 12, 7, 0, 10, 7, 0};
  for (std::size_t i = 0; i < second.size(); ++i) EXPECT_NEAR(m.positions[12 + i], second[i], 1e-12) << i;
  EXPECT_EQ(m.positions[3], 11.0);
  const qem::GltfDocument doc = qem::GltfDocument::parse(t.text(), "instanced.gltf");
  EXPECT_DOUBLE_EQ(doc.primitives()[0].world_scale, 2.0);
  // Written back as it was.
  const json written = json::parse(doc.serialize(false));
  EXPECT_EQ(written["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["SCALE"], 6);
  // Counts that differ, or a SCALE that is not a VEC3: a clear error.
  t.doc["accessors"][6]["count"] = 1;
  EXPECT_NE(qem::test::gltf_error(t.text(), "instanced.gltf")
                .find("EXT_mesh_gpu_instancing SCALE): 1 instances, not 2"),
            std::string::npos)
      << qem::test::gltf_error(t.text(), "instanced.gltf");
  t.doc["accessors"][6]["count"] = 2, t.doc["accessors"][6]["type"] = "VEC2";
  EXPECT_NE(qem::test::gltf_error(t.text(), "instanced.gltf").find("not a VEC3"), std::string::npos)
      << qem::test::gltf_error(t.text(), "instanced.gltf");
  // An index that names no accessor (one far beyond int's range included).
  for (double bad : {7.0, 1e20, -1.0, 0.5}) {
    t.doc["nodes"][0]["extensions"]["EXT_mesh_gpu_instancing"]["attributes"]["SCALE"] = bad;
    EXPECT_NE(qem::test::gltf_error(t.text(), "instanced.gltf").find("not the index of an accessor"),
              std::string::npos)
        << bad << ": " << qem::test::gltf_error(t.text(), "instanced.gltf");
  }
}

TEST(Gltf, MirroringNodeKeepsTheOutwardWinding) {
  Tiny t;
  t.doc["nodes"][0]["scale"] = {-1, 1, 1};
  qem::Mesh m = qem::parse_mesh(t.text(), qem::FileFormat::Gltf, "tiny.gltf");
  EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{0, 2, 1, 0, 3, 2}));
  EXPECT_EQ(m.positions[3], 9.0);
}

TEST(Gltf, RoundTripKeepsUnknownExtensionsAndExtras) {
  for (bool binary : {true, false}) {
    qem::GltfDocument doc = qem::GltfDocument::parse(Tiny().text(), "tiny.gltf");
    std::string out = doc.serialize(binary);
    json j = binary ? split_glb(out).doc : json::parse(out);
    EXPECT_EQ(j["extensionsUsed"], json::array({"EXT_qem_unknown"}));
    EXPECT_EQ(j["materials"][0]["extensions"]["EXT_qem_unknown"]["level"], 3);
    EXPECT_EQ(j["materials"][0]["extras"]["shiny"], true);
    EXPECT_EQ(j["nodes"][0]["extras"]["tag"], "node");
    qem::GltfDocument again = qem::GltfDocument::parse(out, "again");
    EXPECT_EQ(again.mesh(0).positions, doc.mesh(0).positions);
  }
}

/// A smaller mesh of the same attributes: the first `faces` triangles, vertices renumbered.
qem::Mesh first_faces(const qem::Mesh& m, std::size_t faces) {
  qem::Mesh out;
  for (const auto& a : m.attributes) out.attributes.push_back({a.name, a.kind, a.components, {}});
  std::vector<std::int64_t> map(m.vertex_count(), -1);
  for (std::size_t k = 0; k < 3 * faces; ++k) {
    std::uint32_t v = m.indices[k];
    if (map[v] < 0) {
      map[v] = static_cast<std::int64_t>(out.vertex_count());
      out.positions.insert(out.positions.end(), m.positions.begin() + 3 * v, m.positions.begin() + 3 * v + 3);
      for (std::size_t i = 0; i < m.attributes.size(); ++i) {
        const auto& a = m.attributes[i];
        out.attributes[i].values.insert(out.attributes[i].values.end(), a.values.begin() + a.components * v,
                                        a.values.begin() + a.components * (v + 1));
      }
    }
    out.indices.push_back(static_cast<std::uint32_t>(map[v]));
  }
  return out;
}

TEST(Gltf, ReplacedPrimitiveIsWrittenAndItsOldDataDropped) {
  Tiny t;
  t.doc.erase("extensionsUsed");
  qem::GltfDocument doc = qem::GltfDocument::parse(t.text(), "tiny.gltf");
  qem::Mesh one = first_faces(doc.mesh(0), 1);
  doc.replace(0, one);
  Glb g = split_glb(doc.serialize(true));
  // 3 vertices x (12 + 12 + 8 + 16 bytes), 3 ushort indices (+2 padding) instead of 4 vertices.
  EXPECT_EQ(g.bin.size(), 3u * 12 + 3 * 12 + 3 * 8 + 3 * 16 + 8);
  EXPECT_EQ(g.doc["accessors"].size(), 5u);  // the old slots took the new data
  EXPECT_EQ(g.doc["accessors"][0]["max"], json::array({1.0, 1.0, 0.0}));
  qem::GltfDocument again = qem::GltfDocument::parse(doc.serialize(false), "again");
  qem::Mesh back = again.mesh(0);
  EXPECT_EQ(back.positions, one.positions);
  EXPECT_EQ(back.indices, one.indices);
  ASSERT_TRUE(attribute(back, "COLOR_0"));
  EXPECT_NEAR(attribute(back, "COLOR_0")->values[2], 0.2, 1e-7);
  EXPECT_EQ(again.primitives()[0].material, 0);
}

TEST(Gltf, UnknownExtensionsKeepTheOldAccessors) {
  // EXT_qem_unknown might name accessors: none is reused or emptied, new ones are appended.
  qem::GltfDocument doc = qem::GltfDocument::parse(Tiny().text(), "tiny.gltf");
  doc.replace(0, first_faces(doc.mesh(0), 1));
  Glb g = split_glb(doc.serialize(true));
  EXPECT_EQ(g.doc["accessors"].size(), 10u);
  EXPECT_EQ(g.doc["bufferViews"].size(), 10u);
}

TEST(Gltf, ReplaceRefusesAMeshWithOtherAttributes) {
  qem::GltfDocument doc = qem::GltfDocument::parse(Tiny().text(), "tiny.gltf");
  qem::Mesh m = doc.mesh(0);
  m.attributes.pop_back();
  EXPECT_THROW(doc.replace(0, m), qem::Error);
  m = doc.mesh(0);
  m.indices.push_back(0), m.indices.push_back(1), m.indices.push_back(7);
  EXPECT_THROW(doc.replace(0, m), qem::Error);
}

TEST(Gltf, TangentIsDroppedOnReplacedPrimitives) {
  Tiny t;
  t.doc.erase("extensionsUsed");
  for (int k = 0; k < 4; ++k) put(t.bin, 1.0f), put(t.bin, 0.0f), put(t.bin, 0.0f), put(t.bin, 1.0f);
  t.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", 156}, {"byteLength", 64}});
  t.doc["accessors"].push_back({{"bufferView", 5}, {"componentType", 5126}, {"count", 4}, {"type", "VEC4"}});
  t.doc["meshes"][0]["primitives"][0]["attributes"]["TANGENT"] = 5;
  qem::GltfDocument doc = qem::GltfDocument::parse(t.text(), "tiny.gltf");
  ASSERT_EQ(attribute(doc.mesh(0), "TANGENT")->kind, qem::AttributeKind::Tangent);
  doc.replace(0, doc.mesh(0));
  Glb g = split_glb(doc.serialize(true));
  EXPECT_FALSE(g.doc["meshes"][0]["primitives"][0]["attributes"].contains("TANGENT"));
  EXPECT_FALSE(g.doc["accessors"][5].contains("bufferView"));  // its data is gone, its index stays
  EXPECT_FALSE(doc.notes().empty());
}

TEST(Gltf, MorphTargetsAreReadAsOffsetAttributes) {
  Tiny t;
  t.doc["meshes"][0]["primitives"][0]["targets"] = json::array({{{"POSITION", 1}}});  // the normals' data
  qem::GltfDocument doc = qem::GltfDocument::parse(t.text(), "tiny.gltf");
  EXPECT_TRUE(doc.primitives()[0].simplifiable);
  EXPECT_EQ(doc.primitives()[0].morph_targets, 1u);
  const qem::Mesh m = doc.mesh(0);
  const qem::VertexAttribute* offsets = attribute(m, "target0/POSITION");
  ASSERT_TRUE(offsets);
  EXPECT_EQ(offsets->kind, qem::AttributeKind::Scalar);
  EXPECT_EQ(offsets->values, attribute(m, "NORMAL")->values);
  // The scene mesh is the rest pose: no offsets.
  EXPECT_EQ(qem::parse_mesh(t.text(), qem::FileFormat::Gltf, "tiny.gltf").attributes.size(), 3u);
  // A file's own attribute may not take that form of name.
  t.doc["meshes"][0]["primitives"][0]["attributes"]["target0/POSITION"] = 1;
  EXPECT_NE(error_of(t.text()).find("attribute target0/POSITION is no glTF semantic"), std::string::npos);
}

TEST(Gltf, OtherModesArePassedThrough) {
  Tiny t;
  t.doc["meshes"][0]["primitives"][0]["mode"] = 1;  // LINES
  qem::GltfDocument doc = qem::GltfDocument::parse(t.text(), "tiny.gltf");
  EXPECT_FALSE(doc.primitives()[0].simplifiable);
  json j = json::parse(doc.serialize(false));
  EXPECT_EQ(j["meshes"][0]["primitives"][0]["mode"], 1);
}

TEST(Gltf, QuantizedAndSparseAccessorsAreDecoded) {
  Tiny t;
  // KHR_mesh_quantization: POSITION as unsigned shorts (not normalised: their value), TEXCOORD_0
  // as normalised unsigned shorts.
  const std::size_t at = t.bin.size();
  const std::uint16_t q[] = {0, 0, 0, 0, 2, 0, 0, 0, 2, 2, 0, 0, 0, 2, 0, 0};  // VEC3, stride 8 bytes
  for (auto v : q) put(t.bin, v);
  t.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", at}, {"byteLength", 32}, {"byteStride", 8}});
  t.doc["accessors"][0] = {{"bufferView", 5}, {"componentType", 5123}, {"count", 4},
                           {"type", "VEC3"},  {"min", {0, 0, 0}},      {"max", {2, 2, 0}}};
  const std::size_t uv_at = t.bin.size();
  const std::uint16_t uv[] = {0, 0, 65535, 0, 65535, 65535, 0, 65535};
  for (auto v : uv) put(t.bin, v);
  t.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", uv_at}, {"byteLength", 16}});
  t.doc["accessors"][2] = {
      {"bufferView", 6}, {"componentType", 5123}, {"normalized", true}, {"count", 4}, {"type", "VEC2"}};
  // Sparse NORMAL: vertex 2 gets (0, 1, 0).
  const std::size_t sp = t.bin.size();
  put(t.bin, std::uint32_t(2));
  put(t.bin, 0.0f), put(t.bin, 1.0f), put(t.bin, 0.0f);
  t.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", sp}, {"byteLength", 4}});
  t.doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", sp + 4}, {"byteLength", 12}});
  t.doc["accessors"][1]["sparse"] = {{"count", 1},
                                     {"indices", {{"bufferView", 7}, {"componentType", 5125}}},
                                     {"values", {{"bufferView", 8}}}};
  t.doc["extensionsUsed"].push_back("KHR_mesh_quantization");
  t.doc["extensionsRequired"] = {"KHR_mesh_quantization"};
  qem::GltfDocument doc = qem::GltfDocument::parse(t.text(), "tiny.gltf");
  qem::Mesh m = doc.mesh(0);
  EXPECT_EQ(m.positions, (std::vector<double>{0, 0, 0, 2, 0, 0, 2, 2, 0, 0, 2, 0}));
  EXPECT_EQ(attribute(m, "TEXCOORD_0")->values, (std::vector<double>{0, 0, 1, 0, 1, 1, 0, 1}));
  EXPECT_EQ(attribute(m, "NORMAL")->values, (std::vector<double>{0, 0, 1, 0, 0, 1, 0, 1, 0, 0, 0, 1}));
  // Written back as float.
  doc.replace(0, m);
  json j = split_glb(doc.serialize(true)).doc;
  EXPECT_EQ(
      j["accessors"][j["meshes"][0]["primitives"][0]["attributes"]["POSITION"].get<int>()]["componentType"],
      5126);
  EXPECT_EQ(qem::GltfDocument::parse(doc.serialize(true), "again").mesh(0).positions, m.positions);
}

TEST(Gltf, NonIndexedPrimitivesGetSequentialIndices) {
  Tiny t;
  t.doc["meshes"][0]["primitives"][0].erase("indices");
  t.doc["accessors"][0]["count"] = 3;
  for (int k : {1, 2, 3}) t.doc["accessors"][k]["count"] = 3;
  qem::Mesh m = qem::GltfDocument::parse(t.text(), "tiny.gltf").mesh(0);
  EXPECT_EQ(m.indices, (std::vector<std::uint32_t>{0, 1, 2}));
}

TEST(GltfErrors, AccessorBeyondItsBufferView) {
  Tiny t;
  t.doc["accessors"][1]["count"] = 5;
  std::string e = error_of(t.text());
  EXPECT_NE(e.find("tiny.gltf: mesh 0, primitive 0 (NORMAL), accessor 1:"), std::string::npos) << e;
  EXPECT_NE(e.find("buffer view 1"), std::string::npos) << e;
}

TEST(GltfErrors, BufferViewBeyondItsBuffer) {
  Tiny t;
  t.doc["bufferViews"][2]["byteLength"] = 4000;
  std::string e = error_of(t.text());
  EXPECT_NE(e.find("tiny.gltf: buffer view 2 (bytes 96, 4000 long) lies outside its buffer of 156 bytes"),
            std::string::npos)
      << e;
}

TEST(GltfErrors, NodeTransformBeyondTheDoubleRange) {
  Tiny t;
  t.doc["nodes"][0]["scale"] = {1e308, 1e308, 1e308};
  t.doc["nodes"][0]["translation"] = {1e308, 0, 0};
  EXPECT_THROW(qem::parse_mesh(t.text(), qem::FileFormat::Gltf, "tiny.gltf"), qem::Error);
  qem::Mesh m = qem::test::cube();
  m.positions[0] = 1e300;  // beyond float: glTF cannot store it
  EXPECT_THROW(qem::serialize_mesh(m, qem::FileFormat::Gltf, true), qem::Error);
}

TEST(GltfErrors, IndexBeyondTheVertexCount) {
  Tiny t;
  t.bin[144 + 10] = 9;  // the last index: 3 -> 9
  std::string e = error_of(t.text());
  EXPECT_NE(e.find("mesh 0, primitive 0 (indices), accessor 4: index 9"), std::string::npos) << e;
}

TEST(GltfErrors, NotFiniteCoordinate) {
  Tiny t;
  float nan = std::nanf("");
  std::memcpy(&t.bin[4], &nan, 4);
  std::string e = error_of(t.text());
  EXPECT_NE(e.find("(POSITION), accessor 0: element 0 is not a finite number"), std::string::npos) << e;
}

TEST(GltfErrors, UndecodableCompressionIsRefusedByName) {
  Tiny t;
  t.doc["extensionsUsed"] = {"KHR_meshopt_compression"};
  const std::string e = error_of(t.text());
  EXPECT_NE(
      e.find("tiny.gltf: uses KHR_meshopt_compression (compressed geometry), which qem does not decode"),
      std::string::npos)
      << e;
}

TEST(GltfErrors, TruncatedGlb) {
  std::string glb = qem::GltfDocument::parse(Tiny().text(), "tiny.gltf").serialize(true);
  for (std::size_t cut : {std::size_t(3), std::size_t(12), std::size_t(30), glb.size() - 10}) {
    std::string e = error_of(glb.substr(0, cut), "cut.glb");
    EXPECT_EQ(e.rfind("cut.glb: ", 0), 0u) << cut << ": " << e;
  }
}

TEST(GltfErrors, ExternalBufferIsNotReadFromMemory) {
  Tiny t;
  std::string text = t.text();
  json d = json::parse(text);
  d["buffers"][0]["uri"] = "/etc/passwd";
  std::string e = error_of(d.dump());
  EXPECT_EQ(e.rfind("tiny.gltf: ", 0), 0u) << e;
}

TEST(Gltf, ExternalBufferBesideAGltfFile) {
  Tiny t;
  const std::string dir = qem::test::temp_dir();
  {
    std::FILE* f = std::fopen((dir + "/tiny.bin").c_str(), "wb");
    ASSERT_TRUE(f);
    std::fwrite(t.bin.data(), 1, t.bin.size(), f);
    std::fclose(f);
  }
  json d = t.doc;
  d["buffers"][0] = {{"byteLength", t.bin.size()}, {"uri", "tiny.bin"}};
  {
    std::FILE* f = std::fopen((dir + "/tiny.gltf").c_str(), "wb");
    std::string s = d.dump();
    std::fwrite(s.data(), 1, s.size(), f);
    std::fclose(f);
  }
  qem::GltfDocument doc = qem::GltfDocument::load(dir + "/tiny.gltf");
  EXPECT_EQ(doc.mesh(0).face_count(), 2u);
  doc.save(dir + "/out.glb");  // the external buffer moves into the BIN chunk
  EXPECT_EQ(qem::load_mesh(dir + "/out.glb").face_count(), 2u);
}

TEST(Gltf, SaveMeshWritesAMinimalGltfWithAttributesAndMaterials) {
  qem::Mesh m = qem::test::cube();
  qem::VertexAttribute uv{"TEXCOORD_0", qem::AttributeKind::TexCoord, 2, {}};
  for (std::size_t v = 0; v < m.vertex_count(); ++v)
    uv.values.push_back(m.positions[3 * v]), uv.values.push_back(0.5);
  m.attributes.push_back(uv);
  m.face_materials.assign(m.face_count(), 0);
  for (std::size_t f = 6; f < m.face_count(); ++f) m.face_materials[f] = 1;
  m.material_names = {"wood", "steel"};
  const std::string dir = qem::test::temp_dir();
  for (const char* name : {"/cube.glb", "/cube.gltf"}) {
    qem::save_mesh(dir + name, m);
    qem::LoadReport r;
    qem::Mesh back = qem::load_mesh(dir + name, {}, &r);
    EXPECT_EQ(r.binary, std::string(name) == "/cube.glb");
    EXPECT_EQ(back.positions, m.positions);
    EXPECT_EQ(back.face_materials, m.face_materials);
    EXPECT_EQ(back.material_names, m.material_names);
    ASSERT_EQ(back.attributes.size(), 1u);
    EXPECT_EQ(back.attributes[0].values, uv.values);
    // Faces come back grouped by material (one primitive each), here in the same order.
    EXPECT_EQ(back.indices, m.indices);
    EXPECT_EQ(info_status(dir + name), 0);
  }
}

// --- the shared .glb files ----------------------------------------------------------------------

class GltfShared : public ::testing::TestWithParam<const char*> {};

/// The document's JSON without what re-packing changes (buffer view offsets, the buffers) and
/// without the differences tinygltf makes that mean the same: it leaves out properties equal to
/// their default value (`byteOffset: 0`, `mode: 4`, `alphaMode: "OPAQUE"`, factors of 1, ...)
/// and adds the `target` of buffer views it infers from their use by primitives (a hint).
json without_layout(json j) {
  j.erase("buffers");
  for (json& v : j["bufferViews"]) v.erase("byteOffset"), v.erase("target");
  for (json& a : j["accessors"])
    if (a.value("byteOffset", 0) == 0) a.erase("byteOffset");
  qem::test::erase_gltf_defaults(j);
  return j;
}

TEST_P(GltfShared, RoundTripKeepsEverything) {
  const std::string path = qem::test::shared_data(GetParam());
  if (path.empty()) GTEST_SKIP() << "../shared/data not found";
  const std::string original = qem::test::slurp(path);
  qem::GltfDocument doc = qem::GltfDocument::load(path);
  const std::string dir = qem::test::temp_dir();
  doc.save(dir + "/" + GetParam());
  const std::string written = qem::test::slurp(dir + "/" + GetParam());
  Glb a = split_glb(original), b = split_glb(written);
  json ja = without_layout(a.doc), jb = without_layout(b.doc);
  EXPECT_EQ(ja, jb) << "diff: " << json::diff(ja, jb).dump();
  // Every buffer view (accessor data and embedded images alike) byte for byte.
  ASSERT_EQ(a.doc["bufferViews"].size(), b.doc["bufferViews"].size());
  for (std::size_t v = 0; v < a.doc["bufferViews"].size(); ++v)
    EXPECT_EQ(view_bytes(a, v), view_bytes(b, v)) << "buffer view " << v;
  // And the meshes decode the same.
  qem::GltfDocument again = qem::GltfDocument::load(dir + "/" + GetParam());
  ASSERT_EQ(again.primitives().size(), doc.primitives().size());
  for (std::size_t i = 0; i < doc.primitives().size(); ++i)
    if (doc.primitives()[i].simplifiable) {
      EXPECT_EQ(again.mesh(i).positions, doc.mesh(i).positions);
      EXPECT_EQ(again.mesh(i).indices, doc.mesh(i).indices);
    }
  EXPECT_GT(qem::load_mesh(path).face_count(), 0u);
}

INSTANTIATE_TEST_SUITE_P(Files, GltfShared,
                         ::testing::Values("Duck.glb", "CesiumMan.glb", "CesiumMilkTruck.glb",
                                           "SheenCloth.glb", "tiny_cube_vcolor.glb"),
                         [](const auto& info) {
                           std::string n = info.param;
                           return n.substr(0, n.find('.'));
                         });

TEST(GltfSharedDuck, ReplacingOnePrimitiveKeepsTheRest) {
  const std::string path = qem::test::shared_data("Duck.glb");
  if (path.empty()) GTEST_SKIP() << "../shared/data not found";
  qem::GltfDocument doc = qem::GltfDocument::load(path);
  ASSERT_EQ(doc.primitives().size(), 1u);
  const qem::Mesh before = doc.mesh(0);
  qem::Mesh smaller = first_faces(before, before.face_count() / 2);
  doc.replace(0, smaller);
  const std::string dir = qem::test::temp_dir();
  doc.save(dir + "/duck_half.glb");
  Glb a = split_glb(qem::test::slurp(path)), b = split_glb(qem::test::slurp(dir + "/duck_half.glb"));
  EXPECT_LT(b.bin.size(), a.bin.size());
  // Everything but the primitive's accessors and the buffer layout is unchanged.
  json ja = without_layout(a.doc), jb = without_layout(b.doc);
  ja.erase("accessors"), jb.erase("accessors");
  ja.erase("bufferViews"), jb.erase("bufferViews");
  ja["images"][0].erase("bufferView"), jb["images"][0].erase("bufferView");  // renumbered
  EXPECT_EQ(ja, jb) << json::diff(ja, jb).dump();
  // The texture's image bytes are intact.
  const int image_view_a = a.doc["images"][0]["bufferView"], image_view_b = b.doc["images"][0]["bufferView"];
  EXPECT_EQ(view_bytes(a, std::size_t(image_view_a)), view_bytes(b, std::size_t(image_view_b)));
  qem::GltfDocument again = qem::GltfDocument::load(dir + "/duck_half.glb");
  qem::Mesh back = again.mesh(0);
  ASSERT_EQ(back.vertex_count(), smaller.vertex_count());
  EXPECT_EQ(back.indices, smaller.indices);
  for (std::size_t k = 0; k < back.positions.size(); ++k)
    EXPECT_EQ(back.positions[k], double(float(smaller.positions[k])));
  ASSERT_EQ(back.attributes.size(), smaller.attributes.size());
  EXPECT_EQ(info_status(dir + "/duck_half.glb"), 0);
}

}  // namespace
