// The generic data-defined lab: see data_lab.h. Both engines run the plant loaded from the model file
// (the hand engine through the generic mechanism, Bullet through its builder); the controller of the
// library drives the actuated joints from its own model.
#include "labs/generic/data_lab.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <regex>

#include "labs/mechanism_simulation.h"
#include "labs/numbers.h"
#include "physics/det/det.h"
#include "physics/model_file/closure_rows.h"

namespace dyn::generic {
namespace {

namespace fs = std::filesystem;
using Mech = ConstrainedMechanism<Spatial>;

// The lab's part of a run: the reference path, the controller, the trace row.
class Hooks final : public StepHooks {
 public:
  explicit Hooks(const DataSettings& s)
      : s_(s), ctrl_(s.controller, s.model, s.actuated, s.tool, s.q0, s.step.dt), every_(*s.plant) {
    if (s_.path) s_.path->at(0.0, ref_.x, ref_.xd, ref_.xdd), ref_.joint = s_.path->joint();
    if (!s.passive.empty()) loads_mech_ = std::make_unique<Mech>(s.plant->mechanism);
  }
  VecN torque(double t, const VecN& q, const VecN& v) override {
    if (s_.path) s_.path->at(t, ref_.x, ref_.xd, ref_.xdd), ref_.joint = s_.path->joint();
    // The force sensor's truth: the push on the tool at t, in the task's axes.
    if (s_.push && !s_.tool.axes.empty()) {
      ref_.force.resize(Eigen::Index(s_.tool.axes.size()));
      for (std::size_t i = 0; i < s_.tool.axes.size(); ++i) ref_.force[Eigen::Index(i)] = push(t)[s_.tool.axes[i]];
    }
    return ctrl_.torque(t, q, v, ref_);
  }
  void row(const StepRecord& r, std::vector<double>& out) override {
    out.clear();
    out.push_back(r.t);
    out.insert(out.end(), r.q.data(), r.q.data() + r.q.size());
    out.insert(out.end(), r.v.data(), r.v.data() + r.v.size());
    const VecN& u = ctrl_.command();
    out.insert(out.end(), u.data(), u.data() + u.size());
    out.push_back(ctrl_.saturated() ? 1.0 : 0.0);
    // The tool at the plant's state (the controller's model has the plant's geometry: payloads change
    // only inertias).
    VecN x;
    if (!s_.tool.axes.empty()) {
      ctrl_.taskPosition(r.q, x);
      for (int i = 0; i < x.size(); ++i) out.push_back(x[i]);
    }
    // The errors: of the joint path in the actuated coordinates, or of the task path.
    if (ref_.joint) {
      for (std::size_t j = 0; j < s_.actuated.size(); ++j) out.push_back(ref_.x[Eigen::Index(j)]);
      for (std::size_t j = 0; j < s_.actuated.size(); ++j) out.push_back(ref_.x[Eigen::Index(j)] - r.q[s_.actuated[j]]);
    } else if (!s_.tool.axes.empty()) {
      for (int i = 0; i < x.size(); ++i) out.push_back(ref_.x[i]);
      for (int i = 0; i < x.size(); ++i) out.push_back(ref_.x[i] - x[i]);
    }
    // The environment's push on the tool (N, world axes), as the plant feels it over this step.
    if (s_.push)
      for (int i = 0; i < 3; ++i) out.push_back(push(r.t)[3 + i]);
    // The target impedance's response about the reference, and the tool's deviation from it.
    if (s_.target.k > 0) {
      advanceTarget(r.t);
      for (int i = 0; i < x.size(); ++i) out.push_back(ref_.x[i] + xi_[i]);
      for (int i = 0; i < x.size(); ++i) out.push_back(x[i] - ref_.x[i] - xi_[i]);
    }
    // |φ| over every closure row, the ones the description drops too (closure_rows.h).
    out.push_back(r.energy), out.push_back(r.work), out.push_back(std::max(r.residual, every_.residual(r.q)));
    const auto& closures = s_.plant->closures;
    for (std::size_t c = 0; c < closures.size(); ++c)
      for (const auto& row : closures[c].kept) out.push_back(r.forces[c][model_file::rowIndex(row)]);
    // The force each passive joint's bearing carries (its parent on it, world axes): the plant's solve
    // at the row's state (ConstrainedMechanism::jointLoads), for either engine's row.
    if (loads_mech_) {
      const auto sol = loads_mech_->solve(r.q, r.v, r.tau);
      loads_mech_->jointLoads(r.q, r.v, sol, loads_);
      for (const int j : s_.passive)
        for (int a = 3; a < 6; ++a) out.push_back(loads_[std::size_t(j)][a]);
    }
  }

