// The impedance lab (labs/impedance) against the lecture's §4 claims, cheap runs only:
//  * feedback linearisation with an exact model and force feedback: the push response equals the
//    target's analytic step response (x_target) within 0.5 % of the static displacement F/K at
//    dt = 0.2 ms (the one-step sensor delay and the zero-order hold cost O(ω dt));
//  * task_space: the static displacement is K_des⁻¹F (exact gravity model), 1e-3 relative;
//    its apparent mass is the arm's Λ_xx(q), not M_des: ω fitted ≈ √(K/Λ_xx) within 3 %;
//  * joint_space: the joint loop adds its compliance in series, K_id < K_des, and approaches it as K_p grows;
//    the inner loop is the motion-control lab's controller: pid's integral removes the series
//    compliance (K_id = K_des within 1 %), pd_gravity keeps it (θ_des − θ = K_p⁻¹ τ_ext);
//  * a rigid wall's plastic impact: its impulse is in the wall force (5 ms window), so the peak stands
//    well above the settled force, agrees with Bullet within 15 % and does not depend on dt (10 %);
//  * hand vs Bullet over a push: |Δx| ≤ 0.5 mm (Bullet's first-order step at dt = 1 ms);
//  * the target is the exercise's (impedance.json "target"): the gains move the hand, never the target;
//  * the apparent mass each realisation achieves, M_id = K_id/ω_fit²: feedback linearisation and a
//    stiff joint_space loop give the programmed m_xy (force feedback), task_space the arm's Λ_xx from
//    the screening whatever m_xy is (its trace does not depend on m_xy at all);
//  * at rest against a stiff wall the hand presses with F − K_des·gap when its static stiffness is
//    K_des (feedback linearisation, task space); a stiff pid joint loop chatters on the wall;
//  * bad inputs (K_des not positive, a singular reference pose, a wall behind the tip) get one line.
//  * the push is a force, not a held torque: the passive arm under a constant tip push equals a
//    reference RK4 of M q'' + h = J(q)ᵀF (F at every stage, dt/8) to 1e-8 rad at dt 1 ms over 1 s
//    (held over each step as J(q_k)ᵀF it was 6e-2 m off), and Bullet feels the same push.
#include <doctest/doctest.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <string>

#include "tests/physics/reference_rk4.h"
#include "labs/impedance/lab.h"
#include "labs/run.h"
#include "tests/labs/lab_fixture.h"

using namespace dyn;
using namespace dyn::impedance;

namespace {

const test::LabFixture fixture("impedance");

// A realisation programmed with stiffness k, mass m and damping ratio zeta (d = 2ζ√(k m)), graded
// against the same target (so the target's metrics read the law back).
json gains(const char* kind, double k, double zeta, double joint_kp = 2500, double joint_kd = 100, double m = 1.0) {
  return {{"controller", {{"kind", kind}}},
          {"target", {{"k_xy", k}, {"m_xy", m}, {"zeta", zeta}}},
          {"gains", {{"k_xy", {{"value", k}}}, {"d_xy", {{"value", 2 * zeta * std::sqrt(k * m)}}}, {"m_xy", {{"value", m}}},
                     {"joint_kp", {{"value", joint_kp}}}, {"joint_kd", {{"value", joint_kd}}}}}};
}

json metricsOf(const Lab& lab) { return lab.metrics(test::LabFixture::run(lab, Engine::Hand)); }

// The passive arm under a constant push F at the tip from t = 0, no wall, no gravity (under gravity the
// passive arm whips through chaotic swings where any error grows by e^{λt}).
json constantPush(const Eigen::Vector2d& F) {
  return {{"controller", {{"kind", "none"}}},
          {"mechanism", {{"gravity", {0.0, 0.0}}}},
          {"environment", {{"force", {{"value", {F.x(), F.y()}}, {"start", 0.0}, {"rise", 0.0}, {"hold", 0.0}}}, {"wall", {{"enabled", false}}}}},
          {"simulation", {{"duration", 1.0}, {"dt", 1e-3}}}};
}

// Its reference: a test-local RK4 of M q'' = J(q)ᵀF − h(q, q') (M, h, J from the rigid arm's tree
// algorithms and point Jacobian) at step dt from the lab's pose; θ at T.
Eigen::Vector3d referencePush(const Settings& s, const Eigen::Vector2d& F, double dt, double T) {
  motion_control::FixedArm<3> arm(motion_control::describe(s.plant));
  const Planar::Pos tip(s.plant.links[2].length, 0.0);
  const Planar::Vec Fs(0.0, F.x(), F.y());
  auto accel = [&](const VecN& q, const VecN& v) {
    MatN J;
    VecN jd;
    arm.pointJacobian(2, tip, q, v, J, jd);
    const Eigen::MatrixXd M = arm.massMatrix(q);
    return VecN(M.ldlt().solve(Eigen::VectorXd(J.transpose() * Fs - arm.inverseDynamics(q, v, VecN::Zero(3)))));
  };
  return dyn::test::referenceRk4(accel, VecN(s.pose), VecN::Zero(3), dt, std::lround(T / dt));
}

}  // namespace

