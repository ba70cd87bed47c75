// dynlab bench: speed is measured here, never asserted in tests.
//   hand vs Bullet: µs per step of each engine (the median of 50-step blocks, timing.h) on the lab's default config, and the ratio,
//     for the engine alone (advance the state one dt under the torques a full run applied: the headline) and for
//     the full simulation step (+ controller and trace row: energy, residual, constraint force);
//   and speed with accuracy: the hand engine also with Bullet's order of method (labs/settings.h
//     firstOrderPatch: one dynamics evaluation per step, as Bullet's own step), each run's error
//     against the reference (the lab's configured hand run) in the lab's measures of agreement;
//     the reference engine described by the lab (Lab::referenceEngine);
//   render, render+PNG, render+video: frames per second at 640×480 (MSAA 4, overlay on);
//   grading: CPU seconds of a full rubric grade of the lab's instructor/good.json.
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "app/cli/bench/bench.h"
#include "app/cli/commands.h"
#include "app/cli/model/model.h"
#include "app/shared/movie.h"
#include "labs/run.h"
#include "labs/utf8.h"
#include "render/video.h"

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace dyn::app {

ScratchDir::ScratchDir(const std::string& prefix) {
  std::string name = (fs::temp_directory_path() / (prefix + "-XXXXXX")).string();
  if (!mkdtemp(name.data())) throw std::runtime_error("dynlab bench: cannot make a scratch folder " + name + " (" + std::strerror(errno) + ")");
  path_ = name;
}

ScratchDir::~ScratchDir() {
  std::error_code ec;  // nothing to say if it is already gone
  fs::remove_all(path_, ec);
}

namespace {

// Wall times per step, µs, on every engine alike (timing.h timedRun: each block's steps back to back).
struct StepTimes {
  double full = 0;    // Simulation::step (controller, trace row, engine): the median block's
  double engine = 0;  // Simulation::advanceEngine replaying a full run's torques, the engine alone: the median block's
  bool has_engine = false;
  std::vector<double> full_blocks, engine_blocks;  // each block's µs per step
};

// The runs compared, timed in turn in short blocks (hand, Bullet, hand, ... 50 steps each): this
// machine's clock speed wanders by half within milliseconds (a fixed chain of multiply-adds takes 0.83
// to 1.26 µs from one 2 ms block to the next), so engines timed one after the other would each catch
// their own phase and their ratio would move by ±10 % from run to run. Blocks keep each engine's data
// in cache (one step each in turn would time the hand step after Bullet's had evicted it).
struct TimedRun {
  const Lab* lab;
  Engine engine;
};

// The engine pass: each run's engine alone is a second run of the same lab, replaying the torques the
// first (full steps, untimed) applied, so it takes the lab's own path with only the engine timed.
class EngineReplay {
 public:
  explicit EngineReplay(const std::vector<TimedRun>& runs) : runs_(runs), full_(runs.size()), alone_(runs.size()) {
    for (std::size_t i = 0; i < runs.size(); ++i) restart(i);
  }
  // One block of run i's engine alone, timed back to back (NaN: left out, both runs started again).
  double block(std::size_t i) {
    if (!record(i)) return std::nan("");
    std::size_t k = 0;
    const double t = timedRun(kBlock, [&] { return alone_[i]->advanceEngine(torques_[k++]); });
    if (std::isnan(t)) restart(i);
    return t;
  }

 private:
  void restart(std::size_t i) {
    full_[i] = runs_[i].lab->simulate(runs_[i].engine);
    alone_[i] = runs_[i].lab->simulate(runs_[i].engine);
  }
  // The next kBlock torques of run i's full run; where it ends or fails inside the block both runs start
  // again and the block is taken from the start. False if no whole block can be had (a short run, or
  // a lab without the engine alone: appliedTorque empty).
  bool record(std::size_t i) {
    for (int attempt = 0; attempt < 2; ++attempt) {
      torques_.clear();
      while (int(torques_.size()) < kBlock && full_[i]->step(row_)) {
        VecN tau = full_[i]->appliedTorque();
        if (tau.size() == 0) break;  // the row at the run's end (no step), or no engine alone
        torques_.push_back(std::move(tau));
      }
      if (int(torques_.size()) == kBlock) return true;
      restart(i);
    }
    return false;
  }
  const std::vector<TimedRun>& runs_;
  std::vector<std::unique_ptr<Simulation>> full_, alone_;
  std::vector<VecN> torques_;
  std::vector<double> row_;
};

// With a MuJoCo run (mujoco timed()): its steps timed last in each round (both passes alike: it has
// no controller), its times as out's last entry.
std::vector<StepTimes> stepMicros(const std::vector<TimedRun>& runs, int steps, MujocoRun& mujoco) {
  const std::size_t count = runs.size();
  StepTimes mj;
  // Every engine's steps are timed back to back in both passes, MuJoCo's as the others': in the engine
  // pass the hand's and Bullet's replay torques a full run computed untimed before the block (the
  // controller's work between two timed steps would leave each to start from its leavings: +18 % on the
  // pen's step with the same instructions, which MuJoCo's, back to back, never paid).
  auto mujocoBlock = [&](std::vector<double>& blocks) {
    if (mujoco.timed()) blocks.push_back(timedRun(kBlock, [&] { return mujoco.step(); }));
  };
  std::vector<double> row;
  std::vector<StepTimes> out(count);
  std::vector<std::unique_ptr<Simulation>> sims;
  auto restart = [&](std::size_t i) { sims[i] = runs[i].lab->simulate(runs[i].engine); };
  for (const TimedRun& r : runs) sims.push_back(r.lab->simulate(r.engine));
  // One block of run i's full steps, back to back (a failed one restarts the run; short runs wrap around).
  auto block = [&](std::size_t i) { return timedRun(kBlock, [&] { return sims[i]->step(row) || (restart(i), false); }); };
  const int rounds = std::max(1, steps / kBlock);
  for (int r = 0; r < rounds; ++r) {
    for (std::size_t i = 0; i < count; ++i) out[i].full_blocks.push_back(block(i));
    mujocoBlock(mj.full_blocks);
  }
  sims.clear();
  EngineReplay replay(runs);
  if (mujoco.timed()) mujoco.restart();
  for (int r = 0; r < rounds; ++r) {
    for (std::size_t i = 0; i < count; ++i) out[i].engine_blocks.push_back(replay.block(i));
    mujocoBlock(mj.engine_blocks);
  }
  for (StepTimes& t : out) {
    t.full = median(t.full_blocks);
    t.engine = median(t.engine_blocks);
    t.has_engine = countedBlocks(t.engine_blocks) > 0;
  }
  if (mujoco.timed()) {
    mj.full = median(mj.full_blocks);
    mj.engine = median(mj.engine_blocks);
    mj.has_engine = true;
    out.push_back(mj);
  }
  return out;
}

// Frames per second of draw+read (+ PNG, + video) over `frames` frames of the hand run.
struct Fps {
  double render = 0, png = 0, video = 0;
};

Fps frameRates(const Lab& lab, const Trace& trace, int frames) {
  auto context = makeOffscreenContext(640, 480);
  Renderer renderer(*context);
  const auto rows = frameRows(trace, lab.dt(), 30);
  const ScratchDir scratch("dynlab-bench");
  const fs::path& dir = scratch.path();
  auto run = [&](int mode) {
    std::unique_ptr<VideoWriter> video;
    if (mode == 2) video = std::make_unique<VideoWriter>((dir / "bench.mp4").string(), 640, 480, 30);
    const auto t0 = Clock::now();
    for (int k = 0; k < frames; ++k) {
      Scene scene;
      Overlay overlay;
      const std::size_t row = rows[std::size_t(k) % rows.size()];
      lab.scene(trace, row, nullptr, scene);
      lab.overlay(trace, row, overlay);
      const Image image = renderer.render(scene, &overlay);
      if (mode == 1) writePng((dir / "bench.png").string(), image, nullptr, PngEncoding::Fast);  // as run --frames writes them
      if (video) video->addFrame(image);
    }
    if (video) video->close();
    return frames / std::chrono::duration<double>(Clock::now() - t0).count();
  };
  run(0);  // warm up (shader compilation, first ImGui frame)
  return Fps{run(0), run(1), run(2)};
}

// "integrator + drift" of a config's simulation block, as labs/ parses it for every lab.
std::string schemeOf(const json& config, const std::string& file) {
  return schemeName(parseSimulation(JsonView(config, file)["simulation"], IndependentForm::Yes).step);
}

// The hand engine with a reference engine's order of method (labs/settings.h firstOrderPatch),
// unless the lab is configured that way already (lab null).
struct Variant {
  std::unique_ptr<Lab> lab;
  std::string scheme;
};
Variant firstOrderVariant(const LoadedLab& loaded) {
  const json config = mergePatch(loaded.config, firstOrderPatch());
  const std::string scheme = schemeOf(config, loaded.config_file);
  if (scheme == schemeOf(loaded.config, loaded.config_file)) return {nullptr, scheme};
  return {buildLab(*loaded.entry, config, loaded.config_file + " (bench: " + scheme + ")"), scheme};
}

// The lab's own measures of disagreement (numbers at the top level of Lab::agreement; counts left out).
json errorAgainst(const Lab& lab, const Trace& run, const Trace& reference) {
  const json agreement = lab.agreement(run, reference);
  json out = json::object();
  for (const auto& [k, v] : agreement.items())
    if (v.is_number_float()) out[k] = v;
  return out;
}

// MuJoCo's step against the hand's at equal order: its median µs and the ratios block by block.
struct MujocoTimes {
  StepTimes mujoco, hand;  // hand: the first-order hand run (or the lab's own when it is first order)
  bool alone = false;      // the hand's engine-alone blocks (else its full steps)
  double us() const { return alone ? mujoco.engine : mujoco.full; }
  double handUs() const { return alone ? hand.engine : hand.full; }
  Ratio over() const {
    return alone ? ratio(mujoco.engine_blocks, hand.engine_blocks) : ratio(mujoco.full_blocks, hand.full_blocks);
  }
};

void addMujoco(const MujocoRun& run, const MujocoTimes& t, const std::string& hand_scheme, json& out) {
  if (!run.timed()) {
    out["mujoco_left_out"] = run.left_out;
    return;
  }
  const Ratio r = t.over();
  out["mujoco_file"] = run.file;
  out["mujoco_scheme"] = run.scheme;
  if (!run.stands_in.empty()) out["mujoco_stands_in"] = run.stands_in;
  out["mujoco_us_per_step"] = t.us();
  out["mujoco_hand_scheme"] = hand_scheme;
  out["mujoco_hand_us_per_step"] = t.handUs();
  out["mujoco_over_hand_equal_order"] = r.median;
  out["mujoco_over_hand_equal_order_quartiles"] = {r.low, r.high};
}

// The MuJoCo line under the engines' (Bullet's ratio at the same order beside it, timed in the same run).
void printMujoco(const MujocoRun& run, const MujocoTimes& t, const std::string& hand_scheme, const Ratio& bullet) {
  if (!run.timed()) {
    std::printf("  MuJoCo not timed: %s\n", run.left_out.c_str());
    return;
  }
  const Ratio r = t.over();
  std::printf("  at equal order  hand %s %.2f µs   MuJoCo %.2f µs   MuJoCo/hand %.1fx (blocks %.1f–%.1f)   Bullet/hand %.1fx (blocks %.1f–%.1f)\n",
              hand_scheme.c_str(), t.handUs(), t.us(), r.median, r.low, r.high, bullet.median, bullet.low, bullet.high);
  std::printf("    MuJoCo: %s on %s%s\n", run.scheme.c_str(), termName(run.file, 300).c_str(),
              run.stands_in.empty() ? ", passive from the lab's start" : (", passive from the lab's start; stands in: " + run.stands_in).c_str());
}

}  // namespace

int bench(const BenchArgs& a) {
  if (isModelFile(a.lab)) return benchModel(a);  // a model file where a lab goes (app/cli/bench/bench_model.cpp)
  bool found = a.lab.empty();
  for (const auto& entry : labRegistry()) found = found || entry.name == a.lab;
  if (!found) {
    std::fprintf(stderr, "error: <command line>: LAB: unknown lab \"%s\" (see dynlab list)\n", a.lab.c_str());
    return 2;
  }
  for (const auto& entry : labRegistry()) {
    if (!a.lab.empty() && entry.name != a.lab) continue;
    LoadedLab loaded;
    try {
      loaded = loadLab(entry.name);
    } catch (const InputError& e) {
      std::fprintf(stderr, "error: %s\n", e.what());
      return 2;
    }
    const Lab& lab = *loaded.lab;
    const Variant variant = firstOrderVariant(loaded);
    const std::unique_ptr<Lab>& first_order = variant.lab;
    const std::string& first_scheme = variant.scheme;
    const std::string scheme = schemeOf(loaded.config, loaded.config_file);
    // Every engine timed in the same stretch of time, in turn (stepMicros).
    std::vector<TimedRun> runs{{&lab, Engine::Hand}, {&lab, Engine::Bullet}};
    if (first_order) runs.push_back({first_order.get(), Engine::Hand});
    MujocoRun mujoco = mujocoRun(lab, loaded.config_file);
    const std::vector<StepTimes> times = stepMicros(runs, a.steps, mujoco);
    const StepTimes hand_t = times[0], bullet_t = times[1];
    const StepTimes first_t = first_order ? times[2] : StepTimes{};
    // The headline compares the engines alone, when the lab offers it.
    const bool alone = hand_t.has_engine && bullet_t.has_engine;
    const double hand = alone ? hand_t.engine : hand_t.full, bullet = alone ? bullet_t.engine : bullet_t.full;
    // Speed with accuracy: errors of whole runs against the configured hand run.
    const RunResult reference = runEngine(lab, Engine::Hand);
    const json bullet_error = errorAgainst(lab, runEngine(lab, Engine::Bullet).trace, reference.trace);
    json first_error;
    if (first_order) first_error = errorAgainst(lab, runEngine(*first_order, Engine::Hand).trace, reference.trace);
    const double first_us = first_t.has_engine ? first_t.engine : first_t.full;
    // Ratios from the blocks timed side by side (stepMicros), not from the overall medians.
    auto blocks = [&](const StepTimes& t) -> const std::vector<double>& { return alone ? t.engine_blocks : t.full_blocks; };
    const Ratio speedup = ratio(blocks(bullet_t), blocks(hand_t));
    const Ratio speedup_full = ratio(bullet_t.full_blocks, hand_t.full_blocks);
    const Ratio speedup_first = first_order ? ratio(blocks(bullet_t), blocks(first_t)) : Ratio{};
    // MuJoCo (Euler) against the hand at equal order (its first-order variant, or the lab's own when first order).
    const MujocoTimes mj = mujoco.timed() ? MujocoTimes{times.back(), first_order ? first_t : hand_t, alone} : MujocoTimes{};
    const Fps fps = frameRates(lab, reference.trace, a.frames);
    const json grading = gradeThroughput(entry.name, 5);
    if (a.json) {
      json out = {{"lab", entry.name},
                  {"step_timed", alone ? "engine" : "full"},
                  {"hand_us_per_step", hand},
                  {"bullet_us_per_step", bullet},
                  {"bullet_over_hand", speedup.median},
                  {"bullet_over_hand_quartiles", {speedup.low, speedup.high}},
                  {"hand_full_us_per_step", hand_t.full},
                  {"bullet_full_us_per_step", bullet_t.full},
                  {"bullet_over_hand_full", speedup_full.median},
                  {"hand_scheme", scheme},
                  {"bullet_error", bullet_error},
                  {"render_fps", fps.render},
                  {"render_png_fps", fps.png},
                  {"render_video_fps", fps.video},
                  {"resolution", "640x480"}};
      if (first_order) {
        out["hand_first_order_scheme"] = first_scheme;
        out["hand_first_order_us_per_step"] = first_us;
        out["bullet_over_hand_first_order"] = speedup_first.median;
        out["bullet_over_hand_first_order_quartiles"] = {speedup_first.low, speedup_first.high};
        out["hand_first_order_error"] = first_error;
      }
      addMujoco(mujoco, mj, first_order ? first_scheme : scheme, out);
      for (const auto& [k, v] : grading.items()) out[k] = v;
      std::cout << out.dump() << "\n";
    } else {
      std::printf("%s\n", entry.name.c_str());
      if (alone)
        std::printf("  engine step     hand %.2f µs   Bullet %.2f µs   Bullet/hand %.1fx   (median block of %d; the controller's torques replayed)\n",
                    hand, bullet, speedup.median, kBlock);
      std::printf("  full step       hand %.2f µs   Bullet %.2f µs   Bullet/hand %.1fx   (median block of %d; + controller, trace row)\n",
                  hand_t.full, bullet_t.full, speedup_full.median, kBlock);
      std::printf("  speed and error of whole runs against the reference (hand, %s, dt %g s):\n", scheme.c_str(), lab.dt());
      std::printf("    hand   %-34s %6.2f µs   reference\n", scheme.c_str(), hand);
      // The first-order ratio with the middle half of its blocks; the Bullet line's errors aligned under it.
      char ratio_text[96] = "";
      if (first_order) {
        std::snprintf(ratio_text, sizeof ratio_text, "Bullet/hand %.1fx (blocks %.1f–%.1f)", speedup_first.median, speedup_first.low,
                      speedup_first.high);
        std::printf("    hand   %-34s %6.2f µs   %s   %s\n", first_scheme.c_str(), first_us, ratio_text,
                    describeAgreement(lab, first_error).c_str());
      }
      const int pad = int(std::string(ratio_text).size()) - 2;  // "–" is 3 bytes, 1 column
      std::printf("    %-41s %6.2f µs   %*s   %s\n", lab.referenceEngine().c_str(), bullet, std::max(pad, 0), "",
                  describeAgreement(lab, bullet_error).c_str());
      printMujoco(mujoco, mj, first_order ? first_scheme : scheme, speedup_first.median > 0 ? speedup_first : speedup);
      std::printf("  640x480 fps     render %.0f   +PNG %.0f   +video %.0f\n", fps.render, fps.png, fps.video);
      if (!grading.empty())
        std::printf("  grading         %.3f s CPU per full rubric (%.3f s with plots): %.0f per s per core, 1000 with plots on 2 cores in %.0f s\n",
                    grading["grade_cpu_s"].get<double>(), grading["grade_cpu_s_with_plots"].get<double>(),
                    grading["grade_per_s_per_core"].get<double>(), grading["class_of_1000_on_2_cores_s"].get<double>());
    }
  }
  return 0;
}

}  // namespace dyn::app
