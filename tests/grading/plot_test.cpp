// Tests for grading/plot: the PNG has the asked size, each series' colour lands where its data
// are, bands are filled, NaN gaps stay empty, spikes survive thinning, the same spec gives the
// same bytes (PNG, SVG, PDF), and bad input throws naming the path.
#include "grading/plot.h"

#include <doctest/doctest.h>

#include "tests/test_files.h"
#include <stb/stb_image.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

using namespace dyn;
namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string& name) { return dyn::test::scratchDir("dynlab_plot_test", name); }
using dyn::test::readBytes;

std::vector<double> linspace(int n, double a, double b) {
  std::vector<double> v(n);
  for (int i = 0; i < n; ++i) v[i] = a + (b - a) * i / (n - 1);
  return v;
}

// A decoded RGB picture.
struct Image {
  int w = 0, h = 0;
  std::vector<unsigned char> rgb;
  explicit Image(const fs::path& p) {
    int n = 0;
    unsigned char* data = stbi_load(p.string().c_str(), &w, &h, &n, 3);
    REQUIRE(data != nullptr);
    rgb.assign(data, data + static_cast<size_t>(w) * h * 3);
    stbi_image_free(data);
  }
  bool near(int x, int y, int r, int g, int b, int tol = 40) const {
    const unsigned char* p = &rgb[(static_cast<size_t>(y) * w + x) * 3];
    return std::abs(p[0] - r) <= tol && std::abs(p[1] - g) <= tol && std::abs(p[2] - b) <= tol;
  }
  // Pixels near a colour inside the box [x0, x1) × [y0, y1) given as fractions of the picture.
  int count(double x0, double x1, double y0, double y1, int r, int g, int b) const {
    int n = 0;
    for (int y = static_cast<int>(y0 * h); y < static_cast<int>(y1 * h); ++y)
      for (int x = static_cast<int>(x0 * w); x < static_cast<int>(x1 * w); ++x) n += near(x, y, r, g, b);
    return n;
  }
  // Light-grey pixels (band fill, with or without a grid line under it) in column x.
  int greyCount(int x) const {
    int n = 0;
    for (int y = 0; y < h; ++y) {
      const unsigned char* p = &rgb[(static_cast<size_t>(y) * w + x) * 3];
      n += p[0] >= 180 && p[0] <= 240 && p[0] == p[1] && p[1] == p[2];
    }
    return n;
  }
};

// Palette colours 0 and 1 (Okabe–Ito blue and vermillion).
constexpr int kBlue[3] = {0, 114, 178}, kVermillion[3] = {213, 94, 0};

// Series "a" high on the left half, low on the right; series "b" the other way round.
PlotSpec crossingSpec() {
  PlotSpec s;
  s.title = "Step test";
  s.xlabel = "t (s)";
  s.ylabel = "x (m)";
  const auto x = linspace(400, 0.0, 1.0);
  PlotSeries a{"", x, {}, PlotSeries::Style::Solid, 0}, b{"", x, {}, PlotSeries::Style::Dashed, 1};
  for (double t : x) a.y.push_back(t < 0.5 ? 1.0 : 0.0), b.y.push_back(t < 0.5 ? 0.0 : 1.0);
  s.series = {a, b};
  return s;
}

bool noTmpLeft(const fs::path& dir) {
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".tmp") return false;
  return true;
}

}  // namespace

TEST_CASE("the PNG has the requested size") {
  const fs::path dir = scratch("size");
  writePlot((dir / "a.png").string(), crossingSpec());
  writePlot((dir / "b.png").string(), crossingSpec(), 640, 360);
  const Image a(dir / "a.png"), b(dir / "b.png");
  CHECK(a.w == 800);
  CHECK(a.h == 450);
  CHECK(b.w == 640);
  CHECK(b.h == 360);
  CHECK(noTmpLeft(dir));
}