 private:
  Spatial::Vec push(double t) const { return s_.push ? Spatial::Vec(s_.push->profile().at(t) * s_.push->value()) : Spatial::Vec::Zero(); }
  // ξ'' = (F − D ξ' − K ξ)/M per task axis, F the push along it: RK4 from the last row's time to t in
  // four substeps (the push's profile is right-continuous, on at a step boundary as the engines see it).
  void advanceTarget(double t) {
    const int d = int(s_.tool.axes.size());
    if (xi_.size() != d) xi_ = VecN::Zero(d), xid_ = VecN::Zero(d), t_target_ = t;
    const double K = s_.target.k, M = s_.target.m, D = 2 * s_.target.zeta * std::sqrt(K * M);
    const int sub = 4;
    const double h = (t - t_target_) / sub;
    for (int k = 0; k < sub && h > 0; ++k) {
      const double t0 = t_target_ + k * h;
      for (int i = 0; i < d; ++i) {
        const int a = s_.tool.axes[std::size_t(i)];
        auto acc = [&](double tt, double p, double v) { return (push(tt)[a] - D * v - K * p) / M; };
        const double p = xi_[i], v = xid_[i];
        const double k1p = v, k1v = acc(t0, p, v);
        const double k2p = v + h / 2 * k1v, k2v = acc(t0 + h / 2, p + h / 2 * k1p, v + h / 2 * k1v);
        const double k3p = v + h / 2 * k2v, k3v = acc(t0 + h / 2, p + h / 2 * k2p, v + h / 2 * k2v);
        const double k4p = v + h * k3v, k4v = acc(t0 + h, p + h * k3p, v + h * k3v);
        xi_[i] = p + h / 6 * (k1p + 2 * k2p + 2 * k3p + k4p);
        xid_[i] = v + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
      }
    }
    t_target_ = t;
  }

