// Bullet 3.24 (double precision) reference model of the slider crank, lecture §3: a 3-link
// planar arm in the vertical x–y plane whose tip holds a slider of mass m_c on the x axis,
// φ(θ) = (θ1+θ2+θ3, l1 s1 + l2 s12 + l3 s123) = 0, load separate: m_c x_T'' = f_Tx and
// M θ'' + C θ' + G = τ − J^T f_T (lecture eq. (1) closed by eq. (2)).
//
// Bullet model (the most accurate one in shared/notes/bullet-reference.md): a btMultiBody tree
// cut at joint 1 and built from the slider end,
//     fixed base ─prismatic x─▶ slider ─fixed─▶ link 3 ─rev z (joint 3)─▶ link 2 ─rev z (joint 2)─▶ link 1,
// with the loop closed at joint 1 by a btMultiBodyPoint2Point from link 1 to the world origin.
// The prismatic base joint keeps the slider on y = 0 with a fixed orientation, and link 3 is
// welded to it, so θ1+θ2+θ3 = 0 and y_T = 0 hold by construction; only joint 1 can drift.
//
// Coordinates. φi is the absolute angle of link i (φ3 = 0). Bullet's revolute joints use axis
// +z and measure the child relative to the parent, so
//     b2 = φ2 − φ3 = −θ3,   b3 = φ1 − φ2 = −θ2,   x = x_T,   θ1 = φ1 = b2 + b3.
// Torques. A torque u on a Bullet revolute joint acts +u on the child and −u on the parent; the
// lecture's τi acts +τi on link i and −τi on link i−1. Joint 3's child is link 2 and joint 2's
// child is link 1, so u(joint 3) = −τ3, u(joint 2) = −τ2 (power check: u b' = τ θ'). Joint 1 is
// the cut: τ1 is the pair (+τ1 on link 1, −τ1 on the ground); the ground is fixed, so only the
// +τ1 about world z on link 1 is applied (addLinkTorque, world frame).
//
// Tip force. f_T = (τ_T, f_Tx, f_Ty), the wrench the arm applies to the slider, is the internal
// wrench across the slider–link 3 weld; btMultiBodyJointFeedback cannot be trusted with torques
// (pitfall 4). It is read from the Newton–Euler equations of the arm {1, 2, 3} as one subsystem:
// its external loads are gravity, the ground force F1 at joint 1 (the point-to-point impulse / dt),
// the couple τ1 and −f_T at the tip (τ2, τ3 are internal). Bullet's step is
//     M(q_n) (v_{n+1} − v_n)/dt + h(q_n, v_n) = τ + J_c(q_n)^T λ/dt,
// so with the link accelerations built from (q_n, v_n, a = Δv/dt) on Bullet's own tree these
// body equations hold exactly (up to rounding) for the step Bullet took:
//     f_T   = F1 + Σ m_i (g − a_i),
//     τ_T   = τ1 + (p1 − p_T) × F1 + Σ [(c_i − p_T) × m_i (g − a_i) − I_i α_i].
// Accuracy (tests/physics/bullet): the slider's own equation m_c a_x = f_Tx holds to 1e-12 N;
// one step from rest reproduces eq. (2)'s f_T to ~1e-8 relative; along a fast driven run at
// dt = 1 ms, f_Ty stays within 0.6 % of its peak of eq. (2) solved at the step's start state (the
// gap is Bullet's first-order step and joint-1 stabilisation, and shrinks ∝ dt). Reading the same
// wrench from the lecture's tree instead (J^-T (τ − M a − h)) is 1.3–2× worse: it assumes joint 1 does
// not accelerate, which Bullet's position correction violates.
#include "physics/bullet/slider_crank_bullet.h"

#include <btBulletDynamicsCommon.h>
#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>
#include <BulletDynamics/Featherstone/btMultiBodyPoint2Point.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#ifndef BT_USE_DOUBLE_PRECISION
#error "slider_crank_bullet.cpp must be built against bullet-float64 (BT_USE_DOUBLE_PRECISION)"
#endif

