// The controller library (labs/controllers) on a URDF arm, against what each law says term by term:
//  * per-joint gains: with joint_scale s, joint PD + gravity gives τ_u − G_u = K_p s∘e exactly (G_u
//    from an independent ClosedChain of the same model), and pid's first command K_p s∘e;
//  * the integral's anti-windup under saturation: none winds up as K_i e t, clamping holds |u_I| ≤
//    τ_max, back-calculation settles at τ_max − K_p e + K_i e T_t (where raw − τ_sat = K_i e T_t);
//  * Coulomb compensation adds F̂_c sat(u_d'/w) from the model's joint friction, with the u_d' that moves
//    the tool at x_d' (J_x u_d' = x_d', J_x from an independent ClosedChain).
//  * the impedance laws on the PUMA 560 (6 joints, a 3-axis tool position: redundant), the plant the
//    hand engine with the push as an external force: at a moving state, impedance_inverse_dynamics'
//    tool acceleration J θ'' + J'θ' is the target's ẍ* = M⁻¹(F − D ẋ − K(x − x_ref)) computed here, and
//    impedance_task's obeys Λ ẍ = F + K e − D ẋ at rest (Λ from the mechanism's operationalInertia);
//    both settle at the target's static deflection F/K under a constant push, the posture term holding
//    the null space; with force feedback the push response is the target's, without it is not;
//    impedance_joint (the model on the measured force → inverse kinematics → computed torque) settles at
//    F/K too, and misses the target's response less as its joint loop's ω_n grows (series compliance).
#include <doctest/doctest.h>

#include <cmath>

#include "labs/controllers/controller.h"
#include "physics/forces.h"
#include "physics/integrate.h"
#include "physics/model_file/model_file.h"

using namespace dyn;

namespace {

struct Arm {
  model_file::LoadedModel file = model_file::load(std::string(DYNLAB_SOURCE_DIR) + "/assets/models/planar_arm.urdf");
  std::vector<int> act{0, 1, 2};
  controllers::TaskPoint tool{2, Eigen::Vector3d(0.2, 0, 0), {3, 5}};
  VecN pose = (VecN(3) << 0.3, 0.6, -0.4).finished();
  // The task point's position at the pose (the reference that leaves u_d at the pose).
  VecN toolAt(const VecN& q) {
    ConstrainedMechanism<Spatial> m(file.mechanism);
    const Eigen::Vector3d p = m.pointPosition(tool.link, tool.point, q);
    return (VecN(2) << p.x(), p.z()).finished();
  }
  controllers::Controller make(controllers::Spec spec, const MechanismModel<Spatial>& model) {
    spec.period = 1e-3;
    if (spec.torque_limit.size() == 0) spec.torque_limit = VecN::Constant(3, 1e3);
    return controllers::Controller(spec, model, act, tool, pose, 1e-3);
  }
};

}  // namespace

TEST_CASE("the library's joint laws: per-joint gains scale K_p e, gravity from the model") {
  Arm arm;
  const VecN delta = (VecN(3) << 0.01, -0.02, 0.03).finished(), q = arm.pose + delta, v = VecN::Zero(3);
  const controllers::Reference ref{arm.toolAt(arm.pose), VecN::Zero(2), VecN::Zero(2)};
  const VecN s = (VecN(3) << 1.0, 2.0, 3.0).finished();
  ConstrainedMechanism<Spatial> mech(arm.file.mechanism);
  ClosedChain<ConstrainedMechanism<Spatial>> chain(mech, arm.act);
  REQUIRE(chain.update(q, v));
  for (const auto kind : {controllers::Kind::JointPdGravity, controllers::Kind::Pid}) {
    controllers::Spec spec;
    spec.kind = kind, spec.kp = 100, spec.kd = 5, spec.joint_scale = s;
    auto ctl = arm.make(spec, arm.file.mechanism);
    const VecN tau = ctl.torque(0, q, v, ref);
    const VecN expected = kind == controllers::Kind::Pid ? VecN(-100 * s.cwiseProduct(delta))
                                                         : VecN(-100 * s.cwiseProduct(delta) + chain.Gu());
    CHECK((tau - expected).cwiseAbs().maxCoeff() < 1e-12);
  }
}

