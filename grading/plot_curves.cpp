// Figure curves and a lab's own figures; see plot_curves.h.
#include "grading/plot_curves.h"

#include <algorithm>
#include <cmath>

namespace dyn {
namespace {

std::string join(const std::vector<std::string>& parts, const std::string& sep) {
  std::string s;
  for (const auto& p : parts) s += (s.empty() ? "" : sep) + p;
  return s;
}

std::string trim(std::string s) {
  s.erase(0, s.find_first_not_of(' '));
  s.erase(s.find_last_not_of(' ') + 1);
  return s;
}

// Splits s at every sep (an empty s is one empty part).
std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  for (std::size_t end; (end = s.find(sep, start)) != std::string::npos; start = end + 1)
    parts.push_back(s.substr(start, end - start));
  parts.push_back(s.substr(start));
  return parts;
}

void addOnce(std::vector<std::string>& v, const std::string& s) {
  if (std::find(v.begin(), v.end(), s) == v.end()) v.push_back(s);
}

}  // namespace

std::vector<PlotCurve> parsePlotCurves(const std::string& spec, const std::vector<std::string>& columns,
                                       const std::string& file, const std::string& path) {
  const std::string grammar =
      "expected trace columns separated by commas, each against t or as Y:X for column Y against column X "
      "(\"y:x, y_d:x_d\"), optionally @M to draw it only where column M is nonzero (\"y:x@contact\")";
  // Each name is a column of the lab; the error lists them.
  const auto column = [&](const std::string& raw) {
    const std::string name = trim(raw);
    if (std::find(columns.begin(), columns.end(), name) == columns.end())
      throw InputError(file, path,
                       (name.empty() ? std::string("empty column name") : "unknown column \"" + name + "\"") + "; " +
                           grammar + ", one of: " + join(columns, ", "));
    return name;
  };
  std::vector<PlotCurve> curves;
  std::string against_t, against_column;  // one curve of each kind, for the error that mixes them
  for (const std::string& item : split(spec, ',')) {
    // "Y:X@M": the mask after '@', then the sides.
    const std::vector<std::string> masked = split(item, '@');
    if (masked.size() > 2) throw InputError(file, path, "\"" + trim(item) + "\" has two '@'; " + grammar);
    const std::vector<std::string> sides = split(masked[0], ':');
    if (sides.size() > 2) throw InputError(file, path, "\"" + trim(item) + "\" has two ':'; " + grammar);
    PlotCurve c{column(sides[0]), sides.size() == 2 ? column(sides[1]) : "t",
                masked.size() == 2 ? column(masked[1]) : ""};
    (c.x == "t" ? against_t : against_column) = trim(item);
    if (std::find(curves.begin(), curves.end(), c) == curves.end()) curves.push_back(c);
  }
  if (!against_t.empty() && !against_column.empty())
    throw InputError(file, path,
                     "expected every curve of one plot against t or every one against a column (\"" + against_t +
                         "\" is against t, \"" + against_column + "\" is not): one plot each");
  return curves;
}

bool parametric(const std::vector<PlotCurve>& curves) {
  return std::any_of(curves.begin(), curves.end(), [](const PlotCurve& c) { return c.x != "t"; });
}

std::vector<std::string> yColumns(const std::vector<PlotCurve>& curves) {
  std::vector<std::string> out;
  for (const auto& c : curves) addOnce(out, c.y);
  return out;
}

std::vector<std::string> xColumns(const std::vector<PlotCurve>& curves) {
  std::vector<std::string> out;
  for (const auto& c : curves) addOnce(out, c.x);
  return out;
}

std::string curvesText(const std::vector<PlotCurve>& curves) {
  std::vector<std::string> parts;
  for (const auto& c : curves)
    parts.push_back((c.x == "t" ? c.y : c.y + " vs " + c.x) + (c.mask.empty() ? "" : " where " + c.mask));
  return join(parts, ", ");
}

CurvePoints curvePoints(const Trace& trace, const PlotCurve& curve) {
  for (const auto* c : {&curve.x, &curve.y, &curve.mask})
    if (!c->empty()) trace.require(*c);  // a column the trace lacks: std::out_of_range naming it
  CurvePoints p{trace.series(curve.x), trace.series(curve.y)};
  if (curve.mask.empty()) return p;
  const std::vector<double> mask = trace.series(curve.mask);
  for (std::size_t i = 0; i < mask.size(); ++i)
    if (!(std::isfinite(mask[i]) && mask[i] != 0)) {
      p.y[i] = NAN;
      if (curve.x != "t") p.x[i] = NAN;
    }
  return p;
}

