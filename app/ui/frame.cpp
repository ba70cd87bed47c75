// One frame of the tuning window (frame.h): the same code for dynlab-ui's GLFW window and the page's
// WebGL 2 canvas.
#include "app/ui/frame.h"

#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include <algorithm>
#include <stdexcept>
#include <string>

#include "render/fonts.h"

namespace dyn::ui {

Layout layout(int fb_w, int fb_h) {
  Layout l;
  l.panel_w = std::min(std::clamp(int(fb_w * 0.34), 380, 520), fb_w);
  l.panel_x = fb_w - l.panel_w;
  l.scene_w = l.panel_x & ~1;
  l.scene_h = fb_h & ~1;
  return l;
}

void setupImGui(GLFWwindow* window, const WindowContext& context) {
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;  // nothing written next to the student's files
  // The overlay's font (render/fonts.h): Greek, ±, ≤, −, x₁, … in the notes and units; a missing
  // font file is a one-line error.
  addUiFont(*io.Fonts, 15.0f);
  ImGui::StyleColorsLight();
  ImGuiStyle& style = ImGui::GetStyle();
  style.WindowRounding = 0.0f;
  style.FrameRounding = 3.0f;
  style.Colors[ImGuiCol_WindowBg] = ImVec4(0.97f, 0.97f, 0.98f, 1.0f);
  style.Colors[ImGuiCol_TitleBgActive] = style.Colors[ImGuiCol_TitleBg] = ImVec4(0.22f, 0.29f, 0.38f, 1.0f);
  style.Colors[ImGuiCol_Text] = ImVec4(0.12f, 0.14f, 0.17f, 1.0f);
  // A slider's knob is a thin, light bar: the value's digits drawn over it stay readable.
  style.GrabMinSize = 4.0f;
  style.GrabRounding = 1.0f;
  style.Colors[ImGuiCol_SliderGrab] = ImVec4(0.26f, 0.59f, 0.98f, 0.55f);
  style.Colors[ImGuiCol_SliderGrabActive] = ImVec4(0.26f, 0.59f, 0.98f, 0.75f);
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  if (!ImGui_ImplOpenGL3_Init(glslVersion(context.glsl()))) throw std::runtime_error("Dear ImGui OpenGL3 backend failed to initialise");
}

void shutdownImGui() {
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
}

void TuningFrame::advance(TuningSession& session, PanelState& st, double wall) {
  if (st.playing && session.lab() && !session.finished()) {
    carry_ += st.speed * wall / session.lab()->dt();
    const long n = long(carry_);
    carry_ -= double(n);
    session.advance(n);
  } else {
    carry_ = 0;
  }
  if (st.loop && session.finished() && session.problem().empty()) session.restart();
}

Layout TuningFrame::draw(TuningSession& session, PanelState& st, WindowContext& ctx,
                         const std::function<void(const Layout&)>& extra) {
  const Layout l = layout(ctx.width(), ctx.height());
  std::string scene_error;
  Scene scene;
  Overlay overlay;
  if (session.hasRows()) {
    try {
      session.lab()->scene(session.primary(), session.row(), session.ghost(), scene);
      session.lab()->overlay(session.primary(), session.row(), overlay);
    } catch (const std::exception& e) {
      scene_error = std::string("cannot draw the scene: ") + e.what();
    }
  }
  ctx.clear(scene.background);  // the letterbox around the scene matches it
  if (session.hasRows() && scene_error.empty() && l.scene_w >= 16 && l.scene_h >= 16) {
    try {
      if (!renderer_ || renderer_->width() != l.scene_w || renderer_->height() != l.scene_h) {
        RenderOptions o;
        o.width = l.scene_w;
        o.height = l.scene_h;
        renderer_.reset();
        renderer_ = std::make_unique<Renderer>(ctx, o);
      }
      renderer_->draw(scene, &overlay);
      renderer_->present(l.scene_x, l.scene_y, ctx.height());
    } catch (const std::exception& e) {
      scene_error = std::string("cannot draw the scene: ") + e.what();
    }
  }
  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  // Two frames at the same clock reading (a browser's virtual time) give no time step: 1.86 asserts.
  if (ImGui::GetIO().DeltaTime <= 0.0f) ImGui::GetIO().DeltaTime = 1.0f / 60.0f;
  ImGui::NewFrame();
  const float scale = std::max(ImGui::GetIO().DisplayFramebufferScale.x, 1e-3f);
  const std::string shown = !scene_error.empty() ? scene_error : !session.hasRows() ? "no run: " + session.problem() : "";
  if (!shown.empty())
    ImGui::GetBackgroundDrawList()->AddText(ImVec2(20, 20), IM_COL32(160, 30, 20, 255), shown.c_str());
  drawTuningPanel(session, st, float(l.panel_x) / scale, float(l.panel_w) / scale, float(ctx.height()) / scale);
  if (extra) extra(l);
  ImGui::Render();
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  return l;
}

}  // namespace dyn::ui
