// The rolling kind (physics/constraints/rolling.h) as a Bullet 3.24 multibody constraint: a disk on a
// link of a btMultiBody rolls without slip on the ground plane z = h. Internal to physics/bullet/.
//   contact  P = p − r d, d = u/|u|, u = ẑ − (ẑ·a) a      (p the disk centre, a its world axle)
//   rows     world x, y: the wheel's material point at P has no ground velocity (no position error:
//            nonholonomic, there is nothing to drift back to); world z: the same velocity with the
//            position error P_z − h of the step's start (Bullet's ERP pulls the rim back onto the ground)
// Where the rows are written. Bullet's step solves the velocities v₁ and then moves q₁ = q₀ + dt v₁.
// Rows written at q₀ hold at q₀, and the state Bullet returns then reads a slip of r θ' φ' dt (the
// heading turned under them: 2.7e-4 m/s for the unicycle at 1 ms). So the Jacobians are taken at the
// predicted end of the step q₀ + dt v* (v*: Bullet's velocities before the constraint impulses, this
// step's free acceleration included), where the wheel will be: the returned states hold the rows to
// the solver's tolerance (~1e-14 m/s) and the trajectory stays first order.
// All three rows are bilateral (impulse in ±cap): the description's rolling constraint is an
// equality, so the wheel cannot lift off here either (the friction model is the one that can).
// Bullet applies the impulse λ_i along +e_i to the wheel at P, so the ground's force on the wheel
// over the step is f = λ / dt (world axes, at P, no moment).
#pragma once
#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraint.h>

namespace dyn::bullet {

// The disk's geometry at the multibody's current state: centre, world axle, down, contact point.
struct RimContact {
  btVector3 centre, axle, down, point;
};
RimContact rimContact(const btMultiBody& body, int link, const btVector3& centre_link, const btVector3& axle_link,
                      double radius);

class RollingNoSlipConstraint final : public btMultiBodyConstraint {
 public:
  // centre_link, axle_link: in Bullet's link frame (its centre of mass, principal axes).
  RollingNoSlipConstraint(btMultiBody* body, int link, const btVector3& centre_link, const btVector3& axle_link,
                          double radius, double ground_height);

  void finalizeMultiDof() override {}
  int getIslandIdA() const override;
  int getIslandIdB() const override { return -1; }  // the world
  void createConstraintRows(btMultiBodyConstraintArray& rows, btMultiBodyJacobianData& data,
                            const btContactSolverInfo& info) override;
  void debugDraw(btIDebugDraw*) override {}

  // The ground's impulse on the wheel over the last step (world axes), and where it acted (the
  // predicted contact point).
  btVector3 impulse() const { return {m_data[0], m_data[1], m_data[2]}; }
  const btVector3& lastPoint() const { return point_; }

 private:
  btVector3 centre_, axle_;
  double radius_, ground_;
  btVector3 point_{0, 0, 0};
  btAlignedObjectArray<btScalar> jac_, q_;  // scratch: the rows' Jacobians, the joint positions
};

}  // namespace dyn::bullet
