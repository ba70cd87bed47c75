// The unicycle of tests/physics/test_rolling.cpp as a description, for the Bullet tests: an upright
// wheel hung from the world by x, y, z, heading φ (about z) and spin θ (about the axle y), the
// carriers massless, q = (x, y, z, φ, θ), one rolling constraint on the ground z = 0.
#pragma once
#include <cmath>
#include <memory>

#include "physics/constraints/rolling.h"
#include "physics/mechanism.h"

namespace dyn::bullet::test {

struct Unicycle {
  double r = 0.1, m = 2.0, g = 9.81, mu = 0.8;
  double carrier_mass = 0.0;  // > 0: every carrier gets this mass (and m r² × it / m inertia)
  double com_y = 0.0;         // a lopsided wheel: centre of mass this far along the axle from the disk's centre
  double product = 0.0;       // and these products of inertia (xy, xz, yz = product, −product/2, product/3)
  double Ia() const { return m * r * r / 2; }
  double Id() const { return m * r * r / 4; }

  MechanismModel<Spatial> model(RollingModel rolling = RollingModel::NoSlip) const {
    using Pos = Spatial::Pos;
    MechanismModel<Spatial> d;
    auto& t = d.tree;
    t.gravity << 0, 0, 0, 0, 0, -g;
    const Spatial::Mat carrier =
        Spatial::inertia(carrier_mass, Pos::Zero(), (carrier_mass * r * r) * Eigen::Matrix3d::Identity());
    int b = t.addBody(-1, JointType::Prismatic, Pos::UnitX(), Spatial::Transform(), carrier);
    b = t.addBody(b, JointType::Prismatic, Pos::UnitY(), Spatial::Transform(), carrier);
    b = t.addBody(b, JointType::Prismatic, Pos::UnitZ(), Spatial::Transform(), carrier);
    b = t.addBody(b, JointType::Revolute, Pos::UnitZ(), Spatial::Transform(), carrier);
    Eigen::Matrix3d Ic = Eigen::Vector3d(Id(), Ia(), Id()).asDiagonal();
    Ic(0, 1) = Ic(1, 0) = product;
    Ic(0, 2) = Ic(2, 0) = -product / 2;
    Ic(1, 2) = Ic(2, 1) = product / 3;
    b = t.addBody(b, JointType::Revolute, Pos::UnitY(), Spatial::Transform(), Spatial::inertia(m, Pos(0, com_y, 0), Ic));
    d.constraints.push_back(std::make_shared<Rolling>(BodyRef::link(b), Pos::Zero(), Pos::UnitY(), r, 0.0, mu));
    d.bullet.rolling = rolling;
    return d;
  }

  // A consistent upright state at heading φ rolling at θ', turning at φ' (on the ground, x = y = 0).
  void state(double phi, double theta_rate, double phi_rate, VecN& q, VecN& v) const {
    q = VecN::Zero(5);
    v = VecN::Zero(5);
    q[2] = r;
    q[3] = phi;
    v << r * std::cos(phi) * theta_rate, r * std::sin(phi) * theta_rate, 0, phi_rate, theta_rate;
  }

  // Speed of the wheel's material point at the contact along the ground: |v_xy − r θ' (cos φ, sin φ)|.
  double slip(const VecN& q, const VecN& v) const {
    return std::hypot(v[0] - r * v[4] * std::cos(q[3]), v[1] - r * v[4] * std::sin(q[3]));
  }
};

}  // namespace dyn::bullet::test
