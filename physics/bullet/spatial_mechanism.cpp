// Bullet 3.24 (double precision) reference model of a spatial mechanism description: the trees as one
// fixed-base btMultiBody (every body whose parent is −1 hangs from the base, which is the world),
// revolute and prismatic joints about their axes at the X_tree placements, and two constraint kinds:
//   rolling, in one of two models (BulletHints::rolling):
//     NoSlip    RollingNoSlipConstraint (rolling_constraint.h): the description's three rows, bilateral;
//     Friction  a ball of the wheel's radius on the wheel link (under the centre it touches the ground
//               where an upright disk does) against the plane z = h, friction μ (contact_balls.h);
//   plane_contact: a ball of radius ρ at c_b on its link against the plane n·x = h (any unit n), friction
//             μ, restitution 0, rigid or with the contact stiffness and damping (k_e, d_e) of the
//             description (contact_balls.h: the shared ball-on-plane model, and what Bullet does with
//             ρ < 1 mm, stiffness and its speculative touchdown).
//   joint_limit, joint_coupling: joint_constraints.h (btMultiBodyJointLimitConstraint, btMultiBodyGearConstraint);
//   point_closure (loop closures, e.g. from a model file): a btMultiBodyPoint2Point when it holds
//             translations only, a btMultiBodyFixedConstraint (the body frames kept aligned) when it
//             holds a rotation row; Bullet then holds all 3 (or 6) rows, so rows the description
//             leaves out must be identically satisfied there (as the model-file loader's dropped
//             rows are: out-of-plane rows of a planar loop). Its force: B's share of the impulses
//             / dt (point-to-point +λ, fixed −λ, rows written for A; moment rows 3..5), at the pivot.
// Ball and free joints: spherical_links.h (a ball a spherical link, a free joint three prismatic links then
// one, on the fixed base). Other constraint kinds, cut joints and payloads are refused (std::invalid_argument: "not yet").
// External forces (description.forces): evaluated at the step's start (time t; the point's place p and
// spatial velocity V from the description's kinematics at (θ, θ')) and applied to the body's Bullet link
// as the force f at its centre of mass and the torque τ + (p − c) × f, world axes (Bullet maps them to
// its joints as Jᵀ F inside its one step, as the hand engine does at every stage); the books add
// (J_Pᵀ F)·Δθ, the held force along the step's first-order displacement.
// The force reported for a ball contact is the plane's on the ball over the step (impulses / dt: the
// normal force η n plus, when μ > 0, the friction force; n·f = η ≥ 0), with its moment about the
// contact point at the step's start (plane_contact: c − ρ n; ~0 unless friction acts on a stand-in
// ball); the gap is the description's, from the state. The rolling force reported is the ground's on
// the wheel, a pure force at the contact point the step used (moment ~0): NoSlip's predicted
// end-of-step point, the friction contact's start-of-step point. Bullet's contact friction holds at the
// step's start geometry, so a
// friction wheel's state reads a slip of v φ' dt while it grips (the NoSlip rows avoid this; see
// rolling_constraint.h); its contact's own slip (start heading, new velocities) is ~1e-12 m/s.
//
// Links. Bullet puts a link's frame at its centre of mass with its inertia diagonal; the description
// puts it at the joint with a full 6×6 inertia. Each Bullet link is the description's body frame
// turned onto its principal axes (E_p: body → link coordinates, identity when the inertia is already
// diagonal) and moved to its centre of mass c. With X_tree = {E_t, r_t} (parent body → joint frame):
//   rotParentToThis = E_p E_t E_p,parentᵀ,  pivot offset e = E_p,parent (r_t − c_parent),
//   pivot → centre of mass d = E_p c,        joint axis E_p axis (this link's frame)
// and Bullet's joint coordinates are the description's θ, θ' one to one (self-checked at start).
// Armature (a joint's rotor inertia a, JointProperties): btMultiBody has none, so each such joint gets
// a rotor link after the description's links, hung from the joint's parent at its anchor, turning
// about its axis (a slide's: a screw), geared to it by a btMultiBodyGearConstraint θ'_r + G θ' = 0
// with G = kRotorGear, of isotropic inertia a/G² and tiny mass: its kinetic energy ½ (a/G²)(G θ' −
// ω_parent·k)² is ½ a θ'² up to a cross term a θ' ω_parent·k / G, which the description leaves out
// (MuJoCo's armature is the limit G → ∞). The gear row is solved by PGS with the loops.
// Massless bodies (the unicycle's x, y, z and heading carriers) get mass and principal inertias of
// 1e-9 × the model's largest: Bullet needs them positive, and their effect is linear in them (the
// tests show 1e-6 × changes nothing at their tolerances).
//
// Settings (shared/notes/bullet-reference.md): gravity from the description, PGS with
// BulletHints::solver_iterations, no damping, no joint-speed cap, never sleep, impulse caps 1e12, a
// collider on every link (mask 0 but the balls' links: pitfall 1), and exactly one
// stepSimulation(dt, 0, dt) per step. Joint springs and friction are joint torques from the state at
// the step's start, as in the planar builder.
#include <btBulletDynamicsCommon.h>
#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyFixedConstraint.h>
#include <BulletDynamics/Featherstone/btMultiBodyGearConstraint.h>
#include <BulletDynamics/Featherstone/btMultiBodyPoint2Point.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <typeinfo>

