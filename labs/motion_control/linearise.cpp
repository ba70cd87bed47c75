// Each joint loop of the controller linearised at the outstretched and the folded configuration
// (lecture §4: constant gains meet a configuration-dependent inertia). Joint i alone, the others
// held, about rest: the plant is m_ii(θ) s² + b_i s (m_ii the plant's, b_i its viscous friction):
//   pid              L(s) = (k_D s² + k_P s + k_I) / (s (m_ii s² + b_i s))
//   pd_gravity       L(s) = (k_D s + k_P) / (m_ii s² + b_i s)          (Ĝ cancels gravity)
//   computed_torque  L(s) = (m̂_ii / m_ii)(K_d s + K_p) / s²             (exact model: the ratio is 1)
//   none, constant   no feedback (zero numerator)
// The delay is half the control period (the zero-order hold). Flexible joints are screened rigid:
// the screening states what the rigid-model gains do, the simulation shows what the springs add.
#include "labs/motion_control/lab.h"

namespace dyn::motion_control {

std::vector<LinearLoop> MotionControlLab::linearise() const {
  const int n = s_.plant.n();
  const ControllerConfig& c = s_.controller;
  ArmMechanism plant(describeRigid(s_.plant)), model(describeRigid(s_.model));
  std::vector<LinearLoop> loops;
  for (const auto& [pose, theta] : {std::pair<const char*, Eigen::VectorXd>{"out", s_.trajectory.outstretched},
                                    std::pair<const char*, Eigen::VectorXd>{"fold", s_.trajectory.folded}}) {
    const MatN M = plant.massMatrix(VecN(theta)), Mh = model.massMatrix(VecN(theta));
    for (int i = 0; i < n; ++i) {
      const double m = M(i, i), b = s_.plant.friction[std::size_t(i)].viscous;
      LinearLoop l;
      l.name = "j" + std::to_string(i + 1) + "_" + pose;
      l.delay = 0.5 * c.period;
      const std::string where = std::string(" at joint ") + std::to_string(i + 1) + (pose[0] == 'o' ? ", outstretched" : ", folded");
      switch (c.kind) {
        case Kind::Pid:
          l = {l.name, "PID loop" + where, {c.ki[i], c.kp[i], c.kd[i]}, {0, 0, b, m}, l.delay};
          break;
        case Kind::PdGravity:
          l = {l.name, "PD + gravity loop" + where, {c.kp[i], c.kd[i]}, {0, b, m}, l.delay};
          break;
        case Kind::ComputedTorque:
          l = {l.name, "computed-torque loop" + where, {Mh(i, i) / m * c.kp[i], Mh(i, i) / m * c.kd[i]}, {0, 0, 1}, l.delay};
          break;
        default:
          l = {l.name, "joint loop (no feedback)" + where, {}, {0, b, m}, l.delay};
      }
      // A pole–zero pair at s = 0 (pid without k_I) cancels: the loop is PD.
      while (l.num.size() > 1 && l.den.size() > 1 && l.num[0] == 0 && l.den[0] == 0)
        l.num.erase(l.num.begin()), l.den.erase(l.den.begin());
      loops.push_back(l);
    }
  }
  return loops;
}

}  // namespace dyn::motion_control
