// dynlab figure end to end: the real binary writes plots (PDF/SVG/PNG, valid and byte-identical on
// a rerun, legend with column and engine(s), the lab's y label when it has one) and stills (the size
// asked for, the arm and slider where the trace puts them at that time); a rerun leaves no stale
// figures; bad input exits 2 and writes nothing.
#include <doctest/doctest.h>
#include <stb_image.h>

#include <cmath>

#include "labs/run.h"
#include "render/renderer.h"
#include "tests/app/cli_run.h"
#include "tests/render/test_scene.h"
#include "tests/test_files.h"

namespace fs = std::filesystem;
using namespace dyn;
using namespace dyn::test::cli;

namespace {

bool startsWith(const std::string& s, const std::string& prefix) { return s.compare(0, prefix.size(), prefix) == 0; }

const std::string kPngMagic = "\x89PNG\r\n\x1a\n";

// Width and height from a PNG's IHDR chunk.
std::pair<int, int> pngSize(const std::string& bytes) {
  REQUIRE(bytes.size() > 24);
  auto be32 = [&](std::size_t i) {
    return int((unsigned char)bytes[i] << 24 | (unsigned char)bytes[i + 1] << 16 | (unsigned char)bytes[i + 2] << 8 |
               (unsigned char)bytes[i + 3]);
  };
  return {be32(16), be32(20)};
}

std::vector<std::string> names(const fs::path& dir) {
  std::vector<std::string> n;
  for (const auto& e : fs::directory_iterator(dir)) n.push_back(e.path().filename().string());
  std::sort(n.begin(), n.end());
  return n;
}

struct Png {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;
  const std::uint8_t* pixel(const Eigen::Vector2d& p) const {
    return &rgba[(std::size_t(std::lround(p.y())) * width + std::size_t(std::lround(p.x()))) * 4];
  }
};

Png loadPng(const fs::path& p) {
  Png png;
  int n = 0;
  unsigned char* data = stbi_load(p.string().c_str(), &png.width, &png.height, &n, 4);
  REQUIRE_MESSAGE(data, "cannot load " << p);
  png.rgba.assign(data, data + std::size_t(png.width) * png.height * 4);
  stbi_image_free(data);
  return png;
}

// Within a few levels of a scene colour (lighting shades the faces a little).
bool near(const std::uint8_t* p, const Color& c) { return test::nearColor(p, c, 40); }

}  // namespace

TEST_CASE("dynlab figure --plot: valid PDF, SVG and PNG files, legend per column and engine, same bytes on rerun") {
  TempDir dir("figure_plot");
  for (const std::string format : {"pdf", "svg", "png"}) {
    INFO("format ", format);
    const std::vector<std::string> cmd = {"figure", "slider_crank", "--out",  "out", "--duration", "0.3",
                                          "--plot", "f_Ty,f_des",   "--plot", "x_c", "--format",   format};
    const Result r = dynlab(dir, cmd);
    INFO("stdout: ", r.out, "\nstderr: ", r.err);
    REQUIRE(r.code == 0);
    CHECK(names(dir / "out") == std::vector<std::string>{"plot_f_Ty+f_des." + format, "plot_x_c." + format});
    // The command prints the paths it wrote.
    CHECK(r.out.find("out/plot_f_Ty+f_des." + format) != std::string::npos);
    CHECK(r.out.find("out/plot_x_c." + format) != std::string::npos);
    const auto first = snapshot(dir / "out");
    for (const auto& [name, bytes] : first) {
      INFO("file ", name);
      if (format == "pdf") CHECK(startsWith(bytes, "%PDF-"));
      if (format == "png") CHECK(startsWith(bytes, kPngMagic));
      if (format == "svg") CHECK(bytes.find("<svg") != std::string::npos);
      CHECK(bytes.size() > 1000);
    }
    REQUIRE(dynlab(dir, cmd).code == 0);
    CHECK(snapshot(dir / "out") == first);
    if (format == "svg") {
      // SVG keeps its text: both engines in the legend, and the rubric's y label (with its unit)
      // for the columns the lab plots itself; else the column name with the lab's unit.
      const std::string force = test::svgText(first.at("plot_f_Ty+f_des.svg"));
      const std::string x = test::svgText(first.at("plot_x_c.svg"));
      // The setpoint is the same in both runs: drawn once, for both engines.
      for (const char* label : {"f_Ty (hand)", "f_Ty (Bullet)", "f_des (hand, Bullet)", "rail force f_Ty (N)"})
        CHECK_MESSAGE(force.find(label) != std::string::npos, "missing " << label);
      CHECK(force.find("f_des (Bullet)") == std::string::npos);
      CHECK(x.find("x_c (hand)") != std::string::npos);
      CHECK(x.find("x_c (Bullet)") != std::string::npos);
      CHECK(x.find("x_c (m)") != std::string::npos);
    }
  }
  // One engine: no Bullet series; and the bytes depend on what was asked.
  const std::string svg = test::svgText(readFile(dir / "out/plot_x_c.svg"));
  REQUIRE(dynlab(dir, {"figure", "slider_crank", "--out", "hand", "--duration", "0.3", "--plot", "x_c", "--format", "svg",
                       "--engine", "hand"})
              .code == 0);
  const std::string hand = test::svgText(readFile(dir / "hand/plot_x_c.svg"));
  CHECK(hand.find("x_c (hand)") != std::string::npos);
  CHECK(hand.find("Bullet") == std::string::npos);
  CHECK(hand != svg);
}

