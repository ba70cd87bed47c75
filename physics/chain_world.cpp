// Tree dynamics in world coordinates (equations in chain_world.h), for planar and spatial algebra.
#include "physics/chain_world.h"

namespace dyn {

template <class S>
void crbaWorld(const TreeModel<S>& model, TreeData<S>& data, Eigen::Ref<Eigen::MatrixXd> M) {
  const int n = model.dof();
  // World inertias (kept for the velocity stage), each also its composite's first term.
  typename S::Inertia zero{};
  if constexpr (S::kDim == 3) zero.setZero();
  for (int i = 0; i < n; ++i) {
    const auto& b = model.bodies[std::size_t(i)];
    if (b.massless) data.I_w[i] = data.Ic_rb[i] = zero;
    else if constexpr (S::kDim == 6) S::inertiaInParent(data.X_world[i], b.central, data.I_w[i], data.Ic_rb[i]);  // from the centre of mass
    else data.I_w[i] = data.Ic_rb[i] = S::inertiaInParent(data.X_world[i], b.inertia);
  }
  // Composite inertias, leaves to root: in one frame they simply add.
  for (int i = n - 1; i >= 0; --i) {
    const int p = model.bodies[std::size_t(i)].parent;
    if (p >= 0) data.Ic_rb[p] += data.Ic_rb[i];
  }
  for (int j = 0; j < n; ++j) {
    // The force that moving joint j alone needs, seen by every joint on the way to the root (parents
    // precede their children); the joints off that path see none. Each entry written once (M is
    // symmetric): no zeroing pass first, which for a small M is a memset call.
    const typename S::Vec F = S::inertiaTimes(data.Ic_rb[j], data.S_w[j]);
    for (int r = j, i = j; r >= 0; --r)
      if (r == i) {
        M(i, j) = M(j, i) = S::dot(data.S_w[i], F);
        i = model.bodies[std::size_t(i)].parent;
      } else {
        M(r, j) = M(j, r) = 0.0;
      }
  }
}

template <class S>
void biasForcesWorld(const TreeModel<S>& model, TreeData<S>& data, const VecN& qd, Eigen::Ref<Eigen::VectorXd> h) {
  using Vec = typename S::Vec;
  const int n = model.dof();
  // Outward: velocities, velocity-product accelerations, and each massive body's net force.
  for (int i = 0; i < n; ++i) {
    const auto& b = model.bodies[std::size_t(i)];
    const Vec vJ = data.S_w[i] * qd[i];
    data.v_w[i] = b.parent < 0 ? vJ : Vec(data.v_w[b.parent] + vJ);
    // (A root's V_i ×m S_i θ'_i is S_i θ'_i × itself: zero. A ball's sub-body: V_parent ×m S_i θ'_i,
    // without its siblings' rates: chain.h.)
    int anchor = i;
    if (b.joint == JointType::Ball) anchor = model.bodies[std::size_t(model.balls[std::size_t(b.ball)].first)].parent;
    const Vec c = b.parent < 0 || anchor < 0 ? Vec(Vec::Zero()) : S::crossMotion(data.v_w[anchor], vJ);
    data.a_w[i] = b.parent < 0 ? c : Vec(data.a_w[b.parent] + c);
    if (b.massless) {
      data.f[i].setZero();
      continue;
    }
    const Vec a = data.a_w[i] - model.gravity;
    data.f[i] = S::inertiaTimes(data.I_w[i], a) + S::crossForce(data.v_w[i], S::inertiaTimes(data.I_w[i], data.v_w[i]));
  }
  // Inward: each joint carries its subtree's forces (same frame: a sum).
  for (int i = n - 1; i >= 0; --i) {
    h[i] = S::dot(data.S_w[i], data.f[i]);
    const int p = model.bodies[std::size_t(i)].parent;
    if (p >= 0) data.f[p] += data.f[i];
  }
}

template <class S>
double kineticEnergyWorld(const TreeModel<S>& model, const TreeData<S>& data) {
  double T = 0;
  for (int i = 0; i < model.dof(); ++i) T += 0.5 * S::dot(data.v_w[i], S::inertiaTimes(data.I_w[i], data.v_w[i]));
  return T;
}

#define DYNLAB_INSTANTIATE(S)                                                                  \
  template void crbaWorld<S>(const TreeModel<S>&, TreeData<S>&, Eigen::Ref<Eigen::MatrixXd>);  \
  template void biasForcesWorld<S>(const TreeModel<S>&, TreeData<S>&, const VecN&, Eigen::Ref<Eigen::VectorXd>); \
  template double kineticEnergyWorld<S>(const TreeModel<S>&, const TreeData<S>&);
DYNLAB_INSTANTIATE(Planar)
DYNLAB_INSTANTIATE(Spatial)
#undef DYNLAB_INSTANTIATE

}  // namespace dyn
