// The viewer's JSON reader/writer and the LOD manifest format (src/view/json.h, lod_manifest.h).
#include <gtest/gtest.h>

#include <cmath>

#include "qem/error.h"
#include "view/json.h"
#include "view/lod_manifest.h"

namespace qem::view {
namespace {

TEST(ViewJson, ParsesNestedValuesAndEscapes) {
  JsonValue v = parse_json(R"({"a": [1, -2.5e3, true, false, null], "s": "x\"\u00e9\n", "o": {}})", "t.json");
  ASSERT_TRUE(v.is_object());
  const JsonValue* a = v.find("a");
  ASSERT_TRUE(a && a->is_array());
  ASSERT_EQ(a->array.size(), 5u);
  EXPECT_EQ(a->array[0].number, 1);
  EXPECT_EQ(a->array[1].number, -2500);
  EXPECT_TRUE(a->array[2].boolean);
  EXPECT_TRUE(a->array[4].is_null());
  EXPECT_EQ(v.find("s")->string, "x\"\xc3\xa9\n");
  EXPECT_TRUE(v.find("o")->is_object());
  EXPECT_EQ(v.find("missing"), nullptr);
}

TEST(ViewJson, ErrorsNameTheFileAndLine) {
  try {
    parse_json("{\n  \"a\": 1,\n  \"b\": tru\n}", "m.json");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("m.json:3:"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_json("[1, 2", "x"), Error);
  EXPECT_THROW(parse_json("[1] 2", "x"), Error);
  EXPECT_THROW(parse_json("\"unterminated", "x"), Error);
  EXPECT_THROW(parse_json(std::string(1000, '['), "x"), Error);  // depth limit, not a stack overflow
}

TEST(ViewJson, WritesQuotedStringsAndNumbers) {
  EXPECT_EQ(json_quote("a\"b\\c\n\x01"), "\"a\\\"b\\\\c\\n\\u0001\"");
  EXPECT_EQ(json_number(0.1), "0.1");
  EXPECT_EQ(json_number(1280), "1280");
  EXPECT_EQ(json_number(NAN), "null");
  EXPECT_EQ(json_number(INFINITY), "null");
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
