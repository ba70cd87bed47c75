// Mechanisms from model files (physics/model_file) against independent references:
//  * the slider crank as MJCF equals the slider crank lab's C++ description (M, h, φ, G = [J, −A] and
//    the whole solve of eq. (2)) at random states, to 1e-12;
//  * M and the bias C v + G of every model file in assets/models (the PUMA 560 among them) equal
//    MuJoCo's own (mj_fullM, qfrc_bias) from the same file, to 1e-10, at random states;
//  * a planar four-bar's connect keeps its 2 independent rows (y dropped), and a passive run keeps
//    the closure at rounding level and the energy to RK4's order;
//  * a joint's armature is MuJoCo's (M_ii += a to mj_fullM's rounding), in the energy, and a passive
//    run keeps that energy to RK4's order;
//  * hostile and unsupported files get one-line errors naming the file and the element, fast.
#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include <Eigen/LU>

#include "labs/slider_crank/mechanism.h"
#include "physics/constrained_mechanism.h"
#include "physics/constraints/point_closure.h"
#include "physics/model_file/hand_engine.h"
#include "physics/model_file/model_file.h"
#include "tests/physics/model_file/fixtures.h"

using namespace dyn;
using namespace dyn::test_model_file;
namespace fs = std::filesystem;

namespace {

// The slider crank lab's plant, read from its JSON (so the file and the lab cannot drift apart unseen).
slider_crank::Params labParams() {
  std::ifstream in(std::string(DYNLAB_SOURCE_DIR) + "/labs/slider_crank/slider_crank.json");
  const nlohmann::json j = nlohmann::json::parse(in)["mechanism"];
  slider_crank::Params p;
  for (int i = 0; i < 3; ++i) {
    const auto& l = j["links"][std::size_t(i)];
    p.links[std::size_t(i)] = {l["length"].get<double>(), l["mass"].get<double>(), l["inertia"].get<double>(),
                               Eigen::Vector2d(l["com"][0].get<double>(), l["com"][1].get<double>())};
  }
  p.load_mass = j["load_mass"];
  p.tool_mass = j["tool_mass"];
  p.gravity = Eigen::Vector2d(j["gravity"][0].get<double>(), j["gravity"][1].get<double>());
  return p;
}

// One passive RK4 + projection run from q0 at rest: the largest |E − E0| and |φ|∞ (and the largest
// kinetic energy: the mechanism really moved).
std::pair<double, double> passiveRun(ConstrainedMechanism<Spatial>& mech, VecN q, double T, double dt) {
  StepOptions o;
  o.dt = dt;
  VecN v = VecN::Zero(q.size());
  const double e0 = mech.energy(q, v);
  const VecN tau = VecN::Zero(mech.n());
  double de = 0, phi = 0, swing = 0;
  for (int k = 0; k < int(std::lround(T / dt)); ++k) {
    REQUIRE(step(mech, o, tau, q, v));
    de = std::max(de, std::abs(mech.energy(q, v) - e0));
    phi = std::max(phi, mech.residual(q));
    swing = std::max(swing, mech.kineticEnergy(q, v));
  }
  CHECK(swing > 0.1);  // J: the four-bar swings through its lowest pose
  return {de, phi};
}

std::string writeFile(const std::string& name, const std::string& text) {
  static const fs::path dir = scratchFolder("model_file_test");
  return test_model_file::writeFile(dir, name, text).string();
}

// A one-body MJCF around a body's inside and an extra top-level section.
std::string mjcf(const std::string& body, const std::string& extra = "") {
  return "<mujoco><default><geom contype=\"0\" conaffinity=\"0\"/></default><worldbody><body name=\"b\">" + body +
         "<geom name=\"g\" type=\"sphere\" size=\"0.1\"/></body></worldbody>" + extra + "</mujoco>";
}

}  // namespace

