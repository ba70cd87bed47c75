// A loaded model as a picture: see model_scene.h.
#include "labs/model_scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "labs/run_bounds.h"
#include "physics/det/det.h"

namespace dyn {
namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Box3 = Eigen::AlignedBox3d;
using Shape = model_file::Geom::Shape;

// Bodies whose file keeps MuJoCo's default grey get the labs' link colours, neighbours told apart.
const Color kPalette[4] = {{0.23f, 0.42f, 0.68f, 1.0f}, {0.20f, 0.58f, 0.55f, 1.0f}, {0.52f, 0.42f, 0.72f, 1.0f}, {0.80f, 0.52f, 0.25f, 1.0f}};
const Color kWorld{0.60f, 0.60f, 0.60f, 1.0f}, kJoint{0.15f, 0.15f, 0.18f, 1.0f}, kClosure{0.90f, 0.45f, 0.10f, 1.0f};
const Color kGhost{0.55f, 0.35f, 0.75f, 0.35f}, kFloor{0.86f, 0.86f, 0.84f, 1.0f}, kPedestal{0.40f, 0.42f, 0.47f, 1.0f};

Color colorOf(const model_file::Geom& g) {
  if (g.file_color) return {g.rgba[0], g.rgba[1], g.rgba[2], g.rgba[3]};
  return g.link < 0 ? kWorld : kPalette[g.link % 4];
}

// A round step near x: 1, 2 or 5 × 10^k.
double niceStep(double x) {
  const double p = det::pow(10.0, std::floor(det::log10(std::max(x, 1e-9))));
  const double f = x / p;
  return (f < 1.5 ? 1 : f < 3.5 ? 2 : f < 7.5 ? 5 : 10) * p;
}

void extend(Box3& box, const Vec3& p, double r) {
  box.extend(p - Vec3::Constant(r));
  box.extend(p + Vec3::Constant(r));
}

// The box a shape occupies (its oriented extents' world box).
void extendShape(Box3& box, const Vec3& c, const Mat3& R, const model_file::Geom& g) {
  Vec3 half;
  switch (g.shape) {
    case Shape::Sphere: half = Vec3::Constant(g.size[0]); break;
    case Shape::Capsule: half = {g.size[0], g.size[0], g.size[1] + g.size[0]}; break;
    case Shape::Cylinder: half = {g.size[0], g.size[0], g.size[1]}; break;
    case Shape::Mesh:  // its vertices' box, which need not be centred on the geom's origin
      half = 0.5 * g.mesh->box.sizes();
      box.extend(c + R * g.mesh->box.center() - R.cwiseAbs() * half);
      box.extend(c + R * g.mesh->box.center() + R.cwiseAbs() * half);
      return;
    default: half = g.size; break;
  }
  const Vec3 world = R.cwiseAbs() * half;
  box.extend(c - world);
  box.extend(c + world);
}

}  // namespace

ModelPicture::ModelPicture(const model_file::LoadedModel& model) : model_(model), data_(model.mechanism.tree) {
  const auto& tree = model.mechanism.tree;
  for (const auto& j : model.joints)
    if (j.type == "free") {
      base_qpos_ = j.qpos;
      break;
    }
  // Up against gravity (world z without it).
  const Vec3 g = tree.gravity.tail<3>();
  up_ = g.norm() > 1e-9 ? Vec3(-g.normalized()) : Vec3::UnitZ();
  // Planar: every hinge about one axis, every slide across it (frames are world-aligned at q0).
  bool found = false;
  planar_ = true;
  for (const auto& b : tree.bodies)
    if (b.joint == JointType::Revolute) {
      const Vec3 a = b.axis.normalized();
      if (!found) axis_ = a, found = true;
      else if (a.cross(axis_).norm() > 1e-9) planar_ = false;
    }
  for (const auto& b : tree.bodies)
    if (b.joint == JointType::Prismatic && std::abs(b.axis.normalized().dot(axis_)) > 1e-9) planar_ = false;
  planar_ = planar_ && found;
  // Sizes of the marks: from the rods the file draws, else from the mechanism's size.
  std::vector<double> radii;
  for (const auto& geom : model.drawing.geoms)
    if (geom.shape == Shape::Capsule || geom.shape == Shape::Cylinder) radii.push_back(geom.size[0]);
  Box3 box;
  for (const Vec3& p : anchors(model.q0)) box.extend(p);
  place(model.q0);
  for (const auto& geom : model.drawing.geoms)
    if (geom.shape != Shape::Plane && geom.link >= 0) box.extend(point(geom.link, geom.pos));
  for (const auto& b : model.drawing.bones) box.extend(point(b.link, b.to));
  const double extent = std::max(box.isEmpty() ? 0.0 : box.diagonal().norm(), 0.05);
  std::sort(radii.begin(), radii.end());
  const double rod = radii.empty() ? 0.02 * extent : radii[radii.size() / 2];
  rod_radius_ = std::clamp(rod, 0.004 * extent, 0.03 * extent);
  joint_radius_ = std::max(1.4 * rod_radius_, 0.015 * extent);
  keepShapePoints();
}

