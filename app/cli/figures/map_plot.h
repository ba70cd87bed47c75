// Drawing a stability/score map (dynlab map) with PLplot: one filled cell per grid point (stable or
// unstable, or a metric's value on a colour scale), the screening's boundary as the zero contour of
// a field, axis labels with units, a legend and (for values) a colour bar. PNG (pngcairo), SVG (svg)
// or PDF (pdfcairo, its creation date pinned), by the file's extension; the same map gives the
// same bytes. Written to path + ".tmp", then renamed.
#pragma once
#include <string>
#include <vector>

namespace dyn::app {

struct MapPicture {
  std::string title, xlabel, ylabel;
  std::vector<double> xs, ys;   // grid coordinates, increasing or decreasing
  std::vector<int> stable;      // xs.size() × ys.size(), index j * nx + i: 1 stable, 0 unstable
  std::vector<double> value;    // empty, or a metric per point (drawn where stable and finite)
  std::string value_label;      // the colour bar's label
  std::vector<double> boundary; // empty, or a field whose zero level is drawn as the boundary
  std::string stable_label, unstable_label, boundary_label;
};

// Throws std::runtime_error naming the path on failure (bad extension, unwritable, PLplot error).
void writeMapPicture(const std::string& path, const MapPicture& map, int width_px = 900, int height_px = 600);

}  // namespace dyn::app
