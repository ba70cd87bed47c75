// physics/linear: roots, the Padé delay, the zero-order hold, and loop margins (continuous and sampled)
// against closed-form answers.
#include <doctest/doctest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <vector>

#include "physics/linear.h"

using namespace dyn;

TEST_CASE("roots of (s+1)(s+2)(s²+2s+5) are −1, −2, −1±2j") {
  const Poly p = polyMul(polyMul({1, 1}, {2, 1}), {5, 2, 1});
  const auto r = polyRoots(p);
  REQUIRE(r.size() == 4);
  int found = 0;
  for (const auto& z : r) {
    for (std::complex<double> want : {std::complex<double>(-1, 0), {-2, 0}, {-1, 2}, {-1, -2}})
      if (std::abs(z - want) < 1e-9) ++found;
    CHECK(std::abs(polyEval(p, z)) < 1e-9);
  }
  CHECK(found == 4);
}

TEST_CASE("Padé (3,3) of e^{−sT} is all-pass and matches the phase at ωT ≤ 1") {
  const double T = 0.01;
  const Poly num = padeDenominator(-T, 3), den = padeDenominator(T, 3);
  for (double w : {1.0, 10.0, 50.0, 100.0}) {
    const std::complex<double> s(0, w);
    const auto ratio = polyEval(num, s) / polyEval(den, s);
    CHECK(std::abs(ratio) == doctest::Approx(1.0).epsilon(1e-12));
    CHECK(std::abs(ratio - std::exp(-s * T)) < 1e-5);
  }
}

TEST_CASE("integral loop k/s with delay T: delay margin π/(2k), stable iff T below it") {
  const double k = 40;
  LinearLoop loop{"force", "integral", {k}, {0, 1}, 0.0};
  const LoopAnalysis free = analyseLoop(loop);
  CHECK(free.crossover == doctest::Approx(k).epsilon(1e-6));
  CHECK(free.phase_margin == doctest::Approx(M_PI / 2).epsilon(1e-6));
  CHECK(free.delay_margin == doctest::Approx(M_PI / (2 * k)).epsilon(1e-6));
  CHECK(free.stable);
  // The Padé poles agree with the exact delay criterion on either side of the margin.
  loop.delay = 0.9 * M_PI / (2 * k);
  CHECK(analyseLoop(loop).stable);
  loop.delay = 1.1 * M_PI / (2 * k);
  const LoopAnalysis late = analyseLoop(loop);
  CHECK_FALSE(late.stable);
  CHECK(late.max_real > 0);
}

TEST_CASE("PD loop (k_d s + k_p)/(m s²): poles and damping of m s² + k_d s + k_p") {
  const double m = 2.5, kp = 400, kd = 30;
  const LoopAnalysis a = analyseLoop({"motion", "PD", {kp, kd}, {0, 0, m}, 0.0});
  const double zeta = kd / (2 * std::sqrt(kp * m)), wn = std::sqrt(kp / m);
  REQUIRE(a.poles.size() == 2);
  CHECK(a.poles[0].real() == doctest::Approx(-zeta * wn));
  CHECK(std::abs(a.poles[0].imag()) == doctest::Approx(wn * std::sqrt(1 - zeta * zeta)));
  CHECK(a.min_damping == doctest::Approx(zeta));
  CHECK(a.stable);
}

TEST_CASE("proportional loop: gain below 1 tolerates any delay, above 1 none") {
  LinearLoop loop{"force", "P", {0.5}, {1}, 0.01};
  LoopAnalysis a = analyseLoop(loop);
  CHECK(a.delay_margin == kUnboundedDelay);
  CHECK(a.stable);
  loop.num = {2.0};
  a = analyseLoop(loop);
  CHECK(a.delay_margin == 0.0);
  CHECK_FALSE(a.stable);
}

TEST_CASE("a loop unstable without delay has no delay margin") {
  // L = 1/(s − 2): closed loop s − 1 (unstable) although |L| crosses 1.
  const LoopAnalysis a = analyseLoop({"x", "unstable plant", {1}, {-2, 1}, 0.0});
  CHECK_FALSE(a.stable);
  CHECK(a.delay_margin == 0.0);
}

