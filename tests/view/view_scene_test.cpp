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

// A level without appearance (the aggregate has more fields: -Wmissing-field-initializers).
ViewLevel level(std::string name, Mesh mesh, double error = std::numeric_limits<double>::quiet_NaN()) {
  ViewLevel l;
  l.name = std::move(name);
  l.mesh = std::move(mesh);
  l.error = error;
  return l;
}

ViewScene chain_scene() {
  ViewScene s;
  s.mode = ViewMode::Chain;
  s.title = "sphere";
  // Far from the origin: the export must centre positions so Float32 keeps their precision.
  s.levels.push_back(level("fine", test::transformed(test::icosphere(2), 1, 1000, 0, 0), 0.0));
  s.levels.push_back(level("coarse", test::transformed(test::icosphere(1), 1, 1000, 0, 0), 0.05));
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
  s.levels.push_back(level("cube", test::cube()));
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
  s.levels.push_back(level("heat", m));
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
  s.levels.push_back(level("caf\xe9.ply", test::cube()));
  auto files = scene_files(s);
  json doc = json::parse(files["data/scene.json"]);  // throws on invalid UTF-8
  EXPECT_EQ(doc["title"], "caf\xef\xbf\xbd");        // U+FFFD
  EXPECT_EQ(doc["levels"][0]["name"], "caf\xef\xbf\xbd.ply");
  s.title = "quote \" backslash \\ newline \n";
  EXPECT_EQ(json::parse(scene_files(s)["data/scene.json"])["title"], s.title);
}

// A quad of two faces with normals, UVs, RGBA colours and two materials, one textured.
ViewLevel appearance_level() {
  ViewLevel l;
  l.name = "quad";
  l.mesh.positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  l.mesh.indices = {0, 1, 2, 0, 2, 3};
  l.mesh.attributes.push_back({"NORMAL", AttributeKind::Normal, 3, {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}});
  l.mesh.attributes.push_back({"TEXCOORD_0", AttributeKind::TexCoord, 2, {0, 0, 1, 0, 1, 1, 0, 1}});
  l.mesh.attributes.push_back({"COLOR_0", AttributeKind::Color, 4, {1, 0, 0, 1, 0, 1, 0, 1, 0, 0, 1, 1, 1, 1, 1, 0.5}});
  l.mesh.face_materials = {1, 0};
  l.mesh.material_names = {"plain", "skin"};
  ViewMaterial plain{"plain", {0.1, 0.2, 0.3}, 0.5, ""}, skin{"skin", {1, 1, 1}, 1, "tex/skin.png"};
  l.materials = {plain, skin};
  l.files["tex/skin.png"] = "PNG";
  return l;
}

TEST(ViewScene, ExportsNormalsUvsColoursMaterialsAndTextures) {
  ViewScene s;
  s.levels.push_back(appearance_level());
  auto files = scene_files(s);
  json doc = json::parse(files["data/scene.json"]);
  EXPECT_EQ(doc["version"], 2);
  const json& l = doc["levels"][0];
  EXPECT_EQ(floats(files.at(l["normals"])), (std::vector<float>{0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1}));
  EXPECT_EQ(floats(files.at(l["uvs"])), (std::vector<float>{0, 0, 1, 0, 1, 1, 0, 1}));
  EXPECT_EQ(l["color_components"], 4);
  auto colors = floats(files.at(l["colors"]));
  ASSERT_EQ(colors.size(), 16u);
  EXPECT_FLOAT_EQ(colors[15], 0.5f);
  const std::string& mats = files.at(l["face_materials"]);
  std::vector<std::uint32_t> ids(mats.size() / 4);
  std::memcpy(ids.data(), mats.data(), mats.size());
  EXPECT_EQ(ids, (std::vector<std::uint32_t>{1, 0}));
  ASSERT_EQ(l["materials"].size(), 2u);
  EXPECT_EQ(l["materials"][0]["name"], "plain");
  EXPECT_TRUE(l["materials"][0]["texture"].is_null());
  EXPECT_DOUBLE_EQ(l["materials"][0]["opacity"].get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(l["materials"][0]["color"][2].get<double>(), 0.3);
  // The texture is served beside the level's buffers, under the name the model gave it.
  EXPECT_EQ(l["materials"][1]["texture"], "data/level0/tex/skin.png");
  EXPECT_EQ(files.at("data/level0/tex/skin.png"), "PNG");
}

TEST(ViewScene, GltfLevelsPointAtTheDocumentInsteadOfBuffers) {
  ViewScene s;
  s.mode = ViewMode::Compare;
  ViewLevel g;
  g.name = "man.glb";
  g.mesh = test::cube();
  g.gltf = "man.glb";
  g.files = {{"man.glb", "glTF..."}, {"textures/skin.jpg", "JPEG"}};
  s.levels.push_back(g);
  s.levels.push_back(level("simplified.obj", test::cube()));
  auto files = scene_files(s);
  json doc = json::parse(files["data/scene.json"]);
  const json& l0 = doc["levels"][0];
  EXPECT_EQ(l0["gltf"], "data/level0/man.glb");
  EXPECT_EQ(l0["faces"], 12);
  EXPECT_FALSE(l0.contains("positions"));
  EXPECT_FALSE(files.count("data/level0.pos.f32"));
  EXPECT_EQ(files.at("data/level0/textures/skin.jpg"), "JPEG");
  EXPECT_TRUE(doc["levels"][1].contains("positions"));  // mixed formats side by side
  EXPECT_FALSE(doc["levels"][1].contains("gltf"));
}

TEST(ViewScene, RejectsInconsistentAppearance) {
  auto fails = [](auto change) {
    ViewScene s;
    s.levels.push_back(appearance_level());
    change(s.levels[0]);
    EXPECT_THROW(scene_files(s), Error);
  };
  fails([](ViewLevel& l) { l.mesh.attributes[1].values.pop_back(); });       // UVs of the wrong size
  fails([](ViewLevel& l) { l.mesh.face_materials = {0}; });                  // one material for two faces
  fails([](ViewLevel& l) { l.mesh.face_materials = {0, 2}; });               // a material that does not exist
  fails([](ViewLevel& l) { l.materials[1].texture = "tex/missing.png"; });   // a texture not among the files
  fails([](ViewLevel& l) { l.files["../escape.png"] = "x"; });              // a key leading out of the folder
  fails([](ViewLevel& l) { l.files["/abs.png"] = "x"; });
  fails([](ViewLevel& l) { l.gltf = "missing.glb"; });
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
  bad.levels.push_back(level("bad", m));
  EXPECT_THROW(scene_files(bad), Error);
}

}  // namespace
}  // namespace qem::view
