// The unicycle controller's loops, linearised about straight rolling at the nominal speed v (controller.h):
//   speed     J_y θ'' = τ_y, J_y = I_a + m r²;  PI on θ':      L(s) = (k_iv + k_pv s) / (J_y s²)
//   heading   I_z φ'' = τ_z;                   PD on φ:       L(s) = (k_pφ + k_dφ s) / (I_z s²)
//   cross     e_ct' = v (φ − φ_d), φ following φ_c = −k_ct e_ct through the closed heading loop
//             T(s) = (k_pφ + k_dφ s) / (I_z s² + k_dφ s + k_pφ):   L(s) = k_ct v T(s) / s
// Each with the actuation delay plus half a step (the torque is held over the step). Every loop is
// reported with the controller off too (no feedback), so the screening metrics always exist.
#include "labs/delay_line.h"
#include "labs/unicycle/lab.h"

namespace dyn::unicycle {

std::vector<LinearLoop> UnicycleLab::linearise() const {
  const auto& c = s_.controller;
  const bool on = c.kind == ControllerKind::Path;
  const Gains g = on ? c.gains : Gains{};
  const Mechanism mech(s_.params);
  const double Jy = mech.driveInertia(), Iz = s_.params.steer_inertia, v = s_.reference.speed;
  const double delay = (c.delay > 0 ? DelayLine::realised(c.delay, s_.step.dt) : 0.0) + 0.5 * s_.step.dt;
  const std::string off = " (controller off)";
  std::vector<LinearLoop> loops;
  loops.push_back({"speed", on ? "speed loop (PI on θ', k_pv and k_iv)" : "speed loop" + off, {g.ki_speed, g.kp_speed}, {0, 0, Jy}, delay});
  loops.back().controller_integrators = 1;  // the PI law's 1/s: with k_iv = 0 the loop is P on θ'
  loops.push_back({"heading", on ? "heading loop (PD, k_pφ and k_dφ)" : "heading loop" + off, {g.kp_heading, g.kd_heading}, {0, 0, Iz}, delay});
  const double k = g.k_cross * v;
  loops.push_back({"cross", on ? "cross-track loop (k_ct through the heading loop)" : "cross-track loop" + off,
                   {k * g.kp_heading, k * g.kd_heading}, {0, g.kp_heading, g.kd_heading, Iz}, delay});
  return loops;
}

}  // namespace dyn::unicycle
