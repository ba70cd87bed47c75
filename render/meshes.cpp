// Unit meshes uploaded once: a stretchable capsule (also used for spheres), a capped cone, a
// flat-shaded box, a capped cylinder and a two-sided square. Model matrices and the capsule
// stretch place them in the world. (A scene's own triangle meshes: mesh_cache.cpp.)
#include <cmath>
#include <numbers>
#include <vector>

#include "render/gl_internal.h"

namespace dyn::gl {
namespace {

// Connects ring r to ring r+1 (each `n` vertices, counter-clockwise seen from outside).
void stitchRings(std::vector<GLuint>& indices, GLuint first, GLuint n) {
  for (GLuint i = 0; i < n; ++i) {
    GLuint j = (i + 1) % n;
    GLuint a = first + i, b = first + j, c = first + n + i, d = first + n + j;
    indices.insert(indices.end(), {a, b, d, a, d, c});
  }
}

}  // namespace

// Uploads vertices and triangle indices into a fresh VAO.
Mesh uploadMesh(const std::vector<Vertex>& vertices, const std::vector<GLuint>& indices) {
  Mesh mesh;
  glGenVertexArrays(1, &mesh.vao);
  glGenBuffers(1, &mesh.vbo);
  glGenBuffers(1, &mesh.ebo);
  glBindVertexArray(mesh.vao);
  glBindBuffer(GL_ARRAY_BUFFER, mesh.vbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(vertices.size() * sizeof(Vertex)), vertices.data(),
               GL_STATIC_DRAW);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, mesh.ebo);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(indices.size() * sizeof(GLuint)),
               indices.data(), GL_STATIC_DRAW);
  // Attributes: 0 position, 1 normal, 2 end flag.
  floatAttribute(0, 3, sizeof(Vertex), offsetof(Vertex, position));
  floatAttribute(1, 3, sizeof(Vertex), offsetof(Vertex, normal));
  floatAttribute(2, 1, sizeof(Vertex), offsetof(Vertex, end));
  glBindVertexArray(0);
  mesh.index_count = GLsizei(indices.size());
  return mesh;
}

void floatAttribute(GLuint index, GLint size, GLsizei stride, std::size_t offset) {
  glEnableVertexAttribArray(index);
  glVertexAttribPointer(index, size, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(offset));
}

void Mesh::draw() const {
  glBindVertexArray(vao);
  glDrawElements(GL_TRIANGLES, index_count, GL_UNSIGNED_INT, nullptr);
}

void Mesh::destroy() {
  glDeleteBuffers(1, &ebo);
  glDeleteBuffers(1, &vbo);
  glDeleteVertexArrays(1, &vao);
  vao = vbo = ebo = 0;
}

Mesh makeCapsule(int slices, int half_stacks) {
  const double pi = std::numbers::pi;
  std::vector<Vertex> vertices;
  std::vector<GLuint> indices;
  // Rings from the south pole (z=-1) up to the equator (end 0), then the equator again up to the
  // north pole (end 1); the two equator rings form the cylinder once stretched.
  const int rings = 2 * (half_stacks + 1);
  for (int r = 0; r < rings; ++r) {
    const bool north = r > half_stacks;
    const int k = north ? r - (half_stacks + 1) : r;  // 0..half_stacks within the hemisphere
    const double lat = north ? pi / 2 * k / half_stacks : -pi / 2 + pi / 2 * k / half_stacks;
    for (int s = 0; s < slices; ++s) {
      const double lon = 2 * pi * s / slices;
      const float x = float(std::cos(lat) * std::cos(lon)), y = float(std::cos(lat) * std::sin(lon)),
                  z = float(std::sin(lat));
      vertices.push_back({{x, y, z}, {x, y, z}, north ? 1.0f : 0.0f});
    }
  }
  for (int r = 0; r + 1 < rings; ++r) stitchRings(indices, GLuint(r * slices), GLuint(slices));
  return uploadMesh(vertices, indices);
}

