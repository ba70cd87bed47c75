// The generic constrained mechanism's read-only views of a state (constrained_mechanism.h), included by
// constrained_mechanism_impl.h: the energy books (T = ½ θ'ᵀ M θ' + ½ Σ m_c |v_c|², V the gravity's and
// the springs'), the constraints' residuals |φ|∞ (and |J θ' − A v_c|∞ for velocity-level kinds), and the
// controllers' queries (point positions and Jacobians, M(θ), G(θ), inverse dynamics M θ'' + C θ' + G,
// the task-space inertia Λ = (J M⁻¹ Jᵀ)⁻¹). Each stages what it reads, as the step does.
#pragma once
#include <algorithm>

#include "physics/chain.h"
#include "physics/chain_planar_in_space.h"
#include "physics/cholesky.h"
#include "physics/constrained_mechanism.h"

namespace dyn {

template <class S, int Nj, int Nr, int Nl>
double ConstrainedMechanism<S, Nj, Nr, Nl>::kineticEnergy(const VecN& q, const VecN& v) {
  // The velocity stage at (q, v): usually the step's own (the trace row asks at the step's start).
  positionStage(q);
  if (!have_velocity_ || !same(v, staged_v_)) velocityStage(v);
  double T = kineticEnergyWorldOrPlanar(model_.tree, data_, planar_);
  if (has_armature_)  // the rotors' ½ a θ'²
    for (int i = 0; i < n(); ++i) T += 0.5 * model_.joints[std::size_t(i)].armature * v[i] * v[i];
  for (std::size_t i = 0, off = std::size_t(n()); i < model_.payloads.size(); ++i) {
    const Payload& p = model_.payloads[i];
    const double diag[3] = {p.inertia, p.mass, p.mass};
    for (std::size_t c = 0; c < 3; ++c)
      if (p.free[c]) {
        const double r = v[Eigen::Index(off++)];
        T += 0.5 * diag[c] * r * r;
      }
  }
  return T;
}

template <class S, int Nj, int Nr, int Nl>
double ConstrainedMechanism<S, Nj, Nr, Nl>::potentialEnergy(const VecN& q) {
  positionStage(q);
  double U = dyn::potentialEnergy(model_.tree, data_);
  // Payloads in gravity, −m g·c, and joint springs ½ k (θ − θ_rest)².
  if constexpr (S::kDim == 3)
    for (std::size_t i = 0; i < model_.payloads.size(); ++i)
      U -= model_.payloads[i].mass * (model_.tree.gravity[1] * kin_.payload_pose[i][1] + model_.tree.gravity[2] * kin_.payload_pose[i][2]);
  for (std::size_t i = 0; i < model_.joints.size(); ++i) {
    const double d = q[Eigen::Index(model_.tree.bodies[i].q_index)] - model_.joints[i].rest;
    U += 0.5 * model_.joints[i].stiffness * d * d;
  }
  return U;
}

template <class S, int Nj, int Nr, int Nl>
double ConstrainedMechanism<S, Nj, Nr, Nl>::energy(const VecN& q, const VecN& v) {
  return kineticEnergy(q, v) + potentialEnergy(q);
}

template <class S, int Nj, int Nr, int Nl>
double ConstrainedMechanism<S, Nj, Nr, Nl>::residual(const VecN& q) {
  positionStage(q);
  return rows_ ? phi_.lpNorm<Eigen::Infinity>() : 0.0;
}

template <class S, int Nj, int Nr, int Nl>
double ConstrainedMechanism<S, Nj, Nr, Nl>::residual(const VecN& q, const VecN& v) {
  positionStage(q);
  if (!rows_) return 0.0;
  // Velocity form J θ' − A v_c as well: a velocity-level kind has only this one.
  // (G v = J θ' − A v_c; with the rows selected, taken on G's blocks where they lie, no copies: the
  // same dynamically sized products as on copies of them.)
  auto rates = [&]() -> VecN {
    if (!selected()) return MatN(problem_.J) * v.head(n()) - MatN(problem_.A) * v.tail(k());
    VecN phi;  // the rows over every constraint (problem_ holds the closed ones)
    MatN G;
    constraint(q, phi, G);
    return G.leftCols(n()) * v.head(n()) + G.rightCols(k()) * v.tail(k());
  };
  const VecN gv = rates();
  return std::max(phi_.lpNorm<Eigen::Infinity>(), gv.lpNorm<Eigen::Infinity>());
}

template <class S, int Nj, int Nr, int Nl>
double ConstrainedMechanism<S, Nj, Nr, Nl>::residual(int i, const VecN& q) {
  positionStage(q);
  const int r = model_.constraints[std::size_t(i)]->rows();
  return r ? phi_.segment(offsets_[std::size_t(i)], r).template lpNorm<Eigen::Infinity>() : 0.0;
}

template <class S, int Nj, int Nr, int Nl>
typename S::Pos ConstrainedMechanism<S, Nj, Nr, Nl>::pointPosition(int link, const Pos& point, const VecN& q) {
  treeStage(q);
  return dyn::pointPosition(data_, link, point);
}

template <class S, int Nj, int Nr, int Nl>
void ConstrainedMechanism<S, Nj, Nr, Nl>::pointJacobian(int link, const Pos& point, const VecN& q, const VecN& qd,
                                                        MatN& J, VecN& Jdot_qd) {
  treeStage(q);
  have_velocity_ = false;
  velocityKinematics(model_.tree, VecN(qd.head(n())), data_);
  dyn::pointJacobian(model_.tree, data_, link, point, J, Jdot_qd);
}

template <class S, int Nj, int Nr, int Nl>
MatN ConstrainedMechanism<S, Nj, Nr, Nl>::massMatrix(const VecN& q) {
  treeStage(q);
  MatN M = crba(model_.tree, data_);
  addArmature(M);
  return M;
}

template <class S, int Nj, int Nr, int Nl>
VecN ConstrainedMechanism<S, Nj, Nr, Nl>::gravityTorque(const VecN& q) {
  const VecN zero = VecN::Zero(n());
  treeStage(q);
  have_velocity_ = false;
  velocityKinematics(model_.tree, zero, data_);
  return rnea(model_.tree, data_, zero, zero);
}

template <class S, int Nj, int Nr, int Nl>
VecN ConstrainedMechanism<S, Nj, Nr, Nl>::inverseDynamics(const VecN& q, const VecN& qd, const VecN& qdd) {
  treeStage(q);
  have_velocity_ = false;
  velocityKinematics(model_.tree, VecN(qd.head(n())), data_);
  VecN tau = rnea(model_.tree, data_, qd, qdd);
  if (has_armature_)
    for (int i = 0; i < n(); ++i) tau[i] += model_.joints[std::size_t(i)].armature * qdd[i];
  return tau;
}

template <class S, int Nj, int Nr, int Nl>
MatN ConstrainedMechanism<S, Nj, Nr, Nl>::operationalInertia(const VecN& q, const MatN& J) {
  // Λ⁻¹ = J M⁻¹ Jᵀ by the small Cholesky of M, then Λ by that of Λ⁻¹ (empty if either is singular).
  CholeskyN<> chol_M, chol_L;
  if (!chol_M.compute(massMatrix(q))) return {};
  MatN Y = J.transpose();
  chol_M.forward(Y);
  MatN Linv(J.rows(), J.rows());
  chol_M.inner(Y, int(J.rows()), Linv);
  if (!chol_L.compute(Linv)) return {};
  MatN Lambda = MatN::Identity(J.rows(), J.rows());
  chol_L.solveInPlace(Lambda);
  return Lambda;
}

}  // namespace dyn
