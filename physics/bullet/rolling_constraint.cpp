// The no-slip rolling constraint for Bullet: rows, geometry; the maths is in rolling_constraint.h.
#include "physics/bullet/rolling_constraint.h"

#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>

namespace dyn::bullet {

RimContact rimContact(const btMultiBody& body, int link, const btVector3& centre_link, const btVector3& axle_link,
                      double radius) {
  const btVector3 up(0, 0, 1);
  RimContact c;
  c.centre = body.localPosToWorld(link, centre_link);
  c.axle = body.localDirToWorld(link, axle_link).normalized();
  const btVector3 u = up - up.dot(c.axle) * c.axle;
  // A disk lying flat has no lowest point: take the one under the centre (as rolling.cpp does).
  c.down = u.length() > 1e-9 ? u / u.length() : up;
  c.point = c.centre - radius * c.down;
  return c;
}

RollingNoSlipConstraint::RollingNoSlipConstraint(btMultiBody* body, int link, const btVector3& centre_link,
                                                 const btVector3& axle_link, double radius, double ground_height)
    : btMultiBodyConstraint(body, nullptr, link, -1, 3, false, MAX_MULTIBODY_CONSTRAINT_TYPE),
      centre_(centre_link),
      axle_(axle_link),
      radius_(radius),
      ground_(ground_height) {
  m_data.resize(3);  // the applied impulse of each row (Jacobians are filled per step, not cached)
  for (int i = 0; i < 3; ++i) m_data[i] = 0;
}

int RollingNoSlipConstraint::getIslandIdA() const {
  const btMultiBodyLinkCollider* c = m_linkA < 0 ? m_bodyA->getBaseCollider() : m_bodyA->getLink(m_linkA).m_collider;
  return c ? c->getIslandTag() : -1;
}

void RollingNoSlipConstraint::createConstraintRows(btMultiBodyConstraintArray& rows, btMultiBodyJacobianData& data,
                                                   const btContactSolverInfo& info) {
  btMultiBody& mb = *m_bodyA;
  const int width = 6 + mb.getNumDofs();
  jac_.resize(3 * width);
  // The rows' Jacobians at the predicted end of the step q + dt v (Bullet's velocities already carry
  // this step's free acceleration), where Bullet will put the bodies with the velocities it solves for.
  const RimContact now = rimContact(mb, m_linkA, centre_, axle_, radius_);
  q_.resize(mb.getNumLinks());
  for (int i = 0; i < mb.getNumLinks(); ++i) {
    if (mb.getLink(i).m_dofCount != 1) continue;
    q_[i] = mb.getJointPos(i);
    mb.setJointPos(i, q_[i] + info.m_timeStep * mb.getJointVel(i));
  }
  point_ = rimContact(mb, m_linkA, centre_, axle_, radius_).point;
  for (int k = 0; k < 3; ++k) {
    btVector3 axis(0, 0, 0);
    axis[k] = 1;
    mb.fillConstraintJacobianMultiDof(m_linkA, point_, btVector3(0, 0, 0), axis, &jac_[k * width], data.scratch_r,
                                      data.scratch_v, data.scratch_m);
  }
  for (int i = 0; i < mb.getNumLinks(); ++i)
    if (mb.getLink(i).m_dofCount == 1) mb.setJointPos(i, q_[i]);  // back to the step's start, exactly

  for (int k = 0; k < 3; ++k) {
    btMultiBodySolverConstraint& row = rows.expandNonInitializing();
    row.m_orgConstraint = this;
    row.m_orgDofIndex = k;
    row.m_relpos1CrossNormal.setValue(0, 0, 0);
    row.m_contactNormal1.setValue(0, 0, 0);
    row.m_relpos2CrossNormal.setValue(0, 0, 0);
    row.m_contactNormal2.setValue(0, 0, 0);
    row.m_angularComponentA.setValue(0, 0, 0);
    row.m_angularComponentB.setValue(0, 0, 0);
    row.m_solverBodyIdA = data.m_fixedBodyId;
    row.m_solverBodyIdB = data.m_fixedBodyId;
    btVector3 axis(0, 0, 0);
    axis[k] = 1;
    // Bullet drives the row's velocity to −ERP·error/dt: only z has a position error (the rim's now).
    const btScalar error = k == 2 ? now.point.z() - ground_ : 0.0;
    fillMultiBodyConstraint(row, data, &jac_[k * width], nullptr, btVector3(0, 0, 0), axis, point_, point_, error, info,
                            -m_maxAppliedImpulse, m_maxAppliedImpulse);
  }
}

}  // namespace dyn::bullet