TEST_CASE("a conditionally stable loop (flexible joint under PD): the margin is the least delay to −π") {
  // PD on the motor of a rotor J_m – spring k – link m_L pair, lightly damped (b in the spring):
  //   L(s) = (k_d s + k_p)(m_L s² + b s + k) / (s² (J_m m_L s² + (J_m + m_L)(b s + k))).
  // Near the resonance |L| crosses 1 several times and the phase passes −π between them, yet the loop
  // without delay is stable: the margin there is (PM + 2π)/ω_c, not 0.
  const double Jm = 0.01, mL = 0.05, k = 50, b = 0.02, kp = 2, kd = 0.2;
  LinearLoop loop{"flex", "flexible joint", polyMul({kp, kd}, {k, b, mL}), polyMul({0, 0, 1}, {(Jm + mL) * k, (Jm + mL) * b, Jm * mL}), 0.0};
  const LoopAnalysis free = analyseLoop(loop);
  REQUIRE(free.stable);
  MESSAGE("delay margin ", free.delay_margin, " s at crossover ", free.crossover, " rad/s, PM ", free.phase_margin);
  CHECK(free.delay_margin > 0);
  CHECK(free.delay_margin < kUnboundedDelay);
  // A high-order Padé (its phase is right to ωT ≈ 2π) brackets it on the closed-loop poles.
  loop.delay = 0.97 * free.delay_margin;
  CHECK(analyseLoop(loop, 8).stable);
  loop.delay = 1.03 * free.delay_margin;
  CHECK_FALSE(analyseLoop(loop, 8).stable);
}

TEST_CASE("a PI loop with k_I = 0 screens as its P loop; the plant's own integrator is never cancelled") {
  // Speed loop L(s) = (k_P s + k_I) / (s · J s): the first s is the PI law's, the second the plant's.
  const double J = 0.5, kp = 2.0;
  LinearLoop pi0{"speed", "speed loop", {0.0, kp}, {0.0, 0.0, J}, 0.0};
  pi0.controller_integrators = 1;
  const LoopAnalysis a = analyseLoop(pi0);
  REQUIRE(a.poles.size() == 1);
  CHECK(a.poles[0].real() == doctest::Approx(-kp / J));  // the P loop's pole −k_P/J
  CHECK(a.stable);
  // The same N/D without the flag: a PD position loop with k_P = 0 leaves the position adrift.
  LinearLoop pd0 = pi0;
  pd0.controller_integrators = 0;
  const LoopAnalysis b = analyseLoop(pd0);
  REQUIRE(b.poles.size() == 2);
  CHECK(b.max_real == doctest::Approx(0.0).epsilon(1e-12));
  // With k_I ≠ 0 nothing is cancelled: the PI loop's two poles.
  LinearLoop pi = pi0;
  pi.num = {1.0, kp};
  CHECK(analyseLoop(pi).poles.size() == 2);
}

TEST_CASE("zero-order hold: 1/s, 1/(m s²) and 1/(s + p) held over T are their closed forms") {
  const double T = 1e-3, m = 2.5, p = 40;
  Poly n, d;
  zeroOrderHold({1}, {0, 1}, T, n, d);  // T/(z − 1)
  CHECK(n.size() == 2);
  CHECK(n[0] == doctest::Approx(T).epsilon(1e-12));
  CHECK(std::abs(n[1]) < 1e-15);
  CHECK(d[0] == doctest::Approx(-1.0).epsilon(1e-12));
  CHECK(d[1] == 1.0);
  zeroOrderHold({1}, {0, 0, m}, T, n, d);  // T²(z + 1)/(2m (z − 1)²)
  REQUIRE(n.size() == 3);
  CHECK(n[0] == doctest::Approx(T * T / (2 * m)).epsilon(1e-10));
  CHECK(n[1] == doctest::Approx(T * T / (2 * m)).epsilon(1e-10));
  CHECK(std::abs(n[2]) < 1e-15);
  CHECK(d[0] == doctest::Approx(1.0).epsilon(1e-12));
  CHECK(d[1] == doctest::Approx(-2.0).epsilon(1e-12));
  zeroOrderHold({1}, {p, 1}, T, n, d);  // (1 − e^{−pT}) / (p (z − e^{−pT}))
  CHECK(n[0] == doctest::Approx((1 - std::exp(-p * T)) / p).epsilon(1e-12));
  CHECK(d[0] == doctest::Approx(-std::exp(-p * T)).epsilon(1e-12));
  zeroOrderHold({3}, {1}, T, n, d);  // a static gain passes unchanged
  CHECK(n == Poly{3});
  CHECK(d == Poly{1});
  CHECK_THROWS(zeroOrderHold({0, 0, 1}, {0, 1}, T, n, d));  // improper: s
}

