// Bullet 3.24 (double precision) reference model of a planar mechanism description, built from the
// plan of planar_plan.h: one fixed-base btMultiBody (links at their centres of mass, revolute axes z),
// btMultiBodyPoint2Point constraints for cut revolute joints and point attachments,
// btMultiBodyFixedConstraint for welds that close a loop, and for each plane_contact a ball on its link
// against the plane n·x = h (n in the x–y plane), the model contact_balls.h shares with the spatial
// builder (μ, restitution 0, rigid or compliant; its second friction direction, along z, has no
// effective mass here and stays 0).
//
// Settings (shared/notes/bullet-reference.md): gravity from the description, PGS with
// BulletHints::solver_iterations, no damping, no joint-speed cap, never sleep, a collider with mask 0
// on every link (pitfall 1: multibody constraints are ignored without them), impulse cap 1e12, and
// exactly one stepSimulation(dt, 0, dt) per step.
//
// Torques. The description's τ_i acts +τ_i on the child about the joint axis, −τ_i on the parent.
// On a Bullet joint (which acts +u on its Bullet child): u = sign × τ_i (sign −1 when Bullet's child
// is the description's parent). On a cut joint: link torques +τ_i on the child, −τ_i on the parent
// (none on the world). Joint properties add −k(θ − θ_rest) − b θ' − F_c tanh(θ'/w) from the state at the
// start of the step.
//
// External forces (description.forces): evaluated at the step's start (time t, the point's position and
// velocity from Bullet's own link motion) and applied to the body's Bullet link as a force at its centre
// of mass and the torque τ + (p − c) × f; they join link_force / link_torque like payload pushes.
//
// Constraint forces f (body a on body b, world axes, planar (τ, f_x, f_y) at its point):
//   point-to-point   Bullet's A receives −λ/dt, B +λ/dt (rows world x, y), no moment;
//   fixed constraint the opposite: A receives +λ/dt and the moment +λ_5/dt (row 5: A's frame z = world
//                    z), B −λ/dt, −λ_5/dt (sign found by the slider's own Newton equation in the
//                    tests); reported at point_b's world position;
//   plane_contact    the plane's force on the ball (impulses / dt: normal η n, and friction when μ > 0)
//                    with its moment about c − ρ n at the step's start (~0 unless friction acts on a
//                    stand-in ball);
//   weld realised as the fixed joint P → C: Newton–Euler of the Bullet subtree S beyond it,
//     F_PC = Σ_S m_k (a_k − g) − F_ext,   M_PC = Σ_S [(c_k − p) × m_k (a_k − g) + I_k α_k] − M_ext(p),
//   with the link accelerations of the step Bullet took: (q_n, v_n) and a = (v_{n+1} − v_n)/dt on
//   Bullet's own tree (its step is M(q_n)(v_{n+1} − v_n)/dt + h(q_n, v_n) = τ + J_c(q_n)ᵀλ/dt, so
//   these balances hold to rounding). F_ext, M_ext: constraint impulses / dt on links of S at their
//   pivots, contact forces on links of S, link forces (payload pushes) and link torques applied to S
//   (joint torques inside S are internal). f = ±F_PC (+ if C = b).
#include "physics/bullet/bullet_mechanism.h"

#include <btBulletDynamicsCommon.h>
#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <BulletDynamics/Featherstone/btMultiBodyFixedConstraint.h>
#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>
#include <BulletDynamics/Featherstone/btMultiBodyPoint2Point.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <tuple>

#include "physics/bullet/bullet_mechanism_members.h"
#include "physics/bullet/bullet_world.h"
#include "physics/bullet/contact_balls.h"
#include "physics/bullet/planar_multibody.h"
#include "physics/bullet/planar_plan.h"
#include "physics/constraints/plane_contact.h"

#ifndef BT_USE_DOUBLE_PRECISION
#error "bullet_mechanism.cpp must be built against bullet-float64 (BT_USE_DOUBLE_PRECISION)"
#endif

