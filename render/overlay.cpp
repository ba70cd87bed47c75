// The Dear ImGui overlay: a light panel in the top-left corner with the lab's title, aligned
// label/value lines and one line plot per series. Deterministic: fixed time step, no inputs,
// no ini file, and every frame is built twice so auto-sizing never lags or hides the panel.
#include <imgui.h>
#include <imgui_impl_opengl3.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "render/gl_internal.h"

namespace dyn::gl {
namespace {

ImVec4 toImVec4(const Color& c) { return ImVec4(c.r, c.g, c.b, c.a); }

// A calm light theme that sits on the pale scene background.
void applyStyle() {
  ImGui::StyleColorsLight();
  ImGuiStyle& style = ImGui::GetStyle();
  style.WindowRounding = 6.0f;
  style.FrameRounding = 3.0f;
  style.WindowBorderSize = 1.0f;
  style.WindowPadding = ImVec2(10, 8);
  style.ItemSpacing = ImVec2(8, 4);
  ImVec4* c = style.Colors;
  c[ImGuiCol_WindowBg] = ImVec4(1.00f, 1.00f, 1.00f, 0.90f);
  c[ImGuiCol_Border] = ImVec4(0.70f, 0.72f, 0.76f, 0.60f);
  c[ImGuiCol_TitleBg] = ImVec4(0.22f, 0.29f, 0.38f, 0.95f);
  c[ImGuiCol_TitleBgActive] = c[ImGuiCol_TitleBg];
  c[ImGuiCol_TitleBgCollapsed] = c[ImGuiCol_TitleBg];
  c[ImGuiCol_Text] = ImVec4(0.12f, 0.14f, 0.17f, 1.00f);
  c[ImGuiCol_FrameBg] = ImVec4(0.93f, 0.94f, 0.96f, 1.00f);
}

}  // namespace

namespace {
// The panel has its own Dear ImGui context; whoever else uses ImGui (the tuning window) gets its
// current context back afterwards.
struct KeepImGuiContext {
  ImGuiContext* saved = ImGui::GetCurrentContext();
  ~KeepImGuiContext() { ImGui::SetCurrentContext(saved); }
};
}  // namespace

OverlayPanel::OverlayPanel(int width, int height) {
  const KeepImGuiContext keep;
  context_ = ImGui::CreateContext();
  ImGui::SetCurrentContext(context_);
  ImGuiIO& io = ImGui::GetIO();
  io.IniFilename = nullptr;  // no imgui.ini next to the program
  io.LogFilename = nullptr;
  io.DisplaySize = ImVec2(float(width), float(height));
  io.DisplayFramebufferScale = ImVec2(1, 1);
  io.DeltaTime = 1.0f / 30.0f;  // fixed: output must not depend on wall-clock time
  io.ConfigFlags |= ImGuiConfigFlags_NoMouseCursorChange;
  // A 1080p still reads like a 480p frame: the panel grows by whole multiples of its 480p size.
  scale_ = float(std::max(1, int(std::lround(height / 480.0))));
  ImFontConfig font;
  font.SizePixels = 13.0f * scale_;
  io.Fonts->AddFontDefault(&font);
  applyStyle();
  ImGui::GetStyle().ScaleAllSizes(scale_);
  if (!ImGui_ImplOpenGL3_Init("#version 330 core")) {
    ImGui::DestroyContext(context_);
    throw std::runtime_error("render: Dear ImGui OpenGL3 backend failed to initialise");
  }
}

OverlayPanel::~OverlayPanel() {
  ImGuiContext* saved = ImGui::GetCurrentContext();
  ImGui::SetCurrentContext(context_);
  ImGui_ImplOpenGL3_Shutdown();
  ImGui::DestroyContext(context_);
  ImGui::SetCurrentContext(saved == context_ ? nullptr : saved);
}

void OverlayPanel::buildFrame(const Overlay& overlay) {
  ImGuiIO& io = ImGui::GetIO();
  io.DeltaTime = 1.0f / 30.0f;
  io.MousePos = ImVec2(-FLT_MAX, -FLT_MAX);  // no pointer: nothing hovers
  ImGui_ImplOpenGL3_NewFrame();
  ImGui::NewFrame();

  // Column layout from the text itself: labels left, values aligned after the widest label.
  float label_w = 0, value_w = 0;
  for (const auto& [label, value] : overlay.lines) {
    label_w = std::max(label_w, ImGui::CalcTextSize(label.c_str()).x);
    value_w = std::max(value_w, ImGui::CalcTextSize(value.c_str()).x);
  }
  const float gap = 16.0f * scale_;
  const float title_w = ImGui::CalcTextSize(overlay.title.c_str()).x + 8.0f * scale_;
  const float plot_w = 240.0f * scale_, plot_h = 48.0f * scale_;
  float content_w = std::max({label_w + gap + value_w, title_w, 160.0f * scale_});
  if (!overlay.plots.empty()) content_w = std::max(content_w, plot_w);

  // Fixed place and width; height fits the content (built twice per draw, so never stale).
  ImGui::SetNextWindowPos(ImVec2(10 * scale_, 10 * scale_), ImGuiCond_Always);
  ImGui::SetNextWindowSize(ImVec2(content_w + 2 * ImGui::GetStyle().WindowPadding.x, 0),
                           ImGuiCond_Always);
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoMove |
                                 ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoSavedSettings |
                                 ImGuiWindowFlags_NoScrollbar | ImGuiWindowFlags_NoInputs |
                                 ImGuiWindowFlags_NoFocusOnAppearing | ImGuiWindowFlags_NoNav;
  const std::string title = (overlay.title.empty() ? std::string("dynlab") : overlay.title) +
                            "###dynlab_overlay";
  // Light title text on the dark title bar (the title is drawn inside Begin).
  ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(0.97f, 0.98f, 1.0f, 1.0f));
  ImGui::Begin(title.c_str(), nullptr, flags);
  ImGui::PopStyleColor();

