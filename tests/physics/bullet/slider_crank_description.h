// The slider crank as a mechanism description (physics/mechanism.h) and a thin adapter that runs it
// through BulletMechanism with the interface the slider-crank tests were written against.
// Description: the three links as labs/slider_crank/mechanism.cpp builds them; payload 0 = the slider
// (free x); constraint 0 welds link 3's tip (l3, 0) to the slider's centre; Bullet cut at joint 1.
#pragma once
#include <Eigen/Core>
#include <array>
#include <cmath>
#include <memory>

#include "physics/bullet/bullet_mechanism.h"
#include "physics/mechanism.h"

namespace dyn::bullet::test {

// Test-local constraint: only attachment() matters to the Bullet builder; the rest does nothing.
class AttachmentOnly : public Constraint<Planar> {
 public:
  explicit AttachmentOnly(Attachment<Planar> at, const char* kind = "test attachment") : at_(at), kind_(kind) {}
  const char* kind() const override { return kind_; }
  int rows() const override { return int(at_.rows[0]) + int(at_.rows[1]) + int(at_.rows[2]); }
  void position(const MechanismKinematics<Planar>&, int, VecN&, MatN&, MatN&) const override {}
  void bias(const MechanismKinematics<Planar>&, int, VecN&) const override {}
  Vec force(const MechanismKinematics<Planar>&, const double*) const override { return Vec::Zero(); }
  Planar::Pos point(const MechanismKinematics<Planar>&) const override { return Planar::Pos::Zero(); }
  Attachment<Planar> attachment() const override { return at_; }

 private:
  Attachment<Planar> at_;
  const char* kind_;
};

inline ConstraintPtr<Planar> attach(BodyRef a, Planar::Pos pa, BodyRef b, Planar::Pos pb, std::array<bool, 3> rows,
                                    const char* kind = "test attachment") {
  Attachment<Planar> at;
  at.a = a, at.b = b, at.point_a = pa, at.point_b = pb, at.rows = rows;
  return std::make_shared<AttachmentOnly>(at, kind);
}

struct PlanarLink {
  double length, mass, inertia;  // m, kg, kg·m² about the centre of mass
  Eigen::Vector2d com;           // link frame
};
struct SliderCrankModel {
  std::array<PlanarLink, 3> links;
  double load_mass;
  Eigen::Vector2d gravity;
  Eigen::Vector3d q0, qd0;
};

inline MechanismModel<Planar> sliderCrankDescription(const SliderCrankModel& p) {
  MechanismModel<Planar> m;
  for (int i = 0; i < 3; ++i) {
    const PlanarLink& l = p.links[std::size_t(i)];
    const Planar::Pos offset = i == 0 ? Planar::Pos::Zero() : Planar::Pos(p.links[std::size_t(i - 1)].length, 0.0);
    m.tree.addBody(i - 1, JointType::Revolute, Planar::Axis::Zero(), Planar::translation(offset),
                   Planar::inertia(l.mass, l.com, l.inertia));
  }
  m.tree.gravity << 0.0, p.gravity.x(), p.gravity.y();
  Payload slider;
  slider.name = "slider";
  slider.mass = p.load_mass;
  slider.inertia = p.load_mass * 0.05 * 0.05 / 6.0;
  slider.pose0 << 0.0, 0.0, 0.0;  // x is free; set from q0 by the adapter
  slider.free = {false, true, false};
  m.payloads.push_back(slider);
  m.constraints.push_back(attach(BodyRef::link(2), {p.links[2].length, 0.0}, BodyRef::payload(0), {0.0, 0.0},
                                 {true, true, true}, "tip weld"));
  m.bullet.cut_joints = {0};
  m.bullet.solver_iterations = 30;
  return m;
}

// The slider's x and rate at (θ, θ'), written as the hand-made Bullet model writes them.
inline Eigen::Vector2d sliderOf(const SliderCrankModel& p, const Eigen::Vector3d& q, const Eigen::Vector3d& qd) {
  const double l1 = p.links[0].length, l2 = p.links[1].length, l3 = p.links[2].length;
  const double a1 = q[0], a12 = q[0] + q[1], a123 = q[0] + q[1] + q[2];
  const double w1 = qd[0], w12 = qd[0] + qd[1], w123 = qd[0] + qd[1] + qd[2];
  return {l1 * std::cos(a1) + l2 * std::cos(a12) + l3 * std::cos(a123),
          -l1 * std::sin(a1) * w1 - l2 * std::sin(a12) * w12 - l3 * std::sin(a123) * w123};
}

// BulletMechanism behind the slider-crank tests' interface: q, qd, x_c, v_c, tip force, time.
class SliderCrankMechanism {
 public:
  SliderCrankMechanism(const SliderCrankModel& p, double dt) : dt_(dt) {
    const Eigen::Vector2d s = sliderOf(p, p.q0, p.qd0);
    VecN q(4), v(4);
    q << p.q0, s[0];
    v << p.qd0, s[1];
    mech_ = std::make_unique<BulletMechanism<Planar>>(sliderCrankDescription(p), dt, q, v);
    refresh();
  }
  void step(const Eigen::Vector3d& tau) {
    mech_->step(VecN(tau));
    t_ += dt_;
    refresh();
  }
  Eigen::Vector3d q() const { return q_.head<3>(); }
  Eigen::Vector3d qd() const { return v_.head<3>(); }
  double x_c() const { return q_[3]; }
  double v_c() const { return v_[3]; }
  Eigen::Vector3d tipForce() const { return mech_->constraintForce(0); }
  double time() const { return t_; }
  const BulletMechanism<Planar>& mechanism() const { return *mech_; }

 private:
  void refresh() { mech_->state(q_, v_); }
  double dt_, t_ = 0.0;
  std::unique_ptr<BulletMechanism<Planar>> mech_;
  VecN q_, v_;
};

}  // namespace dyn::bullet::test
