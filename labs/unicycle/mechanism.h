// The rolling unicycle (lecture §3 "Unicycle") described as data: an upright disk wheel of radius r,
// mass m, axle inertia I_a and steer (diametral) inertia I_z, hung from the world by five joints
//   q = (x, y, z, φ, θ):  prismatic x, y, z (the centre), heading φ about the vertical, spin θ about the axle
// (the bodies before the wheel are massless). The lecture's three constraints:
//   planar p_z = r and no slip   — the rolling kind (physics/constraints/rolling.h): the contact's
//                                  material point at rest, rows world x, y (velocity-level) and z
//   no tilt  zᵀ R y = 0          — written into the coordinates (there is no tilt joint), as lecture
//                                  §2.7 allows for holonomic constraints ("integrate only the
//                                  independent coordinates"); its moment is taken by the joints.
// Eq. (2) with no payload (M_c = 0, no α_c): M q'' + h = τ − Jᵀ f and J q'' + J'q' = 0 solved for q'' and
// the ground force f together, v_c = (φ', θ') being the two rates the rows leave free:
//   x' = r cos φ θ',  y' = r sin φ θ',  z' = 0.
// Inputs: τ = (0, 0, 0, τ_z, τ_y): the steer torque on the heading joint, the drive torque on the axle.
// The reduced equations (I_a + m r²) θ'' = τ_y, I_z φ'' = τ_z are the tests' closed form, not used here.
#pragma once
#include "physics/constrained_mechanism.h"

namespace dyn::unicycle {

struct Params {
  double radius = 0.1;       // m
  double mass = 2.0;         // kg
  double axle_inertia = 0.01;   // kg·m², I_a (a uniform disk: m r²/2)
  double steer_inertia = 0.005; // kg·m², I_z (a uniform disk: m r²/4)
  double mu = 0.8;           // friction coefficient: the skid check and Bullet's friction model
  double gravity = 9.81;     // m/s², along −z
};

// Joint order in q.
enum Joint { X = 0, Y = 1, Z = 2, Phi = 3, Theta = 4 };

// The description both engines are built from.
MechanismModel<Spatial> describe(const Params& params);

// Eq. (2) at the unicycle's fixed sizes: 5 joints, 3 rows, no payload (every loop unrolled).
class Mechanism final : public ConstrainedMechanism<Spatial, 5, 3, 0> {
 public:
  explicit Mechanism(const Params& params);
  // A consistent state: the wheel on the ground at (x, y) heading φ, spin θ, turning at φ', rolling at θ'.
  void state(double x, double y, double phi, double theta, double phi_rate, double theta_rate, VecN& q, VecN& v) const;
  // The speed of the contact's material point along the ground (0 when rolling), from a state.
  double slipSpeed(const VecN& q, const VecN& v) const;
  // (I_a + m r²): the inertia the drive torque sees.
  double driveInertia() const { return params_.axle_inertia + params_.mass * params_.radius * params_.radius; }
  const Params& params() const { return params_; }

 private:
  Params params_;
};

}  // namespace dyn::unicycle