#include "physics/bullet/bullet_mechanism.h"
#include "physics/bullet/bullet_mechanism_members.h"
#include "physics/bullet/bullet_world.h"
#include "physics/bullet/contact_balls.h"
#include "physics/bullet/joint_constraints.h"
#include "physics/bullet/rolling_constraint.h"
#include "physics/bullet/spherical_links.h"
#include "physics/constraints/plane_contact.h"
#include "physics/constraints/point_closure.h"
#include "physics/constraints/rolling.h"

#ifndef BT_USE_DOUBLE_PRECISION
#error "spatial_mechanism.cpp must be built against bullet-float64 (BT_USE_DOUBLE_PRECISION)"
#endif

namespace dyn::bullet {
namespace {

// A point closure itself: its subclass the point contact (point_contact.h) is not modelled here yet.
bool isPointClosure(const Constraint<Spatial>* k) { return k && typeid(*k) == typeid(PointClosure<Spatial>); }

using Pos = Spatial::Pos;
using Mat3 = Eigen::Matrix3d;

constexpr double kTiny = 1e-9;          // massless bodies: this × the model's largest mass / inertia
constexpr double kImpulseCap = 1e12;    // pitfall 2: Bullet's default caps are 100 and 1000 N·s
constexpr double kRotorGear = 1000.0;   // armature rotors: θ'_r = −G θ' (rad/rad; rad/m on a slide)

btVector3 bt(const Pos& p) { return {p.x(), p.y(), p.z()}; }
Pos eig(const btVector3& v) { return {v.x(), v.y(), v.z()}; }
btQuaternion quaternion(const Mat3& R) {  // the rotation taking v to R v
  btQuaternion q;
  btMatrix3x3(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2)).getRotation(q);
  return q;
}

// One description body as a Bullet link: principal frame E_p (body → link), centre of mass c (body
// frame), mass and principal inertias (tiny ones for massless bodies).
struct LinkFrame {
  Mat3 E_p = Mat3::Identity();
  Pos com = Pos::Zero();
  double mass = 0;
  Pos inertia = Pos::Zero();
};

std::vector<LinkFrame> linkFrames(const TreeModel<Spatial>& tree) {
  std::vector<LinkFrame> out(tree.bodies.size());
  double max_mass = 0, max_inertia = 0;
  std::vector<Mat3> Ic(tree.bodies.size());
  for (std::size_t i = 0; i < tree.bodies.size(); ++i) {
    const Spatial::Mat& I = tree.bodies[i].inertia;
    Spatial::massAndCom(I, out[i].mass, out[i].com);
    const Mat3 C = Spatial::skew(out[i].com);
    Ic[i] = I.block<3, 3>(0, 0) - out[i].mass * C * C.transpose();  // about the centre of mass
    max_mass = std::max(max_mass, out[i].mass);
    max_inertia = std::max(max_inertia, Ic[i].diagonal().maxCoeff());
  }
  const double tiny_mass = kTiny * (max_mass > 0 ? max_mass : 1.0);
  const double tiny_inertia = kTiny * (max_inertia > 0 ? max_inertia : 1.0);
  for (std::size_t i = 0; i < out.size(); ++i) {
    LinkFrame& l = out[i];
    if (!(l.mass > 0)) l.mass = tiny_mass;
    const Mat3 off = Ic[i] - Mat3(Ic[i].diagonal().asDiagonal());
    if (off.cwiseAbs().maxCoeff() <= 1e-15 * std::max(1e-300, Ic[i].cwiseAbs().maxCoeff())) {
      l.inertia = Ic[i].diagonal();
    } else {
      // Principal axes: link coordinates = Vᵀ body coordinates, V a proper rotation.
      Eigen::SelfAdjointEigenSolver<Mat3> eig(Ic[i]);
      Mat3 V = eig.eigenvectors();
      if (V.determinant() < 0) V.col(2) = -V.col(2);
      l.E_p = V.transpose();
      l.inertia = eig.eigenvalues();
    }
    for (int k = 0; k < 3; ++k) l.inertia[k] = std::max(l.inertia[k], tiny_inertia);
  }
  return out;
}

}  // namespace

