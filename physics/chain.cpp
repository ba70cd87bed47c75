// Tree algorithms of lecture eq. (1) — RNEA, CRBA, ABA, point Jacobians — written once for
// planar and spatial algebra and instantiated for both (see chain.h for the equations).
#include "physics/chain.h"
#include "physics/chain_sized.h"
#include "physics/chain_world.h"

#include <cmath>
#include <stdexcept>

#include "physics/det/det.h"

namespace dyn {

template <class S>
typename TreeModel<S>::Vec TreeModel<S>::motionSubspace(int i) const {
  const Body& b = bodies[i];
  if constexpr (S::kDim == 3) {
    return b.joint != JointType::Prismatic ? S::revoluteAxis() : S::prismaticAxis(b.axis);
  } else {
    return b.joint != JointType::Prismatic ? S::revoluteAxis(b.axis) : S::prismaticAxis(b.axis);
  }
}

template <class S>
void TreeData<S>::resize(int n) {
  X_up.resize(n);
  X_world.resize(n);
  S_i.resize(n);
  S_w.resize(n);
  v.resize(n);
  c.resize(n);
  a.resize(n);
  f.resize(n);
  Ic.resize(n);
  Ic_rb.resize(n);
  I_w.resize(n);
  v_w.resize(n);
  a_w.resize(n);
  U.resize(n);
  pA.resize(n);
  D.resize(n);
  u.resize(n);
}


template <class S>
void positionKinematics(const TreeModel<S>& model, const VecIn& q, TreeData<S>& data) {
  sized::kinematics<true, Eigen::Dynamic>(model, q, data);
}

template <class S>
void worldKinematics(const TreeModel<S>& model, const VecIn& q, TreeData<S>& data) {
  sized::kinematics<false, Eigen::Dynamic>(model, q, data);
}

template <class S>
void velocityKinematics(const TreeModel<S>& model, const VecIn& qd, TreeData<S>& data) {
  using Vec = typename S::Vec;
  for (int i = 0; i < model.dof(); ++i) {
    const int p = model.bodies[i].parent;
    // Body velocity: the parent's, carried across the joint, plus the joint's own S_i θ'_i.
    const Vec vJ = data.S_i[i] * qd[i];
    if (p < 0) data.v[i] = vJ;
    else data.v[i] = S::motion(data.X_up[i], data.v[p]) + vJ;
    // Velocity-product acceleration of the joint: c_i = V_i ×m S_i θ'_i; a ball's sub-body: the
    // parent's velocity carried to it, without its siblings' rates (chain.h).
    if (model.bodies[i].joint == JointType::Ball) {
      const int first = model.balls[std::size_t(model.bodies[i].ball)].first, pf = model.bodies[std::size_t(first)].parent;
      data.c[i] = pf < 0 ? Vec(Vec::Zero()) : S::crossMotion(S::motion(data.X_up[first], data.v[pf]), vJ);
    } else {
      data.c[i] = S::crossMotion(data.v[i], vJ);
    }
  }
}

template <class S>
void forwardKinematics(const TreeModel<S>& model, const VecIn& q, const VecIn& qd, TreeData<S>& data) {
  positionKinematics(model, q, data);
  velocityKinematics(model, qd, data);
}

template <class S>
void rnea(const TreeModel<S>& model, TreeData<S>& data, const VecIn& qd, const VecIn& qdd,
          Eigen::Ref<Eigen::VectorXd> tau, bool with_gravity) {
  const int n = model.dof();
  (void)qd;  // velocities enter through data.v, filled by forwardKinematics
  const typename S::Vec a0 = -model.gravity;
  // Outward: accelerations without gravity (data.a: at θ'' = 0 each link's velocity-product
  // acceleration), then the net force each body needs, gravity added as the world's acceleration
  // −g seen in the body's frame (by linearity the same as starting the recursion from −g).
  for (int i = 0; i < n; ++i) {
    const auto& b = model.bodies[i];
    data.a[i] = (b.parent < 0 ? typename S::Vec(data.S_i[i] * qdd[i]) : typename S::Vec(S::motion(data.X_up[i], data.a[b.parent]) + data.S_i[i] * qdd[i])) + data.c[i];
    // A massless body (a carrier: zero mass and rotational inertia) needs no force of its own.
    if (b.massless) {
      data.f[i].setZero();
      continue;
    }
    const typename S::Vec a = with_gravity ? typename S::Vec(data.a[i] + S::motion(data.X_world[i], a0)) : data.a[i];
    const auto& I = S::compact(b.inertia);  // spatial: the 13 numbers, cheaper to multiply than 6×6
    data.f[i] = S::inertiaTimes(I, a) + S::crossForce(data.v[i], S::inertiaTimes(I, data.v[i]));
  }
  // Inward: project onto the joint axis, pass the rest to the parent.
  for (int i = n - 1; i >= 0; --i) {
    tau[i] = S::dot(data.S_i[i], data.f[i]);
    const int p = model.bodies[i].parent;
    if (p >= 0) data.f[p] += S::forceTranspose(data.X_up[i], data.f[i]);
  }
}

template <class S>
VecN rnea(const TreeModel<S>& model, TreeData<S>& data, const VecIn& qd, const VecIn& qdd, bool with_gravity) {
  VecN tau(model.dof());
  rnea(model, data, qd, qdd, tau, with_gravity);
  return tau;
}

// M from composite inertias in world coordinates (chain_world.h: they simply add there).
template <class S>
void crba(const TreeModel<S>& model, TreeData<S>& data, Eigen::Ref<Eigen::MatrixXd> M) {
  crbaWorld(model, data, M);
}

template <class S>
MatN crba(const TreeModel<S>& model, TreeData<S>& data) {
  MatN M(model.dof(), model.dof());
  crba(model, data, M);
  return M;
}

template <class S>
void aba(const TreeModel<S>& model, TreeData<S>& data, const VecIn& qd, const VecIn& tau,
         Eigen::Ref<Eigen::VectorXd> qdd) {
  (void)qd;
  const int n = model.dof();
  using Vec = typename S::Vec;
  using Mat = typename S::Mat;
  for (int i = 0; i < n; ++i) {
    data.Ic[i] = model.bodies[i].inertia;  // articulated inertia I^A
    data.pA[i] = S::crossForce(data.v[i], model.bodies[i].inertia * data.v[i]);
  }
  // Inward: articulated inertias and bias forces.
  for (int i = n - 1; i >= 0; --i) {
    data.U[i] = data.Ic[i] * data.S_i[i];
    data.D[i] = S::dot(data.S_i[i], data.U[i]);
    data.u[i] = tau[i] - S::dot(data.S_i[i], data.pA[i]);
    const int p = model.bodies[i].parent;
    if (p >= 0) {
      const Mat Ia = data.Ic[i] - data.U[i] * data.U[i].transpose() / data.D[i];
      const Vec pa = data.pA[i] + Ia * data.c[i] + data.U[i] * (data.u[i] / data.D[i]);
      const Mat X = S::motionMatrix(data.X_up[i]);
      data.Ic[p] += X.transpose() * Ia * X;
      data.pA[p] += S::forceTranspose(data.X_up[i], pa);
    }
  }
  // Outward: accelerations.
  const Vec a0 = -model.gravity;
  for (int i = 0; i < n; ++i) {
    const int p = model.bodies[i].parent;
    const Vec a_in = S::motion(data.X_up[i], p < 0 ? a0 : data.a[p]) + data.c[i];
    qdd[i] = (data.u[i] - S::dot(data.U[i], a_in)) / data.D[i];
    data.a[i] = a_in + data.S_i[i] * qdd[i];
  }
}

template <class S>
VecN aba(const TreeModel<S>& model, TreeData<S>& data, const VecIn& qd, const VecIn& tau) {
  VecN qdd(model.dof());
  aba(model, data, qd, tau, qdd);
  return qdd;
}

template <class S>
typename S::Pos pointPosition(const TreeData<S>& data, int body, const typename S::Pos& point) {
  return S::worldPoint(data.X_world[body], point);
}

template <class S>
void pointJacobian(const TreeModel<S>& model, const TreeData<S>& data, int body,
                   const typename S::Pos& point, MatN& J) {
  // World origin → the world-aligned frame at the point.
  if (model.dof() > kMaxDof) throw std::length_error("pointJacobian: J holds at most kMaxDof columns");
  const typename S::Transform X_pw = S::translation(pointPosition(data, body, point));
  J.setZero(S::kDim, model.dof());
  // Column j: joint j's axis, seen from the point, for every joint on the path root → body.
  for (int j = body; j >= 0; j = model.bodies[j].parent)
    J.col(j) = S::motion(X_pw, data.S_w[j]);
}

template <class S>
void pointJacobianDot(const TreeModel<S>& model, const TreeData<S>& data, int body,
                      const typename S::Pos& point, VecN& Jdot_qd) {
  using Vec = typename S::Vec;
  const typename S::Transform X_pw = S::translation(pointPosition(data, body, point));
  // The path root → body, and the velocity-product acceleration along it (θ'' = 0, no gravity).
  int stack_path[kMaxDof];
  std::vector<int> long_path;  // a path longer than kMaxDof: on the heap (large chains only)
  int* path = stack_path;
  if (model.dof() > kMaxDof) long_path.resize(std::size_t(model.dof())), path = long_path.data();
  int depth = 0;
  for (int j = body; j >= 0; j = model.bodies[j].parent) path[depth++] = j;
  Vec a_bias = Vec::Zero();
  for (int k = depth - 1; k >= 0; --k) {
    const int j = path[k];
    a_bias = (model.bodies[j].parent < 0 ? Vec(Vec::Zero()) : Vec(S::motion(data.X_up[j], a_bias))) + data.c[j];
  }
  // Both at the point in world axes, then the classical acceleration J'θ'.
  const Vec v_p = S::motion(X_pw, S::motionInverse(data.X_world[body], data.v[body]));
  const Vec a_p = S::motion(X_pw, S::motionInverse(data.X_world[body], a_bias));
  Jdot_qd = S::classicalAcceleration(a_p, v_p);
}

template <class S>
void pointJacobian(const TreeModel<S>& model, const TreeData<S>& data, int body,
                   const typename S::Pos& point, MatN& J, VecN& Jdot_qd) {
  pointJacobian(model, data, body, point, J);
  pointJacobianDot(model, data, body, point, Jdot_qd);
}

template <class S>
double kineticEnergy(const TreeModel<S>& model, const TreeData<S>& data) {
  double T = 0;
  for (int i = 0; i < model.dof(); ++i) T += 0.5 * S::dot(data.v[i], S::inertiaTimes(model.bodies[i].inertia, data.v[i]));
  return T;
}

template <class S>
double potentialEnergy(const TreeModel<S>& model, const TreeData<S>& data) {
  double U = 0;
  for (int i = 0; i < model.dof(); ++i) {
    double m;
    typename S::Pos c;
    S::massAndCom(model.bodies[i].inertia, m, c);
    U -= m * S::linear(model.gravity).dot(pointPosition(data, i, c));
  }
  return U;
}

TreeModel<Planar> uniformPlanarChain(int n, double length, double mass, double g) {
  TreeModel<Planar> m;
  for (int i = 0; i < n; ++i) {
    const Planar::Pos joint = i == 0 ? Planar::Pos::Zero() : Planar::Pos(length, 0.0);
    m.addBody(i - 1, JointType::Revolute, Planar::Axis::Zero(), Planar::translation(joint),
              Planar::inertia(mass, Planar::Pos(length / 2, 0.0), mass * length * length / 12));
  }
  m.gravity << 0, 0, -g;
  return m;
}

VecN springTorque(const VecN& k, const VecN& q) { return springStiffnessMatrix(k) * q; }

MatN springStiffnessMatrix(const VecN& k) {
  const int n = int(k.size());
  MatN K = MatN::Zero(n, n);
  for (int i = 0; i < n; ++i) {
    K(i, i) = k[i] + (i + 1 < n ? k[i + 1] : 0.0);
    if (i + 1 < n) K(i, i + 1) = K(i + 1, i) = -k[i + 1];
  }
  return K;
}

double springEnergy(const VecN& k, const VecN& q) {
  double P = 0;
  for (int i = 0; i < k.size(); ++i) {
    const double d = q[i] - (i > 0 ? q[i - 1] : 0.0);
    P += 0.5 * k[i] * d * d;
  }
  return P;
}

#define DYNLAB_INSTANTIATE(S)                                                                     \
  template struct TreeModel<S>;                                                                   \
  template struct TreeData<S>;                                                                    \
  template void forwardKinematics<S>(const TreeModel<S>&, const VecIn&, const VecIn&, TreeData<S>&); \
  template void positionKinematics<S>(const TreeModel<S>&, const VecIn&, TreeData<S>&);           \
  template void worldKinematics<S>(const TreeModel<S>&, const VecIn&, TreeData<S>&);              \
  template void velocityKinematics<S>(const TreeModel<S>&, const VecIn&, TreeData<S>&);            \
  template void rnea<S>(const TreeModel<S>&, TreeData<S>&, const VecIn&, const VecIn&,             \
                        Eigen::Ref<Eigen::VectorXd>, bool);                                       \
  template VecN rnea<S>(const TreeModel<S>&, TreeData<S>&, const VecIn&, const VecIn&, bool);     \
  template MatN crba<S>(const TreeModel<S>&, TreeData<S>&);                                       \
  template void crba<S>(const TreeModel<S>&, TreeData<S>&, Eigen::Ref<Eigen::MatrixXd>);          \
  template void aba<S>(const TreeModel<S>&, TreeData<S>&, const VecIn&, const VecIn&,              \
                       Eigen::Ref<Eigen::VectorXd>);                                              \
  template VecN aba<S>(const TreeModel<S>&, TreeData<S>&, const VecIn&, const VecIn&);            \
  template void pointJacobian<S>(const TreeModel<S>&, const TreeData<S>&, int, const S::Pos&,     \
                                 MatN&, VecN&);                                                   \
  template void pointJacobian<S>(const TreeModel<S>&, const TreeData<S>&, int, const S::Pos&, MatN&); \
  template void pointJacobianDot<S>(const TreeModel<S>&, const TreeData<S>&, int, const S::Pos&,  \
                                    VecN&);                                                       \
  template S::Pos pointPosition<S>(const TreeData<S>&, int, const S::Pos&);                       \
  template double kineticEnergy<S>(const TreeModel<S>&, const TreeData<S>&);                      \
  template double potentialEnergy<S>(const TreeModel<S>&, const TreeData<S>&);
DYNLAB_INSTANTIATE(Planar)
DYNLAB_INSTANTIATE(Spatial)
#undef DYNLAB_INSTANTIATE

}  // namespace dyn