  // Label/value lines.
  const ImVec4 muted(0.38f, 0.42f, 0.48f, 1.0f);
  for (const auto& [label, value] : overlay.lines) {
    ImGui::TextColored(muted, "%s", label.c_str());
    ImGui::SameLine(ImGui::GetStyle().WindowPadding.x + label_w + gap);
    ImGui::TextUnformatted(value.c_str());
  }
  if (!overlay.lines.empty() && !overlay.plots.empty()) ImGui::Separator();

  // One plot per series: coloured name with the latest value, then the curve.
  for (std::size_t i = 0; i < overlay.plots.size(); ++i) {
    const Series& s = overlay.plots[i];
    ImVec4 color = toImVec4(s.color);
    color.w = 1.0f;
    ImGui::TextColored(color, "%s", s.name.c_str());
    if (!s.values.empty()) {
      char latest[32];
      std::snprintf(latest, sizeof latest, "%.4g", double(s.values.back()));
      ImGui::SameLine(ImGui::GetStyle().WindowPadding.x + content_w -
                      ImGui::CalcTextSize(latest).x);
      ImGui::TextUnformatted(latest);
    }
    ImGui::PushID(int(i));
    ImGui::PushStyleColor(ImGuiCol_PlotLines, color);
    ImGui::PushStyleColor(ImGuiCol_PlotLinesHovered, color);
    ImGui::PlotLines("##plot", s.values.data(), int(s.values.size()), 0, nullptr, FLT_MAX,
                     FLT_MAX, ImVec2(content_w, plot_h));
    ImGui::PopStyleColor(2);
    ImGui::PopID();
  }
  ImGui::End();
  ImGui::Render();
}

void OverlayPanel::draw(const Overlay& overlay) {
  const KeepImGuiContext keep;
  ImGui::SetCurrentContext(context_);
  // First pass settles the auto-fitted height (and un-hides a new window); second is drawn.
  buildFrame(overlay);
  buildFrame(overlay);
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}

}  // namespace dyn::gl
