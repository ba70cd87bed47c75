// The stiff terms of the arm labs, each against the test's own integration (tests/labs/arm_reference.h:
// classic RK4 written here at 1/128 of a millisecond, M and h from the tree algorithms, springs,
// friction and push written in the test) at the lab's dt = 1 ms and, for the order, at 0.5 and 0.25 ms:
//  * Coulomb friction F_c tanh(θ'/w), w = 0.01 rad/s (motion_control's default PID run, 2 s: the moves
//    out and back, where the joints turn): within 1e-6 rad at 1 ms (plain RK4: 3.0e-4 rad over the 4 s
//    run), fourth order;
//  * flexible joints with that friction (the PID run, 2 s): within 1e-6 rad at 1 ms, fourth order, the
//    sub-steps at ω h ≤ kResolvedOmegaDt = 0.04 for the fastest mode at any pose of the arm;
//  * the impedance lab's passive arm under gravity pushed at the tip (the default push, 2 s): within
//    1e-6 m of the reference at 1 ms (plain RK4: 1.5e-6 m, from the whips, not the push), fourth order.
// The lab's controller is held 1 ms in every run (the same discrete loop; only the plant's step changes).
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "labs/impedance/lab.h"
#include "labs/motion_control/lab.h"
#include "labs/run.h"
#include "tests/labs/arm_reference.h"
#include "tests/labs/lab_fixture.h"

using namespace dyn;

namespace {

const test::LabFixture mc("motion_control"), imp("impedance");
constexpr double kRow = 1e-3;  // s: the reference's rows, the control period
constexpr int kFine = 128;     // reference steps a row

// The largest |f(row of the lab at t) − g(reference at t)| over t = k·1 ms.
template <class F>
double worst(const Trace& tr, double dt, std::size_t rows, F gap) {
  const long every = std::lround(kRow / dt);
  double e = 0;
  for (std::size_t k = 0; k < rows && std::size_t(every) * k < tr.rows(); ++k) e = std::max(e, gap(std::size_t(every) * k, k));
  return e;
}

// The motion-control arm at steps dt (one run each) against one reference: max |θ_lab − θ_ref|, rad.
std::vector<double> armErrors(const json& patch, const std::vector<double>& dts, int substep_scale = 0) {
  const auto lab0 = mc.makeLab(patch);
  const auto& s = dynamic_cast<const motion_control::MotionControlLab&>(*lab0).settings();
  REQUIRE(s.controller.period == kRow);
  test::ArmEquations eq(s.plant);
  VecN q, v;
  motion_control::treeState(s.plant, s.trajectory.outstretched, motion_control::staticDeflection(s.plant, s.trajectory.outstretched), q, v);
  motion_control::Controller ctrl(s.controller, s.trajectory, s.model);
  const long rows = std::lround(s.duration / kRow);
  const auto ref = test::referenceRun(eq, q, v, kRow, rows, kFine, 1, [&](double t, const VecN& qq, const VecN& vv) {
    const auto a = motion_control::armState(s.plant, qq, vv);
    return VecN(motion_control::treeTorque(s.plant, ctrl.torque(t, a.motor, a.motor_rate)));
  });
  std::vector<double> out;
  for (double dt : dts) {
    json p = patch;
    p["simulation"]["dt"] = dt;
    auto lab = mc.makeLab(p);
    if (substep_scale > 0) {  // the same dt, the flexible sub-steps finer
      motion_control::Settings finer = dynamic_cast<const motion_control::MotionControlLab&>(*lab).settings();
      finer.step.substeps *= substep_scale;
      lab = std::make_unique<motion_control::MotionControlLab>(finer);
      substep_scale *= 2;
    }
    const Trace tr = test::LabFixture::run(*lab, Engine::Hand);
    out.push_back(worst(tr, dt, ref.q.size(), [&](std::size_t r, std::size_t k) {
      const auto a = motion_control::armState(s.plant, ref.q[k], ref.v[k]);
      double e = 0;
      for (int i = 0; i < s.plant.n(); ++i) e = std::max(e, std::abs(tr.at(r, "q" + std::to_string(i + 1)) - a.link[i]));
      return e;
    }));
  }
  return out;
}

// Fourth order: each halving of dt divides the error by 12 or more (16 for h⁴).
void checkFourthOrder(const std::vector<double>& e) {
  for (std::size_t i = 0; i + 1 < e.size(); ++i) CHECK(e[i] / e[i + 1] > 12.0);
}

}  // namespace

