// A data lab's JSON, parsed and checked against its model file: see data_lab.h.
#include <algorithm>
#include <cmath>
#include <filesystem>

#include "labs/generic/data_lab.h"
#include "labs/generic/model_description.h"
#include "labs/generic/reach.h"
#include "labs/settings.h"
#include "physics/closed_chain.h"

namespace dyn::generic {
namespace {

constexpr double kMaxCoordinate = 100, kMaxMass = 1e4, kMaxTorque = 1e5, kMaxForce = 1e5;

Eigen::Vector3d vec3(const JsonView& j) {
  j.size(3, 3);
  return {j.at(0).inRange(-kMaxCoordinate, kMaxCoordinate), j.at(1).inRange(-kMaxCoordinate, kMaxCoordinate),
          j.at(2).inRange(-kMaxCoordinate, kMaxCoordinate)};
}

std::string list(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

// The tree body a file body moves with: the last coordinate of its joints (−1: none).
int linkOf(const model_file::LoadedModel& m, const std::string& body) {
  int link = -1;
  for (std::size_t i = 0; i < m.joints.size(); ++i)
    if (m.joints[i].body == body) link = int(i);
  return link;
}

std::vector<std::string> jointBodies(const model_file::LoadedModel& m) {
  std::vector<std::string> b;
  for (const auto& j : m.joints)
    if (std::find(b.begin(), b.end(), j.body) == b.end()) b.push_back(j.body);
  return b;
}

// A body and a point on it given in world coordinates at the file's pose: the tree body and the point
// in its frame (frames are world-aligned at the file's pose, on their joint's anchor).
std::pair<int, Eigen::Vector3d> bodyPoint(const JsonView& body, const JsonView& at, const model_file::LoadedModel& m,
                                          ConstrainedMechanism<Spatial>& mech) {
  const int link = linkOf(m, body.string());
  if (link < 0) body.fail("expected a body with a joint in the model file (" + list(jointBodies(m)) + ")");
  const Eigen::Vector3d anchor = mech.pointPosition(link, Eigen::Vector3d::Zero(), m.q0);
  return {link, vec3(at) - anchor};
}

// True when `file` (which exists) lies inside `base` once links are followed.
bool inside(const std::filesystem::path& file, const std::filesystem::path& base) {
  std::error_code ec;
  const auto f = std::filesystem::canonical(file, ec), b = std::filesystem::canonical(base, ec);
  if (ec) return false;
  const auto rel = f.lexically_relative(b);
  return !rel.empty() && *rel.begin() != "..";
}

// A model file in the lab's own folder, or else in the dynlab tree (e.g. "assets/models/fourbar.xml",
// so a new exercise, in the tree or outside it, may name one of the shipped models without copying
// it): a relative path without "..", whose file (links followed) lies in the lab's folder or the tree.
std::string checkedModelPath(const JsonView& j, const std::string& folder) {
  const std::string rel = j.string();
  const std::filesystem::path p(rel);
  bool up = false;
  for (const auto& part : p) up = up || part == "..";
  if (rel.empty() || p.is_absolute() || up)
    j.fail("expected a model file in the lab's folder or the dynlab tree (a relative path without \"..\")");
  const auto tree = std::filesystem::path(labsRoot()).parent_path();
  std::error_code ec;
  for (const std::filesystem::path& base : {std::filesystem::path(folder), tree}) {
    if (!std::filesystem::exists(base / rel, ec)) continue;
    if (!inside(base / rel, folder) && !inside(base / rel, tree))
      j.fail("expected a model file inside the lab's folder (" + folder + ") or the dynlab tree (" + tree.string() + "); " +
             (base / rel).string() + " links out of both");
    return (base / rel).string();
  }
  j.fail("expected a model file in the lab's folder (" + folder + ") or the dynlab tree (" + tree.string() + "), not found there");
}

// A metric of actuator efforts alone (tau_<joint> columns, a statistic in their unit) is documented in
// their unit: N·m for hinges, N for slides (the handout prints metric_docs' unit beside its thresholds).
template <class Slide>
void checkEffortUnits(const JsonView& c, const DataSettings& s, const Slide& slide) {
  if (!c.has("metric_docs")) return;
  for (const auto& [name, spec] : s.metrics) {
    if (spec.stat == MetricSpec::Stat::Settling || !c["metric_docs"].has(name) || !c["metric_docs"][name].has("unit")) continue;
    // The efforts' common unit (none: a column that is not an effort, or hinges and slides mixed).
    const char* unit = nullptr;
    bool efforts = !spec.of.empty();
    for (const auto& col : spec.of) {
      const char* u = nullptr;
      for (std::size_t j = 0; j < s.actuated.size(); ++j)
        if (col == "tau_" + columnName(s.actuated_names[j])) u = slide(int(j)) ? "N" : "N·m";
      efforts = efforts && u && (!unit || std::string(u) == unit);
      unit = u;
    }
    const JsonView given = c["metric_docs"][name]["unit"];
    if (efforts && given.string() != unit)
      given.fail("\"" + std::string(unit) + "\": " + name + " is a statistic of " + (std::string(unit) == "N" ? "slide actuators' forces (N)" : "hinge actuators' torques (N·m)"));
  }
}

// The model file, loaded from the lab's folder (or the tree) with the given options; one without free
// payload bodies.
model_file::LoadedModel loadModel(const JsonView& mf, const std::string& folder, const model_file::LoadOptions& options) {
  model_file::LoadedModel file;
  model_file::LoadOptions held = options;
  held.joint_limits = false;  // the controller keeps the arm inside its range: limits noted, not held
  try {
    file = app::loadModelOrDescription(checkedModelPath(mf, folder), held);
  } catch (const model_file::ModelFileError& e) {
    mf.fail(std::string("a model file dynlab reads (") + e.what() + ")");
  }
  if (!file.mechanism.payloads.empty()) mf.fail("a model without free payload bodies");
  // The controllers read a coordinate per joint: a ball's or free joint's quaternion is not one.
  for (const model_file::Joint& j : file.joints)
    if (j.type != "hinge" && j.type != "slide")
      mf.fail("a model file whose joints are hinges and slides (joint '" + j.name + "' is part of a " + j.type +
              " joint; a data lab's controllers read one angle per joint: run the file with `dynlab model` or `dynlab run`)");
  // The controller drives the joints: a servo's law (its bias) would not act here.
  for (const model_file::Actuator& a : file.actuators)
    if (a.bias[0] != 0 || a.bias[1] != 0 || a.bias[2] != 0)
      mf.fail("a model file whose actuators are motors (actuator '" + a.name + "' is a servo, force = gain ctrl + bias; a data lab's "
              "controller drives the joints in /actuated with torques: leave the servo out, or run the file with `dynlab model`)");
  return file;
}

// The plant: point masses the controller does not know, added to the bodies they sit on.
void addPayloads(const JsonView& c, model_file::LoadedModel& file, ConstrainedMechanism<Spatial>& probe) {
  if (!c.has("plant")) return;
  const JsonView p = c["plant"];
  p.onlyKeys({"payloads"});
  const JsonView loads = p["payloads"];
  for (std::size_t i = 0, n = loads.size(0, 16); i < n; ++i) {
    const JsonView l = loads.at(i);
    l.onlyKeys({"body", "at", "mass"});
    const auto [link, point] = bodyPoint(l["body"], l["at"], file, probe);
    const double mass = l["mass"].inRange(0, kMaxMass);
    auto& b = file.mechanism.tree.bodies[std::size_t(link)];
    b.inertia += Spatial::inertia(mass, point, Eigen::Matrix3d::Zero());
    b.central = Spatial::central(b.inertia);
    b.massless = Spatial::massless(b.inertia);
  }
}

// Actuated joints, by name, and their torque limits.
void parseActuated(const JsonView& c, const model_file::LoadedModel& file, DataSettings& s) {
  const JsonView act = c["actuated"];
  std::vector<std::string> joint_names;
  for (const auto& j : file.joints) joint_names.push_back(j.name);
  for (std::size_t i = 0, n = act.size(0, file.joints.size()); i < n; ++i) {
    std::string jn = act.at(i).string();
    // A file's motor names its joint.
    for (const model_file::Actuator& a : file.actuators)
      if (a.name == jn && std::find(joint_names.begin(), joint_names.end(), jn) == joint_names.end()) {
        if (!a.tendon.empty()) act.at(i).fail("expected a joint or a joint's motor (motor '" + a.name + "' pulls tendon '" + a.tendon + "': name its joints)");
        jn = a.joint;
      }
    const auto it = std::find(joint_names.begin(), joint_names.end(), jn);
    if (it == joint_names.end()) act.at(i).fail("expected a joint or motor of the model file (" + list(joint_names) + ")");
    const int index = int(it - joint_names.begin());
    if (std::find(s.actuated.begin(), s.actuated.end(), index) != s.actuated.end()) act.at(i).fail("expected each joint once");
    s.actuated.push_back(index), s.actuated_names.push_back(jn);
  }
  const int m = int(s.actuated.size());
  const JsonView lim = c["torque_limit"];
  lim.size(std::size_t(m), std::size_t(m));
  s.controller.torque_limit.resize(m);
  for (int j = 0; j < m; ++j) s.controller.torque_limit[j] = lim.at(std::size_t(j)).positive(kMaxTorque);
}

// The tool: a closure's point or a body's (none: a passive or open-loop lab without a task).
void parseTool(const JsonView& c, const model_file::LoadedModel& file, ConstrainedMechanism<Spatial>& probe, DataSettings& s) {
  if (!c.has("tool")) {
    if (c.has("trajectory") && !TaskPath::isJointSpace(c["trajectory"]))
      c["trajectory"].fail("no task trajectory without a \"tool\" to follow it (or \"space\": \"joint\")");
    return;
  }
  const JsonView tool = c["tool"];
  tool.onlyKeys({"closure", "body", "at", "axes"});
  if (tool.has("closure")) {
    const std::string cn = tool["closure"].string();
    std::vector<std::string> names;
    for (const auto& cl : file.closures) names.push_back(cl.name);
    const auto it = std::find(names.begin(), names.end(), cn);
    if (it == names.end()) tool["closure"].fail("expected a closure of the model file (" + list(names) + ")");
    const auto& cl = file.closures[std::size_t(it - names.begin())];
    if (cl.link1 < 0) tool["closure"].fail("expected a closure whose first body moves");
    s.tool.link = cl.link1, s.tool.point = cl.point1;
  } else {
    std::tie(s.tool.link, s.tool.point) = bodyPoint(tool["body"], tool["at"], file, probe);
    s.tool_on_body = true;
  }
  const JsonView axes = tool["axes"];
  for (std::size_t i = 0, n = axes.size(1, 3); i < n; ++i) {
    const std::string a = axes.at(i).oneOf({"x", "y", "z"});
    if (std::find(s.axis_names.begin(), s.axis_names.end(), a) != s.axis_names.end()) axes.at(i).fail("each axis once");
    s.tool.axes.push_back(3 + (a[0] - 'x'));
    s.axis_names.push_back(a);
  }
}

// The environment: a push on the tool, the plant's only (the controller's model is copied before).
void parseEnvironment(const JsonView& c, model_file::LoadedModel& file, DataSettings& s) {
  if (!c.has("environment")) return;
  const JsonView env = c["environment"];
  env.onlyKeys({"force"});
  const JsonView f = env["force"];
  f.onlyKeys({"value", "start", "rise", "hold"});
  if (s.tool.link < 0) f.fail("a \"tool\" to push on (/tool)");
  const JsonView v = f["value"];
  v.size(3, 3);
  Spatial::Vec w = Spatial::Vec::Zero();
  for (int i = 0; i < 3; ++i) w[3 + i] = v.at(std::size_t(i)).inRange(-kMaxForce, kMaxForce);
  const ForceProfile profile{f["start"].inRange(0, 1e4), f.has("rise") ? f["rise"].inRange(0, 1e4) : 0.0,
                             f.has("hold") ? f["hold"].inRange(0, 1e4) : 0.0};
  s.push.emplace(BodyRef::link(s.tool.link), s.tool.point, w, profile);
  file.mechanism.forces.push_back(std::make_shared<PushForce<Spatial>>(*s.push));
}

// True when actuated joint j (in s.actuated's order) is a slide (metres, not radians).
bool isSlide(const model_file::LoadedModel& file, const DataSettings& s, int j) {
  return file.joints[std::size_t(s.actuated[std::size_t(j)])].type == "slide";
}

// The start: the actuators placed, the loop assembled from the file's pose. "actuated_deg" gives hinges
// in degrees (a slide has no degrees: refused, naming it); "actuated" every coordinate in its own unit
// (rad for a hinge, m for a slide).
void parseStart(const JsonView& c, const model_file::LoadedModel& file, ConstrainedMechanism<Spatial>& probe, DataSettings& s) {
  s.q0 = file.q0;
  const int m = int(s.actuated.size());
  std::string start_key = "actuated_deg";
  if (m > 0 || c.has("initial")) {
    const JsonView init = c["initial"];
    init.onlyKeys({"actuated_deg", "actuated"});
    if (init.has("actuated")) start_key = "actuated";
    if (init.has("actuated") && init.has("actuated_deg")) init["actuated"].fail("either \"actuated\" (rad, m) or \"actuated_deg\", not both");
    const JsonView start = init[start_key];
    start.size(std::size_t(m), std::size_t(m));
    for (int j = 0; j < m; ++j) {
      const JsonView u = start.at(std::size_t(j));
      const bool slide = isSlide(file, s, j);
      if (start_key == "actuated") {
        s.q0[s.actuated[std::size_t(j)]] = u.inRange(slide ? -kMaxCoordinate : -4 * M_PI, slide ? kMaxCoordinate : 4 * M_PI);
      } else {
        if (slide)
          u.fail("an angle, but " + s.actuated_names[std::size_t(j)] + " is a slide (m): give the start as /initial/actuated, each joint in its own unit (rad, m)");
        s.q0[s.actuated[std::size_t(j)]] = u.inRange(-720, 720) * M_PI / 180.0;
      }
    }
  }
  // (The probe has the file's geometry; the payloads changed only inertias.)
  if (!assemble(probe, s.q0, s.actuated)) c["initial"][start_key].fail("actuator positions at which the loop closes");
}

// The path, from where the tool starts (a joint path: from where the actuators start).
void parsePath(const JsonView& c, const model_file::LoadedModel& file, ConstrainedMechanism<Spatial>& probe, DataSettings& s) {
  const int m = int(s.actuated.size());
  if (c.has("trajectory") && TaskPath::isJointSpace(c["trajectory"])) {
    if (m == 0) c["trajectory"]["space"].fail("a task path: a joint path needs actuated joints (/actuated)");
    VecN u0(m);
    for (int j = 0; j < m; ++j) u0[j] = s.q0[s.actuated[std::size_t(j)]];
    s.path = std::make_shared<TaskPath>(c["trajectory"], u0, 4 * M_PI);
    // Degrees move hinges only: a slide's target is metres ("move", the coordinates' own units).
    const JsonView segs = c["trajectory"]["segments"];
    for (std::size_t i = 0, n = segs.size(0, 64); i < n; ++i)
      for (int j = 0; j < m && segs.at(i).has("move_deg"); ++j)
        if (isSlide(file, s, j))
          segs.at(i)["move_deg"].fail("a hinge path, but " + s.actuated_names[std::size_t(j)] +
                                      " is a slide (m): give this segment as \"move\", each joint in its own unit (rad, m)");
  } else if (!s.tool.axes.empty()) {
    const Eigen::Vector3d p0 = probe.pointPosition(s.tool.link, s.tool.point, s.q0);
    VecN x0(Eigen::Index(s.tool.axes.size()));
    for (std::size_t i = 0; i < s.tool.axes.size(); ++i) x0[Eigen::Index(i)] = p0[s.tool.axes[i] - 3];
    s.path = std::make_shared<TaskPath>(c["trajectory"], x0, kMaxCoordinate);
    // A task path is followed by the actuators alone: a degree of freedom none drives would be free,
    // and the path's first point "singular" for it. Said as what it is, before the reach check.
    if (c.has("trajectory") && m > 0 && file.dof != m)
      c["actuated"].fail("expected one actuated joint per degree of freedom for a task path: the model file's mechanism has " +
                         std::to_string(file.dof) + " after its loops close, " + std::to_string(m) +
                         " actuated (`dynlab model FILE` shows its joints and loops)");
    // Every point of it within reach, away from singular poses (labs/generic/reach.h).
    if (c.has("trajectory")) checkReach(c["trajectory"], *s.path, s.model, s.actuated, s.tool, s.axis_names, s.q0);
  }
}

// The controller: a kind of the library, its period, delay, noise, constant torques and the joint laws'
// options (labs/controllers/laws.h: per-joint gain scale, pid's anti-windup, Coulomb compensation).
void parseController(const JsonView& ctl, DataSettings& s) {
  ctl.onlyKeys({"kind", "control_period", "delay_steps", "noise", "constant", "joint_scale", "anti_windup", "tracking_time",
               "coulomb_compensation", "compensation_width", "posture_omega"});
  const int m = int(s.actuated.size());
  const std::string kind = ctl["kind"].string();
  if (std::find(controllers::kindNames().begin(), controllers::kindNames().end(), kind) == controllers::kindNames().end())
    ctl["kind"].fail("one of " + list(controllers::kindNames()));
  auto& cs = s.controller;
  cs.kind = controllers::kindFromName(kind);
  cs.period = ctl["control_period"].inRange(s.step.dt, 1.0);
  const double ratio = cs.period / s.step.dt;
  if (std::abs(ratio - std::round(ratio)) > 1e-6) ctl["control_period"].fail("a whole multiple of the simulation step /simulation/dt");
  cs.delay_steps = ctl.has("delay_steps") ? ctl["delay_steps"].integer(0, 1000) : 0;
  if (ctl.has("noise")) {
    const JsonView nz = ctl["noise"];
    nz.onlyKeys({"angle", "rate", "force", "seed"});
    cs.noise_angle = nz["angle"].inRange(0, 1), cs.noise_rate = nz["rate"].inRange(0, 100);
    cs.noise_force = nz.has("force") ? nz["force"].inRange(0, kMaxForce) : 0.0;
    cs.seed = std::uint64_t(nz["seed"].integer(0, 1LL << 53));
  }
  cs.constant = VecN::Zero(m);
  if (ctl.has("constant")) {
    ctl["constant"].size(std::size_t(m), std::size_t(m));
    for (int j = 0; j < m; ++j) cs.constant[j] = ctl["constant"].at(std::size_t(j)).inRange(-kMaxTorque, kMaxTorque);
  }
  cs.joint_scale = VecN::Ones(m);
  if (ctl.has("joint_scale")) {
    ctl["joint_scale"].size(std::size_t(m), std::size_t(m));
    for (int j = 0; j < m; ++j) cs.joint_scale[j] = ctl["joint_scale"].at(std::size_t(j)).inRange(0, 1e3);
  }
  if (ctl.has("anti_windup")) {
    const std::string aw = ctl["anti_windup"].oneOf({"clamping", "back_calculation", "none"});
    cs.anti_windup = aw == "clamping" ? controllers::laws::AntiWindup::Clamping
                     : aw == "none"   ? controllers::laws::AntiWindup::None
                                      : controllers::laws::AntiWindup::BackCalculation;
  }
  if (ctl.has("tracking_time")) cs.tracking_time = ctl["tracking_time"].inRange(1e-4, 100);
  if (ctl.has("coulomb_compensation")) cs.coulomb_compensation = ctl["coulomb_compensation"].boolean();
  if (ctl.has("compensation_width")) cs.compensation_width = ctl["compensation_width"].inRange(1e-6, 100);
  if (ctl.has("posture_omega")) cs.posture_omega = ctl["posture_omega"].inRange(0, 1e4);
}

// The gains declared in "gains": every kind a submission may pick finds its own (a joint path feeds
// the joint laws only: the task laws need a task path).
void parseControllerGains(const JsonView& c, DataSettings& s) {
  std::vector<std::string> declared;
  for (const auto& [g, _] : c["gains"].raw().items()) declared.push_back(g);
  const auto gains = parseGains(c["gains"], declared);
  std::vector<std::string> possible{c["controller"]["kind"].string()};
  if (c.has("submission_options") && c["submission_options"].has("kind"))
    for (const auto& k : c["submission_options"]["kind"]["choices"].raw()) possible.push_back(k.get<std::string>());
  for (const auto& k : possible) {
    if (std::find(controllers::kindNames().begin(), controllers::kindNames().end(), k) == controllers::kindNames().end())
      c["submission_options"]["kind"].fail("controller kinds of the library (" + list(controllers::kindNames()) + ")");
    for (const auto& g : controllers::gainsOf(controllers::kindFromName(k)))
      if (!gains.count(g)) c["gains"].fail("a gain \"" + g + "\" (the controller kind " + k + " reads it)");
    const auto kk = controllers::kindFromName(k);
    using K = controllers::Kind;
    const bool task = kk == K::TaskPdGravity || kk == K::TaskInverseDynamics || kk == K::ImpedanceTask || kk == K::ImpedanceInverseDynamics ||
                      kk == K::ImpedanceJoint;
    if (s.path && s.path->joint() && task)
      c["trajectory"]["space"].fail("\"task\" for the controller kind " + k + " (a joint path feeds joint_pd_gravity, pid and computed_torque)");
  }
  auto& cs = s.controller;
  auto gain = [&](const char* g) { return gains.count(g) ? gains.at(g) : 0.0; };
  cs.kp = gain("kp"), cs.kd = gain("kd"), cs.ki = gain("ki"), cs.omega_n = gain("omega_n"), cs.zeta = gain("zeta");
  cs.k_imp = gain("k_imp"), cs.d_imp = gain("d_imp"), cs.m_imp = gains.count("m_imp") ? gains.at("m_imp") : 1.0;
  if (!(cs.m_imp > 0)) c["gains"]["m_imp"].fail("a mass above 0 (kg): the impedance law divides by it");
}

// The exercise's target impedance M ξ'' + D ξ' + K ξ = F (ξ = x − x_d per task axis; D = 2ζ√(KM)).
void parseTarget(const JsonView& c, DataSettings& s) {
  if (!c.has("target")) return;
  const JsonView t = c["target"];
  t.onlyKeys({"k", "m", "zeta"});
  if (s.tool.axes.empty() || (s.path && s.path->joint())) t.fail("a task: the target is the tool's (/tool and a task trajectory)");
  s.target.k = t["k"].positive(1e7), s.target.m = t["m"].positive(1e5), s.target.zeta = t["zeta"].inRange(0, 100);
}

// The trace's columns: time, coordinates, rates, efforts, the task's (x, its reference, the error) or a
// joint path's (u_d and e_u per actuated joint), the push, the target, the books, the closure forces and
// the passive joints' loads.
void traceColumns(const model_file::LoadedModel& file, DataSettings& s) {
  s.columns = {"t"};
  for (const auto& j : file.joints) s.columns.push_back("q_" + columnName(j.name));
  for (const auto& j : file.joints) s.columns.push_back("v_" + columnName(j.name));
  for (const auto& a : s.actuated_names) s.columns.push_back("tau_" + columnName(a));
  s.columns.push_back("tau_sat");
  const bool joint_path = s.path && s.path->joint();
  for (const auto& a : s.axis_names) s.columns.push_back("tool_" + a);
  for (const char* p : {"ref_", "e_"})
    for (const auto& a : joint_path ? s.actuated_names : s.axis_names) s.columns.push_back(p + (joint_path ? columnName(a) : a));
  if (s.push)
    for (const char* a : {"push_x", "push_y", "push_z"}) s.columns.push_back(a);
  if (s.target.k > 0)
    for (const char* p : {"target_", "dev_"})
      for (const auto& a : s.axis_names) s.columns.push_back(p + a);
  for (const char* k : {"energy", "work", "constraint_residual"}) s.columns.push_back(k);
  for (const auto& cl : file.closures)
    for (const auto& r : cl.kept) s.columns.push_back("f_" + columnName(cl.name) + "_" + r);
  for (int j = 0; j < int(file.joints.size()); ++j)
    if (std::find(s.actuated.begin(), s.actuated.end(), j) == s.actuated.end()) s.passive.push_back(j);
  for (const int j : s.passive)
    for (const char* a : {"x", "y", "z"}) s.columns.push_back("load_" + columnName(file.joints[std::size_t(j)].name) + "_" + a);
}

}  // namespace

// Parsed in the order the checks depend on: the model and plant, the actuators, the tool and its push,
// the start and the path, the simulation, the controller and its gains, the target, the trace's
// columns and the metrics that read them.
DataSettings parseDataSettings(const JsonView& c, const std::string& name, const std::string& folder,
                               const model_file::LoadOptions& options) {
  DataSettings s;
  s.name = name, s.folder = folder;
  c.onlyKeys({"lab", "title", "description", "variants", "model_file", "actuated", "torque_limit", "tool", "initial", "trajectory",
              "plant", "controller", "gains", "metrics", "passive_tolerance", "simulation", "rubric", "metric_docs",
              "figures", "submission_options", "map", "drawing", "environment", "target"});
  s.title = c["title"].string();
  // The model (the controller's), and the plant: the model with the payloads the controller does not know.
  model_file::LoadedModel file = loadModel(c["model_file"], folder, options);
  s.model = file.mechanism;
  ConstrainedMechanism<Spatial> probe(file.mechanism);
  addPayloads(c, file, probe);
  parseActuated(c, file, s);
  parseTool(c, file, probe, s);
  parseEnvironment(c, file, s);
  parseStart(c, file, probe, s);
  parsePath(c, file, probe, s);
  const SimulationSettings sim = parseSimulation(c["simulation"]);
  s.step = sim.step, s.duration = sim.duration;
  s.passive_tolerance = c.has("passive_tolerance") ? c["passive_tolerance"].inRange(1e-14, 1.0) : 1e-6;
  parseController(c["controller"], s);
  parseControllerGains(c, s);
  parseTarget(c, s);
  traceColumns(file, s);
  if (c.has("metrics")) s.metrics = parseMetrics(c["metrics"], s.columns, sim.exercise_duration, s.step.dt);
  checkEffortUnits(c, s, [&](int j) { return isSlide(file, s, j); });
  s.plant = std::make_shared<const model_file::LoadedModel>(std::move(file));
  return s;
}

}  // namespace dyn::generic
