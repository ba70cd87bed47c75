// The unicycle's description (mechanism.h): thirty lines of data; physics/ does the rest.
#include "labs/unicycle/mechanism.h"

#include <cmath>

#include "physics/constrained_mechanism_impl.h"
#include "physics/constraints/rolling.h"
#include "physics/det/det.h"

namespace dyn {
template class ConstrainedMechanism<Spatial, 5, 3, 0>;
}

namespace dyn::unicycle {

MechanismModel<Spatial> describe(const Params& p) {
  MechanismModel<Spatial> d;
  auto& t = d.tree;
  t.gravity << 0, 0, 0, 0, 0, -p.gravity;
  const Spatial::Mat none = Spatial::Mat::Zero();
  const Spatial::Transform here;
  // The centre's three translations and the heading carry nothing; the wheel spins about its y axis.
  int b = t.addBody(-1, JointType::Prismatic, Spatial::Pos::UnitX(), here, none);
  b = t.addBody(b, JointType::Prismatic, Spatial::Pos::UnitY(), here, none);
  b = t.addBody(b, JointType::Prismatic, Spatial::Pos::UnitZ(), here, none);
  b = t.addBody(b, JointType::Revolute, Spatial::Pos::UnitZ(), here, none);
  const Eigen::Vector3d I(p.steer_inertia, p.axle_inertia, p.steer_inertia);
  b = t.addBody(b, JointType::Revolute, Spatial::Pos::UnitY(), here, Spatial::inertia(p.mass, Spatial::Pos::Zero(), I.asDiagonal()));
  d.constraints.push_back(std::make_shared<Rolling>(BodyRef::link(b), Spatial::Pos::Zero(), Spatial::Pos::UnitY(), p.radius, 0.0, p.mu));
  return d;
}

Mechanism::Mechanism(const Params& params) : ConstrainedMechanism<Spatial, 5, 3, 0>(describe(params)), params_(params) {}

void Mechanism::state(double x, double y, double phi, double theta, double phi_rate, double theta_rate, VecN& q, VecN& v) const {
  const double r = params_.radius;
  q.resize(5);
  v.resize(5);
  q << x, y, r, phi, theta;
  v << r * det::cos(phi) * theta_rate, r * det::sin(phi) * theta_rate, 0.0, phi_rate, theta_rate;
}

double Mechanism::slipSpeed(const VecN& q, const VecN& v) const {
  // The contact's material velocity: the centre's, less r θ' along the heading (ω × (−r ẑ)).
  const double r = params_.radius, c = det::cos(q[Phi]), s = det::sin(q[Phi]);
  return det::hypot(v[X] - r * c * v[Theta], v[Y] - r * s * v[Theta]);
}

}  // namespace dyn::unicycle