TEST_CASE("motion_control: Coulomb friction where it turns, within 1e-6 rad of the reference at dt 1 ms, fourth order") {
  const std::vector<double> e = armErrors({{"simulation", {{"duration", 2.0}}}}, {1e-3, 5e-4, 2.5e-4});
  MESSAGE("PID run, max |θ − θ_ref| at dt 1, 0.5, 0.25 ms: " << e[0] << ", " << e[1] << ", " << e[2] << " rad");
  CHECK(e[0] < 1e-6);
  checkFourthOrder(e);
}

TEST_CASE("motion_control: flexible joints with friction, within 1e-6 rad of the reference at dt 1 ms, fourth order") {
  const json patch = {{"mechanism", {{"flexible", {{"enabled", true}}}}}, {"simulation", {{"duration", 2.0}}}};
  const auto lab = mc.makeLab(patch);
  const auto& s = dynamic_cast<const motion_control::MotionControlLab&>(*lab).settings();
  // The sub-steps from the trajectory's two poses; no pose of the arm has a faster mode (M depends on
  // θ2, θ3 alone: a 15° grid).
  const double w = std::max(motion_control::fastestMode(s.plant, s.trajectory.outstretched),
                            motion_control::fastestMode(s.plant, s.trajectory.folded));
  double fastest = 0;
  for (int a = 0; a < 24; ++a)
    for (int b = 0; b < 24; ++b) fastest = std::max(fastest, motion_control::fastestMode(s.plant, Eigen::Vector3d(0, a * M_PI / 12, b * M_PI / 12)));
  MESSAGE("fastest mode " << w << " rad/s (any pose: " << fastest << "), " << s.step.substeps << " sub-steps: ω h = " << w * s.step.dt / s.step.substeps);
  CHECK(fastest <= w * (1 + 1e-12));
  CHECK(w * s.step.dt / s.step.substeps <= 0.04);
  const double e = armErrors(patch, {1e-3})[0];
  MESSAGE("flexible PID run, max |θ − θ_ref| at dt 1 ms: " << e << " rad");
  CHECK(e < 1e-6);
  // The order, on the springs alone (Coulomb off: friction's own order is the test above): dt 1 ms in
  // the lab's sub-steps, then twice and four times as many.
  json springs = patch;
  springs["controller"]["kind"] = "none";
  springs["mechanism"]["friction"] = mc.defaults()["mechanism"]["friction"];
  for (auto& f : springs["mechanism"]["friction"]) f["coulomb"] = 0.0;
  const std::vector<double> o = armErrors(springs, {1e-3, 1e-3, 1e-3}, 1);
  MESSAGE("passive flexible arm, Coulomb off, max |θ − θ_ref| with 1, 2, 4 times the sub-steps: " << o[0] << ", " << o[1] << ", " << o[2] << " rad");
  CHECK(o[0] < 1e-6);
  checkFourthOrder(o);
}

TEST_CASE("impedance: the pushed passive arm under gravity, within 1e-6 m of the reference at dt 1 ms, fourth order") {
  const json patch = {{"controller", {{"kind", "none"}}}};
  const auto lab0 = imp.makeLab(patch);
  const auto& s = dynamic_cast<const impedance::ImpedanceLab&>(*lab0).settings();
  test::ArmEquations eq(s.plant, [&](double t) { return s.force.at(t); });
  const auto ref = test::referenceRun(eq, VecN(s.pose), VecN::Zero(3), kRow, std::lround(s.duration / kRow), kFine, 1,
                                      [](double, const VecN&, const VecN&) { return VecN(VecN::Zero(3)); });
  std::vector<double> e;
  for (double dt : {1e-3, 5e-4, 2.5e-4}) {
    json p = patch;
    p["simulation"]["dt"] = dt;
    const Trace tr = test::LabFixture::run(*imp.makeLab(p), Engine::Hand);
    e.push_back(worst(tr, dt, ref.q.size(), [&](std::size_t r, std::size_t k) {
      const Eigen::Vector3d x = impedance::tipPose(s.plant, Eigen::Vector3d(ref.q[k]));
      return std::hypot(tr.at(r, "x") - x[0], tr.at(r, "y") - x[1]);
    }));
  }
  MESSAGE("passive pushed arm, max |x_tip − x_ref| at dt 1, 0.5, 0.25 ms: " << e[0] << ", " << e[1] << ", " << e[2] << " m");
  CHECK(e[0] < 1e-6);
  checkFourthOrder(e);
}
