// The bench's clock work (app/cli/bench/): step times in blocks, their medians and ratios. Nothing
// here asserts a speed; tests/app/bench_timing_test.cpp checks the statistics on made-up readings.
#pragma once
#include <chrono>
#include <cmath>
#include <vector>

namespace dyn::app {

// The steps of a block: every bench's engines take turns in blocks this long (the machine's speed
// wanders within milliseconds: side by side, each block catches the same phase).
constexpr int kBlock = 50;

// The middle value (0 for none); NaN entries (blocks left out, timedRun) are skipped.
double median(std::vector<double> v);
// The blocks that were timed (not NaN).
int countedBlocks(const std::vector<double>& blocks);
// The clock reads' cost (µs) as a call timed alone sees it (bench_scaling's steps, each timed alone):
// a sub-microsecond step is not charged the timer's own ~11 ns.
double clockOverhead();
// How many times slower `slow` is than `fast`, block by block (timed side by side): the median, and
// the middle half of the blocks' ratios (how much the measurement itself moves). Pairs with a NaN
// block are skipped.
struct Ratio {
  double median = 0, low = 0, high = 0;  // median, 25th and 75th percentiles
};
Ratio ratio(const std::vector<double>& slow, const std::vector<double>& fast);

// A block's time. The clock here ticks every ~10 ns: a 0.3 µs step timed alone reads 0.30 or 0.31 µs,
// and a median of such readings sticks to one tick (3 % of a ratio at that size). So a block is never
// summarised by its median call: its calls run back to back, timed together with one pair of clock
// reads (the tick and the reads' cost spread over the block). NaN (the block left out) when a call
// failed: its restart would be timed with the steps.
template <class Timed>
double timedRun(int calls, Timed&& timed) {
  using Clock = std::chrono::steady_clock;
  bool all = true;
  const auto t0 = Clock::now();
  for (int k = 0; k < calls; ++k) all = timed() && all;
  const double t = std::chrono::duration<double, std::micro>(Clock::now() - t0).count();
  return all && calls > 0 ? t / calls : std::nan("");
}
// The mean of the readings within twice their median, plus two ticks (NaN for none): calls timed one
// at a time (bench_scaling), where a median would stick to a tick and an interrupt is not the step.
double meanWithoutOutliers(const std::vector<double>& readings);

}  // namespace dyn::app