TEST_CASE("feedback linearisation with an exact model is the target's analytic push response") {
  json p = gains("feedback_linearisation", 400, 0.5);
  p["simulation"] = {{"dt", 0.0002}, {"duration", 1.2}};
  p["controller"]["control_period"] = 0.0002;
  const auto lab = fixture.makeLab(p);
  const RunResult r = runEngine(*lab, Engine::Hand);
  REQUIRE(r.failure.empty());
  const double d_static = 10.0 / 400;
  double worst = 0;
  for (std::size_t i = 0; i < r.trace.rows(); ++i)
    worst = std::max({worst, std::abs(r.trace.at(i, "x") - r.trace.at(i, "x_target")), std::abs(r.trace.at(i, "y") - r.trace.at(i, "y_target"))});
  MESSAGE("feedback linearisation: max |x − x_target| = ", worst, " m against F/K = ", d_static, " m");
  CHECK(worst <= 0.005 * d_static);
  // And the metrics read the target back: ζ and ω within 2 %.
  const json m = lab->metrics(r.trace);
  CHECK(m["zeta"].get<double>() == doctest::Approx(0.5).epsilon(0.02));
  CHECK(m["omega_n"].get<double>() == doctest::Approx(std::sqrt(400.0)).epsilon(0.02));
}

TEST_CASE("task_space: static stiffness is K_des, the apparent mass is the arm's own Λ") {
  const auto lab = fixture.makeLab(gains("task_space", 300, 1.5));
  const RunResult r = runEngine(*lab, Engine::Hand);
  REQUIRE(r.failure.empty());
  const json m = lab->metrics(r.trace);
  MESSAGE("task_space: K_id = ", m["stiffness"].get<double>(), " N/m for K_des = 300");
  CHECK(m["stiffness_error"].get<double>() < 1e-3);
  // Under-damped so the frequency is well defined: ω fitted against √(K/Λ_xx) from the screening's Λ.
  const auto lab2 = fixture.makeLab(gains("task_space", 300, 0.3));
  const RunResult r2 = runEngine(*lab2, Engine::Hand);
  REQUIRE(r2.failure.empty());
  const auto loops = lab2->linearise();
  REQUIRE(loops.size() == 2);
  const double lambda_xx = loops[0].den[2];
  const double w_fit = lab2->metrics(r2.trace)["omega_n"].get<double>();
  MESSAGE("task_space: ω fitted ", w_fit, " rad/s, √(K/Λ_xx) = ", std::sqrt(300 / lambda_xx), " (Λ_xx = ", lambda_xx, " kg)");
  CHECK(w_fit == doctest::Approx(std::sqrt(300 / lambda_xx)).epsilon(0.03));
  CHECK(std::abs(lambda_xx - 1.0) > 0.1);  // the point: the arm's Λ is not the M_des = 1 kg asked for
  // Its identified apparent mass is Λ_xx too.
  CHECK(lab2->metrics(r2.trace)["apparent_mass"].get<double>() == doctest::Approx(lambda_xx).epsilon(0.05));
}

TEST_CASE("joint_space: the joint loop's compliance in series, shrinking as K_p grows") {
  double previous = 1e9;
  for (double kp : {400.0, 2500.0, 20000.0}) {
    const auto lab = fixture.makeLab(gains("joint_space", 400, 1.0, kp, 2 * std::sqrt(kp)));
    const RunResult r = runEngine(*lab, Engine::Hand);
    REQUIRE(r.failure.empty());
    const double err = lab->metrics(r.trace)["stiffness_error"].get<double>();
    MESSAGE("joint_space K_p = ", kp, ": |K_id/K_des − 1| = ", err);
    CHECK(err < previous);
    previous = err;
  }
  CHECK(previous < 0.05);
}

