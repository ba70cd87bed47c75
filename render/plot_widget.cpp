// The live plot with a y scale; see plot_widget.h.
#include "render/plot_widget.h"

#include <imgui.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace dyn {
namespace {

// x as the label of a scale whose step is `step`: fixed decimals for everyday magnitudes, else
// as many significant digits as the step needs.
std::string label(double x, double step, double magnitude) {
  char b[48];
  const int step_exp = int(std::floor(std::log10(step) + 1e-9));
  if (magnitude < 1e6 && step_exp >= -4) {
    std::snprintf(b, sizeof b, "%.*f", std::max(0, -step_exp), x);
  } else {
    const int digits = std::clamp(int(std::floor(std::log10(magnitude))) - step_exp + 1, 1, 12);
    std::snprintf(b, sizeof b, "%.*g", digits, x);
  }
  std::string s = b;
  if (s.find_first_not_of("-0.") == std::string::npos) s = "0";  // never "-0.00"
  return s;
}

}  // namespace

PlotScale plotScale(double lo, double hi) {
  if (!(std::isfinite(lo) && std::isfinite(hi))) lo = 0, hi = 1;
  if (lo > hi) std::swap(lo, hi);
  if (hi - lo <= 1e-12 * std::max(std::abs(lo), std::abs(hi)) || hi - lo < 1e-300) {
    // Flat: a range around the value, a tenth of it each way (or ±1 around zero).
    const double d = lo != 0 ? 0.1 * std::abs(lo) : 1.0;
    lo -= d, hi += d;
  }
  // A round step of about a fifth of the span; the range out to whole steps.
  const double raw = (hi - lo) / 5;
  double step = std::pow(10.0, std::floor(std::log10(raw)));
  if (raw / step >= 5) step *= 5;
  else if (raw / step >= 2) step *= 2;
  PlotScale s;
  s.hi = std::ceil(hi / step - 1e-9) * step;
  s.lo = std::floor(lo / step + 1e-9) * step;
  const double magnitude = std::max(std::abs(s.lo), std::abs(s.hi));
  s.top = label(s.hi, step, magnitude);
  s.bottom = label(s.lo, step, magnitude);
  return s;
}

namespace {
// The range of the finite values, rounded out.
PlotScale valueScale(const std::vector<float>& values) {
  double lo = INFINITY, hi = -INFINITY;
  for (float v : values)
    if (std::isfinite(v)) lo = std::min(lo, double(v)), hi = std::max(hi, double(v));
  return lo > hi ? plotScale(0, 1) : plotScale(lo, hi);
}
}  // namespace

float plotGutter(const std::vector<float>& values) {
  const PlotScale scale = valueScale(values);
  return std::max(ImGui::CalcTextSize(scale.top.c_str()).x, ImGui::CalcTextSize(scale.bottom.c_str()).x) +
         ImGui::GetStyle().ItemInnerSpacing.x;
}

void plotWithScale(const char* id, const std::vector<float>& values, const Color& color, float width, float height,
                   float line_width, float min_gutter) {
  ImGui::PushID(id);
  const ImVec2 p0 = ImGui::GetCursorScreenPos();
  ImGui::Dummy(ImVec2(width, height));
  ImDrawList* dl = ImGui::GetWindowDrawList();
  const ImGuiStyle& style = ImGui::GetStyle();

  // The range and its labels, in a gutter on the left.
  const PlotScale scale = valueScale(values);
  const float pad = style.ItemInnerSpacing.x;
  const ImVec2 top = ImGui::CalcTextSize(scale.top.c_str()), bottom = ImGui::CalcTextSize(scale.bottom.c_str());
  const float gutter = std::max(std::max(top.x, bottom.x) + pad, min_gutter);
  const ImVec2 f0(p0.x + gutter, p0.y), f1(p0.x + width, p0.y + height);
  const ImU32 muted = ImGui::GetColorU32(ImVec4(0.38f, 0.42f, 0.48f, 1.0f));
  dl->AddRectFilled(f0, f1, ImGui::GetColorU32(ImGuiCol_FrameBg), style.FrameRounding);
  dl->AddText(ImVec2(f0.x - pad - top.x, f0.y), muted, scale.top.c_str());
  dl->AddText(ImVec2(f0.x - pad - bottom.x, f1.y - bottom.y), muted, scale.bottom.c_str());

  // Value -> pixel row inside the frame (a line's width in from its edges).
  const float inset = std::max(2.0f, line_width);
  const float x0 = f0.x + inset, x1 = f1.x - inset, y0 = f0.y + inset, y1 = f1.y - inset;
  auto yOf = [&](double v) { return float(y1 - (v - scale.lo) / (scale.hi - scale.lo) * (y1 - y0)); };
  if (scale.lo < 0 && scale.hi > 0)
    dl->AddLine(ImVec2(x0, yOf(0)), ImVec2(x1, yOf(0)), ImGui::GetColorU32(ImVec4(0.6f, 0.62f, 0.66f, 0.6f)),
                std::max(1.0f, 0.5f * line_width));

  // The curve: every value. With more values than columns, a column whose values span more than
  // a line's width goes through their smallest and largest in order (a fast ripple shows as the
  // band it fills, never aliased away); a quieter one is one point, its last value.
  std::vector<ImVec2> points;
  const std::size_t n = values.size();
  const int columns = std::max(2, int(x1 - x0));
  auto add = [&](float x, float v) {
    if (std::isfinite(v)) points.emplace_back(x, yOf(v));
  };
  if (n <= std::size_t(columns)) {
    for (std::size_t i = 0; i < n; ++i) add(n > 1 ? x0 + (x1 - x0) * float(i) / float(n - 1) : x1, values[i]);
  } else {
    for (int c = 0; c < columns; ++c) {
      const std::size_t a = n * std::size_t(c) / std::size_t(columns), b = n * std::size_t(c + 1) / std::size_t(columns);
      std::size_t lo_i = a, hi_i = a;
      for (std::size_t i = a; i < b; ++i) {
        if (values[i] < values[lo_i]) lo_i = i;
        if (values[i] > values[hi_i]) hi_i = i;
      }
      const float x = x0 + (x1 - x0) * float(c) / float(columns - 1);
      if (yOf(values[lo_i]) - yOf(values[hi_i]) > line_width) {
        add(x, values[std::min(lo_i, hi_i)]);
        add(x, values[std::max(lo_i, hi_i)]);
      }
      add(x, values[b - 1]);
    }
  }
  const ImU32 col = ImGui::GetColorU32(ImVec4(color.r, color.g, color.b, 1.0f));
  if (points.size() == 1) dl->AddCircleFilled(points[0], line_width + 1, col);
  else if (points.size() > 1) dl->AddPolyline(points.data(), int(points.size()), col, ImDrawFlags_None, line_width);
  ImGui::PopID();
}

}  // namespace dyn