template <>
struct BulletMechanism<Spatial>::Impl {
  // A rolling constraint of the description and its Bullet model.
  struct Wheel {
    int constraint = -1, link = -1;
    const Rolling* rolling = nullptr;
    btVector3 centre, axle;                       // Bullet link frame
    RollingNoSlipConstraint* noslip = nullptr;    // NoSlip
    int ball = -1;                                // Friction: its ball in `balls`
    btVector3 start_point{0, 0, 0};               // the no-slip contact point at the last step's start
  };
  // A plane_contact of the description: a ball in `balls`.
  struct Contact {
    int constraint = -1, link = -1, ball = -1;
    const PlaneContact<Spatial>* plane = nullptr;
    btVector3 centre;                             // Bullet link frame
    btVector3 start_point{0, 0, 0};               // c − ρ n at the last step's start
  };

  // A point_closure of the description: its Bullet constraint, and the sign taking B's force to the
  // description's (a on b): −1 when the closure's a is the world (Bullet's A must be a link).
  struct Loop {
    int constraint = -1;
    bool weld = false;
    double sign = 1.0;
    btMultiBodyConstraint* bt = nullptr;
  };

  MechanismModel<Spatial> model;
  double dt;
  std::vector<Loop> loops;
  std::vector<LinkFrame> frames;
  std::vector<Wheel> wheels;
  std::vector<Contact> contacts;
  std::vector<Spatial::Vec> force;  // per description constraint, over the last step
  std::vector<int> rotor_joint;     // per rotor link (Bullet link n + k): the joint it is geared to
  std::string summary;
  const std::string& describe() const { return summary; }
  std::unique_ptr<TreeData<Spatial>> kinematics;  // the external forces' points (none: no forces)

  BulletWorld world;  // before what it holds: destroyed after it
  std::unique_ptr<btMultiBody> body;
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btMultiBodyLinkCollider>> colliders;
  std::vector<std::unique_ptr<btMultiBodyConstraint>> closures;
  ContactBalls balls;  // Friction wheels and plane contacts
  JointConstraints joint_constraints;  // joint limits and couplings

  Impl(const MechanismModel<Spatial>& m, double step, const VecN& q0, const VecN& v0) : model(m), dt(step), world(bt(Spatial::linear(m.tree.gravity)), m.bullet.solver_iterations) {
    check(q0, v0);
    frames = linkFrames(m.tree);
    if (!m.forces.empty()) kinematics = std::make_unique<TreeData<Spatial>>(m.tree);
    force.assign(m.constraints.size(), Spatial::Vec::Zero());
    btContactSolverInfo& info = world->getSolverInfo();
    // Two friction directions, clipped together to the cone (without the flag Bullet keeps one).
    info.m_solverMode |= SOLVER_USE_2_FRICTION_DIRECTIONS;
    info.m_solverMode &= ~SOLVER_DISABLE_IMPLICIT_CONE_FRICTION;
    buildTree();
    buildRotors();
    buildColliders();
    buildConstraints();
    setState(q0, v0);
    summarise();
  }

  ~Impl() { removeModel(world, body, colliders, closures, balls); }