TEST_CASE("the slider crank as MJCF equals the lab's C++ description (M, h, φ, J, the solve; 1e-12)") {
  const model_file::LoadedModel file = model_file::load(model("slider_crank.xml"));
  REQUIRE(file.closures.size() == 1);
  // The weld keeps the planar rows (ω_z, x, y) in the lab's order; the out-of-plane ones are dropped.
  CHECK(file.closures[0].kept == std::vector<std::string>{"wz", "x", "y"});
  CHECK(file.closures[0].dropped == std::vector<std::string>{"wx", "wy", "z"});
  CHECK(file.dof == 1);
  ConstrainedMechanism<Spatial> f(file.mechanism);
  ConstrainedMechanism<Planar> lab(slider_crank::describe(labParams()));
  const double m_c = labParams().load_mass, x0 = 1.1;  // the slider's mass and its position at qpos0
  Random r;
  for (int trial = 0; trial < 20; ++trial) {
    CAPTURE(trial);
    // Same coordinates but the slider's: the lab's x_c is absolute, the file's slide counts from x0.
    const VecN q = r.vec(4, 2.0), v = r.vec(4, 3.0), tau = r.vec(3, 5.0);
    VecN ql = q;
    ql[3] += x0;
    // M: the lab's tree M beside the slider's M_c = m_c.
    const MatN Mf = f.massMatrix(q), Ml = lab.massMatrix(ql);
    CHECK(maxAbs(Mf.topLeftCorner(3, 3) - Ml) < 1e-12);
    CHECK(maxAbs(Mf.col(3).head(3)) < 1e-12);
    CHECK(std::abs(Mf(3, 3) - m_c) < 1e-12);
    // h = C v + G: the tree's, and the slider's b_c + G_c = −m_c g_x = 0.
    const VecN hf = f.inverseDynamics(q, v, VecN::Zero(4)), hl = lab.inverseDynamics(ql, v.head(3), VecN::Zero(3));
    CHECK(maxAbs(hf.head(3) - hl) < 1e-12);
    CHECK(std::abs(hf[3]) < 1e-12);
    // φ and G = [J, −A] row by row (the lab's payload column is −A; the file's slider is a tree joint).
    checkSameConstraints(f, q, lab, ql, 3);
    // The whole solve: accelerations and the constraint force (η), so also J'θ' − A'v_c.
    VecN tau_f = VecN::Zero(4);  // the file's slider is a tree joint: no force on it
    tau_f.head(3) = tau;
    const auto sf = f.solve(q, v, tau_f), sl = lab.solve(ql, v, tau);
    CHECK(maxAbs(sf.qdd.head(3) - sl.qdd) < 1e-12 * std::max(1.0, maxAbs(sl.qdd)));
    CHECK(std::abs(sf.qdd[3] - sl.alpha_c[0]) < 1e-12 * std::max(1.0, maxAbs(sl.qdd)));
    CHECK(maxAbs(sf.eta - sl.eta) < 1e-12 * std::max(1.0, maxAbs(sl.eta)));
    CHECK(std::abs(f.energy(q, v) - lab.energy(ql, v)) < 1e-12);
  }
}

TEST_CASE("M and the bias C v + G equal MuJoCo's own (mj_fullM, qfrc_bias) for every model file in assets/models") {
  // Every .xml and .urdf there, found by listing the folder (a file added later is checked too).
  std::vector<std::string> files;
  for (const auto& entry : fs::directory_iterator(model("")))
    if (const std::string ext = entry.path().extension().string(); ext == ".xml" || ext == ".urdf")
      files.push_back(entry.path().filename().string());
  std::sort(files.begin(), files.end());
  for (const char* expected : {"arm3d.xml", "fivebar.xml", "fourbar.urdf", "fourbar.xml", "geared_arm.xml", "planar_arm.urdf", "puma560.urdf",
                               "slider_crank.xml"})
    CHECK_MESSAGE(std::count(files.begin(), files.end(), expected) == 1, expected);
  for (const std::string& entry : files) {
    const char* name = entry.c_str();
    CAPTURE(entry);
    const model_file::LoadedModel file = model_file::load(model(name));
    model_file::MujocoReference mj(file);
    ConstrainedMechanism<Spatial> mech(file.mechanism);
    const int n = mech.n();
    REQUIRE(mj.nv() == n);
    Random r;
    double worst_M = 0, worst_h = 0;
    for (int trial = 0; trial < 20; ++trial) {
      const VecN q = file.q0 + r.vec(n, 1.5), v = r.vec(n, 3.0);
      const MatN M = mech.massMatrix(q), Mmj = mj.massMatrix(q);
      const VecN h = mech.inverseDynamics(q, v, VecN::Zero(n)), hmj = mj.bias(q, v);
      worst_M = std::max(worst_M, maxAbs(M - Mmj) / std::max(1.0, maxAbs(Mmj)));
      worst_h = std::max(worst_h, maxAbs(h - hmj) / std::max(1.0, maxAbs(hmj)));
    }
    MESSAGE(std::string(name) << ": |M - M_mujoco| " << worst_M << ", |h - h_mujoco| " << worst_h);
    CHECK(worst_M < 1e-10);
    CHECK(worst_h < 1e-10);
  }
}

