// Scene: what a lab wants drawn, as plain data in world coordinates (metres, z out of the
// plane for planar labs). Labs fill it from their state; render/ turns it into pixels.
// No GL here, so labs never depend on the renderer.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "physics/det/det.h"
#include "physics/triangle_mesh.h"

namespace dyn {

// RGBA in [0, 1]; alpha < 1 draws translucent (the Bullet ghost).
struct Color {
  float r = 0.8f, g = 0.8f, b = 0.8f, a = 1.0f;
};

// A rounded rod from p0 to p1 (links).
struct Capsule {
  Eigen::Vector3d p0, p1;
  double radius;
  Color color;
};

// A ball (joints, point masses).
struct Sphere {
  Eigen::Vector3d center;
  double radius;
  Color color;
};

// An oriented box (slider, rail, table); rotation maps box axes to world axes.
struct Box {
  Eigen::Vector3d center;
  Eigen::Vector3d half_extents;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Color color;
};

// A force arrow: from origin along vector (already scaled to metres by the lab).
struct Arrow {
  Eigen::Vector3d origin, vector;
  double radius;
  Color color;
};

// A polyline (trajectories, reference paths, ink), width_px wide on screen. Points may lie exactly
// on a Plane: planes are drawn pushed back in depth, so a path or ink on a table shows without
// lifting it; where lines overlap at the same depth, the later one is on top. An ink trail with
// pen lifts is one Polyline per stroke (see inkStrokes below).
struct Polyline {
  std::vector<Eigen::Vector3d> points;
  double width_px = 2.0;
  Color color;
};

// A solid cylinder (wheel, disk, axle, puck); a disk is a short one. rotation maps the cylinder's
// axes to world axes: local z is the axis (faces at +-half_length), local x the first spoke.
// spokes > 0 draws that many bars, evenly spaced, on both faces from the centre to near the rim, so
// a spinning wheel shows its rotation (see axisSpin below to build rotation from axis and angle).
struct Cylinder {
  Eigen::Vector3d center;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  double radius, half_length;
  Color color;
  int spokes = 0;
  Color spoke_color{0.15f, 0.15f, 0.18f, 1.0f};
};

// A finite rectangle (ground, table top): rotation maps its axes to world axes (local z is the
// normal, local x/y span half_size). thickness > 0 makes it a slab that deep below the surface
// (a table top). grid > 0 draws lines every `grid` metres, through the centre, in grid_color.
// Planes are pushed back in depth, so polylines (paths, ink) lying on them are always visible.
struct Plane {
  Eigen::Vector3d center;
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector2d half_size;
  Color color;
  double thickness = 0.0;
  double grid = 0.0;
  Color grid_color{0.55f, 0.55f, 0.55f, 1.0f};
};

// A cone opening from apex along axis (direction, any length) to `length` metres, capped at the
// far end: friction cones (apex at the contact, half_angle = atan(mu)); usually translucent
// (color.a < 1). Seen side-on, as in a planar scene, it reads as a 2-D wedge.
struct Cone {
  Eigen::Vector3d apex, axis;
  double half_angle;  // radians
  double length;      // metres along the axis
  Color color;
};

// A coil spring glyph from p0 to p1: `turns` turns of a helix of `radius`, drawn with a wire of
// wire_radius; the first and last `lead` (a fraction of the length) are straight, on the axis.
struct Spring {
  Eigen::Vector3d p0, p1;
  double radius;
  Color color;
  int turns = 8;
  double wire_radius = 0.0;  // 0: radius / 8
  double lead = 0.1;         // fraction of the length that is straight at each end
};

// A triangle mesh (a model file's mesh geom) placed in the world: rotation maps the mesh's axes to world
// axes, position is where its origin goes. Drawn two-sided, lit as smooth surfaces broken at sharp
// edges; the renderer uploads each mesh once (by the shared pointer) however many frames show it.
struct MeshShape {
  std::shared_ptr<const TriangleMesh> mesh;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Color color;
};

// The camera's orthonormal frame: right, up, and back (from the target towards the eye).
struct CameraBasis {
  Eigen::Vector3d right, up, back;
};

// The camera: looks from eye at target; orthographic when ortho, showing at least half_height
// metres above and below the target and, when half_width > 0, at least half_width either side:
// the frame's aspect decides which one binds, so one scene frames well at 4:3 and at 16:9.
struct Camera {
  Eigen::Vector3d eye{0, 0, 5}, target{0, 0, 0}, up{0, 1, 0};
  bool ortho = true;
  double half_height = 1.0;  // ortho: half the visible height in metres (at least)
  double half_width = 0.0;   // ortho: half the visible width in metres (at least); 0: no demand
  double fov_y_deg = 45.0;   // perspective only
  // Ortho: the half height actually shown in a frame of this aspect (width / height).
  double visibleHalfHeight(double aspect) const { return std::max(half_height, half_width / aspect); }
  // The view frame; `up` only picks the roll (a world axis stands in when it is along the view).
  CameraBasis basis() const;
  // Looks at the axis-aligned box [lo, hi] from direction `from` (target towards eye, any length)
  // and fits it in a frame of this aspect (width / height) with margin (1.1: 10 % spare): moves
  // the eye (perspective) or sets half_width/half_height (ortho). Keeps up, fov_y_deg and ortho.
  void lookAtBox(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, const Eigen::Vector3d& from,
                 double aspect, double margin = 1.1);
};

// How a frame is laid out. With fit, the renderer places the camera itself, so no lab lays out
// a frame by hand: it keeps the camera's view direction (eye − target), up and projection (ortho,
// or fov_y_deg), and fits `bounds` (empty: the box of every primitive, render/framing.h) into the
// part of the frame the overlay panel leaves free (the whole frame without a panel), with `margin`
// spare (1.08: 4 % on each side). A lab sets bounds to the space its mechanism moves through over
// the run, so the camera holds still from frame to frame.
// clip: the scene is cut at the edge of the part of the frame it is fitted into, so a camera that
// follows something across a large floor (Inset below shows the whole of it) never draws under the
// panel; without it, what lies outside bounds may spill over the rest of the frame.
// points: when given, what is fitted is these points' picture (the shapes' own extents over the run,
// a model picture's mesh vertices) rather than the picture of bounds' eight corners, which seen at
// an angle is larger than what it holds; bounds still places the camera's target and floor.
struct Framing {
  bool fit = false;
  Eigen::AlignedBox3d bounds;  // default-constructed: empty
  double margin = 1.08;
  bool clip = false;
  std::vector<Eigen::Vector3d> points;
};

struct Inset;

// Everything a frame shows. Opaque things are drawn first, then polylines, then everything with
// alpha < 1 (back to front, each translucent shape blended once over what is behind it).
struct Scene {
  std::vector<Capsule> capsules;
  std::vector<Sphere> spheres;
  std::vector<Box> boxes;
  std::vector<Arrow> arrows;
  std::vector<Polyline> polylines;
  Camera camera;
  Color background{0.96f, 0.96f, 0.94f, 1.0f};
  std::vector<Cylinder> cylinders;
  std::vector<Plane> planes;
  std::vector<Cone> cones;
  std::vector<Spring> springs;
  Framing framing;  // fit: the renderer chooses the camera (see Framing)
  std::vector<Inset> insets;  // second views drawn over a corner of this one (see Inset)
  std::vector<MeshShape> meshes;  // drawn after the other shapes