namespace dyn::bullet {
namespace {

// Bullet link indices of the tree (base is −1).
constexpr int kSlider = 0, kLink3 = 1, kLink2 = 2, kLink1 = 3, kNumLinks = 4;

Eigen::Vector2d rot(double a, const Eigen::Vector2d& v) {
  const double c = std::cos(a), s = std::sin(a);
  return {c * v.x() - s * v.y(), s * v.x() + c * v.y()};
}
double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); }
Eigen::Vector2d perp(const Eigen::Vector2d& v) { return {-v.y(), v.x()}; }  // ẑ × v

btVector3 bt(const Eigen::Vector2d& v) { return {v.x(), v.y(), 0.0}; }

// Planar inertia about the COM on z; the out-of-plane values only need to be positive.
btVector3 inertia3(double izz) { return {izz, izz, izz}; }

}  // namespace

struct SliderCrankBullet::Impl {
  SliderCrankModel model;
  double dt = 0.0;
  double t = 0.0;
  Eigen::Vector3d f_tip = Eigen::Vector3d::Zero();

  // Bullet objects, torn down in reverse order in ~Impl.
  std::unique_ptr<btDefaultCollisionConfiguration> config;
  std::unique_ptr<btCollisionDispatcher> dispatcher;
  std::unique_ptr<btDbvtBroadphase> broadphase;
  std::unique_ptr<btMultiBodyConstraintSolver> solver;
  std::unique_ptr<btMultiBodyDynamicsWorld> world;
  std::unique_ptr<btMultiBody> body;
  std::unique_ptr<btSphereShape> shape;
  std::vector<std::unique_ptr<btMultiBodyLinkCollider>> colliders;
  std::unique_ptr<btMultiBodyPoint2Point> closure;

  Impl(const SliderCrankModel& m, double step) : model(m), dt(step) {
    if (!(dt > 0.0)) throw std::invalid_argument("SliderCrankBullet: dt must be > 0");
    if (!(m.load_mass > 0.0)) throw std::invalid_argument("SliderCrankBullet: load_mass must be > 0");
    config = std::make_unique<btDefaultCollisionConfiguration>();
    dispatcher = std::make_unique<btCollisionDispatcher>(config.get());
    broadphase = std::make_unique<btDbvtBroadphase>();
    solver = std::make_unique<btMultiBodyConstraintSolver>();
    world = std::make_unique<btMultiBodyDynamicsWorld>(dispatcher.get(), broadphase.get(), solver.get(),
                                                       config.get());
    // Pitfall 2: Bullet's default gravity is (0, −10, 0); use the model's.
    world->setGravity(bt(m.gravity));
    // PGS iterations: Bullet's default 10 leaves the 3 closure rows short of convergence (tip
    // force 0.2 % off eq. (2) after one step from rest); 30 solves them to ~1e-6 (+~25 % time).
    world->getSolverInfo().m_numIterations = 30;
    build();
    setState(m.q0, m.qd0);
  }

  ~Impl() {
    if (world) {
      if (closure) world->removeMultiBodyConstraint(closure.get());
      for (auto& c : colliders) world->removeCollisionObject(c.get());
      if (body) world->removeMultiBody(body.get());
    }
    closure.reset();
    colliders.clear();
    body.reset();
    world.reset();
  }

  const PlanarLink& link(int i) const { return model.links[i - 1]; }  // lecture numbering 1..3

