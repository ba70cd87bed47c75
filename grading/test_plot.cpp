// Each simulated test's plot, derived for any lab; see test_plot.h.
#include "grading/test_plot.h"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <vector>

#include "grading/isolated.h"
#include "grading/plot.h"
#include "grading/plot_curves.h"

namespace dyn {
namespace {

// Test hook: DYNLAB_FAULT_INJECTION="plot-trap:NAME" aborts the drawing of the plots of a grade
// written into a folder named NAME (out_dir, or the folder out_dir stages for), as a plotting
// library that traps does. Unset in normal use.
bool plotTrapInjected(const std::string& out_dir) {
  const char* spec = std::getenv("DYNLAB_FAULT_INJECTION");
  if (!spec) return false;
  std::filesystem::path folder(out_dir);
  if (folder.filename().empty()) folder = folder.parent_path();
  if (folder.filename().string().rfind(".staging", 0) == 0) folder = folder.parent_path();
  return ("," + std::string(spec) + ",").find(",plot-trap:" + folder.filename().string() + ",") != std::string::npos;
}

bool wordChar(unsigned char c) { return std::isalnum(c) || c == '_'; }

struct Word {
  std::string text;
  std::size_t begin, end;
};

// The trace columns a metric's definition names, in order (never "t"); in "a − b" (or "a - b")
// of two columns, b is the reference the response a is measured against.
PlotRequest columnsNamed(const std::string& what, const std::vector<std::string>& columns) {
  const auto column = [&](const std::string& w) {
    return w != "t" && std::find(columns.begin(), columns.end(), w) != columns.end();
  };
  std::vector<Word> words;
  for (std::size_t i = 0; i < what.size();) {
    if (!wordChar(static_cast<unsigned char>(what[i]))) {
      ++i;
      continue;
    }
    const std::size_t b = i;
    while (i < what.size() && wordChar(static_cast<unsigned char>(what[i]))) ++i;
    if (column(what.substr(b, i - b))) words.push_back({what.substr(b, i - b), b, i});
  }
  PlotRequest out;
  for (std::size_t k = 0; k < words.size(); ++k) {
    if (k + 1 < words.size() && out.reference.empty()) {
      std::string between = what.substr(words[k].end, words[k + 1].begin - words[k].end);
      between.erase(std::remove(between.begin(), between.end(), ' '), between.end());
      if (between == "\xE2\x88\x92" || between == "-") out.reference = words[k + 1].text;  // U+2212 or '-'
    }
    if (words[k].text != out.reference &&
        std::find(out.columns.begin(), out.columns.end(), words[k].text) == out.columns.end())
      out.columns.push_back(words[k].text);
  }
  return out;
}

std::string seconds(double t) { return fmtNumber(t) + " s"; }

// "not scored: f_rms counts from t = 0.5 s" (or "until", or "from ... to ...").
std::string windowLabel(const std::string& metric, double from, double to) {
  const bool f = std::isfinite(from), u = std::isfinite(to);
  return "not scored: " + metric + " counts " +
         (f && u ? "from t = " + seconds(from) + " to " + seconds(to) : f ? "from t = " + seconds(from) : "until t = " + seconds(to));
}

std::string slug(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (std::isalnum(static_cast<unsigned char>(c))) out += char(std::tolower(static_cast<unsigned char>(c)));
    else if (!out.empty() && out.back() != '-') out += '-';
  }
  while (!out.empty() && out.back() == '-') out.pop_back();
  return out.substr(0, 40);
}

// A file's bytes in one read (a character at a time through a stream buffer cost as much as
// writing the file); empty if it cannot be read.
std::string fileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return {};
  std::string bytes(std::size_t(std::max<std::streamoff>(0, in.tellg())), '\0');
  in.seekg(0);
  if (!in.read(bytes.data(), std::streamsize(bytes.size()))) return {};
  return bytes;
}

std::string withUnit(double x, const std::string& unit) { return fmtNumber(x) + (unit.empty() || unit == "1" ? "" : " " + unit); }

