// dynlab-ui: the interactive tuning window. Each frame: advance the run by speed × wall time (a
// fixed 1/60 s per frame in scripted runs, so they are deterministic), draw the lab's scene with
// the offscreen renderer and blit it in, then the tuning panel on the right. Its own executable:
// it links libGL (GLFW), and dynlab links OSMesa; the two never meet in one process.
#include <imgui.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <fstream>
#include <iostream>

#include "labs/generic/model_lab.h"
#include "app/ui/frame.h"
#include "grading/student.h"
#include "labs/generic/lab_folders.h"
#include "labs/utf8.h"
#include "render/renderer.h"
#include "render/window_context.h"

namespace {

using namespace dyn;
using namespace dyn::ui;

struct Args {
  std::string lab, config, gains, scenario, student, engine = "both", size = "1320x720", save, screenshot, state;
  std::vector<std::string> set, labs;
  app::ModelFileFlags files;  // a model file's --key, --ignore-contacts, --package-path
  double speed = 1.0;
  bool paused = false;
  long frames = -1;  // scripted: this many frames, then exit
};

// What the last frame showed, for scripted runs and their tests.
json frameState(const TuningSession& s, const WindowContext& ctx, const Layout& l, long frame, const PanelState& st) {
  json widgets = json::array();
  const float scale = std::max(ImGui::GetIO().DisplayFramebufferScale.x, 1e-3f);  // window → framebuffer pixels
  const auto px = [&](const float* r) { return json{r[0] * scale, r[1] * scale, r[2] * scale, r[3] * scale}; };
  for (const auto& w : st.widgets) widgets.push_back({{"name", w.name}, {"frame", px(w.frame)}, {"label", px(w.label)}});
  json values = json::object();
  if (s.hasRows())
    for (std::size_t c = 0; c < s.primary().columns.size(); ++c) values[s.primary().columns[c]] = s.primary().at(s.row(), int(c));
  return {{"lab", s.labName()},
          {"scenario", s.scenario()},
          {"frame", frame},
          {"row", s.row()},
          {"t", s.time()},
          {"finished", s.finished()},
          {"problem", s.problem()},
          {"ghost_problem", s.ghostProblem()},
          {"engine", name(s.engine())},
          {"values", values},
          {"submission", s.submission()},
          {"metrics", s.metrics()},
          {"screening", s.screening()},
          {"window", {{"width", ctx.width()}, {"height", ctx.height()}}},
          {"viewport", {{"x", l.scene_x}, {"y", l.scene_y}, {"width", l.scene_w}, {"height", l.scene_h}}},
          {"gl", ctx.description()},
          {"gain_sliders", widgets},
          {"panel_right", st.window_right * scale},
          {"notes", s.notes()}};
}

bool writeText(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary);
    out << text;
    if (!(out.flush())) return std::remove(tmp.c_str()), false;
  }
  return std::rename(tmp.c_str(), path.c_str()) == 0;
}