TEST_CASE("joint_space: the motion-control lab's pid and pd_gravity as the inner loop") {
  json p = gains("joint_space", 400, 1.0, 3000, 60);
  p["controller"]["inner"] = "pid";
  p["gains"]["joint_ki"] = {{"value", 30000.0}};
  const auto pid = fixture.makeLab(p);
  const RunResult r = runEngine(*pid, Engine::Hand);
  REQUIRE(r.failure.empty());
  const double pid_err = pid->metrics(r.trace)["stiffness_error"].get<double>();
  p["controller"]["inner"] = "pd_gravity";
  const auto pd = fixture.makeLab(p);
  const RunResult r2 = runEngine(*pd, Engine::Hand);
  REQUIRE(r2.failure.empty());
  const double pd_err = pd->metrics(r2.trace)["stiffness_error"].get<double>();
  MESSAGE("joint_space pid: |K_id/K_des − 1| = ", pid_err, ", pd_gravity: ", pd_err);
  CHECK(pid_err < 0.01);
  CHECK(pd_err > 5 * pid_err);
  // An unknown inner loop is named.
  p["controller"]["inner"] = "admittance";
  CHECK(fixture.inputError(p).find("/controller/inner") == 0);
}

TEST_CASE("a rigid wall's impact: the impulse counts, hand and Bullet agree, dt does not matter") {
  json p = gains("task_space", 500, 0.7);
  p["environment"]["wall"] = {{"enabled", true}, {"x", 0.4216}, {"stiffness", 0.0}, {"damping", 0.0}};
  p["simulation"] = {{"duration", 0.6}};
  p["environment"]["force"]["hold"] = 0.4;
  auto peak = [&](const json& patch, Engine e, double* settled = nullptr) {
    const auto lab = fixture.makeLab(patch);
    const RunResult r = runEngine(*lab, e);
    REQUIRE(r.failure.empty());
    const json m = lab->metrics(r.trace);
    if (settled) *settled = m["wall_force_settled"].get<double>();
    return m["wall_force_peak"].get<double>();
  };
  double settled = 0;
  const double hand = peak(p, Engine::Hand, &settled), bullet = peak(p, Engine::Bullet);
  json fine = p;
  fine["simulation"]["dt"] = 0.0005;
  fine["controller"]["control_period"] = 0.0005;
  const double hand_fine = peak(fine, Engine::Hand);
  MESSAGE("rigid wall: 5 ms peak ", hand, " N (Bullet ", bullet, ", dt/2 ", hand_fine, "), settled ", settled, " N");
  CHECK(hand > 3 * settled);
  CHECK(hand == doctest::Approx(bullet).epsilon(0.15));
  CHECK(hand == doctest::Approx(hand_fine).epsilon(0.1));
}

TEST_CASE("the push is a force at every stage: the passive pushed arm is M q'' + h = J(q)ᵀF to 1e-8") {
  const Eigen::Vector2d F(5.0, 0.0);
  const auto lab = fixture.makeLab(constantPush(F));
  const Settings& s = dynamic_cast<const ImpedanceLab&>(*lab).settings();
  const RunResult r = runEngine(*lab, Engine::Hand);
  REQUIRE(r.failure.empty());
  // The trace's last row is at t = 1 s.
  const Eigen::Vector3d ref_last = referencePush(s, F, 1.25e-4, 1.0);
  const std::size_t last = r.trace.rows() - 1;
  const Eigen::Vector3d q(r.trace.at(last, "q1"), r.trace.at(last, "q2"), r.trace.at(last, "q3"));
  const double err = (q - ref_last).cwiseAbs().maxCoeff();
  MESSAGE("|θ − θ_ref| at t = 1 s: " << err << " rad (θ moved " << (ref_last - s.pose).cwiseAbs().maxCoeff() << " rad)");
  CHECK(err < 1e-8);
  // The work column is the push's work (no τ, no friction): E − E0 − W at RK4's error.
  const double drift = lab->metrics(r.trace)["energy_drift"].get<double>();
  MESSAGE("|E − E0 − W| " << drift << " J");
  CHECK(drift < 1e-8);
  // Bullet applies the same push (a link force at its step's start): first order, within 1e-2 rad.
  const RunResult b = runEngine(*lab, Engine::Bullet);
  REQUIRE(b.failure.empty());
  const Eigen::Vector3d qb(b.trace.at(last, "q1"), b.trace.at(last, "q2"), b.trace.at(last, "q3"));
  MESSAGE("Bullet |θ − θ_ref|: " << (qb - ref_last).cwiseAbs().maxCoeff() << " rad");
  CHECK((qb - ref_last).cwiseAbs().maxCoeff() < 1e-2);
}

