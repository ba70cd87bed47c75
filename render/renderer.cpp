// Renderer: draws a Scene with GL 3.3 core into a 4x multisample framebuffer (opaque meshes,
// polylines, then translucent meshes back to front), adds the Dear ImGui overlay, resolves into
// a single-sample framebuffer and reads it back top-down.
#include "render/renderer.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "render/gl_internal.h"

namespace dyn {
namespace {

using Eigen::Matrix3d;
using Eigen::Matrix4d;
using Eigen::Vector3d;

// Camera basis: right, up, back (towards the viewer), from the look-at parameters.
struct CameraBasis {
  Vector3d right, up, back;
};

CameraBasis basisOf(const Camera& camera) {
  Vector3d back = camera.eye - camera.target;
  back = back.norm() > 1e-12 ? back.normalized() : Vector3d::UnitZ();
  Vector3d right = camera.up.cross(back);
  if (right.norm() < 1e-9) right = Vector3d::UnitY().cross(back);  // up parallel to view
  if (right.norm() < 1e-9) right = Vector3d::UnitX();
  right.normalize();
  return {right, back.cross(right), back};
}

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

// One mesh draw: model matrix, normal matrix, capsule stretch, colour, view depth.
struct DrawItem {
  const gl::Mesh* mesh;
  Eigen::Matrix4f model;
  Eigen::Matrix3f normal;
  Eigen::Vector3f stretch;
  Color color;
  double depth;  // distance in front of the camera of the item's centre
};

Eigen::Matrix4f affine(const Matrix3d& linear, const Vector3d& translation) {
  Matrix4d m = Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = linear;
  m.topRightCorner<3, 1>() = translation;
  return m.cast<float>();
}

// Polyline vertex: this end, the other end, which side of the quad.
struct LineVertex {
  float position[3];
  float other[3];
  float side;
};

}  // namespace

struct Renderer::Impl {
  GlContext& context;
  RenderOptions options;
  int width, height, samples = 0;
  GLuint msaa_fbo = 0, msaa_color = 0, msaa_depth = 0;
  GLuint resolve_fbo = 0, resolve_color = 0, resolve_depth = 0;
  gl::ShadedProgram shaded;
  gl::LineProgram line;
  // Capsule/sphere levels of detail by on-screen radius (silhouette error under ~1/4 pixel).
  static constexpr int kLevels = 4;
  static constexpr double kLevelMaxRadiusPx[kLevels] = {5, 16, 48, 1e300};
  gl::Mesh capsules[kLevels];
  gl::Mesh cone, box;
  GLuint line_vao = 0, line_vbo = 0;
  std::unique_ptr<gl::OverlayPanel> overlay;  // created on first use
  std::vector<DrawItem> items;                // reused between frames
  std::vector<LineVertex> line_vertices;

