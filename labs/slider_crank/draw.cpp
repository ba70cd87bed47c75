// What the slider-crank lab shows: rail, slider, the arm, the constraint-force arrow, the
// reference marker, the Bullet run as a translucent ghost, and the live overlay panel.
#include <cmath>
#include <cstdio>

#include "labs/slider_crank/lab.h"

namespace dyn::slider_crank {
namespace {

const Color kLink{0.23f, 0.42f, 0.68f, 1.0f}, kJoint{0.15f, 0.15f, 0.18f, 1.0f};
const Color kRail{0.55f, 0.55f, 0.55f, 1.0f}, kSlider{0.85f, 0.55f, 0.20f, 1.0f};
const Color kForce{0.85f, 0.15f, 0.15f, 1.0f}, kRef{0.20f, 0.65f, 0.30f, 1.0f};
const Color kGhost{0.55f, 0.35f, 0.75f, 0.35f};

Eigen::Vector3d at(const Eigen::Vector2d& p, double z = 0) { return {p.x(), p.y(), z}; }

void drawArm(const Mechanism& mech, const Eigen::Vector3d& th, Color link, Color joint, double z, Scene& s) {
  const auto p = mech.jointPoints(th);
  for (int i = 0; i < 3; ++i) s.capsules.push_back({at(p[i], z), at(p[i + 1], z), 0.018, link});
  for (int i = 0; i < 3; ++i) s.spheres.push_back({at(p[i], z + 0.01), 0.024, joint});
}

Eigen::Vector3d thetaAt(const Trace& tr, std::size_t r) { return {tr.at(r, "q1"), tr.at(r, "q2"), tr.at(r, "q3")}; }

std::string fmt(const char* f, double x) {
  char b[64];
  std::snprintf(b, sizeof b, f, x);
  return b;
}

}  // namespace

void SliderCrankLab::scene(const Trace& tr, std::size_t row, const Trace* ghost, Scene& s) const {
  const Mechanism mech(s_.params);
  const auto& L = s_.params.links;
  const double reach = L[0].length + L[1].length + L[2].length;
  const double x_min = L[1].length + L[2].length - L[0].length - 0.15, x_max = reach + 0.15;
  // Camera: the whole crank circle and the rail's working range in the right 56 % of the frame's
  // width, clear of the overlay panel on the left; the circle (and the force arrow below the rail)
  // in its height. A 4:3 frame is width-bound, a 16:9 one shows the same width a little closer.
  const double x_lo = std::min(-L[0].length, x_min) - 0.05;
  const double visible_w = (x_max - x_lo) / 0.56;
  s.camera.ortho = true;
  s.camera.half_width = 0.5 * visible_w;
  s.camera.half_height = L[0].length + 0.35;
  s.camera.target = {x_max + 0.02 - 0.5 * visible_w, 0.12, 0};
  s.camera.eye = s.camera.target + Eigen::Vector3d(0, 0, 5);

  // Ground mount and rail.
  s.boxes.push_back({{0, -0.04, -0.02}, {0.05, 0.03, 0.02}, Eigen::Matrix3d::Identity(), kRail});
  s.boxes.push_back({{0.5 * (x_min + x_max), -0.035, -0.03}, {0.5 * (x_max - x_min), 0.008, 0.02},
                     Eigen::Matrix3d::Identity(), kRail});
  // The Bullet ghost at the same time, behind the arm.
  if (ghost && row < ghost->rows()) drawArm(mech, thetaAt(*ghost, row), kGhost, kGhost, -0.05, s);
  // The arm and the slider.
  const Eigen::Vector3d th = thetaAt(tr, row);
  drawArm(mech, th, kLink, kJoint, 0.0, s);
  const double x_c = tr.at(row, "x_c");
  s.boxes.push_back({{x_c, 0, -0.01}, {0.045, 0.022, 0.03}, Eigen::Matrix3d::Identity(), kSlider});
  // Reference marker on the rail.
  s.spheres.push_back({{tr.at(row, "x_d"), -0.035, 0.02}, 0.012, kRef});
  // The constraint force the arm applies to the slider, (f_Tx, f_Ty).
  const Eigen::Vector3d f(tr.at(row, "f_Tx"), tr.at(row, "f_Ty"), 0);
  if (f.norm() > 1e-9)
    s.arrows.push_back({{x_c, 0, 0.04}, f * s_.arrow_scale, 0.008, kForce});
  // The crank pin's path so far.
  Polyline path;
  path.color = {0.4f, 0.4f, 0.45f, 0.6f};
  const std::size_t first = row > 2000 ? row - 2000 : 0;
  for (std::size_t r = first; r <= row; r += 5) path.points.push_back(at(mech.jointPoints(thetaAt(tr, r))[1], 0.03));
  if (path.points.size() > 1) s.polylines.push_back(std::move(path));
}

void SliderCrankLab::overlay(const Trace& tr, std::size_t row, Overlay& o) const {
  const auto& c = s_.controller;
  o.title = "slider crank";
  const char* law = c.kind == ControllerKind::None ? "none (passive)"
                    : c.law == ForceLaw::OpenLoop  ? "open loop"
                    : c.law == ForceLaw::Proportional ? "proportional"
                                                   : "integral";
  o.lines = {{"t", fmt("%.3f s", tr.at(row, "t"))},
             {"force law", law},
             {"kp_x, kd_x", fmt("%.0f", c.gains.kp_x) + ", " + fmt("%.1f", c.gains.kd_x)},
             {"kp_f, ki_f", fmt("%.2f", c.gains.kp_f) + ", " + fmt("%.1f", c.gains.ki_f)},
             {"delay", fmt("%.0f ms", c.delay * 1e3)},
             {"x_c / x_d", fmt("%.3f", tr.at(row, "x_c")) + " / " + fmt("%.3f m", tr.at(row, "x_d"))},
             {"f_Ty / f_des", fmt("%.2f", tr.at(row, "f_Ty")) + " / " + fmt("%.2f N", tr.at(row, "f_des"))}};
  // Live plots over the last two seconds.
  Series force{"f_Ty (N)", {}, kForce}, err{"x error (mm)", {}, kRef};
  const std::size_t window = std::size_t(2.0 / s_.step.dt);
  const std::size_t first = row > window ? row - window : 0;
  const std::size_t stride = std::max<std::size_t>(1, window / 200);
  for (std::size_t r = first; r <= row; r += stride) {
    force.values.push_back(float(tr.at(r, "f_Ty")));
    err.values.push_back(float(1e3 * (tr.at(r, "x_c") - tr.at(r, "x_d"))));
  }
  o.plots = {force, err};
}

}  // namespace dyn::slider_crank