TEST_CASE("arm3d: joint references, carriers, fused bodies and joint properties are read") {
  const model_file::LoadedModel file = model_file::load(model("arm3d.xml"));
  REQUIRE(file.joints.size() == 5);
  CHECK(file.q0[0] == doctest::Approx(0.3));
  CHECK(file.q0[3] == doctest::Approx(-0.2));
  CHECK(file.q0[4] == doctest::Approx(0.05));
  // upper's first hinge is a massless carrier; bracket (no joint) is fused into upper.
  CHECK(file.mechanism.tree.bodies[1].massless);
  CHECK(file.bodies == std::vector<std::string>{"base", "upper", "fore", "tip"});
  REQUIRE(file.mechanism.joints.size() == 5);
  const JointProperties& elbow = file.mechanism.joints[3];
  CHECK(elbow.stiffness == 3.0);
  CHECK(elbow.rest == doctest::Approx(0.1));
  CHECK(elbow.viscous == 0.05);
  CHECK(file.dof == 5);
}

TEST_CASE("four-bar: the connect's dependent row is dropped; a passive run keeps closure and energy") {
  const model_file::LoadedModel file = model_file::load(model("fourbar.xml"));
  REQUIRE(file.closures.size() == 1);
  CHECK(file.closures[0].name == "pin_C");
  CHECK(file.closures[0].kept == std::vector<std::string>{"x", "z"});
  CHECK(file.closures[0].dropped == std::vector<std::string>{"y"});
  CHECK(file.dof == 1);
  ConstrainedMechanism<Spatial> mech(file.mechanism);
  CHECK(mech.residual(file.q0) < 1e-15);
  VecN phi;
  MatN G;
  mech.constraint(file.q0, phi, G);
  REQUIRE(G.rows() == 2);
  // Why the row goes: with all three rows, Λ = J M⁻¹ Jᵀ is singular (the y row of J is zero), so the
  // Schur route cannot factor it and the solve falls back to the full-pivot LU, whose η on the zero row
  // is arbitrary; the accelerations agree.
  MechanismModel<Spatial> all = file.mechanism;
  const auto at = all.constraints[0]->attachment();
  all.constraints[0] = std::make_shared<PointClosure<Spatial>>(at.a, at.point_a, at.b, at.point_b, PointClosure<Spatial>::translations());
  ConstrainedMechanism<Spatial> full(all);
  const VecN q = file.q0 + VecN(Eigen::Vector3d(0.3, -0.2, 0.1)), v = VecN(Eigen::Vector3d(1.0, -2.0, 0.5)), tau = VecN::Zero(3);
  VecN phi_all;
  MatN G_all;
  full.constraint(q, phi_all, G_all);
  REQUIRE(G_all.rows() == 3);
  const MatN Minv = mech.massMatrix(q).inverse();
  const Eigen::Matrix3d Lambda = G_all * Minv * G_all.transpose();
  CHECK(Eigen::FullPivLU<Eigen::Matrix3d>(Lambda).rank() == 2);
  CHECK(G_all.row(1).cwiseAbs().maxCoeff() == 0.0);
  const auto s_kept = mech.solve(q, v, tau), s_all = full.solve(q, v, tau);
  MESSAGE("four-bar: |qdd(all rows, LU) - qdd(kept rows, Schur)| " << (s_all.qdd - s_kept.qdd).cwiseAbs().maxCoeff());
  CHECK((s_all.qdd - s_kept.qdd).cwiseAbs().maxCoeff() < 1e-9);
  // Passive swing, 2 s: closure at rounding level, energy error at RK4's order (halving dt: ~1/16).
  const auto [de1, phi1] = passiveRun(mech, file.q0, 2.0, 2e-3);
  const auto [de2, phi2] = passiveRun(mech, file.q0, 2.0, 1e-3);
  MESSAGE("four-bar: |E - E0| " << de1 << " J (dt 2 ms), " << de2 << " J (dt 1 ms); |phi| " << phi1 << ", " << phi2);
  CHECK(phi1 < 1e-12);
  CHECK(phi2 < 1e-12);
  CHECK(de2 < 1e-6);
  CHECK(de1 / de2 > 8.0);
}

