// Mechanisms from model files: an MJCF or URDF file read by MuJoCo's own parser (Debian's
// libmujoco-dev 2.2.2: mj_loadXML applies MuJoCo's defaults and computes inertias from geoms), its
// compiled mjModel mapped onto the description (mechanism.h, spatial algebra):
//   bodies       each MuJoCo body's joints in order, one tree body per joint (a body with two joints:
//                a massless carrier, then the body); a body without joints is fused into its parent
//   frames       every tree body's frame sits on its joint's anchor and is world-aligned at the
//                file's reference pose qpos0, so X_tree = (R(a, q0), o_i − o_parent) for a hinge and
//                (1, o_i − o_parent − a q0) for a slide; coordinates are MuJoCo's qpos (θ = qpos)
//   inertias     body_mass, xipos, ximat, body_inertia at qpos0, summed over fused bodies
//   joints       stiffness / springref, damping, frictionloss (as Coulomb smoothed over a rate width);
//                range limits as one-sided rows with events (joint_limit.h), after the closures
//   couplings    <equality> joint and tendon (fixed tendons) as one row each, MuJoCo's polycoef form
//                (coupling.h); fixed tendons also drive actuators and carry their own springs and
//                dampers (actuators.h); spatial tendons, tendon limits and muscles refused
//   closures     <equality> connect (3 translation rows) and weld (6 rows) as point closures, with the
//                rows that are identically dependent on the others (a planar loop's out-of-plane
//                rows) dropped and named
//   elements     dynlab's own, given beside the file (LoadOptions: GivenRolling, GivenContact): a
//                wheel rolling without slip and a ball against a plane (unilateral), after the closures
// Anything else the description cannot represent is a one-line ModelFileError naming the file, the
// element and what is supported. The file is parsed once, from the checked files, in a child process
// with time and memory limits (compile.cpp, fence.h), after its size is counted (sizes.cpp); the
// compiled model is kept (LoadedModel::compiled) for MuJoCo's own cross-check and simulation. This
// folder is the only code that includes MuJoCo.
#pragma once
#include <array>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "physics/mechanism.h"
#include "physics/triangle_mesh.h"
#include "physics/types.h"