  // What this model cannot build, said before anything is built.
  void check(const VecN& q0, const VecN& v0) const {
    const std::string who = "BulletMechanism (spatial): ";
    if (!(dt > 0.0) || !std::isfinite(dt)) throw std::invalid_argument(who + "dt must be a positive number");
    if (!model.payloads.empty()) throw std::invalid_argument(who + "spatial payloads: not yet");
    if (!model.bullet.cut_joints.empty()) throw std::invalid_argument(who + "cut joints: not yet");
    if (const std::string why = model.validate(); !why.empty()) throw std::invalid_argument(who + why);
    if (model.tree.bodies.empty()) throw std::invalid_argument(who + "the mechanism has no tree bodies");
    if (model.bullet.solver_iterations < 1) throw std::invalid_argument(who + "solver_iterations must be ≥ 1");
    const int n = model.treeDof();
    if (q0.size() != model.tree.nq() || v0.size() != n)
      throw std::invalid_argument(who + "q0 and v0 need " + (model.tree.nq() == n ? std::to_string(n) + " coordinates (one per tree joint)" :
                                                             std::to_string(model.tree.nq()) + " and " + std::to_string(n) + " coordinates (a quaternion per ball)"));
    for (int i = 0; i < int(model.joints.size()); ++i)
      if (model.tree.bodies[std::size_t(i)].joint == JointType::Ball && model.joints[std::size_t(i)].armature != 0)
        throw std::invalid_argument(who + "armature on a ball joint: not yet");
    for (int i = 0; i < n; ++i) {
      const auto& b = model.tree.bodies[std::size_t(i)];
      if (b.parent >= i) throw std::invalid_argument(who + "body " + std::to_string(i) + " comes before its parent");
      if (!(b.axis.norm() > 0) || !b.axis.allFinite())
        throw std::invalid_argument(who + "body " + std::to_string(i) + " has no joint axis");
    }
    for (std::size_t c = 0; c < model.constraints.size(); ++c) {
      const Constraint<Spatial>* k = model.constraints[c].get();
      if (const std::string why = JointConstraints::refusal(*k); !why.empty()) throw std::invalid_argument(who + why);
      if (!dynamic_cast<const Rolling*>(k) && !dynamic_cast<const PlaneContact<Spatial>*>(k) && !isPointClosure(k) && !JointConstraints::isJointKind(*k))
        throw std::invalid_argument(who + "constraint " + std::to_string(c) + " (" + k->kind() +
                                    "): not yet (only rolling, plane_contact and point_closure)");
    }
  }

  void buildTree() {
    const int n = model.treeDof();
    for (int i = 0; i < int(model.joints.size()); ++i)
      if (model.joints[std::size_t(i)].armature != 0) rotor_joint.push_back(i);
    body = std::make_unique<btMultiBody>(n + int(rotor_joint.size()), 1.0, btVector3(1, 1, 1), /*fixedBase=*/true, /*canSleep=*/false);
    body->setBaseWorldTransform(btTransform::getIdentity());
    static const LinkFrame world_frame;  // the base is the world: identity, centre at the origin
    for (int i = 0; i < n; ++i) {
      const auto& b = model.tree.bodies[std::size_t(i)];
      const LinkFrame& l = frames[std::size_t(i)];
      const LinkFrame& p = b.parent < 0 ? world_frame : frames[std::size_t(b.parent)];
      const btQuaternion rot = quaternion(l.E_p * b.X_tree.E * p.E_p.transpose());
      const btVector3 axis = bt(l.E_p * b.axis.normalized());
      const btVector3 e = bt(p.E_p * (b.X_tree.r - p.com)), d = bt(l.E_p * l.com);
      if (b.joint == JointType::Ball) {  // spherical_links.h: carriers fixed at the pivot, the body spherical
        const auto& ball = model.tree.balls[std::size_t(b.ball)];
        if (ballCarrier(model.tree, i)) body->setupFixed(i, l.mass, bt(l.inertia), b.parent, rot, e, d, true);
        else body->setupSpherical(i, l.mass, bt(l.inertia), b.parent, quaternion(l.E_p * ball.post * ball.pre.transpose() * p.E_p.transpose()), e, d, true);
      } else if (b.joint == JointType::Revolute)
        body->setupRevolute(i, l.mass, bt(l.inertia), b.parent, rot, axis, e, d, true);
      else
        body->setupPrismatic(i, l.mass, bt(l.inertia), b.parent, rot, axis, e, d, true);
    }
    // Rotors: the parent link's axes, the pivot on the joint's anchor, the centre on the pivot.
    double max_mass = 0;
    for (const LinkFrame& l : frames) max_mass = std::max(max_mass, l.mass);
    for (std::size_t k = 0; k < rotor_joint.size(); ++k) {
      const auto& b = model.tree.bodies[std::size_t(rotor_joint[k])];
      const LinkFrame& p = b.parent < 0 ? world_frame : frames[std::size_t(b.parent)];
      const double I = model.joints[std::size_t(rotor_joint[k])].armature / (kRotorGear * kRotorGear);
      const btVector3 axis = bt(p.E_p * b.X_tree.E.transpose() * b.axis.normalized());
      body->setupRevolute(n + int(k), kTiny * max_mass, btVector3(I, I, I), b.parent, btQuaternion::getIdentity(), axis,
                          bt(p.E_p * (b.X_tree.r - p.com)), btVector3(0, 0, 0), true);
    }
    body->finalizeMultiDof();
    // Pitfall 2: no damping, no velocity cap, never sleep.
    body->setLinearDamping(0.0);
    body->setAngularDamping(0.0);
    body->setMaxCoordinateVelocity(1e6);
    body->setMaxAppliedImpulse(kImpulseCap);
    body->setCanSleep(false);
    body->setHasSelfCollision(false);
    body->setUseGyroTerm(true);
    world->addMultiBody(body.get());
  }

