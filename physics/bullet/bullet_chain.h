// Bullet 3.24's btMultiBody of a planar tree (physics/chain.h TreeModel<Planar>) of any size, for the
// scaling bench (`dynlab bench --scaling`) and the large-chain tests: grown by the planar builders' own
// plan and multibody (planar_plan.h, planar_multibody.h: links at their centres of mass in Bullet's x–y
// plane, no damping, no joint-speed cap, gyroscopic terms on). It has no colliders: a bare tree has
// nothing to collide with and no multibody constraint that would need them (pitfall 1), so Bullet's
// step is its articulated-body dynamics and integration alone. Eigen-only header; Bullet stays in the .cpp.
#pragma once
#include <memory>
#include <string>

#include "physics/chain.h"

namespace dyn::bullet {

class BulletChain {
 public:
  // q0, v0: one value per tree joint. Throws std::invalid_argument for a tree it cannot model.
  BulletChain(const TreeModel<Planar>& tree, double dt, const Eigen::VectorXd& q0, const Eigen::VectorXd& v0);
  ~BulletChain();
  BulletChain(const BulletChain&) = delete;
  BulletChain& operator=(const BulletChain&) = delete;

  // One fixed step of dt (exactly one Bullet step) with the joint torques τ held.
  void step(const VecIn& tau);
  // Joint coordinates and rates, in the tree's joint order and sign.
  void state(Eigen::VectorXd& q, Eigen::VectorXd& v) const;
  // World position of `point` (body coordinates) of tree body `body`, as Bullet has it.
  Eigen::Vector2d pointPosition(int body, const Eigen::Vector2d& point) const;
  int dof() const;
  // One line for the bench: what was built.
  std::string describe() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dyn::bullet
