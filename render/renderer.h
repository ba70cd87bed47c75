// Renderer: draws a Scene (labs/scene.h) with a shaded primitive pass, an optional Dear ImGui
// overlay panel, 4× MSAA, and reads the frame back as an Image. A scene that asks to be fitted
// (Scene::framing) gets its camera placed in the part of the frame the panel leaves free.
#pragma once
#include <memory>
#include <vector>

#include "labs/scene.h"
#include "render/framing.h"
#include "render/gl_context.h"
#include "render/image.h"

namespace dyn {

struct RenderOptions {
  int msaa = 4;           // samples; 0 or 1 disables
  bool show_overlay = true;
  int width = 0, height = 0;  // frame size; 0 takes the context's (a window draws the scene smaller)
};

class Renderer {
 public:
  // The context must be current and outlive the renderer.
  explicit Renderer(GlContext& context, RenderOptions options = {});
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Draws one frame; overlay may be null. Deterministic: same input, same pixels.
  void draw(const Scene& scene, const Overlay* overlay);
  // Reads the last drawn frame (top row first).
  Image read() const;
  // draw + read.
  Image render(const Scene& scene, const Overlay* overlay) {
    draw(scene, overlay);
    return read();
  }

  // Copies the last frame into the default framebuffer (a window's back buffer), its top-left
  // corner at pixel (x, y) counted from the top of a target_height-tall framebuffer. Exact copy.
  void present(int x, int y, int target_height) const;

  // The last frame's camera: the scene's own, or the one fitted into the free part of the frame
  // when the scene asks for it (Scene::framing); project() with it finds what was drawn where.
  const Camera& camera() const;
  // The last frame's overlay panel (empty without one) and the part of the frame the scene was
  // fitted into (the whole frame when the scene is not fitted).
  PixelRect panelRect() const;
  PixelRect sceneRect() const;
  // The last frame's insets (Scene::insets, in order): the rectangle each scene was drawn in (inside
  // its border) and its camera: project() with the rectangle's w x h, offset by its x, y.
  const std::vector<PixelRect>& insetRects() const;
  const std::vector<Camera>& insetCameras() const;

  // Waits until the GPU (llvmpipe) has finished the last draw; for timing without read().
  void finish();
  int width() const;
  int height() const;

  // World point -> pixel (x right, y down) under the scene camera; for tests and labels.
  static Eigen::Vector2d project(const Camera& camera, int width, int height,
                                 const Eigen::Vector3d& world);
  // The projection * view matrix used for drawing (GL clip space, aspect from width/height).
  static Eigen::Matrix4d viewProjection(const Camera& camera, int width, int height);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dyn
