// dynlab-ui end to end: the real window in a virtual X display (xvfb-run). Its screenshot is the
// OSMesa render of the state it reports (GLX and OSMesa share llvmpipe, so the pixels agree), the
// arm is where that state puts it, the gains it saves grade exactly as the same gains typed by
// hand, unstable gains are reported in words, and `dynlab ui` runs it. Without xvfb-run the
// window cases print DYNLAB_TEST_SKIPPED, which ctest reports as skipped.
#include <doctest/doctest.h>
#include <stb_image.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "labs/generic/model_lab.h"
#include "labs/run.h"
#include "render/renderer.h"
#include "tests/app/cli_run.h"
#include "tests/test_files.h"

namespace fs = std::filesystem;
using namespace dyn;

namespace {

using test::cli::cat;
using test::cli::Result;

// Without a display at all: what must work before (or instead of) a window.
Result noDisplay(const fs::path& dir, const std::string& bin, const std::vector<std::string>& args) {
  ProcessOptions o;
  o.unset_env = {"DISPLAY", "WAYLAND_DISPLAY"};
  return test::cli::run(dir, cat({bin}, args), o);
}

bool haveXvfb() {
  static const bool have = test::cli::haveXvfb();
  if (!have) std::cout << "DYNLAB_TEST_SKIPPED: xvfb-run (packages xvfb, xauth) not found; the window tests did not run\n";
  return have;
}

// bin ARGS in a fresh virtual X display (24-bit, larger than the window).
Result inXvfb(const fs::path& dir, const std::string& bin, const std::vector<std::string>& args) {
  return test::cli::run(dir, test::cli::inXvfb(cat({bin}, args), "1600x1000"));
}

struct Png {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;
  const std::uint8_t* pixel(int x, int y) const { return &rgba[(std::size_t(y) * width + x) * 4]; }
};

Png loadPng(const fs::path& p) {
  Png png;
  int n = 0;
  unsigned char* data = stbi_load(p.string().c_str(), &png.width, &png.height, &n, 4);
  if (data) png.rgba.assign(data, data + std::size_t(png.width) * png.height * 4);
  stbi_image_free(data);
  return png;
}

// Pixels of the screenshot's region at (x0, y0) that differ from ref by more than 2 in a channel.
struct Diff {
  long differing = 0;
  int max = 0;
};
Diff compare(const Png& shot, int x0, int y0, const Image& ref) {
  Diff d;
  for (int y = 0; y < ref.height; ++y)
    for (int x = 0; x < ref.width; ++x) {
      int m = 0;
      for (int c = 0; c < 3; ++c) m = std::max(m, std::abs(int(shot.pixel(x0 + x, y0 + y)[c]) - int(ref.pixel(x, y)[c])));
      d.max = std::max(d.max, m);
      d.differing += m > 2 ? 1 : 0;
    }
  return d;
}

// The first `rows` rows of a trace: what the window's session had when it drew a row.
Trace upTo(const Trace& trace, std::size_t rows) {
  Trace t = trace;
  t.data.resize(std::min(rows, trace.rows()) * trace.columns.size());
  return t;
}

// The OSMesa frame of a row, from the traces as the window had them then (the lab frames its
// scene around the run so far); camera, when given, receives the camera the frame was drawn with.
Image renderOsmesa(const Lab& lab, const Trace& full, const Trace* full_ghost, std::size_t row, int w, int h,
                   Camera* camera = nullptr) {
  const Trace trace = upTo(full, row + 1), ghost = full_ghost ? upTo(*full_ghost, row + 1) : Trace{};
  auto context = makeOffscreenContext(w, h);
  Renderer renderer(*context);
  Scene scene;
  Overlay overlay;
  lab.scene(trace, row, full_ghost ? &ghost : nullptr, scene);
  lab.overlay(trace, row, overlay);
  Image image = renderer.render(scene, &overlay);
  if (camera) *camera = renderer.camera();
  return image;
}

// Grades a submission with the real dynlab; returns results.json.
json grade(const fs::path& dir, const std::string& file, const std::string& out) {
  const Result r = test::cli::run(dir, {DYNLAB_BIN, "grade", file, "--out", out, "--no-plots"});
  INFO("dynlab grade " << file << ": " << r.out << r.err);
  CHECK(r.code == 0);
  return loadJsonFile((dir / out / "results.json").string());
}

const std::string kExamples = std::string(DYNLAB_SOURCE_DIR) + "/labs/slider_crank/examples/";

}  // namespace