TEST_CASE("each series' colour appears where its data are") {
  const fs::path dir = scratch("where");
  writePlot((dir / "p.png").string(), crossingSpec());
  const Image img(dir / "p.png");
  // Quadrants, keeping clear of the middle where both lines jump.
  const auto quads = [&](const int* c) {
    return std::array<int, 4>{img.count(0.0, 0.4, 0.0, 0.45, c[0], c[1], c[2]),   // upper left
                              img.count(0.6, 1.0, 0.0, 0.45, c[0], c[1], c[2]),   // upper right
                              img.count(0.0, 0.4, 0.55, 1.0, c[0], c[1], c[2]),   // lower left
                              img.count(0.6, 1.0, 0.55, 1.0, c[0], c[1], c[2])};  // lower right
  };
  const auto a = quads(kBlue), b = quads(kVermillion);
  INFO("blue UL UR LL LR: " << a[0] << " " << a[1] << " " << a[2] << " " << a[3]);
  INFO("vermillion UL UR LL LR: " << b[0] << " " << b[1] << " " << b[2] << " " << b[3]);
  CHECK(a[0] > 200);
  CHECK(a[3] > 200);
  CHECK(a[1] == 0);
  CHECK(a[2] == 0);
  CHECK(b[1] > 100);  // dashed: fewer pixels
  CHECK(b[2] > 100);
  CHECK(b[0] == 0);
  CHECK(b[3] == 0);
}

TEST_CASE("a band is filled between lo and hi") {
  const fs::path dir = scratch("band");
  PlotSpec s;
  const auto x = linspace(50, 0.0, 1.0);
  s.series.push_back({"", x, std::vector<double>(x.size(), 0.0), PlotSeries::Style::Solid, 0});
  s.series.push_back({"", x, std::vector<double>(x.size(), 1.0), PlotSeries::Style::Solid, 0});
  writePlot((dir / "plain.png").string(), s);
  s.bands.push_back({"", x, std::vector<double>(x.size(), 0.3), std::vector<double>(x.size(), 0.6)});
  writePlot((dir / "band.png").string(), s);
  const Image plain(dir / "plain.png"), band(dir / "band.png");
  // In every sampled column the band is ≈ 27% of the frame in light grey; without it, grey only
  // comes from 1-pixel grid lines (a column may hit a vertical grid line, so take the minimum).
  int band_min = 1 << 30, plain_min = 1 << 30;
  for (double f : {0.3, 0.41, 0.52, 0.63, 0.74}) {
    band_min = std::min(band_min, band.greyCount(static_cast<int>(f * band.w)));
    plain_min = std::min(plain_min, plain.greyCount(static_cast<int>(f * plain.w)));
  }
  CHECK(band_min > 90);
  CHECK(plain_min < 20);
}

TEST_CASE("non-finite values split the line and never crash") {
  const fs::path dir = scratch("nan");
  PlotSpec s;
  const auto x = linspace(1000, 0.0, 1.0);
  PlotSeries gap{"with a gap", x, {}, PlotSeries::Style::Solid, 0};
  for (double t : x) gap.y.push_back(t > 0.3 && t < 0.8 ? NAN : std::sin(6 * t));
  gap.y[10] = INFINITY;
  gap.y[20] = -INFINITY;
  s.series.push_back(gap);
  s.series.push_back({"all NaN", {0.0, 0.5, 1.0}, {NAN, NAN, NAN}, PlotSeries::Style::Dashed, 1});
  s.vlines = {0.3, NAN};
  s.vline_label = "went unstable";
  REQUIRE_NOTHROW(writePlot((dir / "gap.png").string(), s));
  const Image img(dir / "gap.png");
  CHECK(img.count(0.0, 0.3, 0.0, 1.0, kBlue[0], kBlue[1], kBlue[2]) > 100);
  CHECK(img.count(0.45, 0.55, 0.0, 1.0, kBlue[0], kBlue[1], kBlue[2]) == 0);  // the NaN stretch stays empty

  // A run that is NaN from the first sample still gets a plot (its time axis, y in [-1, 1]).
  PlotSpec dead;
  dead.series.push_back({"x", {0.0, 1.0, 2.0}, {NAN, NAN, NAN}});
  CHECK_NOTHROW(writePlot((dir / "dead.png").string(), dead));
  CHECK(fs::file_size(dir / "dead.png") > 0);

  // Constant and huge values get a usable range.
  PlotSpec flat;
  flat.series.push_back({"flat", {0.0, 1.0}, {3.0, 3.0}});
  flat.series.push_back({"huge", {0.0, 1.0}, {1e300, -1e300}});
  CHECK_NOTHROW(writePlot((dir / "flat.png").string(), flat));
}

