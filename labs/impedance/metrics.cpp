// What the impedance lab measures. Along the force direction û (the push), with d(t) = û·(x − x_ref):
//   stiffness        K_id = |F| / d_static, d_static the mean displacement over the last 20 % of the push
//   omega_n, zeta    the 2nd-order step response d_s(1 − …) best fitting d(t) over the push (grid, then
//                    refined), against the target's ω_t = √(K/M_des), ζ_t = D/(2√(KM_des))
//   apparent_mass    M_id = K_id / ω_fit² (kg): the mass the push feels, against the target's M_des
//   response_error   the largest |d − d_target| over the push (d_target: the target's analytic response),
//                    relative to the target's static displacement |F|/K_des: stiffness, mass and
//                    damping at once, the target realised or not
//   coupling         max |off-axis displacement| / max |d| over the push
//   wall_force_peak  the largest mean normal force of the wall over any 5 ms window (∫F dt / 5 ms):
//                    a rigid wall's plastic impact is an impulse P = Λ_n v_n (its row carries P/dt), a
//                    stiff wall's a short peak; a window of fixed length reads both alike, whatever dt
//   wall_overshoot   (peak − settled)/settled, settled: the mean wall force over the push's last 20 %
//                    (no settled contact: against |F| instead), when there is a wall
//   wall_force_error RMS of F_wall − F_t over the push's last 20 %, relative to F_t = F_x − K_des
//                    (x_wall − r − x_ref), what the target at rest against the wall presses with (the
//                    push along x reaching the wall): a steady press off by |mean − F_t|, or chattering
#include <algorithm>
#include <cmath>
#include <map>

#include "labs/impedance/lab.h"
#include "labs/numbers.h"
#include "physics/det/det.h"