namespace dyn::bullet {
namespace {

using Vec2 = Eigen::Vector2d;

// The same angle modulo 2π, nearest to `near` (exact when no turn is added).
double unwrap(double raw, double near) {
  constexpr double kTurn = 2.0 * std::numbers::pi;
  return raw + kTurn * std::round((near - raw) / kTurn);
}

}  // namespace

template <>
struct BulletMechanism<Planar>::Impl {
  // A plane_contact of the description: a ball in `balls`, and its force over the last step.
  struct Contact {
    int constraint = -1, link = -1, ball = -1;
    const PlaneContact<Planar>* plane = nullptr;
    btVector3 centre{0, 0, 0};  // Bullet link frame
    btVector3 start{0, 0, 0};   // c − ρ n at the last step's start
    Vec2 f = Vec2::Zero();      // the plane's force on the ball, and its moment about `start`
    double m = 0;
  };
  MechanismModel<Planar> model;
  Plan plan;
  double dt;
  std::vector<int> joint_link;                    // per tree joint: its Bullet link (−1: cut)
  std::vector<double> qb, qdb;                    // Bullet coordinates per link (0 for fixed links)
  std::vector<LinkMotion> now;                    // link motion at the current state
  std::vector<double> cut_theta;                  // per tree joint: unwrapped angle if cut
  std::vector<double> link_torque;                // link torques applied over the last step
  std::vector<Vec2> link_force;                   // link forces (at the centre of mass) over the last step
  std::vector<Planar::Vec> force;                 // per description constraint, last step
  Books books;                                    // work of the held forces along each step's displacement
  const std::string& describe() const { return plan.summary; }

  BulletWorld world;  // before what it holds: destroyed after it
  std::unique_ptr<btMultiBody> body;
  std::unique_ptr<btSphereShape> shape;
  std::vector<std::unique_ptr<btMultiBodyLinkCollider>> colliders;
  std::vector<std::unique_ptr<btMultiBodyConstraint>> closures;
  std::vector<Contact> contacts;
  ContactBalls balls;

  Impl(const MechanismModel<Planar>& m, double step, const VecN& q0, const VecN& v0)
      : model(m), plan(makePlan(m)), dt(step), world(bt(plan.gravity), m.bullet.solver_iterations) {
    if (!(dt > 0.0)) throw std::invalid_argument("BulletMechanism: dt must be > 0");
    if (q0.size() != plan.coordinates || v0.size() != plan.coordinates)
      throw std::invalid_argument("BulletMechanism: q0 and v0 need " + std::to_string(plan.coordinates) +
                                  " coordinates (tree joints, then payload free coordinates)");
    if (!m.joints.empty() && int(m.joints.size()) != m.treeDof())
      throw std::invalid_argument("BulletMechanism: joints must be empty or one per tree joint");
    for (const JointProperties& j : m.joints)  // the planar builder has no rotor links (the spatial one has)
      if (j.armature != 0) throw std::invalid_argument("BulletMechanism (planar): joint armature: not yet");
    if (m.bullet.solver_iterations < 1) throw std::invalid_argument("BulletMechanism: solver_iterations must be ≥ 1");
    for (int p = 0; p < int(m.payloads.size()); ++p)
      if (!(m.payloads[std::size_t(p)].mass > 0.0) || !(m.payloads[std::size_t(p)].inertia > 0.0))
        throw std::invalid_argument("BulletMechanism: payload " + std::to_string(p) + " needs mass and inertia > 0");
    joint_link.assign(std::size_t(m.treeDof()), -1);
    for (int k = 0; k < int(plan.links.size()); ++k)
      if (plan.links[std::size_t(k)].tree_joint >= 0) joint_link[std::size_t(plan.links[std::size_t(k)].tree_joint)] = k;
    force.assign(m.constraints.size(), Planar::Vec::Zero());
    link_torque.assign(plan.links.size(), 0.0);
    link_force.assign(plan.links.size(), Vec2::Zero());

    build();
    buildContacts();
    setState(q0, v0);
  }

  ~Impl() { removeModel(world, body, colliders, closures, balls); }