  const DataSettings& s_;
  controllers::Controller ctrl_;
  controllers::Reference ref_;
  std::unique_ptr<Mech> loads_mech_;  // the plant, for the passive joints' loads
  model_file::EveryClosureRow every_;  // the plant's closures, every row
  std::vector<Spatial::Vec> loads_;
  VecN xi_, xid_;  // the target's ξ, ξ' at t_target_
  double t_target_ = 0;
};

// Actuated joint j's effort unit: a slide's actuator pushes (N), a hinge's turns (N·m).
const char* effortUnit(const DataSettings& s, std::size_t j) {
  return s.plant->joints[std::size_t(s.actuated[j])].type == "slide" ? "N" : "N·m";
}

const Color kForce{0.85f, 0.15f, 0.10f, 1.0f}, kTool{0.95f, 0.75f, 0.15f, 1.0f};  // as the pen lab's arrow and pen

std::string fmt(const char* f, double x) {
  char b[48];
  std::snprintf(b, sizeof b, f, x);
  return b;
}

}  // namespace

DataLab::DataLab(DataSettings s)
    : SettingsLab(std::move(s)), picture_(*s_.plant), kinematics_(std::make_unique<Mech>(s_.plant->mechanism)) {
  columns_ = s_.columns;
  // max_dq spans every coordinate: rad on hinges, m on slides.
  bool hinge = false, slide = false;
  for (const auto& j : s_.plant->joints) (j.type == "slide" ? slide : hinge) = true;
  agreement_units_ = {{"max_dq", hinge && slide ? "rad, m" : slide ? "m" : "rad"}, {"max_dx", "m"}, {"max_df", "N, N·m"}};
  // The push does work by design: the passive check runs without it (E itself must then stay put).
  passive_ = {s_.passive_tolerance, 0, s_.push ? json{{"environment", nullptr}} : json::object()};
}

std::string DataLab::unit(const std::string& c) const {
  auto starts = [&](const char* p) { return c.rfind(p, 0) == 0; };
  if (c == "t") return "s";
  if (c == "energy" || c == "work") return "J";
  if (c == "constraint_residual") return "m";
  if (s_.push && starts("push_")) return "N";
  if (s_.target.k > 0 && (starts("target_") || starts("dev_"))) return "m";
  // A joint path's reference and error columns carry their joint's unit (below).
  const bool joint_path = s_.path && s_.path->joint();
  if (starts("tool_") || (!joint_path && (starts("ref_") || starts("e_")))) return "m";
  for (std::size_t j = 0; j < s_.actuated.size(); ++j)
    if (c == "tau_" + columnName(s_.actuated_names[j])) return effortUnit(s_, j);
  if (starts("load_")) return "N";
  if (starts("f_")) {
    const std::string row = c.substr(c.rfind('_') + 1);
    return row[0] == 'w' ? "N·m" : "N";
  }
  for (std::size_t i = 0; i < s_.plant->joints.size(); ++i) {
    const bool slide = s_.plant->joints[i].type == "slide";
    const std::string j = columnName(s_.plant->joints[i].name);
    if (c == s_.columns[1 + i] || c == "ref_" + j || c == "e_" + j) return slide ? "m" : "rad";
    if (c == s_.columns[1 + s_.plant->joints.size() + i]) return slide ? "m/s" : "rad/s";
  }
  return {};
}

// A run on mechanism type M (the generic mechanism at fixed or dynamic sizes).
template <class M>
std::unique_ptr<Simulation> runOn(const DataSettings& s, Engine engine) {
  auto mech = std::make_unique<M>(s.plant->mechanism);
  const VecN v0 = VecN::Zero(mech->n());
  return simulateMechanism(engine, std::move(mech), s.step, s.q0, v0, std::make_unique<Hooks>(s), s.columns, s.duration);
}

std::unique_ptr<Simulation> DataLab::simulate(Engine engine) const {
  // The shapes of the shipped loops at fixed sizes (instantiated in physics/model_file/hand_engine.cpp)
  // and a 6-joint open chain's (mechanism.cpp), as the C++ labs fix theirs: every loop of the step
  // unrolled. Any other shape: dynamic sizes.
  const auto& m = s_.plant->mechanism;
  const int n = m.treeDof(), r = m.rows();
  if (m.payloads.empty()) {
    if (n == 4 && r == 2) return runOn<ConstrainedMechanism<Spatial, 4, 2, 0>>(s_, engine);
    if (n == 3 && r == 2) return runOn<ConstrainedMechanism<Spatial, 3, 2, 0>>(s_, engine);
    if (n == 4 && r == 3) return runOn<ConstrainedMechanism<Spatial, 4, 3, 0>>(s_, engine);
    if (n == 6 && r == 0) return runOn<ConstrainedMechanism<Spatial, 6, 0, 0>>(s_, engine);  // mechanism.cpp
  }
  return runOn<Mech>(s_, engine);
}

MujocoTwin DataLab::mujocoTwin() const {
  MujocoTwin t;
  if (!s_.plant->compiled) return t;  // a description without a MuJoCo model
  t.file = s_.plant->file;
  t.loaded = s_.plant;
  t.q = s_.q0, t.v = VecN::Zero(s_.plant->mechanism.treeDof());
  return t;
}

json DataLab::metrics(const Trace& tr) const {
  json out = json::object();
  for (const auto& [name, spec] : s_.metrics) out[name] = evaluate(spec, tr);
  double drift = 0, residual = 0;
  const auto energy = tr.col("energy"), work = tr.col("work"), residual_col = tr.col("constraint_residual");
  const double e0 = tr.rows() ? tr.at(0, "energy") : 0;
  for (std::size_t r = 0; r < tr.rows(); ++r) {
    drift = std::max(drift, std::abs(energy[r] - e0 - work[r]));
    residual = std::max(residual, residual_col[r]);
  }
  out["energy_drift"] = drift;
  out["max_constraint_residual"] = residual;
  out["steps"] = tr.steps();
  return out;
}

json DataLab::differences(const Trace& a, const Trace& b, std::size_t n) const {
  const std::size_t joints = s_.plant->joints.size();
  double dq = 0, dx = 0, df = 0;
  for (std::size_t r = 0; r < n; ++r) {
    for (std::size_t i = 0; i < joints; ++i) dq = std::max(dq, std::abs(a.at(r, int(1 + i)) - b.at(r, int(1 + i))));
    for (const auto& ax : s_.axis_names) dx = std::max(dx, std::abs(a.at(r, "tool_" + ax) - b.at(r, "tool_" + ax)));
    for (std::size_t c = 0; c < s_.columns.size(); ++c)
      if (s_.columns[c].rfind("f_", 0) == 0) df = std::max(df, std::abs(a.at(r, int(c)) - b.at(r, int(c))));
  }
  return {{"max_dq", dq}, {"max_dx", dx}, {"max_df", df}};
}

void DataLab::scene(const Trace& tr, std::size_t row, const Trace* ghost, Scene& out) const {
  const int n = int(s_.plant->joints.size());
  // The run's bounds frame every picture of it (cached: a video asks for every row).
  if (bounds_of_ != tr.data.data() || bounds_rows_ != tr.rows()) {
    bounds_ = runBounds(picture_, n, tr, ghost);
    points_ = runPoints(picture_, n, tr, ghost);
    // The push's arrow: 18 % of the run's size at the push's full value; the camera holds it where
    // the tool starts.
    arrow_ = bounds_.isEmpty() ? 0.0 : 0.18 * bounds_.diagonal().norm();
    tool_ball_ = 0.01 * std::max(bounds_.isEmpty() ? 0.0 : bounds_.diagonal().norm(), 0.05);
    if (s_.push && arrow_ > 0 && tr.rows() > 0 && s_.push->value().tail<3>().norm() > 0) {
      const Eigen::Vector3d dir = s_.push->value().tail<3>().normalized();
      const Eigen::Vector3d tail = kinematics_->pointPosition(s_.tool.link, s_.tool.point, traceQ(tr, 0, n)) - 1.08 * arrow_ * dir;
      bounds_.extend(tail - Eigen::Vector3d::Constant(0.04 * arrow_));
      bounds_.extend(tail + Eigen::Vector3d::Constant(0.04 * arrow_));
      if (!points_.empty()) points_.push_back(tail);
    }
    bounds_of_ = tr.data.data(), bounds_rows_ = tr.rows();
  }
  const VecN q = traceQ(tr, row, n);
  VecN gq;
  if (ghost && row < ghost->rows()) gq = traceQ(*ghost, row, n);
  picture_.scene(q, gq.size() ? &gq : nullptr, bounds_, out, points_);
  picture_.stage(out);  // a spatial arm stands on a floor, on a pedestal
  // A tool given as a body's point: a stick from the body's joint to it, as a pen is drawn.
  if (s_.tool_on_body) {
    const Eigen::Vector3d from = kinematics_->pointPosition(s_.tool.link, Eigen::Vector3d::Zero(), q);
    const Eigen::Vector3d tip = kinematics_->pointPosition(s_.tool.link, s_.tool.point, q);
    out.capsules.push_back({from, tip, tool_ball_ / 1.6, kTool});
    out.spheres.push_back({tip, tool_ball_, kTool});
  }
  // The push on the tool while it acts (the plant's, this row): an arrow ending just short of the tool.
  if (s_.push && arrow_ > 0) {
    const Eigen::Vector3d F(tr.at(row, "push_x"), tr.at(row, "push_y"), tr.at(row, "push_z"));
    const double full = s_.push->value().tail<3>().norm();
    if (F.norm() > 1e-9 && full > 0) {
      const Eigen::Vector3d tool = kinematics_->pointPosition(s_.tool.link, s_.tool.point, q);
      const Eigen::Vector3d v = F * (arrow_ / full), gap = F.normalized() * tool_ball_;
      out.arrows.push_back({tool - gap - v, v, 0.04 * arrow_, kForce});
    }
  }
  // The path: the reference so far as a thin line, the tool's target as a small ball; a joint path's
  // is where the tool would be at the reference angles.
  if (s_.path && s_.path->joint() && !s_.tool.axes.empty()) {
    auto reference = [&](std::size_t r) {
      VecN qr = traceQ(tr, r, n);
      for (std::size_t j = 0; j < s_.actuated.size(); ++j) qr[s_.actuated[j]] = tr.at(r, "ref_" + columnName(s_.actuated_names[j]));
      return Eigen::Vector3d(kinematics_->pointPosition(s_.tool.link, s_.tool.point, qr));
    };
    Polyline path;
    const std::size_t stride = std::max<std::size_t>(1, tr.rows() / 400);
    for (std::size_t r = 0; r < tr.rows(); r += stride) path.points.push_back(reference(r));
    path.color = {0.85f, 0.2f, 0.2f, 0.8f};
    out.polylines.push_back(path);
    out.spheres.push_back({reference(row), 0.01, {0.85f, 0.2f, 0.2f, 1.0f}});
  } else if (s_.tool.axes.size() >= 2) {
    Polyline path;
    const Eigen::Vector3d p0 = kinematics_->pointPosition(s_.tool.link, s_.tool.point, q);
    const std::size_t stride = std::max<std::size_t>(1, tr.rows() / 400);
    for (std::size_t r = 0; r < tr.rows(); r += stride) {
      Eigen::Vector3d p = p0;
      for (std::size_t i = 0; i < s_.tool.axes.size(); ++i) p[s_.tool.axes[i] - 3] = tr.at(r, "ref_" + s_.axis_names[i]);
      path.points.push_back(p);
    }
    path.color = {0.85f, 0.2f, 0.2f, 0.8f};
    out.polylines.push_back(path);
    Eigen::Vector3d target = p0;
    for (std::size_t i = 0; i < s_.tool.axes.size(); ++i) target[s_.tool.axes[i] - 3] = tr.at(row, "ref_" + s_.axis_names[i]);
    out.spheres.push_back({target, 0.006, {0.85f, 0.2f, 0.2f, 1.0f}});
  }
}

void DataLab::overlay(const Trace& tr, std::size_t row, Overlay& o) const {
  o.title = s_.title.substr(0, s_.title.find(':'));  // "Five-bar: task-space control ..." → "Five-bar"
  if (s_.axis_names.empty() && !s_.path) {
    // No task: the passive model's panel (time, energy and its balance, closure), as `dynlab model` draws it.
    modelOverlay(o.title, "passive (τ = 0)", tr, row, s_.step.dt, nullptr, o);
    return;
  }
  // The tracking error's norm: the task's (mm) or a joint path's (mrad, over the actuated joints).
  std::vector<std::string> errors;
  const bool joint_path = s_.path && s_.path->joint();
  for (const auto& a : joint_path ? s_.actuated_names : s_.axis_names) errors.push_back("e_" + (joint_path ? columnName(a) : a));
  // (A joint path's error is in each joint's unit: mrad on hinges, mm on slides.)
  std::size_t slides = 0;
  for (std::size_t j = 0; j < s_.actuated.size(); ++j) slides += std::string(effortUnit(s_, j)) == "N" ? 1 : 0;
  const std::string unit = !joint_path ? "mm" : slides == 0 ? "mrad" : slides == s_.actuated.size() ? "mm" : "mrad, mm";
  auto norm = [&](std::size_t r) {
    double e = 0;
    for (const auto& c : errors) e += det::pow(tr.at(r, c), 2);
    return 1e3 * std::sqrt(e);
  };
  o.lines = {{"t", fmt("%.3f s", tr.at(row, "t"))}, {"tracking |e|", fmt("%.2f ", norm(row)) + unit}};
  // What is graded: the tool's distance from the target's response (an impedance exercise), else |e|.
  auto off = [&](std::size_t r) {
    double d = 0;
    for (const auto& a : s_.axis_names) d += det::pow(tr.at(r, "dev_" + a), 2);
    return 1e3 * std::sqrt(d);
  };
  // An impedance exercise: the push and the tool's distance from the target's response.
  if (s_.push) {
    const double F = std::sqrt(det::pow(tr.at(row, "push_x"), 2) + det::pow(tr.at(row, "push_y"), 2) + det::pow(tr.at(row, "push_z"), 2));
    o.lines.push_back({"push |F|", fmt("%.1f N", F)});
  }
  if (s_.target.k > 0) o.lines.push_back({"off target", fmt("%.2f mm", off(row))});
  for (std::size_t j = 0; j < s_.actuated.size(); ++j)
    o.lines.push_back({"τ " + s_.actuated_names[j], fmt("%.2f ", tr.at(row, "tau_" + columnName(s_.actuated_names[j]))) + effortUnit(s_, j)});
  if (!s_.plant->closures.empty()) o.lines.push_back({"closure |φ|", fmt("%.1e m", tr.at(row, "constraint_residual"))});
  const bool target = s_.target.k > 0;
  Series err{target ? "|x − x_target| (mm)" : "|e| (" + unit + ")", {}, {0.85f, 0.2f, 0.2f, 1.0f}};
  for (std::size_t r = liveWindowStart(row, 2.0, s_.step.dt); r <= row; ++r) err.values.push_back(float(target ? off(r) : norm(r)));
  o.plots = {err};
}

bool isDataLabFolder(const std::string& folder, const std::string& name) {
  std::error_code ec;
  if (!fs::is_regular_file(folder + "/" + name + ".json", ec)) return false;
  for (const auto& e : fs::recursive_directory_iterator(folder, fs::directory_options::skip_permission_denied, ec)) {
    const auto ext = e.path().extension();
    if (ext == ".cpp" || ext == ".h") return false;
  }
  return !ec;
}

bool registerDataLab(const std::string& folder, std::string* why, const std::string& labs_folder) {
  const std::string name = fs::path(folder).filename().string();
  // A lab's name goes into paths, reports and results.json: the same rule as dynlab new-lab's.
  if (!std::regex_match(name, std::regex("[a-z][a-z0-9_]{0,39}"))) {
    if (why) *why = folder + ": expected a lab folder named with lowercase letters, digits and _, starting with a letter (at most 40)";
    return false;
  }
  if (!isDataLabFolder(folder, name)) {
    if (why) *why = folder + ": expected a folder with " + name + ".json and no .cpp or .h";
    return false;
  }
  // The summary from the JSON's title (the lab itself reports a broken JSON when it is used).
  std::string summary = "data-defined lab (" + name + ".json)";
  try {
    const json j = loadJsonFile(folder + "/" + name + ".json");
    if (j.contains("title") && j["title"].is_string()) summary = j["title"].get<std::string>();
  } catch (const std::exception&) {
  }
  const bool ok = registerLab({name, summary,
                               [name, folder](const JsonView& config) -> std::unique_ptr<Lab> {
                                 return std::make_unique<DataLab>(parseDataSettings(config, name, folder));
                               },
                               folder, labs_folder});
  if (!ok && why) *why = "a lab named " + name + " is registered already";
  return ok;
}

int registerDataLabs(const std::string& root) {
  std::error_code ec;
  std::vector<std::string> folders;
  for (const auto& e : fs::directory_iterator(root, ec))
    if (e.is_directory(ec)) folders.push_back(e.path().string());
  std::sort(folders.begin(), folders.end());
  int n = 0;
  for (const auto& f : folders)
    if (isDataLabFolder(f, fs::path(f).filename().string())) n += registerDataLab(f) ? 1 : 0;
  return n;
}

// Every data lab folder of the lab tree, at start-up (as the C++ labs register themselves).
[[maybe_unused]] const int kRegistered = registerDataLabs(labsRoot());

}  // namespace dyn::generic
