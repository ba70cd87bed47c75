// Tree dynamics in world coordinates: chain.h's crba, and the mechanism's velocity stage (lecture
// eq. (1): the same C θ' + G as chain.h's rnea, which works in body coordinates).
// With every body's inertia and joint axis in world coordinates at the world origin,
// I_i^w = X_iᵀ I_i X_i and S_i^w (X_i: world → body i, from positionKinematics), the recursions
// need no transform per joint (Featherstone's absolute-coordinate form; MuJoCo works this way too):
//   V_i = V_p + S_i^w θ'_i                       link velocity
//   A_i = A_p + V_i ×m S_i^w θ'_i                velocity-product acceleration (θ'' = 0): J'θ' of its points
//   F_i = I_i^w (A_i − g) + V_i ×* I_i^w V_i     net force (gravity: the world accelerating at −g)
//   h_i = S_i^w · Σ_{j in subtree(i)} F_j        h = C θ' + G
//   I_c,i = I_i^w + Σ_{children j} I_c,j         composite inertias: a plain sum
//   M_ij = S_i^w · I_c,j S_j^w                   for i on the path root → j
// The world origin is the reference point: fine at the scale of a lab bench (metres).
#pragma once
#include "physics/chain.h"

namespace dyn {

// M(θ) (into M, sized n × n by the caller), after positionKinematics (or worldKinematics); leaves
// I_i^w of every body in data.I_w (zero for massless ones).
template <class S>
void crbaWorld(const TreeModel<S>& model, TreeData<S>& data, Eigen::Ref<Eigen::MatrixXd> M);
// h = C θ' + G (into h, sized n by the caller), leaving data.v_w and data.a_w; after crbaWorld.
template <class S>
void biasForcesWorld(const TreeModel<S>& model, TreeData<S>& data, const VecN& qd, Eigen::Ref<Eigen::VectorXd> h);
// ½ Σ V_i · I_i^w V_i from the last biasForcesWorld.
template <class S>
double kineticEnergyWorld(const TreeModel<S>& model, const TreeData<S>& data);

}  // namespace dyn