  // Each rotor geared to its joint: rotor link A, the joint's link B, θ'_A + G θ'_B = 0 (velocity level).
  void buildRotors() {
    for (std::size_t k = 0; k < rotor_joint.size(); ++k) {
      const int r = model.treeDof() + int(k);
      auto g = std::make_unique<btMultiBodyGearConstraint>(body.get(), r, body.get(), rotor_joint[k], btVector3(0, 0, 0),
                                                           btVector3(0, 0, 0), btMatrix3x3::getIdentity(), btMatrix3x3::getIdentity());
      g->setGearRatio(kRotorGear);
      g->setMaxAppliedImpulse(kImpulseCap);
      world->addMultiBodyConstraint(g.get());
      g->finalizeMultiDof();
      closures.push_back(std::move(g));
    }
  }

  // Pitfall 1: every link gets a collider, with mask 0 (no contacts) unless a friction wheel's.
  void buildColliders() {
    shapes.push_back(std::make_unique<btSphereShape>(0.01));
    addLinkColliders(world, *body, body->getNumLinks(), shapes.front().get(), colliders);
  }

  // Rolling wheels (a NoSlip constraint or a Friction ball) and plane contacts (a ball), in description order.
  void buildConstraints() {
    const bool friction = model.bullet.rolling == RollingModel::Friction;
    std::vector<ContactBall> list;
    for (std::size_t c = 0; c < model.constraints.size(); ++c) {
      if (isPointClosure(model.constraints[c].get())) {
        buildLoop(int(c));
        continue;
      }
      if (JointConstraints::isJointKind(*model.constraints[c])) {
        joint_constraints.add(*world.operator->(), *body, model, int(c), kImpulseCap, closures);
        continue;
      }
      if (const auto* pc = dynamic_cast<const PlaneContact<Spatial>*>(model.constraints[c].get())) {
        Contact k;
        k.constraint = int(c), k.plane = pc, k.link = pc->body().index;
        const LinkFrame& l = frames[std::size_t(k.link)];
        k.centre = bt(l.E_p * (pc->centre() - l.com));
        const PlaneContactParams& p = pc->params();
        k.ball = int(list.size());
        list.push_back({k.link, k.centre, p.radius, bt(pc->normal()), p.height, p.mu, p.stiffness, p.damping});
        contacts.push_back(k);
        continue;
      }
      Wheel w;
      w.constraint = int(c);
      w.rolling = dynamic_cast<const Rolling*>(model.constraints[c].get());
      w.link = w.rolling->wheel().index;
      const LinkFrame& l = frames[std::size_t(w.link)];
      w.centre = bt(l.E_p * (w.rolling->centre() - l.com));
      w.axle = bt(l.E_p * w.rolling->axle());
      if (friction) {
        w.ball = int(list.size());
        list.push_back({w.link, w.centre, w.rolling->radius(), btVector3(0, 0, 1), w.rolling->groundHeight(), w.rolling->mu(), 0.0, 0.0});
      } else {
        auto r = std::make_unique<RollingNoSlipConstraint>(body.get(), w.link, w.centre, w.axle, w.rolling->radius(),
                                                           w.rolling->groundHeight());
        r->setMaxAppliedImpulse(kImpulseCap);
        world->addMultiBodyConstraint(r.get());
        w.noslip = r.get();
        closures.push_back(std::move(r));
      }
      wheels.push_back(w);
    }
    std::vector<btMultiBodyLinkCollider*> link_colliders;
    for (auto& c : colliders) link_colliders.push_back(c.get());
    balls.build(world, link_colliders, std::move(list), "BulletMechanism (spatial): ");
  }

