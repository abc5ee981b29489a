// KHR_draco_mesh_compression (io/gltf_draco.h): documents whose primitives are Draco bitstreams,
// made in code with libdraco's encoder, read as the same triangles with the same attributes, written
// back uncompressed, simplified through the command line; malformed ones refused by name.
#include <draco/compression/encode.h>
#include <draco/mesh/triangle_soup_mesh_builder.h>
#include <draco/point_cloud/point_cloud_builder.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "qem/error.h"
#include "qem/gltf.h"
#include "qem/io.h"
#include "test_meshes.h"

namespace {

using json = nlohmann::json;

/// A corner as the test compares it: position, then UV, then normal.
using Corner = std::array<float, 8>;
/// A face's corners from its smallest, so that the same oriented triangle compares equal whatever
/// corner a file starts it at.
using Face = std::array<Corner, 3>;

std::vector<Face> faces_of(const qem::Mesh& m) {
  const qem::VertexAttribute& uv = qem::test::attribute(m, qem::AttributeKind::TexCoord);
  const qem::VertexAttribute& normal = qem::test::attribute(m, qem::AttributeKind::Normal);
  std::vector<Face> faces;
  for (std::size_t f = 0; f < m.face_count(); ++f) {
    Face face;
    for (int k = 0; k < 3; ++k) {
      const std::size_t v = m.indices[3 * f + k];
      face[k] = {float(m.positions[3 * v]),       float(m.positions[3 * v + 1]),
                 float(m.positions[3 * v + 2]),   float(uv.values[2 * v]),
                 float(uv.values[2 * v + 1]),     float(normal.values[3 * v]),
                 float(normal.values[3 * v + 1]), float(normal.values[3 * v + 2])};
    }
    std::rotate(face.begin(), std::min_element(face.begin(), face.end()), face.end());
    faces.push_back(face);
  }
  std::sort(faces.begin(), faces.end());
  return faces;
}

/// `doc` and `bin` as a .glb: the JSON chunk, then `bin` as the BIN chunk (buffer 0).
std::string glb_of(json doc, std::string bin) {
  doc["buffers"] = {{{"byteLength", bin.size()}}};
  std::string text = doc.dump();
  text.resize((text.size() + 3) & ~std::size_t(3), ' ');
  bin.resize((bin.size() + 3) & ~std::size_t(3), '\0');
  std::string out = "glTF";
  const auto u32 = [&](std::size_t v) {
    const std::uint32_t w = static_cast<std::uint32_t>(v);
    out.append(reinterpret_cast<const char*>(&w), 4);
  };
  u32(2), u32(12 + 8 + text.size() + 8 + bin.size());
  u32(text.size()), out += "JSON", out += text;
  u32(bin.size()), out += "BIN", out += '\0', out += bin;
  return out;
}

/// The error of reading `doc` with `bin` as its buffer (its one view made to fit), "" if none.
std::string error_of(json doc, const std::string& bin) {
  doc["bufferViews"][0]["byteLength"] = bin.size();
  return qem::test::gltf_error(qem::test::gltf_text(doc, bin), "d.gltf");
}

TEST(GltfDraco, DecodesTheSameTrianglesAndAttributes) {
  const qem::Mesh sphere = qem::test::uv_sphere(12, 24);
  std::string bin;
  const json doc = qem::test::draco_document(sphere, bin);
  const qem::GltfDocument d = qem::GltfDocument::parse(qem::test::gltf_text(doc, bin), "d.gltf");
  ASSERT_EQ(d.primitives().size(), 1u);
  EXPECT_TRUE(d.primitives()[0].simplifiable);
  const qem::Mesh m = d.mesh(0);
  EXPECT_EQ(m.face_count(), sphere.face_count());
  EXPECT_EQ(faces_of(m), faces_of(sphere));
  // The same in a .glb, whose JSON chunk the loader rewrites before tinygltf reads it.
  const qem::GltfDocument b = qem::GltfDocument::parse(glb_of(doc, bin), "d.glb");
  EXPECT_EQ(faces_of(b.mesh(0)), faces_of(sphere));
}

TEST(GltfDraco, IsWrittenUncompressedAndReadsBackTheSame) {
  const qem::Mesh sphere = qem::test::uv_sphere(8, 16);
  std::string bin;
  const json doc = qem::test::draco_document(sphere, bin);
  const qem::GltfDocument d = qem::GltfDocument::parse(qem::test::gltf_text(doc, bin), "d.gltf");
  const std::string written = d.serialize(false);
  const json out = json::parse(written);
  EXPECT_FALSE(out.contains("extensionsUsed")) << out.dump();
  EXPECT_FALSE(out.contains("extensionsRequired"));
  EXPECT_FALSE(out["meshes"][0]["primitives"][0].contains("extensions"));
  // Three attributes and the indices, each in a view of its own: the bitstream's view is gone.
  EXPECT_EQ(out["bufferViews"].size(), 4u);
  EXPECT_EQ(out["accessors"].size(), 4u);
  const qem::GltfDocument again = qem::GltfDocument::parse(written, "again.gltf");
  EXPECT_EQ(faces_of(again.mesh(0)), faces_of(sphere));
}

TEST(GltfDraco, CommandLineSimplifiesACompressedFile) {
  const qem::Mesh sphere = qem::test::uv_sphere(24, 48);
  std::string bin;
  const json doc = qem::test::draco_document(sphere, bin);
  const std::string dir = qem::test::temp_dir();
  const std::string in = dir + "/draco_sphere.gltf", out = dir + "/draco_sphere_simplified.glb";
  std::ofstream(in, std::ios::binary) << qem::test::gltf_text(doc, bin);
  ASSERT_EQ(qem::test::run_qem_quietly("simplify '" + in + "' '" + out + "' --ratio 0.2"), 0);
  const qem::GltfDocument d = qem::GltfDocument::load(out);
  ASSERT_EQ(d.primitives().size(), 1u);
  EXPECT_LE(d.primitives()[0].face_count, sphere.face_count() / 5 + 2);
  EXPECT_GT(d.primitives()[0].face_count, 0u);
  EXPECT_EQ(qem::test::open_edges_welded(d.mesh(0)), 0u);
}

TEST(GltfDraco, AStripIsReadAsATriangleList) {
  const qem::Mesh sphere = qem::test::uv_sphere(6, 12);
  std::string bin;
  json doc = qem::test::draco_document(sphere, bin);
  doc["meshes"][0]["primitives"][0]["mode"] = 5;  // Draco decodes faces whatever the mode says
  const qem::GltfDocument d = qem::GltfDocument::parse(qem::test::gltf_text(doc, bin), "d.gltf");
  EXPECT_EQ(d.primitives()[0].mode, 4);
  EXPECT_EQ(faces_of(d.mesh(0)), faces_of(sphere));
}

TEST(GltfDraco, APointCloudIsDecodedAndPassedThrough) {
  const std::vector<float> p = {0, 0, 0, 1, 0, 0, 0, 2, 0, 0, 0, 3, 1, 1, 1};
  draco::PointCloudBuilder builder;
  builder.Start(5);
  const int pos = builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
  for (std::uint32_t i = 0; i < 5; ++i)
    builder.SetAttributeValueForPoint(pos, draco::PointIndex(i), &p[3 * i]);
  const std::unique_ptr<draco::PointCloud> cloud = builder.Finalize(false);
  draco::Encoder encoder;
  draco::EncoderBuffer stream;
  ASSERT_TRUE(encoder.EncodePointCloudToBuffer(*cloud, &stream).ok());
  const std::string bin(stream.data(), stream.size());
  const json doc = {
      {"asset", {{"version", "2.0"}}},
      {"extensionsUsed", {"KHR_draco_mesh_compression"}},
      {"meshes",
       {{{"primitives",
          {{{"attributes", {{"POSITION", 0}}},
            {"mode", 0},
            {"extensions",
             {{"KHR_draco_mesh_compression", {{"bufferView", 0}, {"attributes", {{"POSITION", 0}}}}}}}}}}}}},
      {"accessors",
       {{{"componentType", 5126}, {"count", 5}, {"type", "VEC3"}, {"min", {0, 0, 0}}, {"max", {1, 2, 3}}}}},
      {"bufferViews", {{{"buffer", 0}, {"byteLength", bin.size()}}}},
      {"buffers", {{{"byteLength", 0}}}}};
  const qem::GltfDocument d = qem::GltfDocument::parse(qem::test::gltf_text(doc, bin), "points.gltf");
  EXPECT_FALSE(d.primitives()[0].simplifiable);  // points: passed through, decoded
  const json out = json::parse(d.serialize(false));
  EXPECT_FALSE(out.contains("extensionsUsed"));
  ASSERT_EQ(out["bufferViews"].size(), 1u);
  EXPECT_EQ(out["accessors"][0]["count"], 5);
  EXPECT_EQ(out["accessors"][0]["bufferView"], 0);
  // The decoded points, as a set (Draco may reorder them), from the .glb's BIN chunk.
  const std::string glb = d.serialize(true);
  std::uint32_t json_length;
  std::memcpy(&json_length, glb.data() + 12, 4);
  std::vector<std::array<float, 3>> read(5), expected(5);
  std::memcpy(read.data(), glb.data() + 20 + json_length + 8, sizeof(float) * 15);
  std::memcpy(expected.data(), p.data(), sizeof(float) * 15);
  std::sort(read.begin(), read.end());
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(read, expected);
}

TEST(GltfDraco, MalformedDataIsRefusedByWhatIsWrong) {
  const qem::Mesh sphere = qem::test::uv_sphere(4, 8);
  std::string bin;
  const json good = qem::test::draco_document(sphere, bin);
  ASSERT_EQ(error_of(good, bin), "");

  const std::string broken = bin.substr(0, bin.size() / 2);  // cut off
  EXPECT_NE(error_of(good, broken)
                .find("d.gltf: mesh 0, primitive 0: the Draco data in buffer view 0 cannot be decoded"),
            std::string::npos)
      << error_of(good, broken);
  EXPECT_NE(error_of(good, "not a draco stream at all").find("cannot be decoded"), std::string::npos);

  json doc = good;
  doc["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["attributes"]["NORMAL"] = 7;
  EXPECT_NE(
      error_of(doc, bin).find("d.gltf: mesh 0, primitive 0 (NORMAL): the Draco data has no attribute 7"),
      std::string::npos)
      << error_of(doc, bin);

  doc = good;
  doc["accessors"][1]["type"] = "VEC3";
  EXPECT_NE(error_of(doc, bin).find(
                "(TEXCOORD_0), accessor 1: the Draco attribute has 2 components, the accessor's type 3"),
            std::string::npos)
      << error_of(doc, bin);

  doc = good;
  doc["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["bufferView"] = 5;
  EXPECT_NE(error_of(doc, bin).find("names buffer view 5, which does not exist"), std::string::npos);

  doc = good;
  doc["accessors"][3]["componentType"] = 5126;  // float indices
  EXPECT_NE(
      error_of(doc, bin).find("(indices), accessor 3: component type 5126 cannot hold the decoded indices"),
      std::string::npos)
      << error_of(doc, bin);
}

// A .glb the fuzzer made (one bit flipped in a Draco-compressed one): its POSITION attribute is
// stored as booleans with a byte of 128, which libdraco would read as a bool (undefined
// behaviour, reported by UBSan). Refused with a clear error instead.
TEST(GltfDraco, BooleanAttributeIsRefused) {
  static const unsigned char kGlb[] = {
      0x67, 0x6c, 0x54, 0x46, 0x02, 0x00, 0x00, 0x00, 0x34, 0x02, 0x00, 0x00, 0xc4, 0x01, 0x00, 0x00, 0x4a,
      0x53, 0x4f, 0x4e, 0x7b, 0x22, 0x61, 0x73, 0x73, 0x65, 0x74, 0x22, 0x3a, 0x7b, 0x22, 0x76, 0x65, 0x72,
      0x73, 0x69, 0x6f, 0x6e, 0x22, 0x3a, 0x22, 0x32, 0x2e, 0x30, 0x22, 0x7d, 0x2c, 0x22, 0x65, 0x78, 0x74,
      0x65, 0x6e, 0x73, 0x69, 0x6f, 0x6e, 0x73, 0x55, 0x73, 0x65, 0x64, 0x22, 0x3a, 0x5b, 0x22, 0x4b, 0x48,
      0x52, 0x5f, 0x64, 0x72, 0x61, 0x63, 0x6f, 0x5f, 0x6d, 0x65, 0x73, 0x68, 0x5f, 0x63, 0x6f, 0x6d, 0x70,
      0x72, 0x65, 0x73, 0x73, 0x69, 0x6f, 0x6e, 0x22, 0x5d, 0x2c, 0x22, 0x6d, 0x65, 0x73, 0x68, 0x65, 0x73,
      0x22, 0x3a, 0x5b, 0x7b, 0x22, 0x70, 0x72, 0x69, 0x6d, 0x69, 0x74, 0x69, 0x76, 0x65, 0x73, 0x22, 0x3a,
      0x5b, 0x7b, 0x22, 0x61, 0x74, 0x74, 0x72, 0x69, 0x62, 0x75, 0x74, 0x65, 0x73, 0x22, 0x3a, 0x7b, 0x22,
      0x50, 0x4f, 0x53, 0x49, 0x54, 0x49, 0x4f, 0x4e, 0x22, 0x3a, 0x30, 0x7d, 0x2c, 0x22, 0x69, 0x6e, 0x64,
      0x69, 0x63, 0x65, 0x73, 0x22, 0x3a, 0x30, 0x2c, 0x22, 0x65, 0x78, 0x74, 0x65, 0x6e, 0x73, 0x69, 0x6f,
      0x6e, 0x73, 0x22, 0x3a, 0x7b, 0x22, 0x4b, 0x48, 0x52, 0x5f, 0x64, 0x72, 0x61, 0x63, 0x6f, 0x5f, 0x6d,
      0x65, 0x73, 0x68, 0x5f, 0x63, 0x6f, 0x6d, 0x70, 0x72, 0x65, 0x73, 0x73, 0x69, 0x6f, 0x6e, 0x22, 0x3a,
      0x7b, 0x22, 0x62, 0x75, 0x66, 0x66, 0x65, 0x72, 0x56, 0x69, 0x65, 0x77, 0x22, 0x3a, 0x30, 0x2c, 0x22,
      0x61, 0x74, 0x74, 0x72, 0x69, 0x62, 0x75, 0x74, 0x65, 0x73, 0x22, 0x3a, 0x7b, 0x22, 0x50, 0x4f, 0x53,
      0x49, 0x54, 0x49, 0x4f, 0x4e, 0x22, 0x3a, 0x30, 0x7d, 0x7d, 0x7d, 0x7d, 0x5d, 0x7d, 0x5d, 0x2c, 0x22,
      0x61, 0x63, 0x63, 0x65, 0x73, 0x73, 0x6f, 0x72, 0x73, 0x22, 0x3a, 0x5b, 0x7b, 0x22, 0x63, 0x6f, 0x6d,
      0x70, 0x6f, 0x6e, 0x65, 0x6e, 0x74, 0x54, 0x79, 0x70, 0x65, 0x22, 0x3a, 0x35, 0x31, 0x32, 0x36, 0x2c,
      0x22, 0x63, 0x6f, 0x75, 0x6e, 0x74, 0x22, 0x3a, 0x34, 0x2c, 0x22, 0x74, 0x79, 0x70, 0x65, 0x22, 0x3a,
      0x22, 0x56, 0x45, 0x43, 0x33, 0x22, 0x2c, 0x22, 0x6d, 0x69, 0x6e, 0x22, 0x3a, 0x5b, 0x2d, 0x31, 0x2c,
      0x2d, 0x31, 0x2c, 0x2d, 0x31, 0x5d, 0x2c, 0x22, 0x6d, 0x61, 0x78, 0x22, 0x3a, 0x5b, 0x31, 0x2c, 0x31,
      0x2c, 0x31, 0x5d, 0x7d, 0x2c, 0x7b, 0x22, 0x63, 0x6f, 0x6d, 0x70, 0x6f, 0x6e, 0x65, 0x6e, 0x74, 0x54,
      0x79, 0x70, 0x65, 0x22, 0x3a, 0x35, 0x31, 0x32, 0x33, 0x2c, 0x22, 0x63, 0x6f, 0x75, 0x6e, 0x74, 0x22,
      0x3a, 0x31, 0x32, 0x2c, 0x22, 0x74, 0x79, 0x70, 0x65, 0x22, 0x3a, 0x22, 0x53, 0x43, 0x41, 0x4c, 0x41,
      0x52, 0x22, 0x7d, 0x5d, 0x2c, 0x22, 0x62, 0x75, 0x66, 0x66, 0x65, 0x72, 0x56, 0x69, 0x65, 0x77, 0x73,
      0x22, 0x3a, 0x5b, 0x7b, 0x22, 0x62, 0x75, 0x66, 0x66, 0x65, 0x72, 0x22, 0x3a, 0x30, 0x2c, 0x22, 0x62,
      0x79, 0x74, 0x65, 0x4c, 0x65, 0x6e, 0x67, 0x74, 0x68, 0x22, 0x3a, 0x38, 0x32, 0x7d, 0x5d, 0x2c, 0x22,
      0x62, 0x75, 0x66, 0x66, 0x65, 0x72, 0x73, 0x22, 0x3a, 0x5b, 0x7b, 0x22, 0x62, 0x79, 0x74, 0x65, 0x4c,
      0x65, 0x6e, 0x67, 0x74, 0x68, 0x22, 0x3a, 0x38, 0x32, 0x7d, 0x5d, 0x7d, 0x20, 0x54, 0x00, 0x00, 0x00,
      0x42, 0x49, 0x4e, 0x00, 0x44, 0x52, 0x41, 0x43, 0x4f, 0x02, 0x02, 0x01, 0x01, 0x00, 0x00, 0x00, 0x04,
      0x04, 0x00, 0x03, 0x00, 0x00, 0x01, 0x2f, 0x01, 0x01, 0x10, 0x01, 0xff, 0x00, 0x00, 0x01, 0x00, 0x0b,
      0x03, 0x00, 0x00, 0x00, 0x00, 0x00, 0x80, 0xbf, 0x00, 0x00, 0x80, 0xbf, 0x00, 0x00, 0x80, 0x3f, 0x00,
      0x00, 0x80, 0x3f, 0x00, 0x00, 0x80, 0xbf, 0x00, 0x00, 0x80, 0x49, 0x00, 0x00, 0x80, 0x3f, 0x00, 0x00,
      0x80, 0x3f, 0x00, 0x00, 0x80, 0x3f, 0x00, 0x00, 0x80, 0xbf, 0x00, 0x00, 0x80, 0x3f, 0x00, 0x00, 0x80,
      0xbf, 0x00, 0x00,
  };
  const std::string bytes(reinterpret_cast<const char*>(kGlb), sizeof kGlb);
  try {
    qem::parse_mesh(bytes, qem::FileFormat::Auto, "flipped.glb");
    FAIL() << "expected an error";
  } catch (const qem::Error& e) {
    EXPECT_NE(std::string(e.what()).find("holds booleans"), std::string::npos) << e.what();
  }
}

}  // namespace
