// EXT_meshopt_compression (io/gltf_meshopt.h): documents whose buffer views are meshoptimizer's
// vertex and index codecs (with the octahedral and exponential filters), made in code with
// libmeshoptimizer's encoders into a fallback buffer without data, read as the same triangles with
// the same attributes (as the filters round them), written back uncompressed, simplified through
// the command line; malformed ones refused by what is wrong.
#include <gtest/gtest.h>
#include <meshoptimizer.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "qem/error.h"
#include "qem/gltf.h"
#include "test_meshes.h"

namespace {

using json = nlohmann::json;

template <class T>
void append(std::string& bin, const std::vector<T>& values) {
  bin.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

/// What the document is made of, to compare the decoded primitive with.
struct Expected {
  std::vector<float> positions, uv;  // exact (no filter; the exponential filter keeps 24 bits)
  std::vector<std::int8_t> normals;  // octahedral, 8 bits a component, as the decoder gives them
  std::vector<std::uint32_t> indices;
};

/// `m` (positions, TEXCOORD_0, NORMAL) as one primitive whose four buffer views are compressed:
/// POSITION (ATTRIBUTES), TEXCOORD_0 (ATTRIBUTES, EXPONENTIAL), NORMAL (ATTRIBUTES, OCTAHEDRAL,
/// normalised bytes: KHR_mesh_quantization) and the indices (TRIANGLES, unsigned shorts). Buffer 0
/// holds the encoded bytes (`bin`), buffer 1 is the fallback: no data, only its length.
json meshopt_document(const qem::Mesh& m, std::string& bin, Expected& e) {
  const qem::VertexAttribute& uv = qem::test::attribute(m, qem::AttributeKind::TexCoord);
  const qem::VertexAttribute& normal = qem::test::attribute(m, qem::AttributeKind::Normal);
  const std::size_t n = m.vertex_count();
  e.positions.assign(m.positions.begin(), m.positions.end());
  std::vector<float> uvf(uv.values.begin(), uv.values.end()), nf(normal.values.begin(), normal.values.end());
  e.indices = m.indices;

  // The filters' encodings (the decoder undoes them after the codec).
  std::vector<std::uint32_t> uv_exp(2 * n);
  meshopt_encodeFilterExp(uv_exp.data(), n, 8, 24, uvf.data());
  std::vector<float> n4(4 * n);
  for (std::size_t v = 0; v < n; ++v) std::copy_n(&nf[3 * v], 3, &n4[4 * v]);
  std::vector<std::int8_t> oct(4 * n);
  meshopt_encodeFilterOct(oct.data(), n, 4, 8, n4.data());
  e.normals = oct;
  meshopt_decodeFilterOct(e.normals.data(), n, 4);
  e.uv.resize(2 * n);
  std::memcpy(e.uv.data(), uv_exp.data(), 8 * n);
  meshopt_decodeFilterExp(e.uv.data(), n, 8);

  json views = json::array();
  std::size_t fallback = 0;
  auto compressed = [&](const std::vector<unsigned char>& encoded, std::size_t raw, std::size_t stride,
                        std::size_t count, const char* mode, const char* filter) {
    const std::size_t offset = bin.size();
    bin.append(reinterpret_cast<const char*>(encoded.data()), encoded.size());
    bin.resize((bin.size() + 3) & ~std::size_t(3), '\0');
    json ext = {{"buffer", 0},          {"byteOffset", offset}, {"byteLength", encoded.size()},
                {"byteStride", stride}, {"count", count},       {"mode", mode}};
    if (std::string(filter) != "NONE") ext["filter"] = filter;
    json view = {{"buffer", 1},
                 {"byteOffset", fallback},
                 {"byteLength", raw},
                 {"extensions", {{"EXT_meshopt_compression", ext}}}};
    if (std::string(mode) == "ATTRIBUTES") view["byteStride"] = stride;
    views.push_back(view);
    fallback += (raw + 3) & ~std::size_t(3);
  };
  auto vertex_stream = [&](const void* data, std::size_t stride, const char* filter) {
    std::vector<unsigned char> encoded(meshopt_encodeVertexBufferBound(n, stride));
    encoded.resize(meshopt_encodeVertexBuffer(encoded.data(), encoded.size(), data, n, stride));
    compressed(encoded, n * stride, stride, n, "ATTRIBUTES", filter);
  };
  vertex_stream(e.positions.data(), 12, "NONE");
  vertex_stream(uv_exp.data(), 8, "EXPONENTIAL");
  vertex_stream(oct.data(), 4, "OCTAHEDRAL");
  std::vector<unsigned char> encoded(meshopt_encodeIndexBufferBound(e.indices.size(), n));
  encoded.resize(
      meshopt_encodeIndexBuffer(encoded.data(), encoded.size(), e.indices.data(), e.indices.size()));
  compressed(encoded, 2 * e.indices.size(), 2, e.indices.size(), "TRIANGLES", "NONE");

  std::array<float, 3> lo{1e30f, 1e30f, 1e30f}, hi{-1e30f, -1e30f, -1e30f};
  for (std::size_t v = 0; v < n; ++v)
    for (int k = 0; k < 3; ++k)
      lo[k] = std::min(lo[k], e.positions[3 * v + k]), hi[k] = std::max(hi[k], e.positions[3 * v + k]);
  return {
      {"asset", {{"version", "2.0"}}},
      {"extensionsUsed", {"EXT_meshopt_compression", "KHR_mesh_quantization"}},
      {"extensionsRequired", {"EXT_meshopt_compression", "KHR_mesh_quantization"}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0}}}}},
      {"nodes", {{{"mesh", 0}}}},
      {"meshes",
       {{{"primitives",
          {{{"attributes", {{"POSITION", 0}, {"TEXCOORD_0", 1}, {"NORMAL", 2}}}, {"indices", 3}}}}}}},
      {"accessors",
       {{{"bufferView", 0},
         {"componentType", 5126},
         {"count", n},
         {"type", "VEC3"},
         {"min", lo},
         {"max", hi}},
        {{"bufferView", 1}, {"componentType", 5126}, {"count", n}, {"type", "VEC2"}},
        {{"bufferView", 2}, {"componentType", 5120}, {"normalized", true}, {"count", n}, {"type", "VEC3"}},
        {{"bufferView", 3}, {"componentType", 5123}, {"count", e.indices.size()}, {"type", "SCALAR"}}}},
      {"bufferViews", views},
      {"buffers",
       {{{"byteLength", 0}},
        {{"byteLength", fallback}, {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}}}}};
}

