// Files written the way public robot descriptions are, for the model-file tests (physics and app):
// a binary STL mesh and a one-link URDF arm whose collision shape is a mesh named as the file names it.
#pragma once
#include <cstdint>
#include <string>

namespace dyn::test_model_file {

// A binary STL of the tetrahedron (0, s e_x, s e_y, s e_z), faces outward.
inline std::string tetrahedronStl(float s) {
  const float O[3] = {0, 0, 0}, X[3] = {s, 0, 0}, Y[3] = {0, s, 0}, Z[3] = {0, 0, s};
  const float* faces[4][3] = {{O, Y, X}, {O, X, Z}, {O, Z, Y}, {X, Y, Z}};
  std::string b(80, ' ');
  const std::uint32_t count = 4;
  b.append(reinterpret_cast<const char*>(&count), 4);
  for (const auto& f : faces) {
    const float normal[3] = {0, 0, 0};
    b.append(reinterpret_cast<const char*>(normal), 12);
    for (const float* v : f) b.append(reinterpret_cast<const char*>(v), 12);
    b.append(2, '\0');
  }
  return b;
}

// A one-link URDF arm (joint j1, about y) whose collision shape is the mesh `filename`, as ROS exports
// write it (package://…, file://…, meshes/…).
inline std::string meshArmUrdf(const std::string& filename) {
  return "<robot name=\"arm\"><link name=\"base\"/><link name=\"l1\"><inertial><origin xyz=\"0 0 -0.2\"/><mass value=\"1\"/>"
         "<inertia ixx=\"0.01\" iyy=\"0.01\" izz=\"0.01\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/></inertial>"
         "<collision><geometry><mesh filename=\"" + filename + "\"/></geometry></collision></link>"
         "<joint name=\"j1\" type=\"revolute\"><parent link=\"base\"/><child link=\"l1\"/><origin rpy=\"0.3 0 0\"/><axis xyz=\"0 1 0\"/>"
         "<limit lower=\"-3\" upper=\"3\" effort=\"1\" velocity=\"1\"/></joint></robot>";
}

}  // namespace dyn::test_model_file
