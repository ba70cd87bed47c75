// Where a PNG has ink (any pixel not white): its box, and whether any lies within `strip` pixels of
// an edge (a title, label or legend cut off by the page). Shared by the figure and map tests.
#pragma once
#include <doctest/doctest.h>
#include <stb_image.h>

#include <algorithm>
#include <cstddef>
#include <filesystem>

namespace dyn::test {

struct Ink {
  int width = 0, height = 0, x0 = 0, y0 = 0, x1 = -1, y1 = -1;
  bool at_edge = false;
};

inline Ink inkOf(const std::filesystem::path& png, int strip = 2) {
  Ink ink;
  int n = 0;
  unsigned char* data = stbi_load(png.string().c_str(), &ink.width, &ink.height, &n, 3);
  REQUIRE(data != nullptr);
  ink.x0 = ink.width, ink.y0 = ink.height;
  for (int y = 0; y < ink.height; ++y)
    for (int x = 0; x < ink.width; ++x) {
      const unsigned char* p = data + (std::size_t(y) * ink.width + x) * 3;
      if (p[0] > 250 && p[1] > 250 && p[2] > 250) continue;
      ink.x0 = std::min(ink.x0, x), ink.x1 = std::max(ink.x1, x), ink.y0 = std::min(ink.y0, y), ink.y1 = std::max(ink.y1, y);
      ink.at_edge = ink.at_edge || x < strip || y < strip || x >= ink.width - strip || y >= ink.height - strip;
    }
  stbi_image_free(data);
  return ink;
}

}  // namespace dyn::test
