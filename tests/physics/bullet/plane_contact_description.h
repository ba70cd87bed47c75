// Descriptions with a plane_contact, for the Bullet tests (test_plane_contact_bullet.cpp):
//  * Ball: a ball of mass m on three prismatic carriers x, y, z (massless), q = its centre; spatial.
//  * Arm: the pen-on-table arm of issue 12 (joint 1 about the vertical, joints 2 and 3 pitch about
//    their y axes; column h1, links l2, l3, the pen tip a ball at the end of link 3), spatial.
//  * Disk: a planar ball (payload-free: carriers x, y, then the disk turning), for the planar builder.
// Each also gives its ball's centre, gap and the closed forms the tests need (G(θ), tip Jacobian).
#pragma once
#include <cmath>
#include <memory>

#include "physics/chain.h"
#include "physics/constraints/plane_contact.h"
#include "physics/mechanism.h"

namespace dyn::bullet::test {

struct Ball {
  using Pos = Spatial::Pos;
  double m = 0.5, g = 9.81;
  Pos normal = Pos::UnitZ();
  PlaneContactParams params;

  MechanismModel<Spatial> model() const {
    MechanismModel<Spatial> d;
    auto& t = d.tree;
    t.gravity << 0, 0, 0, 0, 0, -g;
    const Spatial::Mat none = Spatial::Mat::Zero();
    const double I = 0.4 * m * 0.02 * 0.02;  // a solid ball of 2 cm (its turning does not matter here)
    int b = t.addBody(-1, JointType::Prismatic, Pos::UnitX(), Spatial::Transform(), none);
    b = t.addBody(b, JointType::Prismatic, Pos::UnitY(), Spatial::Transform(), none);
    b = t.addBody(b, JointType::Prismatic, Pos::UnitZ(), Spatial::Transform(),
                  Spatial::inertia(m, Pos::Zero(), I * Eigen::Matrix3d::Identity()));
    d.constraints.push_back(std::make_shared<PlaneContact<Spatial>>(BodyRef::link(b), Pos::Zero(), normal, params));
    return d;
  }
  // n·c − ρ − h with c = q (the carriers' coordinates are the centre's world position).
  double gap(const VecN& q) const { return normal.normalized().dot(Pos(q[0], q[1], q[2])) - params.radius - params.height; }
};

struct Arm {
  using Pos = Spatial::Pos;
  double h1 = 0.3, l2 = 0.3, l3 = 0.35, m1 = 2.0, m2 = 1.5, m3 = 1.0, g = 9.81;
  double product = 0;          // products of inertia of link 3 (Bullet then turns its link onto principal axes)
  PlaneContactParams params;  // height: the table's z