// The largest font-size="N" of an SVG (PLplot writes one per text).
int largestFont(const std::string& svg) {
  int most = 0;
  for (std::size_t at = svg.find("font-size=\""); at != std::string::npos; at = svg.find("font-size=\"", at + 1))
    most = std::max(most, std::atoi(svg.c_str() + at + 11));
  return most;
}

TEST_CASE("dynlab figure: plots are --size big (PNG pixels, PDF and SVG page), text --font-scale, y --y-scale") {
  TempDir dir("figure_plot_size");
  const std::vector<std::string> fig = {"figure", "slider_crank", "--duration", "0.3", "--plot", "x_c"};
  REQUIRE(dynlab(dir, cat(fig, {"--out", "a", "--format", "png", "--size", "1280x720"})).code == 0);
  CHECK(pngSize(readFile(dir / "a/plot_x_c.png")) == std::pair<int, int>(1280, 720));
  REQUIRE(dynlab(dir, cat(fig, {"--out", "b", "--format", "pdf", "--size", "1024x768"})).code == 0);
  CHECK(readFile(dir / "b/plot_x_c.pdf").find("/MediaBox [ 0 0 1024 768 ]") != std::string::npos);
  REQUIRE(dynlab(dir, cat(fig, {"--out", "c", "--format", "svg", "--size", "640x360"})).code == 0);
  const std::string small = readFile(dir / "c/plot_x_c.svg");
  CHECK(small.find("width=\"640px\"") != std::string::npos);
  CHECK(small.find("height=\"360px\"") != std::string::npos);
  // Without --size a plot is 800x450 (a still 1920x1080).
  REQUIRE(dynlab(dir, cat(fig, {"--out", "d", "--format", "pdf"})).code == 0);
  CHECK(readFile(dir / "d/plot_x_c.pdf").find("/MediaBox [ 0 0 800 450 ]") != std::string::npos);
  // --font-scale: the same page, bigger text.
  REQUIRE(dynlab(dir, cat(fig, {"--out", "e", "--format", "svg", "--size", "640x360", "--font-scale", "2"})).code == 0);
  const std::string big = readFile(dir / "e/plot_x_c.svg");
  CHECK(largestFont(big) >= 1.8 * largestFont(small));
  CHECK(big.find("width=\"640px\"") != std::string::npos);
  // --y-scale log: tick labels are powers of ten ("10" with a superscript exponent); linear: none.
  const std::vector<std::string> residual = {"figure",   "slider_crank", "--duration", "0.3", "--plot", "constraint_residual",
                                             "--engine", "bullet",       "--format",   "svg"};
  REQUIRE(dynlab(dir, cat(residual, {"--out", "f", "--y-scale", "log"})).code == 0);
  CHECK(test::svgText(readFile(dir / "f/plot_constraint_residual.svg")).find(">10<tspan") != std::string::npos);
  REQUIRE(dynlab(dir, cat(residual, {"--out", "h", "--y-scale", "linear"})).code == 0);
  CHECK(test::svgText(readFile(dir / "h/plot_constraint_residual.svg")).find(">10<tspan") == std::string::npos);
  // A plot needs room for its labels; a bad scale is named.
  checkBadInput(dir, cat(fig, {"--out", "g", "--size", "80x60"}), {"--size 80x60", "at least 100x100"}, dir / "g");
  CHECK(dynlab(dir, cat(fig, {"--out", "g", "--y-scale", "cubic"})).code == 2);
  CHECK(dynlab(dir, cat(fig, {"--out", "g", "--font-scale", "0"})).code == 2);
}

