// A lab's MuJoCo twin (mujoco_twin.h): the coordinate map and the hand model's M and bias.
#include "labs/mujoco_twin.h"

#include "physics/constrained_mechanism.h"

namespace dyn {

VecN MujocoTwin::toFile(const VecN& x) const {
  if (order.empty()) return x;
  VecN out(Eigen::Index(order.size()));
  for (std::size_t i = 0; i < order.size(); ++i) out[Eigen::Index(i)] = x[order[i]];
  return out;
}

VecN MujocoTwin::fromFile(const VecN& x) const {
  if (order.empty()) return x;
  VecN out(Eigen::Index(order.size()));
  for (std::size_t i = 0; i < order.size(); ++i) out[order[i]] = x[Eigen::Index(i)];
  return out;
}

template <class S>
std::function<void(const VecN&, const VecN&, MatN&, VecN&)> handDynamics(const MechanismModel<S>& description) {
  // The trees alone (the constraints bear on neither M nor the bias); payloads added below.
  MechanismModel<S> trees;
  trees.tree = description.tree;
  trees.joints = description.joints;
  auto mech = std::make_shared<ConstrainedMechanism<S>>(trees);
  const std::vector<Payload> payloads = description.payloads;
  const typename S::Vec gravity = description.tree.gravity;
  return [mech, payloads, gravity](const VecN& q, const VecN& v, MatN& M, VecN& bias) {
    const int n = mech->n();
    int k = 0;
    for (const Payload& p : payloads) k += p.dof();
    M.setZero(n + k, n + k);
    bias.setZero(n + k);
    M.topLeftCorner(n, n) = mech->massMatrix(q.head(n));
    bias.head(n) = mech->inverseDynamics(q.head(n), v.head(n), VecN::Zero(n));
    int at = n;
    for (const Payload& p : payloads) {
      // (ψ, x, y): inertia about the centre of mass, then the mass twice; gravity's (0, g_x, g_y).
      const double diagonal[3] = {p.inertia, p.mass, p.mass};
      for (int c = 0; c < 3; ++c) {
        if (!p.free[std::size_t(c)]) continue;
        M(at, at) = diagonal[c];
        bias[at] = c == 0 ? 0.0 : -p.mass * gravity[c];
        ++at;
      }
    }
  };
}

template std::function<void(const VecN&, const VecN&, MatN&, VecN&)> handDynamics(const MechanismModel<Planar>&);
template std::function<void(const VecN&, const VecN&, MatN&, VecN&)> handDynamics(const MechanismModel<Spatial>&);

}  // namespace dyn
