// Fixed-step integration of a constrained mechanism and what to do about drift (lecture §2.7).
//
// State: generalized coordinates q = (θ, x_c) and rates v = (θ', v_c); the position constraint
// φ(q) = 0 with velocity form G(q) v = 0 (G = [J, −A] for the lecture's J θ' = A v_c).
// Integrators:  semi-implicit Euler  v⁺ = v + dt a(q, v),  q⁺ = q + dt v⁺   (1st order, symplectic)
//               RK4                  classic four-stage                     (4th order)
//               either in `substeps` equal sub-steps of dt with τ held (stiff modes: ω dt/substeps small),
//               and an RK4 step that the system marks at its first stage (ConstrainedSystem::refine: a
//               stiff term near where it turns, e.g. friction about θ' = 0) retaken from its start as
//               `refine_substeps` equal sub-steps: the decision a function of the step's start alone
//               (deterministic), each sub-step an RK4 step of its own (fourth order either way)
// The books: beside (q, v) step() integrates, with the same scheme and stage weights, the work W of τ
// and of the external forces (power (τ + Q_ext)·v) and D, that of joint friction (≤ 0), so that
// E − E0 − W − D is at the integrator's own error (τ held: its share is τ·Δq, exactly). The clock: each
// stage is evaluated at its time t + c dt (time-dependent external forces read it); the last stage just
// inside the step (t + dt(1 − 1e-9)), so that a force switched on at a step boundary acts from there on.
// Drift:        none | Baumgarte  s = −2ζω G v − ω² φ  inside the solve
//               | projection: q ← q − W⁻¹Gᵀ(G W⁻¹ Gᵀ)⁻¹ φ (Newton), v ← v − W⁻¹Gᵀ(G W⁻¹ Gᵀ)⁻¹ G v
//                 with W the mass matrix (the velocity projection removes the least kinetic energy)
//               | independent: keep only the independent coordinates and rebuild the rest
//                 (the mechanism's recoverDependent, e.g. the slider crank from its crank angle).
#pragma once
#include <string>

#include "physics/types.h"

