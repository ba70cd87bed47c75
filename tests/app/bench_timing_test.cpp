// The bench's timing statistics (app/cli/bench/timing.h) on made-up readings: no speed is asserted.
// The clock ticks every ~10 ns, so a step's readings come in whole ticks; what a block reports must
// not stick to a tick, leave out an interrupted call, and a block left out must not pair with another.
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "app/cli/bench/timing.h"

using namespace dyn::app;

TEST_CASE("a block's mean of readings in whole ticks is not stuck to a tick, and an interrupted call is left out") {
  // A 0.3125 µs step read on a 10 ns clock: a quarter of the readings 0.32, the rest 0.31 (the tick's
  // phase is random), and one call interrupted for 40 µs.
  std::vector<double> readings;
  for (int k = 0; k < 400; ++k) readings.push_back(k % 4 == 0 ? 0.32 : 0.31);
  readings.push_back(40.0);
  CHECK(median(readings) == doctest::Approx(0.31));  // the median sticks to the tick
  CHECK(meanWithoutOutliers(readings) == doctest::Approx(0.3125).epsilon(1e-12));
  // Two ticks' grace above twice the median: a reading of 0.63 still counts (not an interrupt).
  CHECK(meanWithoutOutliers({0.31, 0.31, 0.63}) == doctest::Approx((0.31 + 0.31 + 0.63) / 3));
  CHECK(std::isnan(meanWithoutOutliers({})));
}

TEST_CASE("blocks left out (NaN) are skipped by the median and by the ratios' pairs") {
  const double nan = std::nan("");
  CHECK(median({nan, 1.0, nan, 3.0, 2.0}) == 2.0);
  CHECK(median({nan, nan}) == 0.0);
  // Block 1 of the slow engine and block 2 of the fast one were left out: pairs 0 and 3 remain.
  const Ratio r = ratio({2.0, nan, 9.0, 6.0}, {1.0, 1.0, nan, 2.0});
  CHECK(r.median == 3.0);
  CHECK(r.low == 2.0);
  CHECK(r.high == 3.0);
}

TEST_CASE("timedRun: µs per call of a block, left out when a call failed") {
  int calls = 0;
  const double t = timedRun(50, [&] { return ++calls, true; });
  CHECK(calls == 50);
  CHECK(t >= 0.0);
  CHECK(!std::isnan(t));
  calls = 0;
  CHECK(std::isnan(timedRun(50, [&] { return ++calls != 7; })));
  CHECK(calls == 50);  // the block still runs to its end (the engines take turns in whole blocks)
}