  void build() {
    const PlanarLink &L1 = link(1), &L2 = link(2), &L3 = link(3);
    const double mc = model.load_mass;
    // Slider: a small block; its rotational inertia never matters (orientation is fixed).
    const double ic = mc * 0.05 * 0.05 / 6.0;
    const btQuaternion id = btQuaternion::getIdentity();

    body = std::make_unique<btMultiBody>(kNumLinks, 1.0, btVector3(1, 1, 1), /*fixedBase=*/true,
                                         /*canSleep=*/false);
    body->setBaseWorldTransform(btTransform::getIdentity());
    // Slider: prismatic along world x, its COM at the tip (x_T, 0).
    body->setupPrismatic(kSlider, mc, inertia3(ic), -1, id, btVector3(1, 0, 0), btVector3(0, 0, 0),
                         btVector3(0, 0, 0), true);
    // Link 3 welded to the slider at the tip; its frame is world-aligned (φ3 = 0).
    body->setupFixed(kLink3, L3.mass, inertia3(L3.inertia), kSlider, id, btVector3(0, 0, 0),
                     bt(L3.com - Eigen::Vector2d(L3.length, 0)));
    // Joint 3 (link 3's origin) to link 2, whose far end (its x = l2) sits at joint 3.
    body->setupRevolute(kLink2, L2.mass, inertia3(L2.inertia), kLink3, id, btVector3(0, 0, 1), bt(-L3.com),
                        bt(L2.com - Eigen::Vector2d(L2.length, 0)), true);
    // Joint 2 (link 2's origin) to link 1, whose far end sits at joint 2.
    body->setupRevolute(kLink1, L1.mass, inertia3(L1.inertia), kLink2, id, btVector3(0, 0, 1), bt(-L2.com),
                        bt(L1.com - Eigen::Vector2d(L1.length, 0)), true);
    body->finalizeMultiDof();

    // Pitfall 2: no damping, no velocity cap, never sleep.
    body->setLinearDamping(0.0);
    body->setAngularDamping(0.0);
    body->setMaxCoordinateVelocity(1e6);
    body->setCanSleep(false);
    body->setHasSelfCollision(false);
    body->setUseGyroTerm(true);
    world->addMultiBody(body.get());

    // Pitfall 1: the loop closure is ignored unless every link has a collider; mask 0 = no contacts.
    shape = std::make_unique<btSphereShape>(0.01);
    for (int i = -1; i < kNumLinks; ++i) {
      auto c = std::make_unique<btMultiBodyLinkCollider>(body.get(), i);
      c->setCollisionShape(shape.get());
      c->setActivationState(DISABLE_DEACTIVATION);
      world->addCollisionObject(c.get(), btBroadphaseProxy::DefaultFilter, 0);
      if (i < 0)
        body->setBaseCollider(c.get());
      else
        body->getLink(i).m_collider = c.get();
      colliders.push_back(std::move(c));
    }

    // Loop closure at joint 1: link 1's origin (its joint) pinned to the world origin.
    closure = std::make_unique<btMultiBodyPoint2Point>(body.get(), kLink1, nullptr, bt(-L1.com),
                                                       btVector3(0, 0, 0));
    closure->setMaxAppliedImpulse(1e12);  // pitfall 2: default cap is 100 N·s per step
    world->addMultiBodyConstraint(closure.get());
    closure->finalizeMultiDof();
  }

  // Lecture state (θ, θ') -> Bullet joint coordinates, then refresh transforms and colliders.
  void setState(const Eigen::Vector3d& q, const Eigen::Vector3d& qd) {
    const double l1 = link(1).length, l2 = link(2).length, l3 = link(3).length;
    const double a1 = q[0], a12 = q[0] + q[1], a123 = q[0] + q[1] + q[2];
    const double xT = l1 * std::cos(a1) + l2 * std::cos(a12) + l3 * std::cos(a123);
    const double w1 = qd[0], w12 = qd[0] + qd[1], w123 = qd[0] + qd[1] + qd[2];
    const double vT = -l1 * std::sin(a1) * w1 - l2 * std::sin(a12) * w12 - l3 * std::sin(a123) * w123;
    body->setJointPos(kSlider, xT);
    body->setJointPos(kLink2, -q[2]);
    body->setJointPos(kLink1, -q[1]);
    body->setJointVel(kSlider, vT);
    body->setJointVel(kLink2, -qd[2]);
    body->setJointVel(kLink1, -qd[1]);
    btAlignedObjectArray<btQuaternion> w2l;
    btAlignedObjectArray<btVector3> origin;
    body->forwardKinematics(w2l, origin);
    body->updateCollisionObjectWorldTransforms(w2l, origin);
  }

