// Polynomials, the Padé delay, closed-loop poles and margins of one loop; equations in linear.h.
#include "physics/linear.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>

#include "physics/det/det.h"

namespace dyn {
namespace {

// e^M by scaling and squaring a Taylor series (‖M / 2^s‖ ≤ ½: twenty terms are exact to rounding).
Eigen::MatrixXd expm(const Eigen::MatrixXd& M) {
  const double norm = M.cwiseAbs().rowwise().sum().maxCoeff();
  const int s = norm > 0.5 ? int(std::ceil(det::log2(norm / 0.5))) : 0;
  const Eigen::MatrixXd X = M / std::ldexp(1.0, s);
  Eigen::MatrixXd E = Eigen::MatrixXd::Identity(M.rows(), M.cols()), term = E;
  for (int k = 1; k <= 20; ++k) {
    term = term * X / double(k);
    E += term;
  }
  for (int i = 0; i < s; ++i) E = E * E;
  return E;
}

// p without its highest-order zero coefficients.
Poly trimmed(Poly p) {
  while (!p.empty() && p.back() == 0.0) p.pop_back();
  return p;
}

// A crossover of |L| = 1 and the phase margin π + ∠L there (in (−π, π]).
struct Crossing {
  double w, pm;
};

// Every crossover of |L(ω)| = 1 on a log grid over [w_lo, w_hi], refined by bisection.
std::vector<Crossing> crossings(const std::function<std::complex<double>(double)>& L, double w_lo, double w_hi) {
  std::vector<Crossing> out;
  auto g = [&](double w) { return det::abs(L(w)) - 1.0; };
  const int grid = 900;
  double prev_w = w_lo, prev_g = g(w_lo);
  for (int i = 1; i <= grid; ++i) {
    const double w = w_lo * det::pow(w_hi / w_lo, double(i) / grid), gw = g(w);
    if ((prev_g > 0) != (gw > 0)) {
      double lo = prev_w, hi = w;
      for (int it = 0; it < 60; ++it) {
        const double mid = std::sqrt(lo * hi);
        ((g(mid) > 0) == (prev_g > 0) ? lo : hi) = mid;
      }
      const double wc = std::sqrt(lo * hi);
      double pm = M_PI + det::arg(L(wc));
      if (pm > M_PI) pm -= 2 * M_PI;
      out.push_back({wc, pm});
    }
    prev_w = w;
    prev_g = gw;
  }
  return out;
}

// The least extra delay that turns a crossover's phase to −π: PM/ω_c, or one more turn when the phase
// is already past it (a conditionally stable loop with several crossovers, e.g. a flexible joint's
// resonance: stable as it is, so the turn is still ahead); over several: the least (kUnboundedDelay if none).
double extraDelay(const Crossing& c) { return (c.pm > 0 ? c.pm : c.pm + 2 * M_PI) / c.w; }
double extraDelay(const std::vector<Crossing>& cs) {
  double best = kUnboundedDelay;
  for (const Crossing& c : cs) best = std::min(best, extraDelay(c));
  return best;
}

// The largest real part and the least damping of a set of poles.
void summarise(LoopAnalysis& a) {
  a.max_real = a.poles.empty() ? 0.0 : -INFINITY;
  a.min_damping = 1;
  for (const auto& p : a.poles) {
    a.max_real = std::max(a.max_real, p.real());
    if (std::abs(p.imag()) > 1e-9 && det::abs(p) > 0) a.min_damping = std::min(a.min_damping, -p.real() / det::abs(p));
  }
  a.stable = a.max_real < 0;
}

// The sampled loop's poles (as ln z / T) and delay margin; the crossover and phase margin stay the
// continuous delay-free loop's (set by the caller).
void analyseSampled(const LinearLoop& loop, LoopAnalysis& a) {
  const SampledLoop& d = loop.sampled;
  const double T = d.period;
  const int N = std::max(0, d.steps);
  Poly gn, gd;
  zeroOrderHold(d.plant_num, d.plant_den, T, gn, gd);
  const Poly num = polyMul(d.ctrl_num, gn), den_free = polyMul(d.ctrl_den, gd);
  Poly den = den_free;
  den.insert(den.begin(), std::size_t(N), 0.0);  // × z^N
  a.poles.clear();
  for (const auto& z : polyRoots(polyAdd(den, num)))
    if (det::abs(z) > 1e-300) a.poles.push_back(det::log(z) / T);  // z = 0: a mode gone in one step
  std::sort(a.poles.begin(), a.poles.end(), [](auto x, auto y) { return x.real() != y.real() ? x.real() > y.real() : x.imag() > y.imag(); });
  summarise(a);
  // The margin from the loop without its N whole steps (their phase is ωNT exactly): crossovers on the
  // unit circle below the Nyquist frequency π/T. The stated delay beyond the whole steps (the hold's
  // T/2, an Euler integrator's) is already in L's phase: margin = that + PM/ω_c, above the stated
  // delay exactly when NT < PM/ω_c, i.e. when the loop is stable.
  const auto L = [&](double w) {
    const std::complex<double> z = det::polar(1.0, w * T);
    return det::div(polyEval(num, z), polyEval(den_free, z));
  };
  const std::vector<Crossing> cs = crossings(L, 1e-3, M_PI / T * (1 - 1e-9));
  const double base = loop.delay - N * T;
  if (a.stable) {
    const double extra = cs.empty() ? (det::abs(L(M_PI / T)) < 1.0 ? kUnboundedDelay : 0.0) : extraDelay(cs);
    a.delay_margin = std::min(kUnboundedDelay, base + extra);
  } else {
    // Past its margin (or unstable without the delay: no margin at all); never above the stated delay.
    double extra = cs.empty() ? -base : kUnboundedDelay;
    for (const Crossing& c : cs) extra = std::min(extra, c.pm > 0 ? c.pm / c.w : -base);
    a.delay_margin = std::clamp(base + extra, 0.0, loop.delay);
  }
}

}  // namespace

Poly polyMul(const Poly& a, const Poly& b) {
  if (a.empty() || b.empty()) return {};
  Poly c(a.size() + b.size() - 1, 0.0);
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t j = 0; j < b.size(); ++j) c[i + j] += a[i] * b[j];
  return c;
}

