// What a figure plots, named the way `dynlab figure --plot` and a lab's JSON write it: curves of
// one trace column against another, several to a plot,
//   "f_Ty, f_des"      f_Ty and f_des against t
//   "y:x, y_d:x_d"     y against x and y_d against x_d: an x–y (parametric) plot, the path in the plane
//   "y_p:x_p@contact"  y_p against x_p only where the column contact is nonzero (the line breaks where
//                      it is 0: the ink where a pen touched); "f_z@contact" likewise against t
// and the figures a lab asks `dynlab figure` to draw by default, beside its rubric's plots:
//   "figures": [{"plot": "y:x, y_d:x_d", "title": "path in the plane"}]   ("xlabel", "ylabel" optional)
#pragma once
#include <string>
#include <vector>

#include "grading/plot.h"
#include "labs/config.h"
#include "labs/lab.h"
#include "labs/trace.h"

namespace dyn {

// Column y against column x ("t": a time plot), drawn where column mask is nonzero (empty: everywhere).
struct PlotCurve {
  std::string y, x = "t", mask;
  bool operator==(const PlotCurve& o) const { return y == o.y && x == o.x && mask == o.mask; }
};

// "a, b" or "y:x, y_d:x_d" (each optionally "@mask") → its curves in order, repeats dropped. Every name is one of columns,
// and a plot is against t or against columns, not both (one x axis). Throws InputError(file,
// path, what was expected, listing the columns for an unknown one).
std::vector<PlotCurve> parsePlotCurves(const std::string& spec, const std::vector<std::string>& columns,
                                       const std::string& file, const std::string& path);

// Whether the curves are an x–y plot (some x is not t).
bool parametric(const std::vector<PlotCurve>& curves);

// The y columns, and the x columns, each once, in order.
std::vector<std::string> yColumns(const std::vector<PlotCurve>& curves);
std::vector<std::string> xColumns(const std::vector<PlotCurve>& curves);

// "y vs x" for an x–y curve, "y" for a time curve, " where mask" after a masked one; joined by ", ".
std::string curvesText(const std::vector<PlotCurve>& curves);

// A curve's points in a trace: its x and y columns, and where its mask is 0 (or not finite) y is NaN
// (x too on an x–y curve, so the axes span only what is drawn): the plotter breaks the line there.
// Throws std::out_of_range naming a column the trace lacks.
struct CurvePoints {
  std::vector<double> x, y;
};
CurvePoints curvePoints(const Trace& trace, const PlotCurve& curve);

// One run of a figure: what it is called in a legend (empty: the only run) and its engines' traces
// (null: that engine did not run).
struct PlotRun {
  std::string name;
  const Trace* hand = nullptr;
  const Trace* bullet = nullptr;
};

// Every run's series of the curves, hand solid and Bullet dashed. One run: each curve a colour,
// "y (hand)", "y (Bullet)", or once as "y (hand, Bullet)" when both engines give the same points (a
// reference, a setpoint). Several runs (gains files overlaid): run r is colour r in every curve, so a
// run's target (x_target beside x) is its response's colour; the curves are told apart by pattern,
// the same in every run (the first curve solid, the next dashed, then dotted, dash-dot; a curve's
// Bullet line, where it differs from hand, the pattern after the curve's): "y (NAME, hand)",
// "y (NAME, Bullet)" (or "y (NAME, hand, Bullet)"). What every run and engine gives alike (a set
// point) is one line "y (every run)", and a line several runs give alike is one line naming them
// ("x_target (a.json, b.json, hand)"), each in a colour after the runs': no legend entry for a
// line hidden under another.
std::vector<PlotSeries> runSeries(const std::vector<PlotCurve>& curves, const std::vector<PlotRun>& runs);

// An axis label of columns with the lab's units: "x, x_d (m)" when they share one, else each its
// own ("x_c (m), q1 (rad)").
std::string axisLabel(const Lab& lab, const std::vector<std::string>& columns);

// Equal aspect is right when every column on both axes has one and the same unit (metres against
// metres), not for a phase plot (m/s against m) or unitless columns.
bool sameUnit(const Lab& lab, const std::vector<std::string>& xs, const std::vector<std::string>& ys);

// One of a lab's own figures.
struct LabFigure {
  std::vector<PlotCurve> curves;
  std::string title, xlabel, ylabel;  // empty: derived (the lab and columns; columns with units)
  std::vector<std::pair<std::string, double>> levels;  // constant y levels drawn across (label, y)
};

// Reads config["figures"] (absent: none): an array of at most 20 objects with "plot" (the --plot
// grammar above) and optional "title", "xlabel", "ylabel" strings (one line, at most 200 bytes),
// and optional "levels": at most 5 {"label", "at", "minus", "when"}, a level y = config[at] −
// config[minus] (JSON pointers to numbers; "minus" optional) drawn only when config[when] (a
// pointer to a boolean, optional) is true, e.g. a wall that only some scenarios enable.
// Throws InputError naming the file and the JSON path ("/figures/0/plot").
std::vector<LabFigure> parseLabFigures(const JsonView& config, const std::vector<std::string>& columns);

}  // namespace dyn