namespace {

// The same points, a NaN (a masked point) equal to a NaN.
bool samePoints(const CurvePoints& a, const CurvePoints& b) {
  const auto same = [](const std::vector<double>& u, const std::vector<double>& v) {
    return u.size() == v.size() &&
           std::equal(u.begin(), u.end(), v.begin(), [](double p, double q) { return p == q || (std::isnan(p) && std::isnan(q)); });
  };
  return same(a.x, b.x) && same(a.y, b.y);
}

}  // namespace

namespace {

// Several runs: the pattern of the i-th line kind of a plot (a curve, or its Bullet twin).
PlotSeries::Style pattern(int i) {
  constexpr PlotSeries::Style kinds[] = {PlotSeries::Style::Solid, PlotSeries::Style::Dashed, PlotSeries::Style::Dotted,
                                         PlotSeries::Style::DashDot};
  return kinds[i % 4];
}

}  // namespace

std::vector<PlotSeries> runSeries(const std::vector<PlotCurve>& curves, const std::vector<PlotRun>& runs) {
  std::vector<PlotSeries> out;
  const bool several = runs.size() > 1;
  // Several runs: run r is colour r in every curve; what every run shares, or some runs share, is
  // drawn once (no legend entry for a line hidden under another), each such line in the next
  // colour after the runs' (two of them may lie close: a model's x_des on the target x_target).
  int shared = int(runs.size());
  int slot = 0;  // several runs: the line kinds so far (each its own pattern)
  for (std::size_t k = 0; k < curves.size(); ++k) {
    const std::string name = curvesText({curves[k]});
    // Every engine's points of this curve, in run order, hand before Bullet.
    struct Source {
      std::size_t run;
      bool bullet;
      CurvePoints points;
    };
    std::vector<Source> sources;
    for (std::size_t r = 0; r < runs.size(); ++r) {
      if (runs[r].hand) sources.push_back({r, false, curvePoints(*runs[r].hand, curves[k])});
      if (runs[r].bullet) sources.push_back({r, true, curvePoints(*runs[r].bullet, curves[k])});
    }
    const auto all_same = [&](std::size_t run, bool any_run) {
      std::size_t n = 0;
      const Source* first = nullptr;
      for (const auto& s : sources)
        if (any_run || s.run == run) {
          if (first && !samePoints(first->points, s.points)) return false;
          first = first ? first : &s, ++n;
        }
      return n > 1;
    };
    if (!several) {
      // One run: each curve a colour, its engines once when they agree, else hand solid, Bullet dashed.
      if (all_same(0, false)) {
        out.push_back({name + " (hand, Bullet)", sources[0].points.x, sources[0].points.y, PlotSeries::Style::Solid, int(k)});
        continue;
      }
      for (const auto& s : sources)
        out.push_back({name + " (" + (s.bullet ? "Bullet" : "hand") + ")", s.points.x, s.points.y,
                       s.bullet ? PlotSeries::Style::Dashed : PlotSeries::Style::Solid, int(k)});
      continue;
    }
    // Several runs that all agree (a set point): one curve for all of them.
    if (all_same(0, true)) {
      out.push_back({name + " (every run)", sources[0].points.x, sources[0].points.y, pattern(slot++), shared++});
      continue;
    }
    // Each run's lines: its engines once when they agree, else each; the hand (or agreed) line in
    // this curve's pattern, a differing Bullet line in the next one.
    struct Line {
      std::vector<std::size_t> runs;
      std::string engines;
      const CurvePoints* points;
      bool bullet;
    };
    std::vector<Line> lines;
    for (std::size_t r = 0; r < runs.size(); ++r) {
      if (all_same(r, false)) {
        const Source& s = *std::find_if(sources.begin(), sources.end(), [&](const Source& s) { return s.run == r; });
        lines.push_back({{r}, "hand, Bullet", &s.points, false});
        continue;
      }
      for (const auto& s : sources)
        if (s.run == r) lines.push_back({{r}, s.bullet ? "Bullet" : "hand", &s.points, s.bullet});
    }
    const bool twin = std::any_of(lines.begin(), lines.end(), [](const Line& l) { return l.bullet; });
    const int own = slot++, bullet = twin ? slot++ : own;
    // Lines of several runs with the same points (a target two runs share): one line naming them.
    std::vector<Line> merged;
    for (const Line& l : lines) {
      auto same = std::find_if(merged.begin(), merged.end(),
                               [&](const Line& m) { return m.bullet == l.bullet && samePoints(*m.points, *l.points); });
      if (same == merged.end()) merged.push_back(l);
      else same->runs.push_back(l.runs.front());
    }
    for (const Line& l : merged) {
      std::string label;
      for (std::size_t r : l.runs) label += runs[r].name + ", ";
      out.push_back({name + " (" + label + l.engines + ")", l.points->x, l.points->y, pattern(l.bullet ? bullet : own),
                     l.runs.size() == 1 ? int(l.runs.front()) : shared++});
    }
  }
  return out;
}

