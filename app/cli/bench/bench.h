// Timing helpers shared by the bench commands (app/cli/bench/bench.cpp, app/cli/bench/bench_scaling.cpp, app/cli/bench/bench_model.cpp).
#pragma once
#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace dyn {
class Lab;
}

namespace dyn::app {

// The middle value (0 for none).
double median(std::vector<double> v);
// The cost of one pair of clock reads (µs, median of many): subtracted from every timed sample, so
// a sub-microsecond step is not charged the timer's own ~20–50 ns.
double clockOverhead();
// How many times slower `slow` is than `fast`, block by block (timed side by side): the median, and
// the middle half of the blocks' ratios (how much the measurement itself moves).
struct Ratio {
  double median = 0, low = 0, high = 0;  // median, 25th and 75th percentiles
};
Ratio ratio(const std::vector<double>& slow, const std::vector<double>& fast);

// The one timing loop of every bench: `calls` calls of timed() (true when it counted), each between two
// clock reads less their cost `clock`; before() runs untimed first and skips the call when false. The
// median µs of the counted calls; each also appended to all.
template <class Before, class Timed>
double timedBlock(int calls, double clock, std::vector<double>& all, Before&& before, Timed&& timed) {
  using Clock = std::chrono::steady_clock;
  using Micros = std::chrono::duration<double, std::micro>;
  std::vector<double> times;
  for (int k = 0; k < calls; ++k) {
    if (!before()) continue;
    const auto t0 = Clock::now();
    const bool counted = timed();
    const double t = Micros(Clock::now() - t0).count() - clock;
    if (counted) times.push_back(t);
  }
  all.insert(all.end(), times.begin(), times.end());
  return median(times);
}

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