void expect_decoded(const qem::Mesh& m, const Expected& e) {
  ASSERT_EQ(m.vertex_count() * 3, e.positions.size());
  for (std::size_t i = 0; i < e.positions.size(); ++i) ASSERT_EQ(m.positions[i], double(e.positions[i])) << i;
  EXPECT_EQ(m.indices, e.indices);
  const qem::VertexAttribute& uv = qem::test::attribute(m, qem::AttributeKind::TexCoord);
  for (std::size_t i = 0; i < e.uv.size(); ++i) ASSERT_EQ(uv.values[i], double(e.uv[i])) << i;
  const qem::VertexAttribute& normal = qem::test::attribute(m, qem::AttributeKind::Normal);
  for (std::size_t v = 0; v < m.vertex_count(); ++v)
    for (int k = 0; k < 3; ++k)  // normalised signed bytes: max(c / 127, -1)
      ASSERT_EQ(normal.values[3 * v + k], std::max(e.normals[4 * v + k] / 127.0, -1.0)) << v;
}

std::string error_of(const json& doc, const std::string& bin) {
  return qem::test::gltf_error(qem::test::gltf_text(doc, bin), "m.gltf");
}

TEST(GltfMeshopt, DecodesEveryViewAndFilter) {
  const qem::Mesh sphere = qem::test::uv_sphere(12, 24);
  std::string bin;
  Expected e;
  const json doc = meshopt_document(sphere, bin, e);
  const qem::GltfDocument d = qem::GltfDocument::parse(qem::test::gltf_text(doc, bin), "m.gltf");
  ASSERT_EQ(d.primitives().size(), 1u);
  const qem::Mesh m = d.mesh(0);
  expect_decoded(m, e);
  // The octahedral normals are within a byte's rounding of the sphere's.
  const qem::VertexAttribute& normal = qem::test::attribute(m, qem::AttributeKind::Normal);
  const qem::VertexAttribute& original = qem::test::attribute(sphere, qem::AttributeKind::Normal);
  for (std::size_t i = 0; i < normal.values.size(); ++i)
    EXPECT_NEAR(normal.values[i], original.values[i], 0.02) << i;
}

