// What the motion-control lab shows: the arm, its desired pose as a green ghost outline, the Bullet
// run as a violet ghost, coil springs at the joints when they are flexible, joints turning red while
// their torque saturates; and the overlay with tracking errors and torques.
#include <algorithm>
#include <cmath>

#include "labs/motion_control/lab.h"
#include "labs/numbers.h"

namespace dyn::motion_control {
namespace {

const Color kLink{0.23f, 0.42f, 0.68f, 1.0f}, kJoint{0.15f, 0.15f, 0.18f, 1.0f}, kSat{0.85f, 0.15f, 0.15f, 1.0f};
const Color kDesired{0.20f, 0.65f, 0.30f, 0.55f}, kGhost{0.55f, 0.35f, 0.75f, 0.35f}, kSpring{0.85f, 0.55f, 0.20f, 1.0f};
const Color kBase{0.55f, 0.55f, 0.55f, 1.0f};

Eigen::Vector3d at(const Eigen::Vector2d& p, double z = 0) { return {p.x(), p.y(), z}; }

Eigen::VectorXd angles(const Trace& tr, std::size_t r, const char* base, int n) {
  Eigen::VectorXd th(n);
  for (int i = 0; i < n; ++i) th[i] = tr.at(r, base + std::to_string(i + 1));
  return th;
}

void drawArm(const std::vector<Eigen::Vector2d>& p, Color link, Color joint, double radius, double z, Scene& s) {
  for (std::size_t i = 0; i + 1 < p.size(); ++i) s.capsules.push_back({at(p[i], z), at(p[i + 1], z), radius, link});
  for (std::size_t i = 0; i + 1 < p.size(); ++i) s.spheres.push_back({at(p[i], z + 0.01), radius * 1.35, joint});
}

}  // namespace

void MotionControlLab::scene(const Trace& tr, std::size_t row, const Trace* ghost, Scene& s) const {
  const int n = s_.plant.n();
  s.camera.ortho = true;
  s.camera.eye = {0, 0, 5};
  s.camera.target = {0, 0, 0};
  s.framing.fit = true;
  // The desired paths of the joints and the tip over the whole run (faint green): where the arm is
  // asked to go. They span the space the run sweeps, which the renderer frames (a still camera).
  const Trajectory& T = s_.trajectory;
  std::vector<Polyline> paths(static_cast<std::size_t>(n));
  for (int k = 0; k <= 200; ++k) {
    Eigen::VectorXd q, qd, qdd;
    T.at(s_.duration * k / 200.0, q, qd, qdd);
    const auto pts = jointPoints(s_.plant, q);
    for (int i = 0; i < n; ++i) paths[std::size_t(i)].points.push_back(at(pts[std::size_t(i) + 1], -0.08));
  }
  auto extend = [&](const Eigen::Vector3d& p) {
    s.framing.bounds.extend(p - Eigen::Vector3d(0.03, 0.03, 0.03)), s.framing.bounds.extend(p + Eigen::Vector3d(0.03, 0.03, 0.03));
  };
  for (auto& path : paths) {
    for (const auto& p : path.points) extend(p);
    path.color = {0.20f, 0.65f, 0.30f, 0.45f};
    s.polylines.push_back(std::move(path));
  }
  for (const Trace* t : {&tr, ghost})
    if (t && row < t->rows())
      for (const auto& p : jointPoints(s_.plant, angles(*t, row, "q", n))) extend(at(p));
  s.boxes.push_back({{0, -0.03, -0.03}, {0.05, 0.03, 0.02}, Eigen::Matrix3d::Identity(), kBase});
  // Desired pose and the Bullet run behind the arm.
  drawArm(jointPoints(s_.plant, angles(tr, row, "qd", n)), kDesired, kDesired, 0.012, -0.06, s);
  if (ghost && row < ghost->rows()) drawArm(jointPoints(s_.plant, angles(*ghost, row, "q", n)), kGhost, kGhost, 0.016, -0.04, s);
  const auto p = jointPoints(s_.plant, angles(tr, row, "q", n));
  drawArm(p, kLink, tr.at(row, "tau_sat") > 0.5 ? kSat : kJoint, 0.018, 0.0, s);
  // Flexible joints: a coil along each link's start, stretched by the deflection (drawing only).
  if (s_.plant.flexible)
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector2d dir = (p[std::size_t(i) + 1] - p[std::size_t(i)]).normalized();
      const double len = 0.08 * (1.0 + 5.0 * std::clamp(tr.at(row, "defl" + std::to_string(i + 1)), -0.1, 0.1));
      s.springs.push_back({at(p[std::size_t(i)], 0.04), at(p[std::size_t(i)] + len * dir, 0.04), 0.02, kSpring, 6});
    }
}

void MotionControlLab::overlay(const Trace& tr, std::size_t row, Overlay& o) const {
  const int n = s_.plant.n();
  static const char* kinds[] = {"none", "constant", "pid", "computed torque", "PD + gravity"};
  o.title = s_.plant.flexible ? "motion control (flexible joints)" : "motion control";
  o.lines = {{"t", fmt("%.3f s", tr.at(row, "t"))},
             {"controller", kinds[int(s_.controller.kind)]},
             {"control period", fmt("%.0f ms", s_.controller.period * 1e3)},
             {"torque limit", tr.at(row, "tau_sat") > 0.5 ? "SATURATED" : "within"}};
  for (int i = 0; i < n; ++i)
    o.lines.push_back({"e" + subscript(i + 1) + ", τ" + subscript(i + 1),
                       fmt("%.3f rad", tr.at(row, "e" + std::to_string(i + 1))) + ", " +
                           fmt("%.1f N·m", tr.at(row, "tau" + std::to_string(i + 1)))});
  static const Color palette[] = {{0.85f, 0.15f, 0.15f, 1}, {0.2f, 0.65f, 0.3f, 1}, {0.23f, 0.42f, 0.68f, 1}, {0.85f, 0.55f, 0.2f, 1}};
  std::vector<Series> errs;
  // In radians, as the trace and the rubric have them.
  for (int i = 0; i < std::min(n, 4); ++i) errs.push_back({"e" + subscript(i + 1) + " (rad)", {}, palette[i]});
  Series sat{"saturated", {}, kSat};
  for (std::size_t r = liveWindowStart(row, 2.0, s_.step.dt); r <= row; ++r) {
    for (int i = 0; i < int(errs.size()); ++i) errs[std::size_t(i)].values.push_back(float(tr.at(r, "e" + std::to_string(i + 1))));
    sat.values.push_back(float(tr.at(r, "tau_sat")));
  }
  o.plots = errs;
  o.plots.push_back(sat);
}

}  // namespace dyn::motion_control
