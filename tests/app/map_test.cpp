// dynlab map end to end: a small grid through the real binary writes a valid picture (PNG, SVG,
// PDF; byte-identical on a rerun and whatever the thread count); the screening reproduces the
// lecture — the proportional force law is unstable under delay once k_pf ≥ 1, the integral law
// beyond its delay margin π/(2 k_if) —; bad axis specs are one line and exit 2; nothing of the
// picture (labels, legend, colour bar) reaches the page's edge, at any page size.
#include <doctest/doctest.h>
#include <stb_image.h>

#include <cmath>

#include "app/cli/figures/map_plot.h"
#include "tests/app/cli_run.h"
#include "tests/app/png_ink.h"

using namespace dyn::test::cli;
using dyn::test::Ink;
using dyn::test::inkOf;

namespace {

std::string magicOf(const fs::path& p) { return readFile(p).substr(0, 8); }

// A 9 × 7 map with the grasp's long axis label, stable on the left and unstable on the right.
dyn::app::MapPicture longLabelMap(bool values) {
  dyn::app::MapPicture m;
  m.title = "grasp: simulated, 4 s per point";
  m.xlabel = "f_squeeze: internal-force set point: how hard each finger squeezes (N)";
  m.ylabel = "mu: friction coefficient at the contacts";
  for (int i = 0; i < 9; ++i) m.xs.push_back(1 + 0.625 * i);
  for (int j = 0; j < 7; ++j) m.ys.push_back(0.2 + j * 0.8 / 6);
  for (int j = 0; j < 7; ++j)
    for (int i = 0; i < 9; ++i) {
      m.stable.push_back(i < 2 + j / 2);
      m.boundary.push_back(2.5 + j / 2.0 - i);
      if (values) m.value.push_back(0.1 * (i + j));
    }
  m.value_label = values ? "cone_margin_min: the worst friction-cone margin over the run (N)" : "";
  m.stable_label = "stable (run completes)";
  m.unstable_label = "unstable (watchdog)";
  m.boundary_label = "screening boundary";
  return m;
}

}  // namespace

TEST_CASE("a 5 × 4 screening map: PNG, SVG and PDF, the same bytes on a rerun") {
  TempDir dir("map_files");
  const std::vector<std::string> grid = {"map", "slider_crank", "--x", "kp_f=0:2:5", "--y", "delay=0:0.04:4"};
  for (const std::string ext : {"png", "svg", "pdf"}) {
    INFO(ext);
    const Result a = dynlab(dir, cat(grid, {"--out", "a." + ext}));
    REQUIRE_MESSAGE(a.code == 0, a.err);
    REQUIRE(dynlab(dir, cat(grid, {"--out", "b." + ext})).code == 0);
    const std::string bytes = readFile(dir / ("a." + ext));
    if (ext == "png") CHECK(magicOf(dir / "a.png") == "\x89PNG\r\n\x1a\n");
    if (ext == "svg") CHECK(bytes.find("<svg") != std::string::npos);
    if (ext == "pdf") CHECK(bytes.rfind("%PDF-", 0) == 0);
    CHECK(bytes == readFile(dir / ("b." + ext)));
    CHECK_FALSE(fs::exists(dir / ("a." + ext + ".tmp")));
  }
}

TEST_CASE("--sim: the simulated map is the same with one thread or two") {
  TempDir dir("map_sim");
  const std::vector<std::string> grid = {"map",   "slider_crank", "--x", "kp_f=0.5:1.5:3", "--y",  "delay=0.01:0.03:2",
                                         "--sim", "--duration",   "0.4", "--metric",       "f_rms"};
  const Result one = dynlab(dir, cat(grid, {"--jobs", "1", "--out", "one.png", "--data", "one.csv"}));
  REQUIRE_MESSAGE(one.code == 0, one.err);
  REQUIRE(dynlab(dir, cat(grid, {"--jobs", "2", "--out", "two.png", "--data", "two.csv"})).code == 0);
  CHECK(readFile(dir / "one.csv") == readFile(dir / "two.csv"));
  CHECK(readFile(dir / "one.png") == readFile(dir / "two.png"));
  // Every point was simulated (sim_stable 0 or 1, never -1).
  const Csv csv = readCsv(dir / "one.csv");
  REQUIRE(csv.rows.size() == 6);
  for (std::size_t r = 0; r < csv.rows.size(); ++r) CHECK((csv.at(r, "sim_stable") == 0 || csv.at(r, "sim_stable") == 1));
}

TEST_CASE("screening: proportional law unstable under delay once k_pf ≥ 1, stable below") {
  TempDir dir("map_p");
  const Result r =
      dynlab(dir, {"map", "slider_crank", "--x", "kp_f=0:2:9", "--y", "delay=0.005:0.05:4", "--out", "m.png", "--data", "m.csv"});
  REQUIRE_MESSAGE(r.code == 0, r.err);
  const Csv csv = readCsv(dir / "m.csv");
  REQUIRE(csv.rows.size() == 36);
  for (std::size_t i = 0; i < csv.rows.size(); ++i) {
    const double k = csv.at(i, "kp_f");
    INFO("kp_f = ", k, ", delay = ", csv.at(i, "delay"));
    CHECK(csv.at(i, "screen_stable") == (k < 1 ? 1 : 0));
    CHECK(csv.at(i, "sim_stable") == -1);  // not simulated without --sim
  }
}

