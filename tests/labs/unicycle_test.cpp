// The unicycle lab (labs/unicycle) against the lecture's wheel (§3 "Unicycle"), through the lab itself:
//  * from rest under constant torques the hand run equals the closed form θ'' = τ_y/(I_a + m r²),
//    φ'' = τ_z/I_z, x' = r cos φ θ', y' = r sin φ θ' to 1e-9 (RK4, dt 1 ms, 5 s);
//  * with no torque and initial rates it rolls a circle of radius r θ'/φ' at constant energy, and the
//    reported lateral force is m r θ' φ', the normal force m g, with no slip;
//  * Bullet's no-slip wheel agrees within tolerances stated per dt; Bullet's friction wheel slips
//    exactly where the no-slip force leaves the friction cone, and not before;
//  * bad inputs (r ≤ 0, μ < 0, a path that is not a list of points) get one line naming the JSON path.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "grading/grade.h"

#include "labs/run.h"
#include "labs/unicycle/lab.h"
#include "tests/labs/lab_fixture.h"

using namespace dyn;
using namespace dyn::unicycle;

namespace {

const test::LabFixture fixture("unicycle");

json constantTorques(double tau_y, double tau_z, double duration, double dt) {
  return {{"controller", {{"kind", "constant"}, {"tau_drive", tau_y}, {"tau_steer", tau_z}}},
          {"initial", {{"phi_deg", 0.0}, {"phi_rate", 0.0}, {"theta_rate", 0.0}}},
          {"simulation", {{"dt", dt}, {"duration", duration}}}};
}

}  // namespace

TEST_CASE("unicycle: from rest under constant torques the hand run is the closed form") {
  const double tau_y = 0.04, tau_z = 0.003, T = 5.0;
  const auto lab = fixture.makeLab(constantTorques(tau_y, tau_z, T, 1e-3));
  const Trace tr = fixture.run(*lab, Engine::Hand);
  const Params& p = dynamic_cast<const UnicycleLab&>(*lab).settings().params;
  const double th_dd = tau_y / (p.axle_inertia + p.mass * p.radius * p.radius), ph_dd = tau_z / p.steer_inertia;
  // The row at t = T, and the closed form's x, y by Simpson's rule (200 000 intervals: error ~1e-15).
  const std::size_t row = tr.rows() - 1;
  REQUIRE(std::abs(tr.at(row, "t") - T) < 1e-12);
  const int n = 200000;
  double x = 0, y = 0;
  for (int i = 0; i <= n; ++i) {
    const double t = T * i / n, w = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2), phi = 0.5 * ph_dd * t * t;
    x += w * p.radius * th_dd * t * std::cos(phi);
    y += w * p.radius * th_dd * t * std::sin(phi);
  }
  x *= T / n / 3, y *= T / n / 3;
  CHECK(std::abs(tr.at(row, "theta_rate") - th_dd * T) < 1e-9);
  CHECK(std::abs(tr.at(row, "phi_rate") - ph_dd * T) < 1e-9);
  CHECK(std::abs(tr.at(row, "phi") - 0.5 * ph_dd * T * T) < 1e-9);
  CHECK(std::abs(tr.at(row, "x") - x) < 1e-9);
  CHECK(std::abs(tr.at(row, "y") - y) < 1e-9);
  // The torques' work is the energy gained: the rolling constraint does no work.
  CHECK(std::abs(tr.at(row, "energy") - tr.at(0, "energy") - tr.at(row, "work")) < 1e-9);
}