bool ModelPicture::groundPivot(std::size_t i) const {
  const auto& b = model_.mechanism.tree.bodies[i];
  return b.parent < 0 && b.joint == JointType::Revolute;
}

// A free joint's three slides carry its body from the world's origin: their frames are no joints the
// robot has (left behind as it falls), so no ball marks them.
bool ModelPicture::marked(std::size_t i) const {
  return !(i < model_.joints.size() && model_.joints[i].type == "free" && model_.mechanism.tree.bodies[i].joint == JointType::Prismatic);
}

void ModelPicture::place(const VecN& q) const { worldKinematics(model_.mechanism.tree, q, data_); }

Vec3 ModelPicture::point(int link, const Vec3& p) const {
  return link < 0 ? p : Vec3(Spatial::worldPoint(data_.X_world[std::size_t(link)], p));
}

Mat3 ModelPicture::rotation(int link) const {
  return link < 0 ? Mat3::Identity() : Mat3(data_.X_world[std::size_t(link)].E.transpose());
}

std::vector<Vec3> ModelPicture::anchors(const VecN& q) const {
  place(q);
  std::vector<Vec3> out;
  for (std::size_t i = 0; i < data_.X_world.size(); ++i) out.push_back(data_.X_world[i].r);
  return out;
}

Box3 ModelPicture::bounds(const VecN& q) const {
  Box3 box, fixed;
  const std::vector<Vec3> at = anchors(q);  // (placed the frames at q)
  for (std::size_t i = 0; i < at.size(); ++i)
    if (marked(i)) extend(box, at[i], joint_radius_);
  for (const auto& g : model_.drawing.geoms)
    if (g.shape != Shape::Plane) extendShape(g.link < 0 ? fixed : box, point(g.link, g.pos), rotation(g.link) * g.rot, g);
  for (const auto& b : model_.drawing.bones) extend(box, point(b.link, b.to), rod_radius_);
  // The ground mounts (drawBodies), whatever the view: a ball of their reach under each world joint.
  if (planar_)
    for (std::size_t i = 0; i < data_.X_world.size(); ++i)
      if (groundPivot(i)) extend(box, data_.X_world[i].r, 3.2 * joint_radius_);
  // What the world holds counts unless it dwarfs the mechanism (a table 100 m wide): then the
  // mechanism is framed and the rest drawn around it.
  if (!fixed.isEmpty() && (box.isEmpty() || fixed.diagonal().norm() <= 3 * box.diagonal().norm())) box.extend(fixed);
  return box;
}

void ModelPicture::drawBodies(bool ghost, Scene& s) const {
  // The ghost sits a little behind the mechanism when seen side-on, and its meshes always: where the
  // engines agree, a robot shows its own colours, not the ghost's over them.
  const Vec3 behind = -(s.camera.eye - s.camera.target).normalized() * 3 * joint_radius_;
  const Vec3 back = ghost && planar_ ? behind : Vec3::Zero();
  for (const auto& g : model_.drawing.geoms) {
    if (g.shape == Shape::Plane || (ghost && g.link < 0)) continue;
    const Vec3 c = point(g.link, g.pos) + (ghost && g.shape == Shape::Mesh ? behind : back);
    const Mat3 R = rotation(g.link) * g.rot;
    const Color color = ghost ? kGhost : colorOf(g);
    switch (g.shape) {
      case Shape::Sphere: s.spheres.push_back({c, g.size[0], color}); break;
      case Shape::Capsule: s.capsules.push_back({c - g.size[1] * R.col(2), c + g.size[1] * R.col(2), g.size[0], color}); break;
      case Shape::Cylinder: s.cylinders.push_back({c, R, g.size[0], g.size[1], color}); break;
      case Shape::Mesh: s.meshes.push_back({g.mesh, c, R, color}); break;
      default: s.boxes.push_back({c, g.size, R, color}); break;
    }
  }
  for (const auto& b : model_.drawing.bones)
    s.capsules.push_back({point(b.link, b.from) + back, point(b.link, b.to) + back, rod_radius_, ghost ? kGhost : kPalette[b.link % 4]});
  if (ghost) return;
  // Side-on, a ground mount under each hinge on the world (as the planar labs draw theirs), behind
  // the links.
  if (planar_) {
    const CameraBasis view = s.camera.basis();
    Mat3 R;
    R << view.right, view.up, view.back;
    const double r = joint_radius_;
    for (std::size_t i = 0; i < data_.X_world.size(); ++i)
      if (groundPivot(i))
        s.boxes.push_back({data_.X_world[i].r - 1.2 * r * view.up - 1.2 * r * view.back, Vec3(1.7 * r, 0.9 * r, 0.5 * r), R, kWorld});
  }
  for (std::size_t i = 0; i < data_.X_world.size(); ++i)
    if (marked(i)) s.spheres.push_back({data_.X_world[i].r, joint_radius_, kJoint});
  for (const auto& c : model_.closures) s.spheres.push_back({point(c.link1, c.point1), 0.85 * joint_radius_, kClosure});
}