int run(const Args& a) {
  // Everything that can be wrong with the input is checked before a window opens.
  // A model file where a lab goes: its passive motion (labs/generic/model_lab.h), nothing to tune but the engines.
  const bool model = app::isModelFile(a.lab);
  if (model)
    for (const auto& [given, option] : {std::pair{!a.config.empty(), "--config"}, {!a.gains.empty(), "--gains"}, {!a.scenario.empty(), "--scenario"}, {!a.student.empty(), "--student"}})
      if (given) throw InputError("<command line>", option, "a model file runs passive, without a lab's config, gains or scenario");
  if (!model)
    for (const auto& [given, option] : {std::pair{a.files.ignore_contacts, "--ignore-contacts"}, {!a.files.key.empty(), "--key"}, {!a.files.package_paths.empty(), "--package-path"}})
      if (given) throw InputError("<command line>", option, "for a model file (.xml, .urdf); " + termName(a.lab) + " is a lab");
  // A model file's notes (its load's, servos stiffer than its step): said once, on stderr and in the panel.
  std::vector<std::string> notes;
  TuningSession session = model ? TuningSession(app::loadModelLab(a.lab, std::nullopt, a.files, &notes))
                                : TuningSession(a.lab, a.config, a.gains, a.scenario, studentPlant(a.student));
  for (const std::string& n : notes) std::cerr << "note: " << termName(n, 1000) << "\n";
  session.setNotes(std::move(notes));
  for (const auto& s : a.set) session.set(s);
  session.setEngine(parseEngineChoice(a.engine));
  session.restart();
  int win_w = 0, win_h = 0;
  if (!parseFrameSize(a.size, 400, 300, win_w, win_h))
    throw InputError("<command line>", "--size", "expected WIDTHxHEIGHT, at least 400x300, got \"" + a.size + "\"");

  PanelState st;
  st.playing = !a.paused;
  st.speed = a.speed;
  st.save_path = a.save.empty() ? session.labName() + "_gains.json" : a.save;
  const bool scripted = a.frames >= 0;

  std::unique_ptr<WindowContext> ctx;
  try {
    ctx = makeWindowContext({win_w, win_h, "dynlab — " + termName(session.title()), !scripted});
  } catch (const std::exception& e) {
    std::cerr << "error: " << termName(e.what(), 1000) << "\n";
    return 1;
  }
  setupImGui(ctx->window(), *ctx);
  TuningFrame tuning;
  double last = ctx->seconds();
  int code = 0;
  for (long frame = 0; !ctx->shouldClose() && (!scripted || frame < a.frames); ++frame) {
    ctx->pollEvents();
    // Time: the run advances speed × wall time in fixed lab steps (carrying the fraction).
    const double now = ctx->seconds();
    const double wall = scripted ? 1.0 / 60.0 : std::min(now - last, 0.1);
    last = now;
    tuning.advance(session, st, wall);
    const Layout l = tuning.draw(session, st, *ctx);

    if (scripted && frame + 1 == a.frames) {
      if (!a.screenshot.empty() && !writePng(a.screenshot, ctx->screenshot())) {
        std::cerr << "error: " << a.screenshot << ": cannot write the screenshot\n";
        code = 1;
      }
      if (!a.state.empty() && !writeText(a.state, frameState(session, *ctx, l, frame, st).dump(2) + "\n")) {
        std::cerr << "error: " << a.state << ": cannot write the state\n";
        code = 1;
      }
      if (!a.save.empty()) {
        saveGains(session, st);
        if (st.status_is_error) {
          std::cerr << "error: " << termName(st.status, 1000) << "\n";
          code = 1;
        }
      }
      std::printf("dynlab-ui: %ld frames, t = %.3f s (row %zu)%s%s\n", a.frames, session.time(), session.row(),
                  session.problem().empty() ? "" : "; stopped: ", termName(session.problem(), 1000).c_str());
    }
    ctx->swap();
  }
  tuning.release();
  shutdownImGui();
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  Args a;
  CLI::App cli{"dynlab-ui — tune a lab's controller gains interactively and watch the mechanism move.\n"
               "Space: play/pause, R: restart. \"Save gains…\" writes a submission for `dynlab grade`."};
  cli.set_version_flag("--version", std::string(DYNLAB_VERSION));
  cli.add_option("LAB", a.lab, "Lab name (see `dynlab list`), or a model file (.xml, .urdf) to watch move passive")->required();
  cli.add_option("--config", a.config, "Lab config JSON (default: labs/LAB/LAB.json)");
  cli.add_option("--labs", a.labs, "A folder of lab folders outside the dynlab tree (repeatable; DYNLAB_LABS=DIR:DIR does the same)")
      ->type_name("DIR")->allow_extra_args(false);
  cli.add_option("--gains", a.gains, "Start from these gains: a submission or gains JSON");
  cli.add_option("--scenario", a.scenario, "Tune under one rubric scenario (heavy_load, noisy_sensor, ...) exactly as the grader runs it");
  cli.add_option("--student", a.student, "Tune on this student's plant (the lab's variants; DYNLAB_STUDENT_KEY, the key on "
                                          "their handout, or DYNLAB_COURSE_SECRET)");
  cli.add_option("--set", a.set, "NAME=VALUE: set a gain or an option (e.g. kp=500, law=integral: names the lab's JSON declares); repeatable");
  cli.add_option("--engine", a.engine, "hand, bullet, or both (Bullet drawn as a ghost)")->check(CLI::IsMember({"hand", "bullet", "both"}));
  cli.add_option("--speed", a.speed, "Simulated seconds per wall second")->check(CLI::Range(0.02, 20.0));
  cli.add_flag("--paused", a.paused, "Start paused");
  cli.add_option("--size", a.size, "Window size WIDTHxHEIGHT (default 1320x720)");
  cli.add_option("--save", a.save, "Where \"Save gains…\" writes (default LAB_gains.json); with --frames, saved after the last frame");
  auto* frames = cli.add_option("--frames", a.frames, "Scripted run: draw N frames (1/60 s of simulated time × speed each), then exit")
                     ->check(CLI::Range(1L, 1000000L));
  cli.add_option("--screenshot", a.screenshot, "With --frames: PNG of the whole window at the last frame")->needs(frames);
  cli.add_option("--state", a.state, "With --frames: JSON of what the last frame shows (row, t, values, scene viewport)")->needs(frames);
  cli.add_option("--key", a.files.key, "A model file: start from its keyframe NAME (qpos, qvel and the actuators' ctrl; default: qpos0 at rest, controls 0)");
  cli.add_flag("--ignore-contacts", a.files.ignore_contacts, "A model file: leave out the note that its geoms collide in MuJoCo but not here");
  cli.add_option("--package-path", a.files.package_paths, "A model file: a folder holding the packages its package://NAME/… paths name (repeatable)")
      ->allow_extra_args(false);
  try {
    cli.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = cli.exit(e);
    return code == 0 ? 0 : 2;
  }
  try {
    // Labs outside the tree, as dynlab's (app/cli/lab_options.h): --labs, then DYNLAB_LABS, after the tree's.
    std::vector<generic::LabsFolder> folders;
    for (const auto& dir : a.labs) folders.push_back({dir, "--labs"});
    for (const auto& f : generic::labsFoldersFromEnvironment()) folders.push_back(f);
    generic::useLabsFolders(folders);
    return run(a);
  } catch (const InputError& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "error: " << termName(e.what(), 1000) << "\n";
    return 1;
  }
}
