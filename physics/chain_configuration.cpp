// The configuration operations of a tree with ball joints (chain.h): q has a unit quaternion
// Q = (w, x, y, z) per ball (MuJoCo's qpos), θ' its local angular velocity ω (MuJoCo's qvel).
//   q̇ = N(q) θ'          Q̇ = ½ Q ⊗ (0, ω)                 (the integrators' RK4 in the embedding)
//   q ⊕ h θ'             Q ⊗ (cos(|ω|h/2), ω̂ sin(|ω|h/2)) (the exponential map, as MuJoCo's
//                                                          mj_integratePos; Euler and the projection)
//   normalisation        Q / |Q|                            (after a step in the embedding)
// Hinges and slides: identity maps, q[q_index] = θ'.
#include <cmath>

#include "physics/chain.h"
#include "physics/det/det.h"

namespace dyn {

namespace {

// q ⊗ p for quaternions (w, x, y, z) stored in 4 doubles.
void quatMultiply(const double* a, const double* b, double* out) {
  out[0] = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3];
  out[1] = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2];
  out[2] = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1];
  out[3] = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0];
}

void normalize4(double* Q) {
  const double n = std::sqrt(Q[0] * Q[0] + Q[1] * Q[1] + Q[2] * Q[2] + Q[3] * Q[3]);
  if (!(n > 0)) {
    Q[0] = 1, Q[1] = Q[2] = Q[3] = 0;
    return;
  }
  for (int k = 0; k < 4; ++k) Q[k] /= n;
}

}  // namespace

template <class S>
void configurationRate(const TreeModel<S>& model, const VecIn& q, const VecIn& qd, Eigen::Ref<Eigen::VectorXd> qdot) {
  for (int i = 0; i < model.dof(); ++i) {
    const auto& b = model.bodies[std::size_t(i)];
    if (b.joint != JointType::Ball) {
      qdot[b.q_index] = qd[i];
      continue;
    }
    if (i != model.balls[std::size_t(b.ball)].first) continue;
    const double Q[4] = {q[b.q_index], q[b.q_index + 1], q[b.q_index + 2], q[b.q_index + 3]};
    const double w[4] = {0.0, 0.5 * qd[i], 0.5 * qd[i + 1], 0.5 * qd[i + 2]};
    quatMultiply(Q, w, qdot.data() + b.q_index);
  }
}

template <class S>
void integrateConfiguration(const TreeModel<S>& model, Eigen::Ref<Eigen::VectorXd> q, const VecIn& qd, double h) {
  for (int i = 0; i < model.dof(); ++i) {
    const auto& b = model.bodies[std::size_t(i)];
    if (b.joint != JointType::Ball) {
      q[b.q_index] += h * qd[i];
      continue;
    }
    if (i != model.balls[std::size_t(b.ball)].first) continue;
    double* Q = q.data() + b.q_index;
    const double wx = qd[i], wy = qd[i + 1], wz = qd[i + 2];
    const double speed = std::sqrt(wx * wx + wy * wy + wz * wz), angle = speed * h;
    if (speed == 0.0 || angle == 0.0) continue;
    const double s = det::sin(0.5 * angle) / speed;
    const double dq[4] = {det::cos(0.5 * angle), wx * s, wy * s, wz * s};
    const double Q0[4] = {Q[0], Q[1], Q[2], Q[3]};
    quatMultiply(Q0, dq, Q);
    normalize4(Q);
  }
}

template <class S>
void normalizeConfiguration(const TreeModel<S>& model, Eigen::Ref<Eigen::VectorXd> q) {
  for (const auto& ball : model.balls) normalize4(q.data() + model.bodies[std::size_t(ball.first)].q_index);
}

#define DYNLAB_INSTANTIATE(S)                                                                                    \
  template void configurationRate<S>(const TreeModel<S>&, const VecIn&, const VecIn&, Eigen::Ref<Eigen::VectorXd>); \
  template void integrateConfiguration<S>(const TreeModel<S>&, Eigen::Ref<Eigen::VectorXd>, const VecIn&, double);  \
  template void normalizeConfiguration<S>(const TreeModel<S>&, Eigen::Ref<Eigen::VectorXd>);
DYNLAB_INSTANTIATE(Planar)
DYNLAB_INSTANTIATE(Spatial)
#undef DYNLAB_INSTANTIATE

}  // namespace dyn
