// The harness every mechanism lab shares (labs/mechanism_simulation.h): its energy books.
//  * in a driven run of every lab (its default controller, 1 s) the hand engine's E − E0 − W (the
//    "energy_drift" metric: W the work of τ, of external forces and of joint friction, integrated
//    with the motion's RK4 stages) falls at fourth order when dt halves, and is at the integrator's
//    error (a trapezoid's books fell at second order and read 1e-6…1e-5 J at 1 ms);
//  * Bullet's books (held forces × displacement) keep E − E0 − W within a first-order engine's error;
//  * the engine alone (`dynlab bench`'s engine pass) replaying the torques a full run applied takes
//    that run's states bit for bit, on both engines of every lab that offers it.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "labs/run.h"
#include "tests/labs/lab_fixture.h"

using namespace dyn;

namespace {

// energy_drift of a 1 s hand run of `lab`'s default config at step dt (its control periods unchanged:
// whole multiples of both steps).
double drift(const std::string& lab, double dt, const json& extra = json::object(), Engine engine = Engine::Hand) {
  const test::LabFixture fixture(lab);
  const json patch = mergePatch({{"simulation", {{"dt", dt}, {"duration", 1.0}}}}, extra);
  const auto l = fixture.makeLab(patch);
  const Trace tr = test::LabFixture::run(*l, engine);
  return l->metrics(tr)["energy_drift"].get<double>();
}

}  // namespace

TEST_CASE("E − E0 − W is at the integrator's error, fourth order, in a driven run of every lab") {
  // dt: the coarser of the two steps compared (dt/2 the finer); bound: |E − E0 − W| allowed at dt
  // (measured values in each lab's README). Motion control's Coulomb friction, F_c tanh(θ'/w) with w =
  // 0.01 rad/s, crosses zero in w/|θ''| ≈ 1 ms: RK4 is in its asymptotic range from dt 0.5 ms on.
  // Pen on table: 0.1 s, before its touchdown (a plastic impact takes out energy the books do not hold).
  const struct {
    const char* lab;
    double dt, bound;
    json patch;
  } cases[] = {{"slider_crank", 1e-3, 1e-10, json::object()},
               {"grasp", 1e-3, 1e-10, json::object()},
               {"unicycle", 1e-3, 1e-10, json::object()},
               {"impedance", 1e-3, 1e-9, json::object()},
               {"motion_control", 5e-4, 1e-5, json::object()},
               {"pen_on_table", 1e-3, 1e-8, {{"simulation", {{"duration", 0.1}}}}}};
  for (const auto& c : cases) {
    const double coarse = drift(c.lab, c.dt, c.patch), fine = drift(c.lab, c.dt / 2, c.patch);
    MESSAGE(std::string(c.lab) << ": |E − E0 − W| at dt " << c.dt << " s: " << coarse << " J, at dt/2: " << fine << " J, ratio " << coarse / fine);
    CHECK_MESSAGE(coarse < c.bound, c.lab);
    // Fourth order (16), unless both are at rounding level.
    CHECK_MESSAGE((coarse / fine > 12.0 || coarse < 1e-11), c.lab);
  }
}

TEST_CASE("Bullet's books: E − E0 − W stays within a first-order engine's error") {
  for (const char* lab : {"impedance", "motion_control", "grasp"}) {
    const double d = drift(lab, 1e-3, json::object(), Engine::Bullet);
    MESSAGE(std::string(lab) << ": Bullet |E − E0 − W| " << d << " J");
    CHECK_MESSAGE(d < 5e-2, lab);
  }
}

TEST_CASE("the engine alone, replaying a full run's torques, takes that run's states bit for bit") {
  // The bench times the engine pass on such a replay: it must step the states the lab's own run steps
  // (contacts closing and opening, limits, the controller's torques at 1 kHz), not a run of its own.
  int offered = 0;
  for (const LabEntry& entry : labRegistry()) {
    const auto lab = test::LabFixture(entry.name).makeLab();
    const long whole = std::lround(lab->duration() / lab->dt()), kMost = 600;  // its first 600 steps
    for (Engine engine : {Engine::Hand, Engine::Bullet}) {
      const std::string engine_name = name(engine);
      CAPTURE(entry.name);
      CAPTURE(engine_name);
      const auto full = lab->simulate(engine), alone = lab->simulate(engine);
      std::vector<double> row;
      VecN q1, v1, q2, v2, last;
      int steps = 0, differing = 0;
      while (steps < kMost && full->step(row)) {
        const VecN tau = full->appliedTorque();
        if (tau.size() == 0) break;  // the row at the run's end, or no engine alone
        REQUIRE(alone->advanceEngine(tau));
        last = tau;
        REQUIRE(full->engineState(q1, v1));
        REQUIRE(alone->engineState(q2, v2));
        // (bitwise: == on every entry, and the same sizes)
        if (!(q1.size() == q2.size() && v1.size() == v2.size() && q1 == q2 && v1 == v2)) ++differing;
        ++steps;
      }
      if (steps == 0) continue;  // a data lab's replayed file run: no engine alone
      ++offered;
      CHECK(steps == std::min(whole, kMost));
      CHECK(differing == 0);
      if (steps == whole) CHECK_FALSE(alone->advanceEngine(last));  // the run is over
    }
  }
  MESSAGE(offered, " runs replayed");
  CHECK(offered >= 2);
}
