// The reference path and the leader that runs along it (the unicycle lab's reference).
//   path     a uniform Catmull–Rom spline through the JSON's points (open; end tangents by reflecting
//            the neighbour), tabulated by arc length s with its heading φ_p(s) (unwrapped) and
//            curvature κ(s) = (x'y'' − y'x'') / |c'|³
//   speed    the leader's speed limit along the path: v_lim(s) = min(v_nom, √(a_lat / |κ(s)|)),
//            reduced so that braking at a_long reaches every later limit (a backward pass) and the
//            path's end at rest; the leader accelerates at most a_long:
//            v ← min(v_lim(s), v + a_long dt),  s ← s + v dt  (one step per control step)
//   reference  p_d = c(s), φ_d = φ_p(s), v_d = v, φ_d' = κ(s) v
// Cornering faster needs lateral force m v φ' = m v² κ: a_lat (a gain) is how hard the student lets
// the leader corner; the grader checks the force against μ m g.
#pragma once
#include <Eigen/Core>
#include <vector>

namespace dyn::unicycle {

class Path {
 public:
  struct Sample {
    Eigen::Vector2d p;
    double heading, curvature;  // rad, 1/m
  };
  // points: at least 2, consecutive points distinct (checked by the lab's parser).
  explicit Path(std::vector<Eigen::Vector2d> points, int samples_per_segment = 64);
  double length() const { return s_.back(); }
  Sample at(double s) const;  // s clamped to [0, length()]
  const std::vector<Eigen::Vector2d>& points() const { return points_; }
  // The tabulated samples (for drawing): every table point.
  std::vector<Eigen::Vector2d> polyline() const;

  // The speed limit table for a lateral acceleration a_lat and longitudinal a_long (m/s²), top speed v_nom.
  std::vector<double> speedLimits(double v_nom, double a_lat, double a_long) const;
  // The limit at s from such a table (linear between samples).
  double limitAt(const std::vector<double>& table, double s) const;

 private:
  std::size_t index(double s, double& frac) const;
  std::vector<Eigen::Vector2d> points_;
  std::vector<double> s_, heading_, curvature_;
  std::vector<Eigen::Vector2d> p_;
};

// The leader: a point running along the path at the limited speed, from rest at s = 0.
struct ReferenceSettings {
  std::vector<Eigen::Vector2d> points;
  double speed = 1.5;   // m/s, v_nom
  double accel = 1.0;   // m/s², a_long
};

class Leader {
 public:
  Leader(const Path& path, const ReferenceSettings& r, double a_lat);
  void advance(double dt);  // one control step
  double s() const { return s_; }
  double speed() const { return v_; }
  Path::Sample sample() const { return path_->at(s_); }

 private:
  const Path* path_;
  std::vector<double> limit_;
  double speed_max_, accel_;
  double s_ = 0, v_ = 0;
};

}  // namespace dyn::unicycle
