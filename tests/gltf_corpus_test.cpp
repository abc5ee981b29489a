// The shared .glb files (../shared/data; skipped when absent) through qem's glTF document path:
// written back without simplification, the JSON is the same except the buffer layout, and every
// accessor's data and every image's bytes are the same by content; after `qem simplify`, only the
// replaced primitives' accessors differ, skinned primitives keep valid skins, and the face target
// holds. The JSON and the data are read here with nlohmann/json and by hand, not by qem.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "qem/gltf.h"
#include "test_meshes.h"

namespace {

using json = nlohmann::json;

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
  const std::size_t at = 20 + json_length;
  if (at + 8 <= bytes.size()) {
    std::uint32_t bin_length;
    std::memcpy(&bin_length, bytes.data() + at, 4);
    g.bin = bytes.substr(at + 8, bin_length);
  }
  return g;
}

std::size_t component_size(int type) {
  switch (type) {
    case 5120:
    case 5121:
      return 1;
    case 5122:
    case 5123:
      return 2;
    default:
      return 4;
  }
}

std::size_t component_count(const std::string& type) {
  if (type == "SCALAR") return 1;
  if (type == "VEC2") return 2;
  if (type == "VEC3") return 3;
  if (type == "VEC4" || type == "MAT2") return 4;
  if (type == "MAT3") return 9;
  return 16;
}

/// Accessor `a`'s elements, each as its bytes (stride and offsets resolved; no buffer view: zeros).
std::vector<std::string> elements(const Glb& g, std::size_t a) {
  const json& acc = g.doc["accessors"][a];
  EXPECT_FALSE(acc.contains("sparse")) << "accessor " << a << ": sparse accessors are not read by this test";
  const std::size_t size = component_size(acc["componentType"]) * component_count(acc["type"]);
  const std::size_t count = acc["count"];
  std::vector<std::string> out(count, std::string(size, '\0'));
  if (!acc.contains("bufferView")) return out;
  const json& view = g.doc["bufferViews"][acc["bufferView"].get<std::size_t>()];
  const std::size_t stride = view.value("byteStride", size);
  const std::size_t base = view.value("byteOffset", std::size_t(0)) + acc.value("byteOffset", std::size_t(0));
  for (std::size_t i = 0; i < count; ++i) out[i] = g.bin.substr(base + i * stride, size);
  return out;
}

/// Accessor `a` as numbers, normalised integers mapped to [0, 1] / [-1, 1] (glTF 2.0 §3.11).
std::vector<double> numbers(const Glb& g, std::size_t a) {
  const json& acc = g.doc["accessors"][a];
  const int type = acc["componentType"];
  const bool normalized = acc.value("normalized", false);
  const std::size_t cs = component_size(type);
  std::vector<double> out;
  for (const std::string& e : elements(g, a))
    for (std::size_t k = 0; k < e.size(); k += cs) {
      double v = 0;
      const char* p = e.data() + k;
      if (type == 5126) {
        float f;
        std::memcpy(&f, p, 4), v = f;
      } else if (type == 5121) {
        v = static_cast<unsigned char>(*p), v = normalized ? v / 255 : v;
      } else if (type == 5123) {
        std::uint16_t u;
        std::memcpy(&u, p, 2), v = normalized ? u / 65535.0 : u;
      } else if (type == 5125) {
        std::uint32_t u;
        std::memcpy(&u, p, 4), v = u;
      } else {
        ADD_FAILURE() << "component type " << type << " not read by this test";
      }
      out.push_back(v);
    }
  return out;
}

/// Image `i`'s bytes: from its buffer view, or its URI as written (data: URI or a file name).
std::string image_bytes(const Glb& g, std::size_t i) {
  const json& im = g.doc["images"][i];
  if (im.contains("bufferView")) {
    const json& view = g.doc["bufferViews"][im["bufferView"].get<std::size_t>()];
    return g.bin.substr(view.value("byteOffset", std::size_t(0)), view["byteLength"].get<std::size_t>());
  }
  return im.value("uri", std::string());
}

/// The JSON without the buffer / buffer view / accessor layout, and without the values tinygltf
/// writes or leaves out for their defaults (the same meaning either way).
json without_layout(json j) {
  j.erase("buffers");
  j.erase("bufferViews");
  for (json& a : j["accessors"]) a.erase("bufferView"), a.erase("byteOffset");
  for (json& im : j["images"]) im.erase("bufferView");
  qem::test::erase_gltf_defaults(j);
  return j;
}

const char* const kFiles[] = {"CesiumMan.glb", "CesiumMilkTruck.glb", "Duck.glb", "SheenCloth.glb",
                              "tiny_cube_vcolor.glb"};

class GltfCorpus : public ::testing::TestWithParam<const char*> {};

TEST_P(GltfCorpus, WrittenBackUnchangedByContent) {
  const std::string path = qem::test::shared_data(GetParam());
  if (path.empty()) GTEST_SKIP() << "../shared/data not found";
  const std::string out = qem::test::temp_dir() + "/" + GetParam();
  qem::GltfDocument::load(path).save(out);
  const Glb a = split_glb(qem::test::slurp(path)), b = split_glb(qem::test::slurp(out));
  const json ja = without_layout(a.doc), jb = without_layout(b.doc);
  EXPECT_EQ(ja, jb) << json::diff(ja, jb).dump();
  ASSERT_EQ(a.doc["accessors"].size(), b.doc["accessors"].size());
  for (std::size_t k = 0; k < a.doc["accessors"].size(); ++k)
    EXPECT_EQ(elements(a, k), elements(b, k)) << "accessor " << k;
  ASSERT_EQ(a.doc.value("images", json::array()).size(), b.doc.value("images", json::array()).size());
  for (std::size_t i = 0; i < a.doc.value("images", json::array()).size(); ++i)
    EXPECT_EQ(image_bytes(a, i), image_bytes(b, i)) << "image " << i;
}

