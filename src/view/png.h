// The pictures of `qem render` and their PNG encoding (8-bit RGB, through libpng).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace qem::view {

struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  ///< 3 bytes per pixel, rows top to bottom
};

/// The PNG file bytes of an image. Throws qem::Error when the pixels do not match the size.
std::string encode_png(const Image& image);

/// Writes the PNG atomically (temporary file, then rename). Throws qem::Error on failure.
void save_png(const std::string& path, const Image& image);

}  // namespace qem::view