TEST_CASE("a one-sample spike survives thinning of a long series") {
  const fs::path dir = scratch("spike");
  PlotSpec s;
  const auto x = linspace(20000, 0.0, 1.0);
  std::vector<double> y(x.size(), 0.0);
  y[12345] = 1.0;
  s.series.push_back({"", x, y, PlotSeries::Style::Solid, 0});
  s.series.push_back({"", {0.0, 1.0}, {0.0, 0.0}, PlotSeries::Style::Solid, 6});  // black baseline
  writePlot((dir / "spike.png").string(), s);
  const Image img(dir / "spike.png");
  CHECK(img.count(0.0, 1.0, 0.0, 0.35, kBlue[0], kBlue[1], kBlue[2]) > 10);
}

TEST_CASE("the same spec gives the same bytes") {
  const fs::path dir = scratch("same");
  PlotSpec s = crossingSpec();
  s.series[0].label = "a";
  s.series[1].label = "b";
  s.bands.push_back({"band", linspace(10, 0, 1), std::vector<double>(10, 0.4), std::vector<double>(10, 0.6)});
  s.vlines = {0.5};
  s.vline_label = "marker";
  for (const char* ext : {".png", ".svg", ".pdf"}) {
    writePlot((dir / (std::string("one") + ext)).string(), s);
    writePlot((dir / (std::string("two") + ext)).string(), s);
    const std::string one = readBytes(dir / (std::string("one") + ext)), two = readBytes(dir / (std::string("two") + ext));
    CHECK_MESSAGE(one.size() > 1000, ext);
    CHECK_MESSAGE(one == two, ext);
  }
  CHECK(readBytes(dir / "one.png").substr(1, 3) == "PNG");
  CHECK(readBytes(dir / "one.pdf").substr(0, 5) == "%PDF-");
}

TEST_CASE("the SVG keeps the title as text") {
  const fs::path dir = scratch("svg");
  PlotSpec s = crossingSpec();
  s.title = "Slider tracking & force";
  writePlot((dir / "p.svg").string(), s);
  // PLplot writes each character as a numeric reference (&#x53;); decode them.
  const std::string raw = readBytes(dir / "p.svg");
  const std::string text = test::svgText(raw);
  CHECK(text.find("Slider tracking & force") != std::string::npos);
  CHECK(raw.find("width=\"800px\"") != std::string::npos);
}

