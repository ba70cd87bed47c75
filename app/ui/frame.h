// One frame of the tuning window: advance the run by the wall time that passed, draw the lab's scene
// (render/'s Renderer, blitted left of the panel) and the tuning panel (panel.h) into the window's
// framebuffer. Shared by dynlab-ui (main.cpp, a GLFW window) and the page (app/web/page_main.cpp,
// a WebGL 2 canvas): the same layout, scene and widgets in both.
#pragma once
#include <functional>
#include <memory>

#include "app/ui/panel.h"
#include "render/renderer.h"
#include "render/window_context.h"

struct GLFWwindow;

namespace dyn::ui {

// Where the scene goes in the window: all of it left of the panel (the renderer fits the lab's
// scene into whatever that leaves beside the overlay panel).
struct Layout {
  int scene_x = 0, scene_y = 0, scene_w = 0, scene_h = 0;  // framebuffer pixels, y from the top
  int panel_x = 0, panel_w = 0;
};
Layout layout(int fb_w, int fb_h);

// Dear ImGui for the window: its font and style, the GLFW and OpenGL3 backends (the shading
// language the context names). Throws std::runtime_error when the backend cannot start.
void setupImGui(GLFWwindow* window, const WindowContext& context);
void shutdownImGui();

class TuningFrame {
 public:
  // The run advances speed × wall seconds in fixed lab steps (the fraction carried to the next
  // frame), or restarts when it loops.
  void advance(TuningSession& session, PanelState& st, double wall);
  // Clears the window, draws the scene and the panel, then `extra` (more ImGui, may be empty) and
  // renders ImGui. Returns the layout it drew.
  Layout draw(TuningSession& session, PanelState& st, WindowContext& ctx,
              const std::function<void(const Layout&)>& extra = {});
  void release() { renderer_.reset(); }  // before the context goes

 private:
  std::unique_ptr<Renderer> renderer_;
  double carry_ = 0;
};

}  // namespace dyn::ui
