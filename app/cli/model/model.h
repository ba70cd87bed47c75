// `dynlab model FILE`: a mechanism from an MJCF or URDF file (physics/model_file): loads it, prints
// what dynlab read (bodies, joints, closures and their kept rows, the freedom left, notes), checks M
// and the bias against MuJoCo's own, runs it passive (or with constant joint torques, --torque) with
// the hand engine (RK4 + projection) and/or Bullet and reports each one's closure residual and energy
// balance and their agreement; writes
// OUT/trace.csv (hand), OUT/trace_bullet.csv and OUT/summary.txt, and with --video / --frames the run
// drawn from the file's geoms (labs/model_scene.h): OUT/video.mp4, OUT/frames/NNNNN.png.
// With dynlab's own elements beside the file (STEM.loops.json: rolling wheels, plane contacts) the hand
// engine steps as the labs do (contacts closed and opened, touchdowns located) and the trace names each
// element's forces (normal, tangential or wheel-axes components), gap or slip, and the touchdowns' energy.
// `dynlab run FILE.xml|FILE.urdf` (a model file where a lab name goes) is the same command. FILE may be a
// description (DESC.json) that `dynlab model FILE --export DESC.json` wrote: read without MuJoCo, the same runs.
// Registered on the command line by ModelCommand, so main.cpp only constructs it and asks it to run.
#pragma once
#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "labs/generic/model_lab.h"
#include "labs/run.h"

namespace dyn::app {

// The steps a model file runs at (--dt, or the file's <option timestep>), s.
inline constexpr double kMinDt = 1e-5, kMaxDt = 1e-2;

struct ModelArgs {
  std::string file, out, engine = "both";
  std::string loops;  // closures beside the file (labs/generic/model_loops.h); "": STEM.loops.json when it exists
  double duration = 2.0;  // s
  double dt = 0;          // s; 0: the file's <option timestep>
  ModelFileFlags files;   // --ignore-contacts, --package-path, --key
  bool video = false, frames = false;  // 30 frames per second of simulated time, 640×480
  std::vector<std::string> torques;    // "JOINT=VALUE": constant torques (N·m; N on a slide); none: passive
  std::string export_to;  // --export DESC.json: write the description (labs/generic/model_description.h) and run nothing
};

// --ignore-contacts, --key NAME and --package-path DIR (repeatable) on a command that reads model files (model, run,
// figure, bench), into flags.
void addModelFileOptions(CLI::App* command, ModelFileFlags& flags);

// 0, or 2 after one line on stderr when model-file options (`--ignore-contacts`, `--key`, `--package-path`) are
// given for a lab, not a model file.
int refuseModelFileFlags(const std::string& lab, const ModelFileFlags& flags);

struct RunArgs;
// `dynlab run FILE`: the run's options onto `dynlab model FILE`'s (lab-only options refused: exit 2).
int runModelFile(const RunArgs& args);

// 0 ran and wrote; 1 the run failed (projection, non-finite state) or a write failed; 2 bad input
// (one line, nothing written).
int model(const ModelArgs& args);

class ModelCommand {
 public:
  explicit ModelCommand(CLI::App& cli);
  bool chosen() const { return bool(*command_); }
  int run() const { return model(args_); }

 private:
  ModelArgs args_;
  CLI::App* command_ = nullptr;
};

}  // namespace dyn::app