  // A loop closure: pivots in the Bullet link frames (the world's: world coordinates), a link as A.
  void buildLoop(int c) {
    Attachment<Spatial> at = model.constraints[std::size_t(c)]->attachment();
    Loop loop;
    loop.constraint = c;
    for (int r = 0; r < 3; ++r) loop.weld = loop.weld || at.rows[std::size_t(r)];
    if (at.a.isWorld()) {
      std::swap(at.a, at.b);
      std::swap(at.point_a, at.point_b);
      loop.sign = -1.0;
    }
    static const LinkFrame world_frame;
    const LinkFrame& la = frames[std::size_t(at.a.index)];
    const LinkFrame& lb = at.b.isWorld() ? world_frame : frames[std::size_t(at.b.index)];
    const btVector3 pa = bt(la.E_p * (at.point_a - la.com)), pb = bt(lb.E_p * (at.point_b - lb.com));
    // A weld keeps the body frames aligned: each link's frame is its body's turned by E_p.
    auto frame = [](const Mat3& E) { return btMatrix3x3(E(0, 0), E(0, 1), E(0, 2), E(1, 0), E(1, 1), E(1, 2), E(2, 0), E(2, 1), E(2, 2)); };
    btMultiBody* b = at.b.isWorld() ? nullptr : body.get();
    const int link_b = at.b.isWorld() ? -1 : at.b.index;
    std::unique_ptr<btMultiBodyConstraint> k;
    if (loop.weld)
      k = b ? std::unique_ptr<btMultiBodyConstraint>(new btMultiBodyFixedConstraint(body.get(), at.a.index, b, link_b, pa, pb, frame(la.E_p), frame(lb.E_p)))
            : std::unique_ptr<btMultiBodyConstraint>(new btMultiBodyFixedConstraint(body.get(), at.a.index, nullptr, pa, pb, frame(la.E_p), frame(lb.E_p)));
    else
      k = b ? std::unique_ptr<btMultiBodyConstraint>(new btMultiBodyPoint2Point(body.get(), at.a.index, b, link_b, pa, pb))
            : std::unique_ptr<btMultiBodyConstraint>(new btMultiBodyPoint2Point(body.get(), at.a.index, nullptr, pa, pb));
    k->setMaxAppliedImpulse(kImpulseCap);
    world->addMultiBodyConstraint(k.get());
    k->finalizeMultiDof();
    loop.bt = k.get();
    closures.push_back(std::move(k));
    loops.push_back(loop);
  }

  // B's share of a loop's impulses over the step, as the description's force (a on b, world axes).
  Spatial::Vec loopForce(const Loop& l) const {
    Spatial::Vec f = Spatial::Vec::Zero();
    const double s = l.sign * (l.weld ? -1.0 : 1.0) / dt;
    for (int r = 0; r < 3; ++r) f[3 + r] = s * l.bt->getAppliedImpulse(r);
    if (l.weld)
      for (int r = 0; r < 3; ++r) f[r] = s * l.bt->getAppliedImpulse(3 + r);
    return f;
  }

