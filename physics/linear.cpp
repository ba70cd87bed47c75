// Polynomials, the Padé delay, closed-loop poles and margins of one loop; equations in linear.h.
#include "physics/linear.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

namespace dyn {

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
    p[std::size_t(k)] = c * std::pow(T, k);
    c *= double(n - k) / (double(2 * n - k) * double(k + 1));
  }
  return p;
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
  a.max_real = -INFINITY;
  for (const auto& p : a.poles) {
    a.max_real = std::max(a.max_real, p.real());
    if (std::abs(p.imag()) > 1e-9 && std::abs(p) > 0) a.min_damping = std::min(a.min_damping, -p.real() / std::abs(p));
  }
  if (a.poles.empty()) a.max_real = 0;
  a.stable = a.max_real < 0;

  // Gain crossovers of the delay-free loop on a log grid, refined by bisection.
  auto gain = [&](double w) {
    const std::complex<double> s(0, w);
    return std::abs(polyEval(loop.num, s) / polyEval(loop.den, s));
  };
  const double w_lo = 1e-3, w_hi = 1e6;
  const int grid = 900;
  double best = kUnboundedDelay;
  bool crossed = false;
  double prev_w = w_lo, prev_g = gain(w_lo) - 1.0;
  for (int i = 1; i <= grid; ++i) {
    const double w = w_lo * std::pow(w_hi / w_lo, double(i) / grid);
    const double g = gain(w) - 1.0;
    if ((prev_g > 0) != (g > 0)) {
      double lo = prev_w, hi = w;
      for (int it = 0; it < 60; ++it) {
        const double mid = std::sqrt(lo * hi);
        ((gain(mid) - 1.0 > 0) == (prev_g > 0) ? lo : hi) = mid;
      }
      const double wc = std::sqrt(lo * hi);
      const std::complex<double> L = polyEval(loop.num, {0, wc}) / polyEval(loop.den, {0, wc});
      double pm = M_PI + std::arg(L);
      if (pm > M_PI) pm -= 2 * M_PI;
      // The least delay that turns this crossover's phase to −π: PM/ω_c, or one more turn when the
      // phase is already past it (a conditionally stable loop with several crossovers, e.g. a
      // flexible joint's resonance: stable without delay, so the turn is still ahead).
      const double dm = (pm > 0 ? pm : pm + 2 * M_PI) / wc;
      if (!crossed || dm < best) {
        best = dm;
        a.crossover = wc;
        a.phase_margin = pm;
      }
      crossed = true;
    }
    prev_w = w;
    prev_g = g;
  }
  // No crossover: a loop gain below 1 everywhere tolerates any delay; above 1 at high frequency, none.
  if (!crossed) best = gain(w_hi) < 1.0 ? kUnboundedDelay : 0.0;
  // A loop that is unstable without any delay has no delay margin at all.
  for (const auto& p : polyRoots(polyAdd(loop.den, loop.num)))
    if (p.real() >= 0) best = 0.0;
  a.delay_margin = best;
  return a;
}

}  // namespace dyn
