// What the pen-on-table lab shows, in perspective from in front of the arm and above the table: the
// table (a slab with a 5 cm grid), the reference circle (green), the ink the pen left where it touched
// (gaps where it lifted off), the arm (column, upper arm, forearm ending in the pen), the commanded
// point (x_d, y_d, z_des) as a small green ball, the table's push on the pen (red arrow, η = −f_z), and
// the Bullet run as a translucent ghost arm; the overlay plots f_z against f_zd, and z_des.
#include <algorithm>
#include <cmath>

#include "labs/numbers.h"
#include "labs/pen_on_table/lab.h"
#include "physics/det/det.h"

namespace dyn::pen_on_table {
namespace {

const Color kColumn{0.35f, 0.38f, 0.45f, 1.0f}, kArm{0.23f, 0.42f, 0.68f, 1.0f}, kPen{0.95f, 0.75f, 0.15f, 1.0f};
const Color kJoint{0.15f, 0.15f, 0.18f, 1.0f}, kRef{0.20f, 0.65f, 0.30f, 1.0f}, kInk{0.10f, 0.10f, 0.45f, 1.0f};
const Color kForce{0.85f, 0.15f, 0.10f, 1.0f}, kTable{0.86f, 0.78f, 0.64f, 1.0f}, kGhost{0.55f, 0.35f, 0.75f, 0.35f};
const Color kFloor{0.90f, 0.90f, 0.88f, 1.0f};

// The arm's joints and tip at θ: base, shoulder, elbow, the ball's centre (the closed form of mechanism.h).
struct Pose {
  Eigen::Vector3d base, shoulder, elbow, centre;
};

Pose pose(const Params& p, double q1, double q2, double q3) {
  const Eigen::Vector3d out(det::cos(q1), det::sin(q1), 0);
  auto along = [&](double pitch) { return Eigen::Vector3d(det::cos(pitch) * out + Eigen::Vector3d(0, 0, -det::sin(pitch))); };
  Pose a;
  a.base = Eigen::Vector3d::Zero();
  a.shoulder = Eigen::Vector3d(0, 0, p.links[0].length);
  a.elbow = a.shoulder + p.links[1].length * along(q2);
  a.centre = a.elbow + p.links[2].length * along(q2 + q3);
  return a;
}

// The arm at a trace row; the last 40 % of the forearm is the pen.
void drawArm(const Params& p, const Trace& tr, std::size_t row, bool ghost, Scene& s) {
  const Pose a = pose(p, tr.at(row, "q1"), tr.at(row, "q2"), tr.at(row, "q3"));
  const auto tone = [&](Color c) { return ghost ? kGhost : c; };
  const double r1 = p.links[0].radius, r2 = p.links[1].radius, r3 = p.links[2].radius;
  s.cylinders.push_back({0.5 * (a.base + a.shoulder), Eigen::Matrix3d::Identity(), r1, 0.5 * p.links[0].length, tone(kColumn)});
  s.spheres.push_back({a.shoulder, 1.2 * r2, tone(kJoint)});
  s.capsules.push_back({a.shoulder, a.elbow, r2, tone(kArm)});
  s.spheres.push_back({a.elbow, 1.2 * r3, tone(kJoint)});
  const Eigen::Vector3d pen = a.elbow + 0.6 * (a.centre - a.elbow);
  s.capsules.push_back({a.elbow, pen, r3, tone(kArm)});
  s.capsules.push_back({pen, a.centre, std::max(0.5 * r3, p.tip_radius), tone(kPen)});
  s.spheres.push_back({a.centre, std::max(p.tip_radius, 0.002), tone(kJoint)});
}

}  // namespace

void PenOnTableLab::scene(const Trace& tr, std::size_t row, const Trace* ghost, Scene& s) const {
  const Params& p = s_.params;
  const double z_t = p.table_height, r = s_.circle.radius;
  const Eigen::Vector3d c(s_.circle.centre.x(), s_.circle.centre.y(), z_t);
  // The table: a block from the floor (z = 0) up to z_t round the circle, with a 5 cm grid on its top.
  const double half = std::max(2.0 * r, 0.12);
  const Eigen::Vector3d table_centre = c + Eigen::Vector3d(-0.25 * half, 0, 0);
  const Eigen::Vector2d table_half(1.25 * half, 1.5 * half);
  const double floor_z = std::min(0.0, z_t - 0.05);
  s.planes.push_back({table_centre, Eigen::Matrix3d::Identity(), table_half, kTable, z_t - floor_z, 0.05, {0.70f, 0.62f, 0.50f, 1.0f}});
  // What the camera holds: the table block, the column, and where the arm went over the run (both runs).
  Eigen::AlignedBox3d box;
  box.extend(table_centre + Eigen::Vector3d(-table_half.x(), -table_half.y(), floor_z - z_t));
  box.extend(table_centre + Eigen::Vector3d(table_half.x(), table_half.y(), 0));
  box.extend(Eigen::Vector3d(-p.links[0].radius, -p.links[0].radius, floor_z));
  for (const Trace* t : {&tr, ghost})
    if (t)
      for (std::size_t k = 0; k < t->rows(); k += std::max<std::size_t>(1, t->rows() / 200)) {
        const Pose a = pose(p, t->at(k, "q1"), t->at(k, "q2"), t->at(k, "q3"));
        for (const Eigen::Vector3d& x : {a.shoulder, a.elbow, a.centre}) {
          box.extend(x + Eigen::Vector3d::Constant(p.links[1].radius));
          box.extend(x - Eigen::Vector3d::Constant(p.links[1].radius));
        }
      }
  // The floor the column stands on: exactly the box's footprint (so it is framed too).
  s.planes.push_back({Eigen::Vector3d(box.center().x(), box.center().y(), floor_z), Eigen::Matrix3d::Identity(),
                      0.5 * box.sizes().head<2>(), kFloor, 0.0, 0.1});
  s.framePerspective(box, Eigen::Vector3d(0.9, -1.1, 0.6));

  // The reference circle on the table.
  Polyline circle{{}, 1.5, kRef};
  for (int k = 0; k <= 96; ++k) {
    const double a = 2 * M_PI * k / 96;
    circle.points.push_back(c + r * Eigen::Vector3d(det::cos(a), det::sin(a), 0));
  }
  s.polylines.push_back(std::move(circle));
  // The ink: the tip's path while it touched the table, up to this row.
  std::vector<Eigen::Vector3d> points;
  std::vector<bool> down;
  const std::size_t stride = std::max<std::size_t>(1, tr.rows() / 3000);
  for (std::size_t k = 0; k <= row; k += stride) {
    points.emplace_back(tr.at(k, "x_p"), tr.at(k, "y_p"), z_t);
    down.push_back(tr.at(k, "contact") > 0.5);
  }
  for (auto& stroke : inkStrokes(points, down, 3.0, kInk)) s.polylines.push_back(std::move(stroke));

  // The arms: Bullet's as a ghost, the hand run's solid; the commanded point.
  if (ghost && row < ghost->rows()) drawArm(p, *ghost, row, true, s);
  drawArm(p, tr, row, false, s);
  s.spheres.push_back({Eigen::Vector3d(tr.at(row, "x_d"), tr.at(row, "y_d"), tr.at(row, "z_des")), 0.006, kRef});
  // The force the pen applies to the table, f_z ẑ (the lecture's sign: down while pressing), ending on
  // the table beside the tip (3 cm to the camera's right, so the pen does not hide it); its 5 ms mean,
  // so a touchdown's impulse shows as P / 5 ms whatever the step.
  const double f_z = tr.at(row, "f_z_5ms");
  if (f_z < -1e-9) {
    const Eigen::Vector3d beside = Eigen::Vector3d(tr.at(row, "x_p"), tr.at(row, "y_p"), z_t) + 0.03 * Eigen::Vector3d(1.1, 0.9, 0).normalized();
    s.arrows.push_back({beside - Eigen::Vector3d(0, 0, f_z * s_.arrow_scale), Eigen::Vector3d(0, 0, f_z * s_.arrow_scale), 0.003, kForce});
  }
}

void PenOnTableLab::overlay(const Trace& tr, std::size_t row, Overlay& o) const {
  const auto& c = s_.controller;
  o.title = "pen on table";
  const char* kind = c.kind == ControllerKind::None         ? "none (passive)"
                     : c.kind == ControllerKind::Constant   ? "constant torques"
                     : c.law == ForceLaw::Damper            ? "accommodation, damper"
                                                            : "accommodation, spring";
  o.lines = {{"t", fmt("%.2f s", tr.at(row, "t"))},
             {"controller", kind},
             {"f_z (5 ms)", fmt("%.2f N", tr.at(row, "f_z_5ms")) + fmt(" (f_zd %.2f N)", c.f_zd)},
             {"f_meas", fmt("%.2f N", tr.at(row, "f_meas"))},
             {"z_des − z_t", fmt("%.2f mm", 1e3 * (tr.at(row, "z_des") - s_.params.table_height))},
             {"contact", tr.at(row, "contact") > 0.5 ? "yes" : "no (lifted)"}};
  // Live plots over the last three seconds, every step up to this row: f_z (5 ms mean), its error from f_zd (the
  // plot's zero line is the set point), and the commanded height above the table.
  Series force{"f_z, 5 ms mean (N)", {}, kForce}, error{"f_z − f_zd (N)", {}, kRef}, height{"z_des − z_t (mm)", {}, kArm};
  for (std::size_t r = liveWindowStart(row, 3.0, s_.step.dt); r <= row; ++r) {
    force.values.push_back(float(tr.at(r, "f_z_5ms")));
    error.values.push_back(float(tr.at(r, "f_z_5ms") - tr.at(r, "f_zd")));
    height.values.push_back(float(1e3 * (tr.at(r, "z_des") - s_.params.table_height)));
  }
  o.plots = {force, error, height};
}

}  // namespace dyn::pen_on_table
