// The generic constrained mechanism's implementation (constrained_mechanism.h). Include this (not only
// the header) to instantiate it at a lab's fixed sizes, e.g.
//   template class dyn::ConstrainedMechanism<dyn::Planar, 3, 3, 1>;
// physics/constrained_mechanism.cpp instantiates the bounded (Dynamic) sizes for both algebras. Here:
// construction, the two stages, the solve and the integrator's interface; the rigid contacts'
// touchdowns, impacts and lift-offs, and the rows the integrators see (G, the Baumgarte term), are in
// constrained_mechanism_contacts.h; energy, residuals and the controllers' queries in
// constrained_mechanism_queries.h.
#pragma once
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "physics/chain_sized.h"
#include "physics/chain_world.h"
#include "physics/constrained_mechanism.h"
#include "physics/constrained_mechanism_contacts.h"
#include "physics/constrained_mechanism_queries.h"
#include "physics/det/det.h"
#include "physics/fixed_size_copy.h"

namespace dyn {

template <class S, int Nj, int Nr, int Nl>
ConstrainedMechanism<S, Nj, Nr, Nl>::ConstrainedMechanism(MechanismModel<S> model)
    : model_(std::move(model)), data_(model_.tree) {
  if (const std::string why = model_.validate(); !why.empty()) throw std::invalid_argument(why);
  for (const auto& c : model_.constraints) {
    offsets_.push_back(rows_);
    row_count_.push_back(c->rows());
    row_owner_.insert(row_owner_.end(), std::size_t(c->rows()), int(offsets_.size()) - 1);
    rows_ += c->rows();
    // Rigid unilateral contacts start open (updateContacts closes them); compliant ones never close.
    const bool released = c->unilateral() || c->compliant();
    released_.push_back(char(released));
    compliant_.push_back(char(c->compliant()));
    rigid_contact_.push_back(char(c->unilateral() && !c->compliant()));
    any_compliant_ = any_compliant_ || c->compliant();
    any_released_kind_ = any_released_kind_ || released;
    any_rigid_contact_ = any_rigid_contact_ || rigid_contact_.back();
  }
  closed_rows_.reserve(std::size_t(rows_));  // selectClosedRows: no allocation in a step
  limitRows();
  auto fits = [](int fixed, int actual) { return fixed == Eigen::Dynamic || fixed == actual; };
  const int dof = model_.treeDof(), payload = model_.payloadDof();
  if (!fits(Nj, dof) || !fits(Nr, rows_) || !fits(Nl, payload))
    throw std::invalid_argument("the mechanism's sizes (" + std::to_string(dof) + " joints, " + std::to_string(rows_) +
                                " constraint rows, " + std::to_string(payload) + " payload coordinates) do not match this instantiation");
  has_forces_ = !model_.forces.empty();
  for (const JointProperties& j : model_.joints) has_armature_ = has_armature_ || j.armature != 0.0;
  if constexpr (S::kDim == 6) planar_ = PlanarTreeData(model_.tree);
  if constexpr (S::kDim == 6) fused_ = planar_.axis < 0 && model_.payloads.empty() && sized::fusedSerial<Nj>(model_.tree);
  kin_.model = &model_;
  kin_.tree = &data_;
  kin_.payload_pose.assign(model_.payloads.size(), Eigen::Vector3d::Zero());
  kin_.payload_rate.assign(model_.payloads.size(), Eigen::Vector3d::Zero());
  kin_.payload_cs.assign(model_.payloads.size(), Eigen::Vector2d(1, 0));
  kin_.link_angle.assign(std::size_t(n()), 0.0);
  kin_.theta = VecN::Zero(nqTree());
  kin_.theta_rate = VecN::Zero(n());
  // Planar: the fixed part of each link's angle, its placement's rotation (X_tree.E = rotation(angle)).
  if constexpr (S::kDim == 3)
    for (const auto& b : model_.tree.bodies) tree_angle_.push_back(det::atan2(b.X_tree.E(0, 1), b.X_tree.E(0, 0)));
  // The payloads' M_c = diag(I, m, m) on their free coordinates, and G_c = −m g: constant.
  const int kk = k();
  problem_.Mc = MatN::Zero(kk, kk);
  problem_.bc_Gc = VecN::Zero(kk);
  for (std::size_t i = 0; i < model_.payloads.size(); ++i) {
    const Payload& p = model_.payloads[i];
    const double diag[3] = {p.inertia, p.mass, p.mass};
    double g[3] = {0.0, 0.0, 0.0};
    if constexpr (S::kDim == 3) g[1] = model_.tree.gravity[1], g[2] = model_.tree.gravity[2];
    for (int c = 0, col = model_.payloadOffset(int(i)); c < 3; ++c)
      if (p.free[std::size_t(c)]) {
        problem_.Mc(col, col) = diag[c];
        problem_.bc_Gc[col] = -p.mass * g[c];
        ++col;
      }
  }
  gravity_bc_ = problem_.bc_Gc;
  impact_.assign(model_.constraints.size(), Vec::Zero());
  problem_.A.setZero(rows_, kk);
  phi_.setZero(rows_);
  phi_full_.setZero(rows_);
}

template <class S, int Nj, int Nr, int Nl>
void ConstrainedMechanism<S, Nj, Nr, Nl>::stagePosition(const VecN& q, const VecN* qd) {
  const int nn = n(), kk = k(), nqt = nqTree();
  // World transforms and joint axes, unless a controller's query just staged the whole tree at θ (the
  // parent frames are treeStage's, for the body-frame queries).
  // (A planar tree's always: treeStage's 3 × 3 products round otherwise than kinematicsPlanar.)
  if (planar_.axis >= 0 || !have_tree_ || q.head(nqt) != tree_q_) {
    sized::kinematicsWorldOrPlanar<Nj>(model_.tree, q.head(nqt), data_, planar_);
    have_tree_ = false;
  }
  have_velocity_ = false;
  // M from world composite inertias; the world inertias stay for the velocity stage. With θ' (stageBoth,
  // fused_): the velocity stage's h in the same pass.
  problem_.M.resize(nn, nn);
  bool fused = false;  // (only stageBoth passes θ', and only where fused_: 6-D)
  if constexpr (S::kDim == 6)
    if (qd) {
      problem_.h.resize(nn);
      sized::crbaAndBiasSerial<Nj>(model_.tree, data_, *qd, problem_.M, problem_.h);
      fused = true;
    }
  if (!fused) sized::crbaWorldOrPlanar<Nj>(model_.tree, data_, planar_, problem_.M);
  addArmature(problem_.M);
  setFixed<Nj>(kin_.theta, q, nqt);
  // Planar link angles: the parent's, the placement's, and the joint's own for a revolute.
  if constexpr (S::kDim == 3)
    for (int i = 0; i < nn; ++i) {
      const auto& b = model_.tree.bodies[std::size_t(i)];
      kin_.link_angle[std::size_t(i)] = (b.parent < 0 ? 0.0 : kin_.link_angle[std::size_t(b.parent)]) + tree_angle_[std::size_t(i)] +
                                        (b.joint == JointType::Revolute ? q[i] : 0.0);
    }
  // Payload poses: the free coordinates from q, the others where they were put.
  for (std::size_t i = 0, off = std::size_t(nqt); i < model_.payloads.size(); ++i) {
    const Payload& p = model_.payloads[i];
    for (std::size_t c = 0; c < 3; ++c) kin_.payload_pose[i][Eigen::Index(c)] = p.free[c] ? q[Eigen::Index(off++)] : p.pose0[Eigen::Index(c)];
    const double psi = kin_.payload_pose[i][0];
    kin_.payload_cs[i] = p.free[0] || psi != 0.0 ? Eigen::Vector2d(det::cos(psi), det::sin(psi)) : Eigen::Vector2d(1.0, 0.0);
  }
  // Every constraint's φ, J and A rows, then eq. (2) factored at this configuration.
  // (Joint limits alone: φ = −gap of each, JointLimit::position's φ, and the solve's φ with it, in one
  // pass (limitRowsAtStage); their J rows are constant.)
  if (only_limits_) {
    limitRowsAtStage();
  } else {
    setZeroAt<Nr, Nj>(J_full_, rows_, nn);
    setZeroAt<Nr, Nl>(A_full_, rows_, kk);
    for (std::size_t i = 0; i < model_.constraints.size(); ++i) model_.constraints[i]->position(kin_, offsets_[i], phi_full_, J_full_, A_full_);
    setFixed<Nr>(phi_, phi_full_);
    rigid_known_ = false;  // (rigidContactsAtStage when asked)
  }
  // Some rows released at dynamic sizes: the closed rows alone, compacted (selectClosedRows); φ = 0 on
  // the released ones.
  if (selectClosedRows()) {
    // (A one-row constraint's entry stored alone: GCC makes a loop over a few doubles a memset call.)
    if (!only_limits_) {
      for (std::size_t i = 0; i < model_.constraints.size(); ++i) {
        if (released_[i] && row_count_[i] == 1) phi_[offsets_[i]] = 0.0;
        else if (released_[i]) phi_.segment(offsets_[i], row_count_[i]).setZero();
      }
    }
    factored_ = factorClosedRows();
    setFixed<kState>(staged_q_, q);
    have_position_ = true;
    return;
  }
  problem_.J = J_full_;
  problem_.A = A_full_;
  // Released rows (open or compliant contacts) are zeroed in the solve (the full rows stay for gaps
  // and compliant forces): with compliance 1, η = 0.
  if (any_released_kind_) {
    setZeroAt<Nr, 1>(problem_.compliance, rows_, 1);
    for (std::size_t i = 0; i < model_.constraints.size(); ++i)
      if (released_[i])
        for (int r = offsets_[i]; r < offsets_[i] + row_count_[i]; ++r) {
          phi_[r] = 0.0;
          problem_.J.row(r).setZero();
          if (kk) problem_.A.row(r).setZero();
          problem_.compliance[r] = 1.0;
        }
  }
  factored_ = factor_.factor(problem_, problem_.J, problem_.A);
  setFixed<kState>(staged_q_, q);
  have_position_ = true;
}

template <class S, int Nj, int Nr, int Nl>
void ConstrainedMechanism<S, Nj, Nr, Nl>::treeStage(const VecN& q) {
  if (have_tree_ && q.head(nqTree()) == tree_q_) return;
  positionKinematics(model_.tree, q.head(nqTree()), data_);
  tree_q_ = q.head(nqTree());
  have_tree_ = true;
  have_position_ = have_velocity_ = false;  // data_ no longer holds the stages' configuration
}

template <class S, int Nj, int Nr, int Nl>
void ConstrainedMechanism<S, Nj, Nr, Nl>::velocityStage(const VecN& v, bool h_staged) {
  const int nn = n();
  // θ' (without a payload, v itself: no copy).
  VecN head;
  if constexpr (Nl != 0) head = v.head(nn);
  const VecN& qd = Nl != 0 ? head : v;
  have_last_ = false;  // the last solve was at other rates
  // Link velocities, each link's velocity-product acceleration and h = Cθ' + G, in world coordinates.
  problem_.h.resize(nn);
  setFixed<Nj>(kin_.theta_rate, qd, nn);
  if (!h_staged) sized::biasForcesWorldOrPlanar<Nj>(model_.tree, data_, planar_, qd, problem_.h);
  // Joint springs and friction join h; friction's power for the books.
  friction_power_ = 0.0;
  if (!model_.joints.empty())
    for (int i = 0; i < nn; ++i) {
      const JointProperties& j = model_.joints[std::size_t(i)];
      const double f = j.friction(qd[i]);
      problem_.h[i] += j.stiffness * (staged_q_[model_.tree.bodies[std::size_t(i)].q_index] - j.rest) + f;
      friction_power_ -= f * qd[i];
    }
  // Payload rates: the free coordinates' rates, zero for the held ones.
  for (std::size_t i = 0, off = std::size_t(nn); i < model_.payloads.size(); ++i)
    for (std::size_t c = 0; c < 3; ++c)
      kin_.payload_rate[i][Eigen::Index(c)] = model_.payloads[i].free[c] ? v[Eigen::Index(off++)] : 0.0;
  // External forces at the clock's time: Q = [J, −A]ᵀ F through the point's Jacobian (h −= JᵀF on the
  // tree, b_c + G_c += AᵀF on the payloads), and their power F·V_P.
  external_power_ = 0.0;
  if (has_forces_) {
    const int kk = k();
    external_bc_.setZero(kk);
    MatN Jp(S::kDim, nn), Ap(S::kDim, kk);
    std::array<bool, S::kDim> all;
    all.fill(true);
    for (const auto& force : model_.forces) {
      const BodyRef b = force->body();
      const Pos p = kin_.position(b, force->point());
      const Vec V = kin_.pointVelocity(b, p);
      const Vec F = force->force(time_, p, V);
      if (F.isZero(0.0)) continue;  // a push outside its window: no Jacobian to build
      external_power_ += F.dot(V);
      Jp.setZero();
      if (kk) Ap.setZero();
      kin_.addPointJacobian(b, p, all, 1.0, 0, Jp, Ap);
      problem_.h.noalias() -= Jp.transpose() * F;
      if (kk) external_bc_.noalias() += Ap.transpose() * F;
    }
  }
  // J'θ' − A'v_c of every constraint (of the closed ones alone, compacted, when the rows are selected:
  // the released rows' bias is not solved for). Joint limits alone, selected: J constant, J'θ' = 0.
  if (only_limits_ && selected()) {
    problem_.Jdot_qd.setZero(Eigen::Index(closed_rows_.size()));
    setFixed<kState>(staged_v_, v);
    have_velocity_ = true;
    return;
  }
  VecN bias(rows_);
  for (std::size_t i = 0; i < model_.constraints.size(); ++i)
    if (!selected() || !released_[i]) model_.constraints[i]->bias(kin_, offsets_[i], bias);
  // Released rows: no bias; a compliant contact's force enters as −Jᵀη on the tree (h += Jᵀη) and
  // Aᵀη on the payloads.
  if (any_released_kind_) {
    if (any_compliant_) {
      compliant_eta_.setZero(rows_);
      compliant_bc_.setZero(k());
    }
    for (std::size_t i = 0; i < model_.constraints.size(); ++i) {
      if (!released_[i]) continue;
      const auto& c = *model_.constraints[i];
      if (!selected())  // (selected: the released rows' bias is not gathered)
        for (int r = offsets_[i]; r < offsets_[i] + row_count_[i]; ++r) bias[r] = 0.0;
      if (!compliant_[i]) continue;
      const int r = offsets_[i];
      const double eta = c.compliantForce(kin_);
      compliant_eta_[r] = eta;
      problem_.h += eta * J_full_.row(r).transpose();
      if (k()) compliant_bc_ -= eta * A_full_.row(r).transpose();
    }
  }
  if (selected()) gatherClosedRows(bias, problem_.Jdot_qd);
  else problem_.Jdot_qd = bias;
  setFixed<kState>(staged_v_, v);
  have_velocity_ = true;
}

template <class S, int Nj, int Nr, int Nl>
void ConstrainedMechanism<S, Nj, Nr, Nl>::stageBoth(const VecN& q, const VecN& v) {
  const bool fuse = fused_ && v.size() == n();  // (θ' is v itself: no payload coordinates)
  stagePosition(q, fuse ? &v : nullptr);
  velocityStage(v, fuse);
}

template <class S, int Nj, int Nr, int Nl>
void ConstrainedMechanism<S, Nj, Nr, Nl>::stage(const VecN& q, const VecN* v) {
  if (!v) return positionStage(q);
  if (!stageBothIfNew(q, *v)) velocityStage(*v);
}

template <class S, int Nj, int Nr, int Nl>
typename ConstrainedMechanism<S, Nj, Nr, Nl>::Solution ConstrainedMechanism<S, Nj, Nr, Nl>::evaluate(
    const VecN& q, const VecN& v, const VecN& tau, const VecN* stab, bool with_qdd, bool with_forces) {
  // Both stages are kept (the trace row's solve and the step's first stage share them); both made at
  // once when the position is new.
  if (!stageBothIfNew(q, v) && (!have_velocity_ || !same(v, staged_v_))) velocityStage(v);
  // τ: the tree torques, optionally followed by generalised forces on the payload coordinates
  // (an external push w on the payload: M_c α_c + b_c + G_c = Aᵀ f + w).
  if (tau.size() != n() && tau.size() != n() + k())
    throw std::invalid_argument("ConstrainedMechanism: τ needs n tree torques, or n + k with payload forces");
  problem_.tau = tau.head(n());
  if constexpr (Nl == 0) {
    problem_.bc_Gc.resize(0);  // no payload
  } else {
    if (tau.size() == n() + k()) problem_.bc_Gc = gravity_bc_ - tau.tail(k());
    else problem_.bc_Gc = gravity_bc_;
    if (any_compliant_ && k()) problem_.bc_Gc += compliant_bc_;
    if (has_forces_ && k()) problem_.bc_Gc += external_bc_;
  }
  if (!stab) problem_.stab.resize(0);
  else if (selected()) gatherClosedRows(*stab, problem_.stab);
  else setFixed<Nr>(problem_.stab, *stab);
  Solution s;
  if (!factored_) s = solveConstrainedBlockLU(problem_);
  else factor_.solve(problem_, s, with_qdd);
  if (!with_forces) return s;  // (η compacted when the rows are selected)
  if (selected()) scatterClosedRows(s);
  // A compliant contact's η is its force, not the solve's (its row is released).
  if (any_compliant_)
    for (std::size_t i = 0; i < model_.constraints.size(); ++i)
      if (compliant_[i]) {
        const int r = offsets_[i];
        s.eta[r] = compliant_eta_[r];
        s.f[r] = compliant_eta_[r];
      }
  return s;
}

template <class S, int Nj, int Nr, int Nl>
typename ConstrainedMechanism<S, Nj, Nr, Nl>::Solution ConstrainedMechanism<S, Nj, Nr, Nl>::solve(
    const VecN& q, const VecN& v, const VecN& tau, const VecN* stab) {
  Solution s = evaluate(q, v, tau, stab);
  // Kept: the integrator's first stage usually comes back to this state (the trace row's solve).
  if (!stab) {
    last_tau_ = tau;
    last_ = s;
    have_last_ = true;
  }
  return s;
}

template <class S, int Nj, int Nr, int Nl>
void ConstrainedMechanism<S, Nj, Nr, Nl>::accelerations(const VecN& q, const VecN& v, const VecN& tau,
                                                        const VecN* stab, VecN& a) {
  // The state solve() was last asked about: the same answer (a pure function of q, v, τ). The stages
  // are still at (q, v): any restaging clears have_last_.
  const bool known = !stab && have_last_ && have_position_ && have_velocity_ && same(q, staged_q_) && same(v, staged_v_) &&
                     same(tau, last_tau_);
  a.resize(n() + k());
  // Entry by entry, at the fixed sizes where known: θ'' was just stored 8 bytes at a time, and a block
  // copy (memcpy) reloads it 16 bytes at a time, which stalls on store forwarding.
  const int nn = Nj == Eigen::Dynamic ? n() : Nj, kk = Nl == Eigen::Dynamic ? k() : Nl;
  auto put = [&](const Solution& s) {
    for (int i = 0; i < nn; ++i) a[i] = s.qdd[i];
    for (int i = 0; i < kk; ++i) a[nn + i] = s.alpha_c[i];
  };
  if (known) put(last_);
  else put(evaluate(q, v, tau, stab, true, false));  // θ'' and α_c alone
}

template <class S, int Nj, int Nr, int Nl>
void ConstrainedMechanism<S, Nj, Nr, Nl>::setTime(double t) {
  // Time-dependent forces: a new time is a new velocity stage (and no remembered solve).
  if (t != time_ && has_forces_) have_velocity_ = have_last_ = false;
  time_ = t;
}

template <class S, int Nj, int Nr, int Nl>
void ConstrainedMechanism<S, Nj, Nr, Nl>::derivatives(const VecN& q, const VecN& v, const VecN& tau, const VecN* stab,
                                                      VecN& a, double& work, double& friction) {
  // After accelerations() the stages are at (q, v) and the clock's time: their powers are this state's.
  ConstrainedMechanism::accelerations(q, v, tau, stab, a);
  work = external_power_;
  friction = friction_power_;
  if constexpr (Nj != Eigen::Dynamic)
    if (tau.size() == Nj) {  // the usual τ (n torques): the loop unrolled
      for (int i = 0; i < Nj; ++i) work += tau[i] * v[i];
      return;
    }
  for (int i = 0; i < int(tau.size()); ++i) work += tau[i] * v[i];
}

template <class S, int Nj, int Nr, int Nl>
void ConstrainedMechanism<S, Nj, Nr, Nl>::configurationRate(const VecN& q, const VecN& v, VecN& qdot) {
  if (model_.tree.balls.empty()) {
    qdot = v;
    return;
  }
  const int nqt = nqTree(), kk = k();
  qdot.resize(nqt + kk);
  dyn::configurationRate(model_.tree, q.head(nqt), v.head(n()), qdot.head(nqt));
  qdot.tail(kk) = v.tail(kk);
}

template <class S, int Nj, int Nr, int Nl>
void ConstrainedMechanism<S, Nj, Nr, Nl>::integrateConfiguration(VecN& q, const VecN& dx, double h) {
  if (model_.tree.balls.empty()) {
    if (kState != Eigen::Dynamic && q.size() == kState && dx.size() == kState)
      for (int i = 0; i < kState; ++i) q[i] += h * dx[i];  // Eigen's q + h dx entry by entry, unrolled
    else
      q += h * dx;
    return;
  }
  const int nqt = nqTree(), kk = k();
  dyn::integrateConfiguration(model_.tree, q.head(nqt), dx.head(n()), h);
  q.tail(kk) += h * dx.tail(kk);
}

template <class S, int Nj, int Nr, int Nl>
void ConstrainedMechanism<S, Nj, Nr, Nl>::normalizeConfiguration(VecN& q) {
  if (!model_.tree.balls.empty()) dyn::normalizeConfiguration(model_.tree, q.head(nqTree()));
}

template <class S, int Nj, int Nr, int Nl>
void ConstrainedMechanism<S, Nj, Nr, Nl>::metric(const VecN& q, MatN& W) {
  positionStage(q);
  W = MatN::Zero(n() + k(), n() + k());
  W.topLeftCorner(n(), n()) = problem_.M;
  W.bottomRightCorner(k(), k()) = problem_.Mc;
}

template <class S, int Nj, int Nr, int Nl>
bool ConstrainedMechanism<S, Nj, Nr, Nl>::correction(const VecN& q, const VecN& e, VecN& dx) {
  positionStage(q);
  if (!factored_) return ConstrainedSystem::correction(q, e, dx);
  Solution s;
  return impulseResponse(e, s, dx);
}

template <class S, int Nj, int Nr, int Nl>
bool ConstrainedMechanism<S, Nj, Nr, Nl>::impulseResponse(const VecN& e, Solution& s, VecN& dx) {
  // Eq. (2) for impulses: M dθ = −Jᵀ f, M_c dx_c = Aᵀ f, J dθ − A dx_c = e (τ − h = 0, J'θ' = −e).
  Problem impulse;
  impulse.tau.setZero(n());
  impulse.h.setZero(n());
  if (selected()) {  // the closed rows the factor holds (negated after the gather: exact)
    gatherClosedRows(e, impulse.Jdot_qd);
    impulse.Jdot_qd = -impulse.Jdot_qd;
  } else {
    impulse.Jdot_qd = -e;
  }
  factor_.solve(impulse, s);
  if (selected()) scatterClosedRows(s);
  dx.resize(n() + k());
  dx.head(n()) = s.qdd;
  dx.tail(k()) = s.alpha_c;
  return dx.allFinite();
}

template <class S, int Nj, int Nr, int Nl>
typename S::Vec ConstrainedMechanism<S, Nj, Nr, Nl>::constraintForce(int i, const Solution& s) {
  return model_.constraints[std::size_t(i)]->force(kin_, s.eta.data() + offsets_[std::size_t(i)]);
}

template <class S, int Nj, int Nr, int Nl>
void ConstrainedMechanism<S, Nj, Nr, Nl>::jointLoads(const VecN& q, const VecN& v, const Solution& s,
                                                     std::vector<Vec>& loads) {
  const int nn = n();
  // The constraint forces first, at the staged configuration: each at the world origin.
  positionStage(q);
  std::vector<std::pair<Attachment<S>, Vec>> applied;
  for (std::size_t c = 0; c < model_.constraints.size(); ++c) {
    const auto& con = *model_.constraints[c];
    const Vec f = constraintForce(int(c), s);
    applied.emplace_back(con.attachment(), S::forceTranspose(S::translation(con.point(kin_)), f));
  }
  // What each subtree needs (data_.f after RNEA: joint i's force in body i's axes), in world axes.
  inverseDynamics(q, v, VecN(s.qdd.head(nn)));
  loads.resize(std::size_t(nn));
  for (int i = 0; i < nn; ++i) loads[std::size_t(i)] = S::forceTranspose(data_.X_world[std::size_t(i)], data_.f[std::size_t(i)]);
  // Less what the constraints apply to the subtree: f_c on body b, −f_c on body a, up every joint above them.
  for (const auto& [at, f] : applied)
    for (const auto& [body, sign] : {std::pair{at.b, 1.0}, std::pair{at.a, -1.0}})
      if (body.kind == BodyRef::Kind::Link)
        for (int k = body.index; k >= 0; k = model_.tree.bodies[std::size_t(k)].parent) loads[std::size_t(k)] -= sign * f;
}

template <class S, int Nj, int Nr, int Nl>
void ConstrainedMechanism<S, Nj, Nr, Nl>::constraintReport(int i, const Solution& s, double* out) {
  model_.constraints[std::size_t(i)]->report(kin_, s.eta.data() + offsets_[std::size_t(i)], out);
}

}  // namespace dyn