namespace dyn::model_file {

// A file larger than this is refused before it is parsed (an included model file too).
inline constexpr std::size_t kMaxFileBytes = 4u << 20;
// What a model file may name (meshes, textures, height fields, includes): each file at most
// kMaxAssetBytes, at most kMaxAssetFiles names, at most kMaxAssetsBytes in all; only regular files
// (resolved through links) inside the model file's folder, the ROS package it sits in, or a package
// folder a package:// name finds (mujoco_call.h's FileSearch). Checked before MuJoCo parses.
inline constexpr std::size_t kMaxAssetBytes = 16u << 20;
inline constexpr std::size_t kMaxAssetsBytes = 64u << 20;
inline constexpr int kMaxAssetFiles = 256;
// What a model file may write, its includes expanded, counted before MuJoCo compiles it (sizes.cpp):
// far past any real model (MuJoCo Menagerie's arms and humanoids have tens of bodies and joints and
// at most a few hundred geoms; a loop mechanism a handful of equalities; dynlab moves at most kMaxDof
// coordinates), far below what makes MuJoCo's parser slow or crash (47,000 bodies crash MuJoCo
// 2.2.2's parser after 11 s; 100,000 take 92 s and 1.7 GB). See assets/models/README.md.
inline constexpr int kMaxBodies = 1000;     // MJCF bodies, URDF links
inline constexpr int kMaxJoints = 1000;
inline constexpr int kMaxGeoms = 5000;      // MJCF geoms, URDF visual and collision shapes
inline constexpr int kMaxEqualities = 200;  // MJCF equality constraints (≤ 6 rows each)
inline constexpr int kMaxElements = 1000000;  // XML elements visited while counting
inline constexpr int kMaxIncludeDepth = 8;
// MuJoCo's parser runs in a child process (fence.h): at most this long (wall clock and CPU time)
// and this much memory past the caller's; a crash, a timeout or running out is a one-line refusal.
inline constexpr double kParseSeconds = 20;
inline constexpr std::size_t kParseMemoryBytes = std::size_t(1) << 30;
// MuJoCo's data for a model (mjData: nstack numbers and its buffer) at most this large.
inline constexpr std::size_t kMaxDataBytes = std::size_t(256) << 20;

// One line: "FILE: what is wrong; what is supported".
struct ModelFileError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// A closure row's name (wx wy wz x y z, world axes) as its place in a spatial force (moment, force); −1 if
// it names none.
inline constexpr const char* kRowNames[6] = {"wx", "wy", "wz", "x", "y", "z"};
inline int rowIndex(const std::string& row) {
  for (int i = 0; i < 6; ++i)
    if (row == kRowNames[i]) return i;
  return -1;
}

// A loop closure as the file names it, and which of its rows the description keeps.
struct Closure {
  std::string name;   // the equality's name (or "connect #i")
  std::string kind;   // "connect" or "weld"
  std::string body1, body2;
  std::vector<std::string> kept, dropped;  // row names: wx wy wz x y z (world axes)
  int link1 = -1, link2 = -1;              // the tree bodies the anchors move with (−1: the world)
  Eigen::Vector3d point1 = Eigen::Vector3d::Zero(), point2 = Eigen::Vector3d::Zero();  // in their frames
};

// The description's constraints after the closures, in order: the file's joint limits (joint_limit.h,
// unilateral) and joint and fixed-tendon equalities (coupling.h), then dynlab's own elements given
// beside the file (GivenRolling, GivenContact below): a rolling wheel (physics/constraints/rolling.h)
// or a ball against a plane (plane_contact.h, unilateral).
struct Contact {
  std::string name;
  // "rolling" or "plane_contact" (given beside the file); from the file itself: "joint_limit" (one per
  // limited side, body: the joint's), "joint_coupling" or "tendon_coupling" (an <equality> <joint> or
  // <tendon>, body: its first joint's)
  std::string kind;
  std::string body;  // the MuJoCo body (URDF link) it is on
  int link = -1;     // the tree body it moves with
  double mu = 0;     // rolling: the skid report's μ (and Bullet's friction model); plane: Bullet's friction
  // A coupling row (an <equality> joint or tendon): its trace column is η, its generalised force.
  bool coupling() const { return kind == "joint_coupling" || kind == "tendon_coupling"; }
};

// What the file draws (drawing only: the dynamics never reads it). Each shape is fixed to a tree body
// (link −1: the world), its pose given in that body's frame (on its joint's anchor, world-aligned at q0).
struct Geom {
  enum class Shape { Sphere, Capsule, Cylinder, Box, Plane, Mesh };
  Shape shape = Shape::Sphere;
  std::string name, body;
  int link = -1;
  Eigen::Vector3d pos = Eigen::Vector3d::Zero();
  Eigen::Matrix3d rot = Eigen::Matrix3d::Identity();  // the shape's axes (capsule, cylinder: along z)
  // sphere: radius; capsule, cylinder: radius, half length; box: half extents; plane: half sizes x, y
  // (0: unbounded); mesh: the half extents of its vertices' box
  Eigen::Vector3d size = Eigen::Vector3d::Zero();
  std::shared_ptr<const TriangleMesh> mesh;  // a mesh's triangles in the shape's frame (shared by the geoms that draw it)
  std::array<float, 4> rgba{0.5f, 0.5f, 0.5f, 1.0f};
  bool file_color = false;  // rgba is the file's (a geom's or its material's), not MuJoCo's default grey
};

// A segment drawn for a moving body the file gives no geom: from its joint's anchor to each child's
// anchor and to its centre of mass, in its tree body's frame.
struct Bone {
  int link = -1;
  Eigen::Vector3d from = Eigen::Vector3d::Zero(), to = Eigen::Vector3d::Zero();
};

struct Drawing {
  std::vector<Geom> geoms;
  std::vector<Bone> bones;
  std::vector<std::string> notes;  // what is drawn other than as written (an ellipsoid as its bounding capsule, ...)
};

// A joint as the file names it (one per rate, in v's order: a ball joint's three rates NAME_wx, NAME_wy,
// NAME_wz, a free joint's six NAME_x … NAME_wz).
struct Joint {
  std::string name, body, type;  // type: "hinge", "slide", "ball" or "free"
  int qpos = 0;                  // its coordinate in q (a ball's or free joint's rotation rates: the quaternion's w)
  bool limited = false;
  double lower = 0, upper = 0;
};

// A fixed tendon's length as a linear form of the coordinates (MuJoCo's ten_length over qpos): l = Σ coef_k q_k.
struct TendonTerm {
  int coordinate = 0;  // the joint's rate in v (its torque in τ)
  double coef = 1;
  int qpos = -1;       // its coordinate in q when that differs (after a ball's quaternion); −1: coordinate
  // The same joint and coefficient (qpos follows from the joint).
  bool operator==(const TendonTerm& o) const { return coordinate == o.coordinate && coef == o.coef; }
};

// An actuator as the file writes it (MuJoCo's <motor>, <position>, <velocity>, <general> on a hinge or
// slide joint or a fixed tendon, without activation dynamics), read from the compiled model: MuJoCo's
// affine law on its path's length l = Σ coef_k q_k (a joint: its coordinate, coef 1)
//   u = ctrl clamped to [ctrl_lower, ctrl_upper] when ctrl_limited,  l_a = gear l,  l_a' = gear l'
//   force = gain u + bias[0] + bias[1] l_a + bias[2] l_a'  clamped to [force_lower, force_upper] when force_limited
// and the torque on each coordinate of its path gear · coef_k · force (actuators.h applies it).
struct Actuator {
  std::string name, joint, tendon;  // what it drives: a joint or a fixed tendon (the other "")
  std::vector<TendonTerm> path;
  double gear = 1, gain = 0;
  std::array<double, 3> bias{0, 0, 0};
  bool ctrl_limited = false, force_limited = false;
  double ctrl_lower = 0, ctrl_upper = 0, force_lower = 0, force_upper = 0;
};

// A fixed tendon's own spring, damper and friction (MuJoCo's passive tendon forces, its frictionloss as a
// joint's: Coulomb smoothed over a rate width, JointProperties::friction) on its length l = Σ coef_k q_k:
//   f = stiffness (rest − l) − damping l' − frictionloss tanh(l'/w),  on each coordinate coef_k f.
struct TendonSpring {
  std::string name;
  std::vector<TendonTerm> path;
  double stiffness = 0, rest = 0, damping = 0, frictionloss = 0, friction_width = 1e-2;
};

// A closure with every one of its rows, the dropped ones too (what a run measures: closure_rows.h).
struct EveryRow {
  std::string name;
  ConstraintPtr<Spatial> rows;
  std::vector<std::string> dropped;  // row names
};

namespace detail {
struct Compiled;  // MuJoCo's compiled model (mujoco_call.h)
}

struct LoadedModel {
  std::string file;
  // The model MuJoCo compiled from the checked files, in the fence, once: MujocoReference and
  // MujocoSimulation start from it (nothing parses the file again).
  std::shared_ptr<const detail::Compiled> compiled;
  MechanismModel<Spatial> mechanism;
  VecN q0;                         // the file's reference pose qpos0 (closed: every loop holds there)
  std::vector<std::string> coordinates;  // per entry of q: its name (a quaternion's: NAME_qw … NAME_qz)
  std::vector<Joint> joints;       // per coordinate
  std::vector<std::string> bodies;  // per MuJoCo body that moves (the world and fused bodies left out)
  std::vector<Closure> closures;   // per mechanism constraint, first
  std::vector<EveryRow> every_closure_row;  // per closure of the file (one whose rows all repeat others' too)
  std::vector<Contact> contacts;   // per mechanism constraint after the closures (rolling, plane contacts)
  std::vector<std::string> notes;  // what is read but not enforced (limits, unused motors, ...)
  Drawing drawing;                  // what the renderer draws (beside the description, never in it)
  double timestep = 0;             // the file's <option timestep>
  std::vector<Actuator> actuators;  // the file's, driven by ctrl (actuators.h)
  std::vector<TendonSpring> tendons;  // the file's fixed tendons with stiffness, damping or frictionloss (actuators.h)
  std::vector<std::string> keyframes;  // the file's keyframes' names (LoadOptions::key picks one)
  // Where a run starts and the controls it holds: q0 at rest with every control 0, or the keyframe
  // chosen (its qpos, qvel and ctrl; key names it).
  VecN start_q, start_v, ctrl;
  std::string key;
  int dof = 0;                     // coordinates minus independent closure and rolling rows at q0 (contacts,
                                   // unilateral, not counted)
};

// A loop closure given beside the file (plain data; labs/generic/model_loops.h reads it from the lab JSON beside
// a URDF, which cannot express loops): held exactly as an MJCF <equality> connect or weld is.
struct GivenClosure {
  std::string where;              // where it was given, for errors: "FILE.loops.json: loops[0]"
  std::string name, kind;         // kind: "connect" (3 translation rows) or "weld" (6 rows)
  std::string body1, body2;       // link (MuJoCo body) names; "world" for the ground
  Eigen::Vector3d point1 = Eigen::Vector3d::Zero();  // in body1's frame (a URDF link's frame)
  bool has_point2 = false;        // false: point2 is where point1 sits at the reference pose
  Eigen::Vector3d point2 = Eigen::Vector3d::Zero();  // in body2's frame
};

// A wheel rolling without slip on the ground z = height (physics/constraints/rolling.h), given beside the
// file: 3 rows, x and y velocity-level (nonholonomic), z its rim's lowest point on the ground. The file
// is written with the wheel on the ground at the reference pose.
struct GivenRolling {
  std::string where;  // for errors: "FILE.loops.json: rolling[0]"
  std::string name, body;  // body: a link (MuJoCo body) the wheel is fixed to
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // the disk's centre, in the body's frame
  Eigen::Vector3d axle = Eigen::Vector3d::UnitY();   // its axle, in the body's frame
  double radius = 0, height = 0, mu = 0;  // m; the ground z = height; μ for the skid report
};

// A ball of radius ρ fixed to a body against the half-space normal·x ≥ height (plane_contact.h): one
// unilateral row, frictionless in the hand engine (μ: Bullet's friction), rigid (stiffness 0: plastic
// touchdowns, lift-off) or compliant. The ball may not start inside the plane.
struct GivenContact {
  std::string where;  // for errors: "FILE.loops.json: contacts[0]"
  std::string name, body;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();     // the ball's centre, in the body's frame
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();   // the plane's outward normal, world
  double radius = 0, height = 0, mu = 0, stiffness = 0, damping = 0;
};

struct LoadOptions {
  // Geoms that may collide load all the same (dynlab has no geom-geom contact; MuJoCo's copies run
  // with contact disabled); false: that is noted once, true: not noted (--ignore-contacts).
  bool ignore_contacts = false;
  std::string key;  // a keyframe's name: runs start from it (LoadedModel::start_q, start_v, ctrl); "": q0 at rest
  // Folders holding the packages package://NAME/… names (DIR/NAME, or DIR itself named NAME), searched
  // before the folders above the file and ROS_PACKAGE_PATH's (--package-path)
  std::vector<std::string> package_paths;
  std::vector<GivenClosure> closures;  // held after the file's own equalities, in this order
  std::vector<GivenRolling> rolling;   // then these, in this order
  std::vector<GivenContact> contacts;  // then these
  // Joint range limits held as one-sided rows (joint_limit.h); false: read and noted, not held (the data
  // labs, whose controllers keep their arms inside the range: their runs stay as they were).
  bool joint_limits = true;
};

// Reads FILE (MJCF or URDF). Throws ModelFileError.
LoadedModel load(const std::string& path, const LoadOptions& options = {});

// MuJoCo's own M(q) (mj_fullM) and bias C(q, v) v + G(q) (qfrc_bias) from the same compiled model,
// for cross-checks: the same coordinates as LoadedModel.
class MujocoReference {
 public:
  explicit MujocoReference(const LoadedModel& model);
  ~MujocoReference();
  MujocoReference(const MujocoReference&) = delete;
  MujocoReference& operator=(const MujocoReference&) = delete;
  int nv() const;
  MatN massMatrix(const VecN& q);
  VecN bias(const VecN& q, const VecN& v);
  // MuJoCo's actuator forces on the coordinates (qfrc_actuator) at (q, v) with controls ctrl.
  VecN actuation(const VecN& q, const VecN& v, const VecN& ctrl);
  // MuJoCo's passive forces on the coordinates (qfrc_passive: joints' and tendons' springs and dampers).
  VecN passive(const VecN& q, const VecN& v);
  // MuJoCo's own measure of the loops at q: |p1 − p2|∞ (m) over the file's active connects (and welds'
  // points) from its own kinematics (xpos, xmat) — a closure checked by the other engine's geometry; −1
  // when the file has none (loops given beside it are not MuJoCo's).
  double closure(const VecN& q);

