// A test's own integration of the motion-control arm (rigid or flexible) and of the impedance lab's
// pushed arm, written apart from dynlab's step: classic RK4 written out here, at a step `fine` times
// finer than the lab's, of
//   M(q) q'' = τ + J_tip(q)ᵀ F(t) − h(q, q') − k δ − b θ' − F_c tanh(θ'/w)
// with M and h = C q' + G from the tree algorithms (CRBA, RNEA: checked against each other and against
// closed forms in tests/physics), the springs, the friction and the push written here, τ held over each
// control period as the lab's controller would hold it (its own Controller, sampled on the reference's
// state). Used by tests/labs/stiff_terms_test.cpp to measure the lab's RK4 step (friction turning
// over, flexible joints, the push) against it.
#pragma once
#include <Eigen/Cholesky>
#include <cmath>
#include <functional>
#include <vector>

#include "labs/motion_control/controller.h"
#include "labs/motion_control/mechanism.h"

namespace dyn::test {

// The arm's equations of motion as the test writes them (see the top).
class ArmEquations {
 public:
  ArmEquations(const motion_control::Params& p, std::function<Eigen::Vector2d(double)> push = {})
      : p_(p), arm_(motion_control::describe(p)), push_(std::move(push)) {}

  VecN accel(double t, const VecN& q, const VecN& v, const VecN& tau) {
    const int n = p_.n();
    VecN f = tau - arm_.inverseDynamics(q, v, VecN::Zero(q.size()));
    for (int i = 0; i < n; ++i) {
      const int m = p_.flexible ? 2 * i : i;  // the joint the friction acts on (the rotor's, flexible)
      const double b = p_.friction[std::size_t(i)].viscous, Fc = p_.friction[std::size_t(i)].coulomb;
      f[m] -= b * v[m] + Fc * std::tanh(v[m] / p_.coulomb_width);
      if (p_.flexible) f[m + 1] -= p_.stiffness[std::size_t(i)] * q[m + 1];
    }
    if (push_) {
      MatN J;
      VecN jd;
      arm_.pointJacobian(p_.flexible ? 2 * n - 1 : n - 1, Planar::Pos(p_.links.back().length, 0.0), q, v, J, jd);
      const Eigen::Vector2d F = push_(t);
      f += J.transpose() * Planar::Vec(0.0, F.x(), F.y());
    }
    return VecN(arm_.massMatrix(q).ldlt().solve(Eigen::VectorXd(f)));
  }

  // One classic RK4 step of h from t0 + s with τ held (t0 a lab step's time, s the offset in it); the
  // last stage just inside the step (1e-9 h short of its end, clear of rounding: a push switched at
  // the step's end acts from the next step on).
  void step(double t0, double s, double h, const VecN& tau, VecN& q, VecN& v) {
    const VecN a1 = accel(t0 + s, q, v, tau);
    const VecN q2 = q + 0.5 * h * v, v2 = v + 0.5 * h * a1;
    const VecN a2 = accel(t0 + (s + 0.5 * h), q2, v2, tau);
    const VecN q3 = q + 0.5 * h * v2, v3 = v + 0.5 * h * a2;
    const VecN a3 = accel(t0 + (s + 0.5 * h), q3, v3, tau);
    const VecN q4 = q + h * v3, v4 = v + h * a3;
    const VecN a4 = accel(t0 + (s + (1 - 1e-9) * h), q4, v4, tau);
    q += h / 6 * (v + 2 * v2 + 2 * v3 + v4);
    v += h / 6 * (a1 + 2 * a2 + 2 * a3 + a4);
  }

 private:
  motion_control::Params p_;
  motion_control::ArmMechanism arm_;
  std::function<Eigen::Vector2d(double)> push_;
};

// The reference run: `steps` lab steps of dt from (q, v), each in `fine` RK4 steps; τ from `torque`
// (t, q, v) every `hold` lab steps (a lab step k at t = k dt). Returns the state at every lab step
// (k = 0 … steps).
struct ReferenceRun {
  std::vector<VecN> q, v;
};
inline ReferenceRun referenceRun(ArmEquations& eq, VecN q, VecN v, double dt, long steps, int fine, long hold,
                                 const std::function<VecN(double, const VecN&, const VecN&)>& torque) {
  ReferenceRun out;
  VecN tau;
  const double h = dt / fine;
  for (long k = 0;; ++k) {
    out.q.push_back(q), out.v.push_back(v);
    if (k == steps) return out;
    if (k % hold == 0) tau = torque(double(k) * dt, q, v);
    for (int j = 0; j < fine; ++j) eq.step(double(k) * dt, j * h, h, tau, q, v);
  }
}

}  // namespace dyn::test