TEST(GltfMeshopt, IsWrittenUncompressedAndReadsBackTheSame) {
  const qem::Mesh sphere = qem::test::uv_sphere(8, 16);
  std::string bin;
  Expected e;
  const json doc = meshopt_document(sphere, bin, e);
  const std::string written =
      qem::GltfDocument::parse(qem::test::gltf_text(doc, bin), "m.gltf").serialize(true);
  const qem::GltfDocument again = qem::GltfDocument::parse(written, "again.glb");
  expect_decoded(again.mesh(0), e);
  std::uint32_t json_length;
  std::memcpy(&json_length, written.data() + 12, 4);
  const json out = json::parse(written.substr(20, json_length));
  EXPECT_EQ(out["extensionsUsed"], json::array({"KHR_mesh_quantization"})) << out.dump();
  EXPECT_EQ(out["buffers"].size(), 1u);
  EXPECT_FALSE(out["buffers"][0].contains("extensions"));
  for (const json& view : out["bufferViews"]) EXPECT_FALSE(view.contains("extensions"));
}

TEST(GltfMeshopt, CommandLineSimplifiesACompressedFile) {
  const qem::Mesh sphere = qem::test::uv_sphere(24, 48);
  std::string bin;
  Expected e;
  const json doc = meshopt_document(sphere, bin, e);
  const std::string dir = qem::test::temp_dir();
  const std::string in = dir + "/meshopt_sphere.gltf", out = dir + "/meshopt_sphere_simplified.glb";
  std::ofstream(in, std::ios::binary) << qem::test::gltf_text(doc, bin);
  ASSERT_EQ(qem::test::run_qem_quietly("simplify '" + in + "' '" + out + "' --ratio 0.2"), 0);
  const qem::GltfDocument d = qem::GltfDocument::load(out);
  EXPECT_LE(d.primitives()[0].face_count, sphere.face_count() / 5 + 2);
  EXPECT_GT(d.primitives()[0].face_count, 0u);
  EXPECT_EQ(qem::test::open_edges_welded(d.mesh(0)), 0u);
}

TEST(GltfMeshopt, MalformedDataIsRefusedByWhatIsWrong) {
  const qem::Mesh sphere = qem::test::uv_sphere(4, 8);
  std::string bin;
  Expected e;
  const json good = meshopt_document(sphere, bin, e);
  ASSERT_EQ(error_of(good, bin), "");
  auto ext = [](json& doc, int view) -> json& {
    return doc["bufferViews"][view]["extensions"]["EXT_meshopt_compression"];
  };

  json doc = good;
  ext(doc, 0)["byteLength"] = ext(doc, 0)["byteLength"].get<int>() / 2;  // cut short
  EXPECT_NE(error_of(doc, bin).find("m.gltf: buffer view 0: EXT_meshopt_compression data does not decode"),
            std::string::npos)
      << error_of(doc, bin);

  doc = good;
  ext(doc, 1)["byteOffset"] = bin.size();
  EXPECT_NE(error_of(doc, bin).find("m.gltf: buffer view 1: EXT_meshopt_compression's data (buffer 0, bytes"),
            std::string::npos)
      << error_of(doc, bin);

  doc = good;  // a view longer than its data could ever expand to (nothing is allocated for it)
  doc["bufferViews"][3]["byteLength"] = 64 * ext(doc, 3)["byteLength"].get<std::size_t>() + 4096;
  EXPECT_NE(error_of(doc, bin).find("data cannot decode to"), std::string::npos) << error_of(doc, bin);

  doc = good;
  ext(doc, 0)["byteStride"] = 6;
  ext(doc, 0)["count"] = 2 * sphere.vertex_count();
  EXPECT_NE(error_of(doc, bin).find("mode \"ATTRIBUTES\" with byteStride 6"), std::string::npos)
      << error_of(doc, bin);

  doc = good;
  ext(doc, 3)["count"] = ext(doc, 3)["count"].get<int>() + 1;
  EXPECT_NE(error_of(doc, bin).find("m.gltf: buffer view 3: "), std::string::npos) << error_of(doc, bin);

  doc = good;
  ext(doc, 0)["filter"] = "QUATERNION";
  EXPECT_NE(error_of(doc, bin).find("filter \"QUATERNION\" is unknown or does not fit"), std::string::npos)
      << error_of(doc, bin);

  doc = good;
  ext(doc, 2).erase("count");
  EXPECT_NE(error_of(doc, bin).find("m.gltf: buffer view 2: EXT_meshopt_compression has no count"),
            std::string::npos)
      << error_of(doc, bin);

  doc = good;
  ext(doc, 2)["buffer"] = 9;
  EXPECT_NE(error_of(doc, bin).find("(buffer 9, bytes"), std::string::npos) << error_of(doc, bin);
}

}  // namespace
