// Plot titles through the real binary: a lab's own figure set (its long declared titles) keeps
// every title on the page at every --size (no ink at the page's edge, as the map's test checks,
// and the title's ink reaches the top), and titles name the lab as people do ("Impedance control"),
// not by its id.
#include <doctest/doctest.h>
#include <stb_image.h>

#include "tests/app/cli_run.h"

using namespace dyn::test::cli;

namespace {

// Where a PNG has ink (any pixel not white): its box, and whether any lies within `strip` pixels of
// an edge (a title cut off by the page).
struct Ink {
  int width = 0, height = 0, x0 = 0, y0 = 0, x1 = -1, y1 = -1;
  bool at_edge = false;
};
Ink inkOf(const fs::path& png, int strip = 2) {
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

std::vector<fs::path> plotsIn(const fs::path& dir, const std::string& ext) {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().filename().string().rfind("plot_", 0) == 0 && e.path().extension() == ext) out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

TEST_CASE("every title of a lab's figure set stays on the page, at every size") {
  TempDir dir("figure_titles");
  // The stiff-wall scenario: the longest titles ("Impedance control (stiff_wall): push response: ...").
  for (const auto& [w, h] : {std::pair{320, 240}, std::pair{640, 480}, std::pair{800, 450}, std::pair{1920, 1080}}) {
    const std::string size = std::to_string(w) + "x" + std::to_string(h), out = "f_" + size;
    const Result r = dynlab(dir, "figure impedance --scenario stiff_wall --duration 0.3 --engine hand --format png --size " +
                                     size + " --out " + out);
    REQUIRE_MESSAGE(r.code == 0, r.err);
    const auto plots = plotsIn(dir / out, ".png");
    REQUIRE(plots.size() >= 5);
    for (const auto& png : plots) {
      const Ink ink = inkOf(png);
      INFO(size, " ", png.filename().string(), ": ink from (", ink.x0, ", ", ink.y0, ") to (", ink.x1, ", ", ink.y1, ")");
      CHECK(ink.width == w);
      CHECK_FALSE(ink.at_edge);
      CHECK(ink.y0 < 0.08 * h);          // the title is drawn, at the top
      CHECK(ink.x1 - ink.x0 > 0.8 * w);  // and nothing shrank away from the edges
    }
  }
}

TEST_CASE("plot titles use the lab's display name, not its id") {
  TempDir dir("figure_title_name");
  const Result r = dynlab(dir, "figure slider_crank --plot x_c --duration 0.3 --engine hand --format svg --out f");
  REQUIRE_MESSAGE(r.code == 0, r.err);
  const std::string svg = readFile(dir / "f/plot_x_c.svg");
  CHECK(svg.find("Slider crank") != std::string::npos);
  CHECK(svg.find("slider_crank") == std::string::npos);
  const Result s = dynlab(dir, "figure impedance --scenario stiff_wall --plot F_ext_x --duration 0.3 --engine hand --format svg --out g");
  REQUIRE_MESSAGE(s.code == 0, s.err);
  CHECK(readFile(dir / "g/plot_F_ext_x.svg").find("Impedance control (stiff_wall)") != std::string::npos);
}
