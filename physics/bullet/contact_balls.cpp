// Balls on Bullet links against static planes (contact_balls.h): colliders, planes, groups, forces.
#include "physics/bullet/contact_balls.h"

#include <BulletDynamics/Featherstone/btMultiBody.h>

#include <algorithm>
#include <stdexcept>

#ifndef BT_USE_DOUBLE_PRECISION
#error "contact_balls.cpp must be built against bullet-float64 (BT_USE_DOUBLE_PRECISION)"
#endif

namespace dyn::bullet {

void ContactBalls::build(BulletWorld& world, const std::vector<btMultiBodyLinkCollider*>& colliders,
                         std::vector<ContactBall> balls, const std::string& who) {
  if (balls.empty()) return;
  // Two friction directions clipped together to the cone (without the flag Bullet keeps one).
  btContactSolverInfo& info = world->getSolverInfo();
  info.m_solverMode |= SOLVER_USE_2_FRICTION_DIRECTIONS;
  info.m_solverMode &= ~SOLVER_DISABLE_IMPLICIT_CONE_FRICTION;
  // Speculative contacts within the absolute 2 cm, not 3.5 % of each sphere's radius.
  world.dispatcher->setDispatcherFlags(world.dispatcher->getDispatcherFlags() &
                                       ~btCollisionDispatcher::CD_USE_RELATIVE_CONTACT_BREAKING_THRESHOLD);

  // Collision groups above Bullet's own filters (bits 0–5).
  int next_bit = 6;
  auto group = [&] {
    if (next_bit > 30) throw std::invalid_argument(who + "more than 25 contact links and planes: not yet");
    return 1 << next_bit++;
  };
  // One Bullet plane per distinct (n, moved height, compliant or not): a compliant plane carries the
  // stiffness flag, which would make every contact on it compliant.
  struct Plane {
    btVector3 normal;
    double height;
    bool compliant;
    int group, mask = 0;
  };
  std::vector<Plane> planes;
  std::vector<int> plane_of(balls.size());
  for (std::size_t i = 0; i < balls.size(); ++i) {
    ContactBall& b = balls[i];
    const double R = std::max(b.radius, kMinRadius);
    const double h = b.height - (R - b.radius);
    const bool compliant = b.stiffness > 0;
    if (b.mu > 10.0) throw std::invalid_argument(who + "μ = " + std::to_string(b.mu) + " > 10: Bullet clips a contact's friction at 10");
    auto same = [&](const Plane& p) { return p.normal == b.normal && p.height == h && p.compliant == compliant; };
    auto it = std::find_if(planes.begin(), planes.end(), same);
    if (it == planes.end()) it = planes.insert(planes.end(), Plane{b.normal, h, compliant, group()});
    plane_of[i] = int(it - planes.begin());
  }

  // Each link with balls: its collider becomes the ball (or a compound of them), in its own group.
  balls_.assign(balls.size(), Placed{});
  std::vector<int> link_group(balls.size(), 0);
  for (std::size_t i = 0; i < balls.size(); ++i) {
    const ContactBall& b = balls[i];
    if (balls_[i].collider) continue;  // placed with an earlier ball of its link
    std::vector<std::size_t> mine;
    for (std::size_t j = i; j < balls.size(); ++j)
      if (balls[j].link == b.link) mine.push_back(j);
    for (std::size_t j : mine) {
      const ContactBall& o = balls[j];
      if (plane_of[j] != plane_of[i] || o.mu != b.mu || o.stiffness != b.stiffness || o.damping != b.damping ||
          o.radius != b.radius)
        throw std::invalid_argument(who + "Bullet link " + std::to_string(b.link) +
                                    " carries balls against different planes or with different radius, μ, stiffness "
                                    "or damping: not yet (a collider has one of each)");
    }
    const double R = std::max(b.radius, kMinRadius);
    shapes_.push_back(std::make_unique<btSphereShape>(R));
    btCollisionShape* shape = shapes_.back().get();
    if (mine.size() > 1 || b.centre.length() != 0.0) {  // off the centre of mass: spheres in a compound
      auto compound = std::make_unique<btCompoundShape>();
      for (std::size_t j : mine) compound->addChildShape(btTransform(btQuaternion::getIdentity(), balls[j].centre), shape);
      shapes_.push_back(std::move(compound));
      shape = shapes_.back().get();
    }
    btMultiBodyLinkCollider* c = colliders.at(std::size_t(b.link) + 1);
    Plane& p = planes[std::size_t(plane_of[i])];
    const int g = group();
    p.mask |= g;
    world->removeCollisionObject(c);
    c->setCollisionShape(shape);
    c->setFriction(b.mu);
    c->setRestitution(0.0);
    c->setRollingFriction(0.0);
    c->setSpinningFriction(0.0);
    if (b.stiffness > 0) c->setContactStiffnessAndDamping(b.stiffness, b.damping);
    world->addCollisionObject(c, g, p.group);
    for (std::size_t k = 0; k < mine.size(); ++k) {
      Placed& placed = balls_[mine[k]];
      placed.ball = balls[mine[k]];
      placed.child = mine.size() > 1 ? int(k) : -1;
      placed.collider = c;
    }
  }

  // The planes, colliding with their links only.
  for (std::size_t k = 0; k < planes.size(); ++k) {
    const Plane& p = planes[k];
    shapes_.push_back(std::make_unique<btStaticPlaneShape>(p.normal, p.height));
    btRigidBody::btRigidBodyConstructionInfo ci(0.0, nullptr, shapes_.back().get());
    ci.m_friction = 1.0;  // combined friction = μ_ball × 1
    ci.m_restitution = 0.0;
    auto body = std::make_unique<btRigidBody>(ci);
    if (p.compliant) body->setContactStiffnessAndDamping(BT_LARGE_FLOAT, 0.0);
    world->addRigidBody(body.get(), p.group, p.mask);
    for (std::size_t i = 0; i < balls.size(); ++i)
      if (plane_of[i] == int(k)) balls_[i].plane = body.get();
    planes_.push_back(std::move(body));
  }
}

void ContactBalls::clear(BulletWorld& world) {
  for (auto& p : planes_) world->removeRigidBody(p.get());
  planes_.clear();
}

void ContactBalls::force(const BulletWorld& world, int i, double dt, const btVector3& P, btVector3& f, btVector3& m) const {
  const Placed& b = balls_.at(std::size_t(i));
  f.setZero();
  m.setZero();
  for (int k = 0; k < world.dispatcher->getNumManifolds(); ++k) {
    const btPersistentManifold* man = world.dispatcher->getManifoldByIndexInternal(k);
    const bool ball_first = man->getBody0() == b.collider && man->getBody1() == b.plane;
    if (!ball_first && !(man->getBody1() == b.collider && man->getBody0() == b.plane)) continue;
    const double sign = ball_first ? 1.0 : -1.0;  // Bullet's impulses act on body 0 along +normal, +friction
    for (int j = 0; j < man->getNumContacts(); ++j) {
      const btManifoldPoint& cp = man->getContactPoint(j);
      if (b.child >= 0 && (ball_first ? cp.m_index0 : cp.m_index1) != b.child) continue;  // another ball of the link
      const btVector3 impulse = cp.m_normalWorldOnB * cp.m_appliedImpulse + cp.m_lateralFrictionDir1 * cp.m_appliedImpulseLateral1 +
                                cp.m_lateralFrictionDir2 * cp.m_appliedImpulseLateral2;
      const btVector3 fj = sign * impulse / dt;
      const btVector3 x = ball_first ? cp.getPositionWorldOnA() : cp.getPositionWorldOnB();  // on the ball
      f += fj;
      m += (x - P).cross(fj);
    }
  }
}

void addLinkColliders(BulletWorld& world, btMultiBody& body, int links, btCollisionShape* shape,
                      std::vector<std::unique_ptr<btMultiBodyLinkCollider>>& colliders) {
  for (int i = -1; i < links; ++i) {
    auto c = std::make_unique<btMultiBodyLinkCollider>(&body, i);
    c->setCollisionShape(shape);
    c->setActivationState(DISABLE_DEACTIVATION);
    world->addCollisionObject(c.get(), btBroadphaseProxy::DefaultFilter, 0);
    if (i < 0)
      body.setBaseCollider(c.get());
    else
      body.getLink(i).m_collider = c.get();
    colliders.push_back(std::move(c));
  }
}

void removeModel(BulletWorld& world, std::unique_ptr<btMultiBody>& body, std::vector<std::unique_ptr<btMultiBodyLinkCollider>>& colliders,
                 std::vector<std::unique_ptr<btMultiBodyConstraint>>& closures, ContactBalls& balls) {
  for (auto& c : closures) world->removeMultiBodyConstraint(c.get());
  balls.clear(world);
  for (auto& c : colliders) world->removeCollisionObject(c.get());
  if (body) world->removeMultiBody(body.get());
  closures.clear();
  colliders.clear();
  body.reset();
}

}  // namespace dyn::bullet