TEST_CASE("sampled PD on m s²: the poles are ln of the eigenvalues of the held closed loop, over T") {
  // x' = v, m v' = u held over T, u_k = −(k_p x_k + k_d v_k): exactly x⁺ = x + T v + T² u/(2m),
  // v⁺ = v + T u/m. Its matrix's eigenvalues are e^{sT} of the screened poles.
  const double m = 2.5, kp = 4e4, kd = 300, T = 2e-3;
  LinearLoop loop{"motion", "PD", {kp, kd}, {0, 0, m}, T / 2};
  loop.sampled = {T, {kp, kd}, {0, 0, m}};
  const LoopAnalysis a = analyseLoop(loop);
  Eigen::Matrix2d Phi;
  Phi << 1 - T * T * kp / (2 * m), T - T * T * kd / (2 * m), -T * kp / m, 1 - T * kd / m;
  const Eigen::Vector2cd z = Phi.eigenvalues();
  REQUIRE(a.poles.size() == 2);
  for (int i = 0; i < 2; ++i) {
    const std::complex<double> s = std::log(z[i]) / T;
    bool found = false;
    for (const auto& p : a.poles) found = found || std::abs(p - s) < 1e-8 * std::abs(s);
    CHECK(found);
  }
  CHECK(a.stable);
  // Past the sampled loop's limit (here k_d T/m ≥ 2 or so) it is unstable although the continuous one is not.
  loop.sampled = {T, {kp, 3000}, {0, 0, m}};
  loop.num = {kp, 3000};
  CHECK_FALSE(analyseLoop(loop).stable);
}

TEST_CASE("sampled integral loop a z^{−N}/(z − 1): delay margin π/(2ω_c), ω_c = (2/T) asin(a/2)") {
  // L(e^{jωT}) = a e^{−jωT(N + ½)} / (2j sin(ωT/2)): its crossover and the stated delay (N + ½)T
  // give a margin that does not depend on N (past it, at 40 steps, the loop is unstable: the same margin).
  const double T = 1e-3, k = 120, a = k * T, wc = 2 / T * std::asin(a / 2);
  for (const int N : {1, 5, 10, 40}) {  // 40 steps: far past the margin
    CAPTURE(N);
    LinearLoop loop{"force", "integral", {k}, {0, 1}, (N + 0.5) * T};
    loop.sampled = {T, {1}, {1}, {a}, {-1, 1}, N};
    const LoopAnalysis an = analyseLoop(loop);
    CHECK(an.delay_margin == doctest::Approx(M_PI / (2 * wc)).epsilon(1e-6));
    CHECK(an.stable == (loop.delay < an.delay_margin));
    // The slowest pole decays as the recursion f(k+1) = f(k) − a f(k − N) does.
    std::vector<double> f(2000, 0.0);
    f[std::size_t(N)] = 1.0;
    for (std::size_t j = std::size_t(N); j + 1 < f.size(); ++j) f[j + 1] = f[j] - a * f[j - std::size_t(N)];
    double peak_early = 0, peak_late = 0;
    for (std::size_t j = 1000; j < 1300; ++j) peak_early = std::max(peak_early, std::abs(f[j]));
    for (std::size_t j = 1700; j < 2000; ++j) peak_late = std::max(peak_late, std::abs(f[j]));
    const double rate = std::log(peak_late / peak_early) / (700 * T);
    CHECK(rate == doctest::Approx(an.max_real).epsilon(0.02));
  }
}

TEST_CASE("a delay of more than kMaxSampledSteps steps is screened in continuous time (a grade's budget holds)") {
  // dt 10 µs against a 10 ms delay is 1000 steps: 1000 discrete poles to find, seconds per screening;
  // at such a step the sampled and the continuous loop agree, and the continuous answer is the same one.
  const double T = 1e-5, k = 20;
  const int N = 1000;
  LinearLoop loop{"force", "integral", {k}, {0, 1}, (N + 0.5) * T};
  const LoopAnalysis continuous = analyseLoop(loop);
  loop.sampled = {T, {1}, {1}, {k * T}, {-1, 1}, N};
  REQUIRE(N > kMaxSampledSteps);
  const LoopAnalysis an = analyseLoop(loop);
  CHECK(an.delay_margin == continuous.delay_margin);
  CHECK(an.max_real == continuous.max_real);
  CHECK(an.poles.size() == continuous.poles.size());
  // The closed form of the continuous integral loop k e^{−sτ}/s: margin π/(2k).
  CHECK(an.delay_margin == doctest::Approx(M_PI / (2 * k)).epsilon(1e-3));
}