Vec3 ModelPicture::base(const VecN& q) const { return follows() ? Vec3(q.segment<3>(base_qpos_)) : Vec3(Vec3::Zero()); }

void ModelPicture::scene(const VecN& q, const VecN* ghost, const Box3& frame, Scene& s, const std::vector<Vec3>& points) const {
  const Box3 box = frame.isEmpty() ? bounds(q) : follows() ? frame.translated(base(q)) : frame;
  // The camera's direction; the renderer fits the box beside the panel (Scene::framing).
  if (planar_) {
    Vec3 up = up_ - up_.dot(axis_) * axis_;
    if (up.norm() < 1e-6) up = std::abs(axis_.z()) < 0.9 ? Vec3::UnitZ() : Vec3::UnitY();
    up.normalize();
    // Look along the axis from the side that puts world x (else y) to the right.
    Vec3 back = axis_;
    const Vec3 right = up.cross(back);
    const double sense = std::abs(right.x()) > 1e-6 ? right.x() : right.y();
    if (sense < 0) back = -back;
    s.camera.ortho = true;
    s.camera.up = up;
    s.camera.target = box.isEmpty() ? Vec3(Vec3::Zero()) : Vec3(box.center());
    s.camera.eye = s.camera.target + 5 * back;
  } else {
    Vec3 h = Vec3::UnitX() - up_.x() * up_;
    if (h.norm() < 0.1) h = Vec3::UnitY() - up_.y() * up_;
    h.normalize();
    const Vec3 side = up_.cross(h);
    s.camera.ortho = false;
    s.camera.fov_y_deg = 35;
    s.camera.up = up_;
    s.camera.target = box.isEmpty() ? Vec3(Vec3::Zero()) : Vec3(box.center());
    // From the front and a little above, the box's longer level side across the picture (an arm
    // reaching along x is seen from −y, one reaching along y from +x), so the arm, not the box's
    // depth, fills the width.
    const Vec3 d = box.isEmpty() ? Vec3(Vec3::Zero()) : Vec3(box.diagonal());
    const bool along_h = std::abs(d.dot(h)) >= std::abs(d.dot(side));
    s.camera.eye = s.camera.target + (along_h ? Vec3(0.5 * h - 1.2 * side) : Vec3(1.2 * h - 0.5 * side)) + 0.55 * up_;
  }
  s.framing.fit = true;
  s.framing.bounds = box;
  s.framing.points = points;
  if (follows() && !frame.isEmpty())
    for (Vec3& p : s.framing.points) p += base(q);
  // Floors: under the framed box, about as large as it, slabs so a side-on view shows their edge.
  const double reach = box.isEmpty() ? 1.0 : 0.75 * box.diagonal().norm();
  for (const auto& g : model_.drawing.geoms) {
    if (g.shape != Shape::Plane) continue;
    const Mat3 R = rotation(g.link) * g.rot;
    const Vec3 p = point(g.link, g.pos), n = R.col(2), c = box.isEmpty() ? p : Vec3(box.center());
    Eigen::Vector2d half(g.size[0] > 0 ? std::min(g.size[0], reach) : reach, g.size[1] > 0 ? std::min(g.size[1], reach) : reach);
    Color color = g.file_color ? Color{g.rgba[0], g.rgba[1], g.rgba[2], g.rgba[3]} : kFloor;
    s.planes.push_back({c - n.dot(c - p) * n, R, half, color, 0.02 * reach, niceStep(reach / 4)});
  }
  if (ghost) {
    place(*ghost);
    drawBodies(true, s);
  }
  place(q);
  drawBodies(false, s);
}