Poly polyAdd(const Poly& a, const Poly& b) {
  Poly c(std::max(a.size(), b.size()), 0.0);
  for (std::size_t i = 0; i < a.size(); ++i) c[i] += a[i];
  for (std::size_t i = 0; i < b.size(); ++i) c[i] += b[i];
  return c;
}

std::complex<double> polyEval(const Poly& p, std::complex<double> s) {
  std::complex<double> y = 0;
  for (auto it = p.rbegin(); it != p.rend(); ++it) y = y * s + *it;  // Horner
  return y;
}

std::vector<std::complex<double>> polyRoots(const Poly& p) {
  // Drop negligible leading coefficients, relative to the largest one.
  double scale = 0;
  for (double c : p) scale = std::max(scale, std::abs(c));
  std::size_t n = p.size();
  while (n > 0 && std::abs(p[n - 1]) <= 1e-14 * scale) --n;
  if (n < 2) return {};
  const int deg = int(n) - 1;
  // Companion matrix of the monic polynomial; its eigenvalues are the roots.
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(deg, deg);
  for (int i = 1; i < deg; ++i) C(i, i - 1) = 1.0;
  for (int i = 0; i < deg; ++i) C(i, deg - 1) = -p[std::size_t(i)] / p[n - 1];
  const Eigen::EigenSolver<Eigen::MatrixXd> es(C, false);
  std::vector<std::complex<double>> roots(es.eigenvalues().data(), es.eigenvalues().data() + deg);
  // A fixed order (by real part, then imaginary) keeps reports identical run to run.
  std::sort(roots.begin(), roots.end(), [](auto a, auto b) {
    return a.real() != b.real() ? a.real() > b.real() : a.imag() > b.imag();
  });
  return roots;
}

Poly padeDenominator(double T, int n) {
  // P(sT) = Σ_k (2n−k)! n! / ((2n)! k! (n−k)!) (sT)^k, built by the ratio of consecutive terms.
  Poly p(std::size_t(n) + 1);
  double c = 1.0;
  for (int k = 0; k <= n; ++k) {
    p[std::size_t(k)] = c * det::pow(T, k);
    c *= double(n - k) / (double(2 * n - k) * double(k + 1));
  }
  return p;
}

