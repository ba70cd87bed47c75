// The file's joint-space constraints onto the description, after its loop closures: joint range limits
// (physics/constraints/joint_limit.h: each limited side a one-sided row with events) and joint and
// fixed-tendon equalities (coupling.h: one row each, MuJoCo's polycoef form); fixed tendons' paths (for
// the actuators that drive them) and own springs, dampers and friction (actuators.h applies them); and
// what about tendons and actuators dynlab cannot hold (spatial tendons, tendon limits, muscles), refused
// in one line. Each element also goes into out.contacts (the
// description's constraints after the closures, in order) so that runs report its force and gap.
#include <cmath>
#include <cstdio>

#include "physics/constraints/coupling.h"
#include "physics/constraints/joint_limit.h"
#include "physics/model_file/mujoco_call.h"
#include "physics/model_file/number_text.h"

namespace dyn::model_file::detail {
namespace {

std::string named(const mjModel* m, int type, int id, const char* what) {
  const char* n = mj_id2name(m, type, id);
  return n && *n ? std::string(n) : std::string(what) + " #" + std::to_string(id);
}

// A fixed tendon's length as a coupling's linear form: Σ coef_k θ_{j_k}.
Coupling::Form tendonForm(const mjModel* m, int t) {
  Coupling::Form f;
  for (const TendonTerm& term : fixedTendonPath(m, t)) f.push_back({term.coordinate, term.coef});
  return f;
}

std::string num(double x) { return detail::numberText(x, 6); }

}  // namespace

std::vector<TendonTerm> fixedTendonPath(const mjModel* m, int t) {
  std::vector<TendonTerm> path;
  for (int w = m->tendon_adr[t]; w < m->tendon_adr[t] + m->tendon_num[t]; ++w) path.push_back({m->jnt_dofadr[m->wrap_objid[w]], m->wrap_prm[w], m->jnt_qposadr[m->wrap_objid[w]]});
  return path;
}

void checkTendons(const std::string& path, const mjModel* m) {
  auto fail = [&](const std::string& what) { throw ModelFileError(path + ": " + what); };
  const std::string held = "dynlab reads fixed tendons (<fixed> over joints) in <equality><tendon>, in actuators and with their own "
                           "stiffness, damping and frictionloss";
  for (int t = 0; t < m->ntendon; ++t) {
    const std::string tendon = "tendon '" + named(m, mjOBJ_TENDON, t, "tendon") + "'";
    for (int w = m->tendon_adr[t]; w < m->tendon_adr[t] + m->tendon_num[t]; ++w)
      if (m->wrap_type[w] != mjWRAP_JOINT) fail(tendon + " is a spatial tendon (it wraps sites or geoms); " + held);
      else if (!std::isfinite(m->wrap_prm[w]) || std::abs(m->wrap_prm[w]) > 1e9)
        fail(tendon + "'s coef is " + num(m->wrap_prm[w]) + "; dynlab reads finite values within ±1e+09");
    if (m->tendon_limited[t]) fail(tendon + " has a range (limited); " + held + ", not tendon limits (limit its joints instead)");
    const double numbers[4] = {m->tendon_stiffness[t], m->tendon_lengthspring[t], m->tendon_damping[t], m->tendon_frictionloss[t]};
    for (const double x : numbers)
      if (!std::isfinite(x) || std::abs(x) > 1e9)
        fail(tendon + "'s stiffness, spring length, damping or frictionloss is " + num(x) + "; dynlab reads finite values within ±1e+09");
  }
  for (int i = 0; i < m->nu; ++i) {
    const std::string a = "actuator '" + named(m, mjOBJ_ACTUATOR, i, "actuator") + "'";
    if (m->actuator_dyntype[i] == mjDYN_MUSCLE || m->actuator_gaintype[i] == mjGAIN_MUSCLE || m->actuator_biastype[i] == mjBIAS_MUSCLE)
      fail(a + " is a muscle; dynlab reads actuators on joints and fixed tendons only (motor, position, velocity, general)");
  }
}

void readTendons(const mjModel* m, LoadedModel& out) {
  const int flags = m->opt.disableflags;
  for (int t = 0; t < m->ntendon; ++t) {
    TendonSpring s;
    s.name = named(m, mjOBJ_TENDON, t, "tendon");
    s.path = fixedTendonPath(m, t);
    if (!(flags & mjDSBL_PASSIVE)) s.stiffness = m->tendon_stiffness[t], s.rest = m->tendon_lengthspring[t], s.damping = m->tendon_damping[t];
    if (!(flags & (mjDSBL_FRICTIONLOSS | mjDSBL_CONSTRAINT))) s.frictionloss = m->tendon_frictionloss[t];
    if (s.stiffness == 0 && s.damping == 0 && s.frictionloss == 0) continue;
    if (s.frictionloss != 0)
      out.notes.push_back("tendon '" + s.name + "': frictionloss " + num(s.frictionloss) + " read as Coulomb friction smoothed over a rate width of " +
                          num(s.friction_width) + " (MuJoCo: exact stiction)");
    out.tendons.push_back(std::move(s));
  }
}

namespace {
// For a refusal: the file's named keyframes that start joint jt inside its range, as the option to take
// ("--key home"), or that a keyframe is the way when none is named or inside.
std::string keysInside(const mjModel* m, const Joint& jt) {
  if (m->nkey == 0) return "";
  std::string keys;
  for (int k = 0; k < m->nkey; ++k) {
    const char* n = mj_id2name(m, mjOBJ_KEY, k);
    const double q = m->key_qpos[std::size_t(k) * std::size_t(m->nq) + std::size_t(jt.qpos)];
    if (n && *n && q >= jt.lower - 1e-9 && q <= jt.upper + 1e-9) keys += std::string(keys.empty() ? "" : " or ") + "--key " + oneLine(n);
  }
  return keys.empty() ? ", or a keyframe that starts inside it (--key NAME)" : ", or a keyframe of the file that does (" + keys + ")";
}
}  // namespace

void addJointElements(const std::string& path, const mjModel* m, const LoadOptions& options, LoadedModel& out) {
  MechanismModel<Spatial>& mech = out.mechanism;
  // Limits: each limited hinge or slide, its two sides (MuJoCo's jnt_range), never starting outside.
  for (int j = 0; j < m->nv; ++j) {
    const Joint& jt = out.joints[std::size_t(j)];
    if (!jt.limited) continue;
    if (!options.joint_limits) {
      out.notes.push_back("joint '" + jt.name + "': limit [" + num(jt.lower) + ", " + num(jt.upper) + "] " + (jt.type == "hinge" ? "rad" : "m") + " read, not enforced (a data lab: its controller keeps the joint inside)");
      continue;
    }
    // A run from a keyframe starts there (controls.cpp's readStart checks it); else from q0.
    const double q0 = out.q0[jt.qpos];
    if (options.key.empty() && !(q0 >= jt.lower - 1e-9 && q0 <= jt.upper + 1e-9))
      throw ModelFileError(path + ": joint '" + jt.name + "' starts at " + num(q0) + ", outside its range [" + num(jt.lower) + ", " + num(jt.upper) +
                           "] (its ref, or 0); expected the reference pose inside the range" +
                           keysInside(m, jt));
    const int parent = mech.tree.bodies[std::size_t(j)].parent;
    for (const JointLimit::Side side : {JointLimit::Side::Lower, JointLimit::Side::Upper}) {
      const bool lower = side == JointLimit::Side::Lower;
      mech.constraints.push_back(std::make_shared<JointLimit>(j, parent, side, lower ? jt.lower : jt.upper));
      out.contacts.push_back({jt.name + (lower ? "_lower" : "_upper"), "joint_limit", jt.body, j, 0.0});
    }
  }
  // Joint and tendon equalities (connect and weld are the closures, read before).
  const bool equalities = !(m->opt.disableflags & (mjDSBL_EQUALITY | mjDSBL_CONSTRAINT));
  for (int e = 0; equalities && e < m->neq; ++e) {
    const bool joint = m->eq_type[e] == mjEQ_JOINT;
    if ((!joint && m->eq_type[e] != mjEQ_TENDON) || !m->eq_active[e]) continue;
    const std::string name = named(m, mjOBJ_EQUALITY, e, joint ? "joint equality" : "tendon equality");
    const mjtNum* c = m->eq_data + mjNEQDATA * e;
    const std::array<double, 5> poly{c[0], c[1], c[2], c[3], c[4]};
    if (!(std::abs(poly[0]) <= 1e-12))
      throw ModelFileError(path + ": equality '" + name + "' has polycoef[0] = " + num(poly[0]) +
                           ": it does not hold at the reference pose; dynlab needs polycoef=\"0 …\" (or refs that satisfy it)");
    auto form = [&](int id) { return id < 0 ? Coupling::Form{} : joint ? Coupling::Form{{m->jnt_dofadr[id], 1.0}} : tendonForm(m, id); };
    Coupling::Form first = form(m->eq_obj1id[e]), second = form(m->eq_obj2id[e]);
    if (first.empty()) throw ModelFileError(path + ": equality '" + name + "' couples a tendon over no joint; expected a fixed tendon with joints");
    mech.constraints.push_back(std::make_shared<Coupling>(joint ? "joint_coupling" : "tendon_coupling", first, second, poly, out.q0));
    out.contacts.push_back({name, joint ? "joint_coupling" : "tendon_coupling", out.joints[std::size_t(first.front().joint)].body, first.front().joint, 0.0});
  }
  // A fixed tendon nothing reads (no equality, actuator, stiffness, damping or frictionloss): noted.
  for (int t = 0; t < m->ntendon; ++t) {
    bool used = m->tendon_stiffness[t] != 0 || m->tendon_damping[t] != 0 || m->tendon_frictionloss[t] != 0;
    for (int e = 0; equalities && e < m->neq; ++e)
      used = used || (m->eq_type[e] == mjEQ_TENDON && m->eq_active[e] && (m->eq_obj1id[e] == t || m->eq_obj2id[e] == t));
    for (int i = 0; i < m->nu; ++i) used = used || (m->actuator_trntype[i] == mjTRN_TENDON && m->actuator_trnid[2 * i] == t);
    if (!used) out.notes.push_back("tendon '" + named(m, mjOBJ_TENDON, t, "tendon") + "': a fixed tendon nothing drives or holds; read, nothing to hold");
  }
  if (mech.rows() > kMaxDof)
    throw ModelFileError(path + ": its loops, joint limits (a row per limited side) and couplings make " + std::to_string(mech.rows()) +
                         " constraint rows, more than dynlab's " + std::to_string(kMaxDof) + "; remove limited=\"true\" from joints that cannot reach their stops");
}

}  // namespace dyn::model_file::detail
