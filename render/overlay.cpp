// The Dear ImGui overlay: a light panel in the top-left corner with the lab's title, aligned
// label/value lines and one plot per series, with its y scale (render/plot_widget.h). Deterministic: fixed time step, no inputs,
// no ini file, and every frame is built twice so auto-sizing never lags or hides the panel.
#include <imgui.h>
#include <imgui_impl_opengl3.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "labs/utf8.h"
#include "render/fonts.h"
#include "render/gl_internal.h"
#include "render/plot_widget.h"

namespace dyn::gl {
namespace {

ImVec4 toImVec4(const Color& c) { return ImVec4(c.r, c.g, c.b, c.a); }

// The longest start of text (cut between UTF-8 characters) that fits in width with "...".
std::string elide(const std::string& text, float width) {
  if (ImGui::CalcTextSize(text.c_str()).x <= width) return text;
  std::string cut = text;
  while (!cut.empty()) {
    // Drop the last character: back to its first byte (not a 10xxxxxx continuation byte).
    std::size_t n = cut.size() - 1;
    while (n > 0 && (static_cast<unsigned char>(cut[n]) & 0xC0) == 0x80) --n;
    cut.resize(n);
    if (ImGui::CalcTextSize((cut + "...").c_str()).x <= width) break;
  }
  return cut + "...";
}

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

OverlayPanel::OverlayPanel(int width, int height, Glsl dialect) {
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
  // A 1080p still reads like a 480p frame: the panel grows by whole multiples of its 480p size,
  // the next one from 1.8x the height on (720p keeps the 480p panel and leaves the scene room).
  scale_ = float(std::max(1, int(std::floor(height / 480.0 + 0.2))));
  try {
    addUiFont(*io.Fonts, 13.0f * scale_);  // DejaVu Sans: Greek and the math operators too
  } catch (...) {
    ImGui::DestroyContext(context_);
    throw;
  }
  applyStyle();
  ImGui::GetStyle().ScaleAllSizes(scale_);
  if (!ImGui_ImplOpenGL3_Init(glslVersion(dialect))) {
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

  // Text from a file (a lab's title, a model file's name) shown escaped and clipped (termName):
  // no control character reaches ImGui and no 200 kB name is measured.
  std::vector<std::pair<std::string, std::string>> lines;
  for (const auto& [label, value] : overlay.lines) lines.emplace_back(termName(label), termName(value));
  // Column layout from the text itself: labels left, values aligned after the widest label.
  float label_w = 0, value_w = 0;
  for (const auto& [label, value] : lines) {
    label_w = std::max(label_w, ImGui::CalcTextSize(label.c_str()).x);
    value_w = std::max(value_w, ImGui::CalcTextSize(value.c_str()).x);
  }
  const float gap = 16.0f * scale_;
  const std::string title = overlay.title.empty() ? std::string("dynlab") : termName(overlay.title);
  const float title_w = ImGui::CalcTextSize(title.c_str()).x + 8.0f * scale_;
  const float plot_w = 240.0f * scale_, plot_h = 48.0f * scale_;
  float content_w = std::max(label_w + gap + value_w, 160.0f * scale_);
  if (!overlay.plots.empty()) content_w = std::max(content_w, plot_w);
  // A long title widens the panel up to 40 % of the frame, never more: the scene needs the rest.
  const ImVec2 pad = ImGui::GetStyle().WindowPadding;
  content_w = std::max(content_w, std::min(title_w, 0.4f * ImGui::GetIO().DisplaySize.x - 2 * pad.x));
  const bool title_fits = title_w <= content_w;

  // Fixed place and width; height fits the content (built twice per draw, so never stale).
  ImGui::SetNextWindowPos(ImVec2(10 * scale_, 10 * scale_), ImGuiCond_Always);
  ImGui::SetNextWindowSize(ImVec2(content_w + 2 * pad.x, 0), ImGuiCond_Always);
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoMove |
                                 ImGuiWindowFlags_NoCollapse | ImGuiWindowFlags_NoSavedSettings |
                                 ImGuiWindowFlags_NoScrollbar | ImGuiWindowFlags_NoInputs |
                                 ImGuiWindowFlags_NoFocusOnAppearing | ImGuiWindowFlags_NoNav;
  // The window's own label is empty (a title's "##" would mean something to ImGui); the title is
  // drawn on the bar by hand: whole, or cut short with "..." and then written out in full, wrapped,
  // as the panel's first line.
  ImGui::Begin("###dynlab_overlay", nullptr, flags);
  const std::string bar = title_fits ? title : elide(title, content_w - 8.0f * scale_);
  const ImVec2 at(ImGui::GetWindowPos().x + ImGui::GetStyle().FramePadding.x, ImGui::GetWindowPos().y + ImGui::GetStyle().FramePadding.y);
  ImGui::GetForegroundDrawList()->AddText(at, ImGui::GetColorU32(ImVec4(0.97f, 0.98f, 1.0f, 1.0f)), bar.c_str());
  if (!title_fits) {
    ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + content_w);
    ImGui::TextUnformatted(title.c_str());
    ImGui::PopTextWrapPos();
    ImGui::Separator();
  }

  // Label/value lines.
  const ImVec4 muted(0.38f, 0.42f, 0.48f, 1.0f);
  for (const auto& [label, value] : lines) {
    ImGui::TextColored(muted, "%s", label.c_str());
    ImGui::SameLine(ImGui::GetStyle().WindowPadding.x + label_w + gap);
    ImGui::TextUnformatted(value.c_str());
  }
  if (!overlay.lines.empty() && !overlay.plots.empty()) ImGui::Separator();

  // One plot per series: coloured name with the latest value, then the curve (their frames
  // lined up: one gutter for every y scale).
  float gutter = 0;
  for (const Series& s : overlay.plots) gutter = std::max(gutter, plotGutter(s.values));
  for (std::size_t i = 0; i < overlay.plots.size(); ++i) {
    const Series& s = overlay.plots[i];
    ImVec4 color = toImVec4(s.color);
    color.w = 1.0f;
    ImGui::TextColored(color, "%s", termName(s.name).c_str());
    if (!s.values.empty()) {
      char latest[32];
      std::snprintf(latest, sizeof latest, "%.4g", double(s.values.back()));
      ImGui::SameLine(ImGui::GetStyle().WindowPadding.x + content_w -
                      ImGui::CalcTextSize(latest).x);
      ImGui::TextUnformatted(latest);
    }
    ImGui::PushID(int(i));
    plotWithScale("##plot", s.values, s.color, content_w, plot_h, scale_, gutter);
    ImGui::PopID();
  }
  rect_ = {ImGui::GetWindowPos().x, ImGui::GetWindowPos().y, ImGui::GetWindowSize().x, ImGui::GetWindowSize().y};
  ImGui::End();
  ImGui::Render();
}

PixelRect OverlayPanel::layout(const Overlay& overlay) {
  const KeepImGuiContext keep;
  ImGui::SetCurrentContext(context_);
  // First pass settles the auto-fitted height (and un-hides a new window); the second is drawn.
  buildFrame(overlay);
  buildFrame(overlay);
  return rect_;
}

void OverlayPanel::render() {
  const KeepImGuiContext keep;
  ImGui::SetCurrentContext(context_);
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}

void OverlayPanel::draw(const Overlay& overlay) {
  layout(overlay);
  render();
}

}  // namespace dyn::gl
