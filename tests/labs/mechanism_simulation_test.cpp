// The harness every mechanism lab shares (labs/mechanism_simulation.h): its energy books.
//  * in a driven run of every lab (its default controller, 1 s) the hand engine's E − E0 − W (the
//    "energy_drift" metric: W the work of τ, of external forces and of joint friction, integrated
//    with the motion's RK4 stages) falls at fourth order from dt 1 ms to 0.5 ms, and is at the
//    integrator's error at 1 ms (a trapezoid's books fell at second order and read 1e-6…1e-5 J);
//  * Bullet's books (held forces × displacement) keep E − E0 − W within a first-order engine's error.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "labs/run.h"
#include "tests/labs/lab_fixture.h"

using namespace dyn;

namespace {

// energy_drift of a 1 s hand run of `lab`'s default config at step dt (its control periods unchanged:
// whole multiples of both steps).
double drift(const std::string& lab, double dt, const json& extra = json::object(), Engine engine = Engine::Hand) {
  const test::LabFixture fixture(lab);
  json patch = {{"simulation", {{"dt", dt}, {"duration", 1.0}}}};
  patch = mergePatch(patch, extra);
  const auto l = fixture.makeLab(patch);
  const Trace tr = test::LabFixture::run(*l, engine);
  return l->metrics(tr)["energy_drift"].get<double>();
}

}  // namespace

TEST_CASE("E − E0 − W is at the integrator's error, fourth order, in a driven run of every lab") {
  // Pen on table: 0.1 s, before its touchdown (a plastic impact takes out energy the books do not hold).
  const struct {
    const char* lab;
    json patch;
    double at_1ms;  // J: the bound at dt 1 ms (measured values in each lab's README)
  } cases[] = {{"slider_crank", json::object(), 1e-8},
               {"grasp", json::object(), 1e-8},
               {"unicycle", json::object(), 1e-8},
               {"impedance", json::object(), 1e-8},
               {"motion_control", json::object(), 1e-8},
               {"pen_on_table", {{"simulation", {{"duration", 0.1}}}}, 1e-8}};
  for (const auto& c : cases) {
    const double coarse = drift(c.lab, 1e-3, c.patch), fine = drift(c.lab, 5e-4, c.patch);
    MESSAGE(c.lab << ": |E − E0 − W| at dt 1 ms " << coarse << " J, 0.5 ms " << fine << " J, ratio " << coarse / fine);
    CHECK_MESSAGE(coarse < c.at_1ms, c.lab);
    CHECK_MESSAGE(coarse / fine > 12.0, c.lab);  // fourth order: 16
  }
}

TEST_CASE("Bullet's books: E − E0 − W stays within a first-order engine's error") {
  for (const char* lab : {"impedance", "motion_control", "grasp"}) {
    const double d = drift(lab, 1e-3, json::object(), Engine::Bullet);
    MESSAGE(lab << ": Bullet |E − E0 − W| " << d << " J");
    CHECK_MESSAGE(d < 5e-2, lab);
  }
}