  Impl(GlContext& c, RenderOptions o)
      : context(c), options(o), width(o.width > 0 ? o.width : c.width()),
        height(o.height > 0 ? o.height : c.height()) {
    createFramebuffers();
    shaded = gl::makeShadedProgram();
    line = gl::makeLineProgram();
    const int slices[kLevels] = {10, 16, 28, 48};
    for (int i = 0; i < kLevels; ++i) capsules[i] = gl::makeCapsule(slices[i], slices[i] / 4 + 1);
    cone = gl::makeCone(40);
    box = gl::makeBox();
    // Polyline stream: attributes 0 position, 1 other end, 2 side.
    glGenVertexArrays(1, &line_vao);
    glGenBuffers(1, &line_vbo);
    glBindVertexArray(line_vao);
    glBindBuffer(GL_ARRAY_BUFFER, line_vbo);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(LineVertex),
                          reinterpret_cast<void*>(offsetof(LineVertex, position)));
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, sizeof(LineVertex),
                          reinterpret_cast<void*>(offsetof(LineVertex, other)));
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 1, GL_FLOAT, GL_FALSE, sizeof(LineVertex),
                          reinterpret_cast<void*>(offsetof(LineVertex, side)));
    glBindVertexArray(0);
  }

  ~Impl() {
    overlay.reset();
    for (auto& mesh : capsules) mesh.destroy();
    cone.destroy();
    box.destroy();
    glDeleteBuffers(1, &line_vbo);
    glDeleteVertexArrays(1, &line_vao);
    glDeleteProgram(shaded.id);
    glDeleteProgram(line.id);
    const GLuint fbos[] = {msaa_fbo, resolve_fbo};
    const GLuint rbos[] = {msaa_color, msaa_depth, resolve_color, resolve_depth};
    glDeleteFramebuffers(2, fbos);
    glDeleteRenderbuffers(4, rbos);
  }

  // Colour + depth renderbuffers: a multisample target (if MSAA) and the single-sample resolve.
  void createFramebuffers() {
    GLint max_samples = 0;
    glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
    samples = options.msaa > 1 ? std::min(options.msaa, int(max_samples)) : 0;
    auto makeTarget = [&](int n, GLuint& fbo, GLuint& color, GLuint& depth) {
      glGenFramebuffers(1, &fbo);
      glGenRenderbuffers(1, &color);
      glGenRenderbuffers(1, &depth);
      glBindFramebuffer(GL_FRAMEBUFFER, fbo);
      glBindRenderbuffer(GL_RENDERBUFFER, color);
      glRenderbufferStorageMultisample(GL_RENDERBUFFER, n, GL_RGBA8, width, height);
      glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color);
      glBindRenderbuffer(GL_RENDERBUFFER, depth);
      glRenderbufferStorageMultisample(GL_RENDERBUFFER, n, GL_DEPTH_COMPONENT24, width, height);
      glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
      if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        throw std::runtime_error("render: framebuffer incomplete (" + std::to_string(n) +
                                 " samples, " + std::to_string(width) + "x" +
                                 std::to_string(height) + ")");
    };
    makeTarget(0, resolve_fbo, resolve_color, resolve_depth);
    if (samples > 0) makeTarget(samples, msaa_fbo, msaa_color, msaa_depth);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
  }

  // Turns the scene's primitives into mesh draws.
  void collectItems(const Scene& scene, const CameraBasis& basis) {
    items.clear();
    auto depthOf = [&](const Vector3d& p) { return (scene.camera.eye - p).dot(basis.back); };
    // Pixels per metre at a point (constant for orthographic cameras).
    const Camera& cam = scene.camera;
    auto pixelsPerMetre = [&](const Vector3d& p) {
      if (cam.ortho) return height / (2.0 * cam.visibleHalfHeight(double(width) / std::max(height, 1)));
      const double half_fov = std::tan(cam.fov_y_deg * M_PI / 360.0);
      return height / (2.0 * half_fov * std::max(depthOf(p), 1e-6));
    };
    auto capsuleMesh = [&](const Vector3d& centre, double r) {
      const double r_px = r * pixelsPerMetre(centre);
      int level = 0;
      while (r_px > kLevelMaxRadiusPx[level]) ++level;
      return &capsules[level];
    };
    auto addCapsule = [&](const Vector3d& p0, const Vector3d& p1, double r, const Color& color) {
      const Vector3d axis = p1 - p0;
      const double length = axis.norm();
      const Matrix3d rot = length > 1e-12 ? frameAlong(axis / length) : Matrix3d::Identity();
      items.push_back({capsuleMesh(0.5 * (p0 + p1), r), affine(rot * r, p0), rot.cast<float>(),
                       Eigen::Vector3f(0, 0, float(length / r)), color, depthOf(0.5 * (p0 + p1))});
    };
    for (const auto& c : scene.capsules)
      if (c.radius > 0) addCapsule(c.p0, c.p1, c.radius, c.color);
    for (const auto& s : scene.spheres)
      if (s.radius > 0) addCapsule(s.center, s.center, s.radius, s.color);
    for (const auto& b : scene.boxes) {
      const Vector3d half = b.half_extents.cwiseMax(1e-9);
      items.push_back({&box, affine(b.rotation * half.asDiagonal(), b.center),
                       (b.rotation * half.cwiseInverse().asDiagonal()).cast<float>(),
                       Eigen::Vector3f::Zero(), b.color, depthOf(b.center)});
    }
    for (const auto& a : scene.arrows) {
      const double length = a.vector.norm();
      if (length < 1e-9 || a.radius <= 0) continue;
      const Vector3d dir = a.vector / length;
      // Head: 2.2 radii wide, 5 radii long, at most half the arrow.
      const double head_r = 2.2 * a.radius, head_len = std::min(5.0 * a.radius, 0.5 * length);
      const Vector3d neck = a.origin + dir * (length - head_len);
      addCapsule(a.origin, neck, a.radius, a.color);
      const Matrix3d rot = frameAlong(dir);
      const Vector3d scale(head_r, head_r, head_len);
      items.push_back({&cone, affine(rot * scale.asDiagonal(), neck),
                       (rot * scale.cwiseInverse().asDiagonal()).cast<float>(),
                       Eigen::Vector3f::Zero(), a.color, depthOf(neck)});
    }
  }

  void drawItem(const DrawItem& item) {
    glUniformMatrix4fv(shaded.model, 1, GL_FALSE, item.model.data());
    glUniformMatrix3fv(shaded.normal_matrix, 1, GL_FALSE, item.normal.data());
    glUniform3fv(shaded.stretch, 1, item.stretch.data());
    glUniform4f(shaded.color, item.color.r, item.color.g, item.color.b, item.color.a);
    // A mirroring box rotation flips the winding; keep culling the back faces.
    glFrontFace(item.model.topLeftCorner<3, 3>().determinant() < 0 ? GL_CW : GL_CCW);
    item.mesh->draw();
  }

  // Polylines as screen-space quads of width_px, one draw per polyline.
  void drawPolylines(const Scene& scene, const Eigen::Matrix4f& view_proj, bool translucent) {
    line_vertices.clear();
    std::vector<std::pair<GLint, GLsizei>> ranges;
    for (const auto& pl : scene.polylines) {
      const GLint first = GLint(line_vertices.size());
      if ((pl.color.a < 1.0f) == translucent) {
        for (std::size_t i = 0; i + 1 < pl.points.size(); ++i) {
          const Eigen::Vector3f a = pl.points[i].cast<float>(), b = pl.points[i + 1].cast<float>();
          // Corners: a on both sides, b on both sides (b's sides flip: its "other" is a).
          const LineVertex a0{{a.x(), a.y(), a.z()}, {b.x(), b.y(), b.z()}, 1};
          const LineVertex a1{{a.x(), a.y(), a.z()}, {b.x(), b.y(), b.z()}, -1};
          const LineVertex b0{{b.x(), b.y(), b.z()}, {a.x(), a.y(), a.z()}, -1};
          const LineVertex b1{{b.x(), b.y(), b.z()}, {a.x(), a.y(), a.z()}, 1};
          line_vertices.insert(line_vertices.end(), {a0, a1, b1, a0, b1, b0});
        }
      }
      ranges.emplace_back(first, GLsizei(line_vertices.size()) - first);
    }
    if (line_vertices.empty()) return;
    glUseProgram(line.id);
    glUniformMatrix4fv(line.view_proj, 1, GL_FALSE, view_proj.data());
    glUniform2f(line.viewport, float(width), float(height));
    glBindVertexArray(line_vao);
    glBindBuffer(GL_ARRAY_BUFFER, line_vbo);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(line_vertices.size() * sizeof(LineVertex)),
                 line_vertices.data(), GL_STREAM_DRAW);
    glDisable(GL_CULL_FACE);
    for (std::size_t i = 0; i < scene.polylines.size(); ++i) {
      if (ranges[i].second == 0) continue;
      const auto& pl = scene.polylines[i];
      glUniform1f(line.half_width, float(std::max(0.5, pl.width_px) / 2));
      glUniform4f(line.color, pl.color.r, pl.color.g, pl.color.b, pl.color.a);
      glDrawArrays(GL_TRIANGLES, ranges[i].first, ranges[i].second);
    }
    glEnable(GL_CULL_FACE);
  }

  void draw(const Scene& scene, const Overlay* panel) {
    const GLuint target = samples > 0 ? msaa_fbo : resolve_fbo;
    glBindFramebuffer(GL_FRAMEBUFFER, target);
    glViewport(0, 0, width, height);
    glDisable(GL_SCISSOR_TEST);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthMask(GL_TRUE);
    const Color& bg = scene.background;
    glClearColor(bg.r, bg.g, bg.b, bg.a);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glDisable(GL_BLEND);
    // Alpha stays 1 where the background is opaque.
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);

    const CameraBasis basis = basisOf(scene.camera);
    const Eigen::Matrix4f view_proj = viewProjection(scene.camera, width, height).cast<float>();
    // Key light from the upper left, in front of the scene; moves with the camera.
    const Vector3d light = (-0.45 * basis.right + 0.65 * basis.up + 0.75 * basis.back).normalized();
    glUseProgram(shaded.id);
    glUniformMatrix4fv(shaded.view_proj, 1, GL_FALSE, view_proj.data());
    glUniform3f(shaded.light_dir, float(light.x()), float(light.y()), float(light.z()));
    glUniform3f(shaded.view_dir, float(basis.back.x()), float(basis.back.y()), float(basis.back.z()));
    glUniform3f(shaded.eye, float(scene.camera.eye.x()), float(scene.camera.eye.y()),
                float(scene.camera.eye.z()));
    glUniform1i(shaded.ortho, scene.camera.ortho ? 1 : 0);

    // Opaque meshes in scene order.
    collectItems(scene, basis);
    for (const auto& item : items)
      if (item.color.a >= 1.0f) drawItem(item);
    // Opaque polylines (depth-tested, so the arm hides what is behind it).
    drawPolylines(scene, view_proj, false);

    // Translucent meshes: a depth-only pass first, so overlapping parts of a ghost (capsule
    // ends, joints) blend once as one surface; then colour far to near, blended, no depth writes.
    std::vector<const DrawItem*> translucent;
    for (const auto& item : items)
      if (item.color.a < 1.0f) translucent.push_back(&item);
    std::stable_sort(translucent.begin(), translucent.end(),
                     [](const DrawItem* a, const DrawItem* b) { return a->depth > b->depth; });
    glUseProgram(shaded.id);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    for (const DrawItem* item : translucent) drawItem(*item);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glEnable(GL_BLEND);
    glDepthMask(GL_FALSE);
    glDepthFunc(GL_LEQUAL);
    for (const DrawItem* item : translucent) drawItem(*item);
    glDepthFunc(GL_LESS);
    glFrontFace(GL_CCW);
    // Translucent lines last.
    drawPolylines(scene, view_proj, true);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glBindVertexArray(0);

    // Resolve the samples into the single-sample framebuffer that read() uses.
    if (samples > 0) {
      glBindFramebuffer(GL_READ_FRAMEBUFFER, msaa_fbo);
      glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_fbo);
      glBlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    }

    // The panel on top, after the resolve: ImGui anti-aliases itself, so it skips the 4x
    // samples (its own GL state is restored by the backend).
    if (options.show_overlay && panel) {
      glBindFramebuffer(GL_FRAMEBUFFER, resolve_fbo);
      glDisable(GL_DEPTH_TEST);
      if (!overlay) overlay = std::make_unique<gl::OverlayPanel>(width, height);
      overlay->draw(*panel);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
  }

  Image read() const {
    Image image;
    image.width = width;
    image.height = height;
    image.rgba.resize(std::size_t(width) * height * 4);
    std::vector<std::uint8_t> bottom_up(image.rgba.size());
    glBindFramebuffer(GL_READ_FRAMEBUFFER, resolve_fbo);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, bottom_up.data());
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    // GL rows start at the bottom; Image rows start at the top.
    const std::size_t row = std::size_t(width) * 4;
    for (int y = 0; y < height; ++y)
      std::copy_n(&bottom_up[std::size_t(height - 1 - y) * row], row, &image.rgba[y * row]);
    return image;
  }
};

