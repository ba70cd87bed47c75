// Plot titles through the real binary: a lab's own figure set (its long declared titles) keeps
// every title on the page at every --size (no ink at the page's edge, as the map's test checks,
// and the title's ink reaches the top), and titles name the lab as people do ("Impedance control"),
// not by its id. A figure's levels (the stiff wall) are drawn where the scenario puts them.
#include <doctest/doctest.h>
#include <stb_image.h>

#include <nlohmann/json.hpp>

#include "tests/app/cli_run.h"
#include "tests/app/png_ink.h"

using namespace dyn::test::cli;
using dyn::test::Ink;
using dyn::test::inkOf;
using nlohmann::json;

namespace {

// An SVG's text as written: PLplot's svg device writes every character as "&#xNN;".
std::string svgText(const std::string& svg) {
  std::string out;
  for (std::size_t i = 0; i < svg.size(); ++i) {
    if (svg.compare(i, 3, "&#x") == 0) {
      const std::size_t end = svg.find(';', i);
      const unsigned long c = std::stoul(svg.substr(i + 3, end - i - 3), nullptr, 16);
      if (c < 0x80) out += char(c);
      else if (c < 0x800) out += char(0xC0 | (c >> 6)), out += char(0x80 | (c & 0x3F));
      else out += char(0xE0 | (c >> 12)), out += char(0x80 | ((c >> 6) & 0x3F)), out += char(0x80 | (c & 0x3F));
      i = end;
    } else {
      out += svg[i];
    }
  }
  return out;
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
    const Result r = dynlab(dir, {"figure", "impedance", "--scenario", "stiff_wall", "--duration", "0.3", "--engine", "hand",
                                  "--format", "png", "--size", size, "--out", out});
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
  const Result r = dynlab(
      dir, {"figure", "slider_crank", "--plot", "x_c", "--duration", "0.3", "--engine", "hand", "--format", "svg", "--out", "f"});
  REQUIRE_MESSAGE(r.code == 0, r.err);
  const std::string svg = svgText(readFile(dir / "f/plot_x_c.svg"));
  CHECK(svg.find("Slider crank") != std::string::npos);
  CHECK(svg.find("slider_crank") == std::string::npos);
  const Result s = dynlab(dir, {"figure", "impedance", "--scenario", "stiff_wall", "--plot", "F_ext_x", "--duration", "0.3",
                                "--engine", "hand", "--format", "svg", "--out", "g"});
  REQUIRE_MESSAGE(s.code == 0, s.err);
  CHECK(svgText(readFile(dir / "g/plot_F_ext_x.svg")).find("Impedance control (stiff_wall)") != std::string::npos);
}

TEST_CASE("a figure's levels: the stiff wall is drawn where the scenario puts it, and only there") {
  TempDir dir("figure_levels");
  const std::vector<std::string> plot = {"--plot", "x, x_target", "--duration", "0.3", "--engine", "hand", "--format", "svg"};
  REQUIRE(dynlab(dir, cat(cat({"figure", "impedance", "--scenario", "stiff_wall"}, plot), {"--out", "w"})).code == 0);
  REQUIRE(dynlab(dir, cat(cat({"figure", "impedance"}, plot), {"--out", "n"})).code == 0);
  CHECK(svgText(readFile(dir / "w/plot_x+x_target.svg")).find("wall (the tip touches it)") != std::string::npos);
  CHECK(svgText(readFile(dir / "n/plot_x+x_target.svg")).find("wall") == std::string::npos);  // no wall in the nominal run
  // A level that points nowhere: one line naming the file and its JSON path, exit 2.
  json config = json::parse(readFile(fs::path(DYNLAB_SOURCE_DIR) / "labs/impedance/impedance.json"));
  config["figures"][0]["levels"][0]["at"] = "/environment/no_such";
  writeFile(dir / "bad.json", config.dump());
  checkBadInput(dir, {"figure", "impedance", "--config", "bad.json", "--out", "b"}, {"bad.json", "/figures/0/levels/0/at"},
                dir / "b");
}
