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

namespace dyn::bullet {

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
