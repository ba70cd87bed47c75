// Demo scenes for the new primitives, shaped like the planned labs: a 3-D arm drawing a circle
// with a pen on a table, a spoked unicycle wheel on the ground with its track and a reference
// path, a planar two-finger grasp with friction cones and forces, and a spring-damper.
// Used by the primitive tests and written as PNGs by primitives_test (DYNLAB_RENDER_DEMO_DIR).
#pragma once
#include <cmath>
#include <numbers>

#include "labs/scene.h"

namespace dyn::test {

constexpr double kPi = std::numbers::pi;

// Pen-on-table: the table top at z=0, the desired circle and the ink drawn so far.
struct PenDemo {
  Eigen::Vector3d circle_centre{0.05, 0.05, 0.0};
  double circle_radius = 0.15;
  double pen_angle = 1.4 * kPi;                 // how far round the pen has gone
  double lift_from = 0.55 * kPi, lift_to = 0.7 * kPi;  // the pen was lifted in between
  Eigen::Vector3d penTip() const {
    return circle_centre + 0.97 * circle_radius * Eigen::Vector3d(std::cos(pen_angle), std::sin(pen_angle), 0);
  }
};

inline Scene penOnTableScene(const PenDemo& d = {}, double aspect = 4.0 / 3.0) {
  Scene s;
  s.background = {0.93f, 0.94f, 0.96f, 1.0f};
  // Table top (a slab with a 10 cm grid) and four legs.
  s.planes.push_back({{0, 0, 0}, Eigen::Matrix3d::Identity(), {0.45, 0.32}, {0.80f, 0.70f, 0.54f, 1.0f},
                      0.04, 0.1, {0.68f, 0.58f, 0.44f, 1.0f}});
  for (double sx : {-1.0, 1.0})
    for (double sy : {-1.0, 1.0})
      s.boxes.push_back({{sx * 0.4, sy * 0.27, -0.37}, {0.025, 0.025, 0.33}, Eigen::Matrix3d::Identity(),
                         {0.55f, 0.45f, 0.33f, 1.0f}});
  // The desired circle, thin blue, exactly on the table.
  Polyline circle{{}, 2.0, {0.15f, 0.35f, 0.85f, 1.0f}};
  for (int i = 0; i <= 96; ++i) {
    const double a = 2 * kPi * i / 96;
    circle.points.push_back(d.circle_centre + d.circle_radius * Eigen::Vector3d(std::cos(a), std::sin(a), 0));
  }
  s.polylines.push_back(circle);
  // The ink: samples of the pen tip (slightly inside the circle, wobbling), up while lifted.
  std::vector<Eigen::Vector3d> tips;
  std::vector<bool> down;
  for (int i = 0; i <= 200; ++i) {
    const double a = d.pen_angle * i / 200;
    const double r = d.circle_radius * (0.97 + 0.02 * std::sin(5 * a));
    tips.push_back(d.circle_centre + r * Eigen::Vector3d(std::cos(a), std::sin(a), 0));
    down.push_back(a < d.lift_from || a > d.lift_to);
  }
  for (auto& stroke : inkStrokes(tips, down, 3.0, {0.08f, 0.08f, 0.12f, 1.0f})) s.polylines.push_back(stroke);
  // The arm: a base puck, a post to the shoulder, two links to the wrist, and the pen straight down.
  const Color link{0.23f, 0.42f, 0.68f, 1.0f}, joint{0.15f, 0.15f, 0.18f, 1.0f};
  const Eigen::Vector3d base(-0.05, -0.26, 0.0), shoulder = base + Eigen::Vector3d(0, 0, 0.28);
  const Eigen::Vector3d tip = d.penTip(), wrist = tip + Eigen::Vector3d(0, 0, 0.12);
  const double link_len = 0.3;
  const Eigen::Vector3d sw = wrist - shoulder;
  const double half = 0.5 * sw.norm(), rise = std::sqrt(std::max(link_len * link_len - half * half, 0.0));
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitZ().dot(sw.normalized()) * sw.normalized();
  const Eigen::Vector3d elbow = shoulder + 0.5 * sw + rise * up.normalized();
  s.cylinders.push_back({base + Eigen::Vector3d(0, 0, 0.02), Eigen::Matrix3d::Identity(), 0.07, 0.02, joint});
  s.capsules.push_back({base, shoulder, 0.03, link});
  s.capsules.push_back({shoulder, elbow, 0.025, link});
  s.capsules.push_back({elbow, wrist, 0.022, link});
  s.capsules.push_back({wrist, tip + Eigen::Vector3d(0, 0, 0.006), 0.006, {0.1f, 0.1f, 0.1f, 1.0f}});
  for (const auto& p : {shoulder, elbow, wrist}) s.spheres.push_back({p, 0.035, joint});
  // Camera: the table top and the arm, seen from the front right and above.
  s.camera.ortho = false;
  s.camera.up = Eigen::Vector3d::UnitZ();
  s.camera.fov_y_deg = 40;
  s.camera.lookAtBox({-0.45, -0.32, -0.25}, {0.45, 0.32, 0.45}, {0.6, -1.2, 1.0}, aspect, 1.02);
  return s;
}

// The unicycle: a spoked wheel rolling on a gridded ground along its track, near a reference path.
struct WheelDemo {
  double wheel_radius = 0.25;
  double spin = 0.3;     // wheel angle (rad)
  double heading = 0.4;  // rad about z
  Eigen::Vector2d contact{0.3, 0.1};
};

inline Scene wheelScene(const WheelDemo& d = {}, double aspect = 4.0 / 3.0) {
  Scene s;
  s.background = {0.90f, 0.93f, 0.97f, 1.0f};
  s.planes.push_back({{0, 0, 0}, Eigen::Matrix3d::Identity(), {2.5, 2.0}, {0.82f, 0.86f, 0.80f, 1.0f},
                      0.0, 0.25, {0.66f, 0.71f, 0.64f, 1.0f}});
  // The reference path: a gentle S across the ground (green), and the track so far (dark):
  // unicycle kinematics run backwards from the contact, the heading easing from -0.5 to d.heading.
  Polyline ref{{}, 2.5, {0.15f, 0.62f, 0.30f, 1.0f}}, track{{}, 3.0, {0.20f, 0.18f, 0.16f, 1.0f}};
  for (int i = 0; i <= 80; ++i) {
    const double x = -2.0 + 4.0 * i / 80;
    ref.points.push_back({x, 0.3 * std::sin(1.6 * x) + 0.05, 0});
  }
  Eigen::Vector2d p = d.contact;
  for (int i = 0; i <= 60; ++i) {
    track.points.insert(track.points.begin(), Eigen::Vector3d(p.x(), p.y(), 0));
    const double t = double(i) / 60, psi = d.heading + t * (-0.5 - d.heading);
    p -= (1.6 / 60) * Eigen::Vector2d(std::cos(psi), std::sin(psi));
  }
  s.polylines.push_back(ref);
  s.polylines.push_back(track);
  // The wheel stands upright; its axle is horizontal, normal to the heading.
  const Eigen::Vector3d forward(std::cos(d.heading), std::sin(d.heading), 0);
  const Eigen::Vector3d axle = Eigen::Vector3d::UnitZ().cross(forward);
  const Eigen::Vector3d hub(d.contact.x(), d.contact.y(), d.wheel_radius);
  s.cylinders.push_back({hub, axisSpin(axle, d.spin), d.wheel_radius, 0.025, {0.22f, 0.22f, 0.25f, 1.0f}, 6,
                         {0.92f, 0.75f, 0.20f, 1.0f}});
  // Fork and seat.
  const Color frame{0.75f, 0.20f, 0.20f, 1.0f};
  const Eigen::Vector3d seat = hub + Eigen::Vector3d(0, 0, 0.42);
  for (double side : {-1.0, 1.0}) s.capsules.push_back({hub + side * 0.05 * axle, seat - Eigen::Vector3d(0, 0, 0.12) + side * 0.02 * axle, 0.012, frame});
  s.capsules.push_back({seat - Eigen::Vector3d(0, 0, 0.12), seat, 0.016, frame});
  s.boxes.push_back({seat, {0.09, 0.04, 0.015}, Eigen::AngleAxisd(d.heading, Eigen::Vector3d::UnitZ()).toRotationMatrix(),
                     {0.15f, 0.15f, 0.17f, 1.0f}});
  s.camera.ortho = false;
  s.camera.up = Eigen::Vector3d::UnitZ();
  s.camera.fov_y_deg = 40;
  // Frame the track, the wheel and the path ahead; the ground runs on past the frame.
  s.camera.lookAtBox({-1.3, -0.5, 0}, {1.0, 0.6, 0.7}, {0.35, -1.2, 0.7}, aspect, 1.0);
  return s;
}

// A planar two-finger grasp: contact forces (arrows) inside their friction cones, each cone
// coloured from green (force well inside) to red (force at the cone's edge).
struct GraspDemo {
  double mu = 0.5;
  double left_ratio = 0.3, right_ratio = 0.95;  // |f_t| / (mu f_n) at each contact
};

inline Color frictionColor(double ratio) {
  return mix({0.15f, 0.70f, 0.25f, 0.45f}, {0.90f, 0.15f, 0.10f, 0.5f}, (ratio - 0.5) / 0.5);
}

inline Scene graspScene(const GraspDemo& d = {}) {
  Scene s;
  // The object (behind z=0), the fingers reaching it from either side.
  s.boxes.push_back({{0, 0, -0.06}, {0.16, 0.11, 0.05}, Eigen::Matrix3d::Identity(), {0.62f, 0.64f, 0.70f, 1.0f}});
  const Color finger{0.23f, 0.42f, 0.68f, 1.0f};
  for (double side : {-1.0, 1.0}) {
    const Eigen::Vector3d contact(side * 0.16, 0.02, 0.0);
    s.capsules.push_back({contact + Eigen::Vector3d(side * 0.03, 0, -0.02), contact + Eigen::Vector3d(side * 0.3, 0.25, -0.02), 0.03, finger});
    s.spheres.push_back({contact + Eigen::Vector3d(side * 0.03, 0, -0.02), 0.03, finger});
    // Friction cone into the object; the force on the object tilted by ratio * mu.
    const double ratio = side < 0 ? d.left_ratio : d.right_ratio;
    const Eigen::Vector3d inward(-side, 0, 0);
    s.cones.push_back({contact + Eigen::Vector3d(0, 0, 0.05), inward, std::atan(d.mu), 0.13, frictionColor(ratio)});
    const Eigen::Vector3d force = 0.12 * (inward + Eigen::Vector3d(0, ratio * d.mu, 0)).normalized();
    s.arrows.push_back({contact + Eigen::Vector3d(0, 0, 0.05), force, 0.008, {0.1f, 0.1f, 0.1f, 1.0f}});
    s.spheres.push_back({contact + Eigen::Vector3d(0, 0, 0.05), 0.012, {0.1f, 0.1f, 0.1f, 1.0f}});
  }
  // Gravity on the object.
  s.arrows.push_back({{0, 0, 0.05}, {0, -0.2, 0}, 0.008, {0.85f, 0.15f, 0.15f, 1.0f}});
  s.camera.half_width = 0.55;
  s.camera.half_height = 0.4;
  return s;
}

// Impedance: a wall, a spring and a damper side by side to a mass on a rail (planar, ortho).
inline Scene springScene(double x = 0.3) {
  Scene s;
  const Color grey{0.55f, 0.55f, 0.55f, 1.0f};
  s.boxes.push_back({{-0.55, 0, -0.02}, {0.03, 0.22, 0.05}, Eigen::Matrix3d::Identity(), grey});
  s.boxes.push_back({{0, -0.16, -0.04}, {0.6, 0.01, 0.03}, Eigen::Matrix3d::Identity(), grey});
  s.boxes.push_back({{x, 0, 0}, {0.08, 0.12, 0.05}, Eigen::Matrix3d::Identity(), {0.85f, 0.55f, 0.20f, 1.0f}});
  s.springs.push_back({{-0.52, 0.06, 0}, {x - 0.08, 0.06, 0}, 0.035, {0.20f, 0.35f, 0.75f, 1.0f}, 7});
  // A dashpot from cylinders: the body from the wall, the rod to the mass.
  const Eigen::Matrix3d along_x = axisSpin(Eigen::Vector3d::UnitX(), 0);
  const double body_end = -0.52 + 0.55 * (x + 0.44);
  s.cylinders.push_back({{-0.52 + 0.5 * (body_end + 0.52), -0.07, 0}, along_x, 0.03, 0.5 * (body_end + 0.52), {0.3f, 0.3f, 0.33f, 1.0f}});
  s.capsules.push_back({{body_end - 0.08, -0.07, 0}, {x - 0.08, -0.07, 0}, 0.01, {0.75f, 0.75f, 0.78f, 1.0f}});
  s.camera.half_width = 0.65;
  s.camera.half_height = 0.3;
  return s;
}

}  // namespace dyn::test
