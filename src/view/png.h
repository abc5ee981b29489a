// A dependency-free PNG encoder for `qem render`: 8-bit RGB, zlib stream of stored (uncompressed)
// deflate blocks, CRC-32 and Adler-32 computed here. Larger than a compressed PNG but exact,
// deterministic and needing no library.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace qem::view {

struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  ///< 3 bytes per pixel, rows top to bottom
};

/// The PNG file bytes of an image.
std::string encode_png(const Image& image);

/// CRC-32 (ISO 3309, as PNG chunks use) of `size` bytes.
std::uint32_t crc32(const std::uint8_t* data, std::size_t size, std::uint32_t crc = 0);

/// Writes the PNG atomically (temporary file, then rename). Throws qem::Error on failure.
void save_png(const std::string& path, const Image& image);

}  // namespace qem::view
