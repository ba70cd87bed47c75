// Framing: the scene's box, the free part of the frame beside the panel, and the camera that fits
// one into the other; see framing.h.
#include "render/framing.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>

#include "render/renderer.h"

namespace dyn {
namespace {

using Eigen::AlignedBox3d;
using Eigen::Vector3d;
using Points = std::vector<Vector3d>;

// Adds a ball of radius r around p.
void addBall(AlignedBox3d& box, const Vector3d& p, double r) {
  box.extend(p - Vector3d::Constant(r));
  box.extend(p + Vector3d::Constant(r));
}

// Adds a box with this centre, rotation and half extents (its world-axis-aligned hull).
void addOriented(AlignedBox3d& box, const Vector3d& centre, const Eigen::Matrix3d& rotation, const Vector3d& half) {
  const Vector3d reach = rotation.cwiseAbs() * half;
  box.extend(centre - reach);
  box.extend(centre + reach);
}

// The box's eight corners (none for an empty box).
Points corners(const AlignedBox3d& box) {
  Points c;
  if (box.isEmpty()) return c;
  for (int i = 0; i < 8; ++i)
    c.push_back({(i & 1 ? box.max() : box.min()).x(), (i & 2 ? box.max() : box.min()).y(), (i & 4 ? box.max() : box.min()).z()});
  return c;
}

AlignedBox3d boxOf(const Points& points) {
  AlignedBox3d box;
  for (const Vector3d& p : points) box.extend(p);
  return box;
}

// Half extents of the points about their box's centre along the camera's right and up axes (how big
// they are, seen from there).
Eigen::Vector2d halfExtents(const Camera& camera, const Points& points) {
  const CameraBasis b = camera.basis();
  const Vector3d centre = boxOf(points).center();
  double x = 0, y = 0;
  for (const Vector3d& c : points) {
    x = std::max(x, std::abs((c - centre).dot(b.right)));
    y = std::max(y, std::abs((c - centre).dot(b.up)));
  }
  return {std::max(x, 1e-9), std::max(y, 1e-9)};
}

// Pixels per metre when a box of these half extents fills a rectangle w x h.
double fillScale(const Eigen::Vector2d& half, double w, double h) {
  return std::min(w / (2 * half.x()), h / (2 * half.y()));
}

}  // namespace

AlignedBox3d sceneBounds(const Scene& s) {
  AlignedBox3d box;
  for (const auto& c : s.capsules) addBall(box, c.p0, c.radius), addBall(box, c.p1, c.radius);
  for (const auto& p : s.spheres) addBall(box, p.center, p.radius);
  for (const auto& b : s.boxes) addOriented(box, b.center, b.rotation, b.half_extents);
  // Arrows: the shaft and a head 2.2 radii wide (render/primitives.cpp).
  for (const auto& a : s.arrows) addBall(box, a.origin, 2.2 * a.radius), addBall(box, a.origin + a.vector, 2.2 * a.radius);
  for (const auto& p : s.polylines)
    for (const auto& q : p.points) box.extend(q);
  for (const auto& c : s.cylinders) addOriented(box, c.center, c.rotation, {c.radius, c.radius, c.half_length});
  for (const auto& p : s.planes) {
    // A slab reaches `thickness` below its surface (local -z).
    const Vector3d below = p.center - 0.5 * p.thickness * p.rotation.col(2);
    addOriented(box, below, p.rotation, {p.half_size.x(), p.half_size.y(), 0.5 * p.thickness});
  }
  for (const auto& c : s.cones) {
    const Vector3d axis = c.axis.norm() > 1e-12 ? c.axis.normalized() : Vector3d::UnitZ();
    box.extend(c.apex);
    addBall(box, c.apex + c.length * axis, c.length * std::tan(std::min(c.half_angle, 1.5)));
  }
  for (const auto& sp : s.springs) {
    const double r = sp.radius + (sp.wire_radius > 0 ? sp.wire_radius : sp.radius / 8);
    addBall(box, sp.p0, r), addBall(box, sp.p1, r);
  }
  for (const auto& m : s.meshes)
    if (m.mesh && !m.mesh->box.isEmpty())
      addOriented(box, m.position + m.rotation * m.mesh->box.center(), m.rotation, 0.5 * m.mesh->box.sizes());
  return box;
}

PixelRect projectedBox(const Camera& camera, int width, int height, const AlignedBox3d& box) {
  return projectedPoints(camera, width, height, corners(box));
}

PixelRect projectedPoints(const Camera& camera, int width, int height, const Points& points) {
  if (points.empty()) return {};
  double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
  for (const Vector3d& c : points) {
    const Eigen::Vector2d p = Renderer::project(camera, width, height, c);
    x0 = std::min(x0, p.x()), x1 = std::max(x1, p.x()), y0 = std::min(y0, p.y()), y1 = std::max(y1, p.y());
  }
  return {x0, y0, x1 - x0, y1 - y0};
}

PixelRect freeRect(int width, int height, const PixelRect& panel, const Camera& camera, const AlignedBox3d& box,
                   double gap) {
  return freeRect(width, height, panel, camera, corners(box), gap);
}

PixelRect freeRect(int width, int height, const PixelRect& panel, const Camera& camera, const Points& box, double gap) {
  const PixelRect whole{0, 0, double(width), double(height)};
  if (panel.empty() || !panel.intersects(whole)) return whole;
  // Right of the panel (full height), or below it (full width): the one the box fills the larger.
  const PixelRect right{panel.right() + gap, 0, width - panel.right() - gap, double(height)};
  const PixelRect below{0, panel.bottom() + gap, double(width), height - panel.bottom() - gap};
  if (box.empty()) return right.empty() ? below : right;
  const Eigen::Vector2d half = halfExtents(camera, box);
  const double s_right = right.empty() ? 0 : fillScale(half, right.w, right.h);
  const double s_below = below.empty() ? 0 : fillScale(half, below.w, below.h);
  if (s_right <= 0 && s_below <= 0) return whole;  // a panel as big as the frame: nothing is free
  return s_below > s_right * 1.0001 ? below : right;
}

Camera fitCamera(Camera camera, const AlignedBox3d& box, int width, int height, const PixelRect& free, double margin) {
  return fitCamera(camera, corners(box), width, height, free, margin);
}

Camera fitCamera(Camera camera, const Points& points, int width, int height, const PixelRect& free, double margin) {
  if (points.empty() || free.empty() || width <= 0 || height <= 0) return camera;
  margin = std::max(margin, 1.0);
  const Vector3d view = camera.eye - camera.target;
  const Vector3d dir = view.norm() > 1e-12 ? view.normalized() : Vector3d::UnitZ();
  const AlignedBox3d box = boxOf(points);
  const Vector3d centre = box.center();
  const double extent = std::max(box.diagonal().norm(), 1e-6);
  camera.target = centre;
  camera.eye = centre + dir;
  const CameraBasis b = camera.basis();
  const double cx = free.x + 0.5 * free.w, cy = free.y + 0.5 * free.h;
  if (camera.ortho) {
    // Pixels per metre: the box's larger side (against the rectangle's) fills it, less the margin.
    const double s = fillScale(halfExtents(camera, points), free.w / margin, free.h / margin);
    camera.half_height = 0.5 * height / s;
    camera.half_width = 0;
    // The box's centre at the rectangle's centre: slide the target by the offset, in metres.
    camera.target = centre - b.right * (cx - 0.5 * width) / s - b.up * (0.5 * height - cy) / s;
    camera.eye = camera.target + dir * (extent + 1.0);
    return camera;
  }
  // Perspective: a distance and a sideways slide of the camera (the view direction is kept), found
  // by a few rounds of "scale by the overflow, slide by the offset", so the points' pixel box is
  // centred in the rectangle and just fills it.
  const double tan_y = std::tan(camera.fov_y_deg * std::numbers::pi / 360.0);
  const double tan_x = tan_y * width / height;
  const Points& cs = points;
  auto nearest = [&](const Vector3d& target) {
    double d = 0;
    for (const Vector3d& c : cs) d = std::max(d, 1.05 * (c - target).dot(b.back) + 0.01 * extent);
    return d;  // never at or past the nearest corner
  };
  // Start: the distance at which every corner is inside the rectangle's share of the view.
  const double ty = tan_y * free.h / height / margin, tx = tan_x * free.w / width / margin;
  double distance = nearest(centre);
  for (const Vector3d& c : cs) {
    const Vector3d r = c - centre;
    distance = std::max({distance, r.dot(b.back) + std::abs(r.dot(b.right)) / tx, r.dot(b.back) + std::abs(r.dot(b.up)) / ty});
  }
  Vector3d target = centre;
  for (int round = 0; round < 40; ++round) {
    camera.target = target;
    camera.eye = target + dir * distance;
    const PixelRect p = projectedPoints(camera, width, height, points);
    const double k = std::max(p.w / (free.w / margin), p.h / (free.h / margin));
    const double du = cx - (p.x + 0.5 * p.w), dv = cy - (p.y + 0.5 * p.h);
    if (std::abs(k - 1) < 1e-6 && std::abs(du) < 1e-3 && std::abs(dv) < 1e-3) break;
    // The picture moves against the camera: right by du pixels when the camera slides left.
    target += -b.right * du * distance * tan_x / (0.5 * width) + b.up * dv * distance * tan_y / (0.5 * height);
    distance = std::max(distance * k, nearest(target));
  }
  camera.target = target;
  camera.eye = target + dir * distance;
  return camera;
}

}  // namespace dyn

namespace dyn {

PixelRect insetRect(const PixelRect& free, const Inset& inset) {
  const double gap = std::max(inset.gap, 0.0);
  double h = std::round(std::clamp(inset.height, 0.05, 1.0) * free.h);
  double w = std::round(std::min(h * std::max(inset.aspect, 0.05), 0.5 * free.w));
  h = std::floor(std::min(h, free.h - 2 * gap)), w = std::floor(std::min(w, free.w - 2 * gap));
  if (!(w > 0 && h > 0)) return {};
  const bool right = inset.corner == Inset::Corner::TopRight || inset.corner == Inset::Corner::BottomRight;
  const bool bottom = inset.corner == Inset::Corner::BottomRight || inset.corner == Inset::Corner::BottomLeft;
  const double x = right ? free.right() - gap - w : free.x + gap, y = bottom ? free.bottom() - gap - h : free.y + gap;
  return {std::round(x), std::round(y), w, h};
}

}  // namespace dyn