// An x–y plot of one test's run (the path in the plane): each column against x (solid), the
// reference against its x (dashed), equal scales when both axes have one unit; no hatching (x is
// not time), and a stopped run says when in its legend.
PlotSpec pathPlotSpec(const GradedTest& g, const TestPlotPlan& plan, const ScenarioRun& run) {
  const Trace& tr = run.trace;
  const PlotRequest& p = plan.request;
  PlotSpec spec;
  spec.title = g.test.name + " (" + g.test.scenario + ")";
  spec.parametric = true;
  spec.equal_aspect = plan.equal_aspect;
  spec.xlabel = p.xlabel;
  spec.ylabel = p.ylabel;
  const std::string stopped = run.failure_time >= 0 ? " (stopped at t = " + seconds(run.failure_time) + ")" : "";
  if (!p.reference.empty() && tr.column(p.reference) >= 0 && tr.column(p.reference_x) >= 0)
    spec.series.push_back({p.reference + " vs " + p.reference_x + " (reference)", tr.series(p.reference_x),
                           tr.series(p.reference), PlotSeries::Style::Dashed, 1});
  int color = 0;
  for (const auto& c : p.columns) {
    if (tr.column(c) < 0 || tr.column(p.x) < 0) continue;
    spec.series.push_back({c + " vs " + p.x + stopped, tr.series(p.x), tr.series(c), PlotSeries::Style::Solid, color});
    color = color == 0 ? 2 : color + 1;  // colour 1 is the reference's
  }
  return spec;
}

// The plot of one test's run: hatched outside the metric's window, the band, the response
// columns (solid) and the reference (dashed), and where the run was stopped.
PlotSpec testPlotSpec(const GradedTest& g, const TestPlotPlan& plan, const ScenarioRun& run) {
  if (!plan.request.x.empty()) return pathPlotSpec(g, plan, run);
  const Trace& tr = run.trace;
  const PlotRequest& p = plan.request;
  PlotSpec spec;
  spec.title = g.test.name + " (" + g.test.scenario + ")";
  spec.xlabel = "t (s)";
  spec.ylabel = p.ylabel;
  const std::vector<double> t = tr.series("t");
  const std::string window = windowLabel(g.test.metric, plan.from, plan.to);
  if (plan.from > t.front()) spec.spans.push_back({window, t.front(), plan.from});
  if (plan.to < t.back()) spec.spans.push_back({spec.spans.empty() ? window : "", plan.to, t.back()});
  if (!p.reference.empty() && tr.column(p.reference) >= 0) {
    const std::vector<double> ref = tr.series(p.reference);
    if (p.band > 0) {
      PlotBand band{"tolerance ±" + withUnit(p.band, plan.band_unit), t, ref, ref};
      for (std::size_t k = 0; k < ref.size(); ++k) band.lo[k] -= p.band, band.hi[k] += p.band;
      spec.bands.push_back(band);
    }
    spec.series.push_back({p.reference + " (reference)", t, ref, PlotSeries::Style::Dashed, 1});
  } else if (p.band > 0) {
    spec.bands.push_back({"limit ±" + withUnit(p.band, plan.band_unit), t, std::vector<double>(t.size(), -p.band),
                          std::vector<double>(t.size(), p.band)});
  }
  int color = 0;
  for (const auto& c : p.columns) {
    if (tr.column(c) < 0) continue;
    spec.series.push_back({c, t, tr.series(c), PlotSeries::Style::Solid, color});
    color = color == 0 ? 2 : color + 1;  // colour 1 is the reference's
  }
  if (run.failure_time >= 0) {
    spec.vlines.push_back(run.failure_time);
    spec.vline_label = "run stopped";
  }
  return spec;
}

}  // namespace