namespace dyn {

enum class Integrator { SemiImplicitEuler, RK4 };
enum class Drift { None, Baumgarte, Projection, Independent };

struct DriftOptions {
  Drift kind = Drift::Projection;
  double zeta = 1.0;     // Baumgarte damping ratio
  double omega = 50.0;   // Baumgarte natural frequency (rad/s)
  double tolerance = 1e-12;
  int max_iterations = 10;
};

// What step() integrates beside the motion (see the top): work of τ and external forces, and of friction.
struct Books {
  double work = 0;      // J, W = ∫ (τ + Q_ext)·v dt
  double friction = 0;  // J, D = −∫ (b θ' + F_c tanh(θ'/w))·θ' dt ≤ 0
};

// What an integrator needs from a mechanism. The control τ is held over the step (zero-order hold).
class ConstrainedSystem {
 public:
  virtual ~ConstrainedSystem() = default;
  // The clock: the time of the state being evaluated (step() sets each stage's and leaves the step's end).
  virtual void setTime(double t) { time_ = t; }
  double time() const { return time_; }
  // One evaluation for the integrator: a = accelerations(q, v, τ, stab), and the power at (q, v):
  // (τ + Q_ext)·v into `work`, the joint friction's into `friction`. The default: τ·v, no friction.
  virtual void derivatives(const VecN& q, const VecN& v, const VecN& tau, const VecN* stab, VecN& a, double& work,
                           double& friction);
  // What step() has integrated so far (see Books); a lab may reset it.
  Books& books() { return books_; }
  const Books& books() const { return books_; }
  virtual int nq() const = 0;
  // Configurations with unit quaternions (ball and free joints: chain.h) have more coordinates than
  // rates: nv() velocity coordinates (also the size of a, G's columns, W, dx), nq() configuration
  // numbers. Then step() integrates q̇ = N(q) v (configurationRate) and moves q by q ⊕ h dx
  // (integrateConfiguration, the exponential map) and normalizes it (normalizeConfiguration): RK4 in
  // the embedding, the quaternions renormalised at the step's end (still 4th order: the exact flow
  // keeps |Q| = 1, so the normalisation moves q by the step's own O(dt⁵) error); semi-implicit Euler
  // v⁺ = v + dt a, q⁺ = q ⊕ dt v⁺ (MuJoCo's); the projection's Newton steps q ⊕ (−dx).
  // The defaults are a system whose q and v have the same size: identity maps.
  virtual int nv() const { return nq(); }
  virtual void configurationRate(const VecN& q, const VecN& v, VecN& qdot) {
    (void)q;
    qdot = v;
  }
  virtual void integrateConfiguration(VecN& q, const VecN& dx, double h) { q += h * dx; }
  virtual void normalizeConfiguration(VecN& q) { (void)q; }
  // Accelerations a = (θ'', α_c) from the solve (2)/(3); stab is the Baumgarte term or null.
  virtual void accelerations(const VecN& q, const VecN& v, const VecN& tau, const VecN* stab,
                             VecN& a) = 0;
  // φ(q) and G(q) (G v = 0 is the velocity constraint).
  virtual void constraint(const VecN& q, VecN& phi, MatN& G) = 0;
  // Baumgarte's s = −2ζω G v − ω² φ at (q, v). The default builds φ and G; a mechanism may answer
  // from its own position stage.
  virtual void baumgarteTerm(const VecN& q, const VecN& v, double zeta, double omega, VecN& s);
  // The projection metric W (mass matrix), positive definite.
  virtual void metric(const VecN& q, MatN& W) = 0;
  // The projection's step: the correction dx of least W-norm with G(q) dx = e,
  //   dx = W⁻¹Gᵀ (G W⁻¹ Gᵀ)⁻¹ e   (W = metric(q)).
  // With W the mass matrix this is eq. (2) solved for impulses (Gauss's principle: τ − h = 0,
  // J'θ' = −e), so a mechanism may answer from the factors of its own solve; false on failure.
  // The default builds W and G and factors them here.
  virtual bool correction(const VecN& q, const VecN& e, VecN& dx);
  // Rebuild the dependent coordinates and rates from the independent ones; false if unsupported.
  virtual bool recoverDependent(VecN& q, VecN& v) {
    (void)q;
    (void)v;
    return false;
  }
  // Whether an RK4 step of h from (q, v), whose first stage gave the accelerations a, is to be taken
  // in StepOptions::refine_substeps sub-steps (integrate.h, top). The default: never.
  virtual bool refine(const VecN& q, const VecN& v, const VecN& a, double h) {
    (void)q, (void)v, (void)a, (void)h;
    return false;
  }

 protected:
  double time_ = 0;
  Books books_;
};

struct StepOptions {
  double dt = 1e-3;
  Integrator integrator = Integrator::RK4;
  DriftOptions drift;
  int substeps = 1;  // equal sub-steps of dt (each with its drift handling), τ held over all of them
  int refine_substeps = 1;  // RK4: sub-steps of a (sub-)step the system's refine() marks (1: none asked)
};

// One fixed step of (q, v) with τ held, the system's clock and books advanced with it. Returns false if
// a projection failed to converge.
bool step(ConstrainedSystem& system, const StepOptions& options, const VecN& tau, VecN& q, VecN& v);

// Projection onto φ = 0 and G v = 0 (also used to make initial conditions consistent).
bool projectPositions(ConstrainedSystem& system, const DriftOptions& options, VecN& q);
void projectVelocities(ConstrainedSystem& system, const VecN& q, VecN& v);

// Names as they appear in lab JSON; parse returns false on an unknown name.
bool parseIntegrator(const std::string& name, Integrator& out);
bool parseDrift(const std::string& name, Drift& out);
const char* name(Integrator i);
const char* name(Drift d);

}  // namespace dyn
