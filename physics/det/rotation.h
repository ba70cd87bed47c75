// det's rotations: what Eigen's AngleAxis computes with the C library's trigonometry, through det
// instead (docs/determinism.md), for the rotations that feed a trace.
#pragma once

#include <Eigen/Geometry>

#include "physics/det/det.h"

namespace det {

// The rotation vector (angle × unit axis, angle in [0, π]) of a rotation matrix: Eigen's
// AngleAxisd(R).angle() * .axis(), the same quaternion steps with det::atan2.
inline Eigen::Vector3d rotationVector(const Eigen::Matrix3d& R) {
  const Eigen::Quaterniond q(R);
  double n = q.vec().norm();
  if (n < 1e-15) n = q.vec().stableNorm();
  if (n == 0.0) return Eigen::Vector3d::Zero();
  const double angle = 2.0 * det::atan2(n, std::abs(q.w()));
  return angle * q.vec() / (q.w() < 0.0 ? -n : n);
}

// The rotation by a about z.
inline Eigen::Matrix3d rotationZ(double a) {
  const double c = det::cos(a), s = det::sin(a);
  return (Eigen::Matrix3d() << c, -s, 0, s, c, 0, 0, 0, 1).finished();
}

}  // namespace det