TEST_CASE("dynlab-ui: --help and bad input need no display, and bad input exits 2 before a window opens") {
  const fs::path dir = test::scratchDir("dynlab_ui_window", "no_display");
  Result r = noDisplay(dir, DYNLAB_UI_BIN, {"--help"});
  CHECK(r.code == 0);
  CHECK(r.out.find("--frames") != std::string::npos);
  CHECK(r.out.find("--set") != std::string::npos);
  r = noDisplay(dir, DYNLAB_UI_BIN, {"slider_crank", "--set", "kp_x=1e9", "--frames", "1"});
  CHECK(r.code == 2);
  CHECK(r.err == "error: <command line>: --set kp_x=1e9: expected a number in [0, 2e+04] N/m, got 1e+09\n");
  r = noDisplay(dir, DYNLAB_UI_BIN, {"slider_crank", "--set", "force_law=bang_bang"});
  CHECK(r.code == 2);
  CHECK(r.err.find("expected one of open_loop, proportional, integral") != std::string::npos);
  r = noDisplay(dir, DYNLAB_UI_BIN, {"no_such_lab"});
  CHECK(r.code == 2);
  CHECK(r.err.find("unknown lab \"no_such_lab\"") != std::string::npos);
  r = noDisplay(dir, DYNLAB_UI_BIN, {"slider_crank", "--screenshot", "x.png"});
  CHECK(r.code == 2);  // --screenshot needs --frames
  // With good input and no display: a clear error, not a crash.
  r = noDisplay(dir, DYNLAB_UI_BIN, {"slider_crank", "--frames", "1"});
  CHECK(r.code == 1);
  CHECK(r.err.find("error: cannot open a window") == 0);
  // The one entry point: dynlab ui execs dynlab-ui with its arguments and exit code.
  r = noDisplay(dir, DYNLAB_BIN, {"ui", "--help"});
  CHECK(r.code == 0);
  CHECK(r.out.find("dynlab-ui") != std::string::npos);
  r = noDisplay(dir, DYNLAB_BIN, {"ui", "slider_crank", "--set", "kd_x=-3", "--frames", "1"});
  CHECK(r.code == 2);
  CHECK(r.err.find("--set kd_x=-3: expected a number in [0, 2000]") != std::string::npos);
}