TEST_CASE("armature: M_ii += a as MuJoCo's mj_fullM, ½ a θ'² in the energy, kept by a passive run") {
  // A one-joint file (once refused): read, and its M is MuJoCo's to rounding.
  const std::string one = writeFile("armature.xml", mjcf("<joint name=\"j\" armature=\"0.1\"/>"));
  const model_file::LoadedModel single = model_file::load(one);
  REQUIRE(single.mechanism.joints.size() == 1);
  CHECK(single.mechanism.joints[0].armature == 0.1);
  model_file::MujocoReference mj_one(single);
  ConstrainedMechanism<Spatial> mech_one(single.mechanism);
  CHECK(maxAbs(mech_one.massMatrix(single.q0) - mj_one.massMatrix(single.q0)) < 1e-12);
  // geared_arm.xml: two hinges (the elbow's parent moves) and a slide, each with its armature. The
  // difference to the same description without armature is exactly diag(a), and M equals MuJoCo's.
  const model_file::LoadedModel file = model_file::load(model("geared_arm.xml"));
  REQUIRE(file.mechanism.joints.size() == 3);
  const VecN a = Eigen::Vector3d(0.32, 0.09, 1.97);
  for (int i = 0; i < 3; ++i) CHECK(file.mechanism.joints[std::size_t(i)].armature == a[i]);
  MechanismModel<Spatial> bare = file.mechanism;
  for (JointProperties& j : bare.joints) j.armature = 0;
  ConstrainedMechanism<Spatial> mech(file.mechanism), without(bare);
  model_file::MujocoReference mj(file);
  Random r;
  double worst = 0, worst_diag = 0, worst_id = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const VecN q = file.q0 + r.vec(3, 1.5), v = r.vec(3, 3.0), qdd = r.vec(3, 5.0);
    worst = std::max(worst, maxAbs(mech.massMatrix(q) - mj.massMatrix(q)));
    worst_diag = std::max(worst_diag, maxAbs(mech.massMatrix(q) - without.massMatrix(q) - MatN(a.asDiagonal())));
    // Inverse dynamics carries the rotors' a θ'' too; the kinetic energy their ½ a θ'².
    worst_id = std::max(worst_id, maxAbs(mech.inverseDynamics(q, v, qdd) - mech.massMatrix(q) * qdd - mech.inverseDynamics(q, v, VecN::Zero(3))));
    CHECK(mech.kineticEnergy(q, v) == doctest::Approx(0.5 * v.dot(mech.massMatrix(q) * v)).epsilon(1e-12));
  }
  MESSAGE("geared arm: |M - M_mujoco| " << worst << ", |M - M_bare - diag(a)| " << worst_diag << ", |ID - M qdd - h| " << worst_id);
  CHECK(worst < 1e-10);
  CHECK(worst_diag < 1e-12);
  CHECK(worst_id < 1e-10);
  // Passive swing from rest, 2 s: the energy to RK4's order (halving dt: ~1/16), and the rotors
  // matter: without them the arm is elsewhere by far more than that.
  const auto [de1, phi1] = passiveRun(mech, file.q0, 2.0, 2e-3);
  const auto [de2, phi2] = passiveRun(mech, file.q0, 2.0, 1e-3);
  MESSAGE("geared arm: |E - E0| " << de1 << " J (dt 2 ms), " << de2 << " J (dt 1 ms)");
  CHECK(de2 < 1e-6);
  CHECK(de1 / de2 > 8.0);
  StepOptions o;
  o.dt = 1e-3;
  VecN q1 = file.q0, v1 = VecN::Zero(3), q2 = file.q0, v2 = VecN::Zero(3);
  for (int k = 0; k < 500; ++k) {
    REQUIRE(step(mech, o, VecN::Zero(3), q1, v1));
    REQUIRE(step(without, o, VecN::Zero(3), q2, v2));
  }
  MESSAGE("geared arm: |q(armature) - q(none)| after 0.5 s " << (q1 - q2).lpNorm<Eigen::Infinity>());
  CHECK((q1 - q2).lpNorm<Eigen::Infinity>() > 0.05);
}