Renderer::Renderer(GlContext& context, RenderOptions options)
    : impl_(std::make_unique<Impl>(context, options)) {}

Renderer::~Renderer() = default;

void Renderer::draw(const Scene& scene, const Overlay* overlay) { impl_->draw(scene, overlay); }

Image Renderer::read() const { return impl_->read(); }

void Renderer::present(int x, int y, int target_height) const {
  const int w = impl_->width, h = impl_->height, bottom = target_height - y - h;
  glBindFramebuffer(GL_READ_FRAMEBUFFER, impl_->resolve_fbo);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
  glBlitFramebuffer(0, 0, w, h, x, bottom, x + w, bottom + h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

void Renderer::finish() { glFinish(); }

int Renderer::width() const { return impl_->width; }

int Renderer::height() const { return impl_->height; }

Matrix4d Renderer::viewProjection(const Camera& camera, int width, int height) {
  const CameraBasis b = basisOf(camera);
  // View: world -> camera (x right, y up, looking down -z).
  Matrix4d view = Matrix4d::Identity();
  view.block<1, 3>(0, 0) = b.right.transpose();
  view.block<1, 3>(1, 0) = b.up.transpose();
  view.block<1, 3>(2, 0) = b.back.transpose();
  view.topRightCorner<3, 1>() = -view.topLeftCorner<3, 3>() * camera.eye;
  // Clip range scaled to the viewing distance.
  const double distance = std::max((camera.eye - camera.target).norm(), 1e-3);
  const double aspect = double(width) / double(std::max(height, 1));
  Matrix4d proj = Matrix4d::Zero();
  if (camera.ortho) {
    const double near = -distance, far = 10.0 * distance + 10.0;
    const double top = camera.visibleHalfHeight(aspect), right = top * aspect;
    proj(0, 0) = 1.0 / right;
    proj(1, 1) = 1.0 / top;
    proj(2, 2) = -2.0 / (far - near);
    proj(2, 3) = -(far + near) / (far - near);
    proj(3, 3) = 1.0;
  } else {
    const double near = 0.01 * distance, far = 10.0 * distance + 10.0;
    const double f = 1.0 / std::tan(camera.fov_y_deg * M_PI / 360.0);
    proj(0, 0) = f / aspect;
    proj(1, 1) = f;
    proj(2, 2) = (far + near) / (near - far);
    proj(2, 3) = 2.0 * far * near / (near - far);
    proj(3, 2) = -1.0;
  }
  return proj * view;
}

Eigen::Vector2d Renderer::project(const Camera& camera, int width, int height,
                                  const Eigen::Vector3d& world) {
  const Eigen::Vector4d clip = viewProjection(camera, width, height) * world.homogeneous();
  const double x = clip.x() / clip.w(), y = clip.y() / clip.w();
  // NDC [-1,1] -> pixels, y flipped so row 0 is the top (as in Image).
  return {(x + 1.0) * 0.5 * width, (1.0 - y) * 0.5 * height};
}

}  // namespace dyn
