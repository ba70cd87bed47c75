// External force kinds (mechanism.h ExternalForce): what a lab puts on its links and payloads.
//   push      F(t) = s(t) F_0 (and a torque s(t) τ_0) at a body point, world axes, whatever the motion;
//             s(t) the profile: 0 before t_s, a ramp to 1 over t_r, 1 for t_h (t_h = 0: for ever), then 0
//   spring    F = −k (p − p_a) − c ṗ at a body point towards a world anchor p_a (zero rest length)
// Profiles are right-continuous (on at t = t_s); the integrator evaluates a step's last stage just
// inside the step (integrate.h), so a push that starts at a step boundary acts from that step on.
#pragma once
#include <algorithm>
#include <stdexcept>

#include "physics/mechanism.h"

namespace dyn {

struct ForceProfile {
  double start = 0, rise = 0, hold = 0;  // s
  double at(double t) const {
    if (t < start || (hold > 0 && t >= start + rise + hold)) return 0.0;
    return rise > 0 ? std::min(1.0, (t - start) / rise) : 1.0;
  }
};

template <class S>
class PushForce final : public ExternalForce<S> {
 public:
  using Vec = typename S::Vec;
  using Pos = typename S::Pos;
  // value: the spatial force at full size (world axes, at the point: planar (τ, f_x, f_y)).
  PushForce(BodyRef body, const Pos& point, const Vec& value, const ForceProfile& profile)
      : body_(body), point_(point), value_(value), profile_(profile) {
    if (!value.allFinite()) throw std::invalid_argument("PushForce: a finite force");
  }
  const char* kind() const override { return "push"; }
  BodyRef body() const override { return body_; }
  Pos point() const override { return point_; }
  Vec force(double t, const Pos& p, const Vec& V) const override {
    (void)p, (void)V;
    return profile_.at(t) * value_;
  }
  const Vec& value() const { return value_; }
  const ForceProfile& profile() const { return profile_; }

 private:
  BodyRef body_;
  Pos point_;
  Vec value_;
  ForceProfile profile_;
};

template <class S>
class WorldSpring final : public ExternalForce<S> {
 public:
  using Vec = typename S::Vec;
  using Pos = typename S::Pos;
  WorldSpring(BodyRef body, const Pos& point, const Pos& anchor, double stiffness, double damping)
      : body_(body), point_(point), anchor_(anchor), k_(stiffness), c_(damping) {
    if (!(stiffness >= 0) || !(damping >= 0)) throw std::invalid_argument("WorldSpring: stiffness and damping ≥ 0");
  }
  const char* kind() const override { return "spring"; }
  BodyRef body() const override { return body_; }
  Pos point() const override { return point_; }
  Vec force(double t, const Pos& p, const Vec& V) const override {
    (void)t;
    Vec F = Vec::Zero();
    F.template tail<Pos::RowsAtCompileTime>() = -k_ * (p - anchor_) - c_ * S::linear(V);
    return F;
  }

 private:
  BodyRef body_;
  Pos point_, anchor_;
  double k_, c_;
};

}  // namespace dyn