TEST_CASE("four-bar: the pin's force satisfies the rocker's Newton–Euler balance about its pivot") {
  // The rocker turns about the fixed y axis at D: I_D,yy α = [(c − D) × m g + (C − D) × f]_y, with f the
  // force the coupler applies on it at C (the closure's a on b). Independent of the solve's assembly:
  // the rocker's own inertia, centre of mass and the reported force alone.
  const model_file::LoadedModel file = model_file::load(model("fourbar.xml"));
  ConstrainedMechanism<Spatial> mech(file.mechanism);
  VecN phi;
  MatN G;
  mech.constraint(file.q0, phi, G);
  const Eigen::MatrixXd kernel = Eigen::FullPivLU<Eigen::MatrixXd>(Eigen::MatrixXd(G)).kernel();
  REQUIRE(kernel.cols() == 1);
  const VecN v = VecN(2.0 * kernel.col(0).normalized());  // on the manifold's tangent: J v = 0
  const auto s = mech.solve(file.q0, v, VecN::Zero(3));
  const Spatial::Vec f = mech.constraintForce(0, s);
  const int rocker = 2;
  const auto& body = file.mechanism.tree.bodies[rocker];
  double m = 0;
  Eigen::Vector3d c_body;
  Spatial::massAndCom(body.inertia, m, c_body);
  const Eigen::Vector3d D = mech.pointPosition(rocker, Eigen::Vector3d::Zero(), file.q0);
  const Eigen::Vector3d c = mech.pointPosition(rocker, c_body, file.q0);
  const Eigen::Vector3d C = mech.kinematics().position(BodyRef::link(rocker), file.mechanism.constraints[0]->attachment().point_b);
  const Eigen::Vector3d g = file.mechanism.tree.gravity.tail<3>();
  const double I_yy = body.inertia(1, 1);  // about the pivot; y is the body's y at every θ (it turns about y)
  const double moment = ((c - D).cross(m * g) + (C - D).cross(Spatial::linear(f)) + f.head<3>()).y();
  MESSAGE("rocker: I α = " << I_yy * s.qdd[rocker] << " N·m, moments " << moment << " N·m, |f| " << f.norm() << " N");
  CHECK(std::abs(I_yy * s.qdd[rocker] - moment) < 1e-12 * std::max(1.0, f.norm()));
  CHECK(f.norm() > 0.1);
}

TEST_CASE("five-bar: 2 degrees of freedom; URDF arm: the fixed tool fused, limits noted") {
  const model_file::LoadedModel five = model_file::load(model("fivebar.xml"));
  CHECK(five.dof == 2);
  REQUIRE(five.closures.size() == 1);
  CHECK(five.closures[0].dropped == std::vector<std::string>{"y"});
  ConstrainedMechanism<Spatial> mech(five.mechanism);
  const auto [de, phi] = passiveRun(mech, five.q0, 2.0, 1e-3);
  MESSAGE("five-bar: |E - E0| " << de << " J, |phi| " << phi);
  CHECK(phi < 1e-12);
  CHECK(de < 1e-6);
  const model_file::LoadedModel arm = model_file::load(model("planar_arm.urdf"));
  CHECK(arm.bodies == std::vector<std::string>{"link1", "link2", "link3"});
  double mass = 0;
  Eigen::Vector3d com;
  Spatial::massAndCom(arm.mechanism.tree.bodies[2].inertia, mass, com);
  CHECK(mass == doctest::Approx(0.6));  // link3 and the tool
  CHECK(arm.notes.empty());
  REQUIRE(arm.contacts.size() == 4);  // the shoulder's and the wrist's limits, each side a one-sided row
  CHECK(arm.contacts[0].kind == "joint_limit");
  REQUIRE(arm.mechanism.joints.size() == 3);
  CHECK(arm.mechanism.joints[0].viscous == 0.01);
}

TEST_CASE("an <include> is found beside the file, whatever the working folder") {
  writeFile("part.xml", mjcf("<joint name=\"j\"/>"));
  const std::string main = writeFile("with_include.xml", "<mujoco model=\"inc\"><include file=\"part.xml\"/></mujoco>");
  const model_file::LoadedModel file = model_file::load(main);
  REQUIRE(file.joints.size() == 1);
  CHECK(file.joints[0].name == "j");
}