namespace dyn::impedance {

// The unit step response of ẍ + 2ζω ẋ + ω² x = ω² (from rest at 0).
double unitStep(double w, double z, double t) {
  if (t <= 0) return 0;
  if (z < 1 - 1e-9) {
    const double wd = w * std::sqrt(1 - z * z);
    return 1 - det::exp(-z * w * t) * (det::cos(wd * t) + z * w / wd * det::sin(wd * t));
  }
  if (z <= 1 + 1e-9) return 1 - det::exp(-w * t) * (1 + w * t);
  const double r = w * std::sqrt(z * z - 1), s1 = -z * w + r, s2 = -z * w - r;
  return 1 + (s2 * det::exp(s1 * t) - s1 * det::exp(s2 * t)) / (s1 - s2);
}

namespace {

constexpr double kImpactWindow = 0.005;  // s, the wall force's averaging window

struct Fit {
  double w = 0, z = 0, cost = 1e300;
};

// Least squares over (ω, ζ) of d_s·unitStep against samples (t − t0, d): a grid on at most ~200 of
// the samples (every stride-th: the grid only picks the basin), then a pattern search on all of them.
Fit fitStep(const std::vector<double>& t, const std::vector<double>& d, double ds, double w0) {
  Fit best;
  auto costEvery = [&](double w, double z, std::size_t stride) {
    double c = 0;
    // The residual squared as one product: det::pow(x, 2) is x·x too (its integer powers multiply),
    // at the cost of a call and its special cases, ~750,000 times a fit.
    for (std::size_t i = 0; i < t.size(); i += stride) {
      const double e = d[i] - ds * unitStep(w, z, t[i]);
      c += e * e;
    }
    return c;
  };
  auto cost = [&](double w, double z) { return costEvery(w, z, 1); };
  const std::size_t stride = std::max<std::size_t>(1, t.size() / 200);
  double grid_best = 1e300;
  for (int i = 0; i <= 60; ++i)
    for (int j = 0; j <= 40; ++j) {
      const double w = w0 * det::pow(10.0, -1.0 + 2.0 * i / 60), z = 0.02 * det::pow(150.0, j / 40.0);
      if (const double c = costEvery(w, z, stride); c < grid_best) grid_best = c, best = {w, z, 0};
    }
  best.cost = cost(best.w, best.z);
  // Refine: shrinking pattern search.
  double hw = 0.05, hz = 0.1;
  for (int it = 0; it < 60; ++it) {
    bool moved = false;
    for (const auto& [a, b] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
      const double w = best.w * (1 + a * hw), z = std::max(1e-3, best.z * (1 + b * hz));
      if (const double c = cost(w, z); c < best.cost) best = {w, z, c}, moved = true;
    }
    if (!moved) hw *= 0.5, hz *= 0.5;
  }
  return best;
}

}  // namespace

json ImpedanceLab::metrics(const Trace& tr) const {
  const Force& f = s_.force;
  const double fn = f.value.norm();
  const Eigen::Vector2d u = fn > 0 ? Eigen::Vector2d(f.value / fn) : Eigen::Vector2d(1, 0), v(-u.y(), u.x());
  // The push's window, cut at the run's end (a shortened run still reads its last 20 %).
  const double t_run = tr.rows() ? tr.at(tr.rows() - 1, "t") + s_.step.dt : s_.duration;
  const double t_end = std::min(t_run, f.hold > 0 ? f.start + f.rise + f.hold : s_.duration);
  const double k_des = u.x() * u.x() * s_.target.K[0] + u.y() * u.y() * s_.target.K[1];
  const double m_des = u.x() * u.x() * s_.target.M[0] + u.y() * u.y() * s_.target.M[1];
  const double d_des = u.x() * u.x() * s_.target.D[0] + u.y() * u.y() * s_.target.D[1];
  std::vector<double> ts, ds, last, wall;
  double d_max = 0, off_max = 0, drift = 0, wall_settled = 0, miss = 0;
  std::size_t settled_rows = 0;
  std::vector<double> late_wall;  // the wall force over the push's last 20 %
  const auto t_col = tr.col("t"), x_col = tr.col("x"), y_col = tr.col("y"), x_ref = tr.col("x_ref"), y_ref = tr.col("y_ref");
  const auto x_target = tr.col("x_target"), y_target = tr.col("y_target"), F_ext_x = tr.col("F_ext_x");
  const auto energy = tr.col("energy"), work = tr.col("work");
  const double e0 = tr.rows() ? tr.at(0, "energy") : 0;
  for (std::size_t r = 0; r < tr.rows(); ++r) {
    const double t = t_col[r];
    const Eigen::Vector2d e(x_col[r] - x_ref[r], y_col[r] - y_ref[r]);
    drift = std::max(drift, std::abs(energy[r] - e0 - work[r]));
    // The wall's normal push on the tip (it pushes −x): the row's F_ext_x less the applied force.
    if (s_.wall.enabled) wall.push_back(-F_ext_x[r] + f.at(t).x());
    if (t < f.start || t >= t_end) continue;
    if (s_.wall.enabled && t >= t_end - 0.2 * (t_end - f.start)) wall_settled += wall.back(), ++settled_rows, late_wall.push_back(wall.back());
    ts.push_back(t - f.start - f.rise / 2);
    ds.push_back(u.dot(e));
    const Eigen::Vector2d e_t(x_target[r] - x_ref[r], y_target[r] - y_ref[r]);
    miss = std::max(miss, std::abs(u.dot(e - e_t)));
    d_max = std::max(d_max, std::abs(u.dot(e)));
    off_max = std::max(off_max, std::abs(v.dot(e)));
    if (t >= t_end - 0.2 * (t_end - f.start)) last.push_back(u.dot(e));
  }
  double d_static = 0;
  for (double x : last) d_static += x / double(std::max<std::size_t>(1, last.size()));
  json m = {{"energy_drift", drift}, {"max_constraint_residual", 0.0}, {"steps", tr.steps()}};
  m["stiffness_target"] = k_des;
  m["omega_target"] = std::sqrt(k_des / m_des);
  m["zeta_target"] = d_des / (2 * std::sqrt(k_des * m_des));
  m["apparent_mass_target"] = m_des;
  if (fn > 0 && std::abs(d_static) > 1e-12 && !ts.empty()) {
    const double k_id = fn / d_static;
    const Fit fit = fitStep(ts, ds, d_static, std::sqrt(k_des / m_des));
    m["stiffness"] = k_id;
    m["stiffness_error"] = std::abs(k_id / k_des - 1);
    m["omega_n"] = fit.w;
    m["zeta"] = fit.z;
    m["omega_error"] = std::abs(fit.w / std::sqrt(k_des / m_des) - 1);
    m["zeta_error"] = std::abs(fit.z - d_des / (2 * std::sqrt(k_des * m_des)));
    m["apparent_mass"] = k_id / (fit.w * fit.w);
    m["apparent_mass_error"] = std::abs(k_id / (fit.w * fit.w) / m_des - 1);
    m["response_error"] = miss / (fn / k_des);
    m["coupling"] = d_max > 0 ? off_max / d_max : 0.0;
    m["fit_rms"] = std::sqrt(fit.cost / double(ts.size())) / std::abs(d_static);
  } else {
    for (const char* k : {"stiffness", "stiffness_error", "omega_n", "zeta", "omega_error", "zeta_error", "apparent_mass",
                          "apparent_mass_error", "response_error", "coupling", "fit_rms"})
      m[k] = 0.0;
  }
  // The wall: the largest 5 ms mean force (a sliding sum over k rows) against the settled force.
  const std::size_t k = std::max<std::size_t>(1, std::size_t(std::lround(kImpactWindow / s_.step.dt)));
  double wall_peak = 0, sum = 0;
  for (std::size_t r = 0; r < wall.size(); ++r) {
    sum += wall[r] - (r >= k ? wall[r - k] : 0.0);
    wall_peak = std::max(wall_peak, sum / double(k));
  }
  wall_settled = settled_rows ? wall_settled / double(settled_rows) : 0.0;
  const double against = wall_settled > 1e-3 * fn ? wall_settled : fn;
  m["wall_force_peak"] = wall_peak;
  m["wall_force_settled"] = wall_settled;
  m["wall_overshoot"] = against > 1e-9 ? std::max(0.0, wall_peak / against - 1) : 0.0;
  const double gap = s_.wall.x - s_.wall.radius - (tr.rows() ? tr.at(0, "x_ref") : 0.0);
  const double f_t = std::max(0.0, f.value.x() - s_.target.K[0] * gap);
  m["wall_force_target"] = f_t;
  double miss_wall = 0;  // RMS of F_wall − F_t: a steady press reads |mean − F_t|, a chattering one its swings
  for (double w : late_wall) miss_wall += (w - f_t) * (w - f_t) / double(late_wall.size());
  m["wall_force_error"] = f_t > 1e-9 ? std::sqrt(miss_wall) / f_t : 0.0;
  return m;
}

json ImpedanceLab::differences(const Trace& a, const Trace& b, std::size_t rows) const {
  double dx = 0, dtau = 0;
  for (std::size_t r = 0; r < rows; ++r) {
    dx = std::max({dx, std::abs(a.at(r, "x") - b.at(r, "x")), std::abs(a.at(r, "y") - b.at(r, "y"))});
    for (const char* c : {"tau1", "tau2", "tau3"}) dtau = std::max(dtau, std::abs(a.at(r, c) - b.at(r, c)));
  }
  return {{"max_dx", dx}, {"max_dtau", dtau}};
}

}  // namespace dyn::impedance
