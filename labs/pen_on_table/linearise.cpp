// The pen-on-table controller's loops, linearised at the circle's first point on the table (controller.h):
//   motion  the tip under the task-space PD, Λ ẍ = k_p (x_d − x) − k_v ẋ in its heaviest direction
//           (the largest eigenvalue m of Λ = (J M⁻¹ Jᵀ)⁻¹: the least damped):  L(s) = (k_v s + k_p) / (m s²),
//           delay dt/2 (the torque is held over the step)
//   force   on a rigid table the tip cannot move along z, so f_z = k_p (z_des − z_t): the lecture's loops
//             damper  ż_des = −(f(t − T) − f_zd)/D_z  ⇒  f' = −(k_p/D_z)(f(t − T) − f_zd):  L(s) = (k_p/D_z)/s
//                     pole −k_p/D_z (time constant D_z/k_p), stable iff (k_p/D_z) T < π/2
//             spring  z_des = z_ref − (f(t − T) − f_zd)/K_z  ⇒  f = … − (k_p/K_z) f(t − T):  L(s) = k_p/K_z,
//                     stable under any delay iff k_p/K_z < 1; its steady-state error when the table is Δ
//                     higher than z_ref assumes: −(k_p K_z/(k_p + K_z)) Δ
//           on a compliant table (k_e) the position loop and the table are springs in series:
//           k_p → k_p k_e/(k_p + k_e). T: the sensor's realised delay, plus one step for the damper (its
//           z_des integrates the reading of the step before).
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
  // The force loop: the position loop's stiffness in series with the table's.
  const double k_e = s_.params.table_stiffness, k = k_e > 0 ? g.kp * k_e / (g.kp + k_e) : g.kp;
  const double T = DelayLine::realised(c.delay, dt);
  if (!on) loops.push_back({"force", "normal-force loop (controller off)", {}, {1}, T});
  else if (c.law == ForceLaw::Damper)
    loops.push_back({"force", "normal-force loop (generalized damper, k_p/D_z)", {k / g.D_z}, {0, 1}, T + dt});
  else
    loops.push_back({"force", "normal-force loop (generalized spring, k_p/K_z)", {k / g.K_z}, {1}, T});
  return loops;
}

}  // namespace dyn::pen_on_table
