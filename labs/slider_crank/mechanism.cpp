// The slider crank's description, and what is particular to it: inverse kinematics and drawing points.
#include "labs/slider_crank/mechanism.h"

#include <Eigen/LU>
#include <cmath>

#include "physics/constrained_mechanism_impl.h"
#include "physics/constraints/point_closure.h"
#include "physics/det/det.h"

namespace dyn {
template class ConstrainedMechanism<Planar, 3, 3, 1>;
}

namespace dyn::slider_crank {
namespace {
const Eigen::Vector3d kA{0.0, 1.0, 0.0};  // the slider moves the tip along world x only
}

MechanismModel<Planar> describe(const Params& p) {
  MechanismModel<Planar> d;
  // Three revolute joints about z; link i+1's joint sits at the end of link i.
  for (int i = 0; i < 3; ++i) {
    const Link& l = p.links[std::size_t(i)];
    const Planar::Pos offset = i == 0 ? Planar::Pos::Zero() : Planar::Pos(p.links[std::size_t(i - 1)].length, 0.0);
    Planar::Mat inertia = Planar::inertia(l.mass, l.com, l.inertia);
    // The tool: a point mass at link 3's tip (spatial inertias in one frame add).
    if (i == 2 && p.tool_mass > 0) inertia += Planar::inertia(p.tool_mass, Planar::Pos(l.length, 0.0), 0.0);
    d.tree.addBody(i - 1, JointType::Revolute, Planar::Axis::Zero(), Planar::translation(offset), inertia);
  }
  d.tree.gravity << 0.0, p.gravity.x(), p.gravity.y();
  // The slider: a payload on a guide along world x (its rotational inertia never matters).
  Payload slider;
  slider.name = "slider";
  slider.mass = p.load_mass;
  slider.inertia = p.load_mass * 0.05 * 0.05 / 6.0;
  slider.free = {false, true, false};
  d.payloads.push_back(slider);
  // The tip welded to the slider: angle, x and y held.
  d.constraints.push_back(std::make_shared<PointClosure<Planar>>(BodyRef::link(2), Planar::Pos(p.links[2].length, 0.0),
                                                                 BodyRef::payload(0), Planar::Pos::Zero(),
                                                                 PointClosure<Planar>::all()));
  // Bullet: grow the tree from the slider and close the loop at joint 1.
  d.bullet.cut_joints = {0};
  d.bullet.solver_iterations = 30;
  return d;
}

Mechanism::Mechanism(const Params& p) : ConstrainedMechanism(describe(p)), params_(p) {}

bool Mechanism::recoverDependent(VecN& q, VecN& v) {
  const auto& L = params_.links;
  const double s12 = -L[0].length * det::sin(q[0]) / L[1].length;
  if (std::abs(s12) > 1.0) return false;
  // Stay on the current branch of cos(θ1+θ2).
  const double branch = det::cos(q[0] + q[1]) >= 0 ? 1.0 : -1.0;
  const double th12 = det::atan2(s12, branch * std::sqrt(1.0 - s12 * s12));
  q[1] = th12 - q[0];
  q[2] = -th12;
  q[3] = tip(q.head(3)).x();
  // Rates: [J_2 J_3 −A] (θ2', θ3', v_c) = −J_1 θ1'.
  MatN J;
  VecN unused;
  tipJacobian(q.head(3), Eigen::Vector3d::Zero(), J, unused);
  Eigen::Matrix3d B;
  B << J.col(1), J.col(2), -kA;
  const Eigen::Vector3d rest = B.fullPivLu().solve(-J.col(0) * v[0]);
  v[1] = rest[0];
  v[2] = rest[1];
  v[3] = rest[2];
  return std::isfinite(v[3]);
}

bool Mechanism::initialState(double theta1, double rate1, int branch, VecN& q, VecN& v) const {
  const auto& L = params_.links;
  const double s12 = -L[0].length * det::sin(theta1) / L[1].length;
  if (std::abs(s12) > 1.0) return false;
  q.resize(4);
  v.resize(4);
  q << theta1, 0, 0, 0;
  v << rate1, 0, 0, 0;
  // The branch is read from cos(θ1+θ2) of the guess: seed it with the requested sign.
  q[1] = (branch >= 0 ? det::asin(s12) : M_PI - det::asin(s12)) - theta1;
  return const_cast<Mechanism*>(this)->recoverDependent(q, v);
}

Eigen::Vector2d Mechanism::tip(const Eigen::Vector3d& th) const { return jointPoints(th)[3]; }

std::array<Eigen::Vector2d, 4> Mechanism::jointPoints(const Eigen::Vector3d& th) const {
  std::array<Eigen::Vector2d, 4> p;
  p[0].setZero();
  double angle = 0;
  for (int i = 0; i < 3; ++i) {
    angle += th[i];
    p[std::size_t(i) + 1] = p[std::size_t(i)] + params_.links[std::size_t(i)].length * Eigen::Vector2d(det::cos(angle), det::sin(angle));
  }
  return p;
}

void Mechanism::tipJacobian(const Eigen::Vector3d& th, const Eigen::Vector3d& rate, MatN& J, VecN& Jdot_qd) {
  pointJacobian(2, tipPoint(), VecN(th), VecN(rate), J, Jdot_qd);
}

Eigen::Vector3d Mechanism::gravityTorque(const Eigen::Vector3d& th) {
  return ConstrainedMechanism::gravityTorque(VecN(th));
}

}  // namespace dyn::slider_crank
