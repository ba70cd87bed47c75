// The fixed-base btMultiBody of a planar plan (planar_plan.h), as every planar Bullet model builds it:
// links at their centres of mass, revolute axes z, in Bullet's x–y plane, with the settings of
// shared/notes/bullet-reference.md pitfall 2 (no damping, no joint-speed cap, never sleeps) plus
// gyroscopic terms on and no self-collision; added to the world. Colliders are the caller's (a model
// with multibody constraints needs them, pitfall 1; a bare chain does not). Private to physics/bullet/.
#pragma once
#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>

#include <memory>

#include "physics/bullet/planar_plan.h"

namespace dyn::bullet {

inline btVector3 bt(const Eigen::Vector2d& v) { return {v.x(), v.y(), 0.0}; }

std::unique_ptr<btMultiBody> makePlanarMultiBody(const Plan& plan, btMultiBodyDynamicsWorld& world);

}  // namespace dyn::bullet