TEST_CASE("the window's scene is the OSMesa render of the state it shows, with the arm where that state says") {
  if (!haveXvfb()) return;
  const fs::path dir = test::scratchDir("dynlab_ui_window", "screenshot");
  const Result r = inXvfb(dir, DYNLAB_UI_BIN,
                          {"slider_crank", "--set", "kp_x=500", "--engine", "both", "--frames", "60", "--screenshot", "shot.png",
                           "--state", "state.json", "--save", "gains.json"});
  INFO(r.out << r.err);
  REQUIRE(r.code == 0);
  const json state = loadJsonFile((dir / "state.json").string());
  CHECK(state["gl"].get<std::string>().find("llvmpipe") != std::string::npos);
  CHECK(state["submission"]["gains"]["kp_x"] == 500.0);
  CHECK(state["problem"] == "");
  // 60 frames of 1/60 s at speed 1: one simulated second.
  CHECK(state["t"].get<double>() == doctest::Approx(1.0).epsilon(0.002));

  // The same state from the saved gains file (it must load back to the same gains).
  const LoadedLab loaded = loadLab("slider_crank", "", (dir / "gains.json").string());
  const RunResult hand = runEngine(*loaded.lab, Engine::Hand), bullet = runEngine(*loaded.lab, Engine::Bullet);
  const std::size_t row = state["row"].get<std::size_t>();
  REQUIRE(row < hand.trace.rows());
  REQUIRE(row > 60);
  for (const auto& column : hand.trace.columns) {
    INFO(column);
    CHECK(state["values"][column].get<double>() == hand.trace.at(row, column));
  }

  // The scene region of the screenshot is the OSMesa frame of that row (Bullet ghost included).
  const Png shot = loadPng(dir / "shot.png");
  REQUIRE(shot.width == state["window"]["width"].get<int>());
  REQUIRE(shot.height == state["window"]["height"].get<int>());
  const json& vp = state["viewport"];
  const int vx = vp["x"], vy = vp["y"], vw = vp["width"], vh = vp["height"];
  REQUIRE(vw >= 320);
  REQUIRE(vx + vw <= shot.width);
  REQUIRE(vy + vh <= shot.height);
  Camera camera;
  const Image same = renderOsmesa(*loaded.lab, hand.trace, &bullet.trace, row, vw, vh, &camera);
  const Diff d = compare(shot, vx, vy, same);
  MESSAGE("window vs OSMesa: " << d.differing << " of " << vw * vh << " pixels differ, largest channel difference " << d.max);
  CHECK(d.differing <= long(vw) * vh / 1000);
  // ... and not the frame 50 ms earlier: the comparison can tell states apart.
  const Image earlier = renderOsmesa(*loaded.lab, hand.trace, &bullet.trace, row - 50, vw, vh);
  CHECK(compare(shot, vx, vy, earlier).differing > 500);

  // The arm where the state says: every opaque link's midpoint is link-coloured in the window,
  // and the slider sits at the state's x_c (seen through the camera the frame was drawn with).
  Scene scene;
  loaded.lab->scene(hand.trace, row, &bullet.trace, scene);
  int links = 0;
  for (const Capsule& c : scene.capsules) {
    if (c.color.a < 1.0f) continue;
    const Eigen::Vector2d px = Renderer::project(camera, vw, vh, 0.5 * (c.p0 + c.p1));
    const std::uint8_t* p = shot.pixel(vx + int(px.x()), vy + int(px.y()));
    INFO("link " << links << " at " << px.transpose() << ": " << int(p[0]) << "," << int(p[1]) << "," << int(p[2]));
    CHECK(int(p[2]) > int(p[0]) + 40);  // blue links (0.23, 0.42, 0.68) on a pale background
    ++links;
  }
  CHECK(links == 3);
  const Eigen::Vector2d slider = Renderer::project(camera, vw, vh, {state["values"]["x_c"].get<double>(), 0.011, 0.0});
  const std::uint8_t* p = shot.pixel(vx + int(slider.x()), vy + int(slider.y()));
  INFO("slider pixel " << int(p[0]) << "," << int(p[1]) << "," << int(p[2]));
  CHECK(int(p[0]) > int(p[1]) + 30);  // orange (0.85, 0.55, 0.20)
  CHECK(int(p[1]) > int(p[2]) + 30);
}

TEST_CASE("gains saved by the window grade exactly like the same gains written by hand") {
  if (!haveXvfb()) return;
  const fs::path dir = test::scratchDir("dynlab_ui_window", "grade");
  const Result r = inXvfb(dir, DYNLAB_UI_BIN,
                          {"slider_crank", "--set", "kp_x=300", "--set", "kd_x=12", "--set", "ki_f=10", "--set",
                           "force_law=integral", "--frames", "3", "--save", "mine.json"});
  INFO(r.out << r.err);
  REQUIRE(r.code == 0);
  const json saved = loadJsonFile((dir / "mine.json").string());
  const json by_hand = {{"lab", "slider_crank"},
                        {"force_law", "integral"},
                        {"gains", {{"kp_x", 300.0}, {"kd_x", 12.0}, {"kp_f", 0.5}, {"ki_f", 10.0}}}};
  CHECK(saved == by_hand);
  std::ofstream(dir / "by_hand.json") << by_hand.dump();
  const json a = grade(dir, "mine.json", "graded_mine"), b = grade(dir, "by_hand.json", "graded_by_hand");
  // These gains, not the lab's defaults: the defaults (each gain's "value" in the config) grade lower.
  json defaults = {{"lab", "slider_crank"}, {"gains", json::object()}};
  const json config = loadJsonFile(std::string(DYNLAB_SOURCE_DIR) + "/labs/slider_crank/slider_crank.json");
  for (const auto& [name, g] : config["gains"].items()) defaults["gains"][name] = g["value"];
  std::ofstream(dir / "defaults.json") << defaults.dump();
  const json d = grade(dir, "defaults.json", "graded_defaults");
  CHECK(a["score"].get<double>() > d["score"].get<double>() + 0.5);
  CHECK(a["score"] == b["score"]);
  CHECK(a["tests"] == b["tests"]);
  CHECK(a["extra_data"]["fingerprint"]["submission_hash"] == b["extra_data"]["fingerprint"]["submission_hash"]);
}

