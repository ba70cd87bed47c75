// Response plots for grading feedback: time series, tolerance bands and event markers drawn with
// PLplot into a PNG, SVG or PDF file that a lecturer can put straight on a slide.
// PNG (pngcairo), SVG (PLplot's own svg device, text kept as text) and PDF (pdfcairo, its creation
// date pinned to 1980-01-01) are byte-deterministic for a given set of installed fonts and libraries.
#pragma once
#include <string>
#include <vector>

namespace dyn {

struct PlotSeries {
  std::string label;                 // legend text
  std::vector<double> x, y;
  enum class Style { Solid, Dashed } style = Style::Solid;
  int color = 0;                     // index into a fixed, colour-blind-safe palette
};

struct PlotBand {                    // a shaded tolerance band lo(x)..hi(x)
  std::string label;
  std::vector<double> x, lo, hi;
};

struct PlotSpec {
  std::string title, xlabel, ylabel;
  std::vector<PlotBand> bands;       // drawn first (light fill)
  std::vector<PlotSeries> series;
  std::vector<double> vlines;        // vertical markers, e.g. the time a run went unstable
  std::string vline_label;           // legend text for the markers (optional)
};

// Writes the plot as PNG (pngcairo) or SVG (svg) or PDF (pdf), chosen by the file extension.
// Deterministic: the same spec gives the same bytes. Throws std::runtime_error naming the path
// on failure (bad extension, unwritable path, empty/ mismatched series). Non-finite y values are
// skipped (split the line), never passed to PLplot; axis ranges come from the finite data
// (a constant series gets a small symmetric range). Writes to path + ".tmp" then renames.
// Series longer than 2000 points are thinned to the min and max of each bucket (spikes stay).
// Text and line widths scale with the picture (800 × 450 is the reference). Labels are UTF-8.
void writePlot(const std::string& path, const PlotSpec& spec, int width_px = 800, int height_px = 450);

}  // namespace dyn
