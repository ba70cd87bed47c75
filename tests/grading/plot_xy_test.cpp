// Tests for grading/plot's x–y (parametric) plots: equalAspect widens the right range about its
// middle; writePlot's frame and data window have one scale on both axes (any page shape, legend
// right or below), so a circle is drawn round (and is not without equal_aspect); x gets headroom;
// spans, vertical markers and log y do not apply; the same spec gives the same bytes.
#include <doctest/doctest.h>
#include <stb/stb_image.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "grading/plot.h"
#include "tests/test_files.h"

using namespace dyn;
namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string& name) { return dyn::test::scratchDir("dynlab_plot_xy_test", name); }

// A circle of radius r about (cx, cy), n samples, as the hand run (blue, solid).
PlotSeries circle(double cx, double cy, double r, const std::string& label = "y vs x (hand)", int n = 2000) {
  PlotSeries s{label, {}, {}, PlotSeries::Style::Solid, 0};
  for (int i = 0; i <= n; ++i) {
    const double a = 2 * M_PI * i / n;
    s.x.push_back(cx + r * std::cos(a)), s.y.push_back(cy + r * std::sin(a));
  }
  return s;
}

PlotSpec pathSpec(bool equal) {
  PlotSpec s;
  s.title = "path in the plane";
  s.xlabel = "x (m)";
  s.ylabel = "y (m)";
  s.parametric = true;
  s.equal_aspect = equal;
  s.series = {circle(0.3, 1.0, 1.0)};
  return s;
}

// Data per pixel along x and along y of a layout.
std::pair<double, double> scales(const PlotLayout& l) {
  return {(l.x_hi - l.x_lo) / (l.frame.x1 - l.frame.x0), (l.y_hi - l.y_lo) / (l.frame.y1 - l.frame.y0)};
}

// The pixel box of the palette blue (the circle) inside a frame.
struct Box {
  int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;
};
Box blueBox(const fs::path& png, const PlotBox& f) {
  int w = 0, h = 0, n = 0;
  unsigned char* d = stbi_load(png.string().c_str(), &w, &h, &n, 3);
  REQUIRE(d != nullptr);
  Box b;
  for (int y = int(f.y0) + 1; y < int(f.y1); ++y)
    for (int x = int(f.x0) + 1; x < int(f.x1); ++x) {
      const unsigned char* p = d + (std::size_t(y) * w + x) * 3;
      if (std::abs(p[0] - 0) < 40 && std::abs(p[1] - 114) < 40 && std::abs(p[2] - 178) < 40)
        b.x0 = std::min(b.x0, x), b.y0 = std::min(b.y0, y), b.x1 = std::max(b.x1, x), b.y1 = std::max(b.y1, y);
    }
  stbi_image_free(d);
  return b;
}

}  // namespace

TEST_CASE("equalAspect widens the range that is stretched, about its middle, and keeps the other") {
  // A 2 × 1 frame showing x in [0, 1] and y in [0, 1]: x has twice y's length per unit; x widens to 2.
  PlotWindow w = equalAspect({0, 1, 0, 1}, 2, 1);
  CHECK(w.x0 == doctest::Approx(-0.5));
  CHECK(w.x1 == doctest::Approx(1.5));
  CHECK(w.y0 == 0);
  CHECK(w.y1 == 1);
  // A tall frame: y widens about its middle (5).
  w = equalAspect({-1, 1, 4, 6}, 1, 3);
  CHECK(w.x0 == -1);
  CHECK(w.x1 == 1);
  CHECK(w.y0 == doctest::Approx(2));
  CHECK(w.y1 == doctest::Approx(8));
  // Wide data in a square frame: y widens, whatever the offset.
  w = equalAspect({100, 110, -0.5, 0.5}, 300, 300);
  CHECK(w.y1 - w.y0 == doctest::Approx(10));
  CHECK(0.5 * (w.y0 + w.y1) == doctest::Approx(0).epsilon(1e-12));
  // Already equal: unchanged.
  w = equalAspect({0, 4, 0, 3}, 400, 300);
  CHECK(w.x0 == 0);
  CHECK(w.x1 == 4);
  CHECK(w.y0 == 0);
  CHECK(w.y1 == 3);
}

