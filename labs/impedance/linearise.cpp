// Each task axis (x, y) of the hand linearised at the reference pose, the other axes held: the arm's
// apparent mass along it is Λ_aa(q) of Λ = (J M⁻¹ Jᵀ)⁻¹ (the plant's), and the loop is
//   task_space              L(s) = (D_des s + K_des) / (Λ_aa s²)        the arm keeps its own Λ
//   feedback_linearisation  L(s) = (Λ̂_aa/Λ_aa)(D_des s + K_des) / (M_des s²)   (exact model: ratio 1)
//   joint_space             the same as feedback linearisation when the joint loop is fast and exact
//   none, constant          no feedback
// The closed loop's poles are then the target's Λ s² + D s + K (task_space) or M_des s² + D s + K.
// The delay is half the control period (the zero-order hold).
#include "labs/impedance/lab.h"

namespace dyn::impedance {

std::vector<LinearLoop> ImpedanceLab::linearise() const {
  motion_control::ArmMechanism plant(motion_control::describeRigid(s_.plant)), model(motion_control::describeRigid(s_.model));
  const VecN q(s_.pose), v = VecN::Zero(3);
  auto lambda = [&](motion_control::ArmMechanism& m) {
    MatN J3;
    VecN jd;
    m.pointJacobian(2, Planar::Pos(s_.plant.links[2].length, 0.0), q, v, J3, jd);
    MatN J(3, 3);
    J.row(0) = J3.row(1), J.row(1) = J3.row(2), J.row(2) = J3.row(0);
    return m.operationalInertia(q, J);
  };
  const MatN L = lambda(plant), Lh = lambda(model);
  std::vector<LinearLoop> loops;
  for (int a = 0; a < 2; ++a) {
    LinearLoop l;
    l.name = a == 0 ? "x" : "y";
    l.delay = 0.5 * s_.period;
    const double K = s_.law.K[a], D = s_.law.D[a], Laa = L.size() ? L(a, a) : 1.0, Lh_aa = Lh.size() ? Lh(a, a) : 1.0;
    const std::string axis = std::string(" along ") + l.name;
    switch (s_.kind) {
      case Kind::TaskSpace:
        l.what = "task-space PD" + axis, l.num = {K, D}, l.den = {0, 0, Laa};
        break;
      case Kind::FeedbackLinearisation:
      case Kind::JointSpace:
        l.what = (s_.kind == Kind::JointSpace ? "joint-space impedance" : "feedback-linearised impedance") + axis;
        l.num = {Lh_aa / Laa * K, Lh_aa / Laa * D}, l.den = {0, 0, s_.law.M[a]};
        break;
      default:
        l.what = "hand (no feedback)" + axis, l.num = {}, l.den = {0, 0, Laa};
    }
    loops.push_back(l);
  }
  return loops;
}

}  // namespace dyn::impedance