TEST_CASE("hostile and unsupported model files: one line naming the file and the element, within a second") {
  double seconds = 0;
  CHECK(errorOf("/nonexistent/model.xml").find("no such file") != std::string::npos);
  CHECK(errorOf(fs::temp_directory_path().string()).find("not a regular file") != std::string::npos);
  CHECK(errorOf(writeFile("empty.xml", " \n")).find("empty") != std::string::npos);
  // 100 MB (sparse): refused by its size before it is read.
  const std::string big = writeFile("big.xml", "<mujoco/>");
  fs::resize_file(big, 100u << 20);
  CHECK(errorOf(big, &seconds).find("more than the") != std::string::npos);
  CHECK(seconds < 1.0);
  fs::remove(big);
  CHECK(errorOf(writeFile("latin1.xml", "<mujoco model=\"caf\xE9\"/>")).find("0xE9 at offset 18 is not valid UTF-8") != std::string::npos);
  CHECK(errorOf(writeFile("malformed.xml", "<mujoco><worldbody><body></worldbody></mujoco>")).find("MuJoCo's parser") != std::string::npos);
  std::string deep = "<mujoco><worldbody>";
  for (int i = 0; i < 100000; ++i) deep += "<body>";
  CHECK(errorOf(writeFile("deep.xml", deep), &seconds).find("too deep") != std::string::npos);
  CHECK(seconds < 1.0);
  const std::string laughs =
      "<?xml version=\"1.0\"?><!DOCTYPE l [<!ENTITY a \"aaaaaaaaaa\"><!ENTITY b \"&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;\">"
      "<!ENTITY c \"&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;\"><!ENTITY d \"&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;\">]><mujoco model=\"&d;\"/>";
  CHECK(errorOf(writeFile("laughs.xml", laughs), &seconds).find("nothing moves") != std::string::npos);
  CHECK(seconds < 1.0);
  // Numbers beyond what a mechanism can mean: refused when read, not found as NaN mid-run.
  const std::string heavy = "<mujoco><worldbody><body name=\"b\"><joint/><geom size=\"0.1\" mass=\"1e308\" contype=\"0\" "
                            "conaffinity=\"0\"/></body></worldbody></mujoco>";
  CHECK(errorOf(writeFile("heavy.xml", heavy)).find("body 'b''s mass is 1e+308") != std::string::npos);
  const std::string inf_g = "<mujoco><option gravity=\"0 0 -inf\"/><worldbody><body><joint/><geom size=\"0.1\" contype=\"0\" "
                            "conaffinity=\"0\"/></body></worldbody></mujoco>";
  CHECK(errorOf(writeFile("inf_gravity.xml", inf_g)).find("<option gravity> is -inf") != std::string::npos);
  // Elements the description cannot hold: named, with what is supported.
  // Ball and free joints load (ball_joints_test.cpp); a ball's cone limit and springs on either do not.
  const std::string ball = errorOf(writeFile("ball.xml", mjcf("<joint name=\"shoulder\" type=\"ball\" limited=\"true\" range=\"0 30\"/>")));
  CHECK(ball.find("joint 'shoulder' (body 'b') is a ball joint with a range (a cone); dynlab holds limits on hinge and slide") != std::string::npos);
  CHECK(errorOf(writeFile("free.xml", mjcf("<joint type=\"free\" name=\"fly\" stiffness=\"5\"/>"))).find("'fly' (body 'b') is a free joint with stiffness 5") !=
        std::string::npos);
  const std::string servo = mjcf("<joint name=\"j\"/>", "<actuator><general name=\"servo\" joint=\"j\" dyntype=\"integrator\"/></actuator>");
  CHECK(errorOf(writeFile("servo.xml", servo)).find("actuator 'servo' has activation dynamics") != std::string::npos);
  const std::string tendon = mjcf("<joint name=\"j\"/>", "<tendon><fixed name=\"t\"><joint joint=\"j\" coef=\"1\"/></fixed></tendon>");
  CHECK(model_file::load(writeFile("tendon.xml", tendon)).contacts.empty());  // a fixed tendon no equality uses: read, holds nothing
  const std::string coupling = "<mujoco><worldbody><body><joint name=\"a\"/><geom size=\"0.1\" contype=\"0\" conaffinity=\"0\"/></body>"
                               "<body><joint name=\"c\"/><geom size=\"0.1\" contype=\"0\" conaffinity=\"0\"/></body></worldbody>"
                               "<equality><joint name=\"gear\" joint1=\"a\" joint2=\"c\"/></equality></mujoco>";
  CHECK(model_file::load(writeFile("coupling.xml", coupling)).contacts.at(0).kind == "joint_coupling");
  const std::string touching = "<mujoco><worldbody><geom name=\"floor\" type=\"plane\" size=\"1 1 0.1\"/>"
                               "<body name=\"b\"><joint name=\"j\"/><geom name=\"ball\" size=\"0.1\"/></body></worldbody></mujoco>";
  // Geoms that may collide load (dynlab has no geom–geom contact), noted once; --ignore-contacts: not noted.
  const auto noted = model_file::load(writeFile("touching.xml", touching)).notes;
  REQUIRE(noted.size() == 1);
  CHECK(noted[0].find("2 geoms collide in MuJoCo but not here (e.g. 'floor' and 'ball')") == 0);
  model_file::LoadOptions ignore;
  ignore.ignore_contacts = true;
  CHECK(model_file::load(writeFile("touching.xml", touching), ignore).notes.empty());
  // A weld whose relpose is not the pose the file is written in: the loop cannot close there.
  const std::string twisted = "<mujoco><default><geom size=\"0.1\" contype=\"0\" conaffinity=\"0\"/></default><worldbody>"
                              "<body name=\"p\"><joint name=\"a\"/><geom/></body><body name=\"s\" pos=\"1 0 0\"><joint name=\"c\"/><geom/></body>"
                              "</worldbody><equality><weld name=\"w\" body1=\"p\" body2=\"s\" relpose=\"1 0 0 0.9 0.1 0 0\"/></equality></mujoco>";
  CHECK(errorOf(writeFile("twisted.xml", twisted)).find("weld 'w' holds a relative orientation") != std::string::npos);
}

