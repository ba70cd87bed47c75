// Point contact with friction: the rows of a point closure, reported in contact axes (point_contact.h).
#include "physics/constraints/point_contact.h"

#include <cmath>

namespace dyn {

template <class S>
PointContact<S>::PointContact(BodyRef a, const Pos& point_a, BodyRef b, const Pos& point_b, const Pos& normal_b, double mu)
    : PointClosure<S>(a, point_a, b, point_b, PointClosure<S>::translations()), normal_b_(normal_b.normalized()), mu_(mu) {}

template <class S>
typename S::Pos PointContact<S>::normal(const MechanismKinematics<S>& k) const {
  return k.direction(this->attachment().b, normal_b_);
}

template <class S>
void PointContact<S>::contactAxes(const Pos& f, const Pos& n, double mu, double* out) {
  const double f_n = -f.dot(n);
  double f_t;
  if constexpr (S::kDim == 3) {
    f_t = f.dot(Pos(-n.y(), n.x()));  // t = ẑ × n
  } else {
    f_t = (f - f.dot(n) * n).norm();
  }
  out[0] = f_n;
  out[1] = f_t;
  out[2] = mu * f_n - std::abs(f_t);
}

template <class S>
void PointContact<S>::report(const MechanismKinematics<S>& k, const double* eta, double* out) const {
  contactAxes(S::linear(this->force(k, eta)), normal(k), mu_, out);
}

template class PointContact<Planar>;
template class PointContact<Spatial>;

}  // namespace dyn
