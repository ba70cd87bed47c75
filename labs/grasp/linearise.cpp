// The grasp controller's loops, linearised at the start pose (controller.h):
//   pose     per object coordinate c ∈ {x, y, ψ}:  M_cc e'' + k_d e' + k_p e = 0
//            L(s) = (k_d s + k_p) / (M_cc s²),  M = Tᵀ W T: the whole mechanism's inertia seen along the
//            object's coordinates (T: the rates of q per unit object rate, the fingers' inverse kinematics;
//            the fingers' share is not compensated by the controller), delay dt/2 (the torque is held a step)
//   squeeze  f_int = s + d (d: the motion-induced squeeze):  integral  L(s) = k_i / s,  delay: the force
//            measurement's, at least one step; k_i = 0 is the open-loop squeeze (no feedback)
// Each screened as it runs, sampled every dt (physics/linear.h, SampledLoop): the pose loops' G through
// the zero-order hold; the squeeze law sums the reading after each step's push, the next step's squeeze
// uses Σ up to f(k + 1 − N) (N: the delay in steps): L(z) = k_i dt z^{−(N−1)}/(z − 1), a delay of
// N dt − dt/2 in continuous terms.
// Every loop is reported with the controller off too (no feedback), so the screening metrics always exist.
#include <cmath>

#include "labs/delay_line.h"
#include "labs/grasp/lab.h"

namespace dyn::grasp {

std::vector<LinearLoop> GraspLab::linearise() const {
  const auto& c = s_.controller;
  const bool on = c.kind == ControllerKind::Grasp;
  const Gains g = on ? c.gains : Gains{};
  // The inertia along each object coordinate at the start: Tᵀ W T.
  Mechanism mech(s_.params);
  VecN q, v;
  mech.assemble(s_.pose0, Eigen::Vector3d::Zero(), q, v);
  MatN W;
  mech.metric(q, W);
  double inertia[3];
  for (int k = 0; k < 3; ++k) {
    VecN qk, tk;
    mech.assemble(s_.pose0, Eigen::Vector3d::Unit(k), qk, tk);
    inertia[k] = tk.dot(W * tk);
  }
  const double dt = s_.step.dt;
  const std::string off = " (controller off)";
  std::vector<LinearLoop> loops;
  loops.push_back({"x", on ? "object x loop (PD, k_p and k_d)" : "object x loop" + off, {g.kp_pos, g.kd_pos}, {0, 0, inertia[1]}, 0.5 * dt});
  loops.push_back({"y", on ? "object y loop (PD, k_p and k_d)" : "object y loop" + off, {g.kp_pos, g.kd_pos}, {0, 0, inertia[2]}, 0.5 * dt});
  loops.push_back({"psi", on ? "object tilt loop (PD, k_pψ and k_dψ)" : "object tilt loop" + off, {g.kp_psi, g.kd_psi}, {0, 0, inertia[0]}, 0.5 * dt});
  if (on)
    for (auto& l : loops) l.sampled = {dt, l.num, l.den};
  const double delay = DelayLine::realised(c.delay, dt);
  if (on && g.ki_int != 0) {
    loops.push_back({"squeeze", "internal-force loop (integral law, k_i)", {g.ki_int}, {0, 1}, delay - 0.5 * dt});
    loops.back().sampled = {dt, {1}, {1}, {g.ki_int * dt}, {-1, 1}, int(DelayLine::steps(c.delay, dt)) - 1};
  } else
    loops.push_back({"squeeze", on ? "internal-force loop (open loop: k_i = 0)" : "internal-force loop" + off, {}, {1}, delay});
  return loops;
}

}  // namespace dyn::grasp
