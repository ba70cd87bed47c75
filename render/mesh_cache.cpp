// A scene's triangle meshes (labs/scene.h MeshShape: a model file's mesh geoms) as GL meshes: normals
// computed here (smooth across gentle angles, sharp at edges), uploaded once per mesh and kept while
// the scene's data keep the mesh.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>

#include "render/gl_internal.h"

namespace dyn::gl {
namespace {

using Eigen::Vector3d;

// More triangles round one point than this and its corners keep their own triangle's normal (the
// smoothing visits every pair round a point: a fan of a million triangles must not cost 10^12).
constexpr std::size_t kMaxRound = 64;

// Each vertex's point: vertices at the same position get the same number (by sorting, so no hash order).
std::vector<std::uint32_t> weld(const std::vector<Eigen::Vector3f>& v) {
  std::vector<std::uint32_t> order(v.size()), id(v.size());
  for (std::uint32_t i = 0; i < order.size(); ++i) order[i] = i;
  auto key = [&](std::uint32_t i) { return std::make_tuple(v[i].x(), v[i].y(), v[i].z()); };
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return key(a) < key(b); });
  std::uint32_t next = 0;
  for (std::size_t k = 0; k < order.size(); ++k) {
    if (k > 0 && key(order[k]) != key(order[k - 1])) ++next;
    id[order[k]] = next;
  }
  return id;
}

}  // namespace

void meshVertices(const TriangleMesh& mesh, std::vector<Vertex>& out) {
  out.clear();
  const auto& v = mesh.vertices;
  // (A vertex that is not a number could not be sorted by weld(): such a mesh is not drawn.)
  if (!std::all_of(v.begin(), v.end(), [](const Eigen::Vector3f& p) { return p.allFinite(); })) return;
  // Each triangle's normal scaled by twice its area, and its direction.
  std::vector<Vector3d> area, unit;
  std::vector<std::size_t> kept;
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    const auto& t = mesh.triangles[f];
    if (t[0] >= v.size() || t[1] >= v.size() || t[2] >= v.size()) continue;
    const Vector3d a = v[t[0]].cast<double>(), b = v[t[1]].cast<double>(), c = v[t[2]].cast<double>();
    const Vector3d n = (b - a).cross(c - a);
    if (!(n.norm() > 0) || !n.allFinite()) continue;  // degenerate: nothing to draw
    kept.push_back(f);
    area.push_back(n);
    unit.push_back(n.normalized());
  }
  // The triangles round each point (CSR: round[start[p] .. start[p + 1])).
  const std::vector<std::uint32_t> point = weld(v);
  const std::size_t points = point.empty() ? 0 : *std::max_element(point.begin(), point.end()) + 1;
  std::vector<std::size_t> start(points + 1, 0), fill;
  for (std::size_t k = 0; k < kept.size(); ++k)
    for (std::uint32_t i : mesh.triangles[kept[k]]) ++start[point[i] + 1];
  for (std::size_t p = 0; p < points; ++p) start[p + 1] += start[p];
  fill.assign(start.begin(), start.end() - 1);
  std::vector<std::size_t> round(start.back());
  for (std::size_t k = 0; k < kept.size(); ++k)
    for (std::uint32_t i : mesh.triangles[kept[k]]) round[fill[point[i]]++] = k;
  const double crease = std::cos(kCreaseDegrees * std::numbers::pi / 180);
  out.reserve(3 * kept.size());
  for (std::size_t k = 0; k < kept.size(); ++k)
    for (std::uint32_t i : mesh.triangles[kept[k]]) {
      const std::size_t p = point[i];
      Vector3d n = unit[k];
      if (start[p + 1] - start[p] <= kMaxRound) {
        Vector3d sum = Vector3d::Zero();
        for (std::size_t r = start[p]; r < start[p + 1]; ++r)
          if (unit[round[r]].dot(unit[k]) >= crease) sum += area[round[r]];
        if (sum.norm() > 0) n = sum.normalized();
      }
      out.push_back({{v[i].x(), v[i].y(), v[i].z()}, {float(n.x()), float(n.y()), float(n.z())}, 0.0f});
    }
}

const Mesh& MeshCache::get(const std::shared_ptr<const TriangleMesh>& mesh) {
  const auto found = entries_.find(mesh.get());
  if (found != entries_.end()) return found->second.gl;
  std::vector<Vertex> vertices;
  meshVertices(*mesh, vertices);
  std::vector<GLuint> indices(vertices.size());
  for (std::size_t i = 0; i < indices.size(); ++i) indices[i] = GLuint(i);
  Entry& entry = entries_[mesh.get()];
  entry = {mesh, uploadMesh(vertices, indices)};
  return entry.gl;
}

void MeshCache::sweep() {
  for (auto it = entries_.begin(); it != entries_.end();) {
    if (it->second.data.use_count() > 1) {
      ++it;
      continue;
    }
    it->second.gl.destroy();
    it = entries_.erase(it);
  }
}

void MeshCache::destroy() {
  for (auto& [key, entry] : entries_) entry.gl.destroy();
  entries_.clear();
}

}  // namespace dyn::gl