TEST_P(GltfCorpus, SimplifiedKeepsEverythingButThePrimitives) {
  const std::string path = qem::test::shared_data(GetParam());
  if (path.empty()) GTEST_SKIP() << "../shared/data not found";
  const std::string out = qem::test::temp_dir() + "/simplified_" + GetParam();
  ASSERT_EQ(qem::test::run_qem_quietly("simplify '" + path + "' '" + out + "' --ratio 0.5"), 0);
  const qem::GltfDocument before = qem::GltfDocument::load(path), after = qem::GltfDocument::load(out);
  const Glb a = split_glb(qem::test::slurp(path)), b = split_glb(qem::test::slurp(out));

  // The face target over the simplifiable primitives; which primitives were replaced.
  ASSERT_EQ(before.primitives().size(), after.primitives().size());
  std::size_t faces_in = 0, faces_out = 0;
  std::set<std::pair<std::size_t, std::size_t>> replaced;
  for (std::size_t i = 0; i < before.primitives().size(); ++i) {
    const qem::GltfPrimitiveInfo &p = before.primitives()[i], &q = after.primitives()[i];
    if (!p.simplifiable) {
      EXPECT_EQ(q.face_count, p.face_count);
      continue;
    }
    faces_in += p.face_count, faces_out += q.face_count;
    if (q.face_count != p.face_count) replaced.insert({p.mesh, p.primitive});
  }
  EXPECT_LE(faces_out, faces_in / 2);
  EXPECT_FALSE(replaced.empty());

  // The JSON: everything but the accessors and the replaced primitives' accessor indices.
  json ja = without_layout(a.doc), jb = without_layout(b.doc);
  ja.erase("accessors"), jb.erase("accessors");
  for (const auto& [m, k] : replaced)
    for (json* j : {&ja, &jb}) {
      json& p = (*j)["meshes"][m]["primitives"][k];
      p.erase("indices");
      for (auto& [semantic, index] : p["attributes"].items()) index = 0;
      p["attributes"].erase("TANGENT");  // dropped on replaced primitives (qem/gltf.h)
    }
  EXPECT_EQ(ja, jb) << json::diff(ja, jb).dump();

  // Accessor data that anything but a replaced primitive uses is unchanged by content: skins'
  // inverse bind matrices, animation samplers, kept primitives and morph targets.
  std::set<std::size_t> kept_accessors;
  for (const json& s : a.doc.value("skins", json::array()))
    if (s.contains("inverseBindMatrices")) kept_accessors.insert(s["inverseBindMatrices"].get<std::size_t>());
  for (const json& an : a.doc.value("animations", json::array()))
    for (const json& s : an["samplers"])
      kept_accessors.insert(s["input"].get<std::size_t>()),
          kept_accessors.insert(s["output"].get<std::size_t>());
  for (std::size_t m = 0; m < a.doc["meshes"].size(); ++m)
    for (std::size_t k = 0; k < a.doc["meshes"][m]["primitives"].size(); ++k) {
      if (replaced.count({m, k})) continue;
      const json& p = a.doc["meshes"][m]["primitives"][k];
      for (const auto& [semantic, index] : p["attributes"].items())
        kept_accessors.insert(index.get<std::size_t>());
      if (p.contains("indices")) kept_accessors.insert(p["indices"].get<std::size_t>());
    }
  for (std::size_t k : kept_accessors) {
    EXPECT_EQ(elements(a, k), elements(b, k)) << "accessor " << k;
    EXPECT_EQ(a.doc["accessors"][k]["count"], b.doc["accessors"][k]["count"]);
  }
  for (std::size_t i = 0; i < a.doc.value("images", json::array()).size(); ++i)
    EXPECT_EQ(image_bytes(a, i), image_bytes(b, i)) << "image " << i;

  // Skinned primitives keep their skin: weights summing to 1, joints within the skin.
  for (const json& node : b.doc.value("nodes", json::array())) {
    if (!node.contains("skin") || !node.contains("mesh")) continue;
    const std::size_t joints = b.doc["skins"][node["skin"].get<std::size_t>()]["joints"].size();
    const std::size_t m = node["mesh"];
    for (std::size_t k = 0; k < b.doc["meshes"][m]["primitives"].size(); ++k) {
      const json& attributes = b.doc["meshes"][m]["primitives"][k]["attributes"];
      ASSERT_TRUE(attributes.contains("JOINTS_0") && attributes.contains("WEIGHTS_0"));
      const std::vector<double> j = numbers(b, attributes["JOINTS_0"]),
                                w = numbers(b, attributes["WEIGHTS_0"]);
      ASSERT_EQ(j.size(), w.size());
      ASSERT_EQ(
          w.size(),
          4 * b.doc["accessors"][attributes["POSITION"].get<std::size_t>()]["count"].get<std::size_t>());
      for (std::size_t v = 0; v < w.size(); v += 4) {
        EXPECT_NEAR(w[v] + w[v + 1] + w[v + 2] + w[v + 3], 1, 1e-3) << "vertex " << v / 4;
        for (int c = 0; c < 4; ++c) EXPECT_LT(j[v + c], double(joints)) << "vertex " << v / 4;
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Files, GltfCorpus, ::testing::ValuesIn(kFiles), [](const auto& info) {
  std::string n = info.param;
  return n.substr(0, n.find('.'));
});

}  // namespace
