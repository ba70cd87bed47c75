// PNG writing with stb_image_write (implementation provided by libstb): written to a temporary
// name and renamed, so a failed write never leaves a half-written PNG under the final name.
#include <stb_image_write.h>

#include <cstdio>
#include <filesystem>
#include <system_error>

#include "render/image.h"

namespace dyn {

bool writePng(const std::string& path, const Image& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgba.size() != std::size_t(image.width) * image.height * 4)
    return false;
  const std::string temp = path + ".tmp";
  const int ok = stbi_write_png(temp.c_str(), image.width, image.height, 4, image.rgba.data(),
                                image.width * 4);
  std::error_code ec;
  if (!ok) {
    std::filesystem::remove(temp, ec);
    return false;
  }
  std::filesystem::rename(temp, path, ec);
  if (ec) {
    std::filesystem::remove(temp, ec);
    return false;
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
