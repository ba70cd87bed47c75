// The generic constrained mechanism's rigid unilateral contacts (constrained_mechanism.h), between and
// within steps; included by constrained_mechanism_impl.h. A contact row is open (released) or closed:
//   touchdown  an open row closes when φ = −gap ≥ 0 and it does not separate, J θ' − A v_c ≥ −ε
//   impact     plastic, eq. (2) for impulses on the closed rows: M dθ = −Jᵀ p, M_c dx_c = Aᵀ p,
//              J dθ − A dx_c = J θ' − A v_c; then θ' ← θ' − dθ (the least-kinetic-energy velocity
//              that keeps every closed row), the plane's impulse P = −p, the loss ½ Δvᵀ W Δv
//   lift-off   while a closed row's η < 0 (it would pull), the row pulling most opens, and solve again
//   locating   a step that ends past a plane is retaken to the crossing h, φ(h) = 0, by regula falsi
//              (Illinois) on h; the contact closes there and the rest of the step follows.
//   solving    at dynamic sizes the closed rows alone, compacted (J̃ = H̃ J, their J'θ' and Baumgarte
//              rows), η = 0 on the open ones; G and the Baumgarte term over every row from them.
#pragma once
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "physics/constrained_mechanism.h"
#include "physics/constraints/joint_limit.h"
#include "physics/fixed_size_copy.h"

