// A joint limit's row, force and report; the maths is in joint_limit.h. The mechanism decides when the
// row is closed (constrained_mechanism_contacts.h), as for a plane contact.
#include "physics/constraints/joint_limit.h"

#include <cmath>
#include <stdexcept>

namespace dyn {

JointLimit::JointLimit(int joint, int parent, Side side, double bound) : joint_(joint), parent_(parent), side_(side), bound_(bound) {
  if (joint < 0 || parent >= joint) throw std::invalid_argument("joint_limit: expected a tree joint after its parent");
  if (!std::isfinite(bound)) throw std::invalid_argument("joint_limit: the bound must be finite");
}

void JointLimit::position(const MechanismKinematics<Spatial>& k, int row, VecN& phi, MatN& J, MatN& A) const {
  (void)A;
  phi[row] = -gap(k);
  J(row, joint_) = -sign();
}

void JointLimit::bias(const MechanismKinematics<Spatial>& k, int row, VecN& b) const {
  (void)k;
  b[row] = 0.0;
}

namespace {
// The joint's axis in world axes, and whether it turns (a hinge) or slides.
Spatial::Pos worldAxis(const MechanismKinematics<Spatial>& k, int joint, bool& turns) {
  const auto& body = k.model->tree.bodies[std::size_t(joint)];
  turns = body.joint == JointType::Revolute;
  return k.direction(BodyRef::link(joint), body.axis.normalized());
}
}  // namespace

Spatial::Vec JointLimit::force(const MechanismKinematics<Spatial>& k, const double* eta) const {
  bool turns = false;
  const Pos a = worldAxis(k, joint_, turns);
  Vec f = Vec::Zero();
  (turns ? f.head<3>() : f.tail<3>()) = sign() * eta[0] * a;
  return f;
}

double JointLimit::along(const MechanismKinematics<Spatial>& k, const Vec& f) const {
  bool turns = false;
  const Pos a = worldAxis(k, joint_, turns);
  return sign() * a.dot(turns ? Pos(f.head<3>()) : Pos(f.tail<3>()));
}

Spatial::Pos JointLimit::point(const MechanismKinematics<Spatial>& k) const { return k.position(BodyRef::link(joint_), Pos::Zero()); }

Attachment<Spatial> JointLimit::attachment() const {
  Attachment<Spatial> at;
  at.a = parent_ < 0 ? BodyRef::world() : BodyRef::link(parent_);
  at.b = BodyRef::link(joint_);
  return at;  // no rows: no Bullet joint models it (physics/bullet: a btMultiBodyJointLimitConstraint)
}

void JointLimit::report(const MechanismKinematics<Spatial>& k, const double* eta, double* out) const {
  out[0] = gap(k);
  out[1] = eta[0];
}

}  // namespace dyn