  static Spatial::Mat rod(double m, double l, double p = 0) {  // a rod along x from the joint, centre of mass at l/2
    Eigen::Matrix3d Ic = Eigen::Vector3d(1e-3 * m, m * l * l / 12, m * l * l / 12).asDiagonal();
    Ic(0, 1) = Ic(1, 0) = p;
    Ic(0, 2) = Ic(2, 0) = -p / 2;
    return Spatial::inertia(m, Pos(l / 2, 0, 0), Ic);
  }
  MechanismModel<Spatial> model() const {
    MechanismModel<Spatial> d;
    auto& t = d.tree;
    t.gravity << 0, 0, 0, 0, 0, -g;
    const Spatial::Mat column =
        Spatial::inertia(m1, Pos(0, 0, h1 / 2), Eigen::Vector3d(m1 * h1 * h1 / 12, m1 * h1 * h1 / 12, 1e-3).asDiagonal());
    int b = t.addBody(-1, JointType::Revolute, Pos::UnitZ(), Spatial::Transform(), column);
    b = t.addBody(b, JointType::Revolute, Pos::UnitY(), Spatial::translation(Pos(0, 0, h1)), rod(m2, l2));
    b = t.addBody(b, JointType::Revolute, Pos::UnitY(), Spatial::translation(Pos(l2, 0, 0)), rod(m3, l3, product));
    d.constraints.push_back(std::make_shared<PlaneContact<Spatial>>(BodyRef::link(b), tip(), Pos::UnitZ(), params));
    return d;
  }
  Pos tip() const { return Pos(l3, 0, 0); }  // the ball's centre, link 3's frame
  // The tip's world position, its translational Jacobian (3 × 3) and G(θ) (rnea at rest).
  Pos tipPosition(const VecN& q) const {
    const auto d = model();
    TreeData<Spatial> data(d.tree);
    positionKinematics(d.tree, q, data);
    return pointPosition(data, 2, tip());
  }
  // The translational Jacobian (3 × 3) of the contact point P = c − ρ ẑ moving with link 3: a friction
  // force acts there, ρ below the tip's centre (the normal force's line passes through both).
  Eigen::Matrix3d tipJacobian(const VecN& q) const {
    const auto d = model();
    TreeData<Spatial> data(d.tree);
    positionKinematics(d.tree, q, data);
    MatN J;
    pointJacobian(d.tree, data, 2, tip(), J);
    const Pos r = -params.radius * Pos::UnitZ();  // v_P = v_c + ω × r
    return J.bottomRows<3>() - Spatial::skew(r) * J.topRows<3>();
  }
  VecN gravityTorque(const VecN& q) const {
    const auto d = model();
    TreeData<Spatial> data(d.tree);
    forwardKinematics(d.tree, q, VecN::Zero(3), data);
    return rnea(d.tree, data, VecN::Zero(3), VecN::Zero(3));
  }
  // Joint accelerations with no contact (the articulated-body algorithm).
  VecN freeAcceleration(const VecN& q, const VecN& v, const VecN& tau) const {
    const auto d = model();
    TreeData<Spatial> data(d.tree);
    forwardKinematics(d.tree, q, v, data);
    return aba(d.tree, data, v, tau);
  }
  double gap(const VecN& q) const { return tipPosition(q).z() - params.radius - params.height; }
};

// A planar disk of mass m, inertia I, its centre the ball's. Either tree bodies — carriers x, y
// (massless) and, if `spin`, a revolute turning it; q = (x, y[, ψ]) — or a payload free in (ψ, x, y);
// q = (ψ, x, y). Gravity −y; the plane's normal lies in the x–y plane.
struct Disk {
  using Pos = Planar::Pos;
  double m = 0.5, I = 1e-4, g = 9.81;
  bool spin = true, payload = false;
  Pos normal = Pos::UnitY();
  PlaneContactParams params;

  MechanismModel<Planar> model() const {
    MechanismModel<Planar> d;
    auto& t = d.tree;
    t.gravity << 0, 0, -g;
    BodyRef ball;
    if (payload) {
      Payload p;
      p.mass = m, p.inertia = I;
      d.payloads.push_back(p);
      ball = BodyRef::payload(0);
    } else {
      const Planar::Mat disk = Planar::inertia(m, Pos::Zero(), I);
      int b = t.addBody(-1, JointType::Prismatic, Pos::UnitX(), Planar::Transform(), Planar::Mat::Zero());
      b = t.addBody(b, JointType::Prismatic, Pos::UnitY(), Planar::Transform(), spin ? Planar::Mat::Zero() : disk);
      if (spin) b = t.addBody(b, JointType::Revolute, Pos::Zero(), Planar::Transform(), disk);
      ball = BodyRef::link(b);
    }
    d.constraints.push_back(std::make_shared<PlaneContact<Planar>>(ball, Pos::Zero(), normal, params));
    return d;
  }
  int dof() const { return payload ? 3 : spin ? 3 : 2; }
  int x() const { return payload ? 1 : 0; }  // index of the centre's x in q (y follows)
  VecN state(const Pos& c) const {
    VecN q = VecN::Zero(dof());
    q.segment<2>(x()) = c;
    return q;
  }
  Pos centre(const VecN& q) const { return q.segment<2>(x()); }
  double gap(const VecN& q) const { return normal.normalized().dot(centre(q)) - params.radius - params.height; }
};

}  // namespace dyn::bullet::test
