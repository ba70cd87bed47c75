// The one text font of every overlay panel and of the tuning window: DejaVu Sans (Debian package
// fonts-dejavu-core, which scripts/setup installs), rasterised by Dear ImGui's font atlas
// (stb_truetype), with Latin, Greek, sub- and superscripts, arrows and the math operators, so
// θ, τ, ω, Δ, "−", "·", "²", "≤", "√", "∫", "→", "x₁" and "Sᵀ" are drawn as themselves, not "?".
#pragma once
#include <string>

struct ImFont;       // Dear ImGui (global namespace)
struct ImFontAtlas;

namespace dyn {

// Where the font is read from: $DYNLAB_FONT when set (another TTF), else DejaVu Sans.
std::string uiFontPath();

// The code points the atlas holds (pairs of first, last; zero-terminated, as ImGui wants them).
const unsigned short* uiGlyphRanges();

// Adds the font at `pixels` high to the atlas (the first font added is ImGui's default).
// Throws std::runtime_error with one line naming the file and the package when it is missing
// or not a font.
ImFont* addUiFont(ImFontAtlas& atlas, float pixels);

}  // namespace dyn
