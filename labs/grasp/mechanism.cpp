// The grasp's description, and what is particular to it: assembling the fingers on the object and the
// grasp map (equations in mechanism.h).
#include "labs/grasp/mechanism.h"

#include <Eigen/LU>
#include <cmath>

#include "physics/constrained_mechanism_impl.h"
#include "physics/constraints/point_contact.h"
#include "physics/det/det.h"

namespace dyn {
template class ConstrainedMechanism<Planar, 4, 4, 3>;
}

namespace dyn::grasp {
namespace {

Eigen::Vector2d rotate(double a, const Eigen::Vector2d& p) {
  const double c = det::cos(a), s = det::sin(a);
  return {c * p.x() - s * p.y(), s * p.x() + c * p.y()};
}

}  // namespace

MechanismModel<Planar> describe(const Params& p) {
  MechanismModel<Planar> d;
  for (const Finger& f : p.fingers) {
    // Joint 1 at the base, joint 2 at the end of link 1; centres of mass at mid-length.
    const int first = d.tree.dof();
    for (int j = 0; j < 2; ++j) {
      const Link& l = f.links[std::size_t(j)];
      const Planar::Pos offset = j == 0 ? Planar::Pos(f.base) : Planar::Pos(f.links[0].length, 0.0);
      d.tree.addBody(j == 0 ? -1 : first, JointType::Revolute, Planar::Axis::Zero(), Planar::translation(offset),
                     Planar::inertia(l.mass, Planar::Pos(0.5 * l.length, 0.0), l.inertia));
    }
  }
  d.tree.gravity << 0.0, p.gravity.x(), p.gravity.y();
  if (p.joint.viscous != 0 || p.joint.coulomb != 0) d.joints.assign(std::size_t(d.tree.dof()), p.joint);
  Payload object;
  object.name = "object";
  object.mass = p.object.mass;
  object.inertia = p.object.inertia;
  d.payloads.push_back(object);
  // Each fingertip (the end of its second link) presses on its contact point of the object.
  for (std::size_t i = 0; i < p.fingers.size(); ++i) {
    const Finger& f = p.fingers[i];
    d.constraints.push_back(std::make_shared<PointContact<Planar>>(
        BodyRef::link(int(2 * i + 1)), Planar::Pos(f.links[1].length, 0.0), BodyRef::payload(0), f.contact, f.normal, p.mu));
  }
  d.forces = p.forces;
  // Bullet: fingers as one multibody from the world, the object on guide links, point-to-point grips.
  d.bullet.solver_iterations = 50;
  return d;
}

Mechanism::Mechanism(const Params& p) : ConstrainedMechanism(describe(p)), params_(p) {}

TwoFingers::TwoFingers(const Params& p) : ConstrainedMechanism(describe(p)), shape_(p) {}

Eigen::Vector2d Mechanism::contactPoint(int i, const Eigen::Vector3d& pose) const {
  return pose.tail<2>() + rotate(pose[0], params_.fingers[std::size_t(i)].contact);
}

Eigen::Vector2d Mechanism::contactNormal(int i, double psi) const {
  return rotate(psi, params_.fingers[std::size_t(i)].normal.normalized());
}

bool Mechanism::assemble(const Eigen::Vector3d& pose, const Eigen::Vector3d& rate, VecN& q, VecN& v, std::string* why) const {
  const int m = fingers(), nn = 2 * m;
  q.setZero(nn + 3);
  v.setZero(nn + 3);
  q.tail(3) = pose;
  v.tail(3) = rate;
  for (int i = 0; i < m; ++i) {
    const Finger& f = params_.fingers[std::size_t(i)];
    const double l1 = f.links[0].length, l2 = f.links[1].length;
    const Eigen::Vector2d p = contactPoint(i, pose), d = p - f.base;
    // Two-link inverse kinematics: cos θ2 from the distance, θ1 from the direction.
    const double c2 = (d.squaredNorm() - l1 * l1 - l2 * l2) / (2 * l1 * l2);
    if (!(std::abs(c2) <= 1.0)) {
      if (why) *why = "finger " + std::to_string(i + 1) + " cannot reach its contact point (" + std::to_string(d.norm()) +
                      " m from its base; its links reach " + std::to_string(std::abs(l1 - l2)) + " to " + std::to_string(l1 + l2) + " m)";
      return false;
    }
    const double th2 = (f.elbow >= 0 ? 1.0 : -1.0) * det::acos(c2);
    const double th1 = det::atan2(d.y(), d.x()) - det::atan2(l2 * det::sin(th2), l1 + l2 * det::cos(th2));
    q[joint(i)] = th1;
    q[joint(i) + 1] = th2;
    // Rates: the tip moves with the object's contact point, J_i θ_i' = v_o + ω × r_i.
    const double s1 = det::sin(th1), s12 = det::sin(th1 + th2), c1 = det::cos(th1), c12 = det::cos(th1 + th2);
    Eigen::Matrix2d J;
    J << -l1 * s1 - l2 * s12, -l2 * s12, l1 * c1 + l2 * c12, l2 * c12;
    const Eigen::Vector2d r = p - pose.tail<2>();
    const Eigen::Vector2d vp = rate.tail<2>() + rate[0] * Eigen::Vector2d(-r.y(), r.x());
    const Eigen::Vector2d w = J.fullPivLu().solve(vp);
    if (!w.allFinite() || std::abs(J.determinant()) < 1e-12) {
      if (why) *why = "finger " + std::to_string(i + 1) + " is stretched straight (singular) at its contact point";
      return false;
    }
    v[joint(i)] = w[0];
    v[joint(i) + 1] = w[1];
  }
  return true;
}

bool Mechanism::recoverDependent(VecN& q, VecN& v) {
  // Keep each finger on the elbow branch it is on.
  for (int i = 0; i < fingers(); ++i) params_.fingers[std::size_t(i)].elbow = q[joint(i) + 1] >= 0 ? 1 : -1;
  VecN q1, v1;
  if (!assemble(q.tail(3), v.tail(3), q1, v1)) return false;
  q = q1;
  v = v1;
  return true;
}

std::vector<Eigen::Vector2d> Mechanism::fingerPoints(int i, const VecN& q) const {
  const Finger& f = params_.fingers[std::size_t(i)];
  const double a1 = q[joint(i)], a12 = a1 + q[joint(i) + 1];
  const Eigen::Vector2d elbow = f.base + f.links[0].length * Eigen::Vector2d(det::cos(a1), det::sin(a1));
  return {f.base, elbow, elbow + f.links[1].length * Eigen::Vector2d(det::cos(a12), det::sin(a12))};
}

void Mechanism::graspMap(const Eigen::Vector3d& pose, MatN& G, VecN& d) const {
  const int m = fingers();
  G.setZero(3, 2 * m);
  VecN e(2 * m);
  for (int i = 0; i < m; ++i) {
    const Eigen::Vector2d r = contactPoint(i, pose) - pose.tail<2>();
    G(0, 2 * i) = -r.y();
    G(0, 2 * i + 1) = r.x();
    G(1, 2 * i) = 1.0;
    G(2, 2 * i + 1) = 1.0;
    e.segment<2>(2 * i) = -contactNormal(i, pose[0]);
  }
  // d = e − G⁺ G e, G⁺ = Gᵀ (G Gᵀ)⁻¹ (G has full row rank for two or more distinct contacts).
  const Eigen::Matrix3d GGt = G * G.transpose();
  d = e - G.transpose() * GGt.ldlt().solve(G * e);
}

double Mechanism::internalForce(const Eigen::Vector3d& pose, const VecN& F) const {
  MatN G;
  VecN d;
  graspMap(pose, G, d);
  const double dd = d.squaredNorm();
  return dd > 0 ? d.dot(F) / dd : 0.0;
}

MatN Mechanism::tipJacobian(const VecN& q) {
  const int m = fingers();
  MatN out = MatN::Zero(2 * m, n());
  MatN J;
  VecN unused;
  const VecN zero = VecN::Zero(q.size());
  for (int i = 0; i < m; ++i) {
    pointJacobian(joint(i) + 1, Planar::Pos(params_.fingers[std::size_t(i)].links[1].length, 0.0), q, zero, J, unused);
    out.middleRows(2 * i, 2) = J.bottomRows(2);
  }
  return out;
}

}  // namespace dyn::grasp
