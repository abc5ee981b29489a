// The viewer's data export (src/view/scene.h): scene.json and the binary level buffers.
#include <gtest/gtest.h>

#include <cstring>
#include <nlohmann/json.hpp>

#include "qem/error.h"
#include "test_meshes.h"
#include "view/scene.h"

namespace qem::view {
namespace {

using nlohmann::json;

std::vector<float> floats(const std::string& bytes) {
  std::vector<float> out(bytes.size() / 4);
  std::memcpy(out.data(), bytes.data(), out.size() * 4);  // the test host is little endian (x86, arm64)
  return out;
}

ViewScene chain_scene() {
  ViewScene s;
  s.mode = ViewMode::Chain;
  s.title = "sphere";
  // Far from the origin: the export must centre positions so Float32 keeps their precision.
  s.levels.push_back({"fine", test::transformed(test::icosphere(2), 1, 1000, 0, 0), 0.0});
  s.levels.push_back({"coarse", test::transformed(test::icosphere(1), 1, 1000, 0, 0), 0.05});
  return s;
}

TEST(ViewScene, DescribesEveryLevelAndWritesItsBuffers) {
  auto files = scene_files(chain_scene());
  ASSERT_TRUE(files.count("data/scene.json"));
  json doc = json::parse(files["data/scene.json"]);
  EXPECT_EQ(doc["format"], "qem-view");
  EXPECT_EQ(doc["mode"], "chain");
  EXPECT_TRUE(doc["distance_range"].is_null());
  const json& levels = doc["levels"];
  ASSERT_EQ(levels.size(), 2u);
  EXPECT_EQ(levels[0]["faces"], 320);
  EXPECT_EQ(levels[0]["vertices"], 162);
  EXPECT_EQ(levels[1]["faces"], 80);
  EXPECT_EQ(levels[1]["error"], 0.05);
  for (const json& l : levels) {
    const std::string& pos = files.at(l["positions"]);
    const std::string& idx = files.at(l["indices"]);
    EXPECT_EQ(pos.size(), 12 * l["vertices"].get<std::size_t>());
    EXPECT_EQ(idx.size(), 12 * l["faces"].get<std::size_t>());
    EXPECT_FALSE(l.contains("distance"));
  }
  // Centred: the stored coordinates lie within the unit sphere, the centre holds the offset.
  EXPECT_NEAR(doc["center"][0].get<double>(), 1000, 1e-9);
  for (float x : floats(files.at("data/level0.pos.f32"))) EXPECT_LE(std::abs(x), 1.0001f);
  EXPECT_NEAR(doc["radius"].get<double>(), std::sqrt(3.0), 1e-3);
}

TEST(ViewScene, IndicesAreStoredUnchanged) {
  ViewScene s;
  s.levels.push_back({"cube", test::cube()});
  auto files = scene_files(s);
  const std::string& idx = files.at("data/level0.idx.u32");
  std::vector<std::uint32_t> got(idx.size() / 4);
  std::memcpy(got.data(), idx.data(), idx.size());
  EXPECT_EQ(got, s.levels[0].mesh.indices);
  json doc = json::parse(files["data/scene.json"]);
  EXPECT_EQ(doc["mode"], "single");
  EXPECT_TRUE(doc["levels"][0]["error"].is_null());  // unknown (NaN) is null, not invalid JSON
}

TEST(ViewScene, ExportsTheDistancePropertyAndItsRange) {
  ViewScene s;
  Mesh m = test::icosphere(1);
  VertexProperty d{"distance", {}};
  for (std::size_t v = 0; v < m.vertex_count(); ++v) d.values.push_back(0.5 + m.positions[3 * v + 1]);
  m.vertex_properties.push_back(d);
  s.levels.push_back({"heat", m});
  auto files = scene_files(s);
  json doc = json::parse(files["data/scene.json"]);
  const json& range = doc["distance_range"];
  ASSERT_EQ(range.size(), 2u);
  EXPECT_NEAR(range[0].get<double>(), -0.5, 1e-12);
  EXPECT_NEAR(range[1].get<double>(), 1.5, 1e-12);
  auto values = floats(files.at(doc["levels"][0]["distance"]));
  ASSERT_EQ(values.size(), m.vertex_count());
  EXPECT_FLOAT_EQ(values[3], static_cast<float>(d.values[3]));
}

TEST(ViewScene, NamesThatAreNotUtf8StillGiveValidJson) {
  // File names are bytes: a Latin-1 "café.ply" must not break the page's JSON.
  ViewScene s;
  s.title = "caf\xe9";
  s.levels.push_back({"caf\xe9.ply", test::cube()});
  auto files = scene_files(s);
  json doc = json::parse(files["data/scene.json"]);  // throws on invalid UTF-8
  EXPECT_EQ(doc["title"], "caf\xef\xbf\xbd");        // U+FFFD
  EXPECT_EQ(doc["levels"][0]["name"], "caf\xef\xbf\xbd.ply");
  s.title = "quote \" backslash \\ newline \n";
  EXPECT_EQ(json::parse(scene_files(s)["data/scene.json"])["title"], s.title);
}

TEST(ViewScene, IsDeterministic) { EXPECT_EQ(scene_files(chain_scene()), scene_files(chain_scene())); }

TEST(ViewScene, RejectsBadScenes) {
  ViewScene empty;
  EXPECT_THROW(scene_files(empty), Error);
  ViewScene compare = chain_scene();
  compare.mode = ViewMode::Compare;
  EXPECT_NO_THROW(scene_files(compare));
  compare.levels.push_back(compare.levels[0]);
  EXPECT_THROW(scene_files(compare), Error);  // compare needs exactly two meshes
  ViewScene bad;
  Mesh m = test::tetrahedron();
  m.indices[5] = 99;
  bad.levels.push_back({"bad", m});
  EXPECT_THROW(scene_files(bad), Error);
}

}  // namespace
}  // namespace qem::view