  void build() {
    const int n = int(plan.links.size());
    body = makePlanarMultiBody(plan, *world.world);

    // Pitfall 1: every link needs a collider for the constraints to act; mask 0 = no contacts.
    shape = std::make_unique<btSphereShape>(0.01);
    addLinkColliders(world, *body, n, shape.get(), colliders);

    // Cut joints and point attachments: point-to-point (to the world: pivot_b in world coordinates).
    for (const PlanConstraint& pc : plan.constraints) {
      const btVector3 pa = bt(pc.pivot_a), pb = bt(pc.pivot_b);
      const btMatrix3x3 frame = btMatrix3x3::getIdentity();  // a weld keeps the body frames aligned
      std::unique_ptr<btMultiBodyConstraint> c;
      if (pc.kind == PlanConstraint::Kind::Weld)
        c = pc.link_b == kWorldLink
                ? std::unique_ptr<btMultiBodyConstraint>(
                      new btMultiBodyFixedConstraint(body.get(), pc.link_a, nullptr, pa, pb, frame, frame))
                : std::unique_ptr<btMultiBodyConstraint>(
                      new btMultiBodyFixedConstraint(body.get(), pc.link_a, body.get(), pc.link_b, pa, pb, frame, frame));
      else
        c = pc.link_b == kWorldLink
                ? std::unique_ptr<btMultiBodyConstraint>(new btMultiBodyPoint2Point(body.get(), pc.link_a, nullptr, pa, pb))
                : std::unique_ptr<btMultiBodyConstraint>(
                      new btMultiBodyPoint2Point(body.get(), pc.link_a, body.get(), pc.link_b, pa, pb));
      c->setMaxAppliedImpulse(1e12);  // pitfall 2: default cap is 100 N·s per step
      world->addMultiBodyConstraint(c.get());
      c->finalizeMultiDof();
      closures.push_back(std::move(c));
    }
  }

  // Each plane_contact: a ball at c_b on its body's link (frame at the body's centre of mass, its angle).
  void buildContacts() {
    std::vector<ContactBall> list;
    for (std::size_t c = 0; c < model.constraints.size(); ++c) {
      const Constraint<Planar>* k = model.constraints[c].get();
      if (!k->unilateral()) continue;
      const auto* pc = dynamic_cast<const PlaneContact<Planar>*>(k);
      if (!pc) throw std::invalid_argument("BulletMechanism: constraint " + std::to_string(c) + " (" + k->kind() + "): not yet");
      const BodyRef b = pc->body();
      Contact ct;
      ct.constraint = int(c), ct.plane = pc, ct.ball = int(list.size());
      Vec2 com = Vec2::Zero();
      if (b.kind == BodyRef::Kind::Link) {
        double mass;
        Planar::massAndCom(model.tree.bodies[std::size_t(b.index)].inertia, mass, com);
        ct.link = plan.link_of_tree_body[std::size_t(b.index)];
      } else {
        ct.link = plan.link_of_payload[std::size_t(b.index)];
      }
      ct.centre = bt(pc->centre() - com);
      const PlaneContactParams& p = pc->params();
      list.push_back({ct.link, ct.centre, p.radius, bt(pc->normal()), p.height, p.mu, p.stiffness, p.damping});
      contacts.push_back(ct);
    }
    std::vector<btMultiBodyLinkCollider*> link_colliders;
    for (auto& c : colliders) link_colliders.push_back(c.get());
    balls.build(world, link_colliders, std::move(list), "BulletMechanism: ");
    if (!contacts.empty())  // before ", PGS n iterations"
      plan.summary.insert(plan.summary.rfind(", PGS"),
                          ", " + std::to_string(contacts.size()) + " plane contact(s) as a sphere on a static plane");
  }

  void readBullet() {
    qb.assign(plan.links.size(), 0.0);
    qdb.assign(plan.links.size(), 0.0);
    for (int k = 0; k < int(plan.links.size()); ++k) {
      if (plan.links[std::size_t(k)].joint == PlanLink::Joint::Fixed) continue;
      qb[std::size_t(k)] = body->getJointPos(k);
      qdb[std::size_t(k)] = body->getJointVel(k);
    }
    planarKinematics(plan, qb, qdb, nullptr, now);
  }

