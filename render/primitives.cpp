// The scene's primitives as draws of the unit meshes: capsules, spheres, boxes, arrows (a capsule
// and a cone), planes (a quad or a slab, plus grid lines), cylinders with their spoke bars, cones
// and coil springs (a chain of capsules along a helix), and the scene's own triangle meshes.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "render/gl_internal.h"

namespace dyn::gl {
namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

// A rotation whose z axis is `dir` (unit); the other axes are any orthonormal completion.
Matrix3d frameAlong(const Vector3d& dir) {
  const Vector3d helper = std::abs(dir.z()) < 0.9 ? Vector3d::UnitZ() : Vector3d::UnitX();
  const Vector3d x = helper.cross(dir).normalized();
  Matrix3d r;
  r.col(0) = x;
  r.col(1) = dir.cross(x);
  r.col(2) = dir;
  return r;
}

Eigen::Matrix4f affine(const Matrix3d& linear, const Vector3d& translation) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = linear;
  m.topRightCorner<3, 1>() = translation;
  return m.cast<float>();
}

// Builds the draws of one frame; the helpers append to out.items.
class Collector {
 public:
  Collector(const Camera& camera, const Meshes& meshes, int width, int height, DrawList& out)
      : cam_(camera), basis_(camera.basis()), meshes_(meshes), width_(width),
        height_(height), out_(out) {}

  void capsule(const Vector3d& p0, const Vector3d& p1, double r, const Color& color) {
    const Vector3d axis = p1 - p0;
    const double length = axis.norm();
    const Matrix3d rot = length > 1e-12 ? frameAlong(axis / length) : Matrix3d::Identity();
    out_.items.push_back({capsuleMesh(0.5 * (p0 + p1), r), affine(rot * r, p0), rot.cast<float>(),
                          Eigen::Vector3f(0, 0, float(length / r)), color, depthOf(0.5 * (p0 + p1))});
  }

  // A unit mesh scaled by `half` along the axes of `rot`, centred at `centre`.
  void scaled(const Mesh& mesh, const Matrix3d& rot, const Vector3d& half, const Vector3d& centre,
              const Color& color, bool pushed_back = false) {
    const Vector3d h = half.cwiseMax(1e-9);
    out_.items.push_back({&mesh, affine(rot * h.asDiagonal(), centre),
                          (rot * h.cwiseInverse().asDiagonal()).cast<float>(), Eigen::Vector3f::Zero(),
                          color, depthOf(centre), pushed_back});
  }

  void arrow(const Arrow& a) {
    const double length = a.vector.norm();
    if (length < 1e-9 || a.radius <= 0) return;
    const Vector3d dir = a.vector / length;
    // Head: 2.2 radii wide, 5 radii long, at most half the arrow.
    const double head_r = 2.2 * a.radius, head_len = std::min(5.0 * a.radius, 0.5 * length);
    const Vector3d neck = a.origin + dir * (length - head_len);
    capsule(a.origin, neck, a.radius, a.color);
    const Matrix3d rot = frameAlong(dir);
    const Vector3d scale(head_r, head_r, head_len);
    out_.items.push_back({&meshes_.cone, affine(rot * scale.asDiagonal(), neck),
                          (rot * scale.cwiseInverse().asDiagonal()).cast<float>(),
                          Eigen::Vector3f::Zero(), a.color, depthOf(neck)});
  }

  // A quad (or a slab whose top is the plane) pushed back in depth, and its grid as lines.
  void plane(const Plane& p) {
    const Vector3d normal = p.rotation.col(2);
    if (p.thickness > 0)
      scaled(meshes_.box, p.rotation, {p.half_size.x(), p.half_size.y(), 0.5 * p.thickness},
             p.center - 0.5 * p.thickness * normal, p.color, true);
    else
      scaled(meshes_.quad, p.rotation, {p.half_size.x(), p.half_size.y(), 1.0}, p.center, p.color, true);
    if (p.grid <= 0) return;
    // Lines through the centre every `grid` metres, across the whole rectangle (at most 200 a side).
    for (int axis = 0; axis < 2; ++axis) {
      const double half = p.half_size[axis], across = p.half_size[1 - axis];
      const int n = int(std::min(std::floor(half / p.grid + 1e-9), 200.0));
      const Vector3d along = p.rotation.col(axis), side = p.rotation.col(1 - axis);
      for (int k = -n; k <= n; ++k) {
        const Vector3d c = p.center + k * p.grid * along;
        out_.grid_lines.push_back({{c - across * side, c + across * side}, 1.0, p.grid_color});
      }
    }
  }

  // The cylinder, then each spoke as a thin bar on both faces (half inside, half standing out).
  void cylinder(const Cylinder& c) {
    if (c.radius <= 0 || c.half_length < 0) return;
    // The body's facets ignore the spin (any frame along the axis), so a turning wheel's outline
    // stays put; only the spokes turn.
    const Matrix3d& rot = c.rotation;
    const Vector3d axis = rot.col(2).normalized();
    scaled(meshes_.cylinder, frameAlong(axis), {c.radius, c.radius, c.half_length}, c.center, c.color);
    const double bar_half_len = 0.46 * c.radius, bar_half_width = 0.035 * c.radius;
    const double bar_half_depth = std::min(0.03 * c.radius, 0.5 * c.half_length + 0.01 * c.radius);
    for (int k = 0; k < c.spokes; ++k) {
      const double angle = 2 * std::numbers::pi * k / c.spokes;
      const Matrix3d bar_rot = rot * Eigen::AngleAxisd(angle, Vector3d::UnitZ()).toRotationMatrix();
      for (double face : {-1.0, 1.0}) {
        const Vector3d centre = c.center + bar_rot * Vector3d(bar_half_len, 0, face * c.half_length);
        scaled(meshes_.box, bar_rot, {bar_half_len, bar_half_width, bar_half_depth}, centre, c.spoke_color);
      }
    }
  }

