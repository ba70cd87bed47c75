// The screening's pieces (linearise.cpp), for the lab and its tests: one joint's loop about rest,
// the other joints held, rigid or flexible (lecture §4, §1).
#pragma once
#include <Eigen/Core>

#include "labs/motion_control/mechanism.h"
#include "physics/linear.h"

namespace dyn::motion_control {

// A flexible joint i with the others held (their motors and springs locked), about rest at link
// angles θ: the rotor J_m on the motor side (with the joint's viscous friction b), the spring k, and
// the link-side inertia m_L of everything outboard about the joint. Motor θm, link θ:
//   J_m θm'' + b θm' + k (θm − θ) = τ,   m_L θ'' + k (θ − θm) = 0
//   ⇒ θm/τ = (m_L s² + k) / (s (J_m m_L s³ + b m_L s² + (J_m + m_L) k s + b k))
struct FlexibleJoint {
  double rotor = 0, stiffness = 0, link = 0, viscous = 0;  // J_m, k, m_L (kg·m²), b
};
// Read from the flexible tree's mass matrix at θ (δ = 0): M(θm_i, θm_i) = J_m + m_L, M(δ_i, δ_i) = m_L.
FlexibleJoint flexibleJoint(const Params& plant, const Eigen::VectorXd& theta, int i);

// The least damped complex pole pair of a closed loop: natural frequency |p|, damped frequency
// Im p (what the twist rings at), ζ = −Re p/|p| (negative: it grows). found = false without one.
struct Mode {
  bool found = false;
  double natural = 0, damped = 0, damping = 1;  // rad/s, rad/s, 1
};
Mode leastDampedMode(const LoopAnalysis& a);

// A mode damped less than this is flagged: it decays to a tenth only after ln 10/(2πζ) ≈ 3.7
// periods and amplifies what the trajectory puts near its frequency by 1/(2ζ) = 5 or more.
inline constexpr double kLightDamping = 0.1;

}  // namespace dyn::motion_control