TEST_CASE("the library's pid: anti-windup bounds the integral under saturation") {
  Arm arm;
  const VecN e = (VecN(3) << 0.01, -0.02, 0.03).finished(), q = arm.pose - e, v = VecN::Zero(3);
  const controllers::Reference ref{arm.toolAt(arm.pose), VecN::Zero(2), VecN::Zero(2)};
  const double kp = 10, ki = 1000, limit = 1.0, tt = 0.05;
  for (const auto aw : {controllers::laws::AntiWindup::None, controllers::laws::AntiWindup::Clamping,
                        controllers::laws::AntiWindup::BackCalculation}) {
    controllers::Spec spec;
    spec.kind = controllers::Kind::Pid, spec.kp = kp, spec.ki = ki, spec.anti_windup = aw, spec.tracking_time = tt;
    spec.torque_limit = VecN::Constant(3, limit);
    auto ctl = arm.make(spec, arm.file.mechanism);
    const int steps = 2000;  // 2 s: K_i |e| t reaches 20–60 N·m unchecked
    for (int k = 0; k < steps; ++k) ctl.torque(k * 1e-3, q, v, ref);
    CHECK(ctl.saturated());
    const VecN& ui = ctl.integral();
    for (int j = 0; j < 3; ++j) {
      INFO("joint " << j);
      if (aw == controllers::laws::AntiWindup::None) CHECK(std::abs(ui[j]) == doctest::Approx(ki * std::abs(e[j]) * steps * 1e-3));
      if (aw == controllers::laws::AntiWindup::Clamping) CHECK(std::abs(ui[j]) <= limit);
      if (aw == controllers::laws::AntiWindup::BackCalculation)
        CHECK(std::abs(ui[j]) == doctest::Approx(limit - kp * std::abs(e[j]) + ki * std::abs(e[j]) * tt).epsilon(1e-6));
    }
  }
}

TEST_CASE("the library's pid: Coulomb compensation adds the model's F_c sat(u_d'/w)") {
  Arm arm;
  MechanismModel<Spatial> model = arm.file.mechanism;
  model.joints.resize(3);
  const double fc[3] = {0.5, 0.3, 0.2};
  for (int j = 0; j < 3; ++j) model.joints[std::size_t(j)].coulomb = fc[j];
  const VecN q = arm.pose, v = VecN::Zero(3);
  // The tool asked to move at 0.3 m/s along x; w wide enough that sat(u_d'/w) = u_d'/w.
  const VecN xd = (VecN(2) << 0.3, 0.0).finished();
  const controllers::Reference ref{arm.toolAt(arm.pose), xd, VecN::Zero(2)};
  controllers::Spec spec;
  spec.kind = controllers::Kind::Pid, spec.kp = 50, spec.compensation_width = 100;
  auto plain = arm.make(spec, model);
  spec.coulomb_compensation = true;
  auto compensated = arm.make(spec, model);
  const VecN diff = compensated.torque(0, q, v, ref) - plain.torque(0, q, v, ref);
  // The u_d' the compensation used, F_c,j u_d',j / w ⇒ u_d',j = diff_j w / F_c,j, must move the tool at x_d'.
  VecN ud(3);
  for (int j = 0; j < 3; ++j) ud[j] = diff[j] * spec.compensation_width / fc[j];
  ConstrainedMechanism<Spatial> mech(model);
  ClosedChain<ConstrainedMechanism<Spatial>> chain(mech, arm.act);
  REQUIRE(chain.update(q, v));
  Eigen::Vector3d p;
  MatN J;
  VecN bias;
  chain.task(arm.tool.link, arm.tool.point, arm.tool.axes, p, J, bias);
  CHECK((J * ud - xd).cwiseAbs().maxCoeff() < 1e-12);
  CHECK(ud.cwiseAbs().maxCoeff() > 0.1);
}