  // The unit cone turned so its apex (mesh z=1) is at cone.apex and its base `length` along axis.
  void cone(const Cone& c) {
    const double axis_len = c.axis.norm();
    if (axis_len < 1e-12 || c.length <= 0 || c.half_angle <= 0) return;
    const Vector3d dir = c.axis / axis_len;
    const double r = c.length * std::tan(std::min(c.half_angle, 1.5));
    const Vector3d base = c.apex + c.length * dir;
    const Matrix3d rot = frameAlong(-dir);
    const Vector3d scale(r, r, c.length);
    out_.items.push_back({&meshes_.cone, affine(rot * scale.asDiagonal(), base),
                          (rot * scale.cwiseInverse().asDiagonal()).cast<float>(),
                          Eigen::Vector3f::Zero(), c.color, depthOf(c.apex + 0.6 * c.length * dir)});
  }

  // A scene's triangle mesh (uploaded once, cache), two-sided; its normals turned by the inverse
  // transpose of the placement.
  void mesh(const MeshShape& m, MeshCache& cache) {
    if (!m.mesh || m.mesh->triangles.empty() || m.mesh->box.isEmpty()) return;
    const Matrix3d normal = std::abs(m.rotation.determinant()) > 1e-12 ? Matrix3d(m.rotation.inverse().transpose()) : m.rotation;
    DrawItem item{&cache.get(m.mesh), affine(m.rotation, m.position), normal.cast<float>(), Eigen::Vector3f::Zero(),
                  m.color, depthOf(m.position + m.rotation * m.mesh->box.center())};
    item.two_sided = true;
    out_.items.push_back(item);
  }

  // Lead, radial step onto the helix, `turns` turns (16 capsules each), radial step, lead.
  void spring(const Spring& s) {
    const Vector3d d = s.p1 - s.p0;
    const double length = d.norm();
    if (length < 1e-9 || s.radius <= 0) return;
    const Vector3d dir = d / length;
    const Matrix3d frame = frameAlong(dir);
    const double wire = s.wire_radius > 0 ? s.wire_radius : s.radius / 8;
    const double lead = std::clamp(s.lead, 0.0, 0.45) * length;
    const int turns = std::max(s.turns, 1), steps = 16 * turns;
    auto helix = [&](int i) {
      const double t = double(i) / steps, phase = 2 * std::numbers::pi * turns * t;
      return Vector3d(s.p0 + dir * (lead + t * (length - 2 * lead)) +
                      s.radius * (std::cos(phase) * frame.col(0) + std::sin(phase) * frame.col(1)));
    };
    const Vector3d a = s.p0 + lead * dir, b = s.p1 - lead * dir;
    capsule(s.p0, a, wire, s.color);
    capsule(a, helix(0), wire, s.color);
    for (int i = 0; i < steps; ++i) capsule(helix(i), helix(i + 1), wire, s.color);
    capsule(helix(steps), b, wire, s.color);
    capsule(b, s.p1, wire, s.color);
  }

 private:
  double depthOf(const Vector3d& p) const { return (cam_.eye - p).dot(basis_.back); }

  // Pixels per metre at a point (constant for orthographic cameras).
  double pixelsPerMetre(const Vector3d& p) const {
    if (cam_.ortho) return height_ / (2.0 * cam_.visibleHalfHeight(double(width_) / std::max(height_, 1)));
    const double half_fov = std::tan(cam_.fov_y_deg * M_PI / 360.0);
    return height_ / (2.0 * half_fov * std::max(depthOf(p), 1e-6));
  }

  const Mesh* capsuleMesh(const Vector3d& centre, double r) const {
    const double r_px = r * pixelsPerMetre(centre);
    int level = 0;
    while (r_px > Meshes::kLevelMaxRadiusPx[level]) ++level;
    return &meshes_.capsules[level];
  }

  const Camera& cam_;
  CameraBasis basis_;
  const Meshes& meshes_;
  int width_, height_;
  DrawList& out_;
};

}  // namespace

void Meshes::create() {
  const int slices[kLevels] = {10, 16, 28, 48};
  for (int i = 0; i < kLevels; ++i) capsules[i] = makeCapsule(slices[i], slices[i] / 4 + 1);
  cone = makeCone(40);
  box = makeBox();
  cylinder = makeCylinder(64);
  quad = makeQuad();
}

void Meshes::destroy() {
  for (auto& mesh : capsules) mesh.destroy();
  for (Mesh* mesh : {&cone, &box, &cylinder, &quad}) mesh->destroy();
}

void collectDrawList(const Scene& scene, const Camera& camera, const Meshes& meshes, MeshCache& cache, int width,
                     int height, DrawList& out) {
  out.items.clear();
  out.grid_lines.clear();
  Collector add(camera, meshes, width, height, out);
  for (const auto& c : scene.capsules)
    if (c.radius > 0) add.capsule(c.p0, c.p1, c.radius, c.color);
  for (const auto& s : scene.spheres)
    if (s.radius > 0) add.capsule(s.center, s.center, s.radius, s.color);
  for (const auto& b : scene.boxes) add.scaled(meshes.box, b.rotation, b.half_extents, b.center, b.color);
  for (const auto& a : scene.arrows) add.arrow(a);
  for (const auto& p : scene.planes) add.plane(p);
  for (const auto& c : scene.cylinders) add.cylinder(c);
  for (const auto& c : scene.cones) add.cone(c);
  for (const auto& s : scene.springs) add.spring(s);
  for (const auto& m : scene.meshes) add.mesh(m, cache);
}

}  // namespace dyn::gl
