// Response plots for grading feedback: time series, tolerance bands, shaded stretches of the x
// axis and event markers drawn with PLplot into a PNG, SVG or PDF file that a lecturer can put
// straight on a slide.
// PNG (pngcairo), SVG (PLplot's own svg device, text kept as text) and PDF (pdfcairo, its creation
// date pinned to 1980-01-01) are byte-deterministic for a given set of installed fonts and libraries.
#pragma once
#include <string>
#include <vector>

namespace dyn {

struct PlotSeries {
  std::string label;                 // legend text
  std::vector<double> x, y;
  // Dotted and DashDot: more curves of one run told apart in its colour (runSeries, several runs).
  enum class Style { Solid, Dashed, Dotted, DashDot } style = Style::Solid;
  int color = 0;                     // index into a fixed, colour-blind-safe palette
};

struct PlotBand {                    // a shaded tolerance band lo(x)..hi(x)
  std::string label;
  std::vector<double> x, lo, hi;
};

struct PlotSpan {                    // a hatched stretch x0..x1 of the whole height (e.g. "not scored")
  std::string label;
  double x0 = 0, x1 = 0;
};

enum class YScale { Linear, Log, Auto };  // Auto: log when the data are ≥ 0 and span over 3 decades

struct PlotSpec {
  std::string title, xlabel, ylabel;
  std::vector<PlotSpan> spans;       // drawn first (hatched)
  std::vector<PlotBand> bands;       // light fill, over spans and faint series
  std::vector<PlotSeries> series;
  std::vector<double> vlines;        // vertical markers, e.g. the time a run went unstable
  std::string vline_label;           // legend text for the markers (optional)
  YScale y_scale = YScale::Linear;
  double font_scale = 1.0;           // text size relative to the picture's default
  // x–y (parametric) plots: x is data like y (both axes get headroom, y is linear), and with
  // equal_aspect one unit is as long on both axes (a circle looks round): see equalAspect.
  bool parametric = false;
  bool equal_aspect = false;
};

// Where things landed, in pixels from the top-left corner (x0 < x1, y0 < y1).
struct PlotBox {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool empty() const { return x1 <= x0 || y1 <= y0; }
  bool overlaps(const PlotBox& o) const { return !empty() && !o.empty() && x0 < o.x1 && o.x0 < x1 && y0 < o.y1 && o.y0 < y1; }
};
struct PlotLayout {
  PlotBox frame;   // the data area
  PlotBox legend;  // empty when there is no legend; never overlaps the frame
  bool log_y = false;
  double x_lo = 0, x_hi = 0, y_lo = 0, y_hi = 0;  // the data the frame spans (log y: exponents)
};

// World ranges [x0, x1] × [y0, y1] shown in a frame of width × height (any length unit).
struct PlotWindow {
  double x0 = 0, x1 = 0, y0 = 0, y1 = 0;
};
// Equal scales: the narrower range (in data per length) is widened about its middle until one
// data unit spans as much of the frame along x as along y; the other is kept. Ranges must be
// non-empty and the frame positive.
PlotWindow equalAspect(const PlotWindow& w, double frame_width, double frame_height);

// Writes the plot as PNG (pngcairo) or SVG (svg) or PDF (pdf), chosen by the file extension, at
// width × height pixels (1 px = 1 pt: a PDF's page is that many points).
// Deterministic: the same spec gives the same bytes. Throws std::runtime_error naming the path
// on failure (bad extension, unwritable path, empty/ mismatched series). Non-finite y values are
// skipped (split the line), never passed to PLplot; axis ranges come from the finite data
// (a constant series gets a small symmetric range). Writes to path + ".tmp" then renames.
// Series are thinned to about two points per pixel column, keeping each bucket's min and max
// (spikes stay). Text and line widths scale with the picture (800 × 450 is the reference).
// Labels are UTF-8.
// Readable order: a series much rougher than another one (a noisy measurement beside the true
// signal) is drawn first, thin and translucent, under the bands and the other series; then the
// smooth solid series, then dashed ones (references) on top.
// The legend sits outside the frame — right of it when narrow, else below it — so it never
// covers data. Log y: values ≤ 0 are left out; ticks at powers of ten.
// Parametric plots: spans and vertical markers are not drawn (x is not time); with equal_aspect
// the ranges are widened to the frame's shape, then the frame is trimmed (centred) to make the
// scales exactly equal once the tick labels have taken their room.
PlotLayout writePlot(const std::string& path, const PlotSpec& spec, int width_px = 800, int height_px = 450);

// Loads what the first plot of a process needs (fonts, the text shaper) by drawing a few glyphs
// into memory: a batch calls it once before forking its graders, which then inherit it.
void warmUpPlotting();

}  // namespace dyn
