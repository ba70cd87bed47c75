// The controller library (labs/controllers) on a URDF arm, against what each law says term by term:
//  * per-joint gains: with joint_scale s, joint PD + gravity gives τ_u − G_u = K_p s∘e exactly (G_u
//    from an independent ClosedChain of the same model), and pid's first command K_p s∘e;
//  * the integral's anti-windup under saturation: none winds up as K_i e t, clamping holds |u_I| ≤
//    τ_max, back-calculation settles at τ_max − K_p e + K_i e T_t (where raw − τ_sat = K_i e T_t);
//  * Coulomb compensation adds F̂_c sat(u_d'/w) from the model's joint friction, with the u_d' that moves
//    the tool at x_d' (J_x u_d' = x_d', J_x from an independent ClosedChain).
#include <doctest/doctest.h>

#include <cmath>

#include "labs/controllers/controller.h"
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
