// The LOD manifest format (src/view/lod_manifest.h): levels, counts, errors, and malformed JSON.
#include <gtest/gtest.h>

#include <cmath>

#include "qem/error.h"
#include "view/lod_manifest.h"

namespace qem::view {
namespace {

TEST(ViewManifest, JsonErrorsNameTheFileLineAndColumn) {
  try {
    parse_lod_manifest("{\n  \"levels\": [\"a.ply\",\n  tru]\n}", "m.json");
    FAIL() << "no error";
  } catch (const Error& e) {
    // The end of the bad token "tru]": line 3, column 6.
    EXPECT_EQ(std::string(e.what()).rfind("m.json:3:6: invalid JSON: ", 0), 0u) << e.what();
  }
  EXPECT_THROW(parse_lod_manifest("[\"caf\xe9.ply\"]", "x"), Error);  // JSON text is UTF-8
  EXPECT_THROW(parse_lod_manifest("[\"a.ply\", ", "x"), Error);
  EXPECT_THROW(parse_lod_manifest("[\"a.ply\"] 2", "x"), Error);
  EXPECT_THROW(parse_lod_manifest("[\"unterminated", "x"), Error);
  EXPECT_THROW(parse_lod_manifest("", "x"), Error);
}

TEST(ViewManifest, DeepNestingIsAnErrorNotAStackOverflow) {
  EXPECT_THROW(parse_lod_manifest(std::string(100000, '['), "x"), Error);
  EXPECT_THROW(parse_lod_manifest(std::string(100000, '[') + std::string(100000, ']'), "x"), Error);
}

TEST(ViewManifest, ReadsEscapedAndNonAsciiPaths) {
  auto levels = parse_lod_manifest(R"(["caf\u00e9.ply", "a\"b.ply", "\ud83d\ude00.ply"])", "m.json");
  ASSERT_EQ(levels.size(), 3u);
  EXPECT_EQ(levels[0].path, "caf\xc3\xa9.ply");
  EXPECT_EQ(levels[1].path, "a\"b.ply");
  EXPECT_EQ(levels[2].path, "\xf0\x9f\x98\x80.ply");
}

TEST(ViewManifest, ReadsLevelsWithCountsAndErrors) {
  auto levels = parse_lod_manifest(
      R"({"levels": [{"path": "a.ply", "faces": 100, "vertices": 52, "error": 0},
                     {"file": "sub/b.obj", "faces": 10, "error": 0.25}, {"mesh": "/abs/c.off"}]})",
      "dir/lods.json");
  ASSERT_EQ(levels.size(), 3u);
  EXPECT_EQ(levels[0].path, "dir/a.ply");
  EXPECT_EQ(levels[0].faces, 100u);
  EXPECT_EQ(levels[0].vertices, 52u);
  EXPECT_EQ(levels[0].error, 0);
  EXPECT_EQ(levels[1].path, "dir/sub/b.obj");
  EXPECT_EQ(levels[1].error, 0.25);
  EXPECT_EQ(levels[2].path, "/abs/c.off");
  EXPECT_TRUE(std::isnan(levels[2].error));
  EXPECT_EQ(levels[2].faces, 0u);
}

TEST(ViewManifest, AcceptsABareArrayOfPaths) {
  auto levels = parse_lod_manifest(R"(["x.ply", "y.ply"])", "m.json");
  ASSERT_EQ(levels.size(), 2u);
  EXPECT_EQ(levels[1].path, "y.ply");
}

TEST(ViewManifest, RejectsMalformedLevels) {
  EXPECT_THROW(parse_lod_manifest(R"({"levels": []})", "m.json"), Error);
  EXPECT_THROW(parse_lod_manifest(R"({"lods": ["a.ply"]})", "m.json"), Error);
  EXPECT_THROW(parse_lod_manifest(R"([{"faces": 3}])", "m.json"), Error);
  EXPECT_THROW(parse_lod_manifest(R"([{"path": "a.ply", "faces": -1}])", "m.json"), Error);
  EXPECT_THROW(parse_lod_manifest(R"([{"path": "a.ply", "faces": 2.5}])", "m.json"), Error);
  EXPECT_THROW(parse_lod_manifest(R"([{"path": "a.ply", "error": "big"}])", "m.json"), Error);
  try {
    parse_lod_manifest(R"(["a.ply", 3])", "m.json");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("m.json: level 1"), std::string::npos) << e.what();
  }
}

TEST(ViewManifest, RecognisesManifestPaths) {
  EXPECT_TRUE(is_manifest_path("a/lods.JSON"));
  EXPECT_FALSE(is_manifest_path("a/bunny.ply"));
}

}  // namespace
}  // namespace qem::view