TEST_CASE("an equal-aspect plot has one scale on both axes: any page, legend right or below, any font") {
  const fs::path dir = scratch("scale");
  for (auto [w, h] : {std::pair{800, 450}, std::pair{640, 360}, std::pair{450, 800}, std::pair{1280, 720}})
    for (const std::string label : {"y vs x (hand)", "a legend entry far too long to sit beside the frame of this plot"})
      for (double font : {1.0, 2.0}) {
        CAPTURE(w);
        CAPTURE(h);
        CAPTURE(label);
        CAPTURE(font);
        PlotSpec s = pathSpec(true);
        s.series[0].label = label;
        s.font_scale = font;
        const PlotLayout l = writePlot((dir / "p.png").string(), s, w, h);
        const auto [sx, sy] = scales(l);
        CHECK(sx == doctest::Approx(sy).epsilon(1e-9));
        // The whole circle is in the window, with room to spare on the narrower side.
        CHECK(l.x_lo < 0.3 - 1.0);
        CHECK(l.x_hi > 0.3 + 1.0);
        CHECK(l.y_lo < 0.0);
        CHECK(l.y_hi > 2.0);
        CHECK_FALSE(l.legend.overlaps(l.frame));
        CHECK(l.frame.x1 - l.frame.x0 > 0.3 * w);  // the frame is not squeezed away
      }
  // Without equal_aspect the frame keeps its shape and the scales differ.
  const PlotLayout free = writePlot((dir / "free.png").string(), pathSpec(false), 800, 450);
  const auto [fx, fy] = scales(free);
  CHECK(std::abs(fx / fy - 1) > 0.2);
}

TEST_CASE("a circle is drawn round with equal_aspect, and squashed without it") {
  const fs::path dir = scratch("round");
  const PlotLayout l = writePlot((dir / "equal.png").string(), pathSpec(true), 800, 450);
  const Box eq = blueBox(dir / "equal.png", l.frame);
  const double ew = eq.x1 - eq.x0, eh = eq.y1 - eq.y0;
  INFO("equal: " << ew << " x " << eh << " px");
  REQUIRE(eh > 200);
  CHECK(std::abs(ew - eh) <= 3);
  const PlotLayout f = writePlot((dir / "free.png").string(), pathSpec(false), 800, 450);
  const Box fr = blueBox(dir / "free.png", f.frame);
  INFO("free: " << fr.x1 - fr.x0 << " x " << fr.y1 - fr.y0 << " px");
  CHECK(double(fr.x1 - fr.x0) > 1.3 * (fr.y1 - fr.y0));
}

TEST_CASE("an x–y plot: x gets headroom, no hatched span, no time marker, linear y; same bytes twice") {
  const fs::path dir = scratch("xy");
  PlotSpec s = pathSpec(false);
  s.series.push_back({"y_d vs x_d (reference)", {-0.7, 1.3}, {0.0, 2.0}, PlotSeries::Style::Dashed, 1});
  s.spans.push_back({"not scored", -0.7, 0.5});  // a time window: meaningless against x
  s.vlines = {0.0};
  s.vline_label = "run stopped";
  s.y_scale = YScale::Log;
  const PlotLayout l = writePlot((dir / "p.png").string(), s);
  CHECK_FALSE(l.log_y);
  CHECK(l.x_lo < -0.7 - 0.05);
  CHECK(l.x_hi > 1.3 + 0.05);
  // The hatching's colour appears nowhere in the frame; the legend has the two curves only.
  int w = 0, h = 0, n = 0;
  unsigned char* d = stbi_load((dir / "p.png").string().c_str(), &w, &h, &n, 3);
  REQUIRE(d != nullptr);
  int hatch = 0;
  for (int y = int(l.frame.y0) + 2; y < int(l.frame.y1) - 2; ++y)
    for (int x = int(l.frame.x0) + 2; x < int(l.frame.x1) - 2; ++x) {
      const unsigned char* p = d + (std::size_t(y) * w + x) * 3;
      hatch += std::abs(p[0] - 175) < 6 && std::abs(p[1] - 175) < 6 && std::abs(p[2] - 190) < 6;
    }
  stbi_image_free(d);
  CHECK(hatch == 0);
  writePlot((dir / "p.svg").string(), s);
  const std::string svg = test::svgText(dyn::test::readBytes(dir / "p.svg"));
  CHECK(svg.find("y_d vs x_d (reference)") != std::string::npos);
  CHECK(svg.find("run stopped") == std::string::npos);
  CHECK(svg.find("not scored") == std::string::npos);
  // Deterministic, every format, equal aspect on.
  s.equal_aspect = true;
  for (const char* ext : {".png", ".svg", ".pdf"}) {
    writePlot((dir / (std::string("one") + ext)).string(), s);
    writePlot((dir / (std::string("two") + ext)).string(), s);
    const std::string one = dyn::test::readBytes(dir / (std::string("one") + ext));
    CHECK_MESSAGE(one.size() > 1000, ext);
    CHECK_MESSAGE(one == dyn::test::readBytes(dir / (std::string("two") + ext)), ext);
  }
}