namespace dyn {

template <class S, int Nj, int Nr, int Nl>
void ConstrainedMechanism<S, Nj, Nr, Nl>::setClosed(int i, bool closed) {
  const auto& c = *model_.constraints[std::size_t(i)];
  if (!c.unilateral() || c.compliant())
    throw std::invalid_argument("ConstrainedMechanism::setClosed: constraint " + std::to_string(i) + " is not a rigid unilateral contact");
  released_[std::size_t(i)] = char(!closed);
  ++closed_version_;
  invalidate();
}

// Joint limits alone (the PUMA file's rows): their constant J written once (constrained_mechanism.h
// limit_rows_); the position stage computes their φ in place.
template <class S, int Nj, int Nr, int Nl>
void ConstrainedMechanism<S, Nj, Nr, Nl>::limitRows() {
  limit_rows_.assign(model_.constraints.size(), LimitRow{});
  if constexpr (S::kDim == 6)
    for (std::size_t i = 0; i < model_.constraints.size(); ++i)
      if (const auto* limit = dynamic_cast<const JointLimit*>(model_.constraints[i].get()))
        limit_rows_[i] = {model_.tree.bodies[std::size_t(limit->joint())].q_index, limit->joint(), limit->sign(), limit->bound()};
  only_limits_ = !limit_rows_.empty() && std::all_of(limit_rows_.begin(), limit_rows_.end(), [](const LimitRow& l) { return l.coordinate >= 0; });
  // openDepth's shortcut: every rigid contact a limit (φ from q).
  depth_from_q_ = any_rigid_contact_;
  for (std::size_t i = 0; i < model_.constraints.size(); ++i)
    depth_from_q_ = depth_from_q_ && (!rigid_contact_[i] || limit_rows_[i].coordinate >= 0);
  if (!only_limits_) return;
  // The rows' constant J (JointLimit::position's entries), A empty of entries.
  J_full_.setZero(rows_, n());
  A_full_.setZero(rows_, k());
  for (std::size_t i = 0; i < limit_rows_.size(); ++i) J_full_(offsets_[i], limit_rows_[i].column) = -limit_rows_[i].sign;
}

// The position stage's pass over joint limits alone (only_limits_): each row's φ (LimitRow::phi), φ as
// the solve sees it (0 on the released rows), and the open ones' deepest φ and whether one is closed
// (every limit is a rigid contact). Out of stagePosition's own code: the labs' fixed sizes never take it.
template <class S, int Nj, int Nr, int Nl>
void ConstrainedMechanism<S, Nj, Nr, Nl>::limitRowsAtStage() {
  double depth = -INFINITY;
  bool closed = false;
  for (std::size_t i = 0; i < limit_rows_.size(); ++i) {
    const int r = offsets_[i];
    const double phi = limit_rows_[i].phi(kin_.theta);
    phi_full_[r] = phi;
    if (released_[i]) {
      phi_[r] = 0.0;
      depth = std::max(depth, phi);
    } else {
      phi_[r] = phi;
      closed = true;
    }
  }
  open_depth_ = depth, rigid_closed_ = closed, rigid_known_ = true;
}

// While some rows are released (a model file's joint limits away from their stops, contacts open),
// the solve at dynamic sizes holds only the closed rows, compacted: problem_'s J̃ = H̃ J, Ã = H̃ A, J'θ'
// and the Baumgarte term are the closed rows' alone (H̃ the rows of the identity at the closed rows, in
// order, closed_rows_; constrained_solve.h with J̃ given and no H̃), η = 0 on the released rows. The same
// θ'', α_c and η as the solve over every row with the released ones zeroed at unit compliance (each of
// those adds 0 · 0 to the closed rows' sums), without their rows × rows share of Λ nor their bias and
// Baumgarte rows: the PUMA file's twelve limit rows, mostly open, cost nothing in the solve. A fixed
// instantiation keeps its Nr rows (a lab's sizes). True when the rows were selected (selected_).
template <class S, int Nj, int Nr, int Nl>
bool ConstrainedMechanism<S, Nj, Nr, Nl>::selectClosedRows() {
  selected_ = false;
  if constexpr (Nr == Eigen::Dynamic) {
    if (!any_released_kind_) return false;
    // Only joint limits (J constant), the same rows closed as at the last selection: problem_ holds them.
    if (only_limits_ && selected_version_ == closed_version_) return selected_ = true;
    selected_version_ = -1;  // (problem_ is rewritten below, or by the unselected stage)
    closed_rows_.clear();
    for (std::size_t i = 0; i < model_.constraints.size(); ++i)
      if (!released_[i])
        for (int r = offsets_[i]; r < offsets_[i] + row_count_[i]; ++r) closed_rows_.push_back(r);
    const int m = int(closed_rows_.size()), nn = n(), kk = k();
    if (m == rows_) return false;
    problem_.J.resize(m, nn);
    problem_.A.resize(m, kk);
    for (int i = 0; i < m; ++i) {
      const int r = closed_rows_[std::size_t(i)];
      for (int j = 0; j < nn; ++j) problem_.J(i, j) = J_full_(r, j);
      for (int j = 0; j < kk; ++j) problem_.A(i, j) = A_full_(r, j);
    }
    problem_.compliance.resize(0);  // the released rows are out of the solve
    locked_rows_ = kk == 0 && lockedCoordinates();
    selected_ = true;
    if (only_limits_) selected_version_ = closed_version_;
  }
  return selected_;
}

// Whether every selected row locks a coordinate: one entry ±1 (J̃ = −σ e_cᵀ, σ = −J̃_c), each in its own
// column; their coordinates and signs for the elimination (constrained_solve.h factorLocked).
template <class S, int Nj, int Nr, int Nl>
bool ConstrainedMechanism<S, Nj, Nr, Nl>::lockedCoordinates() {
  lock_coordinate_.clear();
  lock_sign_.clear();
  lock_coordinate_.reserve(std::size_t(rows_));  // (once: no allocation in a step)
  lock_sign_.reserve(std::size_t(rows_));
  const int m = int(problem_.J.rows()), nn = n();
  for (int i = 0; i < m; ++i) {
    int column = -1;
    for (int j = 0; j < nn; ++j)
      if (problem_.J(i, j) != 0.0) {
        if (column >= 0) return false;
        column = j;
      }
    if (column < 0 || std::abs(problem_.J(i, column)) != 1.0) return false;
    if (std::find(lock_coordinate_.begin(), lock_coordinate_.end(), column) != lock_coordinate_.end()) return false;
    lock_coordinate_.push_back(column);
    lock_sign_.push_back(-problem_.J(i, column));
  }
  return true;
}

template <class S, int Nj, int Nr, int Nl>
bool ConstrainedMechanism<S, Nj, Nr, Nl>::factorClosedRows() {
  // (Rows are selected, and so locked, at dynamic sizes alone: a fixed instantiation leaves the
  // elimination out, whose n × 0 column block GCC warns about.)
  if constexpr (Nr == Eigen::Dynamic)
    if (locked_rows_) return factor_.factorLocked(problem_, lock_coordinate_.data(), lock_sign_.data(), int(lock_coordinate_.size()));
  return factor_.factor(problem_, problem_.J, problem_.A);
}

// out = the closed rows of a vector over every row (selectClosedRows), in order.
template <class S, int Nj, int Nr, int Nl>
template <class Out>
void ConstrainedMechanism<S, Nj, Nr, Nl>::gatherClosedRows(const VecN& all, Out& out) const {
  out.resize(Eigen::Index(closed_rows_.size()));
  for (std::size_t i = 0; i < closed_rows_.size(); ++i) out[Eigen::Index(i)] = all[closed_rows_[i]];
}

// η and f over every row from a solve on the closed rows (selectClosedRows): zero on the released ones.
template <class S, int Nj, int Nr, int Nl>
void ConstrainedMechanism<S, Nj, Nr, Nl>::scatterClosedRows(Solution& s) const {
  const auto eta = s.eta;
  s.eta.setZero(rows_);
  for (std::size_t i = 0; i < closed_rows_.size(); ++i) s.eta[closed_rows_[i]] = eta[Eigen::Index(i)];
  s.f = s.eta;
}

// The rows as the integrators see them (G = [J, −A] over every row, and the Baumgarte term), from the
// closed rows problem_ holds when they are selected.
template <class S, int Nj, int Nr, int Nl>
void ConstrainedMechanism<S, Nj, Nr, Nl>::constraint(const VecN& q, VecN& phi, MatN& G) {
  positionStage(q);
  phi = phi_;
  // G = [J, −A]: G v = J θ' − A v_c (the released rows zero: −0 in the −A part, as −A of a zero row).
  G.resize(rows_, n() + k());
  if (!selected()) {
    G.leftCols(n()) = problem_.J;
    if (k()) G.rightCols(k()) = -MatN(problem_.A);
    return;
  }
  G.leftCols(n()).setZero();
  if (k()) G.rightCols(k()).setConstant(-0.0);
  for (std::size_t i = 0; i < closed_rows_.size(); ++i) {
    const int r = closed_rows_[i];
    G.row(r).head(n()) = J_full_.row(r);
    if (k()) G.row(r).tail(k()) = -A_full_.row(r);
  }
}

template <class S, int Nj, int Nr, int Nl>
void ConstrainedMechanism<S, Nj, Nr, Nl>::baumgarteTerm(const VecN& q, const VecN& v, double zeta, double omega, VecN& s) {
  positionStage(q);
  // s = −2ζω (J θ' − A v_c) − ω² φ from the stage's own J and A (released rows are zero there); the
  // loops unrolled at fixed sizes.
  const int nn = Nj == Eigen::Dynamic ? n() : Nj, kk = Nl == Eigen::Dynamic ? k() : Nl, rows = Nr == Eigen::Dynamic ? rows_ : Nr;
  s.resize(rows);
  // With the closed rows selected: problem_.J's row i is row closed_rows_[i]; the released rows' s is
  // not solved for (0).
  const int m = selected() ? int(closed_rows_.size()) : rows;
  if (selected()) s.setZero();
  for (int i = 0; i < m; ++i) {
    const int r = selected() ? closed_rows_[std::size_t(i)] : i;
    double gv = 0.0;
    for (int j = 0; j < nn; ++j) gv += problem_.J(i, j) * v[j];
    for (int j = 0; j < kk; ++j) gv -= problem_.A(i, j) * v[nn + j];
    s[r] = -2.0 * zeta * omega * gv - omega * omega * phi_[r];
  }
}

// A contact at or past its plane closes unless it separates faster than this (m/s): rounding-size
// rates (±1e-17 after an impact that reopened) must not leave a penetrating contact open a step.
constexpr double kSeparating = 1e-9;

template <class S, int Nj, int Nr, int Nl>
int ConstrainedMechanism<S, Nj, Nr, Nl>::updateContacts(const VecN& q, VecN& v, const VecN& tau) {
  if (!any_released_kind_) return 0;
  const std::size_t count = model_.constraints.size();
  auto rigid = [&](std::size_t i) { return rigid_contact_[i] != 0; };
  // Touchdown: an open contact at or past its plane (φ = −gap ≥ 0) not moving away (−gap' ≥ 0); the
  // stage knows whether any is (open_depth_) and whether any is closed already. A new position is staged
  // with its rates (stageBoth: one pass where the tree allows it): the step's solve reads both.
  stagedContacts(q, &v);
  int changes = 0;
  bool any_closed = rigid_closed_;  // (after the touchdowns: the lift-off check's)
  for (std::size_t i = 0; open_depth_ >= 0.0 && i < count; ++i) {
    if (!rigid(i)) continue;
    if (!released_[i]) {
      any_closed = true;
      continue;
    }
    const int r = offsets_[i];
    if (!(phi_full_[r] >= 0.0)) continue;  // short of its plane (or stop)
    const double approach = J_full_.row(r).dot(v.head(n())) - (k() ? A_full_.row(r).dot(v.tail(k())) : 0.0);
    if (approach >= -kSeparating) {
      released_[i] = 0;
      ++closed_version_;
      ++changes;
      any_closed = true;
    }
  }
  // The plastic impact: the least-kinetic-energy velocity that satisfies every closed row, eq. (2) for
  // impulses (as correction(): M dθ = −Jᵀ p, J dθ − A dx_c = e = J θ' − A v_c, θ' ← θ' − dθ): the
  // table's impulse on the closed rows is P = −p.
  if (any_impact_) {
    for (Vec& p : impact_) p.setZero();
    any_impact_ = false;
  }
  if (changes) {
    invalidate();
    positionStage(q);
    if (!factored_) {
      projectVelocities(*this, q, v);  // the block LU's correction: no impulse recorded
    } else {
      VecN phi, dx;
      MatN G;
      constraint(q, phi, G);
      Solution s;
      if (impulseResponse(G * v, s, dx)) {
        v -= dx;
        const VecN dv = dx.head(n()), dvc = dx.tail(k());
        impact_loss_ += 0.5 * (dv.dot(problem_.M * dv) + (k() ? dvc.dot(problem_.Mc * dvc) : 0.0));
        const VecN P = -s.eta;
        for (std::size_t i = 0; i < count; ++i)
          if (rigid(i) && !released_[i]) impact_[i] = model_.constraints[i]->force(kin_, P.data() + offsets_[i]);
        any_impact_ = true;
      }
    }
  }
  // Lift-off: while a closed contact's η would pull, open the one pulling most and solve again.
  for (std::size_t pass = 0; any_closed && pass < count; ++pass) {
    const Solution s = evaluate(q, v, tau, nullptr, false, false);  // η alone (compacted when selected)
    std::size_t worst = count;
    double most = 0.0;
    if (selected()) {
      // The closed rows in order (selectClosedRows): each closed contact's first row, constraint by
      // constraint, as the loop below over η scattered to every row.
      for (std::size_t j = 0; j < closed_rows_.size(); ++j) {
        const int r = closed_rows_[j];
        const std::size_t i = std::size_t(row_owner_[std::size_t(r)]);
        if (rigid(i) && r == offsets_[i] && s.eta[Eigen::Index(j)] < most) most = s.eta[Eigen::Index(j)], worst = i;
      }
    } else {
      for (std::size_t i = 0; i < count; ++i)
        if (rigid(i) && !released_[i] && s.eta[offsets_[i]] < most) most = s.eta[offsets_[i]], worst = i;
    }
    if (worst == count) break;
    released_[worst] = 1;
    ++closed_version_;
    invalidate();
    ++changes;
  }
  return changes;
}

// m: how far past its plane a located touchdown may land (the root-finder's tolerance on φ).
constexpr double kTouchdownDepth = 1e-13;

template <class S, int Nj, int Nr, int Nl>
void ConstrainedMechanism<S, Nj, Nr, Nl>::rigidContactsAtStage() {
  double depth = -INFINITY;
  bool closed = false;
  for (std::size_t i = 0; any_rigid_contact_ && i < released_.size(); ++i) {
    if (!rigid_contact_[i]) continue;
    if (released_[i]) depth = std::max(depth, phi_full_[offsets_[i]]);
    else closed = true;
  }
  open_depth_ = depth, rigid_closed_ = closed, rigid_known_ = true;
}

template <class S, int Nj, int Nr, int Nl>
double ConstrainedMechanism<S, Nj, Nr, Nl>::openDepth(const VecN& q, bool stage) {
  if (!stage && depth_from_q_ && !(have_position_ && same(q, staged_q_))) {
    // The open limits' φ as stagePosition computes it (LimitRow::phi), with θ = q's tree part.
    double depth = -INFINITY;
    for (std::size_t i = 0; i < released_.size(); ++i)
      if (rigid_contact_[i] && released_[i]) depth = std::max(depth, limit_rows_[i].phi(q));
    return depth;
  }
  stagedContacts(q);
  return open_depth_;
}

template <class S, int Nj, int Nr, int Nl>
bool ConstrainedMechanism<S, Nj, Nr, Nl>::stepToTouchdowns(const StepOptions& o, const VecN& tau, VecN& q, VecN& v) {
  auto anyOpen = [&] { return anyOpenContact(); };
  StepOptions sub = o;  // the part of the step still to take
  // At most a few touchdowns per step (a contact the impact reopens may come back at once): past
  // them the step ends as it lands, and the next step's updateContacts closes what it finds.
  for (int event = 0;; ++event) {
    if (!anyOpen()) return dyn::step(*this, sub, tau, q, v);
    VecN q0, v0;  // (entry by entry at a fixed state size: no memcpy calls)
    setFixed<kState>(q0, q);
    setFixed<kState>(v0, v);
    // The clock and the books advance with every step taken: a trial restarts them from here.
    const double t0 = time();
    const Books b0 = books();
    if (!dyn::step(*this, sub, tau, q, v)) return false;
    // (The step's end staged, both stages at once: the next step's contact update and solve start
    // from them.)
    stage(q, &v);
    if (event == 3 || !(openDepth(q, true) > 0.0)) return true;
    // A crossing inside the step: bracket it from the start (φ < 0 there, else nothing to locate).
    double lo = 0.0, f_lo = openDepth(q0), hi = sub.dt, f_hi = openDepth(q), depth = f_hi;
    if (!(f_lo < 0.0)) return true;
    VecN q_hi = q, v_hi = v;
    double t_hi = time();
    Books b_hi = books();
    int side = 0;  // Illinois: the end kept twice in a row has its value halved (depth: its true φ)
    for (int it = 0; it < 100 && depth > kTouchdownDepth && hi - lo > 1e-15 * o.dt; ++it) {
      double h = (lo * f_hi - hi * f_lo) / (f_hi - f_lo);
      if (!(h > lo && h < hi)) h = 0.5 * (lo + hi);
      StepOptions trial = o;
      trial.dt = h;
      VecN qt = q0, vt = v0;
      setTime(t0);
      books() = b0;
      if (!dyn::step(*this, trial, tau, qt, vt)) return false;
      const double f = openDepth(qt);
      if (f > 0.0) {
        hi = h, f_hi = depth = f, q_hi = qt, v_hi = vt, t_hi = time(), b_hi = books();
        if (side == 1) f_lo *= 0.5;
        side = 1;
      } else {
        lo = h, f_lo = f;
        if (side == -1) f_hi *= 0.5;
        side = -1;
      }
    }
    // At the touchdown (at most kTouchdownDepth past the plane): close it, then the rest of the step.
    q = q_hi, v = v_hi;
    setTime(t_hi);
    books() = b_hi;
    updateContacts(q, v, tau);
    sub.dt -= hi;
    if (!(sub.dt > 1e-15 * o.dt)) return true;
  }
}

}  // namespace dyn