TEST_CASE("hand vs Bullet over a push") {
  const auto lab = fixture.makeLab(gains("feedback_linearisation", 400, 0.7));
  const RunResult h = runEngine(*lab, Engine::Hand), b = runEngine(*lab, Engine::Bullet);
  REQUIRE(h.failure.empty());
  REQUIRE(b.failure.empty());
  const double dx = lab->agreement(h.trace, b.trace)["max_dx"].get<double>();
  MESSAGE("hand vs Bullet: max |Δx| = ", dx, " m");
  CHECK(dx <= 5e-4);
}

TEST_CASE("the target is the exercise's: the gains move the hand, never the target") {
  // The shipped target, whatever the controller is programmed with.
  const json shipped = fixture.defaults()["target"];
  const double k_t = shipped["k_xy"], m_t = shipped["m_xy"], z_t = shipped["zeta"];
  for (double m : {0.3, 3.0}) {
    json p = {{"controller", {{"kind", "feedback_linearisation"}}},
              {"gains", {{"k_xy", {{"value", 200.0}}}, {"d_xy", {{"value", 5.0}}}, {"m_xy", {{"value", m}}}}}};
    const auto lab = fixture.makeLab(p);
    const Trace tr = test::LabFixture::run(*lab, Engine::Hand);
    const json mt = lab->metrics(tr);
    CHECK(mt["stiffness_target"].get<double>() == doctest::Approx(k_t));
    CHECK(mt["apparent_mass_target"].get<double>() == doctest::Approx(m_t));
    CHECK(mt["zeta_target"].get<double>() == doctest::Approx(z_t));
    // x_target is the target's analytic step response, not the law's: at the push's end F/K_t from x_ref.
    const std::size_t last = std::size_t(std::lround((0.2 + 1.3) / lab->dt())) - 1;
    CHECK(tr.at(last, "x_target") - tr.at(last, "x_ref") == doctest::Approx(10.0 / k_t).epsilon(1e-3));
    // Programmed away from the target, the hand is graded far from it.
    CHECK(mt["response_error"].get<double>() > 0.5);
  }
}

TEST_CASE("apparent mass: force feedback shapes it, task space keeps the arm's") {
  // The arm's Λ_xx at the reference pose, from the screening of a task_space law.
  const auto ts = fixture.makeLab(gains("task_space", 500, 0.7));
  const double lambda_xx = ts->linearise()[0].den[2];
  for (double m : {0.5, 2.0}) {
    CAPTURE(m);
    const json fl = metricsOf(*fixture.makeLab(gains("feedback_linearisation", 500, 0.7, 0, 0, m)));
    const json js = metricsOf(*fixture.makeLab(gains("joint_space", 500, 0.7, 40000, 400, m)));
    json tp = gains("task_space", 500, 0.7, 0, 0, 1.0);
    tp["gains"]["m_xy"] = {{"value", m}};  // task space has no use for m_xy: the same law, the same hand
    const json tm = metricsOf(*fixture.makeLab(tp));
    MESSAGE("m_xy = ", m, " kg: feedback linearisation M_id = ", fl["apparent_mass"].get<double>(), ", joint_space ",
            js["apparent_mass"].get<double>(), ", task_space ", tm["apparent_mass"].get<double>(), " (Λ_xx = ", lambda_xx, ")");
    CHECK(fl["apparent_mass"].get<double>() == doctest::Approx(m).epsilon(0.03));
    CHECK(js["apparent_mass"].get<double>() == doctest::Approx(m).epsilon(0.1));
    CHECK(tm["apparent_mass"].get<double>() == doctest::Approx(lambda_xx).epsilon(0.05));
  }
  // task_space's trace does not depend on m_xy: bit for bit the same run.
  json a = gains("task_space", 500, 0.7), b = a;
  b["gains"]["m_xy"] = {{"value", 5.0}};
  const auto la = fixture.makeLab(a), lb = fixture.makeLab(b);
  const Trace ta = test::LabFixture::run(*la, Engine::Hand), tb = test::LabFixture::run(*lb, Engine::Hand);
  double diff = 0;
  for (std::size_t i = 0; i < ta.rows(); ++i) diff = std::max(diff, std::abs(ta.at(i, "x") - tb.at(i, "x")));
  CHECK(diff == 0.0);
}

