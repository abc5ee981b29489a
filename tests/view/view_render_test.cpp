// `qem render`'s software rasteriser and PNG encoder (src/view/render.h, png.h).
#include <gtest/gtest.h>

#include <cstring>

#include "qem/error.h"
#include "test_meshes.h"
#include "view/png.h"
#include "view/render.h"

namespace qem::view {
namespace {

std::size_t count_pixels(const Image& img, bool (*pred)(const std::uint8_t*)) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < img.rgb.size(); i += 3) n += pred(&img.rgb[i]);
  return n;
}
bool not_background(const std::uint8_t* p) {
  return std::abs(p[0] - 245) + std::abs(p[1] - 245) + std::abs(p[2] - 245) > 24;
}
bool dark(const std::uint8_t* p) { return p[0] + p[1] + p[2] < 200; }
bool saturated(const std::uint8_t* p) {
  return std::max({p[0], p[1], p[2]}) - std::min({p[0], p[1], p[2]}) > 80;
}

std::uint32_t be32(const std::string& s, std::size_t at) {
  return (std::uint32_t(std::uint8_t(s[at])) << 24) | (std::uint32_t(std::uint8_t(s[at + 1])) << 16) |
         (std::uint32_t(std::uint8_t(s[at + 2])) << 8) | std::uint8_t(s[at + 3]);
}

TEST(ViewPng, Crc32MatchesTheStandardCheckValue) {
  const char* s = "123456789";
  EXPECT_EQ(crc32(reinterpret_cast<const std::uint8_t*>(s), 9), 0xCBF43926u);
}

TEST(ViewPng, EncodesValidChunksAndStoredPixels) {
  Image img{3, 2, {}};
  for (int i = 0; i < 18; ++i) img.rgb.push_back(static_cast<std::uint8_t>(i * 13));
  std::string png = encode_png(img);
  ASSERT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  // Walk the chunks, checking each CRC; collect IDAT.
  std::size_t pos = 8;
  std::string idat, types;
  while (pos < png.size()) {
    std::uint32_t len = be32(png, pos);
    std::string type = png.substr(pos + 4, 4);
    types += type + " ";
    std::uint32_t crc = crc32(reinterpret_cast<const std::uint8_t*>(png.data() + pos + 4), len + 4);
    EXPECT_EQ(crc, be32(png, pos + 8 + len)) << type;
    if (type == "IHDR") {
      EXPECT_EQ(be32(png, pos + 8), 3u);
      EXPECT_EQ(be32(png, pos + 12), 2u);
    }
    if (type == "IDAT") idat += png.substr(pos + 8, len);
    pos += 12 + len;
  }
  EXPECT_EQ(types, "IHDR IDAT IEND ");
  // zlib header, one final stored block, then the rows each led by filter byte 0.
  ASSERT_GE(idat.size(), 2u + 5 + 20 + 4);
  EXPECT_EQ(idat.substr(0, 2), "\x78\x01");
  EXPECT_EQ(idat[2], '\x01');
  EXPECT_EQ(std::uint8_t(idat[3]) | (std::uint8_t(idat[4]) << 8), 20);
  std::string raw = idat.substr(7, 20);
  EXPECT_EQ(raw[0], 0);
  EXPECT_EQ(raw[10], 0);
  EXPECT_EQ(std::memcmp(raw.data() + 1, img.rgb.data(), 9), 0);
  EXPECT_EQ(std::memcmp(raw.data() + 11, img.rgb.data() + 9, 9), 0);
}

TEST(ViewPng, SplitsLargeImagesIntoSeveralStoredBlocks) {
  Image img{200, 200, std::vector<std::uint8_t>(200 * 200 * 3, 7)};
  std::string png = encode_png(img);
  // 200 rows of 601 bytes = 120200 bytes: two blocks of 65535 + 54665, 5 header bytes each.
  EXPECT_EQ(png.size(), 8u + 25 + (12 + 2 + 120200 + 10 + 4) + 12);
}

TEST(ViewRender, DrawsTheMeshInTheMiddleOfABackground) {
  Image img = render_mesh(test::icosphere(2), {.width = 160, .height = 120});
  ASSERT_EQ(img.rgb.size(), 160u * 120 * 3);
  std::size_t fg = count_pixels(img, not_background);
  // The unit sphere framed by its box's bounding sphere covers about a fifth of the picture.
  EXPECT_GT(fg, 160u * 120 / 10);
  EXPECT_LT(fg, 160u * 120 / 2);
  EXPECT_FALSE(not_background(&img.rgb[0]));                   // top-left corner
  EXPECT_TRUE(not_background(&img.rgb[3 * (60 * 160 + 80)]));  // centre
  EXPECT_EQ(count_pixels(img, saturated), 0u);                 // grey-blue, no heat map
}

TEST(ViewRender, IsDeterministic) {
  RenderOptions o{.width = 64, .height = 48, .smooth = true, .wireframe = true};
  EXPECT_EQ(render_mesh(test::icosphere(2), o).rgb, render_mesh(test::icosphere(2), o).rgb);
}

TEST(ViewRender, OptionsChangeThePicture) {
  Mesh m = test::icosphere(1);
  Image flat = render_mesh(m, {.width = 120, .height = 90});
  Image smooth = render_mesh(m, {.width = 120, .height = 90, .smooth = true});
  Image wire = render_mesh(m, {.width = 120, .height = 90, .wireframe = true});
  EXPECT_NE(flat.rgb, smooth.rgb);
  EXPECT_GT(count_pixels(wire, dark), count_pixels(flat, dark) + 100);
  Image turned = render_mesh(m, {.width = 120, .height = 90, .yaw_degrees = 75});
  EXPECT_NE(flat.rgb, turned.rgb);
}

TEST(ViewRender, ColoursTheDistancePropertyAsAHeatMap) {
  Mesh m = test::icosphere(2);
  VertexProperty d{"distance", {}};
  for (std::size_t v = 0; v < m.vertex_count(); ++v) d.values.push_back(m.positions[3 * v + 1]);
  m.vertex_properties.push_back(d);
  Image heat = render_mesh(m, {.width = 120, .height = 90});
  EXPECT_GT(count_pixels(heat, saturated), 500u);
  Image plain = render_mesh(m, {.width = 120, .height = 90, .heatmap = false});
  EXPECT_EQ(count_pixels(plain, saturated), 0u);
}

TEST(ViewRender, HeatColoursRunThroughViridis) {
  auto lo = heat_color(0), hi = heat_color(1), mid = heat_color(0.5);
  EXPECT_NEAR(lo[0], 0.267, 1e-12);
  EXPECT_NEAR(hi[1], 0.906, 1e-12);
  EXPECT_NEAR(mid[2], 0.551, 1e-12);
  EXPECT_EQ(heat_color(-3), lo);
  EXPECT_EQ(heat_color(7), hi);
}

TEST(ViewRender, RejectsBadSizesAndIndices) {
  EXPECT_THROW(render_mesh(test::cube(), {.width = 0}), Error);
  EXPECT_THROW(render_mesh(test::cube(), {.width = 10, .height = 9000}), Error);
  Mesh m = test::cube();
  m.indices[0] = 1000;
  EXPECT_THROW(render_mesh(m, {.width = 10, .height = 10}), Error);
  EXPECT_NO_THROW(render_mesh(Mesh{}, {.width = 10, .height = 10}));  // empty: just the background
}

}  // namespace
}  // namespace qem::view