TEST_CASE("MuJoCo's own steps of the same file (the bench's fourth engine) move the same coordinates") {
  // From rest for 20 ms, the arm3d (no loop: MuJoCo's equalities play no part) by mj_step (Euler, the
  // same dt) and by the hand engine (RK4): the same motion to Euler's first-order error, not to zero.
  const model_file::LoadedModel m = model_file::load(model("arm3d.xml"));
  const int n = int(m.q0.size());
  model_file::MujocoSimulation mj(m, 1e-4);
  CHECK(mj.describe().find("mj_step, Euler") != std::string::npos);
  mj.reset(m.q0, VecN::Zero(n));
  ConstrainedMechanism<Spatial> mech(m.mechanism);
  VecN q = m.q0, v = VecN::Zero(n), qm, vm;
  StepOptions o;
  o.dt = 1e-4;
  for (int k = 0; k < 200; ++k) {
    REQUIRE(mj.step());
    REQUIRE(step(mech, o, VecN::Zero(n), q, v));
  }
  mj.state(qm, vm);
  CHECK((q - m.q0).cwiseAbs().maxCoeff() > 1e-3);  // it moved
  CHECK((qm - q).cwiseAbs().maxCoeff() < 0.02 * (q - m.q0).cwiseAbs().maxCoeff());
  CHECK((vm - v).cwiseAbs().maxCoeff() < 0.02 * v.cwiseAbs().maxCoeff());
  CHECK((qm - q).cwiseAbs().maxCoeff() > 0);
}

TEST_CASE("the sized hand engine (hand_engine.h) steps as the dynamically sized mechanism does") {
  // The example loops get fixed sizes; 200 steps of each scheme from the file's pose agree with the
  // dynamic mechanism's to rounding (the same solve, loops unrolled), and an open arm stays dynamic.
  for (const char* file : {"fourbar.xml", "fivebar.xml", "slider_crank.xml", "arm3d.xml"}) {
    INFO(file);
    const model_file::LoadedModel m = model_file::load(model(file));
    std::string sizes;
    const auto sized = model_file::handEngine(m.mechanism, &sizes);
    CHECK(sizes.rfind(std::string(file) == "arm3d.xml" ? "dynamic" : "fixed sizes", 0) == 0);
    for (Integrator integrator : {Integrator::RK4, Integrator::SemiImplicitEuler}) {
      StepOptions o;
      o.integrator = integrator;
      if (integrator == Integrator::SemiImplicitEuler) o.drift.kind = Drift::Baumgarte;
      ConstrainedMechanism<Spatial> dynamic(m.mechanism);
      const auto engine = model_file::handEngine(m.mechanism);
      const int n = int(m.q0.size());
      VecN q1 = m.q0, v1 = VecN::Zero(n), q2 = q1, v2 = v1;
      for (int k = 0; k < 200; ++k) {
        REQUIRE(step(dynamic, o, VecN::Zero(n), q1, v1));
        REQUIRE(step(*engine, o, VecN::Zero(n), q2, v2));
      }
      CHECK((q1 - m.q0).cwiseAbs().maxCoeff() > 1e-3);
      CHECK((q1 - q2).cwiseAbs().maxCoeff() < 1e-12);
      CHECK((v1 - v2).cwiseAbs().maxCoeff() < 1e-10);
    }
  }
}

