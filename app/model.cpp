// dynlab model FILE: see model.h.
#include "app/model.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <deque>
#include <filesystem>
#include <random>
#include <sstream>

#include "app/commands.h"
#include "app/model_loops.h"
#include "labs/generic/data_lab.h"
#include "labs/model_scene.h"
#include "app/movie.h"
#include "app/output.h"
#include "labs/trace.h"
#include "physics/bullet/bullet_mechanism.h"
#include "labs/utf8.h"
#include "physics/constrained_mechanism.h"
#include "physics/constraints/plane_contact.h"
#include "physics/constraints/rolling.h"
#include "physics/model_file/hand_engine.h"
#include "physics/model_file/model_file.h"

namespace dyn::app {
namespace {

std::string fmt(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", x);
  return b;
}

// What dynlab read, as the lines `dynlab model` prints.
std::string describe(const model_file::LoadedModel& m) {
  std::ostringstream o;
  const auto& mech = m.mechanism;
  int kept = 0, all = 0;
  for (const auto& c : m.closures) kept += int(c.kept.size()), all += int(c.kept.size() + c.dropped.size());
  o << m.file << ": " << m.bodies.size() << " moving bodies, " << m.joints.size() << " joints, " << m.closures.size()
    << (m.closures.size() == 1 ? " closure (" : " closures (") << kept << " of " << all << " rows kept), " << m.dof << " degree" << (m.dof == 1 ? "" : "s")
    << " of freedom after closure\n";
  const Eigen::Vector3d g = mech.tree.gravity.tail<3>();
  o << "  gravity (" << fmt(g.x()) << ", " << fmt(g.y()) << ", " << fmt(g.z()) << ") m/s²\n";
  for (std::size_t i = 0; i < m.joints.size(); ++i) {
    const auto& j = m.joints[i];
    double mass = 0;
    Eigen::Vector3d c;
    Spatial::massAndCom(mech.tree.bodies[i].inertia, mass, c);
    o << "  joint " << j.name << " (" << j.type << ", body " << j.body << "): q0 " << fmt(m.q0[Eigen::Index(i)]);
    o << (mech.tree.bodies[i].massless ? ", a massless carrier" : ", carries " + fmt(mass) + " kg");
    if (!mech.joints.empty()) {
      const JointProperties& p = mech.joints[i];
      if (p.stiffness != 0) o << ", spring " << fmt(p.stiffness) << " about " << fmt(p.rest);
      if (p.viscous != 0) o << ", damping " << fmt(p.viscous);
      if (p.coulomb != 0) o << ", friction " << fmt(p.coulomb);
    }
    o << "\n";
  }
  for (const auto& c : m.closures) {
    o << "  closure " << c.name << ": " << c.kind << " " << c.body1 << " to " << c.body2 << ", rows " << join(c.kept) << " kept";
    if (!c.dropped.empty()) o << ", " << join(c.dropped) << " dropped (identically dependent on the rows kept)";
    o << "\n";
  }
  for (std::size_t i = 0; i < m.contacts.size(); ++i) {
    const auto& c = m.contacts[i];
    const Constraint<Spatial>& k = *mech.constraints[m.closures.size() + i];
    if (c.kind == "rolling") {
      const auto& w = static_cast<const Rolling&>(k);
      o << "  rolling " << c.name << ": body " << c.body << ", radius " << fmt(w.radius()) << " m on the ground z = " << fmt(w.groundHeight())
        << ", 3 rows (x y: no slip, velocity-level; z: on the ground), mu " << fmt(w.mu()) << " for the skid margin\n";
    } else {
      const auto& p = static_cast<const PlaneContact<Spatial>&>(k);
      const Eigen::Vector3d nn = p.normal();
      o << "  contact " << c.name << ": a ball of radius " << fmt(p.params().radius) << " m on body " << c.body << " against the plane n·x = "
        << fmt(p.params().height) << " m, n (" << fmt(nn.x()) << ", " << fmt(nn.y()) << ", " << fmt(nn.z()) << "), unilateral, "
        << (p.compliant() ? "compliant (k_e " + fmt(p.params().stiffness) + " N/m, d_e " + fmt(p.params().damping) + " N·s/m)"
                          : std::string("rigid (plastic touchdowns, lift-off)"))
        << ", frictionless in the hand engine" << (p.params().mu > 0 ? ", mu " + fmt(p.params().mu) + " in Bullet's" : "") << "\n";
    }
  }
  for (const auto& n : m.notes) o << "  note: " << n << "\n";
  for (const auto& n : m.drawing.notes) o << "  drawing: " << n << "\n";
  return o.str();
}

// M and the bias against MuJoCo's own at q0 and a few seeded states: the largest differences.
std::string crossCheck(const model_file::LoadedModel& m, ConstrainedMechanism<Spatial>& mech) {
  model_file::MujocoReference mj(m.file);
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int n = mech.n();
  double dM = 0, dh = 0;
  for (int s = 0; s < 5; ++s) {
    VecN q = m.q0, v = VecN::Zero(n);
    for (int i = 0; s > 0 && i < n; ++i) q[i] += u(rng), v[i] = 2.0 * u(rng);
    dM = std::max(dM, (mech.massMatrix(q) - mj.massMatrix(q)).cwiseAbs().maxCoeff());
    dh = std::max(dh, (mech.inverseDynamics(q, v, VecN::Zero(n)) - mj.bias(q, v)).cwiseAbs().maxCoeff());
  }
  return "  against MuJoCo (mj_fullM, qfrc_bias; q0 and 4 seeded states): max |ΔM| " + fmt(dM) + ", max |Δh| " + fmt(dh) + "\n";
}

// The power the joints' damping and friction take out of the mechanism (≥ 0), by the description's
// law (JointProperties::friction), for Bullet's books; the hand engine integrates its own (Books).
double frictionPower(const MechanismModel<Spatial>& d, const VecN& v) {
  double p = 0;
  for (std::size_t i = 0; i < d.joints.size(); ++i) {
    const JointProperties& j = d.joints[i];
    const double w = v[Eigen::Index(i)];
    p += j.friction(w) * w;
  }
  return p;
}


// One engine's passive run: the trace and what the summary reports.
struct Run {
  Trace trace;
  double e0 = 0, residual = 0, balance = 0, kinetic = 0;
  bool ok = true;
  std::string summary;
};

// A rigid plane contact among the model's elements: its touchdowns are plastic impacts.
bool anyImpacts(const model_file::LoadedModel& m) {
  for (std::size_t i = 0; i < m.contacts.size(); ++i)
    if (m.contacts[i].kind == "plane_contact" && !m.mechanism.constraints[m.closures.size() + i]->compliant()) return true;
  return false;
}

Trace emptyTrace(const model_file::LoadedModel& m) {
  Trace t;
  t.columns.push_back("t");
  for (const auto& j : m.joints) t.columns.push_back("q_" + columnName(j.name));
  for (const auto& j : m.joints) t.columns.push_back("v_" + columnName(j.name));
  t.columns.insert(t.columns.end(), {"energy", "work", "constraint_residual"});
  for (const auto& c : m.closures)
    for (const auto& r : c.kept) t.columns.push_back("f_" + columnName(c.name) + "_" + r);
  // dynlab's own elements: a wheel's ground force in wheel axes (heading, axle, up), its skid margin
  // and slip speed; a contact's normal and tangential force and its gap; the touchdowns' energy.
  if (anyImpacts(m)) t.columns.push_back("impacts");
  for (const auto& c : m.contacts) {
    const std::string n = columnName(c.name);
    if (c.kind == "rolling")
      t.columns.insert(t.columns.end(), {"f_" + n + "_long", "f_" + n + "_lat", "f_" + n + "_normal", "skid_margin_" + n, "slip_" + n});
    else
      t.columns.insert(t.columns.end(), {"f_" + n + "_normal", "f_" + n + "_tangent", "gap_" + n});
  }
  return t;
}

// |φ|∞ of a model with dynlab's elements at a state: the closures' and wheels' rows, position and
// velocity forms (a wheel's x, y rows have only the latter: its slip), and each contact's depth past
// its plane (the description's mechanism, whose contacts stay open: their gaps are read, not held).
double elementResidual(const model_file::LoadedModel& m, ConstrainedMechanism<Spatial>& desc, const VecN& q, const VecN& v) {
  double phi = desc.residual(q, v);
  desc.stage(q);
  for (std::size_t i = 0; i < m.contacts.size(); ++i)
    if (const auto* pc = dynamic_cast<const PlaneContact<Spatial>*>(m.mechanism.constraints[m.closures.size() + i].get()))
      if (!pc->compliant()) phi = std::max(phi, -pc->gap(desc.kinematics()));
  return phi;
}

// The row at t: state, energy, the work so far (torques, friction, impacts), |φ|∞ (the description's,
// at this state) and each closure's force on its kept rows, then the elements' columns; the run's
// extremes follow.
void record(Run& run, ConstrainedMechanism<Spatial>& mech, double t, const VecN& q, const VecN& v, double work,
            const std::vector<double>& forces, double phi) {
  const double e = mech.energy(q, v);
  if (run.trace.rows() == 0) run.e0 = e;
  std::vector<double> row{t};
  row.insert(row.end(), q.data(), q.data() + q.size());
  row.insert(row.end(), v.data(), v.data() + v.size());
  row.insert(row.end(), {e, work, phi});
  row.insert(row.end(), forces.begin(), forces.end());
  run.trace.append(row);
  run.residual = std::max(run.residual, phi);
  run.balance = std::max(run.balance, std::abs(e - run.e0 - work));
  run.kinetic = std::max(run.kinetic, mech.kineticEnergy(q, v));
}

// The hand engine from the file's pose at rest: RK4, positions and velocities projected each step,
// stepped by the sized engine the bench times (hand_engine.h); the rows' energy, residual and forces
// (the solve's η at the row's state) from the description's mechanism.
Run runHand(const model_file::LoadedModel& m, ConstrainedMechanism<Spatial>& mech, const ModelArgs& args, const VecN& tau) {
  Run run;
  run.trace = emptyTrace(m);
  StepOptions o;
  o.dt = args.dt;
  const int steps = int(std::lround(args.duration / args.dt)), n = mech.n();
  VecN q = m.q0, v = VecN::Zero(n);
  const std::unique_ptr<ConstrainedSystem> engine = model_file::handEngine(m.mechanism, &run.summary);
  // The books (friction's work) integrated with the motion, at RK4's order (integrate.h).
  engine->setTime(0);
  engine->books() = Books{};
  for (int k = 0; k <= steps; ++k) {
    const auto s = mech.solve(q, v, tau);
    const Books b = engine->books();
    record(run, mech, k * args.dt, q, v, b.work + b.friction, std::vector<double>(s.eta.data(), s.eta.data() + s.eta.size()), mech.residual(q));
    if (k == steps) break;
    if (!(run.ok = step(*engine, o, tau, q, v) && q.allFinite() && v.allFinite())) break;
  }
  return run;
}

// The hand engine with dynlab's elements, stepped as the labs step (labs/mechanism_simulation.h): at
// each step's start the contacts close (a plastic impact on v) or open, and a touchdown inside the step
// is located and closed there. A row's forces are the solve's at its state, plus a touchdown's impulse
// over the step / dt (the step's mean, as impulse engines report it); its work includes the touchdowns'
// −ΔT (the column impacts alone), so E − E0 − W stays RK4's error.
Run runHandElements(const model_file::LoadedModel& m, ConstrainedMechanism<Spatial>& desc, const ModelArgs& args, const VecN& tau) {
  Run run;
  run.trace = emptyTrace(m);
  run.summary = "dynamic sizes; contacts closed and opened between steps, touchdowns located";
  StepOptions o;
  o.dt = args.dt;
  const int steps = int(std::lround(args.duration / args.dt)), n = desc.n();
  const std::size_t closures = m.closures.size();
  int closure_rows = 0;
  for (const auto& c : m.closures) closure_rows += int(c.kept.size());
  const bool impacts = anyImpacts(m);
  ConstrainedMechanism<Spatial> engine(m.mechanism);
  engine.setTime(0);
  engine.books() = Books{};
  VecN q = m.q0, v = VecN::Zero(n);
  for (int k = 0; k <= steps; ++k) {
    engine.updateContacts(q, v, tau);
    const auto s = engine.solve(q, v, tau);
    std::vector<double> row(s.eta.data(), s.eta.data() + closure_rows);
    const double loss = engine.impactLoss();
    if (impacts) row.push_back(loss);
    std::vector<std::array<double, 5>> report(m.contacts.size());
    for (std::size_t i = 0; i < m.contacts.size(); ++i) engine.constraintReport(int(closures + i), s, report[i].data());
    const Books b = engine.books();
    const VecN q_row = q, v_row = v;
    bool stepped = false;
    if (k < steps) {
      stepped = engine.stepLocatingContacts(o, tau, q, v) && q.allFinite() && v.allFinite();
      run.ok = stepped;
    }
    for (std::size_t i = 0; i < m.contacts.size(); ++i) {
      const auto& r = report[i];
      if (m.contacts[i].kind == "rolling") {
        row.insert(row.end(), r.begin(), r.end());
        continue;
      }
      // gap, f_n; a touchdown in the step adds its impulse's normal share / dt.
      const auto* pc = static_cast<const PlaneContact<Spatial>*>(m.mechanism.constraints[closures + i].get());
      const double P = stepped ? pc->normal().dot(Spatial::linear(engine.impactImpulse(int(closures + i)))) : 0.0;
      row.insert(row.end(), {r[1] + P / args.dt, 0.0, r[0]});
    }
    record(run, desc, k * args.dt, q_row, v_row, b.work + b.friction - loss, row, elementResidual(m, desc, q_row, v_row));
    if (k == steps || !run.ok) break;
  }
  return run;
}

// Bullet from the same state; forces: each closure's over the step that starts at the row (the last
// row repeats the last step's).
Run runBullet(const model_file::LoadedModel& m, ConstrainedMechanism<Spatial>& mech, const ModelArgs& args, const VecN& tau) {
  Run run;
  run.trace = emptyTrace(m);
  const int steps = int(std::lround(args.duration / args.dt)), n = mech.n();
  VecN q = m.q0, v = VecN::Zero(n);
  bullet::BulletMechanism<Spatial> bt(m.mechanism, args.dt, q, v);
  run.summary = bt.describe();
  const bool impacts = anyImpacts(m);
  // The power flowing in: the torques' τ·v less what damping and friction take.
  auto inflow = [&](const VecN& w) { return tau.dot(w) - frictionPower(m.mechanism, w); };
  double work = 0, power = inflow(v);
  std::vector<double> forces;
  for (int k = 0; k <= steps; ++k) {
    VecN qn = q, vn = v;
    if (k < steps) {
      bt.step(tau);
      bt.state(qn, vn);
      forces.clear();
      for (std::size_t c = 0; c < m.closures.size(); ++c)
        for (const auto& r : m.closures[c].kept) forces.push_back(bt.constraintForce(int(c))[model_file::rowIndex(r)]);
      // Bullet's impacts are inside its contact impulses: its books hold no separate share.
      if (impacts) forces.push_back(0.0);
      mech.stage(q, &v);
      for (std::size_t i = 0; i < m.contacts.size(); ++i) {
        const int c = int(m.closures.size() + i);
        const Spatial::Vec f = bt.constraintForce(c);
        const Spatial::Pos f_lin = Spatial::linear(f);
        const Constraint<Spatial>& k_c = *m.mechanism.constraints[std::size_t(c)];
        if (m.contacts[i].kind == "rolling") {
          double r[5];
          k_c.report(mech.kinematics(), f_lin.data(), r);  // the rolling rows' η are the force's world components
          forces.insert(forces.end(), r, r + 5);
        } else {
          const auto& pc = static_cast<const PlaneContact<Spatial>&>(k_c);
          const double fn = pc.normal().dot(f_lin);
          forces.insert(forces.end(), {fn, (f_lin - fn * pc.normal()).norm(), pc.gap(mech.kinematics())});
        }
      }
    }
    record(run, mech, k * args.dt, q, v, work, forces, m.contacts.empty() ? mech.residual(q) : elementResidual(m, mech, q, v));
    if (k == steps) break;
    if (!(run.ok = qn.allFinite() && vn.allFinite())) break;
    const double p = inflow(vn);
    work += 0.5 * (power + p) * args.dt;
    power = p;
    q = qn, v = vn;
  }
  return run;
}

std::string report(const Run& r, const std::string& engine, const model_file::LoadedModel& m, const ModelArgs& args) {
  std::ostringstream o;
  const bool driven = !args.torques.empty();
  o << (driven ? "run with constant torques (" + join(args.torques, ", ") + "), " : std::string("passive run, ")) << engine << ", dt "
    << fmt(args.dt) << " s, " << fmt(args.duration) << " s from q0 at rest\n"
    << "  " << (m.contacts.empty() ? "closure residual" : "constraint residual (closures, no-slip rows, contact depth)") << " max |φ|∞ "
    << fmt(r.residual) << "\n"
    << "  energy E0 " << fmt(r.e0) << " J, max |E − E0 − " << (driven || anyImpacts(m) ? "W" : "W_friction") << "| " << fmt(r.balance)
    << " J (kinetic energy up to " << fmt(r.kinetic) << " J"
    << (driven ? "; W: the torques' work and friction's" : anyImpacts(m) ? "; W: friction's and, in the hand engine's books, the touchdowns'" : "")
    << (m.mechanism.joints.empty() && !driven ? "" : "; W by the trapezoid rule in Bullet's books") << ")\n";
  // dynlab's elements: a wheel's largest slip speed, a contact's closest approach and its last force.
  const Trace& t = r.trace;
  if (t.rows() > 0) {
    const std::size_t last = t.rows() - 1;
    for (const auto& c : m.contacts) {
      const std::string n = columnName(c.name);
      double extreme = c.kind == "rolling" ? 0.0 : INFINITY;
      for (std::size_t row = 0; row < t.rows(); ++row)
        extreme = c.kind == "rolling" ? std::max(extreme, std::abs(t.at(row, "slip_" + n))) : std::min(extreme, t.at(row, "gap_" + n));
      if (c.kind == "rolling")
        o << "  rolling " << c.name << ": max slip speed " << fmt(extreme) << " m/s; at the end f_long " << fmt(t.at(last, "f_" + n + "_long"))
          << ", f_lat " << fmt(t.at(last, "f_" + n + "_lat")) << ", f_normal " << fmt(t.at(last, "f_" + n + "_normal")) << " N\n";
      else
        o << "  contact " << c.name << ": min gap " << fmt(extreme) << " m; at the end f_normal " << fmt(t.at(last, "f_" + n + "_normal"))
          << " N, f_tangent " << fmt(t.at(last, "f_" + n + "_tangent")) << " N\n";
    }
    for (std::size_t i = 0; i < m.contacts.size(); ++i)
      if (m.mechanism.constraints[m.closures.size() + i]->compliant()) {
        o << "  note: a compliant contact's spring energy and damping are not in the books (its E − E0 − W holds them)\n";
        break;
      }
    if (anyImpacts(m)) {
      if (engine.rfind("hand", 0) == 0)
        o << "  touchdowns (plastic impacts) took " << fmt(t.at(last, "impacts")) << " J (counted in W)\n";
      else
        o << "  touchdowns: inside Bullet's contact impulses, not counted in W (its E − E0 − W holds their loss)\n";
    }
  }
  if (!r.ok)
    o << "  the run stopped at t = " << fmt(double(r.trace.rows() - 1) * args.dt)
      << " s: the projection failed or the state left the finite numbers\n";
  return o.str();
}

}  // namespace

ModelCommand::ModelCommand(CLI::App& cli) {
  ModelArgs& a = args_;
  command_ = cli.add_subcommand("model", "Load a mechanism from an MJCF or URDF file, print what dynlab read (bodies, joints, "
                                         "loop closures and their rows, freedom), check M and h against MuJoCo's, run it "
                                         "passive with the hand engine and Bullet: closure residual, energy balance, agreement, "
                                         "OUT/trace.csv, OUT/trace_bullet.csv");
  command_->add_option("FILE", a.file, "MJCF (.xml) or URDF file (assets/models/ has examples)")->required();
  command_->add_option("--duration", a.duration, "Simulated time (s, default 2)")->check(CLI::Range(0.0, 600.0));
  command_->add_option("--dt", a.dt, "Fixed step (s, default 0.001; RK4 + projection)")->check(CLI::Range(1e-5, 1e-2));
  command_->add_option("--out", a.out, "Output directory (default: out/model/FILE's stem)");
  command_->add_option("--engine", a.engine, "Which engine(s) to run (default: both)")->check(CLI::IsMember({"hand", "bullet", "both"}));
  command_->add_option("--torque", a.torques, "A constant joint torque JOINT=VALUE (N·m; N on a slide), repeatable (default: passive)")
      ->allow_extra_args(false);
  command_->add_option("--loops", a.loops, "Loop closures beside the file (JSON; default: STEM.loops.json beside FILE when it exists)");
  command_->add_flag("--ignore-contacts", a.ignore_contacts, "Load a file whose geoms may collide, ignoring contacts (noted)");
  command_->add_flag("--video", a.video, "Write video.mp4 of the run drawn from the file's geoms (H.264, 30 fps; the Bullet run as a ghost)");
  command_->add_flag("--frames", a.frames, "Write frames/NNNNN.png (30 fps)");
}

int runModelFile(const RunArgs& r) {
  for (const auto& [given, option] : {std::pair{!r.config.empty(), "--config"}, {!r.gains.empty(), "--gains"}, {!r.scenario.empty(), "--scenario"}})
    if (given) {
      std::fprintf(stderr, "error: <command line>: %s: a model file (%s) runs passive, without a lab's config, gains or scenario\n", option,
                   utf8Quotable(r.lab).c_str());
      return 2;
    }
  ModelArgs a;
  a.file = r.lab;
  a.out = r.out;
  a.engine = r.engine;
  a.video = r.video;
  a.frames = r.frames;
  a.torques = r.torques;
  a.loops = r.loops;
  if (r.duration) {
    if (!(*r.duration > 0 && *r.duration <= 600)) {
      std::fprintf(stderr, "error: <command line>: --duration: expected a time in (0, 600] s for a model file, got %g\n", *r.duration);
      return 2;
    }
    a.duration = *r.duration;
  }
  return model(a);
}

int model(const ModelArgs& args) {
  // A trace row per step: bounded before anything runs.
  constexpr double kMaxSteps = 2e6;
  if (args.duration / args.dt > kMaxSteps) {
    std::fprintf(stderr, "error: --duration %g s at --dt %g s is %.0f steps; at most %.0f (a trace row each)\n", args.duration, args.dt,
                 std::ceil(args.duration / args.dt), kMaxSteps);
    return 2;
  }
  model_file::LoadedModel m;
  try {
    model_file::LoadOptions options;
    options.ignore_contacts = args.ignore_contacts;
    m = loadWithLoops(args.file, args.loops, options);
  } catch (const model_file::ModelFileError& e) {
    std::fprintf(stderr, "error: %s\n", utf8Quotable(e.what()).c_str());
    return 2;
  }
  // Constant torques by joint name: each "JOINT=VALUE" once, a joint of the file, a finite value.
  VecN tau = VecN::Zero(Eigen::Index(m.joints.size()));
  std::vector<bool> given(m.joints.size(), false);
  for (const std::string& t : args.torques) {
    std::vector<std::string> names;
    for (const auto& j : m.joints) names.push_back(j.name);
    const std::size_t eq = t.find('=');
    const std::string joint = t.substr(0, eq);
    const auto it = std::find(names.begin(), names.end(), joint);
    double value = 0;
    char* end = nullptr;
    if (eq != std::string::npos) value = std::strtod(t.c_str() + eq + 1, &end);
    if (eq == std::string::npos || it == names.end() || end == t.c_str() + eq + 1 || *end != '\0' || !std::isfinite(value) ||
        std::abs(value) > 1e4 || given[std::size_t(it - names.begin())]) {
      std::fprintf(stderr, "error: <command line>: --torque %s: expected JOINT=VALUE once per joint, JOINT one of %s's joints (%s), VALUE a finite "
                   "N·m (N on a slide) within ±1e4\n", utf8Quotable(t).c_str(), utf8Quotable(m.file).c_str(), utf8Quotable(join(names)).c_str());
      return 2;
    }
    given[std::size_t(it - names.begin())] = true;
    tau[it - names.begin()] = value;
  }
  ConstrainedMechanism<Spatial> mech(m.mechanism);
  std::string text = describe(m) + crossCheck(m, mech);
  const bool hand = args.engine != "bullet", bullet = args.engine != "hand";
  Run h, b;
  if (hand) h = m.contacts.empty() ? runHand(m, mech, args, tau) : runHandElements(m, mech, args, tau);
  if (bullet) {
    try {
      b = runBullet(m, mech, args, tau);
    } catch (const std::exception& e) {  // a description the Bullet builder cannot model
      std::fprintf(stderr, "error: %s: Bullet: %s\n", utf8Quotable(m.file).c_str(), utf8Quotable(e.what()).c_str());
      return 2;
    }
  }
  if (hand) text += report(h, "hand engine (" + h.summary + "): RK4 + projection", m, args);
  if (bullet) text += report(b, b.summary + ", semi-implicit Euler", m, args);
  if (hand && bullet) {
    double dq = 0;
    const int n = mech.n();
    for (std::size_t r = 0; r < std::min(h.trace.rows(), b.trace.rows()); ++r)
      for (int i = 0; i < n; ++i) dq = std::max(dq, std::abs(h.trace.at(r, 1 + i) - b.trace.at(r, 1 + i)));
    text += "agreement: max |q_hand − q_bullet|∞ " + fmt(dq) + " (Bullet's step is first order)\n";
  }
  const bool ok = (!hand || h.ok) && (!bullet || b.ok);
  const std::filesystem::path out = args.out.empty() ? std::filesystem::path("out/model") / std::filesystem::path(args.file).stem() : std::filesystem::path(args.out);
  text += "wrote " + out.string() + "/" + (hand ? "trace.csv " : "") + (bullet ? "trace_bullet.csv " : "") + "summary.txt";
  if (args.video) text += " video.mp4";
  if (args.frames) text += " frames/";
  text += "\n";
  try {
    Staging staging(out);
    staging.owns({"trace.csv", "trace_bullet.csv", "summary.txt", "video.mp4", "frames"});
    if (hand) staging.write("trace.csv", h.trace.csv());
    if (bullet) staging.write("trace_bullet.csv", b.trace.csv());
    staging.write("summary.txt", text);
    if (args.video || args.frames) {
      // The hand run drawn from the file's geoms, Bullet's as a ghost; the camera framed once around
      // the space both move through.
      const Trace& shown = hand ? h.trace : b.trace;
      const Trace* ghost = hand && bullet ? &b.trace : nullptr;
      const int n = mech.n();
      const ModelPicture picture(m);
      const Eigen::AlignedBox3d box = runBounds(picture, n, shown, ghost);
      const std::string title = std::filesystem::path(m.file).filename().string();
      const std::string engines = hand ? (ghost ? "hand; Bullet ghost" : "hand") : "Bullet";
      const DrawRow draw = [&](std::size_t row, Scene& scene, Overlay* panel) {
        const VecN q = traceQ(shown, row, n);
        VecN gq;
        if (ghost && row < ghost->rows()) gq = traceQ(*ghost, row, n);
        picture.scene(q, gq.size() ? &gq : nullptr, box, scene);
        if (panel) modelOverlay(utf8Quotable(title), engines, shown, row, args.dt, ghost, *panel);
      };
      const int frames = renderFrames(draw, shown, args.dt, {640, 480, 30, args.video, args.frames}, staging.path(""));
      text += "  " + std::to_string(frames) + " frames at 30 per second of simulated time, 640x480\n";
    }
    staging.commit();
  } catch (const std::exception& e) {
    std::fputs(text.c_str(), stdout);
    std::fprintf(stderr, "error: %s\n", utf8Quotable(e.what()).c_str());
    return 1;
  }
  std::fputs(text.c_str(), stdout);
  return ok ? 0 : 1;
}

}  // namespace dyn::app