TEST_CASE("unstable gains: the window says why in the grader's words, and does not crash") {
  if (!haveXvfb()) return;
  const fs::path dir = test::scratchDir("dynlab_ui_window", "unstable");
  const std::string gains = kExamples + "unstable_integral.json";
  const Result r =
      inXvfb(dir, DYNLAB_UI_BIN,
             {"slider_crank", "--gains", gains, "--frames", "20", "--state", "state.json", "--screenshot", "shot.png"});
  INFO(r.out << r.err);
  REQUIRE(r.code == 0);
  const json state = loadJsonFile((dir / "state.json").string());
  const std::string problem = state["problem"];
  CHECK(problem == "unstable: the rail force left its safe range [-500, 500] at t = 0.088 s (f_Ty = -550.3)");
  CHECK(state["finished"] == true);
  CHECK(loadPng(dir / "shot.png").width > 0);
  // The grader stops the nominal scenario with the same sentence.
  const json results = grade(dir, gains, "graded");
  bool said = false;
  for (const auto& t : results["tests"]) said = said || t["output"].get<std::string>().find(problem) != std::string::npos;
  CHECK(said);
}

TEST_CASE("dynlab ui LAB runs the window (one entry point)") {
  if (!haveXvfb()) return;
  const fs::path dir = test::scratchDir("dynlab_ui_window", "entry");
  const Result r = inXvfb(dir, DYNLAB_BIN,
                          {"ui", "slider_crank", "--gains", kExamples + "mediocre.json", "--set", "kp_f=0.25", "--frames", "2",
                           "--state", "state.json"});
  INFO(r.out << r.err);
  REQUIRE(r.code == 0);
  const json state = loadJsonFile((dir / "state.json").string());
  CHECK(state["submission"]["gains"]["kp_x"] == 150.0);  // from --gains
  CHECK(state["submission"]["gains"]["kp_f"] == 0.25);    // from --set, passed through
}

TEST_CASE("dynlab ui FILE: a model file's passive run in the window, its scene the OSMesa render of that state") {
  const std::string file = std::string(DYNLAB_SOURCE_DIR) + "/assets/models/fourbar.xml";
  const fs::path dir = test::scratchDir("dynlab_ui_window", "model");
  // Lab-only options are refused before any display is needed.
  const Result bad = noDisplay(dir, DYNLAB_UI_BIN, {file, "--gains", "g.json"});
  CHECK(bad.code == 2);
  CHECK(bad.err.find("--gains") != std::string::npos);
  CHECK(std::count(bad.err.begin(), bad.err.end(), '\n') == 1);
  if (!haveXvfb()) return;
  const Result r = inXvfb(
      dir, DYNLAB_BIN, {"ui", file, "--engine", "both", "--frames", "30", "--screenshot", "shot.png", "--state", "state.json"});
  INFO(r.out << r.err);
  REQUIRE(r.code == 0);
  const json state = loadJsonFile((dir / "state.json").string());
  CHECK(state["problem"] == "");
  CHECK(state["t"].get<double>() == doctest::Approx(0.5).epsilon(0.01));
  CHECK(state["values"]["constraint_residual"].get<double>() <= 1e-12);
  // The scene region is the OSMesa frame of the same row of the same run.
  const LoadedLab loaded = app::loadModelLab(file, std::nullopt);
  const RunResult hand = runEngine(*loaded.lab, Engine::Hand), bullet = runEngine(*loaded.lab, Engine::Bullet);
  const std::size_t row = state["row"].get<std::size_t>();
  REQUIRE(row < hand.trace.rows());
  CHECK(state["values"]["q_crank"].get<double>() == hand.trace.at(row, "q_crank"));
  const Png shot = loadPng(dir / "shot.png");
  const json& vp = state["viewport"];
  const int vx = vp["x"], vy = vp["y"], vw = vp["width"], vh = vp["height"];
  REQUIRE(vx + vw <= shot.width);
  const Image same = renderOsmesa(*loaded.lab, hand.trace, &bullet.trace, row, vw, vh);
  const Diff d = compare(shot, vx, vy, same);
  MESSAGE("model file, window vs OSMesa: " << d.differing << " of " << vw * vh << " pixels differ");
  CHECK(d.differing <= long(vw) * vh / 1000);
  CHECK(compare(shot, vx, vy, renderOsmesa(*loaded.lab, hand.trace, &bullet.trace, 0, vw, vh)).differing > 500);
}