TEST_CASE("dynlab figure --still: the requested size, the arm and slider where the trace puts them at t") {
  TempDir dir("figure_still");
  const double t = 1.0;  // half the reference period: the slider has moved its full stroke
  const Result r = dynlab(dir, {"figure", "slider_crank", "--out", "out", "--duration", "1.5", "--engine", "hand", "--still", "1",
                                "--size", "960x540", "--no-overlay"});
  INFO("stdout: ", r.out, "\nstderr: ", r.err);
  REQUIRE(r.code == 0);
  CHECK(names(dir / "out") == std::vector<std::string>{"still_1.000.png"});
  const Png png = loadPng(dir / "out/still_1.000.png");
  REQUIRE(png.width == 960);
  REQUIRE(png.height == 540);

  // The same run in-process: where the lab draws the arm and slider at the row nearest t.
  const LoadedLab loaded = loadLab("slider_crank", "", "", 1.5);
  const Trace trace = runEngine(*loaded.lab, Engine::Hand).trace;
  const auto row = std::size_t(std::llround(t / loaded.lab->dt()));
  REQUIRE(trace.at(row, "t") == doctest::Approx(t));
  Scene scene;
  loaded.lab->scene(trace, row, nullptr, scene);
  // The camera the renderer fits the scene with (Scene::framing), without and with the panel.
  auto fitted = [&](bool panel) {
    auto context = makeOffscreenContext(960, 540);
    Renderer renderer(*context, RenderOptions{4, panel});
    Overlay overlay;
    loaded.lab->overlay(trace, row, overlay);
    renderer.draw(scene, &overlay);
    return renderer.camera();
  };
  Camera camera = fitted(false);
  auto px = [&](const Eigen::Vector3d& w) { return Renderer::project(camera, 960, 540, w); };
  const Color link{0.23f, 0.42f, 0.68f, 1.0f}, slider{0.85f, 0.55f, 0.20f, 1.0f};
  // The first two links: their midpoints are link blue.
  for (int i = 0; i < 2; ++i) {
    const Capsule& c = scene.capsules[std::size_t(i)];
    const Eigen::Vector2d p = px(0.5 * (c.p0 + c.p1));
    const std::uint8_t* rgb = png.pixel(p);
    INFO("link ", i, " at ", p.transpose(), " rgb ", int(rgb[0]), " ", int(rgb[1]), " ", int(rgb[2]));
    CHECK(near(rgb, link));
  }
  // The slider's upper right part (clear of the last link and the force arrow) is orange ...
  const double x_c = trace.at(row, "x_c"), x_c0 = trace.at(0, "x_c");
  REQUIRE(std::abs(x_c - x_c0) > 0.1);  // far enough for a wrong row to show
  const Eigen::Vector3d corner(0.03, 0.012, 0);
  CHECK(near(png.pixel(px(Eigen::Vector3d(x_c, 0, 0) + corner)), slider));
  // ... and where it was at t = 0 it is not.
  CHECK_FALSE(near(png.pixel(px(Eigen::Vector3d(x_c0, 0, 0) + corner)), slider));

  // With the overlay panel (default) the top-left corner shows the panel, and the scene is fitted
  // into the rest of the frame: the slider where that camera puts it.
  REQUIRE(dynlab(dir, {"figure", "slider_crank", "--out", "panel", "--duration", "1.5", "--engine", "hand", "--still", "1",
                       "--size", "960x540"})
              .code == 0);
  const Png panel = loadPng(dir / "panel/still_1.000.png");
  REQUIRE(panel.width == 960);
  long differing = 0;
  for (int y = 0; y < 100; ++y)
    for (int x = 0; x < 200; ++x) differing += panel.rgba[(std::size_t(y) * 960 + x) * 4] != png.rgba[(std::size_t(y) * 960 + x) * 4];
  CHECK(differing > 1000);
  camera = fitted(true);
  CHECK(near(panel.pixel(px(Eigen::Vector3d(x_c, 0, 0) + corner)), slider));
}

