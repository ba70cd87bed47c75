// dynlab bench FILE: a mechanism from a model file, timed as app/cli/bench/bench.cpp times labs. Passive from the
// file's pose at rest, at the file's time step, four engines in turn in blocks of 50 steps (the
// clock's speed wanders within milliseconds: engines timed one after the other catch different
// phases), each block's steps timed together (timing.h timedRun: the clock ticks every ~10 ns):
//   hand   semi-implicit Euler + Baumgarte  (first order: Bullet's and MuJoCo's order; the headline)
//   hand   RK4 + projection                 (dynlab model's run: the reference for accuracy)
//   Bullet btMultiBody, semi-implicit Euler  (physics/bullet)
//   MuJoCo mj_step, Euler                    (the same file, MuJoCo's own soft equalities)
// With dynlab's elements beside the file (STEM.loops.json: loops, rolling wheels, plane contacts) the
// hand engines step as the labs and `dynlab model` do (contacts closed and opened between steps,
// touchdowns located), and MuJoCo is left out: its run of the file would not hold those elements.
// Ratios from the blocks timed side by side (median and middle half), and each engine's accuracy over
// a 2 s run: the largest closure residual |φ|∞ and the largest |q − q_ref|∞ against the hand RK4 run.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iostream>
#include <memory>
#include <type_traits>

#include "app/cli/bench/bench.h"
#include "app/cli/commands.h"
#include "app/cli/model/model.h"
#include "physics/model_file/closure_rows.h"
#include "labs/generic/model_loops.h"
#include "labs/generic/model_run.h"
#include "labs/utf8.h"
#include "physics/bullet/bullet_mechanism.h"
#include "physics/constrained_mechanism.h"
#include "physics/model_file/actuators.h"
#include "physics/model_file/hand_engine.h"
#include "physics/model_file/closure_rows.h"
#include "physics/model_file/model_file.h"
#include "physics/model_file/stiff_steps.h"