std::string axisLabel(const Lab& lab, const std::vector<std::string>& columns) {
  if (columns.empty()) return "";
  const std::string unit = lab.unit(columns.front());
  if (std::all_of(columns.begin(), columns.end(), [&](const std::string& c) { return lab.unit(c) == unit; }))
    return join(columns, ", ") + (unit.empty() ? "" : " (" + unit + ")");
  std::vector<std::string> labelled;
  for (const auto& c : columns) labelled.push_back(lab.unit(c).empty() ? c : c + " (" + lab.unit(c) + ")");
  return join(labelled, ", ");
}

bool sameUnit(const Lab& lab, const std::vector<std::string>& xs, const std::vector<std::string>& ys) {
  if (xs.empty() || ys.empty()) return false;
  const std::string unit = lab.unit(xs.front());
  const auto same = [&](const std::string& c) { return lab.unit(c) == unit; };
  return !unit.empty() && unit != "1" && std::all_of(xs.begin(), xs.end(), same) && std::all_of(ys.begin(), ys.end(), same);
}

std::vector<LabFigure> parseLabFigures(const JsonView& config, const std::vector<std::string>& columns) {
  std::vector<LabFigure> out;
  if (!config.has("figures")) return out;
  const JsonView figures = config["figures"];
  for (std::size_t i = 0, n = figures.size(1, 20); i < n; ++i) {
    const JsonView f = figures.at(i);
    f.onlyKeys({"plot", "title", "xlabel", "ylabel", "levels"});
    const JsonView plot = f["plot"];
    LabFigure fig{parsePlotCurves(plot.string(), columns, plot.file(), plot.path()), "", "", ""};
    // Titles and labels are drawn on one line: short, and no control characters.
    const auto text = [&](const char* key) {
      if (!f.has(key)) return std::string();
      const std::string s = f[key].string();
      if (s.size() > 200 || std::any_of(s.begin(), s.end(), [](unsigned char c) { return c < 0x20 || c == 0x7F; }))
        f[key].fail("expected one line of at most 200 bytes, without control characters");
      return s;
    };
    fig.title = text("title"), fig.xlabel = text("xlabel"), fig.ylabel = text("ylabel");
    if (f.has("levels")) {
      const JsonView levels = f["levels"];
      // A pointer into the config (this file's, scenario patches applied) and the value there.
      const auto target = [&](const JsonView& ptr) {
        const std::string p = ptr.string();
        try {
          const json::json_pointer at(p);
          if (!p.empty() && config.raw().contains(at)) return JsonView(config.raw().at(at), config.file(), p);
        } catch (const json::exception&) {
        }
        ptr.fail("expected a JSON pointer to a value of the lab's config, e.g. \"/environment/wall/x\"");
      };
      for (std::size_t k = 0, m = levels.size(0, 5); k < m; ++k) {
        const JsonView l = levels.at(k);
        l.onlyKeys({"label", "at", "minus", "when"});
        double y = target(l["at"]).number();
        if (l.has("minus")) y -= target(l["minus"]).number();
        const std::string label = l["label"].string();
        if (label.empty() || label.size() > 200 || std::any_of(label.begin(), label.end(), [](unsigned char c) { return c < 0x20 || c == 0x7F; }))
          l["label"].fail("expected one line of 1 to 200 bytes, without control characters");
        if (!l.has("when") || target(l["when"]).boolean()) fig.levels.emplace_back(label, y);
      }
    }
    out.push_back(fig);
  }
  return out;
}

}  // namespace dyn
