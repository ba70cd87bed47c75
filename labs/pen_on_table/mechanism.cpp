// The pen-on-table arm's description (mechanism.h): three links and a contact as data; physics/ does the rest.
#include "labs/pen_on_table/mechanism.h"

#include <cmath>

#include "physics/constrained_mechanism_impl.h"
#include "physics/constraints/plane_contact.h"
#include "physics/det/det.h"

namespace dyn {
template class ConstrainedMechanism<Spatial, 3, 1, 0>;
}

namespace dyn::pen_on_table {
namespace {

// A solid cylinder of mass m, radius a and length l about its centre, its axis along `axis` (0 x, 2 z).
Eigen::Matrix3d cylinderInertia(double m, double a, double l, int axis) {
  const double along = m * a * a / 2, across = m * (3 * a * a + l * l) / 12;
  Eigen::Vector3d d = Eigen::Vector3d::Constant(across);
  d[axis] = along;
  return d.asDiagonal();
}

}  // namespace

MechanismModel<Spatial> describe(const Params& p) {
  using Pos = Spatial::Pos;
  MechanismModel<Spatial> d;
  auto& t = d.tree;
  t.gravity << 0, 0, 0, 0, 0, -p.gravity;
  const Link &c = p.links[0], &u = p.links[1], &f = p.links[2];
  // The column turns about z; the upper arm and forearm pitch about their y, lying along their x.
  const Spatial::Mat column = Spatial::inertia(c.mass, Pos(0, 0, c.length / 2), cylinderInertia(c.mass, c.radius, c.length, 2));
  const Spatial::Mat upper = Spatial::inertia(u.mass, Pos(u.length / 2, 0, 0), cylinderInertia(u.mass, u.radius, u.length, 0));
  // The forearm carries the pen; a heavier pen is a point mass at the tip's ball centre.
  Spatial::Mat fore = Spatial::inertia(f.mass, Pos(f.length / 2, 0, 0), cylinderInertia(f.mass, f.radius, f.length, 0));
  if (p.pen_load > 0) fore += Spatial::inertia(p.pen_load, Mechanism::tipPoint(p), Eigen::Matrix3d::Zero());
  int b = t.addBody(-1, JointType::Revolute, Pos::UnitZ(), Spatial::Transform(), column);
  b = t.addBody(b, JointType::Revolute, Pos::UnitY(), Spatial::translation(Pos(0, 0, c.length)), upper);
  b = t.addBody(b, JointType::Revolute, Pos::UnitY(), Spatial::translation(Pos(u.length, 0, 0)), fore);
  // The pen tip's ball against the table z = z_t (normal ẑ).
  PlaneContactParams contact;
  contact.radius = p.tip_radius;
  contact.height = p.table_height;
  contact.mu = p.mu;
  contact.stiffness = p.table_stiffness;
  contact.damping = p.table_damping;
  d.constraints.push_back(std::make_shared<PlaneContact<Spatial>>(BodyRef::link(b), Mechanism::tipPoint(p), Pos::UnitZ(), contact));
  return d;
}

Mechanism::Mechanism(const Params& params) : ConstrainedMechanism<Spatial, 3, 1, 0>(describe(params)), params_(params) {}

Eigen::Vector3d Mechanism::tip(const VecN& q) {
  return pointPosition(kPenLink, tipPoint(params_), q) - params_.tip_radius * Eigen::Vector3d::UnitZ();
}

void Mechanism::tipJacobian(const VecN& q, const VecN& v, Eigen::Vector3d& p, Eigen::Matrix3d& J, Eigen::Vector3d& Jdot_v) {
  MatN J6;
  VecN Jd6;
  pointJacobian(kPenLink, tipPoint(params_), q, v, J6, Jd6);
  J = J6.bottomRows<3>();
  Jdot_v = Jd6.tail<3>();
  p = tip(q);
}

Eigen::Vector3d forwardKinematics(const Params& p, const Eigen::Vector3d& th) {
  const double l2 = p.links[1].length, l3 = p.links[2].length;
  const double R = l2 * det::cos(th[1]) + l3 * det::cos(th[1] + th[2]);
  const double Z = -l2 * det::sin(th[1]) - l3 * det::sin(th[1] + th[2]);
  return {R * det::cos(th[0]), R * det::sin(th[0]), p.links[0].length + Z - p.tip_radius};
}

bool inverseKinematics(const Params& p, const Eigen::Vector3d& tip, Eigen::Vector3d& th) {
  const double l2 = p.links[1].length, l3 = p.links[2].length;
  const double R = det::hypot(tip.x(), tip.y()), Z = tip.z() + p.tip_radius - p.links[0].length;
  if (!(R > 1e-9)) return false;
  const double c3 = (R * R + Z * Z - l2 * l2 - l3 * l3) / (2 * l2 * l3);
  if (!(std::abs(c3) <= 1)) return false;
  // Angles up from the horizontal: φ3 < 0 puts the elbow above the shoulder–tip line.
  const double phi3 = -det::acos(c3);
  const double phi2 = det::atan2(Z, R) - det::atan2(l3 * det::sin(phi3), l2 + l3 * det::cos(phi3));
  th << det::atan2(tip.y(), tip.x()), -phi2, -phi3;
  return true;
}

double elbowSine(const Params& p, const Eigen::Vector3d& tip) {
  const double l2 = p.links[1].length, l3 = p.links[2].length;
  const double R = det::hypot(tip.x(), tip.y()), Z = tip.z() + p.tip_radius - p.links[0].length;
  const double c3 = (R * R + Z * Z - l2 * l2 - l3 * l3) / (2 * l2 * l3);
  return std::abs(c3) >= 1 ? 0.0 : std::sqrt(1 - c3 * c3);
}

}  // namespace dyn::pen_on_table