  // Description state → Bullet coordinates; cut joints keep the description's own angle.
  void setState(const VecN& q, const VecN& v) {
    std::vector<LinkMotion> described;  // floating links' guides take their poses at (q, v)
    descriptionMotion(model, q, v, described);
    for (int k = 0; k < int(plan.links.size()); ++k) {
      const PlanLink& l = plan.links[std::size_t(k)];
      if (l.floating >= 0) {
        const LinkMotion& d = described[std::size_t(l.floating)];
        const int a = l.floating_axis;
        body->setJointPos(k, a < 2 ? d.c[a] : d.phi);
        body->setJointVel(k, a < 2 ? d.v[a] : d.omega);
      }
      if (l.coord < 0) continue;
      body->setJointPos(k, l.sign * q[l.coord]);
      body->setJointVel(k, l.sign * v[l.coord]);
    }
    btAlignedObjectArray<btQuaternion> w2l;
    btAlignedObjectArray<btVector3> origin;
    body->forwardKinematics(w2l, origin);
    body->updateCollisionObjectWorldTransforms(w2l, origin);
    readBullet();
    cut_theta.assign(std::size_t(model.treeDof()), 0.0);
    for (int i : plan.cut_joints) cut_theta[std::size_t(i)] = unwrap(rawCutAngle(i), q[i]);
    checkKinematics();
  }

  // Self-check of the plan's kinematics against Bullet's own link frames (catches a convention slip).
  void checkKinematics() const {
    for (int k = 0; k < int(plan.links.size()); ++k) {
      const btTransform& T = colliders[std::size_t(k + 1)]->getWorldTransform();
      const btVector3 o = T.getOrigin();
      btScalar yaw, pitch, roll;
      T.getBasis().getEulerZYX(yaw, pitch, roll);
      const LinkMotion& m = now[std::size_t(k)];
      const double dphi = std::remainder(double(yaw) - m.phi, 2.0 * std::numbers::pi);
      if ((Vec2(o.x(), o.y()) - m.c).norm() > 1e-9 || std::abs(dphi) > 1e-9)
        throw std::logic_error("BulletMechanism: plan kinematics disagree with Bullet's link " + std::to_string(k));
    }
  }

  const LinkMotion& motionOf(int link, const std::vector<LinkMotion>& ms) const {
    static const LinkMotion world;
    return link < 0 ? world : ms[std::size_t(link)];
  }

  // Relative angle of a cut joint's child to its parent, minus the joint frame's own angle.
  double rawCutAngle(int i) const {
    const int p = model.tree.bodies[std::size_t(i)].parent;
    const int lp = p < 0 ? kWorldLink : plan.link_of_tree_body[std::size_t(p)];
    return motionOf(plan.link_of_tree_body[std::size_t(i)], now).phi - motionOf(lp, now).phi -
           plan.tree_angle[std::size_t(i)];
  }

  void state(VecN& q, VecN& v) const {
    q.resize(plan.coordinates);
    v.resize(plan.coordinates);
    for (int k = 0; k < int(plan.links.size()); ++k) {
      const PlanLink& l = plan.links[std::size_t(k)];
      if (l.coord < 0) continue;
      q[l.coord] = l.sign * qb[std::size_t(k)];
      v[l.coord] = l.sign * qdb[std::size_t(k)];
    }
    for (int i : plan.cut_joints) {
      const int p = model.tree.bodies[std::size_t(i)].parent;
      const int lp = p < 0 ? kWorldLink : plan.link_of_tree_body[std::size_t(p)];
      q[i] = cut_theta[std::size_t(i)];
      v[i] = motionOf(plan.link_of_tree_body[std::size_t(i)], now).omega - motionOf(lp, now).omega;
    }
  }

  // An external force's body as a Bullet link, and its point in that link's frame (at the centre of mass).
  std::pair<int, Vec2> forceLink(const ExternalForce<Planar>& f) const {
    const BodyRef b = f.body();
    Vec2 com = Vec2::Zero();
    if (b.kind == BodyRef::Kind::Link) {
      double mass;
      Planar::massAndCom(model.tree.bodies[std::size_t(b.index)].inertia, mass, com);
      return {plan.link_of_tree_body[std::size_t(b.index)], f.point() - com};
    }
    return {plan.link_of_payload[std::size_t(b.index)], f.point()};
  }

