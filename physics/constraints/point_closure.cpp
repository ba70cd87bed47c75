// Point closure rows; the maths is in point_closure.h.
#include "physics/constraints/point_closure.h"

#include <Eigen/Geometry>
#include <cmath>

#include "physics/det/rotation.h"

namespace dyn {

template <class S>
PointClosure<S>::PointClosure(BodyRef a, const Pos& point_a, BodyRef b, const Pos& point_b, const Rows& rows) {
  at_ = {a, b, point_a, point_b, rows};
  for (bool r : rows) count_ += int(r);
  for (int i = 0; i < (S::kDim == 3 ? 1 : 3); ++i) turns_ = turns_ || rows[std::size_t(i)];
}

template <class S>
typename PointClosure<S>::Rows PointClosure<S>::all() {
  Rows r;
  r.fill(true);
  return r;
}

template <class S>
typename PointClosure<S>::Rows PointClosure<S>::translations() {
  Rows r{};
  for (int i = S::kDim == 3 ? 1 : 3; i < S::kDim; ++i) r[std::size_t(i)] = true;  // planar x, y; spatial x, y, z
  return r;
}

template <class S>
void PointClosure<S>::position(const MechanismKinematics<S>& k, int row, VecN& phi, MatN& J, MatN& A) const {
  const Pos pa = k.position(at_.a, at_.point_a), pb = k.position(at_.b, at_.point_b);
  // φ: the angle error, then the point error, on the held rows.
  Vec err;
  if constexpr (S::kDim == 3) {
    err << std::remainder(k.angle(at_.a) - k.angle(at_.b), 2.0 * M_PI), pa - pb;  // wrapped to [−π, π]
  } else {
    // A pin holds no rotation row: no rotation vector to build (a 3×3 product and an atan2).
    err.template head<3>().setZero();
    if (turns_) {
      err.template head<3>() = det::rotationVector(k.rotation(at_.a) * k.rotation(at_.b).transpose());
    }
    err.template tail<3>() = pa - pb;
  }
  for (int i = 0, out = row; i < S::kDim; ++i)
    if (at_.rows[std::size_t(i)]) phi[out++] = err[i];
  // J θ' − A v_c = S (V_a(P_a) − V_b(P_b)).
  k.addPointJacobian(at_.a, pa, at_.rows, +1.0, row, J, A);
  k.addPointJacobian(at_.b, pb, at_.rows, -1.0, row, J, A);
}

template <class S>
void PointClosure<S>::bias(const MechanismKinematics<S>& k, int row, VecN& b) const {
  // A spatial pin: the classical accelerations' linear parts alone (the same sums as pointBias's).
  if constexpr (S::kDim == 6)
    if (!turns_) {
      const Pos d = k.linearBias(at_.a, k.position(at_.a, at_.point_a)) - k.linearBias(at_.b, k.position(at_.b, at_.point_b));
      for (int i = 3, out = row; i < 6; ++i)
        if (at_.rows[std::size_t(i)]) b[out++] = d[i - 3];
      return;
    }
  const Vec d = k.pointBias(at_.a, k.position(at_.a, at_.point_a)) - k.pointBias(at_.b, k.position(at_.b, at_.point_b));
  for (int i = 0, out = row; i < S::kDim; ++i)
    if (at_.rows[std::size_t(i)]) b[out++] = d[i];
}

template <class S>
typename S::Vec PointClosure<S>::force(const MechanismKinematics<S>& k, const double* eta) const {
  (void)k;
  Vec f = Vec::Zero();
  for (int i = 0, in = 0; i < S::kDim; ++i)
    if (at_.rows[std::size_t(i)]) f[i] = eta[in++];
  return f;
}

template class PointClosure<Planar>;
template class PointClosure<Spatial>;

}  // namespace dyn
