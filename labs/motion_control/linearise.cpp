// Each joint loop of the controller linearised at the outstretched and the folded configuration
// (lecture §4: constant gains meet a configuration-dependent inertia). Joint i alone, the others
// held, about rest; gravity's gradient and Coulomb friction (and its compensation) are left out.
// The controller acts on the motor side: u = −C(s) θm, with
//   pid              C(s) = (k_D s² + k_P s + k_I) / s
//   pd_gravity       C(s) = k_D s + k_P                       (Ĝ cancels gravity)
//   computed_torque  C(s) = m̂_ii (K_d s + K_p) − b̂_i s      (the rigid model's m̂_ii; its viscous
//                                                             estimate b̂_i cancels the plant's b_i)
//   none, constant   no feedback (zero numerator)
// and the plant θm/τ is
//   rigid            1 / (m_ii s² + b_i s)                    (m_ii of the plant's rigid arm)
//   flexible         (m_L s² + k) / (s (J_m m_L s³ + b m_L s² + (J_m + m_L) k s + b k))   (linearise.h)
// so L(s) = C(s) · plant; computed torque's −b̂ s is folded into the plant (b → b − b̂). With the
// springs, the rigid-model gains meet a 4th-order plant: the least damped pole pair is the vibration
// the student sees, named in the screening's remark (and flagged under ζ = kLightDamping). As k → ∞
// the flexible loop tends to the rigid loop of an arm whose rotor turns with its link (m = J_m + m_L).
// The delay is half the control period (the zero-order hold).
#include "labs/motion_control/linearise.h"

#include <cmath>
#include <cstdio>

#include "labs/motion_control/lab.h"
#include "labs/numbers.h"
#include "physics/det/det.h"

namespace dyn::motion_control {
namespace {

std::string fmtNumber(double x) { return fmt("%.3g", x); }

// The vibration mode of a flexible loop in one sentence (empty if its poles have no complex pair).
std::string modeRemark(const LinearLoop& loop) {
  const Mode m = leastDampedMode(analyseLoop(loop));
  if (!m.found) return {};
  std::string r = "least damped mode " + fmtNumber(m.damped) + " rad/s (" + fmtNumber(m.damped / (2 * M_PI)) +
                  " Hz), ζ = " + fmtNumber(m.damping);
  if (m.damping < 0) r += " — warning: it grows, the spring's vibration is unstable";
  else if (m.damping < kLightDamping)
    r += " — warning: lightly damped (ζ < " + fmtNumber(kLightDamping) + "), the gains ring the spring";
  return r;
}

}  // namespace

FlexibleJoint flexibleJoint(const Params& plant, const Eigen::VectorXd& theta, int i) {
  ArmMechanism arm(describe(plant));
  VecN q, v;
  treeState(plant, theta, Eigen::VectorXd::Zero(plant.n()), q, v);
  const MatN M = arm.massMatrix(q);
  FlexibleJoint j;
  j.link = M(2 * i + 1, 2 * i + 1);
  j.rotor = M(2 * i, 2 * i) - j.link;
  j.stiffness = plant.stiffness[std::size_t(i)];
  j.viscous = plant.friction[std::size_t(i)].viscous;
  return j;
}

Mode leastDampedMode(const LoopAnalysis& a) {
  Mode m;
  for (const auto& p : a.poles) {
    if (p.imag() <= 1e-9 * det::abs(p)) continue;  // one of each pair, complex only
    const double zeta = -p.real() / det::abs(p);
    if (!m.found || zeta < m.damping) m = {true, det::abs(p), p.imag(), zeta};
  }
  return m;
}

std::vector<LinearLoop> MotionControlLab::linearise() const {
  const int n = s_.plant.n();
  const ControllerConfig& c = s_.controller;
  const bool flexible = s_.plant.flexible;
  ArmMechanism plant(describeRigid(s_.plant)), model(describeRigid(s_.model));
  std::vector<LinearLoop> loops;
  for (const auto& [pose, theta] : {std::pair<const char*, Eigen::VectorXd>{"out", s_.trajectory.outstretched},
                                    std::pair<const char*, Eigen::VectorXd>{"fold", s_.trajectory.folded}}) {
    const MatN M = plant.massMatrix(VecN(theta)), Mh = model.massMatrix(VecN(theta));
    for (int i = 0; i < n; ++i) {
      LinearLoop l;
      l.name = "j" + std::to_string(i + 1) + "_" + pose;
      l.delay = 0.5 * c.period;
      const std::string where = std::string(" at joint ") + std::to_string(i + 1) + (pose[0] == 'o' ? ", outstretched" : ", folded") +
                                (flexible ? ", flexible (rotor, spring, link)" : "");
      // The controller C(s) (numerator over a power of s) and its name.
      Poly ctrl;
      int ctrl_poles = 0;  // C(s)'s poles at s = 0
      double b_hat = 0;    // computed torque's viscous estimate, fed back positively
      switch (c.kind) {
        case Kind::Pid: ctrl = {c.ki[i], c.kp[i], c.kd[i]}, ctrl_poles = 1, l.what = "PID loop" + where; break;
        case Kind::PdGravity: ctrl = {c.kp[i], c.kd[i]}, l.what = "PD + gravity loop" + where; break;
        case Kind::ComputedTorque: {
          // Rigid: written over m_ii (L = (m̂_ii/m_ii)(K_d s + K_p)/s² when b̂ = b), as it always was.
          const double scale = flexible ? Mh(i, i) : Mh(i, i) / M(i, i);
          ctrl = {scale * c.kp[i], scale * c.kd[i]}, b_hat = s_.model.friction[std::size_t(i)].viscous;
          l.what = "computed-torque loop" + where;
          break;
        }
        default: l.what = "joint loop (no feedback)" + where;
      }
      // The plant θm/τ = P_num / P_den, computed torque's b̂ folded in.
      Poly p_num, p_den;
      if (flexible) {
        const FlexibleJoint f = flexibleJoint(s_.plant, theta, i);
        const double J = f.rotor, m = f.link, k = f.stiffness, b = f.viscous - b_hat;
        p_num = {k, 0, m};
        p_den = {0, b * k, (J + m) * k, b * m, J * m};
      } else {
        const double m = M(i, i), b = s_.plant.friction[std::size_t(i)].viscous - b_hat;
        p_num = {1};
        p_den = c.kind == Kind::ComputedTorque ? Poly{0, b / m, 1} : Poly{0, b, m};
      }
      l.num = ctrl.empty() ? Poly{} : polyMul(ctrl, p_num);
      l.den = p_den;
      if (ctrl_poles) l.den.insert(l.den.begin(), 0.0);
      // Pole–zero pairs at s = 0 (pid without k_I; computed torque with b̂ = b) cancel.
      while (l.num.size() > 1 && l.den.size() > 1 && l.num[0] == 0 && l.den[0] == 0)
        l.num.erase(l.num.begin()), l.den.erase(l.den.begin());
      if (flexible && !l.num.empty()) l.remark = modeRemark(l);
      loops.push_back(l);
    }
  }
  return loops;
}

}  // namespace dyn::motion_control
