// Image: an RGBA8 frame, rows top-down, and writing it as PNG (stb_image_write).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

namespace dyn {

struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;  // width*height*4, top row first
  const std::uint8_t* pixel(int x, int y) const { return &rgba[(std::size_t(y) * width + x) * 4]; }
};

// Small: stb's default compression (stills, screenshots). Fast: a run's frames, about 2.5x
// faster to encode and about as small (see writePng).
enum class PngEncoding { Small, Fast };

// Writes a PNG (encoded in memory, then labs/file_write.h's checked write); returns false (and
// leaves no file behind) on failure, with the reason (the system's error text) in *why if given.
// Either encoding gives the same bytes for the same image every time.
bool writePng(const std::string& path, const Image& image, std::string* why = nullptr,
              PngEncoding encoding = PngEncoding::Small);

// "1920x1080" → width and height; false unless the whole text is WIDTHxHEIGHT with each side in
// [min, 8192] (the callers name their own option and bounds in the message).
bool parseFrameSize(const std::string& text, int min_width, int min_height, int& width, int& height);

}  // namespace dyn
