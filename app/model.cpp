// dynlab model FILE: see model.h.
#include "app/model.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <sstream>

#include "app/output.h"
#include "labs/trace.h"
#include "labs/utf8.h"
#include "physics/constrained_mechanism.h"
#include "physics/model_file/model_file.h"

namespace dyn::app {
namespace {

// A name from the file as a CSV column part: letters, digits, '_', '-', '.'; anything else '_'.
std::string columnName(const std::string& name) {
  std::string out;
  for (char c : name) out += std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' ? c : '_';
  return out.empty() ? "_" : out;
}

std::string fmt(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", x);
  return b;
}

std::string join(const std::vector<std::string>& v, const char* sep = " ") {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? sep : "") + v[i];
  return s;
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
  for (const auto& n : m.notes) o << "  note: " << n << "\n";
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

// The power the joints' damping and friction take out of the mechanism (≥ 0).
double frictionPower(const MechanismModel<Spatial>& d, const VecN& v) {
  double p = 0;
  for (std::size_t i = 0; i < d.joints.size(); ++i) {
    const JointProperties& j = d.joints[i];
    const double w = v[Eigen::Index(i)], width = j.coulomb_width > 0 ? j.coulomb_width : 1e-12;
    p += j.viscous * w * w + j.coulomb * std::clamp(w / width, -1.0, 1.0) * w;
  }
  return p;
}

}  // namespace

ModelCommand::ModelCommand(CLI::App& cli) {
  ModelArgs& a = args_;
  command_ = cli.add_subcommand("model", "Load a mechanism from an MJCF or URDF file, print what dynlab read (bodies, joints, "
                                         "loop closures and their rows, freedom), check M and h against MuJoCo's, run it "
                                         "passive with the hand engine: closure residual, energy balance, OUT/trace.csv");
  command_->add_option("FILE", a.file, "MJCF (.xml) or URDF file (assets/models/ has examples)")->required();
  command_->add_option("--duration", a.duration, "Simulated time (s, default 2)")->check(CLI::Range(0.0, 600.0));
  command_->add_option("--dt", a.dt, "Fixed step (s, default 0.001; RK4 + projection)")->check(CLI::Range(1e-5, 1e-2));
  command_->add_option("--out", a.out, "Output directory (default: out/model/FILE's stem)");
  command_->add_flag("--ignore-contacts", a.ignore_contacts, "Load a file whose geoms may collide, ignoring contacts (noted)");
}

int model(const ModelArgs& args) {
  model_file::LoadedModel m;
  try {
    model_file::LoadOptions options;
    options.ignore_contacts = args.ignore_contacts;
    m = model_file::load(args.file, options);
  } catch (const model_file::ModelFileError& e) {
    std::fprintf(stderr, "error: %s\n", utf8Quotable(e.what()).c_str());
    return 2;
  }
  ConstrainedMechanism<Spatial> mech(m.mechanism);
  std::string text = describe(m) + crossCheck(m, mech);

  // The passive run from the file's pose at rest: RK4, positions and velocities projected each step.
  StepOptions o;
  o.dt = args.dt;
  const int steps = int(std::lround(args.duration / args.dt)), n = mech.n();
  VecN q = m.q0, v = VecN::Zero(n);
  const VecN tau = VecN::Zero(n);
  Trace trace;
  trace.columns.push_back("t");
  for (const auto& j : m.joints) trace.columns.push_back("q_" + columnName(j.name));
  for (const auto& j : m.joints) trace.columns.push_back("v_" + columnName(j.name));
  trace.columns.insert(trace.columns.end(), {"energy", "work", "constraint_residual"});
  for (const auto& c : m.closures)
    for (const auto& r : c.kept) trace.columns.push_back("f_" + columnName(c.name) + "_" + r);
  const double e0 = mech.energy(q, v);
  double work = 0, residual = 0, balance = 0, kinetic = 0, power = frictionPower(m.mechanism, v);
  bool ok = true;
  for (int k = 0; k <= steps && ok; ++k) {
    // The row at t: state, energy, the friction's work so far (trapezoid), |φ|∞ and each closure's η.
    const auto s = mech.solve(q, v, tau);
    const double e = mech.energy(q, v), phi = mech.residual(q);
    std::vector<double> row{k * args.dt};
    row.insert(row.end(), q.data(), q.data() + n);
    row.insert(row.end(), v.data(), v.data() + n);
    row.insert(row.end(), {e, work, phi});
    row.insert(row.end(), s.eta.data(), s.eta.data() + s.eta.size());
    trace.append(row);
    residual = std::max(residual, phi);
    balance = std::max(balance, std::abs(e - e0 - work));
    kinetic = std::max(kinetic, mech.kineticEnergy(q, v));
    if (k == steps) break;
    ok = step(mech, o, tau, q, v) && q.allFinite() && v.allFinite();
    const double p = frictionPower(m.mechanism, v);
    work -= 0.5 * (power + p) * args.dt;
    power = p;
  }
  std::ostringstream run;
  run << "passive run: RK4 + projection, dt " << fmt(args.dt) << " s, " << fmt(args.duration) << " s from q0 at rest\n"
      << "  closure residual max |φ|∞ " << fmt(residual) << "\n"
      << "  energy E0 " << fmt(e0) << " J, max |E − E0 − W_friction| " << fmt(balance) << " J (kinetic energy up to "
      << fmt(kinetic) << " J" << (m.mechanism.joints.empty() ? "" : "; W_friction by the trapezoid rule") << ")\n";
  if (!ok) run << "  the run stopped at t = " << fmt(double(trace.rows() - 1) * args.dt) << " s: the projection failed or the state left the finite numbers\n";
  text += run.str();

  const std::filesystem::path out = args.out.empty() ? std::filesystem::path("out/model") / std::filesystem::path(args.file).stem() : std::filesystem::path(args.out);
  text += "  wrote " + (out / "trace.csv").string() + " (" + std::to_string(trace.rows()) + " rows) and summary.txt\n";
  try {
    Staging staging(out);
    staging.owns({"trace.csv", "summary.txt"});
    staging.write("trace.csv", trace.csv());
    staging.write("summary.txt", text);
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
