// Joint limits and linear joint couplings as Bullet multibody constraints: see joint_constraints.h.
#include "physics/bullet/joint_constraints.h"

#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <BulletDynamics/Featherstone/btMultiBodyGearConstraint.h>
#include <BulletDynamics/Featherstone/btMultiBodyJointLimitConstraint.h>

#include <optional>
#include <tuple>
#include <utility>
#include <vector>

#include "physics/constraints/coupling.h"
#include "physics/constraints/joint_limit.h"

namespace dyn::bullet {
namespace {
constexpr double kGearErp = 0.2;     // the coupling's position error pulled back per step (Bullet's m_erp)
constexpr double kUnlimited = 1e30;  // a side the description does not limit

// A coupling a gear holds: linear (c₂ = c₃ = c₄ = 0) in exactly two joints, whatever its forms (a joint
// against a joint, or a fixed tendon over two joints held to its length): φ = α (θ_a − θ₀_a) + β (θ_b −
// θ₀_b), so θ_a + (β/α) θ_b stays at its value at θ₀. The two joints and β/α; none when it is not so.
struct GearForm {
  int a = -1, b = -1;
  double ratio = 0;
};
std::optional<GearForm> gearForm(const Coupling& c) {
  const auto& p = c.poly();
  if (p[2] != 0 || p[3] != 0 || p[4] != 0) return std::nullopt;
  std::vector<std::pair<int, double>> coef;  // (joint, its coefficient in φ), in the forms' order
  auto add = [&](int joint, double x) {
    for (auto& [j, c] : coef)
      if (j == joint) return void(c += x);
    coef.emplace_back(joint, x);
  };
  for (const Coupling::Term& t : c.first()) add(t.joint, t.coef);
  for (const Coupling::Term& t : c.second()) add(t.joint, -p[1] * t.coef);
  std::erase_if(coef, [](const auto& jc) { return jc.second == 0; });
  if (coef.size() != 2) return std::nullopt;
  return GearForm{coef[0].first, coef[1].first, coef[1].second / coef[0].second};
}
}  // namespace

bool JointConstraints::isJointKind(const Constraint<Spatial>& k) {
  return dynamic_cast<const JointLimit*>(&k) || dynamic_cast<const Coupling*>(&k);
}

std::string JointConstraints::refusal(const Constraint<Spatial>& k) {
  const auto* c = dynamic_cast<const Coupling*>(&k);
  if (!c || gearForm(*c)) return {};
  return std::string(k.kind()) + ": Bullet holds a linear coupling of two joints only (polycoef \"0 c1 0 0 0\" between two <joint>s, or a fixed tendon over two joints); "
         "it runs in the hand engine alone (--engine hand on model, run and figure)";
}

void JointConstraints::add(btMultiBodyDynamicsWorld& world, btMultiBody& body, const MechanismModel<Spatial>& model, int c, double max_impulse,
                           std::vector<std::unique_ptr<btMultiBodyConstraint>>& owned) {
  const Constraint<Spatial>& k = *model.constraints[std::size_t(c)];
  std::unique_ptr<btMultiBodyConstraint> made;
  if (const auto* jl = dynamic_cast<const JointLimit*>(&k)) {
    const bool lower = jl->side() == JointLimit::Side::Lower;
    for (Limit& l : limits_)
      if (l.joint == jl->joint()) {  // the other side of a joint already built
        auto* bt = static_cast<btMultiBodyJointLimitConstraint*>(l.bt);
        lower ? bt->setLowerBound(jl->bound()) : bt->setUpperBound(jl->bound());
        (lower ? l.lower : l.upper) = c;
        return;
      }
    made = std::make_unique<btMultiBodyJointLimitConstraint>(&body, jl->joint(), lower ? jl->bound() : -kUnlimited, lower ? kUnlimited : jl->bound());
    limits_.push_back({jl->joint(), lower ? c : -1, lower ? -1 : c, made.get()});
  } else {
    const auto& cp = static_cast<const Coupling&>(k);
    const GearForm g = *gearForm(cp);  // refusal() turned away the rest
    auto gear = std::make_unique<btMultiBodyGearConstraint>(&body, g.a, &body, g.b, btVector3(0, 0, 0), btVector3(0, 0, 0),
                                                            btMatrix3x3::getIdentity(), btMatrix3x3::getIdentity());
    gear->setGearRatio(g.ratio);
    gear->setErp(kGearErp);
    gear->setRelativePositionTarget(cp.reference()[g.a] + g.ratio * cp.reference()[g.b]);
    made = std::move(gear);
    gears_.push_back({c, made.get()});
  }
  made->setMaxAppliedImpulse(max_impulse);
  world.addMultiBodyConstraint(made.get());
  made->finalizeMultiDof();
  owned.push_back(std::move(made));
}

void JointConstraints::forces(const btMultiBody& body, double dt, std::vector<Spatial::Vec>& force) const {
  for (const Limit& l : limits_) {
    const auto& link = body.getLink(l.joint);
    const bool turns = link.m_jointType == btMultibodyLink::eRevolute;
    const btVector3 axis = body.localDirToWorld(l.joint, turns ? link.m_axes[0].m_topVec : link.m_axes[0].m_bottomVec);
    for (const auto& [c, row, sign] : {std::tuple{l.lower, 0, 1.0}, std::tuple{l.upper, 1, -1.0}}) {
      if (c < 0) continue;
      const double eta = l.bt->getAppliedImpulse(row) / dt;
      Spatial::Vec f = Spatial::Vec::Zero();
      for (int i = 0; i < 3; ++i) f[(turns ? 0 : 3) + i] = sign * eta * axis[i];
      force[std::size_t(c)] = f;
    }
  }
  for (const Gear& g : gears_) {
    Spatial::Vec f = Spatial::Vec::Zero();
    f[0] = g.bt->getAppliedImpulse(0) / dt;
    force[std::size_t(g.constraint)] = f;
  }
}

std::string JointConstraints::describe() const {
  std::string s;
  if (!limits_.empty()) s += ", " + std::to_string(limits_.size()) + " btMultiBodyJointLimitConstraint joint limit(s)";
  if (!gears_.empty()) s += ", " + std::to_string(gears_.size()) + " btMultiBodyGearConstraint joint coupling(s)";
  return s;
}

}  // namespace dyn::bullet