TestPlotPlan planTestPlot(const Rubric& rubric, std::size_t i, const std::map<std::string, MetricDoc>& docs,
                          const Lab& lab) {
  const RubricTest& t = rubric.tests.at(i);
  const std::vector<std::string> columns = lab.columns();
  const auto doc = docs.find(t.metric);
  TestPlotPlan plan;
  if (doc != docs.end()) plan.from = doc->second.from, plan.to = doc->second.to;
  const RubricTest* other = nullptr;
  for (const auto& o : rubric.tests)
    if (!other && &o != &t && o.metric == t.metric && o.plot) other = &o;
  const PlotRequest named = doc != docs.end() ? columnsNamed(doc->second.what, columns) : PlotRequest{};
  if (t.plot) {
    plan.request = *t.plot;
  } else if (other) {
    plan.request = *other->plot;
    if (plan.request.band > 0 && plan.request.band == std::abs(other->full)) plan.request.band = std::abs(t.full);
  } else if (!named.columns.empty()) {
    plan.request = named;
    const std::string unit = lab.unit(named.columns.front());
    if (!unit.empty() && unit == doc->second.unit) plan.request.band = std::abs(t.full);
  } else {
    for (const auto& l : rubric.watchdog.limits)
      if (std::find(plan.request.columns.begin(), plan.request.columns.end(), l.column) == plan.request.columns.end())
        plan.request.columns.push_back(l.column);
    if (plan.request.columns.empty()) plan.request.columns = {"energy"};
  }
  PlotRequest& r = plan.request;
  std::vector<std::string> ys = r.columns;
  if (!r.reference.empty()) ys.push_back(r.reference);
  if (r.ylabel.empty()) r.ylabel = axisLabel(lab, ys);
  // An x–y plot: the x label from its x columns, equal scales when every axis column has one unit.
  if (!r.x.empty()) {
    std::vector<std::string> xs = {r.x};
    if (!r.reference_x.empty() && r.reference_x != r.x) xs.push_back(r.reference_x);
    if (r.xlabel.empty()) r.xlabel = axisLabel(lab, xs);
    plan.equal_aspect = sameUnit(lab, xs, ys);
  }
  plan.band_unit = plan.request.columns.empty() ? "" : lab.unit(plan.request.columns.front());
  return plan;
}

void writeTestPlots(GradeReport& r, const std::map<std::string, ScenarioRun>& runs, const std::string& out_dir,
                    int width_px, int height_px) {
  std::filesystem::create_directories(std::filesystem::path(out_dir) / "plots");
  struct Planned {
    std::size_t test;
    std::string name, path;
  };
  std::vector<Planned> planned;
  for (std::size_t i = 0; i < r.tests.size(); ++i) {
    const GradedTest& g = r.tests[i];
    if (!g.plan || runs.at(g.test.scenario).trace.rows() < 2) continue;
    char name[96];
    std::snprintf(name, sizeof name, "plots/%02zu-%s.png", i + 1, slug(g.test.name).c_str());
    planned.push_back({i, name, (std::filesystem::path(out_dir) / name).string()});
  }
  if (planned.empty()) return;

  // Drawn in a child process: a plotting library that dies (GLib traps when pango cannot start a
  // thread under a tight memory limit) costs the plots, never the grade. A plot that cannot be
  // written (a full disk) is still an error of the machine, as before.
  const IsolatedOutcome drawn = runIsolated([&] {
    if (plotTrapInjected(out_dir)) std::abort();
    for (const Planned& p : planned) {
      const GradedTest& g = r.tests[p.test];
      writePlot(p.path, testPlotSpec(g, *g.plan, runs.at(g.test.scenario)), width_px, height_px);
    }
  }, 120.0);
  if (drawn.kind == IsolatedOutcome::Kind::Threw) throw std::runtime_error(drawn.message);
  if (drawn.kind == IsolatedOutcome::Kind::Died) {
    for (const Planned& p : planned) {
      std::error_code ec;
      std::filesystem::remove(p.path, ec);
      std::filesystem::remove(p.path + ".plplot", ec);
    }
    r.plots_note = "The plots could not be drawn on the grading machine (the plotting library " + drawn.message +
                   "); the scores do not depend on them.";
    return;
  }
  for (const Planned& p : planned) {
    GradedTest& g = r.tests[p.test];
    g.plot_png = fileBytes(p.path);
    g.plot = p.name;
  }
}

}  // namespace dyn
