// What the unicycle lab shows, in perspective from behind and above the course: the ground with a
// grid, the reference path, the leader's point, the wheel (a disk with spokes, so its spin shows)
// and its track so far, the lateral ground force as an arrow (red once it asks for more than μ f_n),
// Bullet's friction-contact wheel as a translucent ghost with its own track (it slides where the
// no-slip wheel would need more friction than there is), and the overlay with speed and lateral force.
#include <algorithm>
#include <cmath>

#include "labs/numbers.h"
#include "labs/unicycle/lab.h"

namespace dyn::unicycle {
namespace {

const Color kWheel{0.23f, 0.42f, 0.68f, 1.0f}, kTrack{0.15f, 0.15f, 0.18f, 1.0f}, kRef{0.20f, 0.65f, 0.30f, 1.0f};
const Color kForce{0.85f, 0.45f, 0.10f, 1.0f}, kSkid{0.90f, 0.10f, 0.10f, 1.0f}, kGhost{0.55f, 0.35f, 0.75f, 0.40f};
const Color kGround{0.90f, 0.90f, 0.86f, 1.0f}, kLeader{0.80f, 0.10f, 0.55f, 0.75f};  // not the path's green; the wheel shows through

Eigen::Vector3d on(double x, double y, double z = 0) { return {x, y, z}; }

// A wheel at (x, y) heading φ, spun by θ: its axle is the horizontal (−sin φ, cos φ).
void drawWheel(double r, double x, double y, double phi, double theta, Color c, Scene& s) {
  const Eigen::Vector3d axle(-std::sin(phi), std::cos(phi), 0);
  s.cylinders.push_back({on(x, y, r), axisSpin(axle, -theta), r, 0.12 * r, c, 6, {0.1f, 0.1f, 0.12f, c.a}});
}

Polyline track(const Trace& tr, std::size_t row, const char* xc, const char* yc, Color c, double width) {
  Polyline p{{}, width, c};
  const std::size_t stride = std::max<std::size_t>(1, tr.rows() / 1500);
  for (std::size_t r = 0; r <= row; r += stride) p.points.push_back(on(tr.at(r, xc), tr.at(r, yc)));
  p.points.push_back(on(tr.at(row, xc), tr.at(row, yc)));
  return p;
}

}  // namespace

void UnicycleLab::scene(const Trace& tr, std::size_t row, const Trace* ghost, Scene& s) const {
  const double r = s_.params.radius;
  // The course's box (the path, where the wheels went, and the wheel's height): the camera holds it.
  Eigen::AlignedBox3d box;
  for (const auto& p : path_.polyline()) box.extend(on(p.x(), p.y()));
  for (const Trace* t : {&tr, ghost})
    if (t)
      for (std::size_t k = 0; k < t->rows(); k += std::max<std::size_t>(1, t->rows() / 400)) {
        box.extend(on(t->at(k, "x"), t->at(k, "y")));
        box.extend(on(t->at(k, "x_fric"), t->at(k, "y_fric")));
      }
  // A margin of floor round the course (the ground is drawn exactly this big, so it is framed too).
  box.extend(box.min() - Eigen::Vector3d(r + 0.15, r + 0.15, 0));
  box.extend(box.max() + Eigen::Vector3d(r + 0.15, r + 0.15, 2 * r));
  // Seen steeply from the front: the course keeps most of its shape, so it fills a tall free area
  // (right of the panel) as well as a wide one, and the wheel is drawn larger.
  s.framePerspective(box, Eigen::Vector3d(0, -0.4, 1.0));

  // Ground, path, leader.
  const Eigen::Vector3d size = box.sizes();
  s.planes.push_back({on(box.center().x(), box.center().y()), Eigen::Matrix3d::Identity(),
                      {0.5 * size.x(), 0.5 * size.y()}, kGround, 0.0, 0.25});
  Polyline ref{{}, 2.0, kRef};
  for (const auto& p : path_.polyline()) ref.points.push_back(on(p.x(), p.y()));
  s.polylines.push_back(std::move(ref));
  // The leader: a ball of 0.6 wheel radii standing on the path (translucent: the wheel starts on it).
  s.spheres.push_back({on(tr.at(row, "x_d"), tr.at(row, "y_d"), 0.6 * r), 0.6 * r, kLeader});

  // Bullet's friction wheel, translucent, and its track.
  if (ghost && row < ghost->rows()) {
    s.polylines.push_back(track(*ghost, row, "x_fric", "y_fric", {0.55f, 0.35f, 0.75f, 1.0f}, 1.5));
    drawWheel(r, ghost->at(row, "x_fric"), ghost->at(row, "y_fric"), ghost->at(row, "phi_fric"), ghost->at(row, "theta"), kGhost, s);
  }
  // The wheel and its track.
  s.polylines.push_back(track(tr, row, "x", "y", kTrack, 2.5));
  const double x = tr.at(row, "x"), y = tr.at(row, "y"), phi = tr.at(row, "phi");
  drawWheel(r, x, y, phi, tr.at(row, "theta"), kWheel, s);
  // The lateral ground force at the contact, along the axle.
  const double f_lat = tr.at(row, "f_lat");
  if (std::abs(f_lat) > 1e-9) {
    const Eigen::Vector3d axle(-std::sin(phi), std::cos(phi), 0);
    s.arrows.push_back({on(x, y, 0.01), axle * (f_lat * s_.arrow_scale), 0.012, tr.at(row, "skid_margin") < 0 ? kSkid : kForce});
  }
}

void UnicycleLab::overlay(const Trace& tr, std::size_t row, Overlay& o) const {
  const auto& c = s_.controller;
  const double mu_mg = s_.params.mu * s_.params.mass * s_.params.gravity;
  o.title = "rolling unicycle";
  const char* kind = c.kind == ControllerKind::None ? "none (passive)" : c.kind == ControllerKind::Constant ? "constant torques" : "path";
  o.lines = {{"t", fmt("%.2f s", tr.at(row, "t"))},
             {"controller", kind},
             {"speed", fmt("%.2f", tr.at(row, "speed")) + fmt(" m/s (ref %.2f)", tr.at(row, "v_d"))},
             {"cross-track", fmt("%.1f mm", 1e3 * tr.at(row, "cross_track"))},
             {"f_lat", fmt("%.2f N", tr.at(row, "f_lat")) + fmt(" (mu m g = %.2f N)", mu_mg)},
             {"skid margin", fmt("%.2f N", tr.at(row, "skid_margin"))}};
  // Live plots over the last four seconds: every step, up to and including this row.
  Series speed{"speed (m/s)", {}, kWheel}, lateral{"f_lat (N)", {}, kForce};
  for (std::size_t r = liveWindowStart(row, 4.0, s_.step.dt); r <= row; ++r) {
    speed.values.push_back(float(tr.at(r, "speed")));
    lateral.values.push_back(float(tr.at(r, "f_lat")));
  }
  o.plots = {speed, lateral};
}

}  // namespace dyn::unicycle
