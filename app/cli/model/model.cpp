// dynlab model FILE: see model.h.
#include "app/cli/model/model.h"

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

#include "app/cli/commands.h"
#include "app/cli/isolated_draw.h"
#include "labs/file_write.h"
#include "labs/generic/model_description.h"
#include "labs/generic/model_loops.h"
#include "labs/generic/model_run.h"
#include "labs/generic/data_lab.h"
#include "labs/model_scene.h"
#include "app/shared/movie.h"
#include "app/cli/output.h"
#include "labs/trace.h"
#include "physics/bullet/bullet_mechanism.h"
#include "labs/numbers.h"
#include "labs/utf8.h"
#include "physics/constrained_mechanism.h"
#include "physics/constraints/coupling.h"
#include "physics/constraints/joint_limit.h"
#include "physics/constraints/plane_contact.h"
#include "physics/constraints/rolling.h"
#include "physics/model_file/actuators.h"
#include "physics/model_file/hand_engine.h"
#include "physics/model_file/model_file.h"
#include "physics/model_file/stiff_steps.h"

namespace dyn::app {
namespace {

std::string fmt(double x) { return dyn::fmt("%.4g", x); }

// A name or path from the file (or the command line) as `dynlab model` prints it: escaped and clipped.
std::string nameShown(const std::string& s) { return termName(s); }

// A note or an error that quotes names: one line, escaped, at most a few names long.
std::string shownLine(const std::string& s) { return termName(s, 1000); }

// What dynlab read, as the lines `dynlab model` prints (every name from the file escaped and clipped).
std::string describe(const model_file::LoadedModel& m) {
  std::ostringstream o;
  const auto& mech = m.mechanism;
  int kept = 0, all = 0;
  for (const auto& c : m.closures) kept += int(c.kept.size()), all += int(c.kept.size() + c.dropped.size());
  o << nameShown(m.file) << ": " << m.bodies.size() << " moving bodies, " << m.joints.size() << " joints, " << m.closures.size()
    << (m.closures.size() == 1 ? " closure (" : " closures (") << kept << " of " << all << " rows kept), " << m.dof << " degree" << (m.dof == 1 ? "" : "s")
    << " of freedom after closure\n";
  const Eigen::Vector3d g = mech.tree.gravity.tail<3>();
  o << "  gravity (" << fmt(g.x()) << ", " << fmt(g.y()) << ", " << fmt(g.z()) << ") m/s²\n";
  for (std::size_t i = 0; i < m.joints.size(); ++i) {
    const auto& j = m.joints[i];
    double mass = 0;
    Eigen::Vector3d c;
    Spatial::massAndCom(mech.tree.bodies[i].inertia, mass, c);
    o << "  joint " << nameShown(j.name) << " (" << nameShown(j.type) << ", body " << nameShown(j.body) << "): q0 " << fmt(m.q0[Eigen::Index(j.qpos)]);
    // A ball's (or free joint's) rotation: its three rates share one quaternion (w x y z), shown once.
    if (mech.tree.bodies[i].joint == JointType::Ball)
      o << (mech.tree.bodies[i].ball >= 0 && mech.tree.balls[std::size_t(mech.tree.bodies[i].ball)].first == int(i)
                ? " (quaternion w; x y z " + fmt(m.q0[j.qpos + 1]) + " " + fmt(m.q0[j.qpos + 2]) + " " + fmt(m.q0[j.qpos + 3]) + "), rate ω in the body's frame"
                : ", rate ω in the body's frame");
    o << (mech.tree.bodies[i].massless ? ", a massless carrier" : ", carries " + fmt(mass) + " kg");
    if (!mech.joints.empty()) {
      const JointProperties& p = mech.joints[i];
      if (p.stiffness != 0) o << ", spring " << fmt(p.stiffness) << " about " << fmt(p.rest);
      if (p.viscous != 0) o << ", damping " << fmt(p.viscous);
      if (p.coulomb != 0) o << ", friction " << fmt(p.coulomb);
      if (p.armature != 0) o << ", armature " << fmt(p.armature);
    }
    o << "\n";
  }
  for (const auto& c : m.closures) {
    o << "  closure " << nameShown(c.name) << ": " << nameShown(c.kind) << " " << nameShown(c.body1) << " to " << nameShown(c.body2) << ", rows " << join(c.kept) << " kept";
    if (!c.dropped.empty()) o << ", " << join(c.dropped) << " dropped (identically dependent on the rows kept)";
    o << "\n";
  }
  for (std::size_t i = 0; i < m.contacts.size(); ++i) {
    const auto& c = m.contacts[i];
    const Constraint<Spatial>& k = *mech.constraints[m.closures.size() + i];
    if (c.kind == "rolling") {
      const auto& w = static_cast<const Rolling&>(k);
      o << "  rolling " << nameShown(c.name) << ": body " << nameShown(c.body) << ", radius " << fmt(w.radius()) << " m on the ground z = " << fmt(w.groundHeight())
        << ", 3 rows (x y: no slip, velocity-level; z: on the ground), mu " << fmt(w.mu()) << " for the skid margin\n";
    } else if (const auto* jl = dynamic_cast<const JointLimit*>(&k)) {
      o << "  limit " << nameShown(c.name) << ": joint stop at " << fmt(jl->bound()) << ", unilateral, rigid (plastic stops, release)\n";
    } else if (const auto* cp = dynamic_cast<const Coupling*>(&k)) {
      const auto& p = cp->poly();
      o << "  coupling " << nameShown(c.name) << ": " << nameShown(c.kind) << ", 1 row, s1 = " << fmt(p[0]);
      if (!cp->second().empty()) o << " + " << fmt(p[1]) << " s2 + " << fmt(p[2]) << " s2^2 + " << fmt(p[3]) << " s2^3 + " << fmt(p[4]) << " s2^4";
      o << " (s: from the reference pose)\n";
    } else {
      const auto& p = static_cast<const PlaneContact<Spatial>&>(k);
      const Eigen::Vector3d nn = p.normal();
      o << "  contact " << nameShown(c.name) << ": a ball of radius " << fmt(p.params().radius) << " m on body " << nameShown(c.body) << " against the plane n·x = "
        << fmt(p.params().height) << " m, n (" << fmt(nn.x()) << ", " << fmt(nn.y()) << ", " << fmt(nn.z()) << "), unilateral, "
        << (p.compliant() ? "compliant (k_e " + fmt(p.params().stiffness) + " N/m, d_e " + fmt(p.params().damping) + " N·s/m)"
                          : std::string("rigid (plastic touchdowns, lift-off)"))
        << ", frictionless in the hand engine" << (p.params().mu > 0 ? ", mu " + fmt(p.params().mu) + " in Bullet's" : "") << "\n";
    }
  }
  for (const auto& a : m.actuators) {
    o << "  actuator " << nameShown(a.name) << " on " << shownLine(model_file::describePath(m, a)) << ": force = " << fmt(a.gain) << " ctrl";
    const char* const terms[3] = {"", " length", " velocity"};
    for (int k = 0; k < 3; ++k)
      if (a.bias[std::size_t(k)] != 0) o << (a.bias[std::size_t(k)] < 0 ? " − " : " + ") << fmt(std::abs(a.bias[std::size_t(k)])) << terms[k];
    o << ", gear " << fmt(a.gear);
    if (a.ctrl_limited) o << ", ctrl in [" << fmt(a.ctrl_lower) << ", " << fmt(a.ctrl_upper) << "]";
    if (a.force_limited) o << ", force in [" << fmt(a.force_lower) << ", " << fmt(a.force_upper) << "]";
    o << "\n";
  }
  for (const auto& t : m.tendons) o << "  " << shownLine(model_file::describeTendon(m, t)) << "\n";
  for (const auto& n : m.notes) o << "  note: " << shownLine(n) << "\n";
  for (const auto& n : m.drawing.notes) o << "  drawing: " << shownLine(n) << "\n";
  return o.str();
}

// M and the bias against MuJoCo's own at q0 and a few seeded states: the largest differences.
std::string crossCheck(const model_file::LoadedModel& m, ConstrainedMechanism<Spatial>& mech) {
  model_file::MujocoReference mj(m);
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int n = mech.n();
  double dM = 0, dh = 0, da = 0;
  for (int s = 0; s < 5; ++s) {
    VecN q = m.q0, v = VecN::Zero(n);
    for (int i = 0; s > 0 && i < n; ++i) q[i] += u(rng), v[i] = 2.0 * u(rng);
    // A ball's quaternion has one more entry than its rates: moved too, then back to unit length.
    for (Eigen::Index i = n; s > 0 && i < q.size(); ++i) q[i] += u(rng);
    normalizeConfiguration(m.mechanism.tree, q);
    dM = std::max(dM, (mech.massMatrix(q) - mj.massMatrix(q)).cwiseAbs().maxCoeff());
    dh = std::max(dh, (mech.inverseDynamics(q, v, VecN::Zero(n)) - mj.bias(q, v)).cwiseAbs().maxCoeff());
    // The actuators' torques at controls spread past their ranges (the clamps included).
    VecN ctrl = m.ctrl;
    for (Eigen::Index i = 0; s > 0 && i < ctrl.size(); ++i) ctrl[i] = 2.0 * u(rng) * (1.0 + std::abs(m.actuators[std::size_t(i)].ctrl_upper));
    if (!m.actuators.empty()) da = std::max(da, (model_file::actuatorTorques(m.actuators, ctrl, q, v) - mj.actuation(q, v, ctrl)).cwiseAbs().maxCoeff());
  }
  return "  against MuJoCo (mj_fullM, qfrc_bias" + std::string(m.actuators.empty() ? "" : ", qfrc_actuator") + "; q0 and 4 seeded states): max |ΔM| " +
         fmt(dM) + ", max |Δh| " + fmt(dh) + (m.actuators.empty() ? "" : ", max |Δτ_actuators| " + fmt(da)) + "\n";
}

// MuJoCo's own measure of the file's loops along a run's trace (MujocoReference::closure at each row's q):
// the closure checked by the other engine's kinematics, not dynlab's. "" without a connect or weld in the file.
std::string mujocoClosure(const model_file::LoadedModel& m, const ModelRun& r) {
  if (m.closures.empty() || r.trace.rows() == 0 || !m.compiled) return "";  // a description has no MuJoCo model
  model_file::MujocoReference mj(m);
  const Eigen::Index nq = m.q0.size();
  double gap = -1;
  VecN q(nq);
  for (std::size_t row = 0; row < r.trace.rows(); ++row) {
    for (Eigen::Index i = 0; i < nq; ++i) q[i] = r.trace.at(row, std::size_t(1 + i));
    gap = std::max(gap, mj.closure(q));
  }
  return gap < 0 ? "" : "  MuJoCo's own measure of the file's loops at this trace (its kinematics: xpos + xmat of each connect's anchors) max |p1 − p2|∞ " + fmt(gap) + " m\n";
}

// The notes on the step: the sub-steps the model's fastest mode asks for (stiff_steps.h), and servos
// stiffer than RK4 follows even at that sub-step.
std::string stepNotes(const model_file::LoadedModel& m, ConstrainedMechanism<Spatial>& mech, double dt) {
  const model_file::FastestMode fastest = model_file::fastestMode(m);
  const double sub_step = dt / model_file::stiffSubsteps(fastest.rate, dt);
  std::string text;
  if (const std::string stiff = model_file::stiffServoNote(m, mech.massMatrix(m.start_q), sub_step); !stiff.empty()) text += "  note: " + shownLine(stiff) + "\n";
  if (const std::string sub = model_file::stiffStepNote(fastest, dt); !sub.empty()) text += "  note: " + shownLine(sub) + "\n";
  return text;
}

// Beside a residual that holds the rows' velocity form (J v: a loop's or a coupling's rate, a wheel's
// slip), the positions' share when the rates' is the larger: Bullet's rows leave a rate error its ERP
// never sees (the Robotiq 2F-85's gear row: 0.25 rad/s against 4e-3 of positions).
std::string ratesApart(const ModelRun& r, const model_file::LoadedModel& m) {
  if (m.contacts.empty() || !ratesDominate(r.residual, r.position_residual)) return "";
  return " (the positions' rows, stops' and contacts' depths " + fmt(r.position_residual) + "; the rest the rows' velocity form J v: a loop's or a coupling's rate, a wheel's slip)";
}

std::string report(const ModelRun& r, const std::string& engine, const model_file::LoadedModel& m, const ModelArgs& args) {
  std::ostringstream o;
  const bool driven = !args.torques.empty() || !m.actuators.empty();
  std::string how = args.torques.empty() ? "" : "constant torques (" + shownLine(join(args.torques, ", ")) + ")";
  if (!m.actuators.empty()) how += (how.empty() ? "" : " and ") + shownLine(model_file::describeControls(m));
  o << (how.empty() ? std::string("passive run, ") : "run with " + how + ", ") << engine << ", dt " << fmt(args.dt) << " s, " << fmt(args.duration)
    << " s " << (m.key.empty() ? std::string("from q0 at rest") : "from keyframe " + nameShown(m.key)) << "\n"
    << "  " << (m.contacts.empty() ? "closure residual" : "constraint residual (closures, couplings, no-slip rows, contact and joint-stop depth)") << " max |φ|∞ "
    << fmt(r.residual) << ratesApart(r, m) << "\n" << mujocoClosure(m, r)
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
      const bool coupling = c.coupling();  // no gap column
      for (std::size_t row = 0; row < t.rows() && !coupling; ++row)
        extreme = c.kind == "rolling" ? std::max(extreme, std::abs(t.at(row, "slip_" + n))) : std::min(extreme, t.at(row, "gap_" + n));
      if (c.kind == "joint_limit")
        o << "  limit " << nameShown(c.name) << ": min gap " << fmt(extreme) << "; at the end f_normal " << fmt(t.at(last, "f_" + n + "_normal")) << "\n";
      else if (coupling)
        o << "  coupling " << nameShown(c.name) << ": at the end f " << fmt(t.at(last, "f_" + n)) << "\n";
      else if (c.kind == "rolling")
        o << "  rolling " << nameShown(c.name) << ": max slip speed " << fmt(extreme) << " m/s; at the end f_long " << fmt(t.at(last, "f_" + n + "_long"))
          << ", f_lat " << fmt(t.at(last, "f_" + n + "_lat")) << ", f_normal " << fmt(t.at(last, "f_" + n + "_normal")) << " N\n";
      else
        o << "  contact " << nameShown(c.name) << ": min gap " << fmt(extreme) << " m; at the end f_normal " << fmt(t.at(last, "f_" + n + "_normal"))
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
    o << "  the run stopped at t = " << fmt(double(r.trace.rows() - 1) * args.dt) << " s: "
      << (r.stopped.empty() ? "the projection failed or the state left the finite numbers" : shownLine(r.stopped)) << "\n";
  return o.str();
}

// --export: the description, read back before it is written (every field must come back to the same
// text: the same bits), then written whole (file_write.h). 0, or 2 after one line on stderr.
int exportDescription(const model_file::LoadedModel& m, const std::string& path) {
  std::string text;
  try {
    text = descriptionText(m);
    model_file::LoadedModel back = readDescriptionText(text, path);
    back.file = m.file;  // (the source's name the description records)
    if (descriptionText(back) != text)
      throw std::runtime_error("the description does not read back to the same numbers (a dynlab bug: please report it)");
    writeFileChecked(path, text);
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s: --export %s: %s\n", nameShown(m.file).c_str(), nameShown(path).c_str(), shownLine(e.what()).c_str());
    return 2;
  }
  std::printf("wrote %s: dynlab's description of %s (%d tree bodies, %zu constraints, %zu geoms; format version %d)\n", nameShown(path).c_str(),
              nameShown(m.file).c_str(), m.mechanism.tree.dof(), m.mechanism.constraints.size(), m.drawing.geoms.size(), kDescriptionVersion);
  return 0;
}

// The step the run takes: --dt, else the file's own <option timestep> within --dt's bounds; 0 after
// one line on stderr.
double runStep(const ModelArgs& args, const model_file::LoadedModel& m) {
  if (args.dt > 0) return args.dt;
  if (m.timestep >= kMinDt && m.timestep <= kMaxDt) return m.timestep;
  std::fprintf(stderr, "error: %s: <option timestep>: %s s, outside the steps dynlab runs a model file at ([%g, %g] s); pass --dt\n",
               nameShown(m.file).c_str(), exactNumber(m.timestep).c_str(), kMinDt, kMaxDt);
  return 0;
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
  command_->add_option("--dt", a.dt, "Fixed step (s, RK4 + projection; default: the file's <option timestep>)")->check(CLI::Range(kMinDt, kMaxDt));
  command_->add_option("--out", a.out, "Output directory (default: out/model/FILE's stem)");
  command_->add_option("--engine", a.engine, "Which engine(s) to run (default: both)")->check(CLI::IsMember({"hand", "bullet", "both"}));
  command_->add_option("--torque", a.torques, "A constant joint torque JOINT=VALUE (N·m; N on a slide), repeatable (default: passive)")
      ->allow_extra_args(false);
  command_->add_option("--loops", a.loops, "Loop closures beside the file (JSON; default: STEM.loops.json beside FILE when it exists)");
  addModelFileOptions(command_, a.files);
  command_->add_option("--export", a.export_to, "Write dynlab's own description of the file to DESC.json (read without MuJoCo, the "
                                               "same runs bit for bit: docs/model_descriptions.md) and run nothing");
  command_->add_flag("--video", a.video, "Write video.mp4 of the run drawn from the file's geoms (H.264, 30 fps; the Bullet run as a ghost)");
  command_->add_flag("--frames", a.frames, "Write frames/NNNNN.png (30 fps)");
}

void addModelFileOptions(CLI::App* command, ModelFileFlags& flags) {
  command->add_flag("--ignore-contacts", flags.ignore_contacts, "A model file: leave out the note that its geoms collide in MuJoCo but not "
                                                                "here (they load either way: dynlab has no geom-geom contact)");
  command->add_option("--key", flags.key, "A model file: start from its keyframe NAME (qpos, qvel and the actuators' ctrl; default: qpos0 "
                                          "at rest, controls 0)");
  command->add_option("--package-path", flags.package_paths, "A model file: a folder holding the packages its package://NAME/… paths name "
                                                            "(DIR/NAME, or DIR itself), repeatable; searched before the folders above "
                                                            "the file and ROS_PACKAGE_PATH")
      ->allow_extra_args(false);
}

int refuseModelFileFlags(const std::string& lab, const ModelFileFlags& flags) {
  if (!flags.ignore_contacts && flags.package_paths.empty() && flags.key.empty()) return 0;
  std::fprintf(stderr, "error: <command line>: %s: for a model file (.xml, .urdf); %s is a lab\n",
               flags.ignore_contacts ? "--ignore-contacts" : !flags.key.empty() ? "--key" : "--package-path", nameShown(lab).c_str());
  return 2;
}

int runModelFile(const RunArgs& r) {
  for (const auto& [given, option] : {std::pair{!r.config.empty(), "--config"}, {!r.gains.empty(), "--gains"}, {!r.scenario.empty(), "--scenario"}})
    if (given) {
      std::fprintf(stderr, "error: <command line>: %s: a model file (%s) runs passive, without a lab's config, gains or scenario\n", option,
                   nameShown(r.lab).c_str());
      return 2;
    }
  ModelArgs a{.file = r.lab, .out = r.out, .engine = r.engine, .loops = r.loops, .files = r.model_files,
              .video = r.video, .frames = r.frames, .torques = r.torques, .export_to = ""};
  if (r.dt) {
    if (!(*r.dt >= kMinDt && *r.dt <= kMaxDt)) {
      std::fprintf(stderr, "error: <command line>: --dt: expected a step in [%g, %g] s for a model file, got %s\n", kMinDt, kMaxDt,
                   exactNumber(*r.dt).c_str());
      return 2;
    }
    a.dt = *r.dt;
  }
  if (r.duration) {
    if (!(*r.duration > 0 && *r.duration <= 600)) {
      std::fprintf(stderr, "error: <command line>: --duration: expected a time in (0, 600] s for a model file, got %s\n", exactNumber(*r.duration).c_str());
      return 2;
    }
    a.duration = *r.duration;
  }
  return model(a);
}

int model(const ModelArgs& asked) {
  // A trace row per step and the frames drawn: the bound every run has (labs/settings.h), before anything runs.
  const auto refuse = [](const char* option, const std::string& problem) {
    std::fprintf(stderr, "error: <command line>: %s: %s\n", option, problem.c_str());
    return 2;
  };
  ModelArgs args = asked;
  if (args.dt > 0)
    if (const std::string problem = runBoundProblem(args.dt, args.duration); !problem.empty()) return refuse("--duration", problem);
  if (args.video || args.frames)
    if (const std::string problem = frameBoundProblem(args.duration, 30); !problem.empty())
      return refuse(args.video ? "--video" : "--frames", problem);
  model_file::LoadedModel m;
  try {
    model_file::LoadOptions options;
    options.ignore_contacts = args.files.ignore_contacts;
    options.package_paths = args.files.package_paths;
    options.key = args.files.key;
    m = loadWithLoops(args.file, args.loops, options);
  } catch (const model_file::ModelFileError& e) {
    std::fprintf(stderr, "error: %s\n", shownLine(e.what()).c_str());
    return 2;
  }
  if (!args.export_to.empty()) return exportDescription(m, args.export_to);
  if ((args.dt = runStep(args, m)) == 0) return 2;
  if (const std::string problem = runBoundProblem(args.dt, args.duration, modelColumns(m).columns.size()); !problem.empty())
    return refuse("--duration", problem);
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
                   "N·m (N on a slide) within ±1e4\n", nameShown(t).c_str(), nameShown(m.file).c_str(), shownLine(join(names)).c_str());
      return 2;
    }
    given[std::size_t(it - names.begin())] = true;
    tau[it - names.begin()] = value;
  }
  ConstrainedMechanism<Spatial> mech(m.mechanism);
  // A description holds no MuJoCo model to check against.
  std::string text = describe(m) + (m.compiled ? crossCheck(m, mech) : "  against MuJoCo: not checked (a description: no MuJoCo model in it)\n");
  text += stepNotes(m, mech, args.dt);
  const bool hand = args.engine != "bullet", bullet = args.engine != "hand";
  ModelRun h, b;
  if (hand) h = m.contacts.empty() ? runHand(m, mech, args.dt, args.duration, tau) : runHandElements(m, mech, args.dt, args.duration, tau);
  if (bullet) {
    try {
      b = runBullet(m, mech, args.dt, args.duration, tau);
    } catch (const std::exception& e) {  // a description the Bullet builder cannot model
      std::fprintf(stderr, "error: %s: Bullet: %s\n", nameShown(m.file).c_str(), shownLine(e.what()).c_str());
      return 2;
    }
  }
  if (hand) text += report(h, "hand engine (" + h.summary + "): RK4 + projection", m, args);
  if (bullet) text += report(b, b.summary + ", semi-implicit Euler", m, args);
  if (hand && bullet) {
    double dq = 0;
    const int n = int(m.q0.size());  // every coordinate (a ball's quaternion too)
    for (std::size_t r = 0; r < std::min(h.trace.rows(), b.trace.rows()); ++r)
      for (int i = 0; i < n; ++i) dq = std::max(dq, std::abs(h.trace.at(r, 1 + i) - b.trace.at(r, 1 + i)));
    text += "agreement: max |q_hand − q_bullet|∞ " + fmt(dq) + " (Bullet's step is first order)\n";
  }
  const bool ok = (!hand || h.ok) && (!bullet || b.ok);
  const std::filesystem::path out = args.out.empty() ? std::filesystem::path("out/model") / std::filesystem::path(args.file).stem() : std::filesystem::path(args.out);
  text += "wrote " + nameShown(out.string()) + "/" + (hand ? "trace.csv " : "") + (bullet ? "trace_bullet.csv " : "") + "summary.txt";
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
      const std::vector<Eigen::Vector3d> points = runPoints(picture, n, shown, ghost);
      const std::string title = std::filesystem::path(m.file).filename().string();
      const std::string engines = hand ? (ghost ? "hand; Bullet ghost" : "hand") : "Bullet";
      const DrawRow draw = [&](std::size_t row, Scene& scene, Overlay* panel) {
        const VecN q = traceQ(shown, row, n);
        VecN gq;
        if (ghost && row < ghost->rows()) gq = traceQ(*ghost, row, n);
        picture.scene(q, gq.size() ? &gq : nullptr, box, scene, points);
        if (panel) modelOverlay(termName(title), engines, shown, row, args.dt, ghost, *panel);
      };
      // Drawn in a child (app/cli/isolated_draw.h): llvmpipe ends the process when memory runs out.
      const int frames = int(frameRows(shown, args.dt, 30).size());
      drawIsolated(args.video ? "video.mp4" : "the frames",
                   [&] { renderFrames(draw, shown, args.dt, {640, 480, 30, args.video, args.frames}, staging.path("")); });
      text += "  " + std::to_string(frames) + " frames at 30 per second of simulated time, 640x480\n";
    }
    staging.commit();
  } catch (const std::bad_alloc&) {
    throw;  // main's one line for it (app/cli/main.cpp)
  } catch (const std::exception& e) {
    std::fputs(text.c_str(), stdout);
    std::fprintf(stderr, "error: %s\n", shownLine(e.what()).c_str());
    return 1;
  }
  std::fputs(text.c_str(), stdout);
  return ok ? 0 : 1;
}

}  // namespace dyn::app