TEST_CASE("bad input throws naming the path") {
  const fs::path dir = scratch("bad");
  const auto message = [](const std::string& path, const PlotSpec& s) {
    try {
      writePlot(path, s);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("(no exception)");
  };
  const PlotSpec ok = crossingSpec();
  for (const std::string& p : {(dir / "plot.gif").string(), (dir / "plot").string(),
                              (dir / "no" / "such" / "dir" / "plot.png").string()}) {
    const std::string m = message(p, ok);
    INFO(m);
    CHECK(m.find(p) != std::string::npos);
  }

  PlotSpec mismatched = ok;
  mismatched.series[0].y.pop_back();
  CHECK(message((dir / "m.png").string(), mismatched).find("m.png") != std::string::npos);
  PlotSpec empty_series = ok;
  empty_series.series[1].x.clear();
  empty_series.series[1].y.clear();
  CHECK(message((dir / "e.png").string(), empty_series).find("e.png") != std::string::npos);
  CHECK(message((dir / "nothing.png").string(), PlotSpec{}).find("nothing.png") != std::string::npos);
  PlotSpec bad_band = ok;
  bad_band.bands.push_back({"b", {0, 1}, {0}, {1, 2}});
  CHECK(message((dir / "b.png").string(), bad_band).find("b.png") != std::string::npos);

  // A failure leaves neither the file nor its .tmp behind.
  CHECK(!fs::exists(dir / "m.png"));
  CHECK(noTmpLeft(dir));
}

namespace {

// Pixels near colour c inside a box given in pixels.
int countIn(const Image& img, const PlotBox& box, const int* c, int tol = 40) {
  int n = 0;
  for (int y = std::max(0, int(box.y0) + 2); y < std::min(img.h, int(box.y1) - 2); ++y)
    for (int x = std::max(0, int(box.x0) + 2); x < std::min(img.w, int(box.x1) - 2); ++x) n += img.near(x, y, c[0], c[1], c[2], tol);
  return n;
}

// Hatching pixels: a light bluish grey (the span colour, or its anti-aliased blend with white).
int hatchIn(const Image& img, const PlotBox& box) {
  int n = 0;
  for (int y = int(box.y0); y < int(box.y1); ++y)
    for (int x = int(box.x0); x < int(box.x1); ++x) {
      const unsigned char* p = &img.rgb[(static_cast<size_t>(y) * img.w + x) * 3];
      n += p[0] >= 150 && p[0] < 245 && std::abs(p[0] - p[1]) <= 3 && p[2] - p[0] >= 5;
    }
  return n;
}

// A fraction [a, b] of a box's width (all of its height).
PlotBox part(const PlotBox& f, double a, double b) { return {f.x0 + a * (f.x1 - f.x0), f.y0, f.x0 + b * (f.x1 - f.x0), f.y1}; }

constexpr int kGreen[3] = {0, 158, 115};

}  // namespace

TEST_CASE("a noisy series is drawn faint, under the smooth response, its reference and band") {
  const fs::path dir = scratch("faint");
  const auto x = linspace(4000, 0.0, 4.0);
  PlotSeries response{"f_Ty", x, {}, PlotSeries::Style::Solid, 0}, reference{"f_des (reference)", x, {}, PlotSeries::Style::Dashed, 1};
  for (double t : x) response.y.push_back(-5 + 0.2 * std::sin(3 * t)), reference.y.push_back(-5);
  // A measurement of the response with noise, listed last (drawn last, over everything, before).
  PlotSeries meas{"f_meas", x, response.y, PlotSeries::Style::Solid, 2};
  std::srand(7);
  for (double& v : meas.y) v += 1.5 * (std::rand() / double(RAND_MAX) - 0.5);
  // The same plot without it, on the same axes (two isolated samples hold the range).
  PlotSeries range{"", x, std::vector<double>(x.size(), NAN), PlotSeries::Style::Solid, 2};
  range.y[0] = *std::min_element(meas.y.begin(), meas.y.end());
  range.y[2] = *std::max_element(meas.y.begin(), meas.y.end());
  PlotSpec s;
  s.bands.push_back({"tolerance", x, std::vector<double>(x.size(), -5.25), std::vector<double>(x.size(), -4.75)});
  s.series = {reference, response, meas};
  const PlotLayout b = writePlot((dir / "noisy.png").string(), s, 640, 360);
  s.series.back() = range;
  const PlotLayout a = writePlot((dir / "clean.png").string(), s, 640, 360);
  const Image clean(dir / "clean.png"), with_noise(dir / "noisy.png");
  // The response and the reference keep most of their pixels (the noise under them is thin and
  // translucent), and the noise is there.
  const int blue_clean = countIn(clean, a.frame, kBlue), blue_noisy = countIn(with_noise, b.frame, kBlue);
  const int ref_clean = countIn(clean, a.frame, kVermillion), ref_noisy = countIn(with_noise, b.frame, kVermillion);
  INFO("response pixels " << blue_clean << " → " << blue_noisy << ", reference " << ref_clean << " → " << ref_noisy);
  CHECK(blue_noisy > 0.8 * blue_clean);
  CHECK(ref_noisy > 0.8 * ref_clean);
  CHECK(countIn(with_noise, b.frame, kGreen, 120) > 1000);
  // The noise is not drawn at full strength: no pixel of the frame is the pure palette green.
  CHECK(countIn(with_noise, b.frame, kGreen, 6) == 0);
}

TEST_CASE("the legend never covers the data: right of the frame, or below it when wide") {
  const fs::path dir = scratch("legend");
  const auto x = linspace(400, 0.0, 1.0);
  for (const std::string label : {"x", "a rather long legend entry that cannot fit beside the frame of the plot"})
    for (auto [w, h] : {std::pair{800, 450}, std::pair{640, 360}, std::pair{1920, 1080}, std::pair{300, 300}}) {
      CAPTURE(label);
      CAPTURE(w);
      PlotSpec s;
      // Data filling the whole frame: any legend inside it would cover some.
      PlotSeries fill{label, x, {}, PlotSeries::Style::Solid, 0};
      for (double t : x) fill.y.push_back(std::sin(200 * t));
      s.series = {fill, {label + " 2", x, std::vector<double>(x.size(), 0.0), PlotSeries::Style::Dashed, 1}};
      s.spans.push_back({"not scored", 0.0, 0.1});
      s.bands.push_back({"band", x, std::vector<double>(x.size(), -0.1), std::vector<double>(x.size(), 0.1)});
      s.title = "legend";
      s.xlabel = "t (s)";
      const PlotLayout l = writePlot((dir / "p.png").string(), s, w, h);
      REQUIRE_FALSE(l.legend.empty());
      CHECK_FALSE(l.legend.overlaps(l.frame));
      CHECK(l.legend.x1 <= w + 1);
      CHECK(l.legend.y1 <= h + 1);
      CHECK(l.legend.x0 >= -1);
      // Short labels sit right of a frame of a usual size, long ones below it.
      if (label == "x" && w >= 640) CHECK(l.legend.x0 >= l.frame.x1);
      else CHECK(l.legend.y0 >= l.frame.y1);
    }
}

TEST_CASE("log y: automatic for positive data over decades, so a 1e-14 residual beside 1e-7 is visible") {
  const fs::path dir = scratch("log");
  const auto x = linspace(1000, 0.0, 4.0);
  PlotSpec s;
  PlotSeries hand{"hand", x, {}, PlotSeries::Style::Solid, 0}, bullet{"Bullet", x, {}, PlotSeries::Style::Dashed, 1};
  for (double t : x) hand.y.push_back(1e-14 * (1.5 + std::sin(5 * t))), bullet.y.push_back(1e-7 * (1.5 + std::sin(3 * t)));
  hand.y[0] = 0.0;  // a zero is left out of a log plot, not an error
  s.series = {hand, bullet};
  s.y_scale = YScale::Auto;
  const PlotLayout log = writePlot((dir / "auto.png").string(), s);
  s.y_scale = YScale::Linear;
  const PlotLayout lin = writePlot((dir / "linear.png").string(), s);
  CHECK(log.log_y);
  CHECK_FALSE(lin.log_y);
  // Where the hand residual's pixels are: well above the frame's bottom on the log axis, on it
  // (indistinguishable from zero) on the linear one.
  const auto lowest = [](const Image& img, const PlotBox& f) {
    double sum = 0;
    int n = 0;
    for (int y = int(f.y0) + 2; y < int(f.y1) - 1; ++y)
      for (int x = int(f.x0) + 2; x < int(f.x1) - 2; ++x)
        if (img.near(x, y, kBlue[0], kBlue[1], kBlue[2])) sum += y, ++n;
    return n ? (f.y1 - sum / n) / (f.y1 - f.y0) : -1.0;  // mean height above the bottom, in frames
  };
  CHECK(lowest(Image(dir / "auto.png"), log.frame) > 0.08);
  CHECK(lowest(Image(dir / "linear.png"), lin.frame) < 0.06);
  // Data below zero stay linear under Auto; Log is there when asked.
  s.series[0].y[5] = -1e-14;
  s.y_scale = YScale::Auto;
  CHECK_FALSE(writePlot((dir / "neg.png").string(), s).log_y);
  s.y_scale = YScale::Log;
  CHECK(writePlot((dir / "forced.png").string(), s).log_y);
}

TEST_CASE("a span is hatched over its stretch of x, and nowhere else") {
  const fs::path dir = scratch("span");
  PlotSpec s = crossingSpec();
  s.spans.push_back({"not scored", 0.0, 0.25});
  const PlotLayout l = writePlot((dir / "span.png").string(), s);
  s.spans.clear();
  writePlot((dir / "plain.png").string(), s);
  const Image span(dir / "span.png"), plain(dir / "plain.png");
  CHECK(hatchIn(span, part(l.frame, 0.02, 0.23)) > 200);
  CHECK(hatchIn(span, part(l.frame, 0.3, 0.98)) == 0);
  CHECK(hatchIn(plain, part(l.frame, 0.02, 0.23)) == 0);
}

TEST_CASE("a PDF's page and a PNG's picture are the size asked for") {
  const fs::path dir = scratch("page");
  writePlot((dir / "p.pdf").string(), crossingSpec(), 1280, 720);
  const std::string pdf = readBytes(dir / "p.pdf");
  CHECK(pdf.find("/MediaBox [ 0 0 1280 720 ]") != std::string::npos);
  writePlot((dir / "p.png").string(), crossingSpec(), 1280, 720);
  const Image png(dir / "p.png");
  CHECK(png.w == 1280);
  CHECK(png.h == 720);
}
