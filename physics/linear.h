// Linear screening of a feedback loop before any simulation (used by the grader):
//   open loop      L(s) = N(s)/D(s) · e^{−sT}            (T: measurement delay)
//   Padé (n, n)    e^{−sT} ≈ P(−sT)/P(sT),  P(x) = Σ_k (2n−k)! n! / ((2n)! k! (n−k)!) x^k
//   closed loop    D(s) P(sT) + N(s) P(−sT) = 0            → poles (companion-matrix eigenvalues),
//                  after cancelling the controller's unused integrators (controller_integrators)
//   margins        |L(jω_c)| = 1:  PM = π + ∠L(jω_c),  delay margin = min over crossovers of PM / ω_c (PM + 2π where PM ≤ 0)
// Polynomials are coefficient vectors in ascending powers of s.
#pragma once
#include <complex>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace dyn {

using Poly = std::vector<double>;  // c0 + c1 s + c2 s² + …

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
};

struct LoopAnalysis {
  std::vector<std::complex<double>> poles;  // closed loop, delay as a Padé approximant
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

LoopAnalysis analyseLoop(const LinearLoop& loop, int pade_order = 3);

}  // namespace dyn