  void step(const VecN& tau_in, double t) {
    const int n = model.treeDof();
    const int k = model.payloadDof();
    if (tau_in.size() != n && tau_in.size() != n + k)
      throw std::invalid_argument("BulletMechanism::step: τ needs one value per tree joint (and optionally per payload coordinate)");
    VecN q, v;
    state(q, v);
    VecN held = VecN::Zero(n + k), friction = VecN::Zero(n);  // generalised forces held over the step
    held.head(tau_in.size()) = tau_in;
    std::fill(link_torque.begin(), link_torque.end(), 0.0);
    std::fill(link_force.begin(), link_force.end(), Vec2::Zero());
    // Payload forces w (ψ, x, y on the free coordinates): a torque and a force at the centre of mass.
    if (tau_in.size() == n + k)
      for (int p = 0, off = n; p < int(model.payloads.size()); ++p) {
        const Payload& pl = model.payloads[std::size_t(p)];
        double w[3] = {0.0, 0.0, 0.0};
        for (std::size_t c = 0; c < 3; ++c)
          if (pl.free[c]) w[c] = tau_in[off++];
        const int l = plan.link_of_payload[std::size_t(p)];
        body->addLinkTorque(l, btVector3(0, 0, w[0]));
        body->addLinkForce(l, btVector3(w[1], w[2], 0));
        link_torque[std::size_t(l)] += w[0];
        link_force[std::size_t(l)] += Vec2(w[1], w[2]);
      }
    // External forces at the step's start: a force at the link's centre of mass and its moment.
    std::vector<std::tuple<int, Vec2, Planar::Vec, Vec2, double>> applied;  // link, point, F, p, φ
    for (const auto& ef : model.forces) {
      const auto [l, r_local] = forceLink(*ef);
      const LinkMotion& m = now[std::size_t(l)];
      const Vec2 r = rotate(m.phi, r_local), p = m.c + r;
      const Planar::Vec V(m.omega, m.v.x() - m.omega * r.y(), m.v.y() + m.omega * r.x());
      const Planar::Vec F = ef->force(t, p, V);
      const double torque = F[0] + cross(r, Vec2(F[1], F[2]));
      body->addLinkForce(l, btVector3(F[1], F[2], 0));
      body->addLinkTorque(l, btVector3(0, 0, torque));
      link_force[std::size_t(l)] += Vec2(F[1], F[2]);
      link_torque[std::size_t(l)] += torque;
      applied.emplace_back(l, r_local, F, p, m.phi);
    }
    for (int i = 0; i < n; ++i) {
      const double tau = heldTorque(model.joints, i, tau_in[i], q[i], v[i], friction[i]);
      // Pitfall 3: applied torques are cleared after each step; apply them every step.
      const int k = joint_link[std::size_t(i)];
      if (k >= 0) {
        body->addJointTorque(k, plan.links[std::size_t(k)].sign * tau);
        continue;
      }
      const int p = model.tree.bodies[std::size_t(i)].parent;
      const int lc = plan.link_of_tree_body[std::size_t(i)];
      body->addLinkTorque(lc, btVector3(0, 0, tau));
      link_torque[std::size_t(lc)] += tau;
      if (p >= 0) {
        const int lp = plan.link_of_tree_body[std::size_t(p)];
        body->addLinkTorque(lp, btVector3(0, 0, -tau));
        link_torque[std::size_t(lp)] -= tau;
      }
    }
    const std::vector<double> q0 = qb, v0 = qdb;
    for (Contact& c : contacts)
      c.start = body->localPosToWorld(c.link, c.centre) - c.plane->params().radius * bt(c.plane->normal());
    world->stepSimulation(dt, 0, dt);  // exactly one step of dt
    readBullet();
    for (int i : plan.cut_joints) cut_theta[std::size_t(i)] = unwrap(rawCutAngle(i), cut_theta[std::size_t(i)]);

    // The step Bullet took: accelerations on its tree at (q_n, v_n).
    std::vector<double> qdd(qb.size());
    for (std::size_t k = 0; k < qb.size(); ++k) qdd[k] = (qdb[k] - v0[k]) / dt;
    std::vector<LinkMotion> start;
    planarKinematics(plan, q0, v0, &qdd, start);
    constraintForces(start);
    // The books: the held forces along the displacement the step took.
    VecN q1, v1;
    state(q1, v1);
    for (int i = 0; i < n + k; ++i) {
      const double dq = q1[i] - q[i];
      books.work += held[i] * dq;
      if (i < n) books.friction -= friction[i] * dq;
    }
    for (const auto& [l, r_local, F, p0, phi0] : applied) {
      const LinkMotion& m = now[std::size_t(l)];
      const Vec2 p1 = m.c + rotate(m.phi, r_local);
      books.work += F[1] * (p1.x() - p0.x()) + F[2] * (p1.y() - p0.y()) + F[0] * (m.phi - phi0);
    }
  }