namespace {

// The PUMA 560 with its tool 0.1 m beyond the wrist centre on the flange axis (puma_motion's), in a
// bent pose away from the wrist's singularity.
struct Puma {
  model_file::LoadedModel file = model_file::load(std::string(DYNLAB_SOURCE_DIR) + "/assets/models/puma560.urdf");
  std::vector<int> act{0, 1, 2, 3, 4, 5};
  controllers::TaskPoint tool;
  VecN pose = (VecN(6) << 0.3, -0.4, -1.2, 0.2, 0.7, -0.1).finished();
  Puma() {
    ConstrainedMechanism<Spatial> m(file.mechanism);
    tool.link = 5;
    tool.point = Eigen::Vector3d(0.4521, -0.15005, 0.5318) - m.pointPosition(5, Eigen::Vector3d::Zero(), file.q0);
    tool.axes = {3, 4, 5};
  }
  Eigen::Vector3d toolAt(const VecN& q) {
    ConstrainedMechanism<Spatial> m(file.mechanism);
    return m.pointPosition(tool.link, tool.point, q);
  }
  // The plant: the model with a push F on the tool from t = t_on.
  MechanismModel<Spatial> pushed(const Eigen::Vector3d& F, double t_on) const {
    MechanismModel<Spatial> d = file.mechanism;
    Spatial::Vec w = Spatial::Vec::Zero();
    w.tail<3>() = F;
    d.forces.push_back(std::make_shared<PushForce<Spatial>>(BodyRef::link(tool.link), tool.point, w, ForceProfile{t_on, 0, 0}));
    return d;
  }
  controllers::Controller make(controllers::Kind kind, double k, double d, double m, double posture = 20, double wn = 0) {
    controllers::Spec spec;
    spec.kind = kind, spec.k_imp = k, spec.d_imp = d, spec.m_imp = m, spec.posture_omega = posture, spec.period = 1e-3;
    spec.omega_n = wn, spec.zeta = 1.0;
    spec.torque_limit = VecN::Constant(6, 1e4);
    return controllers::Controller(spec, file.mechanism, act, tool, pose, 1e-3);
  }
};

// The closed loop on the hand engine (RK4, 1 ms, the controller sampled every step): the tool's
// position each step.
std::vector<Eigen::Vector3d> closedLoop(Puma& arm, controllers::Controller& ctl, const Eigen::Vector3d& F, double t_on, double T,
                                       VecN* q_end = nullptr) {
  const MechanismModel<Spatial> plant = arm.pushed(F, t_on);
  ConstrainedMechanism<Spatial> mech(plant);
  StepOptions o;
  o.dt = 1e-3;
  o.drift.kind = Drift::None;
  VecN q = arm.pose, v = VecN::Zero(6);
  const Eigen::Vector3d x_ref = arm.toolAt(arm.pose);
  controllers::Reference ref{VecN(x_ref), VecN::Zero(3), VecN::Zero(3)};
  std::vector<Eigen::Vector3d> x;
  for (long k = 0; k < std::lround(T / o.dt); ++k) {
    const double t = double(k) * o.dt;
    ref.force = t >= t_on ? VecN(F) : VecN(VecN::Zero(3));
    const VecN tau = ctl.torque(t, q, v, ref);
    REQUIRE(step(mech, o, tau, q, v));
    x.push_back(arm.toolAt(q));
  }
  if (q_end) *q_end = q;
  return x;
}

}  // namespace

TEST_CASE("impedance_inverse_dynamics: the tool's acceleration is the target's ẍ* at a moving state (6 joints, 3 axes)") {
  Puma arm;
  const Eigen::Vector3d F(8.0, -5.0, 12.0), x_ref = arm.toolAt(arm.pose) + Eigen::Vector3d(0.01, -0.02, 0.005);
  const VecN v = (VecN(6) << 0.4, -0.3, 0.5, 1.0, -0.8, 2.0).finished();
  const double K = 500, D = 30, M = 1.5;
  const controllers::Reference ref{VecN(x_ref), VecN::Zero(3), VecN::Zero(3), false, VecN(F)};
  // The plant's θ'' with the push (the hand engine's solve at the push's full size), and the tool's
  // classical acceleration J θ'' + J'θ'.
  ConstrainedMechanism<Spatial> plant(arm.pushed(F, 0.0));
  MatN Jp;
  VecN Jdot;
  plant.pointJacobian(arm.tool.link, arm.tool.point, arm.pose, v, Jp, Jdot);
  const Eigen::Vector3d x = arm.toolAt(arm.pose), xd = (Jp * v).tail<3>();
  auto toolAcceleration = [&](const VecN& tau) { return Eigen::Vector3d((Jp * plant.solve(arm.pose, v, tau).qdd + Jdot).tail<3>()); };
  const Eigen::Vector3d target = (F - D * xd - K * (x - x_ref)) / M;
  for (double posture : {0.0, 20.0}) {
    auto ctl = arm.make(controllers::Kind::ImpedanceInverseDynamics, K, D, M, posture);
    const Eigen::Vector3d a = toolAcceleration(ctl.torque(0, arm.pose, v, ref));
    INFO("posture ω_0 " << posture << ": ẍ " << a.transpose() << " against ẍ* " << target.transpose());
    CHECK((a - target).cwiseAbs().maxCoeff() < 1e-9 * target.cwiseAbs().maxCoeff());
  }
  // Without force feedback the tool obeys Λ ẍ = F + K e − D ẋ at rest (Λ the arm's; the posture term
  // accelerates nothing along the task), not the target.
  auto task = arm.make(controllers::Kind::ImpedanceTask, K, D, M);
  const VecN rest = VecN::Zero(6);
  plant.pointJacobian(arm.tool.link, arm.tool.point, arm.pose, rest, Jp, Jdot);
  const Eigen::Vector3d a = (Jp * plant.solve(arm.pose, rest, task.torque(0, arm.pose, rest, ref)).qdd).tail<3>();
  const MatN Lambda = plant.operationalInertia(arm.pose, MatN(Jp.bottomRows(3)));
  const Eigen::Vector3d rhs = F + K * (x_ref - x);
  INFO("Λ ẍ " << (Lambda * a).transpose() << " against F + K e " << rhs.transpose() << "; Λ diagonal " << Lambda.diagonal().transpose());
  CHECK((Lambda * a - rhs).cwiseAbs().maxCoeff() < 1e-9 * rhs.cwiseAbs().maxCoeff());
  CHECK((a - (F - K * (x - x_ref)) / M).cwiseAbs().maxCoeff() > 0.1 * a.cwiseAbs().maxCoeff());
}

