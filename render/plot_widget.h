// A small live plot with a y scale, for the overlay panel in frames and stills and for the tuning
// window: the curve in a frame, its top and bottom values written beside it (a ±0.03 N ripple
// reads as ±0.03 N, never as full-scale), a faint line at zero when zero is in range, and every
// value drawn: with more values than pixel columns, each column shows the range of its values.
#pragma once
#include <string>
#include <vector>

#include "labs/scene.h"

namespace dyn {

// The y range a plot shows for values in [lo, hi], widened to round numbers (at most two steps of
// about a fifth of the span), and its two labels: as many digits as the step needs ("-4.97" over
// "-5.03"; "1.2e-14" for tiny values). A flat series gets a range around its value.
struct PlotScale {
  double lo = 0, hi = 1;
  std::string top, bottom;
};
PlotScale plotScale(double lo, double hi);

// Draws the plot as the next item of the current Dear ImGui window (size in pixels, the labels
// included); line_width in pixels. Non-finite values are left out. The labels take a gutter on
// the left at least min_gutter wide (plots stacked with the largest plotGutter() line up).
void plotWithScale(const char* id, const std::vector<float>& values, const Color& color, float width, float height,
                   float line_width = 1.0f, float min_gutter = 0.0f);
// The gutter width these values' labels need in the current Dear ImGui font.
float plotGutter(const std::vector<float>& values);

}  // namespace dyn
