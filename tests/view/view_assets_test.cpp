// What `qem view` reads beside a model: the safe resolution of referenced files (safe_path.h),
// OBJ material libraries (mtl.h), and the files of a level (model_assets.h).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "qem/error.h"
#include "qem/gltf.h"
#include "test_meshes.h"
#include "view/model_assets.h"
#include "view/mtl.h"
#include "view/safe_path.h"

namespace qem::view {
namespace {

namespace fs = std::filesystem;

void write(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << text;
}

// A model folder inside a parent folder holding a "secret" the model must not reach.
struct Folders {
  fs::path root =
      fs::path(test::temp_dir()) / ::testing::UnitTest::GetInstance()->current_test_info()->name();
  fs::path model = root / "model";
  Folders() {
    fs::remove_all(root);
    write(root / "secret.txt", "do not serve");
    write(model / "tex" / "a b.png", "PNG bytes");
  }
};

TEST(ViewSafePath, ResolvesFilesInsideTheFolder) {
  Folders f;
  std::string why;
  auto r = resolve_inside(f.model, "tex/a b.png", &why);
  ASSERT_TRUE(r) << why;
  EXPECT_EQ(r->key, "tex/a b.png");
  EXPECT_TRUE(fs::equivalent(r->file, f.model / "tex" / "a b.png"));
  // Windows separators and harmless dots are normalised.
  r = resolve_inside(f.model, "tex\\.\\a b.png", &why);
  ASSERT_TRUE(r) << why;
  EXPECT_EQ(r->key, "tex/a b.png");
  r = resolve_inside(f.model, "tex/../tex/a b.png", &why);
  ASSERT_TRUE(r) << why;
  EXPECT_EQ(r->key, "tex/a b.png");
}

TEST(ViewSafePath, RefusesEverythingOutsideTheFolder) {
  Folders f;
  std::string why;
  EXPECT_FALSE(resolve_inside(f.model, "../secret.txt", &why));
  EXPECT_NE(why.find("outside"), std::string::npos) << why;
  EXPECT_FALSE(resolve_inside(f.model, "tex/../../secret.txt", &why));
  EXPECT_FALSE(resolve_inside(f.model, "..\\secret.txt", &why));
  EXPECT_FALSE(resolve_inside(f.model, (f.root / "secret.txt").string(), &why));
  EXPECT_NE(why.find("absolute"), std::string::npos) << why;
  EXPECT_FALSE(resolve_inside(f.model, "", &why));
  EXPECT_FALSE(resolve_inside(f.model, ".", &why));
  EXPECT_FALSE(resolve_inside(f.model, "tex", &why));  // a folder, not a file
  EXPECT_FALSE(resolve_inside(f.model, "missing.png", &why));
  EXPECT_EQ(why, "no such file");
  // A symbolic link inside the folder that leads out of it.
  fs::create_symlink(f.root / "secret.txt", f.model / "link.png");
  EXPECT_FALSE(resolve_inside(f.model, "link.png", &why));
  EXPECT_NE(why.find("link"), std::string::npos) << why;
}

TEST(ViewSafePath, DecodesPercentEscapes) {
  EXPECT_EQ(percent_decode("a%20b%2Fc.png"), "a b/c.png");
  EXPECT_EQ(percent_decode("100%"), "100%");
  EXPECT_EQ(percent_decode("%zz%4"), "%zz%4");
}

TEST(ViewMtl, ReadsDiffuseColourOpacityAndTexture) {
  std::vector<std::string> notes;
  auto m = parse_mtl(
      "# comment\nnewmtl skin\nKa 0 0 0\nKd 0.5 0.25 1\nd 0.5\nmap_Kd -s 1 1 1 -o 0 0 -bm 2 tex/a b.png\r\n"
      "newmtl plain\nKd 0.3\nTr 0.25\nnewmtl bad\nKd x y z\n",
      "lib.mtl", &notes);
  ASSERT_EQ(m.size(), 3u);
  EXPECT_EQ(m[0].name, "skin");
  EXPECT_DOUBLE_EQ(m[0].diffuse[1], 0.25);
  EXPECT_DOUBLE_EQ(m[0].opacity, 0.5);
  EXPECT_EQ(m[0].diffuse_map, "tex/a b.png");
  EXPECT_DOUBLE_EQ(m[1].diffuse[2], 0.3);
  EXPECT_DOUBLE_EQ(m[1].opacity, 0.75);
  EXPECT_EQ(m[1].diffuse_map, "");
  EXPECT_DOUBLE_EQ(m[2].diffuse[0], 0.8);  // malformed: kept at the default, with a note
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_EQ(notes[0], "lib.mtl, line 11: Kd needs one or three numbers, skipped");
}

TEST(ViewModelAssets, ObjGetsItsMaterialsAndOnlyTexturesInsideItsFolder) {
  Folders f;
  write(f.model / "m.obj",
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvt 1 1\n"
        "usemtl skin\nf 1/1 2/2 3/3\nusemtl thief\nf 2/2 4/4 3/3\nusemtl unknown\nf 1/1 3/3 2/2\n");
  write(f.model / "m.mtl", "newmtl skin\nKd 1 0 0\nmap_Kd tex/a b.png\nnewmtl thief\nmap_Kd ../secret.txt\n");
  std::vector<std::string> warnings;
  ViewLevel level = load_view_level((f.model / "m.obj").string(), {}, &warnings);
  ASSERT_EQ(level.materials.size(), 3u);
  EXPECT_EQ(level.materials[0].name, "skin");
  EXPECT_EQ(level.materials[0].texture, "tex/a b.png");
  EXPECT_DOUBLE_EQ(level.materials[0].color[1], 0);
  EXPECT_EQ(level.materials[1].texture, "");           // refused, not served
  EXPECT_DOUBLE_EQ(level.materials[2].color[0], 0.8);  // not in the library: the MTL default
  EXPECT_EQ(level.files.size(), 1u);
  EXPECT_EQ(level.files.at("tex/a b.png"), "PNG bytes");
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_NE(warnings[0].find("'../secret.txt' not shown: a path outside the model's folder"),
            std::string::npos)
      << warnings[0];
  EXPECT_NE(warnings[1].find("'unknown' is not in its library"), std::string::npos) << warnings[1];
  EXPECT_TRUE(level.gltf.empty());
}

TEST(ViewModelAssets, MissingLibraryIsAWarningNotAnError) {
  Folders f;
  write(f.model / "m.obj", "mtllib nowhere.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n");
  std::vector<std::string> warnings;
  ViewLevel level = load_view_level((f.model / "m.obj").string(), {}, &warnings);
  EXPECT_TRUE(level.materials.empty());  // the page's default look, not white
  EXPECT_TRUE(level.files.empty());
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("material library 'nowhere.mtl' not shown: no such file"), std::string::npos);
}

TEST(ViewModelAssets, PlyFaceColoursBecomeMaterials) {
  Folders f;
  write(f.model / "c.ply",
        "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
        "element face 2\nproperty list uchar int vertex_indices\nproperty uchar red\nproperty uchar green\n"
        "property uchar blue\nend_header\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2 255 0 0\n3 0 2 3 0 0 255\n");
  ViewLevel level = load_view_level((f.model / "c.ply").string(), {}, nullptr);
  ASSERT_EQ(level.materials.size(), 2u);
  EXPECT_DOUBLE_EQ(level.materials[0].color[0], 1);
  EXPECT_DOUBLE_EQ(level.materials[0].color[2], 0);
  EXPECT_DOUBLE_EQ(level.materials[1].color[2], 1);
  EXPECT_EQ(level.mesh.face_materials, (std::vector<std::uint32_t>{0, 1}));
}

TEST(ViewModelAssets, GltfKeepsTheDocumentAndItsRelativeResources) {
  Folders f;
  Mesh tri = test::tetrahedron();
  // A .gltf whose buffer is embedded, with one image beside it and one outside the folder.
  std::string doc = serialize_gltf(tri, false);
  const std::size_t end = doc.find_last_of('}');
  ASSERT_NE(end, std::string::npos);
  ASSERT_EQ(doc.find("\"images\""), std::string::npos);  // serialize_gltf writes none: add them
  doc.insert(end,
             ",\"images\":[{\"uri\":\"tex/a%20b.png\"},{\"uri\":\"../secret.txt\"},"
             "{\"uri\":\"data:image/png;base64,AAAA\"}]");
  write(f.model / "m.gltf", doc);
  EXPECT_EQ(gltf_external_uris(doc, "m.gltf"), (std::vector<std::string>{"tex/a%20b.png", "../secret.txt"}));
  std::vector<std::string> warnings;
  ViewLevel level = load_view_level((f.model / "m.gltf").string(), {}, &warnings);
  EXPECT_EQ(level.gltf, "m.gltf");
  EXPECT_EQ(level.files.at("m.gltf"), doc);
  EXPECT_EQ(level.files.at("tex/a b.png"), "PNG bytes");
  EXPECT_EQ(level.files.size(), 2u);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("'../secret.txt' not shown"), std::string::npos) << warnings[0];
  EXPECT_EQ(level.mesh.face_count(), tri.face_count());
}

