// What a model file draws (model_file.h Drawing): its geoms at qpos0, each on the tree body it moves
// with. Spheres, capsules, cylinders, boxes and meshes (the triangles MuJoCo decoded, each mesh read
// once and shared by the geoms that draw it) as written; an ellipsoid as its bounding capsule, a plane
// as a floor, a height field not at all (each noted). Geoms in MuJoCo's hidden groups (3 and up: by
// convention the collision shapes behind visual ones) and fully transparent ones are left out, as
// MuJoCo's own viewer does, and so is a colliding geom on a body that draws visual-only geoms
// (contype = conaffinity = 0) of another group: the file drew the body twice, once to be seen. A
// moving body without a geom gets bones, so it is seen.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>

#include "physics/model_file/mujoco_call.h"
#include "physics/model_file/number_text.h"

namespace dyn::model_file::detail {
namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using RowMat3 = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;

std::string nameOf(const mjModel* m, int type, int id, const char* what) {
  const char* n = mj_id2name(m, type, id);
  if (n && *n) return n;
  if (type == mjOBJ_BODY && id == 0) return "world";
  return std::string(what) + " #" + std::to_string(id);
}

// The colour MuJoCo draws: the geom's rgba, or its material's when the geom keeps the default grey.
std::array<float, 4> colorOf(const mjModel* m, int g, bool& from_file) {
  const float* c = m->geom_rgba + 4 * g;
  const bool grey = c[0] == 0.5f && c[1] == 0.5f && c[2] == 0.5f && c[3] == 1.0f;
  const int mat = m->geom_matid[g];
  if (grey && mat >= 0) c = m->mat_rgba + 4 * mat;
  from_file = !grey || mat >= 0;
  return {c[0], c[1], c[2], c[3]};
}

// The capsule around points given in the geom's frame: along the axis of their box's largest extent,
// through its centre (rot's columns reordered so that local z is that axis), as wide as the farthest
// point from that axis, its segment as long as the box (an ellipsoid's semi-axes: shorter by the
// radius, which still holds the whole ellipsoid when the radius is its middle semi-axis).
void boundingCapsule(const std::vector<Vec3>& points, bool ellipsoid, Geom& g) {
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (const Vec3& p : points) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const Vec3 centre = 0.5 * (lo + hi), half = 0.5 * (hi - lo);
  int k = 0;
  half.maxCoeff(&k);
  double radius = 0;
  for (const Vec3& p : points) {
    Vec3 off = p - centre;
    off[k] = 0;
    radius = std::max(radius, off.norm());
  }
  Mat3 rot;
  rot.col(2) = g.rot.col(k), rot.col(0) = g.rot.col((k + 1) % 3), rot.col(1) = g.rot.col((k + 2) % 3);
  g.pos += g.rot * centre;
  g.rot = rot;
  g.shape = Geom::Shape::Capsule;
  g.size = {std::max(radius, 1e-6), ellipsoid ? std::max(half[k] - radius, 0.0) : half[k], 0};
}

// Mesh `id` as MuJoCo decoded it (vertices in the mesh's frame: MuJoCo 2.2.2 moved them to the mesh's
// inertial frame and geom_pos/geom_quat with them), or null when it has no triangles, a vertex is not
// finite or a face names a vertex the mesh does not have.
std::shared_ptr<const TriangleMesh> meshOf(const mjModel* m, int id) {
  auto mesh = std::make_shared<TriangleMesh>();
  const int nv = m->mesh_vertnum[id], nf = m->mesh_facenum[id];
  const float* v = m->mesh_vert + 3 * m->mesh_vertadr[id];
  for (int k = 0; k < nv; ++k) {
    const Eigen::Vector3f p(v[3 * k], v[3 * k + 1], v[3 * k + 2]);
    if (!p.allFinite()) return nullptr;
    mesh->vertices.push_back(p);
    mesh->box.extend(p.cast<double>());
  }
  const int* f = m->mesh_face + 3 * m->mesh_faceadr[id];
  for (int k = 0; k < nf; ++k) {
    std::array<std::uint32_t, 3> t{};
    for (int c = 0; c < 3; ++c) {
      if (f[3 * k + c] < 0 || f[3 * k + c] >= nv) return nullptr;
      t[std::size_t(c)] = std::uint32_t(f[3 * k + c]);
    }
    mesh->triangles.push_back(t);
  }
  if (mesh->triangles.empty()) return nullptr;
  return mesh;
}

// Geoms that only collide, on bodies that also draw visual-only geoms (contype = conaffinity = 0) of
// another group (MuJoCo Menagerie: visual in group 2, collision in 3; URDF visuals beside collisions):
// the same body drawn twice, so the colliding ones are left out. Planes are floors, never duplicates.
std::vector<bool> duplicates(const mjModel* m) {
  auto visualOnly = [&](int i) { return m->geom_contype[i] == 0 && m->geom_conaffinity[i] == 0; };
  std::map<int, std::vector<int>> visual_groups;  // body → groups of its visual-only geoms
  for (int i = 0; i < m->ngeom; ++i)
    if (visualOnly(i) && m->geom_group[i] <= 2) visual_groups[m->geom_bodyid[i]].push_back(m->geom_group[i]);
  std::vector<bool> out(std::size_t(m->ngeom), false);
  for (int i = 0; i < m->ngeom; ++i) {
    const auto it = visual_groups.find(m->geom_bodyid[i]);
    if (visualOnly(i) || m->geom_type[i] == mjGEOM_PLANE || it == visual_groups.end()) continue;
    out[std::size_t(i)] = std::find(it->second.begin(), it->second.end(), m->geom_group[i]) == it->second.end();
  }
  return out;
}

std::string num(double x) { return detail::numberText(x, 3); }

}  // namespace

