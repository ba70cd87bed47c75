// The pen-on-table controller's loops, linearised at the circle's first point on the table (controller.h),
// each screened as it runs: sampled every dt (physics/linear.h, SampledLoop), with the continuous L(s)
// beside it for the lecture's formulas, the crossover and the phase margin:
//   motion  the tip under the task-space PD, Λ ẍ = k_p (x_d − x) − k_v ẋ in its heaviest direction
//           (the largest eigenvalue m of Λ = (J M⁻¹ Jᵀ)⁻¹: the least damped):  L(s) = (k_v s + k_p) / (m s²);
//           sampled: that G through the zero-order hold (τ computed from the state at t_k, held a step);
//           continuous equivalent delay dt/2
//   force   on a rigid table the tip cannot move along z, so f_z = k_p (z_des − z_t) at every step: the
//           lecture's loops, with N = the sensor's delay in steps (at least one)
//             damper  ż_des = −(f(t − T) − f_zd)/D_z,  L(s) = (k_p/D_z)/s: pole −k_p/D_z, stable iff (k_p/D_z) T < π/2;
//                     as it runs z_des integrates by explicit Euler after its use, z_des(k+1) = z_des(k) −
//                     dt (f(k − N) − f_zd)/D_z:  L(z) = (k_p dt/D_z) z^{−N}/(z − 1), whose characteristic
//                     z^{N+1} − z^N + k_p dt/D_z is the simulated force's recursion; continuous equivalent
//                     delay N dt + dt/2 (the Euler integrator's half step)
//             spring  z_des = z_ref − (f(t − T) − f_zd)/K_z:  L = k_p/K_z, L(z) = (k_p/K_z) z^{−N}: stable
//                     under any delay iff k_p/K_z < 1; its steady-state error when the table is Δ higher
//                     than z_ref assumes: −(k_p K_z/(k_p + K_z)) Δ
//           on a compliant table (k_e) the position loop and the table are springs in series:
//           k_p → k_p k_e/(k_p + k_e) (quasi-static: the tip's own mode on the table left out).
// Both loops are reported for every force law and with the controller off (L = 0): the screening
// metrics always exist.
#include <Eigen/Eigenvalues>

#include "labs/delay_line.h"
#include "labs/pen_on_table/lab.h"

namespace dyn::pen_on_table {

std::vector<LinearLoop> PenOnTableLab::linearise() const {
  const auto& c = s_.controller;
  const bool on = c.kind == ControllerKind::Accommodation;
  const Gains g = on ? c.gains : Gains{0, 0, 1, 1};
  const double dt = s_.step.dt;
  // The tip's heaviest direction at the circle's first point, on the table.
  Mechanism mech(s_.params);
  Eigen::Vector3d th;
  inverseKinematics(s_.params, {s_.circle.centre.x() + s_.circle.radius, s_.circle.centre.y(), s_.params.table_height}, th);
  Eigen::Vector3d p, Jdv;
  Eigen::Matrix3d J;
  mech.tipJacobian(th, VecN::Zero(3), p, J, Jdv);
  const MatN Lambda = mech.operationalInertia(th, MatN(J));
  const double m = Lambda.size() ? Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(Eigen::Matrix3d(Lambda)).eigenvalues().maxCoeff() : 1.0;
  std::vector<LinearLoop> loops;
  loops.push_back({"motion", on ? "tip position loop (PD, k_p and k_v)" : "tip position loop (controller off)", {g.kp, g.kv}, {0, 0, m}, 0.5 * dt});
  if (on) loops.back().sampled = {dt, {g.kp, g.kv}, {0, 0, m}};
  // The force loop: the position loop's stiffness in series with the table's.
  const double k_e = s_.params.table_stiffness, k = k_e > 0 ? g.kp * k_e / (g.kp + k_e) : g.kp;
  const double T = DelayLine::realised(c.delay, dt);
  const int N = int(DelayLine::steps(c.delay, dt));
  if (!on) {
    loops.push_back({"force", "normal-force loop (controller off)", {}, {1}, T});
  } else if (c.law == ForceLaw::Damper) {
    loops.push_back({"force", "normal-force loop (generalized damper, k_p/D_z)", {k / g.D_z}, {0, 1}, T + 0.5 * dt});
    loops.back().sampled = {dt, {k}, {1}, {dt / g.D_z}, {-1, 1}, N};
  } else {
    loops.push_back({"force", "normal-force loop (generalized spring, k_p/K_z)", {k / g.K_z}, {1}, T});
    loops.back().sampled = {dt, {k}, {1}, {1 / g.K_z}, {1}, N};
  }
  return loops;
}

}  // namespace dyn::pen_on_table
