// What the grasp lab shows: the finger bases, the fingers, the object and its reference outline, each
// contact's friction cone (green inside, turning red as |f_t| nears μ f_n) with the force the finger
// applies, the Bullet run as a translucent ghost, and the live overlay with the cone margins.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "labs/grasp/lab.h"
#include "labs/numbers.h"
#include "labs/run_bounds.h"
#include "physics/det/rotation.h"

namespace dyn::grasp {
namespace {

const Color kLink{0.23f, 0.42f, 0.68f, 1.0f}, kJoint{0.15f, 0.15f, 0.18f, 1.0f}, kBase{0.55f, 0.55f, 0.55f, 1.0f};
const Color kObject{0.85f, 0.55f, 0.20f, 1.0f}, kRef{0.20f, 0.65f, 0.30f, 1.0f}, kForce{0.85f, 0.15f, 0.15f, 1.0f};
const Color kInside{0.20f, 0.70f, 0.30f, 0.35f}, kEdge{0.90f, 0.15f, 0.10f, 0.45f};
const Color kGhost{0.55f, 0.35f, 0.75f, 0.35f};
constexpr double kConeLength = 0.035;  // m, the drawn friction cones

Eigen::Vector3d at(const Eigen::Vector2d& p, double z = 0) { return {p.x(), p.y(), z}; }

Eigen::Matrix3d rotZ(double a) { return det::rotationZ(a); }

VecN stateAt(const Trace& tr, std::size_t r, int m) {
  VecN q(2 * m + 3);
  for (int j = 0; j < 2 * m; ++j) q[j] = tr.at(r, "q" + std::to_string(j + 1));
  q.tail(3) << tr.at(r, "psi_o"), tr.at(r, "x_o"), tr.at(r, "y_o");
  return q;
}

void drawFingers(const Mechanism& mech, const VecN& q, Color link, Color joint, double z, Scene& s) {
  for (int i = 0; i < mech.fingers(); ++i) {
    const auto p = mech.fingerPoints(i, q);
    for (int j = 0; j < 2; ++j) s.capsules.push_back({at(p[std::size_t(j)], z), at(p[std::size_t(j) + 1], z), 0.006, link});
    for (int j = 0; j < 3; ++j) s.spheres.push_back({at(p[std::size_t(j)], z + 0.004), j == 2 ? 0.006 : 0.008, joint});
  }
}

void drawObject(const Object& o, const Eigen::Vector3d& pose, Color c, double z, Scene& s) {
  s.boxes.push_back({at(pose.tail<2>(), z), {0.5 * o.size.x(), 0.5 * o.size.y(), 0.012}, rotZ(pose[0]), c});
}

// The space the mechanism moves through over the run (the rows so far, both engines), as drawn: the
// bases, every finger point (with its joint's radius), the object's corners and its contacts' cones.
Eigen::AlignedBox3d runBounds(const Mechanism& mech, const Trace& tr, const Trace* ghost, const Params& p) {
  Eigen::AlignedBox3d box;
  const Eigen::Vector3d pad(0.009, 0.009, 0.0);
  for (const Finger& f : p.fingers) box.extend(at(f.base) - Eigen::Vector3d(0.014, 0.022, 0)), box.extend(at(f.base) + Eigen::Vector3d(0.014, 0, 0));
  const Eigen::Vector2d h = 0.5 * p.object.size;
  forBoundsRows(tr, ghost, [&](const Trace& run, std::size_t r) {
    const VecN q = stateAt(run, r, mech.fingers());
    const Eigen::Vector3d pose = q.tail(3);
    const Eigen::Matrix2d R = rotZ(pose[0]).topLeftCorner<2, 2>();
    for (int i = 0; i < mech.fingers(); ++i) {
      for (const auto& pt : mech.fingerPoints(i, q)) box.extend(at(pt) - pad), box.extend(at(pt) + pad);
      // The cone's far rim: L (n ± μ t) from the contact.
      const Eigen::Vector2d c = mech.contactPoint(i, pose), n = mech.contactNormal(i, pose[0]);
      const Eigen::Vector2d t(-n.y(), n.x());
      for (const double sgn : {-1.0, 1.0}) box.extend(at(c + kConeLength * (n + sgn * p.mu * t)));
    }
    for (const double sx : {-1.0, 1.0})
      for (const double sy : {-1.0, 1.0}) box.extend(at(pose.tail<2>() + R * Eigen::Vector2d(sx * h.x(), sy * h.y())));
  });
  return box;
}

}  // namespace

void GraspLab::scene(const Trace& tr, std::size_t row, const Trace* ghost, Scene& s) const {
  const Mechanism mech(s_.params);
  const int m = fingers();
  // Side-on, orthographic; the renderer fits the run's space (bases, fingers, object, cones) into the
  // frame beside the panel (Scene::framing), so the camera holds still from frame to frame.
  s.camera.ortho = true;
  s.camera.eye = {0, 0, 5};
  s.camera.target = {0, 0, 0};
  s.framing.fit = true;
  s.framing.bounds = runBounds(mech, tr, ghost && row < ghost->rows() ? ghost : nullptr, s_.params);

  // Bases on the ground.
  for (const Finger& f : s_.params.fingers) s.boxes.push_back({at(f.base - Eigen::Vector2d(0, 0.012), -0.01), {0.014, 0.01, 0.012}, Eigen::Matrix3d::Identity(), kBase});
  // The Bullet ghost at the same time, behind.
  if (ghost && row < ghost->rows()) {
    const VecN qg = stateAt(*ghost, row, m);
    drawFingers(mech, qg, kGhost, kGhost, -0.04, s);
    drawObject(s_.params.object, qg.tail(3), kGhost, -0.04, s);
  }
  // The reference pose as an outline.
  const Eigen::Vector3d pose_d(tr.at(row, "psi_d"), tr.at(row, "x_d"), tr.at(row, "y_d"));
  Polyline outline{{}, 2.0, kRef};
  const Eigen::Vector2d h = 0.5 * s_.params.object.size;
  for (const auto& c : {Eigen::Vector2d(-h.x(), -h.y()), Eigen::Vector2d(h.x(), -h.y()), Eigen::Vector2d(h.x(), h.y()),
                        Eigen::Vector2d(-h.x(), h.y()), Eigen::Vector2d(-h.x(), -h.y())})
    outline.points.push_back(at(pose_d.tail<2>() + (rotZ(pose_d[0]).topLeftCorner<2, 2>() * c), 0.03));
  s.polylines.push_back(std::move(outline));
  // The fingers and the object.
  const VecN q = stateAt(tr, row, m);
  const Eigen::Vector3d pose = q.tail(3);
  drawFingers(mech, q, kLink, kJoint, 0.0, s);
  drawObject(s_.params.object, pose, kObject, 0.0, s);
  // Each contact: its friction cone outside the object (the forces a fingertip may push with lie in
  // it, seen from the finger), coloured by how much of μ f_n the tangential force uses, and the force.
  const double mu = s_.params.mu;
  for (int i = 0; i < m; ++i) {
    const std::string f = "f" + std::to_string(i + 1);
    const Eigen::Vector2d p = mech.contactPoint(i, pose);
    const Eigen::Vector2d n = mech.contactNormal(i, pose[0]);
    const double f_n = tr.at(row, f + "_n"), f_t = tr.at(row, f + "_t");
    const double used = f_n > 0 ? std::abs(f_t) / (mu * f_n) : 1.0;
    s.cones.push_back({at(p, 0.02), at(n), det::atan(mu), kConeLength, mix(kInside, kEdge, (used - 0.5) / 0.5)});
    const Eigen::Vector2d force(tr.at(row, f + "_x"), tr.at(row, f + "_y"));
    if (force.norm() > 1e-9) {
      const Eigen::Vector2d v = force * s_.arrow_scale;
      s.arrows.push_back({at(p - v, 0.03), at(v), 0.0025, kForce});
    }
  }
}

void GraspLab::overlay(const Trace& tr, std::size_t row, Overlay& o) const {
  const auto& c = s_.controller;
  o.title = "multi-finger grasp";
  const char* kind = c.kind == ControllerKind::None ? "none (passive)" : c.kind == ControllerKind::Constant ? "constant torques" : "grasp";
  o.lines = {{"t", fmt("%.3f s", tr.at(row, "t"))},
             {"controller", kind},
             {"kp, kd", fmt("%.0f", c.gains.kp_pos) + ", " + fmt("%.1f", c.gains.kd_pos)},
             {"f_sq, ki", fmt("%.2f N", c.gains.f_squeeze) + ", " + fmt("%.1f", c.gains.ki_int)},
             {"x, y error", fmt("%.1f", 1e3 * (tr.at(row, "x_o") - tr.at(row, "x_d"))) + ", " +
                                fmt("%.1f mm", 1e3 * (tr.at(row, "y_o") - tr.at(row, "y_d")))},
             {"f_int", fmt("%.2f N", tr.at(row, "f_int"))},
             {"cone margin", fmt("%.2f N", tr.at(row, "cone_margin")) + fmt(" (μ = %.2f)", s_.params.mu)}};
  // Live plots over the last two seconds: every step, up to and including this row.
  Series margin{"cone margin (N)", {}, kRef}, squeeze{"f_int (N)", {}, kForce};
  for (std::size_t r = liveWindowStart(row, 2.0, s_.step.dt); r <= row; ++r) {
    margin.values.push_back(float(tr.at(r, "cone_margin")));
    squeeze.values.push_back(float(tr.at(r, "f_int")));
  }
  o.plots = {margin, squeeze};
}

}  // namespace dyn::grasp
