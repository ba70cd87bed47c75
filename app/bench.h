// Timing helpers shared by the bench commands (app/bench.cpp, app/bench_scaling.cpp).
#pragma once
#include <vector>

namespace dyn::app {

// The middle value (0 for none).
double median(std::vector<double> v);
// The cost of one pair of clock reads (µs, median of many): subtracted from every timed sample, so
// a sub-microsecond step is not charged the timer's own ~20–50 ns.
double clockOverhead();

struct BenchArgs;
// dynlab bench FILE.xml|FILE.urdf: the hand step against Bullet's and MuJoCo's for a model file (app/bench_model.cpp).
int benchModel(const BenchArgs& args);

}  // namespace dyn::app
