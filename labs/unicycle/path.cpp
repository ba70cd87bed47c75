// The reference path's spline, its arc-length table and the leader's speed law (path.h).
#include "labs/unicycle/path.h"

#include <algorithm>
#include <cmath>

#include "physics/det/det.h"

namespace dyn::unicycle {

Path::Path(std::vector<Eigen::Vector2d> points, int samples_per_segment) : points_(std::move(points)) {
  const std::size_t n = points_.size();
  auto P = [&](long i) -> Eigen::Vector2d {
    if (i < 0) return 2.0 * points_[0] - points_[1];
    if (i >= long(n)) return 2.0 * points_[n - 1] - points_[n - 2];
    return points_[std::size_t(i)];
  };
  double s = 0, last_heading = 0;
  Eigen::Vector2d last_p = points_[0];
  for (std::size_t seg = 0; seg + 1 < n; ++seg) {
    const long i = long(seg);
    const Eigen::Vector2d p0 = P(i - 1), p1 = P(i), p2 = P(i + 1), p3 = P(i + 2);
    // c(u) = ½ (2p1 + (p2 − p0) u + (2p0 − 5p1 + 4p2 − p3) u² + (3p1 − p0 − 3p2 + p3) u³).
    const Eigen::Vector2d a = p2 - p0, b = 2 * p0 - 5 * p1 + 4 * p2 - p3, c = 3 * p1 - p0 - 3 * p2 + p3;
    for (int k = seg == 0 ? 0 : 1; k <= samples_per_segment; ++k) {
      const double u = double(k) / samples_per_segment;
      const Eigen::Vector2d p = 0.5 * (2 * p1 + a * u + b * u * u + c * u * u * u);
      const Eigen::Vector2d d1 = 0.5 * (a + 2 * b * u + 3 * c * u * u), d2 = 0.5 * (2 * b + 6 * c * u);
      const double speed = std::max(d1.norm(), 1e-12);
      double heading = det::atan2(d1.y(), d1.x());
      if (!s_.empty()) heading = last_heading + std::remainder(heading - last_heading, 2 * M_PI);
      s += (p - last_p).norm();
      s_.push_back(s);
      p_.push_back(p);
      heading_.push_back(heading);
      curvature_.push_back((d1.x() * d2.y() - d1.y() * d2.x()) / (speed * speed * speed));
      last_p = p;
      last_heading = heading;
    }
  }
}

std::size_t Path::index(double s, double& frac) const {
  s = std::clamp(s, 0.0, length());
  std::size_t i = std::size_t(std::upper_bound(s_.begin(), s_.end(), s) - s_.begin());
  i = std::clamp<std::size_t>(i, 1, s_.size() - 1);
  const double ds = s_[i] - s_[i - 1];
  frac = ds > 0 ? (s - s_[i - 1]) / ds : 0.0;
  return i - 1;
}

Path::Sample Path::at(double s) const {
  double f;
  const std::size_t i = index(s, f);
  return {(1 - f) * p_[i] + f * p_[i + 1], (1 - f) * heading_[i] + f * heading_[i + 1],
          (1 - f) * curvature_[i] + f * curvature_[i + 1]};
}

std::vector<Eigen::Vector2d> Path::polyline() const { return p_; }

std::vector<double> Path::speedLimits(double v_nom, double a_lat, double a_long) const {
  std::vector<double> v(s_.size());
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = std::min(v_nom, std::sqrt(a_lat / std::max(std::abs(curvature_[i]), 1e-9)));
  // Stop at the end; brake in time for every later limit: v_i ≤ √(v_{i+1}² + 2 a_long Δs).
  v.back() = 0.0;
  for (std::size_t i = v.size() - 1; i-- > 0;) v[i] = std::min(v[i], std::sqrt(v[i + 1] * v[i + 1] + 2 * a_long * (s_[i + 1] - s_[i])));
  return v;
}

double Path::limitAt(const std::vector<double>& table, double s) const {
  double f;
  const std::size_t i = index(s, f);
  return (1 - f) * table[i] + f * table[i + 1];
}

Leader::Leader(const Path& path, const ReferenceSettings& r, double a_lat)
    : path_(&path), limit_(path.speedLimits(r.speed, a_lat, r.accel)), speed_max_(r.speed), accel_(r.accel) {}

void Leader::advance(double dt) {
  v_ = std::max(0.0, std::min({path_->limitAt(limit_, s_), v_ + accel_ * dt, speed_max_}));
  s_ = std::min(s_ + v_ * dt, path_->length());
}

}  // namespace dyn::unicycle
