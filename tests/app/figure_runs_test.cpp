// dynlab figure with several --gains files (runs overlaid on every plot, each curve named by its
// file) and masked curves ("y_p:x_p@contact": the pen's ink from above) end to end; repeated,
// missing and bad files, and --still with several runs, exit 2 with one line and write nothing.
#include <doctest/doctest.h>

#include "tests/app/cli_run.h"
#include "tests/test_files.h"

namespace fs = std::filesystem;
using namespace dyn;
using namespace dyn::test::cli;

namespace {

bool has(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

std::vector<std::string> names(const fs::path& dir) {
  std::vector<std::string> n;
  for (const auto& e : fs::directory_iterator(dir)) n.push_back(e.path().filename().string());
  std::sort(n.begin(), n.end());
  return n;
}

const std::string kSlider = std::string(DYNLAB_SOURCE_DIR) + "/labs/slider_crank/examples/";
const std::string kPen = std::string(DYNLAB_SOURCE_DIR) + "/labs/pen_on_table/examples/";

}  // namespace

TEST_CASE("dynlab figure --gains A --gains B: each run's curves on one plot, named by file; same bytes twice") {
  TempDir dir("figure_runs");
  writeFile(dir / "a.json", readFile(kSlider + "mediocre.json"));
  writeFile(dir / "b.json", readFile(kSlider + "proportional.json"));
  const std::vector<std::string> cmd = {"figure", "slider_crank", "--gains", "a.json", "--gains",    "b.json",   "--out",
                                        "out",    "--duration",   "0.3",     "--plot", "f_Ty,f_des", "--format", "svg"};
  const Result r = dynlab(dir, cmd);
  INFO("stdout: ", r.out, "\nstderr: ", r.err);
  REQUIRE(r.code == 0);
  // Plots only: a still shows one run.
  CHECK(names(dir / "out") == std::vector<std::string>{"plot_f_Ty+f_des.svg"});
  const auto first = snapshot(dir / "out");
  const std::string svg = test::svgText(first.at("plot_f_Ty+f_des.svg"));
  for (const char* label : {"f_Ty (a.json, hand)", "f_Ty (a.json, Bullet)", "f_Ty (b.json, hand)", "f_Ty (b.json, Bullet)",
                            "f_des (every run)"})
    CHECK_MESSAGE(has(svg, label), "missing " << label);
  CHECK_FALSE(has(svg, "f_des (a.json"));
  REQUIRE(dynlab(dir, cmd).code == 0);
  CHECK(snapshot(dir / "out") == first);

  // The lab's own set with two runs: its plots, overlaid; no stills.
  REQUIRE(dynlab(dir, {"figure", "slider_crank", "--gains", "a.json", "--gains", "b.json", "--out", "own", "--duration", "0.3",
                       "--engine", "hand", "--format", "svg"})
              .code == 0);
  for (const auto& n : names(dir / "own")) CHECK_MESSAGE(n.rfind("plot_", 0) == 0, n);
  // One --gains: the legend as before (engines only).
  REQUIRE(dynlab(dir, {"figure", "slider_crank", "--gains", "a.json", "--out", "one", "--duration", "0.3", "--plot", "f_Ty,f_des",
                       "--format", "svg"})
              .code == 0);
  const std::string one = test::svgText(readFile(dir / "one/plot_f_Ty+f_des.svg"));
  CHECK(has(one, "f_Ty (hand)"));
  CHECK_FALSE(has(one, "a.json"));
}

TEST_CASE("dynlab figure --plot Y:X@M: the pen's ink where contact, named; the lab's own set has it") {
  TempDir dir("figure_mask");
  const Result r = dynlab(dir, {"figure", "pen_on_table", "--gains", kPen + "unstable.json", "--engine", "hand", "--duration",
                                "2.6", "--out", "out", "--format", "svg", "--plot", "y_p:x_p@contact, y_d:x_d"});
  INFO("stdout: ", r.out, "\nstderr: ", r.err);
  REQUIRE(r.code == 1);  // the watchdog stops the unstable run; the figure is still written
  CHECK(has(r.out, "the pen bounced"));
  CHECK(names(dir / "out") == std::vector<std::string>{"plot_y_p-vs-x_p-where-contact+y_d-vs-x_d.svg"});
  const std::string svg = test::svgText(readFile(dir / "out/plot_y_p-vs-x_p-where-contact+y_d-vs-x_d.svg"));
  CHECK(has(svg, "y_p vs x_p where contact (hand)"));
  CHECK(has(svg, "x (m)"));  // the lab's labels for exactly these curves (its "figures")
  CHECK_FALSE(has(svg, "x_p, x_d (m)"));
  // Before touchdown the mask is 0 throughout: nothing drawn, and said so (the other plot is written).
  const Result early = dynlab(dir, {"figure", "pen_on_table", "--engine", "hand", "--duration", "0.05", "--out", "early",
                                    "--format", "svg", "--plot", "y_p:x_p@contact", "--plot", "z_p"});
  INFO("stdout: ", early.out, "\nstderr: ", early.err);
  CHECK(early.code == 0);
  CHECK(names(dir / "early") == std::vector<std::string>{"plot_z_p.svg"});
  CHECK(has(early.out, "not written: plot_y_p-vs-x_p-where-contact.svg (y_p vs x_p where contact: nothing to draw"));
    // The lab's own set, two runs (so no stills): the ink is one of its figures, each run's named.
  const Result two = dynlab(dir, {"figure", "pen_on_table", "--gains", kPen + "mediocre.json", "--gains", kPen + "spring.json",
                                  "--engine", "hand", "--duration", "0.5", "--out", "two", "--format", "svg"});
  INFO("stdout: ", two.out, "\nstderr: ", two.err);
  REQUIRE(two.code == 0);
  const std::string both = test::svgText(readFile(dir / "two/plot_y_p-vs-x_p-where-contact+y_d-vs-x_d.svg"));
  CHECK(has(both, "the ink from above"));
  CHECK(has(both, "y_p vs x_p where contact (mediocre.json, hand)"));
  CHECK(has(both, "y_p vs x_p where contact (spring.json, hand)"));
}

TEST_CASE("dynlab figure --gains: repeated, missing or bad files and --still with several runs are one line") {
  TempDir dir("figure_runs_bad");
  writeFile(dir / "a.json", readFile(kSlider + "mediocre.json"));
  writeFile(dir / "bad.json", "{\"gains\": {\"kp_x\": \"fast\"}}");
  const fs::path out = dir / "out";
  const std::vector<std::string> fig = {"figure", "slider_crank", "--out", "out", "--duration", "0.3", "--plot", "f_Ty"};
  checkBadInput(dir, cat(fig, {"--gains", "a.json", "--gains", "a.json"}), {"--gains a.json", "each gains file once"}, out);
  checkBadInput(dir, cat(fig, {"--gains", "a.json", "--gains", "./a.json"}), {"--gains ./a.json", "each gains file once"}, out);
  checkBadInput(dir, cat(fig, {"--gains", "a.json", "--gains", "missing.json"}), {"missing.json"}, out);
  checkBadInput(dir, cat(fig, {"--gains", "bad.json", "--gains", "a.json"}), {"bad.json"}, out);
  checkBadInput(dir, cat(fig, {"--gains", "a.json", "--gains", kSlider + "proportional.json", "--still", "0.1"}),
                {"--still 0.1", "one --gains file"}, out);
  checkBadInput(dir, cat(fig, {"--plot", "q2:q1@"}), {"--plot q2:q1@", "empty column name"}, out);
  checkBadInput(dir, cat(fig, {"--plot", "q2:q1@x_c@x_d"}), {"has two '@'"}, out);
}