TEST_CASE("at rest on a stiff wall the hand presses with the target's force F − K_des·gap") {
  const json wall = {{"enabled", true}, {"x", 0.4216}, {"stiffness", 50000.0}, {"damping", 20.0}};
  // The target's force, computed here from the geometry: the ball's surface x_wall − r − x_ref away.
  double target = 0;
  int losses = 0;  // contact lost over the push's last 20 % (1.24–1.5 s)
  auto run = [&](json p) {
    p["environment"]["wall"] = wall;
    const auto lab = fixture.makeLab(p);
    const Trace tr = test::LabFixture::run(*lab, Engine::Hand);
    target = 10.0 - 500.0 * (0.4216 - 0.01 - tr.at(0, "x_ref"));
    losses = 0;
    for (std::size_t i = 1; i < tr.rows(); ++i)
      if (tr.at(i, "t") >= 1.24 && tr.at(i, "t") < 1.5 && tr.at(i - 1, "F_ext_x") < 10 - 1e-9 && tr.at(i, "F_ext_x") >= 10 - 1e-9) ++losses;
    const json m = lab->metrics(tr);
    CHECK(m["wall_force_target"].get<double>() == doctest::Approx(target).epsilon(1e-9));
    return m;
  };
  const json fl = run(gains("feedback_linearisation", 500, 0.7));
  CHECK(losses == 0);
  const json ts = run(gains("task_space", 500, 0.7));
  CHECK(losses == 0);
  // A stiff pid joint loop (the shipped joint_space_pid example's gains) tracking x_des into the wall.
  json pid = gains("joint_space", 500, 0.7, 20000, 200);
  pid["controller"]["inner"] = "pid";
  pid["gains"]["joint_ki"] = {{"value", 20000.0}};
  pid["gains"]["k_phi"] = {{"value", 30.0}};
  pid["gains"]["d_phi"] = {{"value", 1.7}};
  const json js = run(pid);
  MESSAGE("settled wall force: feedback linearisation ", fl["wall_force_settled"].get<double>(), " N, task_space ",
          ts["wall_force_settled"].get<double>(), " N, the target's ", target, " N; joint_space pid loses contact ", losses,
          " times late in the push, wall_force_error ", js["wall_force_error"].get<double>());
  CHECK(target > 1.0);
  CHECK(fl["wall_force_settled"].get<double>() == doctest::Approx(target).epsilon(0.03));
  CHECK(ts["wall_force_settled"].get<double>() == doctest::Approx(target).epsilon(0.03));
  CHECK(fl["wall_force_error"].get<double>() < 0.03);
  // It chatters: contact lost again and again, the wall force far from the target's in RMS.
  CHECK(losses >= 3);
  CHECK(js["wall_force_error"].get<double>() > 0.5);
}

TEST_CASE("bad inputs get one line naming the JSON path") {
  CHECK(fixture.inputError({{"target", {{"m_xy", 0.0}}}}).find("/target/m_xy") == 0);
  CHECK(fixture.inputError({{"target", {{"zeta_des", 0.7}}}}).find("/target") == 0);
  CHECK(fixture.inputError({{"gains", {{"k_xy", {{"value", 0.0}}}}}}).find("/gains/k_xy") != std::string::npos);
  CHECK(fixture.inputError({{"pose_deg", {30.0, 0.0, -45.0}}}).find("/pose_deg: a pose away from the task Jacobian's singularity") == 0);
  CHECK(fixture.inputError({{"environment", {{"wall", {{"enabled", true}, {"x", 0.1}}}}}}).find("/environment/wall/x") == 0);
  CHECK(fixture.inputError({{"controller", {{"kind", "admittance"}}}}).find("/controller/kind") == 0);
  CHECK(fixture.inputError(json::object()) == "accepted");
}