TEST_CASE("closures given as plain data beside a URDF are held as MJCF equalities are") {
  // The four-bar's URDF tree with its pin given in C++ (labs/generic/model_loops.h reads the same from JSON).
  model_file::LoadOptions options;
  model_file::GivenClosure pin;
  pin.where = "test: loops[0]";
  pin.name = "pin_C", pin.kind = "connect", pin.body1 = "coupler", pin.body2 = "rocker";
  pin.point1 = Eigen::Vector3d(0.4, 0, 0.1);  // point2 left out: where point1 is at q0
  options.closures = {pin};
  const model_file::LoadedModel urdf = model_file::load(model("fourbar.urdf"), options);
  const model_file::LoadedModel xml = model_file::load(model("fourbar.xml"));
  REQUIRE(urdf.closures.size() == 1);
  CHECK(urdf.closures[0].kept == xml.closures[0].kept);
  CHECK(urdf.closures[0].dropped == xml.closures[0].dropped);
  CHECK((urdf.closures[0].point2 - xml.closures[0].point2).norm() < 1e-15);
  CHECK(urdf.dof == 1);
  // A link the file does not have: named by where the closure was given, with its field.
  options.closures[0].body2 = "nowhere";
  std::string what;
  try {
    model_file::load(model("fourbar.urdf"), options);
  } catch (const model_file::ModelFileError& e) {
    what = e.what();
  }
  CHECK(what.rfind("test: loops[0].body2: expected a link of ", 0) == 0);
  // Beside an MJCF file whose own equality has the name: refused (one force column per name).
  options.closures[0].body2 = "rocker";
  what.clear();
  try {
    model_file::load(model("fourbar.xml"), options);
  } catch (const model_file::ModelFileError& e) {
    what = e.what();
  }
  CHECK(what.rfind("test: loops[0].name: 'pin_C' names a closure of ", 0) == 0);
}

TEST_CASE("puma560.urdf: the published DH geometry and masses are what MuJoCo and dynlab read") {
  const model_file::LoadedModel puma = model_file::load(model("puma560.urdf"));
  REQUIRE(puma.joints.size() == 6);
  CHECK(puma.dof == 6);
  ConstrainedMechanism<Spatial> mech(puma.mechanism);
  // At q = 0 (the toolbox's qz) the wrist centre (joints 4-6 meet there) is at (a2 + a3, -d3, d4).
  const Eigen::Vector3d wrist = mech.pointPosition(4, Eigen::Vector3d::Zero(), puma.q0);
  CHECK((wrist - Eigen::Vector3d(0.4318 + 0.0203, -0.15005, 0.4318)).norm() < 1e-12);
  double total = 0;
  for (const auto& body : puma.mechanism.tree.bodies) {
    double m = 0;
    Eigen::Vector3d c;
    Spatial::massAndCom(body.inertia, m, c);
    total += m;
  }
  CHECK(total == doctest::Approx(1.0 + 17.4 + 4.8 + 0.82 + 0.34 + 0.09));  // link 1's 1 kg on its axis (see the file)
  // Joint 2 holds the arm against gravity at q = 0: by the centres' reaches along x (DH a and r),
  // |τ2| = g (m2 (a2 + r2x) + m3 (a2 + a3 + r3x) + (m4 + m5 + m6) (a2 + a3)), the wrist's masses on the
  // wrist centre's vertical (their r have no x part at qz).
  const VecN g = mech.inverseDynamics(puma.q0, VecN::Zero(6), VecN::Zero(6));
  const double reach = 17.4 * (0.4318 - 0.3638) + 4.8 * (0.4318 + 0.0203 - 0.0203) + (0.82 + 0.34 + 0.09) * (0.4318 + 0.0203);
  CHECK(std::abs(g[1]) == doctest::Approx(9.81 * reach).epsilon(1e-12));
  // Joint 3 (on joint 2's arm end, a2 along x) holds only the wrist's offset a3 = 0.0203 m.
  CHECK(std::abs(g[2]) == doctest::Approx(9.81 * (0.82 + 0.34 + 0.09) * 0.0203).epsilon(1e-12));
  MESSAGE("PUMA 560 gravity torques at q = 0: " << g.transpose() << " N·m");
  CHECK(std::abs(g[0]) < 1e-12);
}