TEST_CASE("impedance laws on the PUMA: the tool settles at the target's F/K; force feedback follows the target's response") {
  Puma arm;
  const Eigen::Vector3d F(0.0, 6.0, -4.0), x_ref = arm.toolAt(arm.pose);
  const double K = 400, M = 2.0, zeta = 0.7, D = 2 * zeta * std::sqrt(K * M), t_on = 0.1, T = 3.0;
  // The target's step response about x_ref (underdamped 2nd order), per axis.
  const double wn = std::sqrt(K / M), wd = wn * std::sqrt(1 - zeta * zeta);
  auto target = [&](double t) {
    const double s = t < t_on ? 0.0 : 1 - std::exp(-zeta * wn * (t - t_on)) * (std::cos(wd * (t - t_on)) + zeta * wn / wd * std::sin(wd * (t - t_on)));
    return Eigen::Vector3d(x_ref + F / K * s);
  };
  double miss[2] = {0, 0};
  for (int i = 0; i < 2; ++i) {
    const auto kind = i == 0 ? controllers::Kind::ImpedanceInverseDynamics : controllers::Kind::ImpedanceTask;
    auto ctl = arm.make(kind, K, D, M);
    const auto x = closedLoop(arm, ctl, F, t_on, T);
    const Eigen::Vector3d deflection = x.back() - x_ref;
    INFO((i == 0 ? "inverse dynamics" : "task") << ": deflection " << deflection.transpose() << " against F/K " << (F / K).transpose());
    CHECK((deflection - F / K).norm() < 1e-3 * (F / K).norm());
    for (std::size_t k = 0; k < x.size(); ++k) miss[i] = std::max(miss[i], (x[k] - target(double(k + 1) * 1e-3)).norm());
  }
  MESSAGE("largest miss of the target's response, relative to |F|/K: with force feedback " << miss[0] / (F / K).norm()
                                                                                           << ", without " << miss[1] / (F / K).norm());
  // With force feedback: the target to the 1 ms hold's lag; without: the arm's Λ (≠ M) shows.
  CHECK(miss[0] < 0.02 * (F / K).norm());
  CHECK(miss[1] > 0.1 * (F / K).norm());
}

TEST_CASE("impedance_joint on the PUMA: the joint loop's compliance in series, Λ⁻¹F/ω_n², shrinks as ω_n grows") {
  Puma arm;
  const Eigen::Vector3d F(6.0, 0.0, -4.0), x_ref = arm.toolAt(arm.pose);
  const double K = 400, M = 2.0, zeta = 0.7, D = 2 * zeta * std::sqrt(K * M), t_on = 0.1, T = 3.0;
  // At rest computed torque holds M ω_n² e_u = −JᵀF: the joints yield by M⁻¹JᵀF/ω_n², the tool by
  // J M⁻¹ Jᵀ F/ω_n² = Λ⁻¹F/ω_n² beyond the model's F/K (first order in the yield; J, M where it rests).
  ConstrainedMechanism<Spatial> mech(arm.file.mechanism);
  double off[2] = {0, 0};
  const double loops[2] = {150.0, 300.0};
  for (int i = 0; i < 2; ++i) {
    auto ctl = arm.make(controllers::Kind::ImpedanceJoint, K, D, M, 0.0, loops[i]);
    VecN q;
    const auto x = closedLoop(arm, ctl, F, t_on, T, &q);
    MatN Jp;
    VecN Jdot;
    mech.pointJacobian(arm.tool.link, arm.tool.point, q, VecN::Zero(6), Jp, Jdot);
    const MatN J = Jp.bottomRows(3);
    const Eigen::Vector3d predicted = J * mech.massMatrix(q).ldlt().solve(MatN(J.transpose())) * F / (loops[i] * loops[i]);
    const Eigen::Vector3d extra = x.back() - x_ref - F / K;
    MESSAGE("ω_n " << loops[i] << ": deflection beyond F/K " << extra.transpose() << ", Λ⁻¹F/ω_n² " << predicted.transpose());
    CHECK((extra - predicted).norm() < 0.1 * predicted.norm());
    off[i] = extra.norm();
  }
  CHECK(off[0] / off[1] == doctest::Approx(4.0).epsilon(0.1));  // a quarter when ω_n doubles
}