void ModelPicture::stage(Scene& s) const {
  Box3& box = s.framing.bounds;
  if (planar_ || box.isEmpty()) return;
  for (const auto& g : model_.drawing.geoms)
    if (g.shape == Shape::Plane) return;
  const auto& bodies = model_.mechanism.tree.bodies;
  // The floor: level (normal up), a tenth of the box's size below its lowest corner, as wide as its footprint.
  const double size = box.diagonal().norm();
  double low = 1e300;
  for (int k = 0; k < 8; ++k) low = std::min(low, up_.dot(box.corner(Box3::CornerType(k))));
  const double floor = low - 0.05 * size;
  const Mat3 R = axisSpin(up_, 0);
  const Vec3 centre = box.center() + (floor - up_.dot(box.center())) * up_;
  Eigen::Vector2d half = Eigen::Vector2d::Zero();
  for (int k = 0; k < 8; ++k) {
    const Vec3 d = R.transpose() * (box.corner(Box3::CornerType(k)) - centre);
    half = half.cwiseMax(d.head<2>().cwiseAbs());
  }
  // The box's footprint, framed with it (as the pen lab's floor).
  s.planes.push_back({centre, R, half, kFloor, 0.02 * size, niceStep(0.25 * half.maxCoeff())});
  for (const double sx : {-1.0, 1.0})
    for (const double sy : {-1.0, 1.0})
      for (const double dz : {0.0, -0.02 * size}) box.extend(centre + R * Vec3(sx * half.x(), sy * half.y(), dz));
  // A pedestal (a column) from the floor up to each joint on the world.
  for (std::size_t i = 0; i < bodies.size(); ++i) {
    if (bodies[i].parent >= 0) continue;
    const Vec3 top = data_.X_world[i].r;
    const double height = up_.dot(top) - floor, radius = 2.5 * joint_radius_;
    if (height <= 0) continue;
    s.cylinders.push_back({top - 0.5 * height * up_, R, radius, 0.5 * height, kPedestal});
    box.extend(top - height * up_ - Vec3::Constant(radius));
    box.extend(top + Vec3::Constant(radius));
    if (!s.framing.points.empty())
      for (const double z : {0.0, -height})
        for (int k = 0; k < 16; ++k) {  // the column's ends, as rings of 16 round its circle
          const double a = 2 * std::numbers::pi * k / 16, r = radius / det::cos(std::numbers::pi / 16);
          s.framing.points.push_back(top + z * up_ + r * (det::cos(a) * R.col(0) + det::sin(a) * R.col(1)));
        }
  }
}

VecN traceQ(const Trace& trace, std::size_t row, int n) {
  VecN q(n);
  for (int i = 0; i < n; ++i) q[i] = trace.at(row, 1 + i);
  return q;
}

Box3 runBounds(const ModelPicture& picture, int n, const Trace& trace, const Trace* ghost) {
  Box3 box;
  forBoundsRows(trace, ghost, [&](const Trace& run, std::size_t r) {
    const VecN q = traceQ(run, r, n);
    box.extend(picture.follows() ? picture.bounds(q).translated(-picture.base(q)) : picture.bounds(q));
  });
  return box;
}

void modelOverlay(const std::string& title, const std::string& engines, const Trace& tr, std::size_t row, double dt, const Trace* ghost, Overlay& o) {
  auto fmt = [](const char* f, double x) {
    char b[48];
    std::snprintf(b, sizeof b, f, x);
    return std::string(b);
  };
  const double e0 = tr.at(0, "energy");
  auto balance = [&](std::size_t r) { return tr.at(r, "energy") - e0 - tr.at(r, "work"); };
  o.title = title;
  o.lines = {{"engine", engines},
             {"t", fmt("%.3f s", tr.at(row, "t"))},
             {"energy E", fmt("%.5f J", tr.at(row, "energy"))},
             {"E − E0 − W", fmt("%.2e J", balance(row))},
             {"closure |φ|", fmt("%.1e", tr.at(row, "constraint_residual"))}};
  if (ghost && row < ghost->rows()) o.lines.push_back({"Bullet |phi|", fmt("%.1e", ghost->at(row, "constraint_residual"))});
  // Live plots over the last two seconds, up to and including this row.
  Series e{"E − E0 − W (mJ)", {}, {0.23f, 0.42f, 0.68f, 1.0f}}, phi{"log₁₀ |φ|", {}, {0.90f, 0.45f, 0.10f, 1.0f}};
  for (std::size_t r = liveWindowStart(row, 2.0, dt); r <= row; ++r) {
    e.values.push_back(float(1e3 * balance(r)));
    phi.values.push_back(float(det::log10(std::max(tr.at(r, "constraint_residual"), 1e-17))));
  }
  o.plots = {e, phi};
}

}  // namespace dyn
