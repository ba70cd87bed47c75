// The bench's timing statistics (timing.h): blocks' means, medians and ratios, the clock's cost.
#include "app/cli/bench/timing.h"

#include <algorithm>

namespace dyn::app {

using Clock = std::chrono::steady_clock;

double median(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return std::isnan(x); }), v.end());
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

int countedBlocks(const std::vector<double>& blocks) {
  return int(std::count_if(blocks.begin(), blocks.end(), [](double x) { return !std::isnan(x); }));
}

double meanWithoutOutliers(const std::vector<double>& readings) {
  const double limit = 2 * median(readings) + 0.02;
  double sum = 0;
  int count = 0;
  for (double t : readings)
    if (t <= limit) sum += t, ++count;
  return count ? sum / count : std::nan("");
}

Ratio ratio(const std::vector<double>& slow, const std::vector<double>& fast) {
  std::vector<double> r;
  for (std::size_t k = 0; k < slow.size() && k < fast.size(); ++k)
    if (fast[k] > 0 && slow[k] > 0) r.push_back(slow[k] / fast[k]);  // (false for NaN)
  if (r.empty()) return {};
  std::sort(r.begin(), r.end());
  return {r[r.size() / 2], r[r.size() / 4], r[(3 * r.size()) / 4]};
}

namespace {
// A fixed piece of work, ~0.25 µs: a chain of multiply-adds through memory the compiler must keep.
void fixedWork() {
  static volatile double x = 1.0;
  for (int j = 0; j < 60; ++j) x = x * 1.0000001 + 1e-9;
}
}  // namespace

double clockOverhead() {
  // Not the cost of two clock reads in a row (~23 ns here): the reads overlap the work around them,
  // so a call timed alone is charged less than that (~11 ns). The cost a timed call sees is measured
  // on the fixed work, timed back to back and each call alone, block by block side by side (the
  // machine's speed wanders): the median of the blocks' differences.
  using Micros = std::chrono::duration<double, std::micro>;
  constexpr int kCalls = 50;
  std::vector<double> differences;
  for (int b = 0; b < 200; ++b) {
    const double together = timedRun(kCalls, [] { return fixedWork(), true; });
    double alone = 0;
    for (int k = 0; k < kCalls; ++k) {
      const auto t0 = Clock::now();
      fixedWork();
      alone += Micros(Clock::now() - t0).count();
    }
    differences.push_back(alone / kCalls - together);
  }
  return std::max(0.0, median(differences));
}

}  // namespace dyn::app
