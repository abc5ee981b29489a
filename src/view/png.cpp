// PNG writing (png.h) with libpng's simplified API.
#include "view/png.h"

#include <png.h>

#include "io/io_common.h"
#include "qem/error.h"

namespace qem::view {

std::string encode_png(const Image& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgb.size() != static_cast<std::size_t>(image.width) * image.height * 3)
    throw Error("encode_png: image size does not match its pixels");
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width);
  png.height = static_cast<png_uint_32>(image.height);
  png.format = PNG_FORMAT_RGB;
  // The buffer holds the largest PNG the image can give; the write reports the size it took.
  png_alloc_size_t size = PNG_IMAGE_PNG_SIZE_MAX(png);
  std::string bytes(size, '\0');
  if (!png_image_write_to_memory(&png, bytes.data(), &size, 0, image.rgb.data(), 0, nullptr))
    throw Error(std::string("cannot encode the picture as PNG: ") + png.message);
  bytes.resize(size);
  return bytes;
}

void save_png(const std::string& path, const Image& image) { io::write_file_atomic(path, encode_png(image)); }

}  // namespace qem::view
