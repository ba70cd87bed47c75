// The overlay's and the window's font: DejaVu Sans read whole, checked, and handed to ImGui's atlas.
#include "render/fonts.h"

#include <imgui.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <vector>

namespace dyn {

std::string uiFontPath() {
  const char* env = std::getenv("DYNLAB_FONT");
  return env && *env ? env : "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
}

const unsigned short* uiGlyphRanges() {
  static const ImWchar ranges[] = {
      0x0020, 0x017F,  // Basic Latin, Latin-1 (°, ±, ·, ², µ), Latin Extended-A
      0x0300, 0x036F,  // combining marks (x + U+0307: ẋ)
      0x0370, 0x03FF,  // Greek
      0x1D00, 0x1DBF,  // phonetic extensions: the modifier letters ᵀ, ᵢ, ᵈ
      0x2000, 0x206F,  // general punctuation: – — ‖ ′ … •
      0x2070, 0x209F,  // superscripts and subscripts: ⁻¹ x₁ τₙ
      0x20D0, 0x20FF,  // combining marks for symbols (the vector arrow over a letter)
      0x2100, 0x218F,  // letterlike symbols and number forms: ℓ ℝ ½
      0x2190, 0x21FF,  // arrows
      0x2200, 0x22FF,  // mathematical operators: − ≤ ≥ √ ∫ ∂ ∇ ≈ ∞
      0x2300, 0x23FF,  // miscellaneous technical: ⌀ ⌈ ⌉
      0x25A0, 0x25FF,  // geometric shapes: ■ ● ▲
      0x27E8, 0x27E9,  // ⟨ ⟩
      0xFFFD, 0xFFFD,  // the replacement character
      0,
  };
  return ranges;
}

ImFont* addUiFont(ImFontAtlas& atlas, float pixels) {
  const std::string path = uiFontPath();
  const std::string where = "render: the overlay and window font " + path;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(where + " cannot be read (Debian: apt-get install fonts-dejavu-core; scripts/setup does)");
  const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  // A TrueType/OpenType file starts with its version tag: 0x00010000, "true" or "OTTO".
  static const char kTags[3][4] = {{0, 1, 0, 0}, {'t', 'r', 'u', 'e'}, {'O', 'T', 'T', 'O'}};
  bool tagged = false;
  for (const auto& tag : kTags) tagged = tagged || (bytes.size() > 12 && std::memcmp(bytes.data(), tag, 4) == 0);
  if (!tagged) throw std::runtime_error(where + " is not a TrueType font (expected DejaVuSans.ttf of fonts-dejavu-core)");
  // The atlas owns and frees the copy (ImGui's allocator).
  void* data = ImGui::MemAlloc(bytes.size());
  std::memcpy(data, bytes.data(), bytes.size());
  ImFontConfig config;
  config.OversampleH = 1;  // glyphs start on whole pixels: crisp stems, the same ones every time
  config.OversampleV = 1;
  config.PixelSnapH = true;
  std::snprintf(config.Name, sizeof config.Name, "DejaVu Sans, %.0f px", double(pixels));
  ImFont* font = atlas.AddFontFromMemoryTTF(data, int(bytes.size()), pixels, &config, uiGlyphRanges());
  if (!font || !atlas.Build()) throw std::runtime_error(where + " could not be rasterised (a damaged font file?)");
  return font;
}

}  // namespace dyn
