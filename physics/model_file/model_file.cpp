// A model file onto the description (model_file.h): read, checked and compiled by MuJoCo in the
// fence (compile.cpp), every element checked against what the description can hold, then mapped at
// the reference pose qpos0.
#include "physics/model_file/model_file.h"

#include <algorithm>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <sstream>
#include <unordered_set>

#include "physics/constrained_mechanism.h"
#include "physics/constraints/point_closure.h"
#include "physics/model_file/closure_rows.h"
#include "physics/model_file/mujoco_call.h"
#include "physics/model_file/number_text.h"

namespace dyn::model_file {

namespace {

using Mat3 = Eigen::Matrix3d;
using Vec3 = Eigen::Vector3d;
using RowMat3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;

struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using DataPtr = std::unique_ptr<mjData, DataDeleter>;

std::string num(double x) { return detail::numberText(x, 6); }

std::string nameOf(const mjModel* m, int type, int id, const char* what) {
  const char* n = mj_id2name(m, type, id);
  if (n && *n) return n;
  if (type == mjOBJ_BODY && id == 0) return "world";
  return std::string(what) + " #" + std::to_string(id);
}

// Everything in the compiled model that the description cannot hold, as one error; what it reads
// but does not enforce, as notes.
void checkSupported(const std::string& file, const mjModel* m, const LoadOptions& opt, std::vector<std::string>& notes) {
  auto fail = [&](const std::string& what) { throw ModelFileError(file + ": " + what); };
  for (int j = 0; j < m->njnt; ++j)
    if (m->jnt_type[j] == mjJNT_BALL || m->jnt_type[j] == mjJNT_FREE)
      detail::checkBallJoint(file, m, j, nameOf(m, mjOBJ_JOINT, j, "joint"), nameOf(m, mjOBJ_BODY, m->jnt_bodyid[j], "body"));
  if (m->nv == 0) fail("no joint: nothing moves (dynlab reads bodies moved by hinge, slide, ball and free joints)");
  if (m->nq > kMaxDof) fail(std::to_string(m->nq) + " coordinates (qpos), more than dynlab's " + std::to_string(kMaxDof));
  for (int b = 1; b < m->nbody; ++b)
    if (m->body_mocapid[b] >= 0) fail("body '" + nameOf(m, mjOBJ_BODY, b, "body") + "' is a mocap body; dynlab reads bodies moved by their joints only");
  detail::checkTendons(file, m);
  if (m->opt.density != 0 || m->opt.viscosity != 0 || m->opt.wind[0] != 0 || m->opt.wind[1] != 0 || m->opt.wind[2] != 0)
    fail("<option> density/viscosity/wind: dynlab has no fluid forces (leave them 0)");
  // Geoms that may collide: noted, not refused (contacts.cpp).
  if (!opt.ignore_contacts) detail::noteContacts(m, notes);
}

// Every number the description reads, finite and within ±kLargest: a mass of 1e308 or an infinite
// gravity is refused here, not found as NaN mid-run.
constexpr double kLargest = 1e9;
void checkNumbers(const std::string& file, const mjModel* m, const mjData* d) {
  auto check = [&](const mjtNum* x, int count, const std::string& what) {
    for (int i = 0; i < count; ++i)
      if (!std::isfinite(x[i]) || std::abs(x[i]) > kLargest)
        throw ModelFileError(file + ": " + what + " is " + num(x[i]) + "; dynlab reads finite values within ±" + num(kLargest));
  };
  check(m->opt.gravity, 3, "<option gravity>");
  for (int b = 1; b < m->nbody; ++b) {
    const std::string body = "body '" + nameOf(m, mjOBJ_BODY, b, "body") + "'";
    check(m->body_mass + b, 1, body + "'s mass");
    check(m->body_inertia + 3 * b, 3, body + "'s inertia");
    check(d->xipos + 3 * b, 3, body + "'s centre of mass");
    check(d->xpos + 3 * b, 3, body + "'s position");
  }
  for (int j = 0; j < m->njnt; ++j) {
    const std::string joint = "joint '" + nameOf(m, mjOBJ_JOINT, j, "joint") + "'";
    check(d->xanchor + 3 * j, 3, joint + "'s anchor");
    check(m->qpos0 + j, 1, joint + "'s ref");
    check(m->qpos_spring + j, 1, joint + "'s springref");
    check(m->jnt_stiffness + j, 1, joint + "'s stiffness");
    check(m->dof_damping + j, 1, joint + "'s damping");
    check(m->dof_frictionloss + j, 1, joint + "'s frictionloss");
    check(m->dof_armature + j, 1, joint + "'s armature");
  }
  for (int e = 0; e < m->neq; ++e) check(m->eq_data + mjNEQDATA * e, mjNEQDATA, "equality '" + nameOf(m, mjOBJ_EQUALITY, e, "equality") + "'s data");
}

// A MuJoCo body as the description sees it: the tree body it moves with (world: −1).
struct Frame {
  int link = -1;
  Vec3 origin = Vec3::Zero();  // that tree body's frame origin, world, at qpos0
};

BodyRef ref(int link) { return link < 0 ? BodyRef::world() : BodyRef::link(link); }

// The frames' links and origins, per MuJoCo body, as drawing.cpp and elements.cpp take them.
void splitFrames(const std::vector<Frame>& frame, std::vector<int>& link, std::vector<Vec3>& origin) {
  for (const Frame& f : frame) link.push_back(f.link), origin.push_back(f.origin);
}

// MuJoCo's numbers at qpos0 carry the rounding of its frames' quarter turns (cos π/2 = 6e-17): a joint's
// axis (0, −1, 2.2e-16) where the file says −e_y, a central inertia R diag(I) Rᵀ with products of
// 1e-17 where the file's are 0. Such residues (Spatial::kResidue: below 1e-12 of the unit, of the
// principal moments' sum) are made exact zeros, so the joint turns about a coordinate axis and the
// body's inertia is diagonal where the file means it (a tilt or a product the file states stays).
Vec3 snappedAxis(Vec3 a) {
  for (int k = 0; k < 3; ++k)
    if (std::abs(a[k]) <= Spatial::kResidue) a[k] = 0.0;
  return a.normalized();
}

// The trees: one body per joint, in MuJoCo's order (parents first), frames on the anchors; each body's
// inertia, gravity and what to draw. Returns each MuJoCo body's frame.
std::vector<Frame> readTree(const std::string& path, const mjModel* m, const mjData* d, LoadedModel& out) {
  MechanismModel<Spatial>& mech = out.mechanism;
  const int flags = m->opt.disableflags;
  std::vector<Frame> frame(std::size_t(m->nbody));
  std::vector<Spatial::Mat> inertia;
  for (int b = 1; b < m->nbody; ++b) {
    Frame f = frame[std::size_t(m->body_parentid[b])];
    for (int k = 0; k < m->body_jntnum[b]; ++k) {
      const int j = m->body_jntadr[b] + k;
      if (m->jnt_qposadr[j] != mech.tree.nq() || m->jnt_dofadr[j] != mech.tree.dof())
        throw ModelFileError(path + ": joint '" + nameOf(m, mjOBJ_JOINT, j, "joint") + "': coordinates out of MuJoCo's usual order");
      if (m->jnt_type[j] == mjJNT_BALL || m->jnt_type[j] == mjJNT_FREE) {
        detail::addBallJoint(m, d, b, j, nameOf(m, mjOBJ_JOINT, j, "joint"), nameOf(m, mjOBJ_BODY, b, "body"), f.link, f.origin, out);
        inertia.resize(std::size_t(mech.tree.dof()), Spatial::Mat::Zero());
        continue;
      }
      const Vec3 o(d->xanchor + 3 * j), a = snappedAxis(Vec3(d->xaxis + 3 * j).normalized());
      const bool hinge = m->jnt_type[j] == mjJNT_HINGE;
      const double q0 = m->qpos0[m->jnt_qposadr[j]];
      // Frames world-aligned at q0: a hinge's placement undoes its turn at q0, a slide's its travel.
      Spatial::Transform X{Mat3::Identity(), o - f.origin, true};
      if (hinge) X.E = Spatial::jointTransform(true, a, q0).E.transpose();
      else X.r -= a * q0;
      mech.tree.addBody(f.link, hinge ? JointType::Revolute : JointType::Prismatic, a, X, Spatial::Mat::Zero());
      inertia.push_back(Spatial::Mat::Zero());
      f = {mech.tree.dof() - 1, o};
      Joint jt;
      jt.name = nameOf(m, mjOBJ_JOINT, j, "joint");
      jt.body = nameOf(m, mjOBJ_BODY, b, "body");
      jt.type = hinge ? "hinge" : "slide";
      jt.limited = m->jnt_limited[j] && !(flags & mjDSBL_LIMIT);
      jt.lower = m->jnt_range[2 * j], jt.upper = m->jnt_range[2 * j + 1];
      jt.qpos = m->jnt_qposadr[j];
      out.joints.push_back(jt);
      out.coordinates.push_back(jt.name);
    }
    frame[std::size_t(b)] = f;
    if (m->body_jntnum[b] > 0) out.bodies.push_back(nameOf(m, mjOBJ_BODY, b, "body"));
    // The body's inertia joins the tree body it moves with (a body without joints is fused into its
    // parent; one fused into the world never moves).
    if (f.link < 0) continue;
    const RowMat3 R = Eigen::Map<const RowMat3>(d->ximat + 9 * b);
    Mat3 Ic = R * Vec3(m->body_inertia + 3 * b).asDiagonal() * R.transpose();
    Spatial::snapProducts(Ic, Ic.trace());
    inertia[std::size_t(f.link)] += Spatial::inertia(m->body_mass[b], Vec3(d->xipos + 3 * b) - f.origin, Ic);
  }
  for (int i = 0; i < mech.tree.dof(); ++i) {
    auto& body = mech.tree.bodies[std::size_t(i)];
    body.inertia = inertia[std::size_t(i)];
    body.central = Spatial::central(body.inertia);
    body.massless = Spatial::massless(body.inertia);
  }
  if (!(flags & mjDSBL_GRAVITY)) mech.tree.gravity.tail<3>() = Vec3(m->opt.gravity);
  // What to draw: the geoms, each on the tree body its MuJoCo body moves with.
  std::vector<int> link;
  std::vector<Vec3> origin;
  splitFrames(frame, link, origin);
  detail::readDrawing(m, d, link, origin, out.drawing);
  return frame;
}

// Joint springs, damping and friction (MuJoCo's passive forces and frictionloss), and armature
// (MuJoCo adds it to M's diagonal whatever the flags); none when every joint is plain.
void readJointProperties(const mjModel* m, LoadedModel& out) {
  MechanismModel<Spatial>& mech = out.mechanism;
  const int flags = m->opt.disableflags;
  bool any = false;
  mech.joints.resize(std::size_t(m->nv));
  for (int j = 0; j < m->nv; ++j) {
    JointProperties& p = mech.joints[std::size_t(j)];
    const int jnt = m->dof_jntid[j];  // (a ball's or free joint's stiffness is refused: checkBallJoint)
    const bool scalar = m->jnt_type[jnt] == mjJNT_HINGE || m->jnt_type[jnt] == mjJNT_SLIDE;
    if (!(flags & mjDSBL_PASSIVE)) {
      p.stiffness = scalar ? m->jnt_stiffness[jnt] : 0.0;
      p.rest = scalar ? m->qpos_spring[m->jnt_qposadr[jnt]] : 0.0;
      p.viscous = m->dof_damping[j];
    }
    if (!(flags & (mjDSBL_FRICTIONLOSS | mjDSBL_CONSTRAINT))) p.coulomb = m->dof_frictionloss[j];
    p.armature = m->dof_armature[j];
    if (p.coulomb > 0)
      out.notes.push_back("joint '" + out.joints[std::size_t(j)].name + "': frictionloss " + num(p.coulomb) +
                          " read as Coulomb friction smoothed over a rate width of " + num(p.coulomb_width) + " (MuJoCo: exact stiction)");
    any = any || p.stiffness != 0 || p.viscous != 0 || p.coulomb != 0 || p.armature != 0;
  }
  if (!any) mech.joints.clear();
}

// A loop closure as read: body a's point tied to body b's, in their frames (world-aligned at qpos0).
// `where` starts each error about it ("FILE: equality 'pin_C'").
struct Tie {
  BodyRef a, b;
  Vec3 pa, pb;
  bool weld;
  std::string where;
  Vec3 p1 = Vec3::Zero(), p2 = Vec3::Zero();  // the anchors, world, at qpos0
};

// The ties read so far, each also a Closure for the report (out.closures, in the same order).
struct Ties {
  const mjModel* m;
  const std::vector<Frame>& frame;
  LoadedModel& out;
  std::vector<Tie> list;
  // Body b1's point p1 tied to body b2's p2 (world, at qpos0).
  void add(const std::string& where, const std::string& name, bool weld, bool rotation, int b1, int b2, const Vec3& p1, const Vec3& p2) {
    const Frame& f1 = frame[std::size_t(b1)];
    const Frame& f2 = frame[std::size_t(b2)];
    if (f1.link == f2.link)
      throw ModelFileError(where + " ties body '" + nameOf(m, mjOBJ_BODY, b1, "body") + "' to '" + nameOf(m, mjOBJ_BODY, b2, "body") +
                           "', which no joint separates (they move as one body)");
    list.push_back({ref(f1.link), ref(f2.link), p1 - f1.origin, p2 - f2.origin, rotation, where, p1, p2});
    Closure c;
    c.name = name;
    c.kind = weld ? "weld" : "connect";
    c.body1 = nameOf(m, mjOBJ_BODY, b1, "body");
    c.body2 = nameOf(m, mjOBJ_BODY, b2, "body");
    c.link1 = f1.link, c.link2 = f2.link, c.point1 = p1 - f1.origin, c.point2 = p2 - f2.origin;
    out.closures.push_back(c);
  }
};

Mat3 rotationOf(const mjData* d, int b) { return Mat3(Eigen::Map<const RowMat3>(d->xmat + 9 * b)); }

// The file's equalities, connect and weld, as ties (points and rows at qpos0).
void readEqualities(const std::string& path, const mjModel* m, const mjData* d, Ties& ties) {
  LoadedModel& out = ties.out;
  const bool equalities = !(m->opt.disableflags & (mjDSBL_EQUALITY | mjDSBL_CONSTRAINT));
  if (!equalities && m->neq > 0) out.notes.push_back(std::to_string(m->neq) + " equalities off (<option><flag equality=\"disable\"/>)");
  for (int e = 0; equalities && e < m->neq; ++e) {
    const std::string name = nameOf(m, mjOBJ_EQUALITY, e, m->eq_type[e] == mjEQ_WELD ? "weld" : "connect");
    if (m->eq_type[e] == mjEQ_JOINT || m->eq_type[e] == mjEQ_TENDON) continue;  // couplings: joint_elements.cpp
    if (m->eq_type[e] != mjEQ_CONNECT && m->eq_type[e] != mjEQ_WELD)
      throw ModelFileError(path + ": equality '" + name + "' is a distance coupling; dynlab reads <connect>, <weld>, <joint> and <tendon> (fixed tendons)");
    if (!m->eq_active[e]) {
      out.notes.push_back("equality '" + name + "' is inactive in the file (active=\"false\"): not held");
      continue;
    }
    const int b1 = m->eq_obj1id[e], b2 = m->eq_obj2id[e];
    const mjtNum* data_e = m->eq_data + mjNEQDATA * e;
    const Mat3 R1 = rotationOf(d, b1), R2 = rotationOf(d, b2);
    const bool weld = m->eq_type[e] == mjEQ_WELD;
    // connect: data = (anchor in body1, anchor in body2); weld: (anchor in body2, relpose in body1: point, quaternion, torquescale).
    const Vec3 p1 = Vec3(d->xpos + 3 * b1) + R1 * Vec3(data_e + (weld ? 3 : 0));
    const Vec3 p2 = Vec3(d->xpos + 3 * b2) + R2 * Vec3(data_e + (weld ? 0 : 3));
    bool rotation = weld;
    if (weld) {
      const Eigen::Quaterniond rel(data_e[6], data_e[7], data_e[8], data_e[9]);
      if ((R1.transpose() * R2 - rel.normalized().toRotationMatrix()).norm() > 1e-9)
        throw ModelFileError(path + ": weld '" + name + "' holds a relative orientation (relpose) other than the one at the reference pose; "
                             "dynlab needs a file written in its closed pose (leave relpose out)");
      if (data_e[10] == 0) {
        rotation = false;
        out.notes.push_back("weld '" + name + "' has torquescale 0: held as a connect (no rotation rows)");
      }
    }
    ties.add(path + ": equality '" + name + "'", name, weld, rotation, b1, b2, p1, p2);
  }
}

// Closures given beside the file, as ties: links by name, points in their frames (a weld holds the
// relative orientation at qpos0, as an MJCF weld without relpose does).
void readGivenClosures(const std::string& path, const mjModel* m, const mjData* d, const LoadOptions& options, Ties& ties) {
  for (const GivenClosure& g : options.closures) {
    auto body = [&](const std::string& field, const std::string& name) {
      const int b = name == "world" ? 0 : mj_name2id(m, mjOBJ_BODY, name.c_str());
      if (b < 0)
        throw ModelFileError(g.where + "." + field + ": expected a link of " + path + ", got '" + name +
                             "' (a link fixed to its parent is fused into it by MuJoCo: name the parent, with the point in its frame)");
      return b;
    };
    if (g.kind != "connect" && g.kind != "weld") throw ModelFileError(g.where + ".kind: expected \"connect\" or \"weld\", got '" + g.kind + "'");
    // Names head the trace's force columns: one per closure.
    for (const Closure& c : ties.out.closures)
      if (c.name == g.name) throw ModelFileError(g.where + ".name: '" + g.name + "' names a closure of " + path + " too (expected a new name)");
    const int b1 = body("body1", g.body1), b2 = body("body2", g.body2);
    const Vec3 p1 = Vec3(d->xpos + 3 * b1) + rotationOf(d, b1) * g.point1;
    const Vec3 p2 = g.has_point2 ? Vec3(Vec3(d->xpos + 3 * b2) + rotationOf(d, b2) * g.point2) : p1;
    ties.add(g.where + " ('" + g.name + "')", g.name, g.kind == "weld", g.kind == "weld", b1, b2, p1, p2);
  }
}

PointClosure<Spatial>::Rows rowsOf(bool weld) { return weld ? PointClosure<Spatial>::all() : PointClosure<Spatial>::translations(); }

int rank(const Eigen::MatrixXd& A) {
  if (A.rows() == 0) return 0;
  Eigen::FullPivLU<Eigen::MatrixXd> lu(A);
  lu.setThreshold(1e-9);
  return int(lu.rank());
}

// The model's extent L at qpos0: the diagonal of the box around its moving bodies' frames and its loop
// anchors (closure_rows.h scales the rows' units by it; a point model counts as 1 m).
double extentOf(const std::vector<Frame>& frame, const std::vector<Tie>& ties) {
  Eigen::AlignedBox3d box;
  for (const Frame& f : frame)
    if (f.link >= 0) box.extend(f.origin);
  for (const Tie& t : ties) box.extend(t.p1), box.extend(t.p2);
  const double L = box.isEmpty() ? 0.0 : box.diagonal().norm();
  return L > 1e-9 ? L : 1.0;
}

// Each loop closes at qpos0 (MuJoCo places connect's second anchor there; a weld's relpose was
// checked); the description keeps the rows closure_rows.h chooses (a planar loop's out-of-plane rows
// dropped, in whatever plane it lies), a closure left with none noted and not held twice. Every row
// of every closure stays in out.every_closure_row for the runs' check.
void keepIndependentRows(const std::string& path, const std::vector<Tie>& ties, double extent, LoadedModel& out) {
  MechanismModel<Spatial>& mech = out.mechanism;
  ConstrainedMechanism<Spatial> full(mech);
  for (std::size_t i = 0; i < ties.size(); ++i)
    if (const double gap = full.residual(int(i), out.q0); !(gap <= 1e-9))
      throw ModelFileError(ties[i].where + " does not hold at the reference pose (gap " + num(gap) +
                           "); write the file in its closed pose");
  RowCandidates rows;
  rows.extent = extent;
  for (const auto& body : out.mechanism.tree.bodies) rows.slide.push_back(body.joint == JointType::Prismatic);
  for (std::size_t i = 0; i < ties.size(); ++i) {
    rows.names.push_back(out.closures[i].name);
    const auto all = rowsOf(ties[i].weld);
    for (int k = 0; k < 6; ++k)
      if (all[std::size_t(k)]) rows.translation.push_back(k >= 3), rows.closure.push_back(int(i));
  }
  const std::vector<bool> kept = chooseIndependentRows(full, out.q0, rows, path);
  std::vector<std::array<bool, 6>> masks(ties.size());
  for (std::size_t i = 0, r = 0; i < ties.size(); ++i) {
    const auto all = rowsOf(ties[i].weld);
    for (int k = 0; k < 6; ++k) {
      if (!all[std::size_t(k)]) continue;
      const bool independent = kept[r++];
      masks[i][std::size_t(k)] = independent;
      (independent ? out.closures[i].kept : out.closures[i].dropped).push_back(kRowNames[k]);
    }
    out.every_closure_row.push_back({out.closures[i].name, mech.constraints[i], out.closures[i].dropped});
  }
  mech.constraints.clear();
  std::vector<Closure> closures;
  for (std::size_t i = 0; i < ties.size(); ++i) {
    if (out.closures[i].kept.empty()) {
      out.notes.push_back("closure '" + out.closures[i].name + "': every row repeats other closures' rows; not held twice");
      continue;
    }
    mech.constraints.push_back(std::make_shared<PointClosure<Spatial>>(ties[i].a, ties[i].pa, ties[i].b, ties[i].pb, masks[i]));
    closures.push_back(out.closures[i]);
  }
  out.closures = closures;
}

// A body drawn as rods (no geom) reaches to its loop anchors too, so the drawn loop closes.
void reachLoopAnchors(LoadedModel& out) {
  auto reach = [&](int link, const Vec3& point) {
    const auto& bones = out.drawing.bones;
    if (link >= 0 && std::any_of(bones.begin(), bones.end(), [&](const Bone& b) { return b.link == link; }))
      out.drawing.bones.push_back({link, Vec3::Zero(), point});
  };
  for (const Closure& c : out.closures) reach(c.link1, c.point1), reach(c.link2, c.point2);
}

// Last, dynlab's own elements beside the file (rolling wheels, plane contacts), and the mechanism's
// freedom at q0: coordinates minus the rank of the bilateral rows there (a contact's row is one-sided).
void addElementsAndFreedom(const std::string& path, const mjModel* m, const mjData* d, const std::vector<Frame>& frame,
                           const LoadOptions& options, LoadedModel& out) {
  std::vector<int> link;
  std::vector<Vec3> origin;
  splitFrames(frame, link, origin);
  detail::addElements(path, m, d, link, origin, options, out);
  MechanismModel<Spatial> bilateral = out.mechanism;
  bilateral.constraints.clear();
  for (const auto& c : out.mechanism.constraints)
    if (!c->unilateral()) bilateral.constraints.push_back(c);
  ConstrainedMechanism<Spatial> reduced(bilateral);
  VecN phi;
  MatN G;
  reduced.constraint(out.q0, phi, G);
  out.dof = m->nv - rank(Eigen::MatrixXd(G));
}

}  // namespace

// Compiled and checked, then read at the reference pose: the trees, the joints, the loop closures
// (their independent rows), dynlab's own elements.
LoadedModel load(const std::string& path, const LoadOptions& options) {
  LoadedModel out;
  out.file = path;
  std::string warnings;
  out.compiled = detail::compile(path, &warnings, options.package_paths);
  const mjModel* m = out.compiled->m;
  if (!warnings.empty() && warnings != " ") out.notes.push_back("MuJoCo: " + warnings);
  out.notes.insert(out.notes.end(), out.compiled->notes.begin(), out.compiled->notes.end());
  checkSupported(path, m, options, out.notes);
  // dynlab has no geom-geom contact: MuJoCo's copies (cross-check, bench) run without it too.
  out.compiled->m->opt.disableflags |= mjDSBL_CONTACT;
  // The reference pose: MuJoCo's kinematics at qpos0 (anchors, axes, centres of mass, principal axes).
  detail::MujocoGuard guard;
  DataPtr data;
  MUJOCO_CALL(path, data.reset(mj_makeData(m)));
  if (!data) throw ModelFileError(path + ": MuJoCo could not make its data");
  mjData* d = data.get();
  MUJOCO_CALL(path, mj_kinematics(m, d));
  checkNumbers(path, m, d);
  out.timestep = m->opt.timestep;
  out.q0 = VecN::Zero(m->nq);
  for (int i = 0; i < m->nq; ++i) out.q0[i] = m->qpos0[i];

  const std::vector<Frame> frame = readTree(path, m, d, out);
  readJointProperties(m, out);
  // Loop closures: the file's equalities, then the closures given beside it, every row at first.
  Ties ties{m, frame, out, {}};
  readEqualities(path, m, d, ties);
  readGivenClosures(path, m, d, options, ties);
  MechanismModel<Spatial>& mech = out.mechanism;
  for (const Tie& t : ties.list) mech.constraints.push_back(std::make_shared<PointClosure<Spatial>>(t.a, t.pa, t.b, t.pb, rowsOf(t.weld)));
  if (const std::string why = mech.validate(); !why.empty()) throw ModelFileError(path + ": " + why);
  if (!ties.list.empty()) {
    keepIndependentRows(path, ties.list, extentOf(frame, ties.list), out);
    reachLoopAnchors(out);
  }
  detail::addJointElements(path, m, options, out);
  addElementsAndFreedom(path, m, d, frame, options, out);
  // The file's actuators and the run's start: q0 at rest, or the keyframe asked for (actuators.cpp).
  detail::readActuators(path, m, out);
  detail::readTendons(m, out);
  detail::readStart(path, m, options.key, out);
  return out;
}

}  // namespace dyn::model_file