TEST_CASE("dynlab figure with neither --plot nor --still: the lab's plots and stills at start, middle and end") {
  TempDir dir("figure_default");
  const Result r = dynlab(dir, {"figure", "slider_crank", "--out", "out", "--duration", "0.4"});
  INFO("stdout: ", r.out, "\nstderr: ", r.err);
  REQUIRE(r.code == 0);
  // The rubric's plots (response with reference, duplicates once) and three stills at 1920x1080.
  CHECK(names(dir / "out") == std::vector<std::string>{"plot_f_Ty+f_des.pdf", "plot_f_Ty+f_meas+f_des.pdf",
                                                      "plot_tau1+tau2+tau3.pdf", "plot_x_c+x_d.pdf",
                                                      "still_0.000.png", "still_0.200.png", "still_0.400.png"});
  for (const auto& [name, bytes] : snapshot(dir / "out")) {
    INFO(name);
    CHECK(r.out.find("out/" + name) != std::string::npos);
    if (startsWith(name, "still_")) {
      REQUIRE(startsWith(bytes, kPngMagic));
      CHECK(pngSize(bytes) == std::pair<int, int>(1920, 1080));
    } else {
      CHECK(startsWith(bytes, "%PDF-"));
    }
  }
}

TEST_CASE("dynlab figure: a rerun replaces the figures of the earlier one and keeps other files") {
  TempDir dir("figure_rerun");
  REQUIRE(dynlab(dir, {"figure", "slider_crank", "--out", "out", "--duration", "0.2", "--plot", "x_c", "--still", "0.1", "--size",
                       "160x120"})
              .code == 0);
  REQUIRE(names(dir / "out") == std::vector<std::string>{"plot_x_c.pdf", "still_0.100.png"});
  writeFile(dir / "out/notes.txt", "mine");
  REQUIRE(dynlab(dir, {"run", "slider_crank", "--out", "out", "--duration", "0.2", "--engine", "hand"}).code == 0);
  const Result r =
      dynlab(dir, {"figure", "slider_crank", "--out", "out", "--duration", "0.2", "--plot", "f_Ty", "--format", "svg"});
  REQUIRE(r.code == 0);
  // The earlier figures are gone, and the command says which; the user's file and dynlab run's
  // outputs are not the figure's.
  CHECK(r.out.find("removed the earlier figure run's plot_x_c.pdf, still_0.100.png") != std::string::npos);
  CHECK(names(dir / "out") ==
        std::vector<std::string>{"notes.txt", "plot_f_Ty.svg", "summary.json", "trace_hand.csv"});
}

TEST_CASE("dynlab figure: bad input exits 2 with one line naming it, and writes nothing") {
  TempDir dir("figure_bad");
  const fs::path out = dir / "out";
  const std::vector<std::string> fig = {"figure", "slider_crank", "--out", "out", "--duration", "1"};
  SUBCASE("unknown column: the error lists the available ones") {
    checkBadInput(dir, cat(fig, {"--plot", "f_Ty", "--plot", "f_Ty,f_Tz"}),
                  {"--plot f_Ty,f_Tz", "unknown column \"f_Tz\"", "t, q1, q2", "f_des"}, out);
    checkBadInput(dir, cat(fig, {"--plot", "x_c,"}), {"--plot x_c,", "empty column name"}, out);
  }
  SUBCASE("a time outside the run") {
    checkBadInput(dir, cat(fig, {"--still", "0.5", "--still", "1.5"}), {"--still 1.5", "[0, 1] s"}, out);
    checkBadInput(dir, cat(fig, {"--still", "-0.1"}), {"--still -0.1", "[0, 1] s"}, out);
  }
  SUBCASE("bad size or format") {
    for (const char* size : {"100", "0x0", "640x480x", "x480", "99999x100", "640X480"})
      checkBadInput(dir, cat(fig, {"--still", "0", "--size", size}), {std::string("--size ") + size, "WIDTHxHEIGHT"}, out);
    checkBadInput(dir, cat(fig, {"--plot", "x_c", "--format", "jpg"}), {"--format jpg", "pdf, svg or png"}, out);
  }
  SUBCASE("malformed config, bad gains") {
    writeFile(dir / "malformed.json", "{\"lab\": \"slider_crank\",,}");
    checkBadInput(dir, cat(fig, {"--config", "malformed.json"}), {"malformed.json", "expected valid JSON"}, out);
    writeFile(dir / "gains_big.json", R"({"gains": {"kp_x": 1e9}})");
    checkBadInput(dir, cat(fig, {"--gains", "gains_big.json"}), {"gains_big.json", "/gains/kp_x"}, out);
    checkBadInput(dir, {"figure", "no_such_lab", "--out", "out"}, {"unknown lab \"no_such_lab\""}, out);
  }
  SUBCASE("bad input leaves an earlier figure run intact") {
    REQUIRE(dynlab(dir, cat(fig, {"--plot", "x_c"})).code == 0);
    const auto before = snapshot(out);
    const Result r = dynlab(dir, cat(fig, {"--plot", "q9"}));
    CHECK(r.code == 2);
    CHECK(snapshot(out) == before);
  }
}
