// PNG writing with stb_image_write (implementation provided by libstb): encoded in memory and
// written by writeFileChecked (temporary name, every write and the close checked, then rename), so
// a full disk is reported and never leaves a half-written PNG under the final name.
#include <stb_image_write.h>

#include <cstdio>
#include <exception>
#include <mutex>

#include "labs/file_write.h"
#include "render/image.h"

namespace dyn {

bool writePng(const std::string& path, const Image& image, std::string* why, PngEncoding encoding) {
  const auto failed = [&](const std::string& reason) {
    if (why) *why = reason;
    return false;
  };
  if (image.width <= 0 || image.height <= 0 ||
      image.rgba.size() != std::size_t(image.width) * image.height * 4)
    return failed("cannot write " + path + ": empty or inconsistent image");
  std::string png;
  const auto append = [](void* context, void* data, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(data), std::size_t(size));
  };
  bool encoded = false;
  {
    // stb's settings are globals: set for this image and put back, one image at a time. Fast:
    // stb's lowest compression level (it raises anything under 5 to 5) and no per-row filter
    // search (filter 0; on flat rendered frames it is no larger than the best filter per row).
    static std::mutex mutex;
    const std::lock_guard<std::mutex> lock(mutex);
    const int level = stbi_write_png_compression_level, filter = stbi_write_force_png_filter;
    if (encoding == PngEncoding::Fast) stbi_write_png_compression_level = 5, stbi_write_force_png_filter = 0;
    encoded = stbi_write_png_to_func(append, &png, image.width, image.height, 4, image.rgba.data(), image.width * 4) != 0;
    stbi_write_png_compression_level = level, stbi_write_force_png_filter = filter;
  }
  if (!encoded) return failed("cannot write " + path + ": PNG encoding failed");
  try {
    writeFileChecked(path, png);
  } catch (const std::exception& e) {
    return failed(e.what());
  }
  return true;
}

bool parseFrameSize(const std::string& text, int min_width, int min_height, int& width, int& height) {
  int w = 0, h = 0, n = 0;
  if (std::sscanf(text.c_str(), "%dx%d%n", &w, &h, &n) != 2 || n != int(text.size())) return false;
  if (w < min_width || h < min_height || w > 8192 || h > 8192) return false;
  width = w;
  height = h;
  return true;
}

}  // namespace dyn
