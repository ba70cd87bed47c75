// Renderer: lays out the overlay panel and, for a scene that asks (Scene::framing), fits the camera
// into the rest of the frame (render/framing.h); draws the Scene with GL 3.3 core into a 4x
// multisample framebuffer (opaque meshes with planes pushed back, the planes' grid lines,
// polylines, then translucent meshes back to front; primitives.cpp turns the scene into mesh
// draws), adds the Dear ImGui panel, resolves into a single-sample framebuffer and reads it back
// top-down.
#include "render/renderer.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <exception>
#include <cmath>
#include <stdexcept>

#include "render/gl_internal.h"

namespace dyn {
namespace {

using Eigen::Matrix4d;
using Eigen::Vector3d;

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
  gl::Meshes meshes;
  gl::MeshCache mesh_cache;                   // the scenes' triangle meshes, uploaded once each
  GLuint line_vao = 0, line_vbo = 0;
  std::unique_ptr<gl::OverlayPanel> overlay;  // created on first use
  gl::DrawList draw_list;                     // reused between frames
  std::vector<LineVertex> line_vertices;
  Camera camera;                              // the last frame's (fitted) camera
  PixelRect panel_rect, scene_rect;           // the last frame's panel and the part left free
  std::vector<PixelRect> inset_rects;         // the last frame's insets (inside their borders)
  std::vector<Camera> inset_cameras;

  Impl(GlContext& c, RenderOptions o)
      : context(c), options(o), width(o.width > 0 ? o.width : c.width()),
        height(o.height > 0 ? o.height : c.height()) {
    createFramebuffers();
    shaded = gl::makeShadedProgram(c.glsl());
    line = gl::makeLineProgram(c.glsl());
    meshes.create();
    // Polyline stream: attributes 0 position, 1 other end, 2 side.
    glGenVertexArrays(1, &line_vao);
    glGenBuffers(1, &line_vbo);
    glBindVertexArray(line_vao);
    glBindBuffer(GL_ARRAY_BUFFER, line_vbo);
    gl::floatAttribute(0, 3, sizeof(LineVertex), offsetof(LineVertex, position));
    gl::floatAttribute(1, 3, sizeof(LineVertex), offsetof(LineVertex, other));
    gl::floatAttribute(2, 1, sizeof(LineVertex), offsetof(LineVertex, side));
    glBindVertexArray(0);
  }

