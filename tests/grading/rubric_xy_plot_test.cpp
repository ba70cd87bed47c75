// A rubric test's x–y plot through the grader: a slider-crank rubric whose force test plots f_Ty
// against f_Tx (the tip force's path) gets that plot in plots/, report.html and results.json,
// planned with x and y labels in the lab's units and equal scales, and no "not scored" hatching (its metric counts from
// 0.5 s on; the same test plotted against t is hatched), the same bytes on a second grade.
#include <doctest/doctest.h>
#include <stb/stb_image.h>

#include <filesystem>
#include <fstream>

#include "grading/grade.h"
#include "tests/test_files.h"

namespace fs = std::filesystem;
using namespace dyn;

namespace {

const std::string kLabDir = std::string(DYNLAB_SOURCE_DIR) + "/labs/slider_crank/";

// The shipped rubric cut to its two nominal tests over 1 s (one scenario: quick), test 2's plot
// given (or kept as shipped when plot is null).
json config(const json& plot) {
  json c = json::parse(std::ifstream(kLabDir + "slider_crank.json"));
  c["simulation"]["duration"] = 1.0;
  json tests = json::array({c["rubric"]["tests"][0], c["rubric"]["tests"][1]});
  if (!plot.is_null()) tests[1]["plot"] = plot;
  c["rubric"]["tests"] = tests;
  c["rubric"].erase("leaderboard");
  return c;
}

GradeOutcome grade(const fs::path& dir, const json& cfg, bool inline_plots = false) {
  std::ofstream(dir / "config.json") << cfg.dump();
  GradeOptions o;
  o.out_dir = dir.string();
  o.config_file = (dir / "config.json").string();
  o.inline_plots = inline_plots;
  return gradeSubmission(kLabDir + "examples/mediocre.json", o);
}

// Hatching pixels (the "not scored" span's light bluish grey) in the middle of a picture.
int hatch(const fs::path& png) {
  int w = 0, h = 0, n = 0;
  unsigned char* rgb = stbi_load(png.string().c_str(), &w, &h, &n, 3);
  REQUIRE(rgb);
  int count = 0;
  for (int y = int(0.12 * h); y < int(0.7 * h); ++y)
    for (int x = int(0.1 * w); x < int(0.75 * w); ++x) {
      const unsigned char* p = rgb + (std::size_t(y) * w + x) * 3;
      count += p[0] >= 150 && p[0] < 245 && std::abs(p[0] - p[1]) <= 3 && p[2] - p[0] >= 5;
    }
  stbi_image_free(rgb);
  return count;
}

}  // namespace

TEST_CASE("a rubric test's x–y plot is drawn, shown inline and never hatched") {
  const json xy = json::parse(R"({"x": "f_Tx", "columns": ["f_Ty"], "reference": "f_des", "reference_x": "f_Tx"})");
  const fs::path dir = dyn::test::scratchDir("rubric_xy_plot", "xy");
  const GradeOutcome g = grade(dir, config(xy), true);
  INFO(g.error);
  REQUIRE_FALSE(g.input_error);
  REQUIRE_FALSE(g.internal_error);
  const json& tests = g.results.at("tests");
  REQUIRE(tests.size() == 2);
  const std::string plot = tests[1].at("extra_data").at("plot");
  CHECK(plot == "plots/02-rail-force-regulated-to-f-des.png");
  const std::string png = dyn::test::readBytes(dir / plot);
  CHECK(png.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0);
  // Inline in results.json (for Gradescope) and in report.html, like every test plot.
  CHECK(tests[1].at("output").get<std::string>().find("data:image/png;base64,") != std::string::npos);
  std::size_t images = 0;
  for (std::size_t at = g.html.find("data:image/png;base64,"); at != std::string::npos;
       at = g.html.find("data:image/png;base64,", at + 1))
    ++images;
  CHECK(images == 2);
  // f_rms counts from 0.5 s: the plot against t hatches it, the x–y one does not.
  CHECK(hatch(dir / plot) < 5);  // a stray anti-aliased pixel of the curve or two
  const fs::path against_t = dyn::test::scratchDir("rubric_xy_plot", "t");
  const GradeOutcome gt = grade(against_t, config(nullptr));
  REQUIRE_FALSE(gt.input_error);
  CHECK(hatch(against_t / gt.results.at("tests")[1].at("extra_data").at("plot").get<std::string>()) > 100);
  // The same grade again: the same plot, byte for byte.
  const fs::path again = dyn::test::scratchDir("rubric_xy_plot", "again");
  REQUIRE_FALSE(grade(again, config(xy), true).input_error);
  CHECK(dyn::test::readBytes(again / plot) == png);
}

TEST_CASE("the grader plans a rubric x–y plot with labels in the lab's units and equal scales") {
  // The PNG keeps no text: the plan the grader drew from says what its axes are.
  const json xy = json::parse(R"({"x": "f_Tx", "columns": ["f_Ty"], "reference": "f_des"})");
  const fs::path dir = dyn::test::scratchDir("rubric_xy_plot", "labels");
  GradeOptions o;
  std::ofstream(dir / "config.json") << config(xy).dump();
  o.config_file = (dir / "config.json").string();
  o.out_dir = dir.string();
  o.keep_runs = true;
  const GradeOutcome g = gradeSubmission(kLabDir + "examples/mediocre.json", o);
  REQUIRE_FALSE(g.input_error);
  REQUIRE(g.graded.tests.size() == 2);
  REQUIRE(g.graded.tests[1].plan);
  const TestPlotPlan& plan = *g.graded.tests[1].plan;
  CHECK(plan.request.x == "f_Tx");
  CHECK(plan.request.reference_x == "f_Tx");
  CHECK(plan.request.xlabel == "f_Tx (N)");
  CHECK(plan.request.ylabel == "f_Ty, f_des (N)");
  CHECK(plan.equal_aspect);
  CHECK(g.graded.tests[1].plot_png.size() > 1000);
}
