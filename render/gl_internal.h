// Internal to render/: GL declarations (prototypes resolved against libOSMesa or libGL; OpenGL ES 3.0
// = WebGL 2 under emscripten), shader programs,
// unit meshes, the scene's primitives as mesh draws, and the Dear ImGui overlay panel used by
// renderer.cpp.
#pragma once
#ifdef __EMSCRIPTEN__
#include <GLES3/gl3.h>
#else
#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/gl.h>
#include <GL/glext.h>
#endif

#include <Eigen/Core>
#include <cstddef>
#include <map>
#include <memory>
#include <vector>

#include "labs/scene.h"
#include "render/framing.h"
#include "render/gl_context.h"

struct ImGuiContext;  // Dear ImGui (global namespace)

namespace dyn::gl {

// ---- shaders.cpp --------------------------------------------------------------------------

// Lit program for meshes: one directional light, ambient, a small specular highlight.
struct ShadedProgram {
  GLuint id = 0;
  GLint view_proj = -1, model = -1, normal_matrix = -1, stretch = -1, color = -1;
  GLint light_dir = -1, view_dir = -1, eye = -1, ortho = -1;
  GLint two_sided = -1;  // a back face lit as the front turned over (a file's mesh, drawn without culling)
};
// Screen-space-width line program for polylines (quads expanded in the vertex shader).
struct LineProgram {
  GLuint id = 0;
  GLint view_proj = -1, viewport = -1, half_width = -1, color = -1;
};
// In the context's GLSL (GlContext::glsl): the same program text after its header.
ShadedProgram makeShadedProgram(Glsl dialect);  // throws std::runtime_error with the compile log
LineProgram makeLineProgram(Glsl dialect);

// ---- meshes.cpp ---------------------------------------------------------------------------

// Vertex of every mesh: position, normal, and `end` (capsules: 1 for vertices moved by the
// stretch uniform, i.e. the p1 hemisphere; 0 elsewhere).
struct Vertex {
  float position[3];
  float normal[3];
  float end;
};

// Enables vertex attribute `index` of the bound VAO: `size` floats at `offset` bytes into each
// `stride`-byte vertex of the bound array buffer.
void floatAttribute(GLuint index, GLint size, GLsizei stride, std::size_t offset);

// An indexed triangle mesh in a VAO.
struct Mesh {
  GLuint vao = 0, vbo = 0, ebo = 0;
  GLsizei index_count = 0;
  void draw() const;
  void destroy();
};

// Uploads vertices and triangle indices into a fresh VAO.
Mesh uploadMesh(const std::vector<Vertex>& vertices, const std::vector<GLuint>& indices);

// Unit capsule along +z: radius 1, hemispheres at z=0 and z=0+stretch; with stretch 0 a sphere.
Mesh makeCapsule(int slices, int half_stacks);
// Unit cone: base radius 1 at z=0 (capped), apex at z=1.
Mesh makeCone(int slices);
// Box [-1,1]^3 with flat faces.
Mesh makeBox();
// Unit cylinder along z: radius 1, z in [-1,1], capped.
Mesh makeCylinder(int slices);
// Square [-1,1]^2 at z=0, two-sided (front normal +z, back normal -z).
Mesh makeQuad();

// ---- mesh_cache.cpp -----------------------------------------------------------------------

// A triangle mesh's vertices for drawing, three per triangle (degenerate ones left out), each corner's
// normal the area-weighted mean of the normals of the triangles round its point (vertices at the same
// position are one point) that turn from its own triangle's by at most kCreaseDegrees: curved
// surfaces shade smooth, edges stay sharp.
inline constexpr double kCreaseDegrees = 40;
void meshVertices(const TriangleMesh& mesh, std::vector<Vertex>& out);

// The scene's triangle meshes, each uploaded the first time a frame shows it and kept while anything
// else holds it: sweep() releases those only the cache still holds (a scene is rebuilt every frame,
// so a mesh no scene names any more goes at the next frame).
class MeshCache {
 public:
  const Mesh& get(const std::shared_ptr<const TriangleMesh>& mesh);
  void sweep();
  void destroy();

 private:
  struct Entry {
    std::shared_ptr<const TriangleMesh> data;  // held, so its address names it while cached
    Mesh gl;
  };
  std::map<const TriangleMesh*, Entry> entries_;
};

// ---- primitives.cpp -----------------------------------------------------------------------

// Every unit mesh the scene's primitives are drawn with.
struct Meshes {
  // Capsule/sphere levels of detail by on-screen radius (silhouette error under ~1/4 pixel).
  static constexpr int kLevels = 4;
  static constexpr double kLevelMaxRadiusPx[kLevels] = {5, 16, 48, 1e300};
  Mesh capsules[kLevels];
  Mesh cone, box, cylinder, quad;
  void create();
  void destroy();
};

// One mesh draw: model matrix, normal matrix, capsule stretch, colour, view depth.
struct DrawItem {
  const Mesh* mesh;
  Eigen::Matrix4f model;
  Eigen::Matrix3f normal;
  Eigen::Vector3f stretch;
  Color color;
  double depth;               // distance in front of the camera of the item's centre
  bool pushed_back = false;   // planes: drawn behind their exact depth so lines on them show
  bool two_sided = false;     // a file's mesh: no culling, back faces lit as front ones
};

// A frame's primitives: mesh draws in scene order (capsules, spheres, boxes, arrows, then planes,
// cylinders and spokes, cones, springs, the scene's triangle meshes) and the planes' grid lines.
struct DrawList {
  std::vector<DrawItem> items;
  std::vector<Polyline> grid_lines;
};
// Fills `out` (cleared first) for a frame of width x height seen through `camera`.
void collectDrawList(const Scene& scene, const Camera& camera, const Meshes& meshes, MeshCache& cache, int width,
                     int height, DrawList& out);

// ---- overlay.cpp --------------------------------------------------------------------------

// The Dear ImGui panel in the top-left corner: title, label/value lines, plots.
class OverlayPanel {
 public:
  OverlayPanel(int width, int height, Glsl dialect);
  ~OverlayPanel();
  OverlayPanel(const OverlayPanel&) = delete;
  OverlayPanel& operator=(const OverlayPanel&) = delete;
  // Lays the panel out for this overlay and returns where it goes (pixels, from the top left);
  // render() then draws that layout into the currently bound framebuffer.
  PixelRect layout(const Overlay& overlay);
  void render();
  void draw(const Overlay& overlay);  // layout + render

 private:
  void buildFrame(const Overlay& overlay);
  ::ImGuiContext* context_ = nullptr;
  PixelRect rect_;
  float scale_ = 1.0f;  // whole multiples of the 640×480 layout, so text and lines stay crisp
};

}  // namespace dyn::gl
