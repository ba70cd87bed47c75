// What the impedance lab shows: the arm, the reference pose as a green ghost, the Bullet run as a
// violet ghost, the target impedance as a spring and damper glyph on the tip along the push (its
// stretch x − x_ref magnified to be seen, the factor in the overlay), the external force as a red
// arrow at the tip, the wall as a grey slab; the overlay with x − x_ref and F.
#include <algorithm>
#include <cmath>

#include "labs/impedance/lab.h"
#include "labs/numbers.h"

namespace dyn::impedance {
namespace {

const Color kLink{0.23f, 0.42f, 0.68f, 1.0f}, kJoint{0.15f, 0.15f, 0.18f, 1.0f}, kRef{0.20f, 0.65f, 0.30f, 0.55f};
const Color kGhost{0.55f, 0.35f, 0.75f, 0.35f}, kSpring{0.85f, 0.55f, 0.20f, 1.0f}, kForce{0.85f, 0.15f, 0.15f, 1.0f};
const Color kWall{0.55f, 0.55f, 0.55f, 1.0f};

constexpr double kRestLength = 0.15;  // m, the spring glyph's length at x = x_ref

Eigen::Vector3d at(const Eigen::Vector2d& p, double z = 0) { return {p.x(), p.y(), z}; }

// A rotation about z taking x̂ to the unit vector u.
Eigen::Matrix3d rotationZ(const Eigen::Vector2d& u) {
  Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
  r.topLeftCorner<2, 2>() << u.x(), -u.y(), u.y(), u.x();
  return r;
}

Eigen::Vector3d angles(const Trace& tr, std::size_t r) { return {tr.at(r, "q1"), tr.at(r, "q2"), tr.at(r, "q3")}; }

void drawArm(const std::vector<Eigen::Vector2d>& p, Color link, Color joint, double radius, double z, Scene& s) {
  for (std::size_t i = 0; i + 1 < p.size(); ++i) s.capsules.push_back({at(p[i], z), at(p[i + 1], z), radius, link});
  for (std::size_t i = 0; i + 1 < p.size(); ++i) s.spheres.push_back({at(p[i], z + 0.01), radius * 1.35, joint});
}

}  // namespace

void ImpedanceLab::scene(const Trace& tr, std::size_t row, const Trace* ghost, Scene& s) const {
  s.camera.ortho = true;
  s.camera.eye = {0, 0, 5};
  s.framing.fit = true;
  const auto ref = motion_control::jointPoints(s_.plant, s_.pose);
  auto extend = [&](const Eigen::Vector2d& p) {
    s.framing.bounds.extend(at(p) - Eigen::Vector3d(0.08, 0.08, 0.03)), s.framing.bounds.extend(at(p) + Eigen::Vector3d(0.08, 0.08, 0.03));
  };
  for (const auto& p : ref) extend(p);
  // The whole run's tip path frames the camera (a still camera over the run).
  // The spring glyph's anchor (see below) at a row: tip − L0 û − g (tip − x_ref).
  const double g = springMagnification(tr);
  const Eigen::Vector2d u = pushDirection(), side(-u.y(), u.x());
  auto anchorAt = [&](std::size_t r) {
    const Eigen::Vector2d x(tr.at(r, "x"), tr.at(r, "y")), xr(tr.at(r, "x_ref"), tr.at(r, "y_ref"));
    return Eigen::Vector2d(x - kRestLength * u - g * (x - xr));
  };
  // The force arrow on the tip (below) is framed too: its head stays in the picture.
  const auto arrowAt = [&](std::size_t r) {
    const Eigen::Vector2d F(tr.at(r, "F_ext_x"), tr.at(r, "F_ext_y"));
    return F.norm() > 1e-6 ? Eigen::Vector2d(std::min(0.3, 0.01 * F.norm()) * F.normalized()) : Eigen::Vector2d::Zero();
  };
  for (std::size_t r = 0; r < tr.rows(); r += std::max<std::size_t>(1, tr.rows() / 100)) {
    const Eigen::Vector2d x(tr.at(r, "x"), tr.at(r, "y"));
    extend(x), extend(anchorAt(r));
    const Eigen::Vector3d head = at(Eigen::Vector2d(x + arrowAt(r)));  // the arrow's head, a small margin round it
    s.framing.bounds.extend(head - Eigen::Vector3d(0.03, 0.03, 0.03)), s.framing.bounds.extend(head + Eigen::Vector3d(0.03, 0.03, 0.03));
  }
  s.boxes.push_back({{0, -0.03, -0.03}, {0.05, 0.03, 0.02}, Eigen::Matrix3d::Identity(), kWall});
  if (s_.wall.enabled) {
    const Eigen::Vector2d tip = ref.back();
    s.boxes.push_back({{s_.wall.x + 0.02, tip.y(), -0.02}, {0.02, 0.25, 0.02}, Eigen::Matrix3d::Identity(), kWall});
    extend({s_.wall.x + 0.05, tip.y()});
  }
  drawArm(ref, kRef, kRef, 0.012, -0.06, s);
  if (ghost && row < ghost->rows()) drawArm(motion_control::jointPoints(s_.plant, angles(*ghost, row)), kGhost, kGhost, 0.016, -0.04, s);
  const auto p = motion_control::jointPoints(s_.plant, angles(tr, row));
  drawArm(p, kLink, kJoint, 0.018, 0.0, s);
  // The target impedance, readable whatever its size: a coil (K_des) beside a damper (D_des) on the
  // tip, along the push, of length L0 at x = x_ref (its anchor then at x_ref − L0 û) and L0 û + g (x − x_ref)
  // away from it: its stretch magnified g times (the overlay says so), the anchor moving instead.
  const Eigen::Vector2d xr(tr.at(row, "x_ref"), tr.at(row, "y_ref")), tip = p.back();
  const Eigen::Vector2d anchor = anchorAt(row), d = tip - anchor;
  s.spheres.push_back({at(xr, 0.03), 0.012, kRef});
  s.boxes.push_back({at(anchor - 0.008 * u, 0.04), {0.008, 0.035, 0.01}, rotationZ(u), kRef});
  s.springs.push_back({at(anchor + 0.018 * side, 0.04), at(tip + 0.018 * side, 0.04), 0.014, kSpring, 8});
  s.capsules.push_back({at(anchor - 0.018 * side, 0.04), at(anchor - 0.018 * side + 0.55 * d, 0.04), 0.011, kJoint});
  s.capsules.push_back({at(tip - 0.018 * side - 0.5 * d, 0.04), at(tip - 0.018 * side, 0.04), 0.004, kJoint});
  s.capsules.push_back({at(tip - 0.022 * side, 0.04), at(tip + 0.022 * side, 0.04), 0.005, kSpring});
  // The force on the tip (environment and wall), 0.01 m per newton, at most 0.3 m.
  if (arrowAt(row).norm() > 0) s.arrows.push_back({at(tip, 0.05), at(arrowAt(row)), 0.008, kForce});
}

Eigen::Vector2d ImpedanceLab::pushDirection() const {
  const double n = s_.force.value.norm();
  return n > 0 ? Eigen::Vector2d(s_.force.value / n) : Eigen::Vector2d(1, 0);
}

// The largest of 1, 2, 5, 10, … 100 that draws the target's static stretch |F|/K_des (along the
// push) at most L0: a 9 mm stretch is drawn ×10 (90 mm against L0 = 150 mm), 20 mm ×5.
double ImpedanceLab::springMagnification(const Trace& tr) const {
  const Eigen::Vector2d u = pushDirection();
  const double k = u.x() * u.x() * s_.target.K[0] + u.y() * u.y() * s_.target.K[1];
  // The larger of the target's stretch and the run's own (a controller softer than the target
  // stretches further): the anchor then never swings more than L0 and the frame stays on the arm.
  double d = s_.force.value.norm() / k;
  for (std::size_t r = 0; r < tr.rows(); ++r)
    d = std::max(d, std::abs(u.x() * (tr.at(r, "x") - tr.at(r, "x_ref")) + u.y() * (tr.at(r, "y") - tr.at(r, "y_ref"))));
  double g = 1;
  for (double c : {2.0, 5.0, 10.0, 20.0, 50.0, 100.0})
    if (c * d <= kRestLength) g = c;
  return d > 0 ? g : 1.0;
}

void ImpedanceLab::overlay(const Trace& tr, std::size_t row, Overlay& o) const {
  static const char* kinds[] = {"none", "constant", "joint space", "task space", "feedback linearisation"};
  o.title = "impedance control";
  o.lines = {{"t", fmt("%.3f s", tr.at(row, "t"))},
             {"realisation", kinds[int(s_.kind)]},
             {"x − x_ref", fmt("%.1f mm", 1e3 * (tr.at(row, "x") - tr.at(row, "x_ref")))},
             {"y − y_ref", fmt("%.1f mm", 1e3 * (tr.at(row, "y") - tr.at(row, "y_ref")))},
             {"F_ext", fmt("(%.1f, ", tr.at(row, "F_ext_x")) + fmt("%.1f) N", tr.at(row, "F_ext_y"))},
             {"spring glyph", fmt("stretch drawn ×%g", springMagnification(tr))}};
  Series dx{"x − x_ref (mm)", {}, {0.85f, 0.15f, 0.15f, 1}}, dy{"y − y_ref (mm)", {}, {0.23f, 0.42f, 0.68f, 1}};
  for (std::size_t r = liveWindowStart(row, 2.0, s_.step.dt); r <= row; ++r) {
    dx.values.push_back(float(1e3 * (tr.at(r, "x") - tr.at(r, "x_ref"))));
    dy.values.push_back(float(1e3 * (tr.at(r, "y") - tr.at(r, "y_ref"))));
  }
  o.plots = {dx, dy};
}

}  // namespace dyn::impedance