  void summarise() {
    std::ostringstream s;
    s << "Bullet 3.24 btMultiBody (" << model.treeDof() << " links) hung from the world";
    if (!wheels.empty()) {
      if (model.bullet.rolling == RollingModel::NoSlip)
        s << ", " << wheels.size() << " rolling wheel(s) as a no-slip constraint (rows x, y velocity-level, z at the rim; bilateral)";
      else
        s << ", " << wheels.size() << " rolling wheel(s) as a sphere on a friction plane (μ = " << wheels.front().rolling->mu()
          << ", cone)";
    }
    if (!contacts.empty()) s << ", " << contacts.size() << " plane contact(s) as a sphere on a static plane";
    s << joint_constraints.describe();
    if (!rotor_joint.empty()) s << ", " << rotor_joint.size() << " armature rotor(s) geared " << kRotorGear << ":1";
    if (!loops.empty()) {
      const auto welds = std::count_if(loops.begin(), loops.end(), [](const Loop& l) { return l.weld; });
      s << ", " << loops.size() - std::size_t(welds) << " btMultiBodyPoint2Point and " << welds << " btMultiBodyFixedConstraint loop closure(s)";
    }
    s << ", PGS " << model.bullet.solver_iterations << " iterations";
    summary = s.str();
  }

  // A ball's A = E_p post (spherical_links.h), at its spherical link i.
  Mat3 sphericalAxes(int i) const { return frames[std::size_t(i)].E_p * model.tree.balls[std::size_t(model.tree.bodies[std::size_t(i)].ball)].post; }

  void setState(const VecN& q, const VecN& v) {
    for (int i = 0; i < model.treeDof(); ++i) {
      const auto& b = model.tree.bodies[std::size_t(i)];
      if (b.joint != JointType::Ball) {
        body->setJointPos(i, q[b.q_index]);
        body->setJointVel(i, v[i]);
      } else if (!ballCarrier(model.tree, i)) {
        double qb[4], wb[3];
        sphericalToBullet(sphericalAxes(i), q.data() + b.q_index, v.data() + i - 2, qb, wb);
        body->setJointPosMultiDof(i, qb);
        body->setJointVelMultiDof(i, wb);
      }
    }
    for (std::size_t k = 0; k < rotor_joint.size(); ++k) {  // each rotor turning with its gear
      body->setJointPos(model.treeDof() + int(k), 0.0);
      body->setJointVel(model.treeDof() + int(k), -kRotorGear * v[rotor_joint[k]]);
    }
    btAlignedObjectArray<btQuaternion> w2l;
    btAlignedObjectArray<btVector3> origin;
    body->forwardKinematics(w2l, origin);
    body->updateCollisionObjectWorldTransforms(w2l, origin);
    checkKinematics(q);
  }

  // Self-check of the link frames against the description's own kinematics (a convention slip shows here).
  void checkKinematics(const VecN& q) const {
    TreeData<Spatial> data(model.tree);
    positionKinematics(model.tree, q, data);
    for (int i = 0; i < model.treeDof(); ++i) {
      if (ballCarrier(model.tree, i)) continue;  // fixed in Bullet, turning in the description: both massless
      const LinkFrame& l = frames[std::size_t(i)];
      const Pos c = pointPosition(data, i, l.com);
      const Mat3 R = data.X_world[std::size_t(i)].E.transpose() * l.E_p.transpose();  // link → world
      double err = (eig(body->localPosToWorld(i, btVector3(0, 0, 0))) - c).norm();
      for (int k = 0; k < 3; ++k) {
        btVector3 e(0, 0, 0);
        e[k] = 1;
        err = std::max(err, (eig(body->localDirToWorld(i, e)) - R.col(k)).norm());
      }
      if (err > 1e-9 * (1 + c.norm()))
        throw std::logic_error("BulletMechanism (spatial): link " + std::to_string(i) + " disagrees with the description's kinematics");
    }
  }

  void state(VecN& q, VecN& v) const {
    const int n = model.treeDof();
    q.resize(model.tree.nq());
    v.resize(n);
    for (int i = 0; i < n; ++i) {
      const auto& b = model.tree.bodies[std::size_t(i)];
      if (b.joint != JointType::Ball) {
        q[b.q_index] = body->getJointPos(i);
        v[i] = body->getJointVel(i);
      } else if (!ballCarrier(model.tree, i)) {
        sphericalFromBullet(sphericalAxes(i), body->getJointPosMultiDof(i), body->getJointVelMultiDof(i), q.data() + b.q_index, v.data() + i - 2);
      }
    }
  }