  // A spatial lab's view: perspective, z up, looking at box from its centre + `from`, and the
  // renderer fitting box in the frame (Framing).
  void framePerspective(const Eigen::AlignedBox3d& box, const Eigen::Vector3d& from, double fov_y_deg = 35) {
    camera.ortho = false;
    camera.fov_y_deg = fov_y_deg;
    camera.up = {0, 0, 1};
    camera.target = box.center();
    camera.eye = box.center() + from;
    framing.fit = true;
    framing.bounds = box;
  }
};

// A second view over a corner of the frame: a map of the whole course beside a camera that follows
// the wheel, or a magnified close-up. Its scene (own primitives, camera, background; its framing
// fits it into the inset, its own insets are ignored) is drawn in a rectangle `height` of the free
// part of the frame high (the part the main scene was fitted into: never under the panel) and
// `aspect` times as wide (at most half the free width), `gap` pixels in from that part's `corner`,
// inside a border of `border_px` in border colour.
struct Inset {
  enum class Corner { TopRight, BottomRight, BottomLeft, TopLeft };
  Scene scene;
  Corner corner = Corner::BottomRight;
  double height = 0.35;  // fraction of the free part's height
  double aspect = 1.0;   // width / height
  double gap = 6.0;      // pixels from the free part's edges
  double border_px = 2.0;
  Color border{0.35f, 0.35f, 0.38f, 1.0f};
};

// ---- Pure helpers for labs (no GL) ----------------------------------------------------------

// Linear blend a -> b by t in [0, 1] (e.g. a friction cone from green to red as |f_t| nears mu f_n).
inline Color mix(const Color& a, const Color& b, double t) {
  const float u = float(std::clamp(t, 0.0, 1.0));
  return {a.r + u * (b.r - a.r), a.g + u * (b.g - a.g), a.b + u * (b.b - a.b), a.a + u * (b.a - a.a)};
}

// A rotation whose z axis is `axis` (normalised) and whose x axis is turned by `spin` radians
// (right-handed about the axis) from a reference: world z projected onto the plane normal to the
// axis ("up" for an upright wheel), or world x when the axis is within ~1 degree of world z (a
// planar scene's disk). For Cylinder::rotation: axisSpin(axle, wheel_angle).
inline Eigen::Matrix3d axisSpin(const Eigen::Vector3d& axis, double spin) {
  const Eigen::Vector3d z = axis.norm() > 1e-12 ? axis.normalized() : Eigen::Vector3d::UnitZ();
  Eigen::Vector3d ref = Eigen::Vector3d::UnitZ() - z.z() * z;
  if (ref.norm() < 0.02) ref = Eigen::Vector3d::UnitX() - z.x() * z;
  const Eigen::Vector3d x0 = ref.normalized(), y0 = z.cross(x0);
  Eigen::Matrix3d r;
  r.col(0) = det::cos(spin) * x0 + det::sin(spin) * y0;
  r.col(1) = z.cross(r.col(0));
  r.col(2) = z;
  return r;
}

// An ink trail from pen-tip samples: one Polyline per run of samples with down[i] (pen on the
// paper); single-sample runs are dropped. Append the result to Scene::polylines.
inline std::vector<Polyline> inkStrokes(const std::vector<Eigen::Vector3d>& points,
                                        const std::vector<bool>& down, double width_px, Color color) {
  std::vector<Polyline> strokes;
  Polyline stroke{{}, width_px, color};
  auto flush = [&] {
    if (stroke.points.size() > 1) strokes.push_back(stroke);
    stroke.points.clear();
  };
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (i < down.size() && down[i]) stroke.points.push_back(points[i]);
    else flush();
  }
  flush();
  return strokes;
}

