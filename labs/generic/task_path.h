// A reference path as data (a data-defined lab's "trajectory"): from the tool's start point, a list of
// segments, each smooth to the second derivative at its ends (quintic timing s(τ) = 10τ³ − 15τ⁴ + 6τ⁵,
// so velocity and acceleration are zero where segments meet):
//   {"move": [x, ...], "time": T}       a straight line to the point
//   {"hold": T}                         stay
//   {"circle": [cx, cz], "turns": n, "time": T}   (two axes) round a centre, from the current point:
//                                       angle ψ0 + 2πn s(τ), radius = the current point's distance
// Coordinates are the task's axes (world metres, e.g. x and z of the tool). After the last segment the
// path holds its end point.
// "space": "joint" makes it a joint path over the actuated coordinates instead, from their start, fed to
// the joint laws without inverse kinematics: {"move_deg": [θ1, ...], "time": T} (degrees),
// {"move": [...], "time": T} (the coordinates' own units: rad, m) and {"hold": T}; no circles.
#pragma once
#include <string>
#include <vector>

#include "labs/config.h"
#include "physics/types.h"

namespace dyn::generic {

class TaskPath {
 public:
  // Whether "trajectory" is a joint path ("space": "joint"; default "task").
  static bool isJointSpace(const JsonView& j);
  // Parses "trajectory": {"segments": [...]} for `dims` task axes (or actuated coordinates), starting at
  // `start`; every coordinate within ±max_coordinate.
  TaskPath(const JsonView& j, const VecN& start, double max_coordinate);
  // The path at t: position, velocity and acceleration.
  void at(double t, VecN& x, VecN& xd, VecN& xdd) const;
  double duration() const { return end_; }
  // Segment i (in the JSON's order) runs over [segmentStart(i), segmentStart(i) + segmentTime(i)]; a hold stays put.
  std::size_t segments() const { return segments_.size(); }
  double segmentStart(std::size_t i) const { return segments_[i].t0; }
  double segmentTime(std::size_t i) const { return segments_[i].T; }
  bool segmentHolds(std::size_t i) const { return segments_[i].kind == Segment::Kind::Hold; }
  bool joint() const { return joint_; }

 private:
  struct Segment {
    enum class Kind { Move, Hold, Circle } kind;
    double t0, T;
    VecN from, to;           // move: ends; hold: the point; circle: the start point and the centre
    double radius = 0, psi0 = 0, sweep = 0;
  };
  std::vector<Segment> segments_;
  VecN start_;
  double end_ = 0;
  bool joint_ = false;
};

}  // namespace dyn::generic
