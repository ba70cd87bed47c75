// Fixed-step integrators (semi-implicit Euler, RK4) and drift handling (Baumgarte, projection,
// independent coordinates) for any ConstrainedSystem; equations in integrate.h.
#include "physics/integrate.h"

#include <algorithm>

#include "physics/constrained.h"

namespace dyn {
namespace {

// Baumgarte's s = −2ζω G v − ω² φ, or nothing.
const VecN* baumgarte(ConstrainedSystem& sys, const DriftOptions& d, const VecN& q, const VecN& v,
                      VecN& s) {
  if (d.kind != Drift::Baumgarte) return nullptr;
  sys.baumgarteTerm(q, v, d.zeta, d.omega, s);
  return &s;
}

}  // namespace

void ConstrainedSystem::baumgarteTerm(const VecN& q, const VecN& v, double zeta, double omega, VecN& s) {
  VecN phi;
  MatN G;
  constraint(q, phi, G);
  s = -2.0 * zeta * omega * (G * v) - omega * omega * phi;
}

bool ConstrainedSystem::correction(const VecN& q, const VecN& e, VecN& dx) {
  // Minimum-W-norm dx with G dx = e is eq. (2) for impulses with M = W, J = G and no payload:
  // W dx = −Gᵀ f, G dx + J'θ' = 0 with τ − h = 0 and J'θ' = −e (pivoted LU where G loses rank).
  VecN phi;
  ConstrainedProblem p;
  constraint(q, phi, p.J);
  metric(q, p.M);
  const int n = int(p.M.rows());
  p.h = VecN::Zero(n);
  p.tau = VecN::Zero(n);
  p.Jdot_qd = -e;
  p.A = MatN::Zero(p.J.rows(), 0);
  dx = solveConstrained(p).qdd;
  return dx.allFinite();
}

bool projectPositions(ConstrainedSystem& sys, const DriftOptions& d, VecN& q) {
  VecN phi, dx;
  MatN G;
  for (int it = 0; it < d.max_iterations; ++it) {
    sys.constraint(q, phi, G);
    if (phi.lpNorm<Eigen::Infinity>() <= d.tolerance) return true;
    if (!sys.correction(q, phi, dx)) return false;
    sys.integrateConfiguration(q, dx, -1.0);  // Newton step on φ(q) = 0: q − dx (a quaternion: q ⊕ (−dx))
  }
  sys.constraint(q, phi, G);
  return phi.lpNorm<Eigen::Infinity>() <= d.tolerance * 1e3;
}

void projectVelocities(ConstrainedSystem& sys, const VecN& q, VecN& v) {
  VecN phi, dx;
  MatN G;
  sys.constraint(q, phi, G);
  if (sys.correction(q, G * v, dx)) v -= dx;
}

void ConstrainedSystem::derivatives(const VecN& q, const VecN& v, const VecN& tau, const VecN* stab, VecN& a,
                                    double& work, double& friction) {
  accelerations(q, v, tau, stab, a);
  work = tau.dot(v.head(tau.size()));
  friction = 0.0;
}

namespace {

// The last stage's time, just inside the step (see integrate.h).
constexpr double kInside = 1.0 - 1e-9;

bool stepOnce(ConstrainedSystem& sys, const StepOptions& o, double dt, const VecN& tau, VecN& q, VecN& v, bool may_refine);

// The step of dt from the clock's time t0 as o.refine_substeps equal RK4 steps (none refined again).
bool refined(ConstrainedSystem& sys, const StepOptions& o, double dt, const VecN& tau, VecN& q, VecN& v) {
  const double t0 = sys.time(), h = dt / o.refine_substeps;
  bool ok = true;
  for (int i = 0; i < o.refine_substeps; ++i) {
    sys.setTime(t0 + i * h);
    ok = stepOnce(sys, o, h, tau, q, v, false) && ok;
  }
  sys.setTime(t0 + dt);
  return ok;
}

// One step of dt from the clock's time t0: the motion, the books, the drift handling (or, marked by
// the system's refine() at its first stage, the same step in sub-steps).
bool stepOnce(ConstrainedSystem& sys, const StepOptions& o, double dt, const VecN& tau, VecN& q, VecN& v, bool may_refine) {
  const double t0 = sys.time();
  VecN s, a;
  double w1, f1;
  Books& books = sys.books();
  if (o.integrator == Integrator::SemiImplicitEuler) {
    sys.derivatives(q, v, tau, baumgarte(sys, o.drift, q, v, s), a, w1, f1);
    v += dt * a;
    sys.integrateConfiguration(q, v, dt);  // q + dt v; a quaternion on the sphere (MuJoCo's)
    books.work += dt * w1;
    books.friction += dt * f1;
  } else {
    // Classic RK4 on (q, v, W, D) with q̇ = N(q) v (= v without quaternions), each stage at its own time;
    // quaternions renormalised at the end (integrate.h).
    VecN a1, a2, a3, a4, d1, d2, d3, d4;
    double w2, w3, w4, f2, f3, f4;
    sys.derivatives(q, v, tau, baumgarte(sys, o.drift, q, v, s), a1, w1, f1);
    if (may_refine && o.refine_substeps > 1 && sys.refine(q, v, a1, dt)) return refined(sys, o, dt, tau, q, v);
    sys.configurationRate(q, v, d1);
    const VecN q2 = q + 0.5 * dt * d1, v2 = v + 0.5 * dt * a1;
    sys.setTime(t0 + 0.5 * dt);
    sys.derivatives(q2, v2, tau, baumgarte(sys, o.drift, q2, v2, s), a2, w2, f2);
    sys.configurationRate(q2, v2, d2);
    const VecN q3 = q + 0.5 * dt * d2, v3 = v + 0.5 * dt * a2;
    sys.derivatives(q3, v3, tau, baumgarte(sys, o.drift, q3, v3, s), a3, w3, f3);
    sys.configurationRate(q3, v3, d3);
    const VecN q4 = q + dt * d3, v4 = v + dt * a3;
    sys.setTime(t0 + kInside * dt);
    sys.derivatives(q4, v4, tau, baumgarte(sys, o.drift, q4, v4, s), a4, w4, f4);
    sys.configurationRate(q4, v4, d4);
    q += dt / 6.0 * (d1 + 2.0 * d2 + 2.0 * d3 + d4);
    sys.normalizeConfiguration(q);
    v += dt / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
    books.work += dt / 6.0 * (w1 + 2.0 * w2 + 2.0 * w3 + w4);
    books.friction += dt / 6.0 * (f1 + 2.0 * f2 + 2.0 * f3 + f4);
  }
  sys.setTime(t0 + dt);
  switch (o.drift.kind) {
    case Drift::Projection: {
      const bool ok = projectPositions(sys, o.drift, q);
      projectVelocities(sys, q, v);
      return ok;
    }
    case Drift::Independent:
      return sys.recoverDependent(q, v);
    default:
      return true;
  }
}

}  // namespace

bool step(ConstrainedSystem& sys, const StepOptions& o, const VecN& tau, VecN& q, VecN& v) {
  const int n = std::max(1, o.substeps);
  if (n == 1) return stepOnce(sys, o, o.dt, tau, q, v, true);
  // Sub-steps: the clock from t0 + i dt/n exactly (no sum of n rounded sub-steps).
  const double t0 = sys.time(), h = o.dt / n;
  bool ok = true;
  for (int i = 0; i < n; ++i) {
    sys.setTime(t0 + i * h);
    ok = stepOnce(sys, o, h, tau, q, v, true) && ok;
  }
  sys.setTime(t0 + o.dt);
  return ok;
}

bool parseIntegrator(const std::string& n, Integrator& out) {
  if (n == "semi_implicit_euler") out = Integrator::SemiImplicitEuler;
  else if (n == "rk4") out = Integrator::RK4;
  else return false;
  return true;
}

bool parseDrift(const std::string& n, Drift& out) {
  if (n == "none") out = Drift::None;
  else if (n == "baumgarte") out = Drift::Baumgarte;
  else if (n == "projection") out = Drift::Projection;
  else if (n == "independent") out = Drift::Independent;
  else return false;
  return true;
}

const char* name(Integrator i) { return i == Integrator::RK4 ? "rk4" : "semi_implicit_euler"; }
const char* name(Drift d) {
  switch (d) {
    case Drift::None: return "none";
    case Drift::Baumgarte: return "baumgarte";
    case Drift::Projection: return "projection";
    default: return "independent";
  }
}

}  // namespace dyn
