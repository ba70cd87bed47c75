// The overlay's font draws Greek letters, math operators, arrows and sub/superscripts as themselves:
// each renders unlike "?" and U+FFFD (Dear ImGui's stand-ins for a glyph its font lacks) and unlike
// the others; a missing or broken font file is one line naming the file and the package.
#include <doctest/doctest.h>

#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "tests/render/test_scene.h"

using namespace dyn;

namespace {

// A panel whose only varying text is one value.
Overlay panelWith(const std::string& value) {
  Overlay overlay;
  overlay.title = "glyphs";
  overlay.lines = {{"x", value}};
  return overlay;
}

// Sets an environment variable for one scope.
struct ScopedEnv {
  std::string name;
  ScopedEnv(const std::string& n, const std::string& value) : name(n) { setenv(n.c_str(), value.c_str(), 1); }
  ~ScopedEnv() { unsetenv(name.c_str()); }
};

std::string overlayError(const Scene& scene) {
  auto context = makeOffscreenContext(320, 240);
  Renderer renderer(*context);
  const Overlay overlay = panelWith("θ");
  try {
    renderer.render(scene, &overlay);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("Greek letters, math operators, arrows and sub/superscripts are drawn as themselves, not as \"?\"") {
  auto context = makeOffscreenContext(320, 240);
  Renderer renderer(*context);
  const Scene scene = test::redCapsuleScene();
  auto frame = [&](const std::string& value) {
    const Overlay overlay = panelWith(value);
    return renderer.render(scene, &overlay).rgba;
  };
  // A glyph the font lacks is drawn as its fallback: U+FFFD when the font has it, else "?".
  const auto unknown = frame("?"), replacement = frame("\uFFFD"), blank = frame(" ");
  REQUIRE(unknown != blank);
  const auto missing = frame("\u4E2D");  // 中: in no font of this atlas
  CHECK((missing == replacement || missing == unknown));
  const std::vector<std::string> glyphs = {"θ", "τ", "ω", "Δ", "μ", "φ", "−", "·", "²", "≤", "≥", "√", "∫",
                                           "→", "₁", "ᵀ", "±", "∂", "≈", "…", "⁻"};
  std::vector<std::pair<std::vector<std::uint8_t>, std::string>> seen;  // each glyph's frame
  for (const std::string& g : glyphs) {
    INFO("glyph ", g);
    const auto image = frame(g);
    CHECK(image != unknown);  // the font has it
    CHECK(image != replacement);
    CHECK(image != blank);    // and it leaves ink
    for (const auto& [other, name] : seen) CHECK_MESSAGE(image != other, g << " is drawn like " << name);
    seen.emplace_back(image, g);
  }
  // A line of them is as wide as its glyphs, with no "?" in between: unlike the same line of "?".
  CHECK(frame("θ τ −") != frame("? ? ?"));
}

TEST_CASE("a missing or broken overlay font is one line naming the file and the package") {
  const Scene scene = test::redCapsuleScene();
  {
    const ScopedEnv env("DYNLAB_FONT", "/nonexistent/DejaVuSans.ttf");
    const std::string error = overlayError(scene);
    CHECK(error.find("/nonexistent/DejaVuSans.ttf") != std::string::npos);
    CHECK(error.find("fonts-dejavu-core") != std::string::npos);
    CHECK(error.find('\n') == std::string::npos);
  }
  {
    const std::string not_font = test::tempPath("not_a_font.ttf");
    std::ofstream(not_font) << "this is not a TrueType font, only some words in a file";
    const ScopedEnv env("DYNLAB_FONT", not_font);
    const std::string error = overlayError(scene);
    CHECK(error.find("not a TrueType font") != std::string::npos);
    CHECK(error.find('\n') == std::string::npos);
    std::filesystem::remove(not_font);
  }
  // The installed font again: the panel draws.
  CHECK(overlayError(scene).empty());
}
