// A ball joint of the description (chain.h: three tree bodies about the columns of R0, one quaternion
// Q in q) as Bullet links (spatial_mechanism.cpp): its two massless carriers as fixed links at the
// pivot (btMultiBody::setupFixed, tiny mass: they do not turn, which a massless body may), the body as
// a spherical link (setupSpherical) whose frame is the body's dynlab frame turned by E_p (onto its
// principal axes). Bullet turns a spherical link by R(Q_b)ᵀ Z (parent link → link, Z its zero
// rotation) with Q_b (x y z w) in the joint's position and its rate ω_b in the link's axes; the
// description turns the body by post R(Q)ᵀ preᵀ with ω in MuJoCo's local axes (post = R0). So with
// A = E_p post:   Z = A preᵀ,   R(Q_b) = A R(Q) Aᵀ, i.e. Q_b = (A (x y z), w),   ω_b = A ω,
// and a torque τ on the rates is A τ on Bullet's (the power is the same). A free joint's three slides
// stay prismatic links (massless: tiny mass) on the fixed base.
#pragma once
#include <Eigen/Core>

#include "physics/chain.h"

namespace dyn::bullet {

// True for a ball's first two bodies (Bullet: fixed links); the third is the spherical link.
inline bool ballCarrier(const TreeModel<Spatial>& tree, int i) {
  const auto& b = tree.bodies[std::size_t(i)];
  return b.joint == JointType::Ball && i != tree.balls[std::size_t(b.ball)].first + 2;
}

// The description's Q (w x y z) and ω into Bullet's joint position (x y z w) and rates.
inline void sphericalToBullet(const Eigen::Matrix3d& A, const double* Q, const double* w, double* qb, double* wb) {
  const Eigen::Vector3d v = A * Eigen::Vector3d(Q[1], Q[2], Q[3]), r = A * Eigen::Vector3d(w[0], w[1], w[2]);
  qb[0] = v.x(), qb[1] = v.y(), qb[2] = v.z(), qb[3] = Q[0];
  wb[0] = r.x(), wb[1] = r.y(), wb[2] = r.z();
}

// And back.
inline void sphericalFromBullet(const Eigen::Matrix3d& A, const double* qb, const double* wb, double* Q, double* w) {
  const Eigen::Vector3d v = A.transpose() * Eigen::Vector3d(qb[0], qb[1], qb[2]), r = A.transpose() * Eigen::Vector3d(wb[0], wb[1], wb[2]);
  Q[0] = qb[3], Q[1] = v.x(), Q[2] = v.y(), Q[3] = v.z();
  w[0] = r.x(), w[1] = r.y(), w[2] = r.z();
}

}  // namespace dyn::bullet
