// The slider-crank controller's loops, linearised at the start configuration (controller.h):
//   motion   m_eff x_c'' = k_px (x_d − x_c) + k_dx (ẋ_d − v_c)   ⇒  L(s) = (k_dx s + k_px) / (m_eff s²)
//            m_eff = m_c + θ_xᵀ M θ_x,  θ_x = J⁻¹ A  (the arm's inertia seen along the slide)
//            delay dt/2: the zero-order hold of a torque computed once per step
//   force    f_Ty = ξ + d:  integral  L(s) = k_if / s,  proportional  L(s) = k_pf,  open loop: L = 0
//            delay: the measurement delay, at least one step (N steps)
// Each screened as it runs, sampled every dt (physics/linear.h, SampledLoop): the motion loop's G
// through the zero-order hold; the integral law sums the reading after each step's push, ξ(k+1) uses
// Σ up to f(k + 1 − N): L(z) = k_if dt z^{−(N−1)}/(z − 1), a delay of N dt − dt/2 in continuous terms;
// the proportional law reads f(k − N): L(z) = k_pf z^{−N}.
// Both loops are reported for every force law and with the controller off: a loop the
// configuration does not close has L = 0 (no feedback), so the screening metrics always exist.
#include <Eigen/LU>
#include <cmath>

#include "labs/delay_line.h"
#include "labs/slider_crank/lab.h"

namespace dyn::slider_crank {

std::vector<LinearLoop> SliderCrankLab::linearise() const {
  const auto& c = s_.controller;
  const bool on = c.kind != ControllerKind::None;
  const Gains g = on ? c.gains : Gains{};  // the controller off closes no loop
  // Effective mass along the slide at the start configuration.
  Mechanism mech(s_.params);
  VecN q, v;
  mech.initialState(s_.theta1, s_.theta1_rate, s_.branch, q, v);
  MatN W, J;
  VecN unused;
  mech.metric(q, W);
  mech.tipJacobian(q.head(3), Eigen::Vector3d::Zero(), J, unused);
  Eigen::Vector4d dq;
  dq << Eigen::Matrix3d(J).fullPivLu().solve(Eigen::Vector3d(0, 1, 0)), 1.0;
  const double m_eff = dq.dot(Eigen::Matrix4d(W) * dq);

  const double dt = s_.step.dt;
  std::vector<LinearLoop> loops;
  loops.push_back({"motion", on ? "slider position loop (PD, k_px and k_dx)" : "slider position loop (controller off)",
                   {g.kp_x, g.kd_x}, {0, 0, m_eff}, 0.5 * dt});
  if (on) loops.back().sampled = {dt, {g.kp_x, g.kd_x}, {0, 0, m_eff}};
  const double delay = DelayLine::realised(c.delay, dt);
  const int N = int(DelayLine::steps(c.delay, dt));
  if (on && c.law == ForceLaw::Integral) {
    loops.push_back({"force", "rail-force loop (integral law, k_if)", {g.ki_f}, {0, 1}, delay - 0.5 * dt});
    loops.back().sampled = {dt, {1}, {1}, {g.ki_f * dt}, {-1, 1}, N - 1};
  } else if (on && c.law == ForceLaw::Proportional) {
    loops.push_back({"force", "rail-force loop (proportional law, k_pf)", {g.kp_f}, {1}, delay});
    loops.back().sampled = {dt, {1}, {1}, {g.kp_f}, {1}, N};
  } else
    loops.push_back({"force", on ? "rail-force loop (open loop)" : "rail-force loop (controller off)", {}, {1}, delay});
  return loops;
}

}  // namespace dyn::slider_crank