  ~Impl() {
    // While an exception unwinds (out of memory while drawing) the context may be half-built: its GL
    // objects and ImGui's are left to the process's end, as the context is (osmesa_context.cpp).
    if (std::uncaught_exceptions() > 0) {
      (void)overlay.release();
      return;
    }
    overlay.reset();
    meshes.destroy();
    mesh_cache.destroy();
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
      if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        // Its formats (RGBA8, DEPTH24) are ones every GL 3.3 has: incomplete, its storage was not
        // allocated (llvmpipe under a memory limit, with or without GL_OUT_OF_MEMORY).
        throw std::runtime_error("out of memory: the renderer could not allocate its framebuffer (" + std::to_string(width) + "x" +
                                 std::to_string(height) + ", " + std::to_string(n) + " samples: incomplete)");
      }
    };
    makeTarget(0, resolve_fbo, resolve_color, resolve_depth);
    if (samples > 0) makeTarget(samples, msaa_fbo, msaa_color, msaa_depth);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
  }

  void drawItem(const gl::DrawItem& item) {
    glUniformMatrix4fv(shaded.model, 1, GL_FALSE, item.model.data());
    glUniformMatrix3fv(shaded.normal_matrix, 1, GL_FALSE, item.normal.data());
    glUniform3fv(shaded.stretch, 1, item.stretch.data());
    glUniform4f(shaded.color, item.color.r, item.color.g, item.color.b, item.color.a);
    // A mirroring box rotation flips the winding; keep culling the back faces (a file's mesh: both
    // sides drawn, as its winding is the file's).
    glFrontFace(item.model.topLeftCorner<3, 3>().determinant() < 0 ? GL_CW : GL_CCW);
    if (item.two_sided) {
      glDisable(GL_CULL_FACE);
      glUniform1i(shaded.two_sided, 1);
    }
    // Planes sit a little behind their depth (about 2 pixels of their slope), so lines on them win.
    if (item.pushed_back) {
      glEnable(GL_POLYGON_OFFSET_FILL);
      glPolygonOffset(2.0f, 2.0f);
    }
    item.mesh->draw();
    if (item.pushed_back) glDisable(GL_POLYGON_OFFSET_FILL);
    if (item.two_sided) {
      glEnable(GL_CULL_FACE);
      glUniform1i(shaded.two_sided, 0);
    }
  }

  // Polylines as screen-space quads of width_px, one draw per polyline.
  void drawPolylines(const std::vector<Polyline>& polylines, const Eigen::Matrix4f& view_proj,
                     bool translucent, int vw, int vh) {
    line_vertices.clear();
    std::vector<std::pair<GLint, GLsizei>> ranges;
    for (const auto& pl : polylines) {
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
    glUniform2f(line.viewport, float(vw), float(vh));
    glBindVertexArray(line_vao);
    glBindBuffer(GL_ARRAY_BUFFER, line_vbo);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(line_vertices.size() * sizeof(LineVertex)),
                 line_vertices.data(), GL_STREAM_DRAW);
    glDisable(GL_CULL_FACE);
    // Where lines overlap at the same depth (a path and the ink on a table), the later one wins.
    glDepthFunc(GL_LEQUAL);
    for (std::size_t i = 0; i < polylines.size(); ++i) {
      if (ranges[i].second == 0) continue;
      const auto& pl = polylines[i];
      glUniform1f(line.half_width, float(std::max(0.5, pl.width_px) / 2));
      glUniform4f(line.color, pl.color.r, pl.color.g, pl.color.b, pl.color.a);
      glDrawArrays(GL_TRIANGLES, ranges[i].first, ranges[i].second);
    }
    glDepthFunc(GL_LESS);
    glEnable(GL_CULL_FACE);
  }

  // Limits drawing (and clears) to the whole pixels inside a rectangle of the frame.
  void scissor(const PixelRect& r) {
    const int x0 = int(std::ceil(r.x)), y0 = int(std::ceil(r.y));
    const int x1 = int(std::floor(r.right())), y1 = int(std::floor(r.bottom()));
    glEnable(GL_SCISSOR_TEST);
    glScissor(x0, height - y1, x1 - x0, y1 - y0);
  }

  // Clears the part of `outer` outside `inner` (whole pixels) to colour c: the exact edge of a
  // clipped view (with 4x MSAA, llvmpipe lets a scissored edge bleed into the pixel beside it).
  void clearAround(const PixelRect& inner, const PixelRect& outer, const Color& c) {
    const double x0 = std::ceil(inner.x), y0 = std::ceil(inner.y), x1 = std::floor(inner.right()), y1 = std::floor(inner.bottom());
    glClearColor(c.r, c.g, c.b, c.a);
    for (const PixelRect& r : {PixelRect{outer.x, outer.y, x0 - outer.x, outer.h},
                               PixelRect{x1, outer.y, outer.right() - x1, outer.h},
                               PixelRect{x0, outer.y, x1 - x0, y0 - outer.y},
                               PixelRect{x0, y1, x1 - x0, outer.bottom() - y1}})
      if (!r.empty()) {
        scissor(r);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
      }
    glDisable(GL_SCISSOR_TEST);
  }

  // The scene's primitives under camera, in a viewport of vw x vh pixels: opaque meshes, the
  // planes' grids, polylines, then translucent meshes and lines.
  void drawContent(const Scene& scene, const Camera& camera, int vw, int vh) {
    const CameraBasis basis = camera.basis();
    const Eigen::Matrix4f view_proj = viewProjection(camera, vw, vh).cast<float>();
    // Key light from the upper left, in front of the scene; moves with the camera.
    const Vector3d light = (-0.45 * basis.right + 0.65 * basis.up + 0.75 * basis.back).normalized();
    glUseProgram(shaded.id);
    glUniformMatrix4fv(shaded.view_proj, 1, GL_FALSE, view_proj.data());
    glUniform3f(shaded.light_dir, float(light.x()), float(light.y()), float(light.z()));
    glUniform3f(shaded.view_dir, float(basis.back.x()), float(basis.back.y()), float(basis.back.z()));
    glUniform3f(shaded.eye, float(camera.eye.x()), float(camera.eye.y()), float(camera.eye.z()));
    glUniform1i(shaded.ortho, camera.ortho ? 1 : 0);

    // Opaque meshes in scene order.
    gl::collectDrawList(scene, camera, meshes, mesh_cache, vw, vh, draw_list);
    for (const auto& item : draw_list.items)
      if (item.color.a >= 1.0f) drawItem(item);
    // Grid lines on the planes: depth-tested but not written, so paths on a plane cover them.
    if (!draw_list.grid_lines.empty()) {
      glDepthMask(GL_FALSE);
      drawPolylines(draw_list.grid_lines, view_proj, false, vw, vh);
      glDepthMask(GL_TRUE);
    }
    // Opaque polylines (depth-tested, so the arm hides what is behind it).
    drawPolylines(scene.polylines, view_proj, false, vw, vh);

    // Translucent meshes: a depth-only pass first, so overlapping parts of a ghost (capsule
    // ends, joints) blend once as one surface; then colour far to near, blended, no depth writes.
    std::vector<const gl::DrawItem*> translucent;
    for (const auto& item : draw_list.items)
      if (item.color.a < 1.0f) translucent.push_back(&item);
    std::stable_sort(translucent.begin(), translucent.end(),
                     [](const gl::DrawItem* a, const gl::DrawItem* b) { return a->depth > b->depth; });
    glUseProgram(shaded.id);
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    for (const gl::DrawItem* item : translucent) drawItem(*item);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glEnable(GL_BLEND);
    glDepthMask(GL_FALSE);
    glDepthFunc(GL_LEQUAL);
    for (const gl::DrawItem* item : translucent) drawItem(*item);
    glDepthFunc(GL_LESS);
    glFrontFace(GL_CCW);
    // Translucent lines last.
    drawPolylines(scene.polylines, view_proj, true, vw, vh);
    glDepthMask(GL_TRUE);
    glDisable(GL_BLEND);
    glBindVertexArray(0);
  }

  void draw(const Scene& scene, const Overlay* panel) {
    mesh_cache.sweep();  // meshes no scene holds any more
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

    // The panel's layout first: a fitted scene goes in the part of the frame it leaves free.
    const bool show_panel = options.show_overlay && panel;
    panel_rect = {};
    if (show_panel) {
      if (!overlay) overlay = std::make_unique<gl::OverlayPanel>(width, height, context.glsl());
      panel_rect = overlay->layout(*panel);
    }
    camera = scene.camera;
    scene_rect = {0, 0, double(width), double(height)};
    if (scene.framing.fit) {
      const Eigen::AlignedBox3d box = scene.framing.bounds.isEmpty() ? sceneBounds(scene) : scene.framing.bounds;
      // As far from the panel as the panel is from the frame's edge; the points' picture when given.
      const auto& points = scene.framing.points;
      if (points.empty()) {
        scene_rect = freeRect(width, height, panel_rect, camera, box, panel_rect.x);
        camera = fitCamera(camera, box, width, height, scene_rect, scene.framing.margin);
      } else {
        scene_rect = freeRect(width, height, panel_rect, camera, points, panel_rect.x);
        camera = fitCamera(camera, points, width, height, scene_rect, scene.framing.margin);
      }
    }

    // The whole scene is cleared to its background; a clipped one is drawn only in its free part.
    const bool clip = scene.framing.fit && scene.framing.clip;
    if (clip) scissor(scene_rect);
    drawContent(scene, camera, width, height);
    glDisable(GL_SCISSOR_TEST);
    if (clip) clearAround(scene_rect, {0, 0, double(width), double(height)}, bg);
    // Insets over corners of the free part: a border, the inset's background, its scene fitted in.
    inset_rects.clear();
    inset_cameras.clear();
    for (const Inset& inset : scene.insets) {
      const PixelRect outer = insetRect(scene_rect, inset);
      const double b = std::round(std::clamp(inset.border_px, 0.0, 0.25 * std::min(outer.w, outer.h)));
      const PixelRect inner{outer.x + b, outer.y + b, outer.w - 2 * b, outer.h - 2 * b};
      if (inner.empty()) continue;
      const Color& back = inset.scene.background;
      scissor(inner);
      glClearColor(back.r, back.g, back.b, back.a);
      glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
      const int iw = int(inner.w), ih = int(inner.h);
      glViewport(int(inner.x), height - int(inner.y) - ih, iw, ih);
      Camera view = inset.scene.camera;
      if (inset.scene.framing.fit) {
        const Eigen::AlignedBox3d box =
            inset.scene.framing.bounds.isEmpty() ? sceneBounds(inset.scene) : inset.scene.framing.bounds;
        const PixelRect all{0, 0, double(iw), double(ih)};
        const auto& points = inset.scene.framing.points;
        view = points.empty() ? fitCamera(view, box, iw, ih, all, inset.scene.framing.margin)
                              : fitCamera(view, points, iw, ih, all, inset.scene.framing.margin);
      }
      drawContent(inset.scene, view, iw, ih);
      glDisable(GL_SCISSOR_TEST);
      glViewport(0, 0, width, height);
      clearAround(inner, outer, inset.border);
      inset_rects.push_back(inner);
      inset_cameras.push_back(view);
    }

    // Resolve the samples into the single-sample framebuffer that read() uses.
    if (samples > 0) {
      glBindFramebuffer(GL_READ_FRAMEBUFFER, msaa_fbo);
      glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolve_fbo);
      glBlitFramebuffer(0, 0, width, height, 0, 0, width, height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    }

    // The panel on top, after the resolve: ImGui anti-aliases itself, so it skips the 4x
    // samples (its own GL state is restored by the backend).
    if (show_panel) {
      glBindFramebuffer(GL_FRAMEBUFFER, resolve_fbo);
      glDisable(GL_DEPTH_TEST);
      overlay->render();
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

const Camera& Renderer::camera() const { return impl_->camera; }

PixelRect Renderer::panelRect() const { return impl_->panel_rect; }

PixelRect Renderer::sceneRect() const { return impl_->scene_rect; }

const std::vector<PixelRect>& Renderer::insetRects() const { return impl_->inset_rects; }

const std::vector<Camera>& Renderer::insetCameras() const { return impl_->inset_cameras; }

int Renderer::width() const { return impl_->width; }

int Renderer::height() const { return impl_->height; }

Matrix4d Renderer::viewProjection(const Camera& camera, int width, int height) {
  const CameraBasis b = camera.basis();
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
