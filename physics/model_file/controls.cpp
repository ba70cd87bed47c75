// What drives a model file's run, read from the compiled model: its actuators (MuJoCo's <motor>,
// <position>, <velocity> and <general> on a hinge or slide joint or a fixed tendon, no activation dynamics: the affine
// law of model_file.h's Actuator) and where the run starts (q0 at rest with every control 0, or a
// keyframe's qpos, qvel and ctrl, which must hold the file's loops). Everything else an actuator may
// be is refused in one line naming it and what is supported.
#include <cmath>

#include "physics/constrained_mechanism.h"
#include "physics/model_file/closure_rows.h"
#include "physics/model_file/mujoco_call.h"
#include "physics/model_file/number_text.h"

namespace dyn::model_file::detail {

namespace {

std::string named(const mjModel* m, int type, int id, const char* what) {
  const char* n = mj_id2name(m, type, id);
  return n && *n ? std::string(n) : std::string(what) + " #" + std::to_string(id);
}

std::string num(double x) { return detail::numberText(x, 6); }

constexpr double kLargest = 1e9;  // as model_file.cpp's checkNumbers

void checkFinite(const std::string& where, const char* what, const mjtNum* x, int count) {
  for (int i = 0; i < count; ++i)
    if (!std::isfinite(x[i]) || std::abs(x[i]) > kLargest)
      throw ModelFileError(where + "'s " + what + " is " + num(x[i]) + "; dynlab reads finite values within ±" + num(kLargest));
}

constexpr const char* kSupported = "dynlab reads motor, position, velocity and general actuators on a hinge or slide joint or a fixed tendon "
                                   "(fixed gain, affine or no bias, no activation dynamics)";

// Actuator i as the affine law; anything else refused.
Actuator readActuator(const std::string& path, const mjModel* m, int i) {
  Actuator a;
  a.name = named(m, mjOBJ_ACTUATOR, i, "actuator");
  const std::string where = path + ": actuator '" + a.name + "'";
  if (m->actuator_dyntype[i] != mjDYN_NONE)
    throw ModelFileError(where + " has activation dynamics (dyntype integrator, filter, muscle or user); " + kSupported);
  const int trn = m->actuator_trntype[i];
  if (trn != mjTRN_JOINT && trn != mjTRN_JOINTINPARENT && trn != mjTRN_TENDON)
    throw ModelFileError(where + " drives a site, a body or a slider-crank; " + kSupported);
  if (m->actuator_gaintype[i] != mjGAIN_FIXED) throw ModelFileError(where + " has a muscle or user gain; " + kSupported);
  if (m->actuator_biastype[i] != mjBIAS_NONE && m->actuator_biastype[i] != mjBIAS_AFFINE)
    throw ModelFileError(where + " has a muscle or user bias; " + kSupported);
  const int id = m->actuator_trnid[2 * i];
  if (trn == mjTRN_TENDON) {  // fixed: checkTendons refused spatial ones
    a.tendon = named(m, mjOBJ_TENDON, id, "tendon");
    a.path = fixedTendonPath(m, id);
  } else {
    a.joint = named(m, mjOBJ_JOINT, id, "joint");
    if (m->jnt_type[id] == mjJNT_BALL || m->jnt_type[id] == mjJNT_FREE) throw ModelFileError(where + " drives a ball or free joint; " + kSupported);
    a.path = {{m->jnt_dofadr[id], 1.0, m->jnt_qposadr[id]}};
  }
  checkFinite(where, "gear", m->actuator_gear + 6 * i, 1);
  checkFinite(where, "gain", m->actuator_gainprm + mjNGAIN * i, 1);
  a.gear = m->actuator_gear[6 * i];
  a.gain = m->actuator_gainprm[mjNGAIN * i];
  if (m->actuator_biastype[i] == mjBIAS_AFFINE) {
    checkFinite(where, "bias", m->actuator_biasprm + mjNBIAS * i, 3);
    for (int k = 0; k < 3; ++k) a.bias[std::size_t(k)] = m->actuator_biasprm[mjNBIAS * i + k];
  }
  a.ctrl_limited = m->actuator_ctrllimited[i] && !(m->opt.disableflags & mjDSBL_CLAMPCTRL);
  a.force_limited = m->actuator_forcelimited[i];
  auto range = [&](bool limited, const char* what, const mjtNum* r, double& lower, double& upper) {
    if (!limited) return;
    checkFinite(where, what, r, 2);
    lower = r[0], upper = r[1];
    if (!(lower <= upper)) throw ModelFileError(where + "'s " + what + " [" + num(lower) + ", " + num(upper) + "] is empty; expected lower ≤ upper");
  };
  range(a.ctrl_limited, "ctrlrange", m->actuator_ctrlrange + 2 * i, a.ctrl_lower, a.ctrl_upper);
  range(a.force_limited, "forcerange", m->actuator_forcerange + 2 * i, a.force_lower, a.force_upper);
  return a;
}

}  // namespace

void readActuators(const std::string& path, const mjModel* m, LoadedModel& out) {
  if (m->nu > 0 && (m->opt.disableflags & mjDSBL_ACTUATION)) {
    out.notes.push_back(std::to_string(m->nu) + " actuators off (<option><flag actuation=\"disable\"/>)");
    return;
  }
  for (int i = 0; i < m->nu; ++i) out.actuators.push_back(readActuator(path, m, i));
}
namespace {

// A keyframe saved from MuJoCo's own run holds the loops only as tightly as its soft equalities do
// (Menagerie's Cassie 'home': its plantar rods 1.5 mm open). Within kKeyframeGap the start is moved onto
// the loops, to the nearest closed pose in the mass metric (integrate.h's projection, the closures' rows
// alone), its rates projected likewise, and that is noted; past it the checks below refuse it.
constexpr double kKeyframeGap = 1e-2;  // m (rad for a weld's rotation rows)
void closeKeyframe(const std::string& where, LoadedModel& out) {
  MechanismModel<Spatial> loops = out.mechanism;
  loops.constraints.resize(out.closures.size());
  if (loops.constraints.empty()) return;
  ConstrainedMechanism<Spatial> mech(loops);
  double gap = 0;
  std::string name;
  for (std::size_t i = 0; i < out.closures.size(); ++i)
    if (const double g = mech.residual(int(i), out.start_q); !(g <= gap)) gap = g, name = out.closures[i].name;
  if (!(gap > 1e-9 && gap <= kKeyframeGap)) return;
  VecN q = out.start_q, v = out.start_v;
  if (!projectPositions(mech, DriftOptions{}, q) || !q.allFinite()) return;
  projectVelocities(mech, q, v);
  if (!v.allFinite()) return;
  const double moved = (q - out.start_q).cwiseAbs().maxCoeff();
  out.start_q = q, out.start_v = v;
  out.notes.push_back(where.substr(where.find("keyframe")) + ": its qpos opens closure '" + name + "' by |φ|∞ " + num(gap) +
                      " (MuJoCo's soft equalities hold a loop only so tightly): runs start from the nearest closed pose (mass-weighted), |Δq|∞ " + num(moved));
}

}  // namespace


void readStart(const std::string& path, const mjModel* m, const std::string& key, LoadedModel& out) {
  const int nq = m->nq, nv = m->nv;
  out.start_q = out.q0;
  out.start_v = VecN::Zero(nv);
  out.ctrl = VecN::Zero(Eigen::Index(out.actuators.size()));
  int chosen = -1;
  for (int k = 0; k < m->nkey; ++k) {
    const char* n = mj_id2name(m, mjOBJ_KEY, k);
    if (!n || !*n) continue;
    out.keyframes.push_back(n);
    if (!key.empty() && key == n && chosen < 0) chosen = k;
  }
  if (key.empty()) return;
  if (chosen < 0) {
    std::string names;
    for (const std::string& n : out.keyframes) names += (names.empty() ? "'" : ", '") + n + "'";
    throw ModelFileError(path + ": --key '" + key + "': no such keyframe; " +
                         (names.empty() ? std::string("the file names no keyframe") : "the file's keyframes: " + names));
  }
  const std::string where = path + ": keyframe '" + key + "'";
  checkFinite(where, "qpos", m->key_qpos + chosen * nq, nq);
  checkFinite(where, "qvel", m->key_qvel + chosen * nv, nv);
  out.key = key;
  out.start_q = Eigen::Map<const VecN>(m->key_qpos + chosen * nq, nq);
  out.start_v = Eigen::Map<const VecN>(m->key_qvel + chosen * nv, nv);
  if (!out.actuators.empty()) {
    checkFinite(where, "ctrl", m->key_ctrl + chosen * m->nu, m->nu);
    out.ctrl = Eigen::Map<const VecN>(m->key_ctrl + chosen * m->nu, m->nu);
  }
  // The joints' stops held (joint_elements.cpp) must not be passed there.
  for (const Contact& c : out.contacts) {
    if (c.kind != "joint_limit") continue;
    // The joint's coordinate in qpos (after a ball's quaternion it is not its rate's index c.link).
    const Joint& jt = out.joints[std::size_t(c.link)];
    if (!(out.start_q[jt.qpos] >= jt.lower - 1e-9 && out.start_q[jt.qpos] <= jt.upper + 1e-9))
      throw ModelFileError(where + ": its qpos puts joint '" + jt.name + "' at " + num(out.start_q[jt.qpos]) + ", outside its range [" + num(jt.lower) +
                           ", " + num(jt.upper) + "]; a keyframe must start inside the joints' ranges");
  }
  closeKeyframe(where, out);
  // The loops must hold there (as at q0: 1e-9), and their velocity form with qvel.
  ConstrainedMechanism<Spatial> mech(out.mechanism);
  for (std::size_t i = 0; i < out.closures.size(); ++i)
    if (const double gap = mech.residual(int(i), out.start_q); !(gap <= 1e-9))
      throw ModelFileError(where + ": its qpos opens closure '" + out.closures[i].name + "' (gap " + num(gap) +
                           "); a keyframe must hold the file's loops");
  // Every row, the dropped ones too (closure_rows.h): a keyframe in another plane than the loop's.
  if (const std::string why = EveryClosureRow(out).opened(out.start_q); !why.empty())
    throw ModelFileError(where + ": its qpos opens a loop (" + why + "); a keyframe must hold the file's loops");
  if (out.contacts.empty())
    if (const double gap = mech.residual(out.start_q, out.start_v); !(gap <= 1e-9))
      throw ModelFileError(where + ": its qvel moves the loops apart (|G v| " + num(gap) + "); a keyframe's qvel must keep them closed");
}

}  // namespace dyn::model_file::detail
