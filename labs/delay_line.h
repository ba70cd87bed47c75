// A sensor's delay line (lecture §3: the force measurement arrives `delay` late): a ring of
// steps(delay, dt) samples; push() the newest each step, value() is the one pushed `steps` pushes
// ago. At least one step: what a sensor measures depends on the torque, which depends on what it saw.
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

namespace dyn {

class DelayLine {
 public:
  static long steps(double delay, double dt) { return std::max<long>(1, std::lround(delay / dt)); }
  // The delay the line realises (s): what a linearised loop should assume.
  static double realised(double delay, double dt) { return double(steps(delay, dt)) * dt; }

  DelayLine(double delay, double dt, double initial = 0.0) : ring_(std::size_t(steps(delay, dt)), initial) {}
  // Every sample, as if the sensor had read v since long before.
  void fill(double v) { std::fill(ring_.begin(), ring_.end(), v); }
  void push(double v) {
    head_ = (head_ + 1) % ring_.size();
    ring_[head_] = v;
  }
  double value() const { return ring_[(head_ + 1) % ring_.size()]; }

 private:
  std::vector<double> ring_;  // newest at head_
  std::size_t head_ = 0;
};

}  // namespace dyn
