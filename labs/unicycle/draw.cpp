// What the unicycle lab shows: a camera that follows the wheel, in perspective from behind, right
// and above its heading, over the floor with a grid: the reference path, the leader's point, the wheel (a disk with
// spokes, so its spin shows) and its track so far, the lateral ground force as an arrow (red once it
// asks for more than μ f_n), Bullet's friction-contact wheel as a translucent ghost with its own track
// (it slides where the no-slip wheel would need more friction than there is); a map of the whole
// course from above in a corner (an Inset: the path, both tracks, the wheel, the leader and the part
// the camera shows); and the overlay with speed and lateral force.
#include <algorithm>
#include <cmath>

#include "labs/numbers.h"
#include "labs/unicycle/lab.h"
#include "physics/det/det.h"

namespace dyn::unicycle {
namespace {

const Color kWheel{0.23f, 0.42f, 0.68f, 1.0f}, kTrack{0.15f, 0.15f, 0.18f, 1.0f}, kRef{0.20f, 0.65f, 0.30f, 1.0f};
const Color kForce{0.85f, 0.45f, 0.10f, 1.0f}, kSkid{0.90f, 0.10f, 0.10f, 1.0f}, kGhost{0.55f, 0.35f, 0.75f, 0.40f};
const Color kGround{0.90f, 0.90f, 0.86f, 1.0f}, kLeader{0.80f, 0.10f, 0.55f, 0.75f};  // not the path's green; the wheel shows through

Eigen::Vector3d on(double x, double y, double z = 0) { return {x, y, z}; }

// A wheel at (x, y) heading φ, spun by θ: its axle is the horizontal (−sin φ, cos φ).
void drawWheel(double r, double x, double y, double phi, double theta, Color c, Scene& s) {
  const Eigen::Vector3d axle(-det::sin(phi), det::cos(phi), 0);
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
  const std::size_t stride = std::max<std::size_t>(1, tr.rows() / 400);
  // The course's box (the path, where the wheels went, and the wheel's height): the map holds it.
  Eigen::AlignedBox3d box;
  for (const auto& p : path_.polyline()) box.extend(on(p.x(), p.y()));
  for (const Trace* t : {&tr, ghost})
    if (t)
      for (std::size_t k = 0; k < t->rows(); k += stride) {
        box.extend(on(t->at(k, "x"), t->at(k, "y")));
        box.extend(on(t->at(k, "x_fric"), t->at(k, "y_fric")));
      }
  // A margin of floor round the course (the ground is drawn exactly this big).
  box.extend(box.min() - Eigen::Vector3d(r + 0.15, r + 0.15, 0));
  box.extend(box.max() + Eigen::Vector3d(r + 0.15, r + 0.15, 2 * r));

  // The follow camera: a disk of floor round the wheel, its radius `half` as far as the leader is
  // ever from it (plus room for the wheel), 3.5 to 10 wheel radii: the same all run, so the wheel
  // keeps its size on screen and the leader stays in the picture.
  double lead = 0;
  for (std::size_t k = 0; k < tr.rows(); k += stride)
    lead = std::max(lead, det::hypot(tr.at(k, "x_d") - tr.at(k, "x"), tr.at(k, "y_d") - tr.at(k, "y")));
  const double half = std::clamp(lead + 2 * r, 3.5 * r, 10 * r);
  const double x = tr.at(row, "x"), y = tr.at(row, "y"), phi = tr.at(row, "phi");
  // Seen from behind and to the right of the leader's heading φ_d (smooth, unlike the wheel's own
  // when it wobbles): the wheel's face, the lateral force along its axle and the leader ahead of it
  // all show whichever way the course turns; the map keeps the course's fixed orientation.
  const double psi = tr.at(row, "phi_d");
  const Eigen::Vector3d heading(det::cos(psi), det::sin(psi), 0), left(-det::sin(psi), det::cos(psi), 0);
  const Eigen::Vector3d from = -0.75 * heading - 0.65 * left + Eigen::Vector3d(0, 0, 0.7);
  // The framed box is axis-aligned: seen along a diagonal it looks √2 wider than square on, so
  // it shrinks as the view turns off the axes and the wheel keeps its size (a disk of radius half
  // round the wheel always shows).
  const double diagonal = std::abs(from.x()) + std::abs(from.y()), square = det::hypot(from.x(), from.y());
  const double side = half * std::sqrt(2.0) * square / diagonal;
  const Eigen::AlignedBox3d view(on(x - side, y - side), on(x + side, y + side, 2 * r));
  s.framePerspective(view, from);
  s.framing.clip = true;  // the floor runs on beyond the view: cut it at the free part's edge

  // Ground, path, leader.
  const Eigen::Vector3d size = box.sizes();
  const Plane ground{on(box.center().x(), box.center().y()), Eigen::Matrix3d::Identity(),
                     {0.5 * size.x(), 0.5 * size.y()}, kGround, 0.0, 0.25};
  // The camera sees beyond its square near the course's edge: floor that far round it, too (the
  // same centre, so the grid lines stay where they are on the map).
  Plane floor = ground;
  floor.half_size += Eigen::Vector2d::Constant(6 * half + 0.5);
  s.planes.push_back(floor);
  Polyline ref{{}, 3.0, kRef};
  for (const auto& p : path_.polyline()) ref.points.push_back(on(p.x(), p.y()));
  s.polylines.push_back(ref);
  // The leader: a ball of 0.6 wheel radii standing on the path (translucent: the wheel starts on it).
  const double x_d = tr.at(row, "x_d"), y_d = tr.at(row, "y_d");
  s.spheres.push_back({on(x_d, y_d, 0.6 * r), 0.6 * r, kLeader});

  // Bullet's friction wheel, translucent, and its track.
  const Color ghost_track{0.55f, 0.35f, 0.75f, 1.0f};
  if (ghost && row < ghost->rows()) {
    s.polylines.push_back(track(*ghost, row, "x_fric", "y_fric", ghost_track, 2.0));
    drawWheel(r, ghost->at(row, "x_fric"), ghost->at(row, "y_fric"), ghost->at(row, "phi_fric"), ghost->at(row, "theta"), kGhost, s);
  }
  // The wheel and its track.
  s.polylines.push_back(track(tr, row, "x", "y", kTrack, 3.0));
  drawWheel(r, x, y, phi, tr.at(row, "theta"), kWheel, s);
  // The lateral ground force at the contact, along the axle.
  const double f_lat = tr.at(row, "f_lat");
  if (std::abs(f_lat) > 1e-9) {
    const Eigen::Vector3d axle(-det::sin(phi), det::cos(phi), 0);
    s.arrows.push_back({on(x, y, 0.01), axle * (f_lat * s_.arrow_scale), 0.012, tr.at(row, "skid_margin") < 0 ? kSkid : kForce});
  }

  // The map: the whole course from above, the wheel and the leader as dots big enough to find,
  // the ghost's track, and the square the camera follows.
  Inset map;
  map.corner = Inset::Corner::TopRight;
  map.aspect = std::clamp(size.x() / std::max(size.y(), 1e-9), 0.6, 1.6);
  Scene& m = map.scene;
  m.background = kGround;
  m.camera.ortho = true;
  m.camera.up = {0, 1, 0};
  m.camera.target = box.center();
  m.camera.eye = box.center() + Eigen::Vector3d(0, 0, 1);
  m.framing.fit = true;
  m.framing.bounds = Eigen::AlignedBox3d(on(box.min().x(), box.min().y()), on(box.max().x(), box.max().y()));
  m.framing.margin = 1.02;
  m.planes.push_back(ground);
  m.polylines.push_back(ref);
  m.polylines.back().width_px = 2.0;
  if (ghost && row < ghost->rows()) m.polylines.push_back(track(*ghost, row, "x_fric", "y_fric", ghost_track, 1.5));
  m.polylines.push_back(track(tr, row, "x", "y", kTrack, 1.5));
  Polyline window{{on(x - side, y - side), on(x + side, y - side), on(x + side, y + side), on(x - side, y + side), on(x - side, y - side)}, 1.5, kWheel};
  m.polylines.push_back(window);
  const double dot = std::max(r, 0.025 * std::max(size.x(), size.y()));
  m.spheres.push_back({on(x_d, y_d, 0.3), 0.8 * dot, {kLeader.r, kLeader.g, kLeader.b, 1.0f}});
  m.spheres.push_back({on(x, y, 0.4), dot, kWheel});
  s.insets.push_back(std::move(map));
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
             {"f_lat", fmt("%.2f N", tr.at(row, "f_lat")) + fmt(" (μmg = %.2f N)", mu_mg)},
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