  void step(const Eigen::Vector3d& tau) {
    // State at the start of the step (Bullet's bias forces and constraint rows use it).
    const double b2 = body->getJointPos(kLink2), b3 = body->getJointPos(kLink1);
    const double v0 = body->getJointVel(kSlider), w2 = body->getJointVel(kLink2), w3 = body->getJointVel(kLink1);

    // Pitfall 3: applied torques are cleared after each step; apply them every step.
    body->addJointTorque(kLink2, -tau[2]);
    body->addJointTorque(kLink1, -tau[1]);
    body->addLinkTorque(kLink1, btVector3(0, 0, tau[0]));
    // Exactly one step of dt (maxSubSteps = 0 means "one variable step of timeStep").
    world->stepSimulation(dt, 0, dt);
    t += dt;

    // Accelerations Bullet applied over the step.
    const double ax = (body->getJointVel(kSlider) - v0) / dt;
    const double al2 = (body->getJointVel(kLink2) - w2) / dt;
    const double al1 = al2 + (body->getJointVel(kLink1) - w3) / dt;
    const double om2 = w2, om1 = w2 + w3;
    const double ph2 = b2, ph1 = b2 + b3;

    // Geometry of Bullet's tree at q_n, relative to the tip p_T.
    const PlanarLink &L1 = link(1), &L2 = link(2), &L3 = link(3);
    const Eigen::Vector2d j3(-L3.length, 0.0);
    const Eigen::Vector2d c3 = j3 + L3.com;
    const Eigen::Vector2d j2 = j3 - rot(ph2, {L2.length, 0.0});
    const Eigen::Vector2d c2 = j2 + rot(ph2, L2.com);
    const Eigen::Vector2d j1 = j2 - rot(ph1, {L1.length, 0.0});
    const Eigen::Vector2d c1 = j1 + rot(ph1, L1.com);

    // COM accelerations along the tree: slider/link 3 translate, links 2 and 1 rotate.
    const Eigen::Vector2d aT(ax, 0.0);
    auto acc = [](const Eigen::Vector2d& a0, double al, double om, const Eigen::Vector2d& r) {
      return Eigen::Vector2d(a0 + al * perp(r) - om * om * r);
    };
    const Eigen::Vector2d a3 = aT;
    const Eigen::Vector2d a2 = acc(aT, al2, om2, c2 - j3);
    const Eigen::Vector2d aj2 = acc(aT, al2, om2, j2 - j3);
    const Eigen::Vector2d a1 = acc(aj2, al1, om1, c1 - j2);

    // Ground force on link 1 at joint 1: the point-to-point rows are world x, y, z and link 1
    // receives −λ (sign confirmed by the tests: f_Tx = m_c a_x to 1e-12, static hold exact).
    const Eigen::Vector2d F1 = -Eigen::Vector2d(closure->getAppliedImpulse(0), closure->getAppliedImpulse(1)) / dt;

    // Newton–Euler of the arm {1,2,3}: net load = momentum rate, solved for −f_T.
    const Eigen::Vector2d& g = model.gravity;
    const Eigen::Vector2d d3 = L3.mass * (g - a3), d2 = L2.mass * (g - a2), d1 = L1.mass * (g - a1);
    const Eigen::Vector2d fT = F1 + d1 + d2 + d3;
    const double tauT = tau[0] + cross(j1, F1) + cross(c1, d1) + cross(c2, d2) + cross(c3, d3) -
                        L1.inertia * al1 - L2.inertia * al2;
    f_tip = {tauT, fT.x(), fT.y()};
  }

  Eigen::Vector3d q() const {
    const double b2 = body->getJointPos(kLink2), b3 = body->getJointPos(kLink1);
    return {b2 + b3, -b3, -b2};
  }
  Eigen::Vector3d qd() const {
    const double w2 = body->getJointVel(kLink2), w3 = body->getJointVel(kLink1);
    return {w2 + w3, -w3, -w2};
  }
};

SliderCrankBullet::SliderCrankBullet(const SliderCrankModel& model, double dt)
    : impl_(std::make_unique<Impl>(model, dt)) {}
SliderCrankBullet::~SliderCrankBullet() = default;

void SliderCrankBullet::step(const Eigen::Vector3d& tau) { impl_->step(tau); }
Eigen::Vector3d SliderCrankBullet::q() const { return impl_->q(); }
Eigen::Vector3d SliderCrankBullet::qd() const { return impl_->qd(); }
double SliderCrankBullet::x_c() const { return impl_->body->getJointPos(kSlider); }
double SliderCrankBullet::v_c() const { return impl_->body->getJointVel(kSlider); }
Eigen::Vector3d SliderCrankBullet::tipForce() const { return impl_->f_tip; }
double SliderCrankBullet::time() const { return impl_->t; }

}  // namespace dyn::bullet
