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

}  // namespace dyn