 private:
  struct Impl;
  Impl* impl_;
};

// MuJoCo's own simulation of the same compiled model (mj_step), for the bench: its constraint solver and soft
// equalities as the file sets them, at a given step and with the semi-implicit Euler integrator
// (MuJoCo's default, first order) or RK4 (rk4: for tests at the hand engine's order), from a state in
// the same coordinates as LoadedModel, its controls held at the model's ctrl; contacts between geoms
// off (dynlab has none), or on (contacts: a lab's contact written as geoms for MuJoCo, labs/mujoco_twin.h).
class MujocoSimulation {
 public:
  MujocoSimulation(const LoadedModel& model, double dt, bool rk4 = false, bool contacts = false);
  ~MujocoSimulation();
  MujocoSimulation(const MujocoSimulation&) = delete;
  MujocoSimulation& operator=(const MujocoSimulation&) = delete;
  void reset(const VecN& q, const VecN& v);
  // One mj_step; false when MuJoCo warned that the state blew up (it then resets its data itself).
  bool step();
  void state(VecN& q, VecN& v) const;
  std::string describe() const;  // "MuJoCo 2.2.2 mj_step, Euler, Newton solver (100 iterations)"

 private:
  struct Impl;
  Impl* impl_;
};

}  // namespace dyn::model_file