inline CameraBasis Camera::basis() const {
  Eigen::Vector3d back = eye - target;
  back = back.norm() > 1e-12 ? back.normalized() : Eigen::Vector3d::UnitZ();
  Eigen::Vector3d right = up.cross(back);
  if (right.norm() < 1e-9) right = Eigen::Vector3d::UnitY().cross(back);  // up parallel to view
  if (right.norm() < 1e-9) right = Eigen::Vector3d::UnitX();
  right.normalize();
  return {right, back.cross(right), back};
}

inline void Camera::lookAtBox(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi,
                              const Eigen::Vector3d& from, double aspect, double margin) {
  const Eigen::Vector3d dir = from.norm() > 1e-12 ? from.normalized() : Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  const double extent = std::max((hi - lo).norm(), 1e-6);
  std::array<Eigen::Vector3d, 8> corners;
  for (int i = 0; i < 8; ++i)
    corners[i] = {(i & 1 ? hi : lo).x(), (i & 2 ? hi : lo).y(), (i & 4 ? hi : lo).z()};
  target = centre;
  eye = target + dir;
  const CameraBasis b = basis();
  margin = std::max(margin, 1.0);
  if (ortho) {
    // The box is symmetric about its centre, so the centre stays the target.
    double x = 0, y = 0;
    for (const auto& c : corners) {
      x = std::max(x, std::abs((c - centre).dot(b.right)));
      y = std::max(y, std::abs((c - centre).dot(b.up)));
    }
    half_width = margin * x;
    half_height = margin * y;
    eye = target + dir * (extent + 1.0);
    return;
  }
  // Perspective: the distance at which every corner is inside both half-angles (tan_x, tan_y),
  // then the target slides so the corners' picture is centred; a few rounds settle it.
  const double tan_y = det::tan(fov_y_deg * std::numbers::pi / 360.0) / margin, tan_x = tan_y * aspect;
  auto fitDistance = [&] {
    double d = 0;
    for (const auto& c : corners) {
      const Eigen::Vector3d r = c - target;
      const double z = r.dot(b.back);
      d = std::max({d, z + std::abs(r.dot(b.right)) / tan_x, z + std::abs(r.dot(b.up)) / tan_y,
                    1.05 * z + 0.01 * extent});  // never at or past the nearest corner
    }
    return d;
  };
  double distance = fitDistance();
  for (int round = 0; round < 3; ++round) {
    double u_lo = 1e300, u_hi = -1e300, v_lo = 1e300, v_hi = -1e300;
    for (const auto& c : corners) {
      const Eigen::Vector3d r = c - target;
      const double depth = distance - r.dot(b.back);
      const double u = r.dot(b.right) / (depth * tan_x), v = r.dot(b.up) / (depth * tan_y);
      u_lo = std::min(u_lo, u), u_hi = std::max(u_hi, u), v_lo = std::min(v_lo, v), v_hi = std::max(v_hi, v);
    }
    target += distance * (0.5 * (u_lo + u_hi) * tan_x * b.right + 0.5 * (v_lo + v_hi) * tan_y * b.up);
    distance = fitDistance();
  }
  eye = target + dir * distance;
}

// A time series for the overlay's live plot.
struct Series {
  std::string name;
  std::vector<float> values;  // oldest first
  Color color;
};

// The first trace row of a live plot that shows the last `seconds` up to and including `row`
// (steps of dt): the plot then runs over rows [liveWindowStart(...), row].
inline std::size_t liveWindowStart(std::size_t row, double seconds, double dt) {
  const std::size_t window = std::size_t(std::lround(seconds / dt));
  return row > window ? row - window : 0;
}

// The overlay panel (Dear ImGui): a title, label/value lines and live plots.
struct Overlay {
  std::string title;
  std::vector<std::pair<std::string, std::string>> lines;
  std::vector<Series> plots;
};

}  // namespace dyn
