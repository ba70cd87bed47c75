// The lecture's control laws (§4, §5) as arithmetic on the quantities a model gives, shared by every
// controller in dynlab: the data-defined labs' library (controller.h), the motion-control lab's joint
// controllers and the impedance lab's realisations. e = x_d − x (desired minus measured) throughout:
//   pd_gravity         τ = K_p e + K_d ė + Ĝ                       (ė = −θ' for regulation: passive)
//   pid                τ = K_p e + K_d ė + u_I,  u_I' = K_i e       (u_I in torque units, anti-windup below;
//                      Coulomb compensation F̂_c sat(θ_d'/w) optional)
//   computed torque    a = ẍ_d + K_p e + K_d ė, then τ = M̂ a + ĥ by the model's own inverse dynamics
//   task pd_gravity    τ = Ĝ + Jᵀ(K e + D ė)
//   target impedance   ẍ* = M_des⁻¹(F − D_des ẋ − K_des (x − x_ref))
// Gains are per coordinate (vectors, multiplied element by element). The arithmetic is written once
// here, in one order, so that every lab's law gives the same bits.
#pragma once
#include <algorithm>
#include <cmath>

#include <Eigen/Core>

namespace dyn::controllers::laws {

// τ = K_p e + K_d ė + G (the passive regulator when ė = −θ').
template <class V, class K>
V pdGravity(const K& kp, const V& e, const K& kd, const V& ed, const V& G) {
  return V(kp.cwiseProduct(e) + kd.cwiseProduct(ed) + G);
}

// The PID's proportional and derivative part plus the integral state u_I (torque units).
template <class V, class K>
V pid(const K& kp, const V& e, const K& kd, const V& ed, const V& u_i) {
  return V(kp.cwiseProduct(e) + kd.cwiseProduct(ed) + u_i);
}

// The computed-torque acceleration a = ẍ_d + K_p e + K_d ė: e'' + K_d e' + K_p e = 0 when the model is exact.
template <class V, class K>
V computedTorqueAcceleration(const V& xdd_d, const K& kp, const V& e, const K& kd, const V& ed) {
  return V(xdd_d + kp.cwiseProduct(e) + kd.cwiseProduct(ed));
}

// τ = G + Jᵀ(K e + D ė): a spring and damper at the task point, gravity cancelled.
template <class V, class J, class W, class K>
V taskPdGravity(const V& G, const J& jac, const K& k, const W& e, const K& d, const W& ed) {
  return V(G + jac.transpose() * (k.cwiseProduct(e) + d.cwiseProduct(ed)));
}

// The target impedance's acceleration ẍ* = M⁻¹(F − D ẋ − K (x − x_ref)).
template <class V>
V impedanceAcceleration(const V& F, const V& m, const V& d, const V& k, const V& x, const V& xd, const V& x_ref) {
  return V((F - d.cwiseProduct(xd) - k.cwiseProduct(x - x_ref)).cwiseQuotient(m));
}

// Coulomb compensation feedforward F̂_c sat(θ_d'/w): the friction the desired motion will meet, its sign
// smoothed over w so that a reference at rest asks for none.
inline double coulombCompensation(double coulomb, double desired_rate, double width) {
  return coulomb * std::clamp(desired_rate / width, -1.0, 1.0);
}

// Each τ_i clipped to ±τ_max,i (the plant interface); true if any clipped.
template <class V, class L>
bool saturate(V& tau, const L& limit) {
  bool clipped = false;
  for (Eigen::Index i = 0; i < tau.size(); ++i) {
    const double c = std::clamp(tau[i], -limit[i], limit[i]);
    clipped = clipped || c != tau[i];
    tau[i] = c;
  }
  return clipped;
}

// The PID's integral u_I (torque units), advanced after the output is known, so that anti-windup can
// read the saturation:
//   none              u_I += K_i e dt
//   clamping          the same, except while joint i's output sat at its limit pushing the way K_i e
//                     would push it further; u_I is kept within ±τ_max
//   back_calculation  u_I += (K_i e + (τ_sat − τ_raw)/T_t) dt   (the excess bleeds off in T_t)
enum class AntiWindup { None, Clamping, BackCalculation };

template <class V, class K, class L>
void integrate(V& u_i, AntiWindup mode, const K& ki, const V& e, const V& raw, const V& sat, const L& limit,
               double tracking_time, double dt) {
  for (Eigen::Index i = 0; i < u_i.size(); ++i) {
    const double push = ki[i] * e[i];  // u_I's rate without anti-windup
    if (mode == AntiWindup::Clamping) {
      const bool clipped = raw[i] != sat[i];
      if (!(clipped && push * raw[i] > 0)) u_i[i] += push * dt;
      u_i[i] = std::clamp(u_i[i], -limit[i], limit[i]);
    } else if (mode == AntiWindup::BackCalculation) {
      u_i[i] += (push + (sat[i] - raw[i]) / tracking_time) * dt;
    } else {
      u_i[i] += push * dt;
    }
  }
}

}  // namespace dyn::controllers::laws
