// The planar plan as one btMultiBody (see planar_multibody.h).
#include "physics/bullet/planar_multibody.h"

#ifndef BT_USE_DOUBLE_PRECISION
#error "planar_multibody.cpp must be built against bullet-float64 (BT_USE_DOUBLE_PRECISION)"
#endif

namespace dyn::bullet {
namespace {

btVector3 inertia3(double izz) { return {izz, izz, izz}; }  // out-of-plane values only need to be ≥ 0
btQuaternion rotParentToThis(double delta) {
  return delta == 0.0 ? btQuaternion::getIdentity() : btQuaternion(btVector3(0, 0, 1), -delta);
}

}  // namespace

std::unique_ptr<btMultiBody> makePlanarMultiBody(const Plan& plan, btMultiBodyDynamicsWorld& world) {
  const int n = int(plan.links.size());
  auto body = std::make_unique<btMultiBody>(n, 1.0, btVector3(1, 1, 1), /*fixedBase=*/true, /*canSleep=*/false);
  body->setBaseWorldTransform(btTransform::getIdentity());
  for (int k = 0; k < n; ++k) {
    const PlanLink& l = plan.links[std::size_t(k)];
    const btQuaternion rot = rotParentToThis(l.delta);
    if (l.joint == PlanLink::Joint::Revolute)
      body->setupRevolute(k, l.mass, inertia3(l.inertia), l.parent, rot, btVector3(0, 0, 1), bt(l.e), bt(l.d), true);
    else if (l.joint == PlanLink::Joint::Prismatic)
      body->setupPrismatic(k, l.mass, inertia3(l.inertia), l.parent, rot, bt(l.axis), bt(l.e), bt(l.d), true);
    else
      body->setupFixed(k, l.mass, inertia3(l.inertia), l.parent, rot, bt(l.e), bt(l.d));
  }
  body->finalizeMultiDof();
  // Pitfall 2: no damping, no velocity cap, never sleep.
  body->setLinearDamping(0.0);
  body->setAngularDamping(0.0);
  body->setMaxCoordinateVelocity(1e6);
  body->setCanSleep(false);
  body->setHasSelfCollision(false);
  body->setUseGyroTerm(true);
  world.addMultiBody(body.get());
  return body;
}

}  // namespace dyn::bullet
