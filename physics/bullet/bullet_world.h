// The Bullet world both reference builders step in (bullet_mechanism.cpp: planar; spatial_mechanism.cpp:
// spatial), made one way (shared/notes/bullet-reference.md): the default collision configuration,
// dispatcher and broadphase, the multibody PGS solver with `iterations`, and gravity from the
// description (pitfall 2: Bullet's default is (0, −10, 0)). Private to physics/bullet/.
// A model removes what it added before the world goes: declare the BulletWorld before the bodies,
// colliders and constraints it holds, so that it is destroyed after them.
#pragma once
#include <btBulletDynamicsCommon.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>

#include <memory>
#include <vector>

#include "physics/mechanism.h"

namespace dyn::bullet {

// The torque both builders hold on tree joint i over a step: τ_i less the description's spring,
// viscous and Coulomb friction from the step's start, τ − k (θ − θ_rest) − F(θ'); F(θ') into friction
// (for the books). Without joint properties, τ_i.
inline double heldTorque(const std::vector<JointProperties>& joints, int i, double tau, double q, double v, double& friction) {
  if (joints.empty()) return tau;
  const JointProperties& jp = joints[std::size_t(i)];
  friction = jp.friction(v);
  return tau - (jp.stiffness * (q - jp.rest) + friction);
}

struct BulletWorld {
  std::unique_ptr<btDefaultCollisionConfiguration> config = std::make_unique<btDefaultCollisionConfiguration>();
  std::unique_ptr<btCollisionDispatcher> dispatcher = std::make_unique<btCollisionDispatcher>(config.get());
  std::unique_ptr<btDbvtBroadphase> broadphase = std::make_unique<btDbvtBroadphase>();
  std::unique_ptr<btMultiBodyConstraintSolver> solver = std::make_unique<btMultiBodyConstraintSolver>();
  std::unique_ptr<btMultiBodyDynamicsWorld> world =
      std::make_unique<btMultiBodyDynamicsWorld>(dispatcher.get(), broadphase.get(), solver.get(), config.get());

  BulletWorld(const btVector3& gravity, int iterations) {
    world->setGravity(gravity);
    world->getSolverInfo().m_numIterations = iterations;
  }
  btMultiBodyDynamicsWorld* operator->() const { return world.get(); }
};

}  // namespace dyn::bullet