Mesh makeCone(int slices) {
  const double pi = std::numbers::pi;
  std::vector<Vertex> vertices;
  std::vector<GLuint> indices;
  const float n = float(1.0 / std::sqrt(2.0));  // side normal for radius 1, height 1
  // Side: a base ring and an apex ring (one apex vertex per slice, normal at the slice middle).
  for (int s = 0; s < slices; ++s) {
    const double lon = 2 * pi * s / slices;
    const float c = float(std::cos(lon)), sn = float(std::sin(lon));
    vertices.push_back({{c, sn, 0}, {c * n, sn * n, n}, 0});
  }
  for (int s = 0; s < slices; ++s) {
    const double lon = 2 * pi * (s + 0.5) / slices;
    vertices.push_back({{0, 0, 1}, {float(std::cos(lon)) * n, float(std::sin(lon)) * n, n}, 0});
  }
  for (int s = 0; s < slices; ++s) {
    GLuint a = GLuint(s), b = GLuint((s + 1) % slices), apex = GLuint(slices + s);
    indices.insert(indices.end(), {a, b, apex});
  }
  // Base cap facing -z: a centre vertex and its own ring with a flat normal.
  const GLuint centre = GLuint(vertices.size());
  vertices.push_back({{0, 0, 0}, {0, 0, -1}, 0});
  for (int s = 0; s < slices; ++s) {
    const double lon = 2 * pi * s / slices;
    vertices.push_back({{float(std::cos(lon)), float(std::sin(lon)), 0}, {0, 0, -1}, 0});
  }
  for (int s = 0; s < slices; ++s) {
    GLuint a = centre + 1 + GLuint(s), b = centre + 1 + GLuint((s + 1) % slices);
    indices.insert(indices.end(), {centre, b, a});
  }
  return uploadMesh(vertices, indices);
}

Mesh makeBox() {
  std::vector<Vertex> vertices;
  std::vector<GLuint> indices;
  // Six faces: normal axis, sign; the other two axes span the face counter-clockwise.
  for (int axis = 0; axis < 3; ++axis) {
    for (float sign : {1.0f, -1.0f}) {
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      const GLuint first = GLuint(vertices.size());
      const float corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
      for (const auto& c : corners) {
        Vertex vert{{0, 0, 0}, {0, 0, 0}, 0};
        vert.position[axis] = sign;
        vert.position[u] = c[0];
        vert.position[v] = sign > 0 ? c[1] : -c[1];  // mirror keeps the winding outward
        vert.normal[axis] = sign;
        vertices.push_back(vert);
      }
      indices.insert(indices.end(), {first, first + 1, first + 2, first, first + 2, first + 3});
    }
  }
  return uploadMesh(vertices, indices);
}

Mesh makeCylinder(int slices) {
  const double pi = std::numbers::pi;
  std::vector<Vertex> vertices;
  std::vector<GLuint> indices;
  // Side: a ring at z=-1 and one at z=+1 with radial normals.
  for (float z : {-1.0f, 1.0f})
    for (int s = 0; s < slices; ++s) {
      const double lon = 2 * pi * s / slices;
      const float c = float(std::cos(lon)), sn = float(std::sin(lon));
      vertices.push_back({{c, sn, z}, {c, sn, 0}, 0});
    }
  stitchRings(indices, 0, GLuint(slices));
  // Caps: a centre and its own ring with the flat normal, wound outward.
  for (float z : {-1.0f, 1.0f}) {
    const GLuint centre = GLuint(vertices.size());
    vertices.push_back({{0, 0, z}, {0, 0, z}, 0});
    for (int s = 0; s < slices; ++s) {
      const double lon = 2 * pi * s / slices;
      vertices.push_back({{float(std::cos(lon)), float(std::sin(lon)), z}, {0, 0, z}, 0});
    }
    for (int s = 0; s < slices; ++s) {
      GLuint a = centre + 1 + GLuint(s), b = centre + 1 + GLuint((s + 1) % slices);
      if (z > 0) indices.insert(indices.end(), {centre, a, b});
      else indices.insert(indices.end(), {centre, b, a});
    }
  }
  return uploadMesh(vertices, indices);
}

Mesh makeQuad() {
  std::vector<Vertex> vertices;
  std::vector<GLuint> indices;
  // The front (normal +z, counter-clockwise from +z) and the back (normal -z, reversed).
  const float corners[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  for (float side : {1.0f, -1.0f}) {
    const GLuint first = GLuint(vertices.size());
    for (const auto& c : corners) vertices.push_back({{c[0], c[1], 0}, {0, 0, side}, 0});
    if (side > 0) indices.insert(indices.end(), {first, first + 1, first + 2, first, first + 2, first + 3});
    else indices.insert(indices.end(), {first, first + 2, first + 1, first, first + 3, first + 2});
  }
  return uploadMesh(vertices, indices);
}

}  // namespace dyn::gl