TEST(ViewModelAssets, CompressedGltfGoesToThePageDecoded) {
  Folders f;
  std::string bin;
  const qem::Mesh sphere = test::uv_sphere(4, 8);
  const std::string doc = test::gltf_text(test::draco_document(sphere, bin), bin);
  write(f.model / "d.gltf", doc);
  ViewLevel level = load_view_level((f.model / "d.gltf").string(), {}, nullptr);
  const std::string& served = level.files.at("d.gltf");
  EXPECT_EQ(served.find("KHR_draco_mesh_compression"), std::string::npos);  // three.js reads it as is
  EXPECT_EQ(GltfDocument::parse(served, "served.gltf").mesh(0).face_count(), sphere.face_count());
  EXPECT_EQ(level.mesh.face_count(), sphere.face_count());
}

TEST(ViewModelAssets, GlbJsonChunkIsRead) {
  const std::string glb = serialize_gltf(test::tetrahedron(), true);
  EXPECT_TRUE(gltf_external_uris(glb, "t.glb").empty());  // one embedded buffer, no URI
  EXPECT_THROW(gltf_external_uris(glb.substr(0, 16), "t.glb"), Error);
  EXPECT_THROW(gltf_external_uris("{not json", "t.gltf"), Error);
}

}  // namespace
}  // namespace qem::view