namespace dyn::app {
namespace {

constexpr double kAccuracyRun = 2.0;  // s: each engine's run from the file's pose, against the hand RK4 run

// One engine as the bench drives it: a step from its own state, back to the start, and its state.
struct Engine {
  std::string name, scheme;
  std::function<bool()> step;
  std::function<void()> restart;
  std::function<void(VecN&, VecN&)> state;
  std::vector<double> blocks;  // µs per step of each block (timing.h timedRun: NaN for a block left out)
};

// The engines from the file's pose at rest.
struct Engines {
  std::unique_ptr<ConstrainedSystem> euler_mech, rk4_mech;
  std::unique_ptr<model_file::DrivenMechanism> euler_el, rk4_el;  // with elements beside the file
  std::unique_ptr<model_file::DrivenMechanismT<model_file::SixJoints>> euler_six, rk4_six;  // the same, six joints fixed
  std::string sizes;
  std::unique_ptr<bullet::BulletMechanism<Spatial>> bullet;
  std::string bullet_left_out;  // why Bullet is not timed (a description its builder cannot model), or empty
  std::unique_ptr<model_file::MujocoSimulation> mujoco;
  VecN q_euler, v_euler, q_rk4, v_rk4;
  std::vector<Engine> list;
};

// A hand engine for a file with elements beside it: contacts updated at each step's start, touchdowns
// located (labs/mechanism_simulation.h's step); restarted as a new mechanism (its contacts open).
template <class Mechanism>
Engine handWithElements(const model_file::LoadedModel& m, const char* scheme, std::unique_ptr<Mechanism>* mech, VecN* q, VecN* v,
                        StepOptions o) {
  Engine x;
  x.name = "hand";
  const bool six = !std::is_same_v<Mechanism, model_file::DrivenMechanism>;
  x.scheme = std::string(scheme) + (six ? " (fixed sizes 6 joints, the closed rows solved;" : " (dynamic sizes;") +
             " contacts closed and opened between steps, touchdowns located)";
  // The zero torque made once (a step allocates nothing); with actuators or tendons, evaluated at each
  // stage (labs/generic/model_run.cpp's runHandElements).
  x.step = [=, zero = VecN(VecN::Zero(Eigen::Index(m.joints.size()))), tau = VecN(VecN::Zero(Eigen::Index(m.joints.size())))]() mutable {
    if (!(*mech)->empty()) tau = (*mech)->hold(*q, *v, zero);
    (*mech)->updateContacts(*q, *v, tau);
    return (*mech)->stepLocatingContacts(o, tau, *q, *v) && q->allFinite() && v->allFinite();
  };
  x.restart = [=, &m] { *mech = std::make_unique<Mechanism>(m), *q = m.start_q, *v = m.start_v; };
  x.state = [=](VecN& qo, VecN& vo) { qo = *q, vo = *v; };
  return x;
}

// Bullet's engine.
void addBullet(const model_file::LoadedModel& m, double dt, Engines& e) {
  const int n = int(m.joints.size());
  const VecN q0 = m.start_q, v0 = m.start_v;
  e.bullet = std::make_unique<bullet::BulletMechanism<Spatial>>(m.mechanism, dt, q0, v0);
  Engine b;
  b.name = "Bullet";
  b.scheme = e.bullet->describe() + ", semi-implicit Euler";
  auto* bt = &e.bullet;
  // Bullet: the zero torque made once (a step allocates nothing); with actuators, theirs at the step's start.
  b.step = [bt, &m, tau = VecN(VecN::Zero(n))] {
    if (m.actuators.empty() && m.tendons.empty()) {
      (*bt)->step(tau);
      return true;
    }
    VecN q, v;
    (*bt)->state(q, v);
    (*bt)->step(model_file::actuatorTorques(m, q, v));
    return true;
  };
  b.restart = [bt, &m, dt, q0, v0] { *bt = std::make_unique<bullet::BulletMechanism<Spatial>>(m.mechanism, dt, q0, v0); };
  b.state = [bt](VecN& q, VecN& v) { (*bt)->state(q, v); };
  e.list.push_back(b);
}

void build(const model_file::LoadedModel& m, double dt, bool beside, Engines& e) {
  const int n = int(m.joints.size());  // rates (a ball's quaternion has one more coordinate)
  const VecN q0 = m.start_q, v0 = m.start_v;
  StepOptions euler;
  euler.dt = dt;
  euler.integrator = Integrator::SemiImplicitEuler;
  euler.drift.kind = Drift::Baumgarte;
  StepOptions rk4;
  rk4.dt = dt;
  // The file's actuators evaluated at each stage (actuators.h); the engines themselves without any.
  e.euler_mech = model_file::withActuators(model_file::handEngine(m.mechanism, &e.sizes), m);
  e.rk4_mech = model_file::withActuators(model_file::handEngine(m.mechanism), m);
  e.q_euler = e.q_rk4 = q0, e.v_euler = e.v_rk4 = v0;
  auto hand = [&, n](const char* scheme, ConstrainedSystem* mech, VecN* q, VecN* v, StepOptions o) {
    Engine x;
    x.name = "hand";
    x.scheme = std::string(scheme) + " (" + e.sizes + ")";
    // The zero torque made once: a step allocates nothing (as a lab's engine step).
    x.step = [=, tau = VecN(VecN::Zero(n))] { return step(*mech, o, tau, *q, *v) && q->allFinite() && v->allFinite(); };
    x.restart = [=] { *q = q0, *v = v0, mech->setTime(0); };
    x.state = [=](VecN& qo, VecN& vo) { qo = *q, vo = *v; };
    return x;
  };
  if (m.contacts.empty()) {
    e.list.push_back(hand("semi-implicit Euler + Baumgarte", e.euler_mech.get(), &e.q_euler, &e.v_euler, euler));
    e.list.push_back(hand("RK4 + projection", e.rk4_mech.get(), &e.q_rk4, &e.v_rk4, rk4));
  } else if (model_file::sixJointsFixed(m.mechanism)) {
    e.list.push_back(handWithElements(m, "semi-implicit Euler + Baumgarte", &e.euler_six, &e.q_euler, &e.v_euler, euler));
    e.list.push_back(handWithElements(m, "RK4 + projection", &e.rk4_six, &e.q_rk4, &e.v_rk4, rk4));
  } else {
    e.list.push_back(handWithElements(m, "semi-implicit Euler + Baumgarte", &e.euler_el, &e.q_euler, &e.v_euler, euler));
    e.list.push_back(handWithElements(m, "RK4 + projection", &e.rk4_el, &e.q_rk4, &e.v_rk4, rk4));
  }
  try {
    addBullet(m, dt, e);
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& x) {  // a description the Bullet builder cannot model: the others are timed
    e.bullet_left_out = x.what();
  }
  if (beside || !m.compiled) return;  // MuJoCo's run of the file would not hold what is beside it; a description holds no MuJoCo model
  e.mujoco = std::make_unique<model_file::MujocoSimulation>(m, dt);
  model_file::MujocoSimulation* mj = e.mujoco.get();
  mj->reset(q0, v0);
  Engine u;
  u.name = "MuJoCo";
  u.scheme = mj->describe();
  u.step = [mj] { return mj->step(); };
  u.restart = [mj, q0, v0] { mj->reset(q0, v0); };
  u.state = [mj](VecN& q, VecN& v) { mj->state(q, v); };
  e.list.push_back(u);
}

// Every engine's steps timed in blocks, in turn; a run that fails (or leaves the finite numbers)
// starts again from the file's pose.
void timeBlocks(std::vector<Engine>& engines, int steps) {
  const int rounds = std::max(1, steps / kBlock);
  for (int r = 0; r < rounds; ++r)
    for (Engine& e : engines) e.blocks.push_back(timedRun(kBlock, [&] { return e.step() || (e.restart(), false); }));
}

// Accuracy over `steps` steps from the file's pose: the largest |φ|∞ (the description's, at each
// engine's state, over every closure row) and the largest |q − q_ref|∞ against the reference run's states.
struct Accuracy {
  double residual = 0, error = 0;
  double position = 0;  // the residual at the positions alone (no velocity form J v)
  bool complete = true;
};
std::vector<Accuracy> accuracy(std::vector<Engine>& engines, const model_file::LoadedModel& m, ConstrainedMechanism<Spatial>& mech, int steps,
                               int reference) {
  std::vector<std::vector<VecN>> path(engines.size());
  std::vector<Accuracy> out(engines.size());
  model_file::EveryClosureRow every(m);  // |φ| over every closure row, the dropped ones too
  for (std::size_t i = 0; i < engines.size(); ++i) {
    Engine& e = engines[i];
    e.restart();
    VecN q, v;
    for (int k = 0; k <= steps; ++k) {
      e.state(q, v);
      if (!q.allFinite()) {
        out[i].complete = false;
        break;
      }
      path[i].push_back(q);
      const RunResidual phi = runResidual(m, mech, every, q, v);
      out[i].residual = std::max(out[i].residual, phi.all);
      out[i].position = std::max(out[i].position, phi.positions);
      if (k < steps && !e.step()) {
        out[i].complete = false;
        break;
      }
    }
  }
  const auto& ref = path[std::size_t(reference)];
  for (std::size_t i = 0; i < engines.size(); ++i)
    for (std::size_t k = 0; k < path[i].size() && k < ref.size(); ++k)
      out[i].error = std::max(out[i].error, (path[i][k] - ref[k]).cwiseAbs().maxCoeff());
  return out;
}

}  // namespace

int benchModel(const BenchArgs& a) {
  // Loops, wheels or contacts beside the file (STEM.loops.json) are held by the hand engine and Bullet.
  const std::string beside = loopsBeside(a.lab);
  model_file::LoadedModel m;
  try {
    model_file::LoadOptions options;
    options.ignore_contacts = a.model_files.ignore_contacts;
    options.package_paths = a.model_files.package_paths;
    options.key = a.model_files.key;
    m = loadWithLoops(a.lab, "", options);
  } catch (const model_file::ModelFileError& e) {
    std::fprintf(stderr, "error: %s\n", termName(e.what(), 1000).c_str());
    return 2;
  }
  const double dt = m.timestep;
  // Its accuracy run (2 s at the file's step, each of 3 engines' q kept per step) has the bound every
  // run has (labs/settings.h).
  if (const std::string problem = runBoundProblem(dt, kAccuracyRun, 3 * std::size_t(m.q0.size()), "timestep"); !problem.empty()) {
    std::fprintf(stderr, "error: %s: <option timestep>: %s\n", utf8Quotable(m.file).c_str(), problem.c_str());
    return 2;
  }
  Engines engines;
  try {
    build(m, dt, !beside.empty(), engines);
  } catch (const std::exception& e) {  // a description the Bullet builder cannot model
    std::fprintf(stderr, "error: %s: %s\n", termName(m.file).c_str(), termName(e.what(), 1000).c_str());
    return 2;
  }
  std::vector<Engine>& list = engines.list;
  for (Engine& e : list) e.restart();
  timeBlocks(list, a.steps);
  ConstrainedMechanism<Spatial> mech(m.mechanism);
  const int run_steps = int(std::lround(kAccuracyRun / dt));
  const std::vector<Accuracy> acc = accuracy(list, m, mech, run_steps, 1);
  const Engine& euler = list[0];
  int rows = 0;
  for (const auto& c : m.closures) rows += int(c.kept.size());
  const std::string mujoco_left_out = beside.empty() ? "" : "MuJoCo not timed: its run of the file would not hold what " + beside + " adds";
  if (a.json) {
    json out = {{"model", m.file}, {"dt", dt}, {"steps_timed", a.steps}, {"closure_rows", rows}, {"accuracy_run_s", kAccuracyRun}};
    if (!beside.empty()) out["beside"] = {{"file", beside}, {"elements", m.contacts.size()}, {"note", mujoco_left_out}};
    if (!engines.bullet_left_out.empty()) out["bullet_left_out"] = engines.bullet_left_out;
    // Whole steps of dt here; model and run take this many per step on a stiff file (stiff_steps.h).
    out["model_run_substeps"] = model_file::stiffSubsteps(model_file::fastestMode(m).rate, dt);
    for (std::size_t i = 0; i < list.size(); ++i) {
      const Ratio r = ratio(list[i].blocks, euler.blocks);
      out["engines"].push_back({{"engine", list[i].name},
                                {"scheme", list[i].scheme},
                                {"us_per_step", median(list[i].blocks)},
                                {"over_hand_first_order", r.median},
                                {"over_hand_first_order_quartiles", {r.low, r.high}},
                                {"max_closure_residual", acc[i].residual},
                                {"max_position_residual", acc[i].position},
                                {"max_q_error_vs_hand_rk4", acc[i].error},
                                {"complete", acc[i].complete}});
    }
    std::cout << out.dump() << "\n";
    return 0;
  }
  const std::string elements = beside.empty() ? "" : ", " + std::to_string(m.contacts.size()) + " wheels or contacts (" + beside + ")";
  const std::string controls = model_file::describeControls(m);
  const std::string start = (controls.empty() ? "passive" : "with " + controls) + " from " + (m.key.empty() ? "its pose at rest" : "keyframe " + m.key);
  std::printf("%s: %d coordinates, %d closure rows%s, dt %g s (the file's), %s\n", termName(m.file).c_str(), int(m.q0.size()), rows,
              termText(elements).c_str(), dt, termName(start, 1000).c_str());
  for (const std::string& note : m.notes) std::printf("  note: %s\n", termName(note, 1000).c_str());
  if (!engines.bullet_left_out.empty()) std::printf("  note: Bullet not timed: %s\n", termName(engines.bullet_left_out, 1000).c_str());
  // A stiff file: the bench steps whole steps of dt, where model and run take sub-steps (stiff_steps.h).
  const model_file::FastestMode fastest = model_file::fastestMode(m);
  if (const int sub = model_file::stiffSubsteps(fastest.rate, dt); sub > 1)
    std::printf("  note: every engine here takes whole steps of dt, without the %d sub-steps per step `dynlab model` and `run` take on this file "
                "(|λ| dt %.3g, joint '%s'): their hand RK4 costs %d times the row below\n",
                sub, fastest.rate * dt, termName(fastest.joint).c_str(), sub);
  if (!beside.empty()) std::printf("  %s\n", termName(mujoco_left_out, 1000).c_str());
  std::printf("  %d steps per engine timed in blocks of %d, in turn; ratios block by block: median (middle half)\n", kBlock * countedBlocks(euler.blocks), kBlock);
  std::printf("  engine             µs/step   over hand, 1st order   max |φ|∞     max |q − q_ref|∞ over 2 s (ref: hand RK4)\n");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const Engine& e = list[i];
    const Ratio r = ratio(e.blocks, euler.blocks);
    char text[64];
    if (i == 0) std::snprintf(text, sizeof text, "1x");
    else std::snprintf(text, sizeof text, "%.1fx (%.1f-%.1f)", r.median, r.low, r.high);
    const std::string label = e.name + (i == 0 ? ", Euler" : i == 1 ? ", RK4" : "");
    std::printf("  %-16s %9.2f   %-22s %-12.2g %.2g%s\n", label.c_str(), median(e.blocks), text, acc[i].residual, acc[i].error,
                acc[i].complete ? "" : " (the 2 s run stopped: non-finite state)");
  }
  // A residual whose rows' velocity form is the larger share (Bullet's gear row on the 2F-85): the positions' own.
  for (std::size_t i = 0; i < list.size(); ++i)
    if (ratesDominate(acc[i].residual, acc[i].position))
      std::printf("  %s: its max |φ|∞ is its rows' velocity form J v (a loop's or a coupling's rate); at the positions (rows, stops' depths): %.2g\n",
                  (list[i].name + (i == 0 ? ", Euler" : i == 1 ? ", RK4" : "")).c_str(), acc[i].position);
  for (const Engine& e : list) std::printf("  %-8s %s\n", (e.name + ":").c_str(), e.scheme.c_str());
  return 0;
}

}  // namespace dyn::app
