// What the bench commands share (app/cli/bench/bench.cpp, bench_scaling.cpp, bench_model.cpp): the timing (timing.h), MuJoCo's run, a scratch folder.
#pragma once
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "app/cli/bench/timing.h"

namespace dyn {
class Lab;
}

namespace dyn::app {

// dynlab bench LAB's MuJoCo run (app/cli/bench/bench_mujoco.cpp): mj_step, Euler, at the lab's dt on the lab's
// mechanism written for MuJoCo (Lab::mujocoTwin), passive from the lab's start.
struct MujocoRun {
  std::string file, scheme;  // the model file; "MuJoCo 2.2.2 mj_step, Euler, ..."
  std::string stands_in;     // what the file holds instead of what MuJoCo cannot ("" when nothing)
  std::string left_out;      // why MuJoCo is not timed ("" when it is)
  bool timed() const { return impl_ != nullptr; }
  bool step();     // one mj_step; false (and back to the start) when the state blew up
  void restart();  // back to the lab's start
  MujocoRun();
  ~MujocoRun();
  MujocoRun(MujocoRun&&) noexcept;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};
MujocoRun mujocoRun(const dyn::Lab& lab, const std::string& config_file);

// A folder of this bench's own under the temporary directory (mkdtemp: a fresh name, mode 0700), removed
// with its files when it goes: two benches at once, or a name someone else made first, never meet.
// Throws std::runtime_error (naming the folder) when none can be made.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& prefix);
  ~ScratchDir();
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

struct BenchArgs;
// dynlab bench FILE.xml|FILE.urdf: the hand step against Bullet's and MuJoCo's for a model file (app/cli/bench/bench_model.cpp).
int benchModel(const BenchArgs& args);

}  // namespace dyn::app