TEST_CASE("unicycle: with no torque it rolls a circle of radius r θ'/φ', held by m r θ' φ'") {
  const double th = 20.0, ph = 1.5;
  const auto lab = fixture.makeLab({{"controller", {{"kind", "none"}}}, {"initial", {{"theta_rate", th}, {"phi_rate", ph}}},
                                    {"simulation", {{"duration", 4.0}}}});
  const Trace tr = fixture.run(*lab, Engine::Hand);
  const Params& p = dynamic_cast<const UnicycleLab&>(*lab).settings().params;
  const double radius = p.radius * th / ph;
  double worst_r = 0, worst_e = 0, worst_lat = 0, worst_n = 0, slip = 0;
  for (std::size_t r = 0; r < tr.rows(); ++r) {
    worst_r = std::max(worst_r, std::abs(std::hypot(tr.at(r, "x"), tr.at(r, "y") - radius) - radius));
    worst_e = std::max(worst_e, std::abs(tr.at(r, "energy") - tr.at(0, "energy")));
    worst_lat = std::max(worst_lat, std::abs(tr.at(r, "f_lat") - p.mass * p.radius * th * ph));
    worst_n = std::max(worst_n, std::abs(tr.at(r, "f_normal") - p.mass * p.gravity));
    slip = std::max(slip, tr.at(r, "slip"));
  }
  MESSAGE("circle: radius error ", worst_r, " m, |ΔE| ", worst_e, " J, f_lat error ", worst_lat, " N");
  CHECK(worst_r < 1e-9);
  CHECK(worst_e < 1e-10 * tr.at(0, "energy"));
  CHECK(worst_lat < 1e-9);
  CHECK(worst_n < 1e-9);
  CHECK(slip < 1e-12);
}

TEST_CASE("unicycle: bad inputs get one line naming the JSON path") {
  CHECK(fixture.inputError({{"mechanism", {{"radius", 0.0}}}}).find("/mechanism/radius: expected the wheel radius r > 0") == 0);
  CHECK(fixture.inputError({{"mechanism", {{"radius", -0.1}}}}).find("/mechanism/radius") == 0);
  CHECK(fixture.inputError({{"mechanism", {{"mu", -0.5}}}}).find("/mechanism/mu: expected a friction coefficient") == 0);
  CHECK(fixture.inputError({{"reference", {{"points", "a circle"}}}}).find("/reference/points: expected the path as a list of points") == 0);
  CHECK(fixture.inputError({{"reference", {{"points", {1.0, 2.0}}}}}).find("/reference/points/0: expected a point [x, y]") == 0);
  CHECK(fixture.inputError({{"reference", {{"points", {{0.0, 0.0}}}}}}).find("/reference/points") == 0);
  CHECK(fixture.inputError({{"reference", {{"points", {{0.0, 0.0}, {0.0, 0.0}}}}}}).find("/reference/points/1: expected a point distinct") == 0);
  CHECK(fixture.inputError({{"gains", {{"a_lat", {{"value", 0.0}}}}}}).find("/gains/a_lat") == 0);
  const std::string missing = fixture.inputError({{"controller", {{"kind", "constant"}}}});
  CHECK_MESSAGE(missing.find("tau_drive") != std::string::npos, missing);
}

namespace {
// The grade of a shipped example (labs/unicycle/examples/<name>.json): results.json.
json gradeExample(const std::string& name) {
  const auto dir = std::filesystem::path(defaultConfigPath("unicycle")).parent_path() / "examples";
  const GradeOutcome g = gradeSubmission((dir / (name + ".json")).string(), GradeOptions{});
  REQUIRE(g.error.empty());
  return g.results;
}
double testScore(const json& results, const std::string& test) {
  for (const auto& t : results.at("tests"))
    if (t.at("name") == test) return t.at("score").get<double>();
  FAIL("no test " << test);
  return -1;
}
}  // namespace

TEST_CASE("unicycle: examples named for a verdict get it") {
  // unstable: a heading loop without damping, which the half-step hold destabilises.
  CHECK(gradeExample("unstable").at("output").get<std::string>().find("unstable") != std::string::npos);
  // unstable_with_delay: stiff loops that the 20 ms actuation delay drives past the steer torque limit.
  CHECK(gradeExample("unstable_with_delay").at("output").get<std::string>().find("actuation_delay**: unstable") != std::string::npos);
  // skidding: stable loops whose leader corners at 6 m/s²: m a_lat = 12 N > μ m g = 5.9 N on the slippery
  // floor, so it skids there, and nothing is unstable.
  const json skid = gradeExample("skidding");
  CHECK(skid.at("output").get<std::string>().find("unstable") == std::string::npos);
  CHECK(testScore(skid, "No skid on a slippery floor (μ = 0.3)") == 0.0);
  // slows_in_turns: the same loops with a_lat 1.85 (m a_lat = 3.7 N < 5.9 N) hold the slippery floor.
  const json slow = gradeExample("../instructor/lessons/slows_in_turns");
  CHECK(testScore(slow, "No skid on a slippery floor (μ = 0.3)") > 0.5 * 3);
  CHECK(slow.at("score").get<double>() > skid.at("score").get<double>());
}