  // Force and moment constraint c applied to Bullet's B over the step (A receives the opposite), world
  // axes. Point-to-point: +λ/dt; fixed constraint: −λ/dt (its rows are written for A), moment row 5.
  double signOnB(std::size_t c) const { return plan.constraints[c].kind == PlanConstraint::Kind::Weld ? -1.0 : 1.0; }
  Vec2 impulseForce(std::size_t c) const {
    return signOnB(c) * Vec2(closures[c]->getAppliedImpulse(0), closures[c]->getAppliedImpulse(1)) / dt;
  }
  double impulseMoment(std::size_t c) const {
    return plan.constraints[c].kind == PlanConstraint::Kind::Weld ? -closures[c]->getAppliedImpulse(5) / dt : 0.0;
  }

  void constraintForces(const std::vector<LinkMotion>& start) {
    for (Contact& c : contacts) {
      btVector3 f, m;
      balls.force(world, c.ball, dt, c.start, f, m);
      c.f = Vec2(f.x(), f.y());
      c.m = m.z();
      force[std::size_t(c.constraint)] = {c.m, c.f.x(), c.f.y()};
    }
    for (std::size_t c = 0; c < plan.constraints.size(); ++c) {
      const PlanConstraint& pc = plan.constraints[c];
      if (pc.constraint < 0) continue;
      const Vec2 f = pc.sign * impulseForce(c);
      force[std::size_t(pc.constraint)] = {pc.sign * impulseMoment(c), f.x(), f.y()};
    }
    for (std::size_t c = 0; c < plan.weld_link.size(); ++c)
      if (plan.weld_link[c] >= 0) force[c] = weldForce(int(c), start);
  }

  // Newton–Euler of the Bullet subtree beyond the weld's fixed joint (see the top of the file).
  Planar::Vec weldForce(int c, const std::vector<LinkMotion>& start) const {
    const int w = plan.weld_link[std::size_t(c)];
    const PlanLink& lw = plan.links[std::size_t(w)];
    std::vector<char> in(plan.links.size(), 0);
    for (int k = w; k < int(plan.links.size()); ++k) {
      const int p = plan.links[std::size_t(k)].parent;
      in[std::size_t(k)] = k == w || (p >= 0 && in[std::size_t(p)]);
    }
    const LinkMotion& P = motionOf(lw.parent, start);
    const Vec2 p = P.c + rotate(P.phi, lw.e);  // the weld point
    Vec2 F = Vec2::Zero();
    double M = 0;
    for (std::size_t k = 0; k < plan.links.size(); ++k) {
      if (!in[k]) continue;
      const PlanLink& l = plan.links[k];
      const LinkMotion& s = start[k];
      const Vec2 D = l.mass * (s.a - plan.gravity) - link_force[k];
      F += D;
      M += cross(s.c - p, D) + l.inertia * s.alpha - link_torque[k];
    }
    for (std::size_t c2 = 0; c2 < plan.constraints.size(); ++c2) {
      const PlanConstraint& pc = plan.constraints[c2];
      const Vec2 lambda = impulseForce(c2);
      const double mu = impulseMoment(c2);
      for (const auto& [link, pivot, f, n] : {std::tuple{pc.link_a, pc.pivot_a, Vec2(-lambda), -mu},
                                              std::tuple{pc.link_b, pc.pivot_b, Vec2(lambda), mu}}) {
        if (link < 0 || !in[std::size_t(link)]) continue;
        const LinkMotion& s = start[std::size_t(link)];
        F -= f;
        M -= n + cross(s.c + rotate(s.phi, pivot) - p, f);
      }
    }
    for (const Contact& ct : contacts) {  // the planes' forces on balls of S
      if (!in[std::size_t(ct.link)]) continue;
      F -= ct.f;
      M -= ct.m + cross(Vec2(ct.start.x(), ct.start.y()) - p, ct.f);
    }
    // F, M: what the parent P applies to C; the description wants a on b.
    const double sign = lw.body == model.constraints[std::size_t(c)]->attachment().b ? 1.0 : -1.0;
    return sign * Planar::Vec(M, F.x(), F.y());
  }
};

// Spatial mechanisms: spatial_mechanism.cpp.
template class BulletMechanism<Planar>;

}  // namespace dyn::bullet
