// Bounded-size Eigen types for the physics: dynamic sizes up to kMaxDof live on the stack,
// so a step never touches the heap (the hand-written step must beat Bullet by 10×).
#pragma once
#include <Eigen/Core>

namespace dyn {

inline constexpr int kMaxDof = 48;
using VecN = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxDof, 1>;
using MatN = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxDof, kMaxDof>;

}  // namespace dyn
