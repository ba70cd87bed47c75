// The description's joint-space constraints in Bullet 3.24 (spatial_mechanism.cpp's builder):
//   joint_limit     one btMultiBodyJointLimitConstraint per limited joint, holding both its sides (a
//                   side the description does not limit sits at ±1e30). Bullet's limit differs from
//                   the hand engine's event: a row exists only once the joint is at or past its stop
//                   (no located touchdown), it is plastic (restitution 0: the rate into the stop goes to
//                   0) and its penetration is pushed out by the solver's ERP over the next steps
//                   (Baumgarte, m_erp = 0.2 per step): the joint overshoots by about its rate × dt, then
//                   comes back. Force: the row's impulse / dt as σ η a (joint_limit.h).
//   joint_coupling  linear, one joint each side (φ = a (θ₁ − θ₁₀) − c₁ b (θ₂ − θ₂₀)): a
//                   btMultiBodyGearConstraint θ'₁ + r θ'₂ = 0, r = −c₁ b / a, with the position error
//                   pulled back at ERP kGearErp to its target θ₁₀ + r θ₂₀. Force: the impulse / dt in
//                   the force's first entry (coupling.h: it is no spatial force). Nonlinear (c₂…c₄) and
//                   tendon couplings are refused (Bullet has no such joint constraint).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "physics/mechanism.h"

class btMultiBody;
class btMultiBodyConstraint;
class btMultiBodyDynamicsWorld;

namespace dyn::bullet {

class JointConstraints {
 public:
  // Empty when Bullet can hold constraint k (a joint limit or a linear joint coupling) or when k is no
  // joint-space kind; else why not.
  static std::string refusal(const Constraint<Spatial>& k);
  static bool isJointKind(const Constraint<Spatial>& k);
  // Builds description constraint c (a joint-space kind) on the multibody's links (the description's
  // joint i is link i), into the world; `owned` keeps it.
  void add(btMultiBodyDynamicsWorld& world, btMultiBody& body, const MechanismModel<Spatial>& model, int c, double max_impulse,
           std::vector<std::unique_ptr<btMultiBodyConstraint>>& owned);
  // After a step: each built constraint's force over it (per description constraint, as above).
  void forces(const btMultiBody& body, double dt, std::vector<Spatial::Vec>& force) const;
  bool empty() const { return limits_.empty() && gears_.empty(); }
  std::string describe() const;

 private:
  struct Limit {
    int joint = -1, lower = -1, upper = -1;  // the description constraints of its two sides (−1: none)
    btMultiBodyConstraint* bt = nullptr;
  };
  struct Gear {
    int constraint = -1;
    btMultiBodyConstraint* bt = nullptr;
  };
  std::vector<Limit> limits_;
  std::vector<Gear> gears_;
};

}  // namespace dyn::bullet
