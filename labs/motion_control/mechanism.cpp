// The motion-control arm as data (mechanism.h), and the maps between tree and arm coordinates.
#include "labs/motion_control/mechanism.h"

#include <cmath>

#include "physics/constrained_mechanism_impl.h"
#include "physics/det/det.h"

namespace dyn {
template class ConstrainedMechanism<Planar, 3, 0, 0>;
template class ConstrainedMechanism<Planar, 6, 0, 0>;
}  // namespace dyn

namespace dyn::motion_control {
namespace {

// The last link with the payload as a point mass at its tip (parallel-axis theorem).
Link withPayload(Link l, double payload) {
  if (payload <= 0) return l;
  const Eigen::Vector2d tip(l.length, 0.0);
  const double m = l.mass + payload;
  const Eigen::Vector2d c = (l.mass * l.com + payload * tip) / m;
  l.inertia += l.mass * (l.com - c).squaredNorm() + payload * (tip - c).squaredNorm();
  l.mass = m;
  l.com = c;
  return l;
}

JointProperties frictionOf(const Params& p, int i) {
  JointProperties j;
  j.viscous = p.friction[std::size_t(i)].viscous;
  j.coulomb = p.friction[std::size_t(i)].coulomb;
  j.coulomb_width = p.coulomb_width;
  return j;
}

MechanismModel<Planar> build(const Params& p, bool flexible) {
  MechanismModel<Planar> d;
  int parent = -1;
  for (int i = 0; i < p.n(); ++i) {
    const Link l = i + 1 == p.n() ? withPayload(p.links[std::size_t(i)], p.payload) : p.links[std::size_t(i)];
    const Planar::Pos offset = i == 0 ? Planar::Pos::Zero() : Planar::Pos(p.links[std::size_t(i - 1)].length, 0.0);
    if (flexible) {
      // The rotor: on the joint axis, driven, with the joint's friction.
      parent = d.tree.addBody(parent, JointType::Revolute, Planar::Axis::Zero(), Planar::translation(offset),
                              Planar::inertia(p.rotor_mass, Eigen::Vector2d::Zero(), p.rotor_inertia));
      d.joints.push_back(frictionOf(p, i));
      // The link on the spring: deflection δ relative to the rotor.
      parent = d.tree.addBody(parent, JointType::Revolute, Planar::Axis::Zero(), Planar::translation(Planar::Pos::Zero()),
                              Planar::inertia(l.mass, l.com, l.inertia));
      JointProperties spring;
      spring.stiffness = p.stiffness[std::size_t(i)];
      d.joints.push_back(spring);
    } else {
      parent = d.tree.addBody(parent, JointType::Revolute, Planar::Axis::Zero(), Planar::translation(offset),
                              Planar::inertia(l.mass, l.com, l.inertia));
      d.joints.push_back(frictionOf(p, i));
    }
  }
  d.tree.gravity << 0.0, p.gravity.x(), p.gravity.y();
  return d;
}

}  // namespace

MechanismModel<Planar> describe(const Params& p) { return build(p, p.flexible); }
MechanismModel<Planar> describeRigid(const Params& p) { return build(p, false); }

ArmState armState(const Params& p, const VecN& q, const VecN& v) {
  const int n = p.n();
  ArmState s;
  s.link.resize(n), s.link_rate.resize(n), s.motor.resize(n), s.motor_rate.resize(n), s.deflection.resize(n);
  for (int i = 0; i < n; ++i) {
    if (p.flexible) {
      s.motor[i] = q[2 * i], s.motor_rate[i] = v[2 * i], s.deflection[i] = q[2 * i + 1];
      s.link[i] = q[2 * i] + q[2 * i + 1], s.link_rate[i] = v[2 * i] + v[2 * i + 1];
    } else {
      s.motor[i] = s.link[i] = q[i], s.motor_rate[i] = s.link_rate[i] = v[i], s.deflection[i] = 0;
    }
  }
  return s;
}

void treeState(const Params& p, const Eigen::VectorXd& theta, const Eigen::VectorXd& deflection, VecN& q, VecN& v) {
  const int n = p.n(), nq = p.flexible ? 2 * n : n;
  q.setZero(nq), v.setZero(nq);
  for (int i = 0; i < n; ++i) {
    if (p.flexible) q[2 * i] = theta[i] - deflection[i], q[2 * i + 1] = deflection[i];
    else q[i] = theta[i];
  }
}

VecN treeTorque(const Params& p, const Eigen::VectorXd& tau) {
  const int n = p.n();
  VecN t = VecN::Zero(p.flexible ? 2 * n : n);
  for (int i = 0; i < n; ++i) t[p.flexible ? 2 * i : i] = tau[i];
  return t;
}

std::vector<Eigen::Vector2d> jointPoints(const Params& p, const Eigen::VectorXd& th) {
  std::vector<Eigen::Vector2d> pts{Eigen::Vector2d::Zero()};
  double angle = 0;
  for (int i = 0; i < p.n(); ++i) {
    angle += th[i];
    pts.push_back(pts.back() + p.links[std::size_t(i)].length * Eigen::Vector2d(det::cos(angle), det::sin(angle)));
  }
  return pts;
}

}  // namespace dyn::motion_control
