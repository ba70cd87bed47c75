// A triangle mesh as plain data (no GL): vertices in the mesh's own frame and triangles as three vertex
// indices each, counter-clockwise seen from outside where the file winds them so. A model file's mesh
// geom carries one (physics/model_file/model_file.h Geom), a Scene draws one (labs/scene.h MeshShape),
// and render/ uploads each once, however many frames show it.
#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <vector>

namespace dyn {

struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;  // indices into vertices, each < vertices.size()
  Eigen::AlignedBox3d box;                               // the vertices' box (empty without any)
};

}  // namespace dyn