void zeroOrderHold(const Poly& num_in, const Poly& den_in, double T, Poly& num_z, Poly& den_z) {
  const Poly num = trimmed(num_in), den = trimmed(den_in);
  if (den.empty()) throw std::invalid_argument("zeroOrderHold: G(s) has a zero denominator");
  const int n = int(den.size()) - 1;
  if (int(num.size()) - 1 > n) throw std::invalid_argument("zeroOrderHold: G(s) is improper (numerator above the denominator's degree)");
  // G = D + b(s)/a(s), a monic of degree n, b of degree < n.
  const double lead = den.back(), D = int(num.size()) == n + 1 ? num.back() / lead : 0.0;
  Eigen::VectorXd a(n), b = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < n; ++i) {
    a[i] = den[std::size_t(i)] / lead;
    b[i] = (std::size_t(i) < num.size() ? num[std::size_t(i)] / lead : 0.0) - D * a[i];
  }
  // Controllable canonical form x' = A x + B u, y = bᵀ x + D u; [Φ Γ; 0 1] = exp([A B; 0 0] T).
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n + 1, n + 1);
  for (int i = 0; i + 1 < n; ++i) M(i, i + 1) = 1.0;
  if (n > 0) {
    M.row(n - 1).head(n) = -a.transpose();
    M(n - 1, n) = 1.0;
  }
  const Eigen::MatrixXd E = expm(M * T);
  const Eigen::MatrixXd Phi = E.topLeftCorner(n, n);
  const Eigen::VectorXd Gamma = E.col(n).head(n);
  // Faddeev–LeVerrier: det(zI − Φ) = Σ c_k z^k and adj(zI − Φ) = Σ_{k=1..n} M_k z^{n−k}, so
  // ZOH{G}(z) = (bᵀ adj(zI − Φ) Γ + D det(zI − Φ)) / det(zI − Φ).
  den_z.assign(std::size_t(n) + 1, 0.0);
  num_z.assign(std::size_t(n) + 1, 0.0);
  den_z[std::size_t(n)] = 1.0;
  Eigen::MatrixXd Mk = Eigen::MatrixXd::Zero(n, n);
  for (int k = 1; k <= n; ++k) {
    Mk = Phi * Mk + den_z[std::size_t(n - k + 1)] * Eigen::MatrixXd::Identity(n, n);
    num_z[std::size_t(n - k)] = b.dot(Mk * Gamma);
    den_z[std::size_t(n - k)] = -(Phi * Mk).trace() / double(k);
  }
  for (int i = 0; i <= n; ++i) num_z[std::size_t(i)] += D * den_z[std::size_t(i)];
}

LoopAnalysis analyseLoop(const LinearLoop& loop, int order) {
  LoopAnalysis a;
  // The controller's integrators at zero gain: a factor s of N and of D that feeds nothing back.
  Poly num = loop.num, den = loop.den;
  for (int k = 0; k < loop.controller_integrators && num.size() > 1 && den.size() > 1 && num.front() == 0 &&
                  den.front() == 0;
       ++k) {
    num.erase(num.begin());
    den.erase(den.begin());
  }
  // Closed-loop characteristic polynomial with the delay as Padé: D P(sT) + N P(−sT).
  if (loop.delay > 0) {
    num = polyMul(num, padeDenominator(-loop.delay, order));
    den = polyMul(den, padeDenominator(loop.delay, order));
  }
  a.poles = polyRoots(polyAdd(den, num));
  summarise(a);

  // Gain crossovers of the delay-free loop; the delay margin is the least over them.
  const auto L = [&](double w) { return det::div(polyEval(loop.num, {0, w}), polyEval(loop.den, {0, w})); };
  const double w_lo = 1e-3, w_hi = 1e6;
  const std::vector<Crossing> cs = crossings(L, w_lo, w_hi);
  double best = kUnboundedDelay;
  for (std::size_t i = 0; i < cs.size(); ++i) {
    const double dm = extraDelay(cs[i]);
    if (i == 0 || dm < best) {
      best = dm;
      a.crossover = cs[i].w;
      a.phase_margin = cs[i].pm;
    }
  }
  // No crossover: a loop gain below 1 everywhere tolerates any delay; above 1 at high frequency, none.
  if (cs.empty()) best = det::abs(L(w_hi)) < 1.0 ? kUnboundedDelay : 0.0;
  // A loop that is unstable without any delay has no delay margin at all.
  for (const auto& p : polyRoots(polyAdd(loop.den, loop.num)))
    if (p.real() >= 0) best = 0.0;
  a.delay_margin = best;
  // The loop as it runs, when the lab gives it: its poles and margin in discrete time.
  if (loop.sampled.period > 0 && loop.sampled.steps <= kMaxSampledSteps) analyseSampled(loop, a);
  return a;
}

}  // namespace dyn