TEST_CASE("every gain slider shows its whole name and its value's digits: a thin knob, names inside the panel") {
  if (!haveXvfb()) return;
  const fs::path dir = test::scratchDir("dynlab_ui_window", "sliders");
  // The unicycle's long gain names (kd_heading, anti_windup) at the default window size.
  const Result r = inXvfb(dir, DYNLAB_UI_BIN, {"unicycle", "--frames", "2", "--screenshot", "shot.png", "--state", "state.json"});
  INFO(r.out << r.err);
  REQUIRE(r.code == 0);
  const json state = loadJsonFile((dir / "state.json").string());
  const Png shot = loadPng(dir / "shot.png");
  REQUIRE(shot.width > 0);
  const double right = state["panel_right"];
  REQUIRE(state["gain_sliders"].size() == state["submission"]["gains"].size());
  for (const auto& w : state["gain_sliders"]) {
    const std::string name = w["name"];
    INFO("gain ", name);
    const int x0 = int(w["frame"][0].get<double>()), y0 = int(w["frame"][1].get<double>());
    const int x1 = int(w["frame"][2].get<double>()), y1 = int(w["frame"][3].get<double>());
    REQUIRE((x0 >= 0 && x1 <= shot.width && y0 >= 0 && y1 <= shot.height && x1 - x0 > 40));
    // The name ends inside the panel (not cut at its edge).
    CHECK(w["label"][2].get<double>() <= right - 2);
    // The knob: columns of the frame holding its blue, at most a few pixels wide; the digits: dark
    // pixels of the text over the frame's middle.
    int knob = 0, dark = 0;
    for (int x = x0 + 2; x < x1 - 2; ++x) {
      bool blue = false;
      for (int y = y0 + 2; y < y1 - 2; ++y) {
        const std::uint8_t* p = shot.pixel(x, y);
        blue = blue || (p[2] > 150 && p[2] > p[0] + 60 && p[1] > 100);
        dark += p[0] < 90 && p[1] < 90 && p[2] < 90;
      }
      knob += blue;
    }
    CHECK(knob <= 6);
    CHECK(dark > 20);
  }
}

TEST_CASE("dynlab ui FILE --key NAME: the run starts from the keyframe, and the file's notes are said once") {
  const std::string file = std::string(DYNLAB_SOURCE_DIR) + "/tests/physics/model_file/files/servo_arm.xml";
  const fs::path dir = test::scratchDir("dynlab_ui_window", "model_key");
  // A lab takes no --key; a keyframe the file lacks is one line naming those it has (no display needed).
  Result bad = noDisplay(dir, DYNLAB_UI_BIN, {"slider_crank", "--key", "reach"});
  CHECK(bad.code == 2);
  CHECK(bad.err == "error: <command line>: --key: for a model file (.xml, .urdf); slider_crank is a lab\n");
  bad = noDisplay(dir, DYNLAB_UI_BIN, {file, "--key", "home"});
  CHECK(bad.code == 2);
  CHECK(bad.err.find("--key 'home': no such keyframe; the file's keyframes: 'reach'") != std::string::npos);
  CHECK(std::count(bad.err.begin(), bad.err.end(), '\n') == 1);
  if (!haveXvfb()) return;
  const Result r = inXvfb(dir, DYNLAB_BIN, {"ui", file, "--key", "reach", "--engine", "hand", "--frames", "3", "--state", "state.json"});
  INFO(r.out << r.err);
  REQUIRE(r.code == 0);
  const json state = loadJsonFile((dir / "state.json").string());
  // The collision geoms' note, on stderr and in the panel, once.
  const std::string contact = "geoms collide in MuJoCo but not here";
  CHECK(r.err.find(contact) != std::string::npos);
  CHECK(r.err.find(contact) == r.err.rfind(contact));
  int in_panel = 0;
  for (const auto& n : state["notes"]) in_panel += n.get<std::string>().find(contact) != std::string::npos;
  CHECK(in_panel == 1);
  // The row on screen is the keyframe run's (qpos, qvel and ctrl from 'reach'), not the run from q0.
  app::ModelFileFlags key;
  key.key = "reach";
  const LoadedLab from_key = app::loadModelLab(file, std::nullopt, key), from_q0 = app::loadModelLab(file, std::nullopt);
  const RunResult hand = runEngine(*from_key.lab, Engine::Hand), plain = runEngine(*from_q0.lab, Engine::Hand);
  const std::size_t row = state["row"].get<std::size_t>();
  REQUIRE(row > 0);
  CHECK(state["values"]["q_elbow"].get<double>() == hand.trace.at(row, "q_elbow"));
  CHECK(std::abs(hand.trace.at(row, "q_elbow") - plain.trace.at(row, "q_elbow")) > 0.1);
}
