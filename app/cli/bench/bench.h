// Timing helpers shared by the bench commands (app/cli/bench/bench.cpp, app/cli/bench/bench_scaling.cpp, app/cli/bench/bench_model.cpp).
#pragma once
#include <chrono>
#include <vector>

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

struct BenchArgs;
// dynlab bench FILE.xml|FILE.urdf: the hand step against Bullet's and MuJoCo's for a model file (app/cli/bench/bench_model.cpp).
int benchModel(const BenchArgs& args);

}  // namespace dyn::app
