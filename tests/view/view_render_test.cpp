// `qem render`'s software rasteriser and PNG encoder (src/view/render.h, png.h).
#include <gtest/gtest.h>
#include <png.h>

#include <fstream>
#include <iterator>

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

// Decodes a PNG with libpng's reader, as any viewer would; an empty image when it cannot.
Image decode_png(const std::string& bytes) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_memory(&png, bytes.data(), bytes.size())) return {};
  png.format = PNG_FORMAT_RGB;
  Image img{static_cast<int>(png.width), static_cast<int>(png.height),
            std::vector<std::uint8_t>(PNG_IMAGE_SIZE(png))};
  if (!png_image_finish_read(&png, nullptr, img.rgb.data(), 0, nullptr)) return {};
  return img;
}

TEST(ViewPng, ReadsBackExactly) {
  Image img{3, 2, {}};
  for (int i = 0; i < 18; ++i) img.rgb.push_back(static_cast<std::uint8_t>(i * 13));
  std::string png = encode_png(img);
  ASSERT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  Image back = decode_png(png);
  EXPECT_EQ(back.width, 3);
  EXPECT_EQ(back.height, 2);
  EXPECT_EQ(back.rgb, img.rgb);
}

TEST(ViewPng, CompressesARenderedPicture) {
  Image img = render_mesh(test::icosphere(2), {.width = 200, .height = 150});
  std::string png = encode_png(img);
  EXPECT_LT(png.size(), img.rgb.size() / 4);  // mostly background: deflate shrinks it well
  EXPECT_EQ(decode_png(png).rgb, img.rgb);
  EXPECT_EQ(encode_png(img), png);  // deterministic
}

TEST(ViewPng, RejectsPixelsThatDoNotMatchTheSize) {
  EXPECT_THROW(encode_png(Image{3, 2, std::vector<std::uint8_t>(17)}), Error);
  EXPECT_THROW(encode_png(Image{0, 2, {}}), Error);
}

TEST(ViewPng, SavesAFileOrFailsClearly) {
  Image img{4, 4, std::vector<std::uint8_t>(48, 200)};
  const std::string path = test::temp_dir() + "/picture.png";
  save_png(path, img);
  std::ifstream in(path, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(decode_png(bytes).rgb, img.rgb);
  EXPECT_THROW(save_png(test::temp_dir() + "/no/such/folder/picture.png", img), Error);
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