void readDrawing(const mjModel* m, const mjData* d, const std::vector<int>& link, const std::vector<Vec3>& origin, Drawing& out) {
  std::vector<bool> drawn(std::size_t(m->nbody), false);
  const std::vector<bool> duplicate = duplicates(m);
  std::map<int, std::shared_ptr<const TriangleMesh>> meshes;  // mesh id → its triangles, read once
  int hidden = 0, clear = 0, doubled = 0;
  for (int i = 0; i < m->ngeom; ++i) {
    const int b = m->geom_bodyid[i];
    Geom g;
    g.name = nameOf(m, mjOBJ_GEOM, i, "geom");
    g.body = nameOf(m, mjOBJ_BODY, b, "body");
    const std::string what = "geom '" + g.name + "' (body '" + g.body + "')";
    if (m->geom_group[i] > 2) {
      ++hidden;
      continue;
    }
    if (duplicate[std::size_t(i)]) {
      ++doubled;
      continue;
    }
    g.rgba = colorOf(m, i, g.file_color);
    if (g.rgba[3] <= 0) {
      ++clear;
      continue;
    }
    g.link = link[std::size_t(b)];
    g.pos = Vec3(d->geom_xpos + 3 * i) - origin[std::size_t(b)];
    g.rot = Eigen::Map<const RowMat3>(d->geom_xmat + 9 * i);
    const mjtNum* size = m->geom_size + 3 * i;
    switch (m->geom_type[i]) {
      case mjGEOM_SPHERE: g.shape = Geom::Shape::Sphere, g.size = {size[0], 0, 0}; break;
      case mjGEOM_CAPSULE: g.shape = Geom::Shape::Capsule, g.size = {size[0], size[1], 0}; break;
      case mjGEOM_CYLINDER: g.shape = Geom::Shape::Cylinder, g.size = {size[0], size[1], 0}; break;
      case mjGEOM_BOX: g.shape = Geom::Shape::Box, g.size = {size[0], size[1], size[2]}; break;
      case mjGEOM_ELLIPSOID: {
        std::vector<Vec3> axes;
        for (int k = 0; k < 3; ++k) axes.push_back(size[k] * Vec3::Unit(k)), axes.push_back(-size[k] * Vec3::Unit(k));
        boundingCapsule(axes, true, g);
        out.notes.push_back(what + ": an ellipsoid, drawn as its bounding capsule");
        break;
      }
      case mjGEOM_MESH: {
        const int id = m->geom_dataid[i];
        if (id < 0 || m->mesh_vertnum[id] <= 0) {
          out.notes.push_back(what + ": a mesh without vertices, not drawn");
          continue;
        }
        if (!meshes.count(id)) meshes[id] = meshOf(m, id);
        g.mesh = meshes[id];
        if (g.mesh) {
          // Its triangles in the geom's frame, which MuJoCo places at the mesh's (geom_xpos, geom_xmat).
          g.shape = Geom::Shape::Mesh;
          g.size = 0.5 * g.mesh->box.sizes();
          break;
        }
        // No usable faces: the capsule around the vertices.
        std::vector<Vec3> points;
        const float* v = m->mesh_vert + 3 * m->mesh_vertadr[id];
        for (int k = 0; k < m->mesh_vertnum[id]; ++k) points.emplace_back(v[3 * k], v[3 * k + 1], v[3 * k + 2]);
        boundingCapsule(points, false, g);
        out.notes.push_back(what + ": a mesh without usable faces, drawn as its bounding capsule (radius " + num(g.size[0]) +
                            " m, length " + num(2 * (g.size[0] + g.size[1])) + " m)");
        break;
      }
      case mjGEOM_PLANE:
        g.shape = Geom::Shape::Plane, g.size = {size[0], size[1], 0};
        out.notes.push_back(what + ": a plane, drawn as a floor under the mechanism");
        break;
      default:
        out.notes.push_back(what + ": a height field, not drawn (dynlab draws spheres, capsules, cylinders, boxes, planes, "
                                   "meshes and planes)");
        continue;
    }
    // Drawing only: a shape beyond what the description reads (±1e9) is left out, not refused.
    constexpr double kLargest = 1e9;
    const bool far_mesh = g.mesh && (g.mesh->box.min().cwiseAbs().maxCoeff() > kLargest || g.mesh->box.max().cwiseAbs().maxCoeff() > kLargest);
    if (!g.rot.allFinite() || !g.pos.allFinite() || !g.size.allFinite() || g.pos.cwiseAbs().maxCoeff() > kLargest ||
        g.size.cwiseAbs().maxCoeff() > kLargest || far_mesh) {
      out.notes.push_back(what + ": its position or size is not finite or beyond ±1e9 m, not drawn");
      continue;
    }
    drawn[std::size_t(b)] = g.shape != Geom::Shape::Plane;
    out.geoms.push_back(g);
  }
  if (hidden > 0) out.notes.push_back(std::to_string(hidden) + " geom" + (hidden == 1 ? "" : "s") + " in groups 3 and up not drawn (MuJoCo's viewer hides them)");
  if (doubled > 0)
    out.notes.push_back(std::to_string(doubled) + " colliding geom" + (doubled == 1 ? "" : "s") +
                        " not drawn: " + (doubled == 1 ? "its body draws" : "their bodies draw") + " visual-only geoms (contype = conaffinity = 0) of another group");
  if (clear > 0) out.notes.push_back(std::to_string(clear) + " transparent geom" + (clear == 1 ? "" : "s") + " (alpha 0) not drawn");

  // Bones for each tree body that nothing is drawn on: from its anchor to its children's anchors and
  // to its bodies' centres of mass.
  std::map<int, bool> has;  // tree body → something drawn on it
  for (int b = 1; b < m->nbody; ++b) has[link[std::size_t(b)]] = has[link[std::size_t(b)]] || drawn[std::size_t(b)];
  for (int b = 1; b < m->nbody; ++b) {
    const int l = link[std::size_t(b)];
    if (l < 0 || has[l] || m->body_jntnum[b] == 0) continue;
    const Vec3& o = origin[std::size_t(b)];
    const std::size_t before = out.bones.size();
    auto bone = [&](const Vec3& p) {
      if ((p - o).norm() > 1e-9 && p.allFinite()) out.bones.push_back({l, Vec3::Zero(), p - o});
    };
    for (int c = 1; c < m->nbody; ++c) {
      const int parent = m->body_parentid[c];
      if (link[std::size_t(parent)] != l) continue;
      if (m->body_jntnum[c] > 0) bone(Vec3(d->xanchor + 3 * m->body_jntadr[c]));  // a child's joint
      else if (c != b) bone(Vec3(d->xipos + 3 * c));                           // a fused body's centre of mass
    }
    bone(Vec3(d->xipos + 3 * b));
    if (out.bones.size() > before)
      out.notes.push_back("body '" + nameOf(m, mjOBJ_BODY, b, "body") + "' has no geom: drawn as rods from its joint to its children's joints and its centre of mass");
  }
}

}  // namespace dyn::model_file::detail