TEST_CASE("screening: integral law unstable beyond the delay margin π/(2 k_if)") {
  // As it runs (sampled every dt = 1 ms, the sum updated after each reading): L(z) = k dt z^{−(N−1)}/(z − 1),
  // a loop delay of N dt − dt/2 and a margin π/(2ω_c), ω_c = (2/dt) asin(k dt/2) (≈ π/(2 k_if)).
  TempDir dir("map_i");
  const Result r = dynlab(
      dir, {"map", "slider_crank", "--x", "ki_f=10:200:20", "--y", "delay=0.005:0.05:10", "--out", "m.svg", "--data", "m.csv"});
  REQUIRE_MESSAGE(r.code == 0, r.err);
  const Csv csv = readCsv(dir / "m.csv");
  REQUIRE(csv.rows.size() == 200);
  int checked = 0;
  const double dt = 1e-3;
  for (std::size_t i = 0; i < csv.rows.size(); ++i) {
    const double k = csv.at(i, "ki_f"), delay = csv.at(i, "delay") - dt / 2, margin = M_PI / (4 / dt * std::asin(k * dt / 2));
    INFO("ki_f = ", k, ", loop delay = ", delay, ", margin = ", margin);
    if (std::abs(delay - margin) < 1e-3 * margin) continue;  // on the boundary
    CHECK(csv.at(i, "screen_stable") == (delay < margin ? 1 : 0));
    // The drawn boundary field: delay margin − delay of the force loop, where it binds (the motion
    // loop's own margin caps it far from the boundary).
    if (margin - delay < 0.04) CHECK(csv.at(i, "screen_margin") == doctest::Approx(margin - delay).epsilon(1e-3));
    CHECK(csv.at(i, "screen_margin") <= margin - delay + 1e-9);
    ++checked;
  }
  CHECK(checked > 150);
}

TEST_CASE("bad axis specs and metrics: one line, exit 2, nothing written") {
  TempDir dir("map_bad");
  const fs::path out = dir / "m.png";
  const std::vector<std::string> y = {"--y", "delay=0:0.05:4", "--out", "m.png"};
  checkBadInput(dir, cat({"map", "slider_crank", "--x", "kq_f=0:2:5"}, y), {"--x", "kq_f"}, out);
  checkBadInput(dir, cat({"map", "slider_crank", "--x", "kp_f=0:2"}, y), {"--x", "kp_f=0:2"}, out);
  checkBadInput(dir, cat({"map", "slider_crank", "--x", "kp_f=0:2:5:1"}, y), {"--x", "kp_f=0:2:5:1"}, out);
  checkBadInput(dir, cat({"map", "slider_crank", "--x", "kp_f=zero:2:5"}, y), {"--x", "kp_f=zero:2:5"}, out);
  checkBadInput(dir, cat({"map", "slider_crank", "--x", "kp_f=0:2:201"}, y), {"--x", "201"}, out);
  checkBadInput(dir, cat({"map", "slider_crank", "--x", "kp_f=0:2:1"}, y), {"--x", "1"}, out);
  checkBadInput(dir, cat({"map", "slider_crank", "--x", "kp_f=0:20:5"}, y), {"--x", "20", "kp_f"}, out);
  checkBadInput(dir, {"map", "slider_crank", "--x", "kp_f=0:2:5", "--y", "/controller/nope=0:1:3", "--out", "m.png"},
                {"--y", "/controller/nope"}, out);
  checkBadInput(dir, cat({"map", "slider_crank", "--x", "kp_f=0:2:5", "--metric", "f_rms"}, y), {"--metric", "f_rms", "--sim"},
                out);
  checkBadInput(dir, cat({"map", "slider_crank", "--x", "kp_f=0:2:5", "--metric", "nope"}, y), {"--metric", "nope"}, out);
  checkBadInput(dir, cat({"map", "no_lab", "--x", "kp_f=0:2:5"}, y), {"no_lab"}, out);
  checkBadInput(dir, {"map", "slider_crank", "--x", "kp_f=0:2:5", "--y", "delay=0:0.05:4", "--out", "m.gif"}, {"--out", "m.gif"},
                dir / "m.gif");
}

TEST_CASE("nothing of a map reaches the page's edge: long labels, legend and colour bar, at every size") {
  TempDir dir("map_edges");
  for (const bool values : {false, true})
    for (const auto& [w, h] : {std::pair{640, 480}, std::pair{900, 600}, std::pair{1920, 1080}}) {
      const fs::path png = dir / ("map_" + std::to_string(values) + "_" + std::to_string(w) + ".png");
      dyn::app::writeMapPicture(png.string(), longLabelMap(values), w, h);
      const Ink ink = inkOf(png);
      INFO(png.filename().string(), ": ink from (", ink.x0, ", ", ink.y0, ") to (", ink.x1, ", ", ink.y1, ")");
      CHECK(ink.width == w);
      CHECK(ink.height == h);
      CHECK_FALSE(ink.at_edge);
      // ... and the picture still fills the page (nothing shrunk away to stay clear of the edges).
      CHECK(ink.x1 - ink.x0 > 0.9 * w);
      CHECK(ink.y1 - ink.y0 > 0.85 * h);
    }
}

TEST_CASE("dynlab map: the grasp's long axis label stays on the page") {
  TempDir dir("map_cli_edges");
  const Result r = dynlab(dir, {"map", "grasp", "--x", "f_squeeze=1:6:6", "--y", "mu=0.2:1:5", "--out", "m.png"});
  REQUIRE_MESSAGE(r.code == 0, r.err);
  CHECK_FALSE(inkOf(dir / "m.png").at_edge);
}
