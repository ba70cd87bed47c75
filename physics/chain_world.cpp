// Tree dynamics in world coordinates (equations in chain_world.h), for planar and spatial algebra.
#include "physics/chain_world.h"

#include "physics/chain_sized.h"

namespace dyn {

template <class S>
void crbaWorld(const TreeModel<S>& model, TreeData<S>& data, Eigen::Ref<Eigen::MatrixXd> M) {
  sized::crbaWorld<Eigen::Dynamic>(model, data, M);
}

template <class S>
void biasForcesWorld(const TreeModel<S>& model, TreeData<S>& data, const VecN& qd, Eigen::Ref<Eigen::VectorXd> h) {
  sized::biasForcesWorld<Eigen::Dynamic>(model, data, qd, h);
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
