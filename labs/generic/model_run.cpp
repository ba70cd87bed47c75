// One engine's run of a loaded model: see model_run.h (moved from app/cli/model/model.cpp, unchanged).
#include "labs/generic/model_run.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>

#include "physics/bullet/bullet_mechanism.h"
#include "physics/constraints/joint_limit.h"
#include "physics/constraints/plane_contact.h"
#include "physics/constraints/rolling.h"
#include "physics/model_file/actuators.h"
#include "physics/model_file/closure_rows.h"
#include "physics/model_file/hand_engine.h"
#include "physics/model_file/stiff_steps.h"

namespace dyn::app {
namespace {

// The row at t: state, energy, the work so far (torques, friction, impacts), |φ|∞ (the description's,
// at this state) and each closure's force on its kept rows, then the elements' columns; the run's
// extremes follow.
void record(ModelRun& run, ConstrainedMechanism<Spatial>& mech, double t, const VecN& q, const VecN& v, double work,
            const std::vector<double>& forces, const RunResidual& phi) {
  const double e = mech.energy(q, v);
  if (run.trace.rows() == 0) run.e0 = e;
  std::vector<double> row{t};
  row.insert(row.end(), q.data(), q.data() + q.size());
  row.insert(row.end(), v.data(), v.data() + v.size());
  row.insert(row.end(), {e, work, phi.all});
  row.insert(row.end(), forces.begin(), forces.end());
  run.trace.append(row);
  run.residual = std::max(run.residual, phi.all);
  run.position_residual = std::max(run.position_residual, phi.positions);
  run.balance = std::max(run.balance, std::abs(e - run.e0 - work));
  run.kinetic = std::max(run.kinetic, mech.kineticEnergy(q, v));
}

// The hand engine holds the kept rows; a dropped row past kDroppedRowDrift is a loop opening: the run
// stops there, saying which (true).
bool stopIfOpened(ModelRun& run, model_file::EveryClosureRow& every, const VecN& q) {
  std::string why = every.opened(q);
  if (why.empty()) return false;
  run.ok = false;
  run.stopped = std::move(why);
  return true;
}

}  // namespace

namespace {
// The largest depth of a rigid contact or a joint stop past its bound at the state desc was staged at.
double elementDepth(const model_file::LoadedModel& m, ConstrainedMechanism<Spatial>& desc) {
  double phi = 0;
  for (std::size_t i = 0; i < m.contacts.size(); ++i)
    if (const auto* pc = dynamic_cast<const PlaneContact<Spatial>*>(m.mechanism.constraints[m.closures.size() + i].get())) {
      if (!pc->compliant()) phi = std::max(phi, -pc->gap(desc.kinematics()));
    } else if (const auto* jl = dynamic_cast<const JointLimit*>(m.mechanism.constraints[m.closures.size() + i].get())) {
      phi = std::max(phi, -jl->gap(desc.kinematics()));
    }
  return phi;
}
}  // namespace

// The description's mechanism keeps its contacts open: their gaps are read, not held.
double elementResidual(const model_file::LoadedModel& m, ConstrainedMechanism<Spatial>& desc, const VecN& q, const VecN& v) {
  const double phi = desc.residual(q, v);
  desc.stage(q);
  return std::max(phi, elementDepth(m, desc));
}

RunResidual runResidual(const model_file::LoadedModel& m, ConstrainedMechanism<Spatial>& desc, model_file::EveryClosureRow& every, const VecN& q,
                        const VecN& v) {
  const double rows = every.residual(q);
  if (m.contacts.empty()) {
    const double phi = desc.residual(q);
    return {std::max(phi, rows), std::max(phi, rows)};
  }
  const double with_rates = desc.residual(q, v), at_positions = desc.residual(q);
  desc.stage(q);
  const double depth = elementDepth(m, desc);
  return {std::max(std::max(with_rates, depth), rows), std::max(std::max(at_positions, depth), rows)};
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


std::vector<std::string> modelNotes(const model_file::LoadedModel& m, double dt) {
  std::vector<std::string> notes = m.notes;
  for (const std::string& n : m.drawing.notes) notes.push_back("drawing: " + n);
  ConstrainedMechanism<Spatial> mech(m.mechanism);
  // The servos at the sub-step the runs take (stiff_steps.h): a note when even that is too coarse.
  const model_file::FastestMode fastest = model_file::fastestMode(m);
  const double h = dt / model_file::stiffSubsteps(fastest.rate, dt);
  if (std::string stiff = model_file::stiffServoNote(m, mech.massMatrix(m.start_q), h); !stiff.empty()) notes.push_back(std::move(stiff));
  if (std::string sub = model_file::stiffStepNote(fastest, dt); !sub.empty()) notes.push_back(std::move(sub));
  return notes;
}

// A rigid plane contact among the model's elements: its touchdowns are plastic impacts.
bool anyImpacts(const model_file::LoadedModel& m) {
  for (std::size_t i = 0; i < m.contacts.size(); ++i)
    if ((m.contacts[i].kind == "plane_contact" || m.contacts[i].kind == "joint_limit") && !m.mechanism.constraints[m.closures.size() + i]->compliant())
      return true;
  return false;
}

std::vector<std::string> coordinateColumns(const model_file::LoadedModel& m) {
  std::vector<std::string> q;
  if (m.coordinates.size() == std::size_t(m.q0.size()))
    for (const auto& c : m.coordinates) q.push_back("q_" + columnName(c));
  else
    for (const auto& j : m.joints) q.push_back("q_" + columnName(j.name));
  return q;
}

Trace modelColumns(const model_file::LoadedModel& m) {
  Trace t;
  t.columns.push_back("t");
  // q's entries by name (a ball's quaternion: NAME_qw … NAME_qz), then the rates (NAME_wx … for a ball).
  const std::vector<std::string> q = coordinateColumns(m);
  t.columns.insert(t.columns.end(), q.begin(), q.end());
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
    else if (c.kind == "joint_limit")  // the stop's force (N·m or N, ≥ 0) and the joint's distance to it
      t.columns.insert(t.columns.end(), {"f_" + n + "_normal", "gap_" + n});
    else if (c.coupling())  // η, its generalised force
      t.columns.push_back("f_" + n);
    else
      t.columns.insert(t.columns.end(), {"f_" + n + "_normal", "f_" + n + "_tangent", "gap_" + n});
  }
  return t;
}

// The hand engine from the file's pose at rest: RK4, positions and velocities projected each step,
// stepped by the sized engine the bench times (hand_engine.h); the rows' energy, residual and forces
// (the solve's η at the row's state) from the description's mechanism.
ModelRun runHand(const model_file::LoadedModel& m, ConstrainedMechanism<Spatial>& mech, double dt, double duration, const VecN& tau) {
  ModelRun run;
  run.trace = modelColumns(m);
  StepOptions o;
  o.dt = dt;
  o.substeps = model_file::stiffSubsteps(model_file::fastestMode(m).rate, dt);  // the model's stiffest mode (stiff_steps.h)
  const int steps = int(std::lround(duration / dt));
  VecN q = m.start_q, v = m.start_v;
  // The file's actuators evaluated at each stage of the step (actuators.h).
  const std::unique_ptr<ConstrainedSystem> engine = model_file::withActuators(model_file::handEngine(m.mechanism, &run.summary), m);
  // The books (friction's work) integrated with the motion, at RK4's order (integrate.h).
  engine->setTime(0);
  engine->books() = Books{};
  model_file::EveryClosureRow every(m);
  for (int k = 0; k <= steps; ++k) {
    const auto s = mech.solve(q, v, tau + model_file::actuatorTorques(m, q, v));
    const Books b = engine->books();
    record(run, mech, k * dt, q, v, b.work + b.friction, std::vector<double>(s.eta.data(), s.eta.data() + s.eta.size()),
           runResidual(m, mech, every, q, v));
    if (stopIfOpened(run, every, q) || k == steps) break;
    if (!(run.ok = step(*engine, o, tau, q, v) && q.allFinite() && v.allFinite())) break;
  }
  return run;
}

// The hand engine with dynlab's elements, stepped as the labs step (labs/mechanism_simulation.h): at
// each step's start the contacts close (a plastic impact on v) or open, and a touchdown inside the step
// is located and closed there. A row's forces are the solve's at its state, plus a touchdown's impulse
// over the step / dt (the step's mean, as impulse engines report it); its work includes the touchdowns'
// −ΔT (the column impacts alone), so E − E0 − W stays RK4's error.
ModelRun runHandElements(const model_file::LoadedModel& m, ConstrainedMechanism<Spatial>& desc, double dt, double duration, const VecN& tau) {
  ModelRun run;
  run.trace = modelColumns(m);
  run.summary = "dynamic sizes; contacts closed and opened between steps, touchdowns located";
  StepOptions o;
  o.dt = dt;
  o.substeps = model_file::stiffSubsteps(model_file::fastestMode(m).rate, dt);
  const int steps = int(std::lround(duration / dt));
  const std::size_t closures = m.closures.size();
  int closure_rows = 0;
  for (const auto& c : m.closures) closure_rows += int(c.kept.size());
  const bool impacts = anyImpacts(m);
  // The file's actuators and tendons evaluated at each stage of the step, as runHand's engine does
  // (actuators.h); the step's contact updates see them at its start.
  model_file::DrivenMechanism engine(m);
  engine.setTime(0);
  engine.books() = Books{};
  model_file::EveryClosureRow every(m);
  VecN q = m.start_q, v = m.start_v;
  for (int k = 0; k <= steps; ++k) {
    VecN driven = engine.hold(q, v, tau);
    if (engine.updateContacts(q, v, driven) > 0) driven = engine.hold(q, v, tau);  // an impact changed v
    const auto s = engine.solve(q, v, driven);
    std::vector<double> row(s.eta.data(), s.eta.data() + closure_rows);
    const double loss = engine.impactLoss();
    if (impacts) row.push_back(loss);
    std::vector<std::array<double, 5>> report(m.contacts.size());
    for (std::size_t i = 0; i < m.contacts.size(); ++i) engine.constraintReport(int(closures + i), s, report[i].data());
    const Books b = engine.books();
    const VecN q_row = q, v_row = v;
    bool stepped = false;
    if (k < steps) {
      stepped = engine.stepLocatingContacts(o, driven, q, v) && q.allFinite() && v.allFinite();
      run.ok = stepped;
    }
    for (std::size_t i = 0; i < m.contacts.size(); ++i) {
      const auto& r = report[i];
      if (m.contacts[i].kind == "rolling") {
        row.insert(row.end(), r.begin(), r.end());
        continue;
      }
      const Constraint<Spatial>& k_c = *m.mechanism.constraints[closures + i];
      if (const auto* jl = dynamic_cast<const JointLimit*>(&k_c)) {  // gap, f_n (+ a touchdown's impulse / dt)
        const double P = stepped ? jl->along(engine.kinematics(), engine.impactImpulse(int(closures + i))) : 0.0;
        row.insert(row.end(), {r[1] + P / dt, r[0]});
        continue;
      }
      if (m.contacts[i].coupling()) {  // its η
        row.push_back(s.eta[engine.rowOffset(int(closures + i))]);
        continue;
      }
      // gap, f_n; a touchdown in the step adds its impulse's normal share / dt.
      const auto* pc = static_cast<const PlaneContact<Spatial>*>(m.mechanism.constraints[closures + i].get());
      const double P = stepped ? pc->normal().dot(Spatial::linear(engine.impactImpulse(int(closures + i)))) : 0.0;
      row.insert(row.end(), {r[1] + P / dt, 0.0, r[0]});
    }
    record(run, desc, k * dt, q_row, v_row, b.work + b.friction - loss, row, runResidual(m, desc, every, q_row, v_row));
    if (stopIfOpened(run, every, q_row) || k == steps || !run.ok) break;
  }
  return run;
}

// Bullet from the same state; forces: each closure's over the step that starts at the row (the last
// row repeats the last step's).
ModelRun runBullet(const model_file::LoadedModel& m, ConstrainedMechanism<Spatial>& mech, double dt, double duration, const VecN& tau) {
  ModelRun run;
  run.trace = modelColumns(m);
  const int steps = int(std::lround(duration / dt));
  VecN q = m.start_q, v = m.start_v;
  // Bullet's explicit dampers and springs need the sub-steps the hand engine takes (stiff_steps.h): the
  // same h = dt / s for both, each of Bullet's a step of its own, the torques (a servo's damping among
  // them) evaluated at each sub-step's start and their work summed over the sub-steps (trapezoid rule).
  const int substeps = model_file::stiffSubsteps(model_file::fastestMode(m).rate, dt);
  const double h = dt / substeps;
  bullet::BulletMechanism<Spatial> bt(m.mechanism, h, q, v);
  run.summary = bt.describe() + (substeps > 1 ? ", " + std::to_string(substeps) + " steps of dt/" + std::to_string(substeps) + " per row" : "");
  const bool impacts = anyImpacts(m);
  // The torques: τ and the file's actuators at the state (held over Bullet's step from its start).
  auto driven = [&](const VecN& p, const VecN& w) { return VecN(tau + model_file::actuatorTorques(m, p, w)); };
  // The power flowing in: the torques' τ·v less what damping and friction take.
  auto inflow = [&](const VecN& p, const VecN& w) { return driven(p, w).dot(w) - frictionPower(m.mechanism, w); };
  double work = 0, power = inflow(q, v);
  std::vector<double> forces;
  model_file::EveryClosureRow every(m);  // |φ| over every row (Bullet's drift is its own: reported, not stopped)
  for (int k = 0; k <= steps; ++k) {
    VecN qn = q, vn = v;
    const double row_work = work;  // the books at the row; work and power run on through the sub-steps
    if (k < steps) {
      for (int sub = 0; sub < substeps; ++sub) {
        if (sub > 0) {  // the sub-step's start: its torques, and the work of the one before
          bt.state(qn, vn);
          const double p = inflow(qn, vn);
          work += 0.5 * (power + p) * h;
          power = p;
        }
        bt.step(driven(qn, vn));
      }
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
        if (const auto* jl = dynamic_cast<const JointLimit*>(&k_c)) {
          forces.insert(forces.end(), {jl->along(mech.kinematics(), f), jl->gap(mech.kinematics())});
        } else if (m.contacts[i].coupling()) {
          forces.push_back(f[0]);  // a coupling: Bullet's gear impulse / dt (builder: constraintForce's first entry)
        } else if (m.contacts[i].kind == "rolling") {
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
    record(run, mech, k * dt, q, v, row_work, forces, runResidual(m, mech, every, q, v));
    if (k == steps) break;
    if (!(run.ok = qn.allFinite() && vn.allFinite())) break;
    const double p = inflow(qn, vn);
    work += 0.5 * (power + p) * h;
    power = p;
    q = qn, v = vn;
  }
  return run;
}

}  // namespace dyn::app
