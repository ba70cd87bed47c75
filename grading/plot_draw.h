// The drawing half of grading/plot: what a spec becomes on a PLplot stream. plot.cpp owns the
// stream and the file; this part prepares the data (log y, which series are faint, axis ranges)
// and draws frame, ticks, data and legend. Internal to grading/plot.
#pragma once
#include <cmath>
#include <string>
#include <vector>

#include "grading/plot.h"

namespace dyn::plot_detail {

struct Range {
  double lo = INFINITY, hi = -INFINITY;
  void add(double v);
  bool empty() const { return lo > hi; }
  void widenIfFlat();  // a degenerate range becomes a small symmetric one around its value
};

// A spec ready to draw: y already log10 when the scale is log, axis ranges fixed, faint series
// marked (drawn first, thin and translucent).
struct Prepared {
  PlotSpec spec;
  Range xr, yr;
  bool log_y = false;
  std::vector<bool> faint;  // per series
};

// Checks the spec and prepares it; throws std::runtime_error("writePlot <path>: ...") when there
// is nothing to draw.
Prepared prepare(const std::string& path, const PlotSpec& spec);

// Draws p on the current, initialised PLplot stream of width × height pixels.
PlotLayout draw(const Prepared& p, int width_px, int height_px);

// The colour slots draw() uses; set once per stream before plinit.
void setColours();

}  // namespace dyn::plot_detail
