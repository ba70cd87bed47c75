// Where a joint's Coulomb friction F_c tanh(θ'/w) turns (mechanism.h JointProperties): within a few
// widths w of θ' = 0 it is a damper of F_c/w (100 N·m·s/rad for F_c = 1 N·m at w = 0.01 rad/s) and a
// turn-over in w/|θ''|, which an RK4 step of 1 ms does not resolve (2.5e-4 rad off over a PID run,
// fourth order only below 0.25 ms); outside them it is a constant ±F_c that any step resolves. A step
// of h from rate θ' with acceleration θ'' (its first stage) is near the turn when
//   |θ'| < widths·w + 2|θ''| h
// (θ' starts in the band, or may reach it or cross zero within the step; the 2 for θ'' changing
// inside it). A system refines such steps (integrate.h ConstrainedSystem::refine): the decision a
// function of the step's start only, so a run stays deterministic.
#pragma once
#include <cmath>
#include <vector>

#include "physics/mechanism.h"

namespace dyn {

inline bool nearFrictionTurn(const JointProperties& j, double rate, double accel, double h, double widths) {
  return j.coulomb != 0 && std::abs(rate) < widths * j.coulomb_width + 2 * std::abs(accel) * h;
}

// Any tree joint (rates v, accelerations a: the joints' first) near its friction's turn.
inline bool nearFrictionTurn(const std::vector<JointProperties>& joints, const VecN& v, const VecN& a, double h,
                             double widths) {
  for (std::size_t i = 0; i < joints.size(); ++i)
    if (nearFrictionTurn(joints[i], v[Eigen::Index(i)], a[Eigen::Index(i)], h, widths)) return true;
  return false;
}

}  // namespace dyn
