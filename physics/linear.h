// Linear screening of a feedback loop before any simulation (used by the grader):
//   open loop      L(s) = N(s)/D(s) · e^{−sT}            (T: measurement delay)
//   Padé (n, n)    e^{−sT} ≈ P(−sT)/P(sT),  P(x) = Σ_k (2n−k)! n! / ((2n)! k! (n−k)!) x^k
//   closed loop    D(s) P(sT) + N(s) P(−sT) = 0            → poles (companion-matrix eigenvalues),
//                  after cancelling the controller's unused integrators (controller_integrators)
//   margins        |L(jω_c)| = 1:  PM = π + ∠L(jω_c),  delay margin = min over crossovers of PM / ω_c (PM + 2π where PM ≤ 0)
// A sampled loop (the controller as it runs, every T seconds) is screened in discrete time:
//   open loop      L(z) = C(z) · ZOH{G}(z) · z^{−N},   ZOH{G}(z) = (1 − z⁻¹) Z{G(s)/s}   (the held output)
//   closed loop    D_C D_G z^N + N_C N_G = 0  → poles z_i, reported as s_i = ln(z_i)/T (the decay per second)
//   delay margin   the loop's stated delay + the extra delay at its crossover on the unit circle,
//                  |L(e^{jωT})| = 1, ω < π/T:  (π + ∠L(e^{jω_c T}))/ω_c  (so it exceeds the delay iff stable)
// Polynomials are coefficient vectors in ascending powers of s (or z).
#pragma once
#include <complex>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace dyn {

using Poly = std::vector<double>;  // c0 + c1 s + c2 s² + …

// The loop as the controller runs it, sampled every `period` s (0: not given, the loop is screened in
// continuous time): L(z) = C(z) · ZOH{G}(z) · z^{−steps}.
//   G(s) = plant_num/plant_den  from the held output to the signal the controller samples (a PD on the
//                               measured state is part of G: (k_d s + k_p)/(m s²)); proper
//   C(z) = ctrl_num/ctrl_den    the controller's own discrete dynamics, polynomials in z (an integrator
//                               by explicit Euler, updated after use: T/(z − 1))
//   steps                       the measurement's delay in whole steps
// A delay of more than kMaxSampledSteps steps (a step far shorter than the delay, where the sampled and
// the continuous loop agree) is screened in continuous time: N steps are N + deg poles to find.
inline constexpr int kMaxSampledSteps = 200;
struct SampledLoop {
  double period = 0;
  Poly plant_num = {}, plant_den = {};
  Poly ctrl_num = {1}, ctrl_den = {1};
  int steps = 0;
};

// One loop of a lab's controller, linearised about its operating point.
struct LinearLoop {
  std::string name;  // short id, e.g. "force" (metrics are named <name>_delay_margin, …)
  std::string what;  // plain words for feedback, e.g. "force loop (integral law)"
  Poly num, den;     // L(s) without the delay
  double delay = 0;  // s
  std::string remark = {};  // what the lab adds to the screening's sentence (e.g. a vibration mode), or empty
  // Factors s of den that are the controller's own integral action (a PI law's 1/s), not the plant's.
  // While the integral gain is zero (num has no constant term) such a factor feeds nothing back: it
  // is cancelled with one of num's, so a PI law with k_I = 0 screens as the P law it is.
  int controller_integrators = 0;
  // The loop as it runs (period > 0): its poles and delay margin are then the sampled loop's, and
  // `delay` is the continuous equivalent the feedback sentence quotes (hold T/2, an Euler integrator's T/2).
  SampledLoop sampled = {};
};

struct LoopAnalysis {
  std::vector<std::complex<double>> poles;  // closed loop, delay as a Padé approximant (sampled: ln z / T)
  double max_real = 0;        // largest real part of the poles (1/s); > 0: unstable
  double min_damping = 1;     // smallest ζ = −Re p / |p| over the complex poles (1 if none)
  double crossover = 0;       // rad/s, 0 if |L| never crosses 1
  double phase_margin = 0;    // rad, of the delay-free loop at the crossover
  double delay_margin = 0;    // s, total delay the loop tolerates (kUnbounded if any)
  bool stable = false;
};

inline constexpr double kUnboundedDelay = 1e3;  // s: reported when |L| < 1 at all frequencies

Poly polyMul(const Poly& a, const Poly& b);
Poly polyAdd(const Poly& a, const Poly& b);
std::complex<double> polyEval(const Poly& p, std::complex<double> s);
// Roots of p (trailing near-zero leading coefficients are dropped).
std::vector<std::complex<double>> polyRoots(const Poly& p);
// P(sT) of the (n, n) Padé approximant of e^{−sT}: numerator is padeDenominator with T → −T.
Poly padeDenominator(double T, int order);

// The zero-order-hold equivalent of G(s) = num/den at period T: num_z/den_z in z, exact for an input
// held over each period (den_z = det(zI − Φ), Φ = e^{AT}; throws std::invalid_argument if G is improper).
void zeroOrderHold(const Poly& num, const Poly& den, double T, Poly& num_z, Poly& den_z);

LoopAnalysis analyseLoop(const LinearLoop& loop, int pade_order = 3);

}  // namespace dyn
