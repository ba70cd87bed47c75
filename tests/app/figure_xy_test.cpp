// dynlab figure's x–y plots end to end: --plot "Y:X" (several curves to a plot) writes
// plot_Y-vs-X.<format> with the hand run and Bullet's, a legend naming engine and columns, axis
// labels with the lab's units, --size honoured, the same bytes on a rerun; a rubric test's x–y
// plot is among the lab's default figures; bad specs exit 2 with one line and write nothing.
#include <doctest/doctest.h>

#include "tests/app/cli_run.h"
#include "tests/test_files.h"

namespace fs = std::filesystem;
using namespace dyn;
using namespace dyn::test::cli;

namespace {

std::vector<std::string> names(const fs::path& dir) {
  std::vector<std::string> n;
  for (const auto& e : fs::directory_iterator(dir)) n.push_back(e.path().filename().string());
  std::sort(n.begin(), n.end());
  return n;
}

bool has(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

}  // namespace

TEST_CASE("dynlab figure --plot Y:X: x–y plots of both runs, legend and labels with units, same bytes twice") {
  TempDir dir("figure_xy");
  const std::vector<std::string> cmd = {"figure", "slider_crank", "--out",    "out",       "--duration", "0.3",
                                        "--plot", "f_Ty:f_Tx",    "--plot",   "v_c : x_c", "--plot",     "q2:q1, q3:q1, q2:q1",
                                        "--plot", "f_des:x_d",    "--format", "svg"};
  const Result r = dynlab(dir, cmd);
  INFO("stdout: ", r.out, "\nstderr: ", r.err);
  REQUIRE(r.code == 0);
  CHECK(names(dir / "out") == std::vector<std::string>{"plot_f_Ty-vs-f_Tx.svg", "plot_f_des-vs-x_d.svg",
                                                       "plot_q2-vs-q1+q3-vs-q1.svg", "plot_v_c-vs-x_c.svg"});
  CHECK(has(r.out, "out/plot_f_Ty-vs-f_Tx.svg"));
  const auto first = snapshot(dir / "out");
  const auto text = [&](const std::string& name) { return test::svgText(first.at(name)); };
  // Hand solid and Bullet dashed, each named; the x and y labels carry the lab's units.
  const std::string force = text("plot_f_Ty-vs-f_Tx.svg");
  for (const char* label : {"f_Ty vs f_Tx (hand)", "f_Ty vs f_Tx (Bullet)", "f_Tx (N)", "f_Ty (N)",
                            "Slider crank: f_Ty vs f_Tx"})  // the lab by its name, not its id
    CHECK_MESSAGE(has(force, label), "missing " << label);
  CHECK_FALSE(has(force, "t (s)"));
  const std::string phase = text("plot_v_c-vs-x_c.svg");
  CHECK(has(phase, "x_c (m)"));
  CHECK(has(phase, "v_c (m/s)"));
  // Two curves against one x; a repeated one is drawn once.
  const std::string joints = text("plot_q2-vs-q1+q3-vs-q1.svg");
  for (const char* label : {"q2 vs q1 (hand)", "q3 vs q1 (Bullet)", "q1 (rad)", "q2, q3 (rad)"})
    CHECK_MESSAGE(has(joints, label), "missing " << label);
  // A curve both engines share exactly (the reference against itself) is drawn once, for both.
  const std::string ref = text("plot_f_des-vs-x_d.svg");
  CHECK(has(ref, "f_des vs x_d (hand, Bullet)"));
  CHECK_FALSE(has(ref, "f_des vs x_d (Bullet)"));
  REQUIRE(dynlab(dir, cmd).code == 0);
  CHECK(snapshot(dir / "out") == first);

  // One engine, PNG at the asked size; PDF's page too.
  REQUIRE(dynlab(dir, {"figure", "slider_crank", "--out", "png", "--duration", "0.3", "--engine", "hand", "--plot", "f_Ty:f_Tx",
                       "--format", "png", "--size", "640x640"})
              .code == 0);
  const std::string png = readFile(dir / "png/plot_f_Ty-vs-f_Tx.png");
  REQUIRE(png.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0);
  CHECK(png.substr(16, 8) == std::string("\0\0\x02\x80\0\0\x02\x80", 8));  // IHDR: 640 x 640
  REQUIRE(
      dynlab(dir, {"figure", "slider_crank", "--out", "pdf", "--duration", "0.3", "--plot", "f_Ty:f_Tx", "--size", "1024x768"})
          .code == 0);
  CHECK(has(readFile(dir / "pdf/plot_f_Ty-vs-f_Tx.pdf"), "/MediaBox [ 0 0 1024 768 ]"));
}

TEST_CASE("dynlab figure: a rubric test's x–y plot is one of the lab's default figures") {
  TempDir dir("figure_xy_default");
  // The torque test's plot becomes the tip force's path f_Ty against f_Tx, with f_des against it.
  std::string config = defaultConfigText();
  const std::size_t at = config.find(R"("plot": {)", config.find(R"("metric": "tau_max")"));
  REQUIRE(at != std::string::npos);
  config.replace(at, config.find('}', at) + 1 - at, R"("plot": {"x": "f_Tx", "columns": ["f_Ty"], "reference": "f_des"})");
  writeFile(dir / "cfg.json", config);
  const Result r = dynlab(dir, {"figure", "slider_crank", "--config", "cfg.json", "--out", "out", "--duration", "0.3", "--format",
                                "svg", "--size", "320x240"});
  INFO("stdout: ", r.out, "\nstderr: ", r.err);
  REQUIRE(r.code == 0);
  const auto files = names(dir / "out");
  CHECK(std::find(files.begin(), files.end(), "plot_f_Ty-vs-f_Tx+f_des-vs-f_Tx.svg") != files.end());
  CHECK(std::find(files.begin(), files.end(), "plot_tau1+tau2+tau3.svg") == files.end());
  const std::string svg = test::svgText(readFile(dir / "out/plot_f_Ty-vs-f_Tx+f_des-vs-f_Tx.svg"));
  CHECK(has(svg, "f_Tx (N)"));
  CHECK(has(svg, "f_des vs f_Tx (hand, Bullet)") != has(svg, "f_des vs f_Tx (hand)"));
}

TEST_CASE("dynlab figure --plot Y:X: bad specs exit 2 with one line naming them, and write nothing") {
  TempDir dir("figure_xy_bad");
  const fs::path out = dir / "out";
  const std::vector<std::string> fig = {"figure", "slider_crank", "--out", "out", "--duration", "0.3"};
  checkBadInput(dir, cat(fig, {"--plot", "x_c, f_Ty:f_Tx"}),
                {"--plot x_c, f_Ty:f_Tx", "against t or every one against a column", "\"x_c\" is against t"}, out);
  checkBadInput(dir, cat(fig, {"--plot", "f_Ty:f_Tz"}), {"--plot f_Ty:f_Tz", "unknown column \"f_Tz\"", "Y:X", "t, q1, q2"}, out);
  checkBadInput(dir, cat(fig, {"--plot", "f_Ty:"}), {"--plot f_Ty:", "empty column name"}, out);
  checkBadInput(dir, cat(fig, {"--plot", "q3:q2:q1"}), {"--plot q3:q2:q1", "has two ':'"}, out);
  // A bad spec among good ones: still nothing written.
  checkBadInput(dir, cat(fig, {"--plot", "f_Ty:f_Tx", "--plot", "x_c:"}), {"--plot x_c:", "empty column name"}, out);
}
