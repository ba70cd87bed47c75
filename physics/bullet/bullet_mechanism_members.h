// BulletMechanism's members that hand each call to its Impl, the same for both algebras: included by
// bullet_mechanism.cpp (planar) and spatial_mechanism.cpp (spatial) after each defines its Impl, which
// then instantiates BulletMechanism for its algebra. Impl provides step(τ, t), books, state(q, v),
// force (per description constraint) and describe().
#pragma once
#include <memory>
#include <stdexcept>
#include <string>

#include "physics/bullet/bullet_mechanism.h"

namespace dyn::bullet {

template <class S>
BulletMechanism<S>::BulletMechanism(const MechanismModel<S>& model, double dt, const VecN& q0, const VecN& v0)
    : impl_(std::make_unique<Impl>(model, dt, q0, v0)) {}

template <class S>
BulletMechanism<S>::~BulletMechanism() = default;

template <class S>
void BulletMechanism<S>::step(const VecN& tau, double t) {
  impl_->step(tau, t);
}

template <class S>
Books BulletMechanism<S>::books() const {
  return impl_->books;
}

template <class S>
void BulletMechanism<S>::state(VecN& q, VecN& v) const {
  impl_->state(q, v);
}

template <class S>
typename S::Vec BulletMechanism<S>::constraintForce(int i) const {
  if (i < 0 || i >= int(impl_->force.size())) throw std::out_of_range("BulletMechanism::constraintForce: no such constraint");
  return impl_->force[std::size_t(i)];
}

template <class S>
std::string BulletMechanism<S>::describe() const {
  return impl_->describe();
}

}  // namespace dyn::bullet
