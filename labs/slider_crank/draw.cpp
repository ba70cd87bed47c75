// What the slider-crank lab shows: rail, slider, the arm, the constraint-force arrow, the
// reference marker, the Bullet run as a translucent ghost, and the live overlay panel. The
// renderer frames it (Scene::framing) around the space the run moves through.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "labs/slider_crank/lab.h"
#include "labs/numbers.h"
#include "labs/run_bounds.h"

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

// The space the mechanism moves through over the run (the rows so far, both engines), with the
// mount, the rail and the force arrow (at most 0.25 m of it: a blow-up's arrow may leave the frame).
Eigen::AlignedBox3d runBounds(const Mechanism& mech, const Trace& tr, const Trace* ghost, double arrow_scale) {
  Eigen::AlignedBox3d box;
  const Eigen::Vector3d pad(0.03, 0.03, 0.03);
  forBoundsRows(tr, ghost, [&](const Trace& run, std::size_t r) {
    for (const auto& p : mech.jointPoints(thetaAt(run, r))) box.extend(at(p) - pad), box.extend(at(p) + pad);
    Eigen::Vector3d f(run.at(r, "f_Tx"), run.at(r, "f_Ty"), 0);
    f *= arrow_scale;
    if (f.norm() > 0.25) f *= 0.25 / f.norm();
    box.extend(Eigen::Vector3d(run.at(r, "x_c"), 0, 0) + f);
  });
  return box;
}

}  // namespace

void SliderCrankLab::scene(const Trace& tr, std::size_t row, const Trace* ghost, Scene& s) const {
  const Mechanism mech(s_.params);
  const auto& L = s_.params.links;
  // The rail: where x_d(t) goes, 0.2 m more each way, within the slider's reach.
  const double reach = L[0].length + L[1].length + L[2].length;
  const double reach_min = L[1].length + L[2].length - L[0].length;
  const double x_min = std::max(reach_min, s_.reference.x0 + std::min(0.0, s_.reference.amplitude) - 0.2);
  const double x_max = std::min(reach, s_.reference.x0 + std::max(0.0, s_.reference.amplitude) + 0.2);
  // Side-on, orthographic; the renderer fits the run's space into the frame beside the panel.
  s.camera.ortho = true;
  s.camera.eye = {0, 0, 5};
  s.camera.target = {0, 0, 0};
  s.framing.fit = true;
  s.framing.bounds = runBounds(mech, tr, ghost && row < ghost->rows() ? ghost : nullptr, s_.arrow_scale);

  // Ground mount and rail.
  s.boxes.push_back({{0, -0.04, -0.02}, {0.05, 0.03, 0.02}, Eigen::Matrix3d::Identity(), kRail});
  s.boxes.push_back({{0.5 * (x_min + x_max), -0.035, -0.03}, {0.5 * (x_max - x_min), 0.008, 0.02},
                     Eigen::Matrix3d::Identity(), kRail});
  for (const Box& b : {s.boxes[0], s.boxes[1]}) s.framing.bounds.extend(b.center - b.half_extents), s.framing.bounds.extend(b.center + b.half_extents);
  // The Bullet ghost at the same time, behind the arm.
  if (ghost && row < ghost->rows()) drawArm(mech, thetaAt(*ghost, row), kGhost, kGhost, -0.05, s);
  // The arm and the slider.
  const Eigen::Vector3d th = thetaAt(tr, row);
  drawArm(mech, th, kLink, kJoint, 0.0, s);
  const double x_c = tr.at(row, "x_c");
  s.boxes.push_back({{x_c, 0, -0.01}, {0.045, 0.022, 0.03}, Eigen::Matrix3d::Identity(), kSlider});
  // The reference x_d: a green wedge pointing down at the rail from just above the slider, where
  // neither the slider nor the force arrow (below it) can hide it.
  s.cones.push_back({{tr.at(row, "x_d"), 0.03, 0.03}, {0, 1, 0}, 0.5, 0.05, kRef});
  s.framing.bounds.extend(Eigen::Vector3d(tr.at(0, "x_d"), 0.03 + 0.05 + 0.01, 0));
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
  // Live plots over the last two seconds: every step, up to and including this row (a plot never
  // ends on an older value than the lines above show).
  Series force{"f_Ty (N)", {}, kForce}, err{"x error (mm)", {}, kRef};
  for (std::size_t r = liveWindowStart(row, 2.0, s_.step.dt); r <= row; ++r) {
    force.values.push_back(float(tr.at(r, "f_Ty")));
    err.values.push_back(float(1e3 * (tr.at(r, "x_c") - tr.at(r, "x_d"))));
  }
  o.plots = {force, err};
}

}  // namespace dyn::slider_crank