  // The external forces at the step's start as Bullet link forces and torques; returns their
  // generalised force Σ J_Pᵀ F (for the books).
  VecN applyForces(double t, const VecN& q, const VecN& v) {
    VecN Q = VecN::Zero(model.treeDof());
    if (model.forces.empty()) return Q;
    forwardKinematics(model.tree, q, v, *kinematics);
    MatN J;
    for (const auto& ef : model.forces) {
      const int i = ef->body().index;  // a link: validate() refuses the world, the builder payloads
      const Pos p = pointPosition(*kinematics, i, ef->point());
      pointJacobian(model.tree, *kinematics, i, ef->point(), J);
      const Spatial::Vec F = ef->force(t, p, Spatial::Vec(J * v));
      if (F.isZero(0.0)) continue;
      const Pos f = F.tail<3>(), c = pointPosition(*kinematics, i, frames[std::size_t(i)].com);
      body->addLinkForce(i, bt(f));  // world axes, at the link frame's origin: the centre of mass
      body->addLinkTorque(i, bt(Pos(F.head<3>() + (p - c).cross(f))));
      Q.noalias() += J.transpose() * F;
    }
    return Q;
  }

  void step(const VecN& tau_in, double t) {
    const int n = model.treeDof();
    if (tau_in.size() != n) throw std::invalid_argument("BulletMechanism::step: τ needs one value per tree joint (" + std::to_string(n) + ")");
    VecN q, v;
    state(q, v);
    const VecN pushed = applyForces(t, q, v);  // pitfall 3: cleared after every step, like the torques
    VecN friction = VecN::Zero(n);
    VecN held(n);
    for (int i = 0; i < n; ++i) held[i] = heldTorque(model.joints, i, tau_in[i], q[model.tree.bodies[std::size_t(i)].q_index], v[i], friction[i]);
    for (int i = 0; i < n; ++i) {  // pitfall 3: cleared after every step
      if (model.tree.bodies[std::size_t(i)].joint != JointType::Ball) body->addJointTorque(i, held[i]);
      else if (!ballCarrier(model.tree, i))  // the ball's three torques on Bullet's axes (spherical_links.h)
        for (int k = 0; const double t : Pos(sphericalAxes(i) * held.segment<3>(i - 2))) body->addJointTorqueMultiDof(i, k++, t);
    }
    for (Wheel& w : wheels)
      w.start_point = rimContact(*body, w.link, w.centre, w.axle, w.rolling->radius()).point;
    for (Contact& k : contacts)
      k.start_point = body->localPosToWorld(k.link, k.centre) - k.plane->params().radius * bt(k.plane->normal());
    world->stepSimulation(dt, 0, dt);  // exactly one step of dt
    for (const Loop& l : loops) force[std::size_t(l.constraint)] = loopForce(l);
    for (Wheel& w : wheels) force[std::size_t(w.constraint)] = w.noslip ? noSlipForce(w) : ballForce(w.ball, w.start_point);
    for (Contact& k : contacts) force[std::size_t(k.constraint)] = ballForce(k.ball, k.start_point);
    joint_constraints.forces(*body, dt, force);
    // The books: the held torques along the step's displacement.
    VecN q1, v1;
    state(q1, v1);
    for (int i = 0; i < n; ++i) {
      // A ball's rates have no coordinate of their own: its displacement dt ω⁺ (Bullet's own first-order step).
      const int k = model.tree.bodies[std::size_t(i)].q_index;
      const double dq = model.tree.bodies[std::size_t(i)].joint == JointType::Ball ? dt * v1[i] : q1[k] - q[k];
      books.work += (tau_in[i] + pushed[i]) * dq;
      books.friction -= friction[i] * dq;
    }
  }
  Books books;

  // The constraint's impulses over the step, at the point it was written at: no moment there.
  Spatial::Vec noSlipForce(const Wheel& w) const {
    Spatial::Vec f = Spatial::Vec::Zero();
    f.tail<3>() = eig(w.noslip->impulse()) / dt;
    return f;
  }

  // The plane's force on a ball over the step (normal and friction impulses / dt) with its moment about
  // P, the contact point at the step's start (a friction wheel: the no-slip point, zero moment for an
  // upright disk up to the contact's penetration); zero when the ball does not touch.
  Spatial::Vec ballForce(int ball, const btVector3& P) const {
    btVector3 f, m;
    balls.force(world, ball, dt, P, f, m);
    Spatial::Vec out;
    out << eig(m), eig(f);
    return out;
  }
};

template class BulletMechanism<Spatial>;

}  // namespace dyn::bullet
