// A coupling's row and bias; the maths is in coupling.h.
#include "physics/constraints/coupling.h"

#include <cmath>
#include <stdexcept>

namespace dyn {

Coupling::Coupling(const char* kind, Form first, Form second, const std::array<double, 5>& poly, const VecN& q0)
    : kind_(kind), first_(std::move(first)), second_(std::move(second)), poly_(poly), q0_(q0) {
  if (first_.empty()) throw std::invalid_argument("coupling: the first object needs at least one joint");
  for (const Form* f : {&first_, &second_})
    for (const Term& t : *f)
      if (t.joint < 0 || t.joint >= q0.size() || !std::isfinite(t.coef)) throw std::invalid_argument("coupling: a term names no tree joint or has a non-finite coefficient");
  for (double c : poly)
    if (!std::isfinite(c)) throw std::invalid_argument("coupling: polycoef must be finite");
}

double Coupling::value(const MechanismKinematics<Spatial>& k, const Form& f) const {
  double s = 0;
  for (const Term& t : f) {
    const int qi = k.model ? k.model->tree.bodies[std::size_t(t.joint)].q_index : t.joint;  // its coordinate in q (after any quaternion)
    s += t.coef * (k.theta[qi] - q0_[qi]);
  }
  return s;
}

double Coupling::rate(const MechanismKinematics<Spatial>& k, const Form& f) {
  double s = 0;
  for (const Term& t : f) s += t.coef * k.theta_rate[t.joint];
  return s;
}

void Coupling::position(const MechanismKinematics<Spatial>& k, int row, VecN& phi, MatN& J, MatN& A) const {
  (void)A;
  const auto& c = poly_;
  double p = 0, slope = 0;
  if (!second_.empty()) {
    const double s = value(k, second_);
    p = s * (c[1] + s * (c[2] + s * (c[3] + s * c[4])));
    slope = c[1] + s * (2 * c[2] + s * (3 * c[3] + s * 4 * c[4]));
  }
  phi[row] = value(k, first_) - c[0] - p;
  for (const Term& t : first_) J(row, t.joint) += t.coef;
  for (const Term& t : second_) J(row, t.joint) -= slope * t.coef;
}

void Coupling::bias(const MechanismKinematics<Spatial>& k, int row, VecN& b) const {
  b[row] = 0.0;
  if (second_.empty()) return;
  const auto& c = poly_;
  const double s = value(k, second_), w = rate(k, second_);
  b[row] = -(2 * c[2] + s * (6 * c[3] + s * 12 * c[4])) * w * w;
}

Spatial::Vec Coupling::force(const MechanismKinematics<Spatial>& k, const double* eta) const {
  (void)k, (void)eta;
  return Vec::Zero();
}

Spatial::Pos Coupling::point(const MechanismKinematics<Spatial>& k) const { return k.position(BodyRef::link(first_.front().joint), Pos::Zero()); }

Attachment<Spatial> Coupling::attachment() const {
  Attachment<Spatial> at;
  at.a = second_.empty() ? BodyRef::world() : BodyRef::link(second_.front().joint);
  at.b = BodyRef::link(first_.front().joint);
  if (at.a == at.b) at.a = BodyRef::world();  // a joint coupled to itself: validate() would refuse a == b
  return at;  // no rows: no Bullet joint models it (physics/bullet: a btMultiBodyGearConstraint when linear)
}

bool Coupling::linearPair() const {
  return first_.size() == 1 && second_.size() == 1 && poly_[2] == 0 && poly_[3] == 0 && poly_[4] == 0 && first_[0].joint != second_[0].joint;
}

}  // namespace dyn
