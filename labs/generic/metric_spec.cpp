// Metrics as data: see metric_spec.h.
#include "labs/generic/metric_spec.h"

#include <algorithm>
#include <cmath>

#include "labs/numbers.h"

namespace dyn::generic {

namespace {

// The window [from, to] inside the run [0, duration] sampled every dt, holding at least one sample:
// from ≤ duration − dt, and a given to in [from + dt, duration].
void readWindow(const JsonView& m, double duration, double dt, MetricSpec& s) {
  const std::string run = "the run lasts " + fmt("%.6g", duration) + " s, sampled every " + fmt("%.6g", dt) + " s";
  if (m.has("from")) {
    s.from = m["from"].number();
    if (!(s.from >= 0 && s.from <= duration - dt))
      m["from"].fail("expected a start in [0, " + fmt("%.6g", duration - dt) + "] s (" + run + "), got " + exactNumber(s.from));
  }
  if (m.has("to")) {
    s.to = m["to"].number();
    if (!(s.to >= s.from + dt && s.to <= duration * (1 + 1e-12)))
      m["to"].fail("expected an end in [" + fmt("%.6g", s.from + dt) + ", " + fmt("%.6g", duration) + "] s (from + one sample, " + run +
                   "), got " + exactNumber(s.to));
  }
}

}  // namespace

namespace {

// The trace's columns for a message: the first 40, then how many more (the header of trace_hand.csv has them all).
std::string columnList(const std::vector<std::string>& columns) {
  std::string s;
  for (std::size_t i = 0; i < columns.size() && i < 40; ++i) s += (i ? ", " : "") + columns[i];
  if (columns.size() > 40) s += ", … " + std::to_string(columns.size() - 40) + " more: the header of `dynlab run`'s trace_hand.csv";
  return s;
}

}  // namespace

std::map<std::string, MetricSpec> parseMetrics(const JsonView& j, const std::vector<std::string>& columns, double duration,
                                               double dt) {
  j.requireObject();
  std::map<std::string, MetricSpec> out;
  for (const auto& [name, value] : j.raw().items()) {
    (void)value;
    const JsonView m = j[name];
    m.onlyKeys({"of", "stat", "from", "to", "band"});
    MetricSpec s;
    const JsonView of = m["of"];
    if (of.raw().is_string()) s.of = {of.string()};
    else
      for (std::size_t i = 0, n = of.size(1, 16); i < n; ++i) s.of.push_back(of.at(i).string());
    for (const auto& c : s.of)
      if (std::find(columns.begin(), columns.end(), c) == columns.end()) of.fail("expected one of this lab's trace columns (" + columnList(columns) + "), not \"" + c + "\"");
    const std::string stat = m["stat"].oneOf({"rms", "mean", "max", "min", "max_abs", "final", "settling", "variation"});
    using St = MetricSpec::Stat;
    s.stat = stat == "rms" ? St::Rms : stat == "mean" ? St::Mean : stat == "max" ? St::Max : stat == "min" ? St::Min
             : stat == "max_abs" ? St::MaxAbs : stat == "final" ? St::Final : stat == "settling" ? St::Settling : St::Variation;
    readWindow(m, duration, dt, s);
    if (s.stat == St::Settling) s.band = m["band"].positive(1e9);
    else if (m.has("band")) m["band"].fail("expected no band: only \"settling\" takes one");
    out[name] = s;
  }
  return out;
}

double evaluate(const MetricSpec& m, const Trace& tr) {
  std::vector<int> cols;
  for (const auto& c : m.of) cols.push_back(tr.require(c));
  const int tcol = tr.require("t");
  // The value at a row: the column, or the norm of several.
  auto value = [&](std::size_t r) {
    if (cols.size() == 1) return tr.at(r, cols[0]);
    double s = 0;
    for (int c : cols) s += tr.at(r, c) * tr.at(r, c);
    return std::sqrt(s);
  };
  using St = MetricSpec::Stat;
  double acc = 0, extreme = m.stat == St::Min ? 1e300 : m.stat == St::Max ? -1e300 : 0, last = 0, settled = -1;
  double t_first = -1, t_last = 0;
  std::size_t count = 0, prev = 0;
  for (std::size_t r = 0; r < tr.rows(); ++r) {
    const double t = tr.at(r, tcol);
    if (t < m.from - 1e-12 || t > m.to + 1e-12) continue;
    const double x = value(r);
    if (t_first < 0) t_first = t;
    t_last = t;
    switch (m.stat) {
      case St::Rms: acc += x * x; break;
      case St::Mean: acc += x; break;
      case St::Max: extreme = std::max(extreme, x); break;
      case St::Min: extreme = std::min(extreme, x); break;
      case St::MaxAbs: extreme = std::max(extreme, std::abs(x)); break;
      case St::Final: last = x; break;
      case St::Settling:
        if (std::abs(x) > m.band) settled = -1;
        else if (settled < 0) settled = t;
        break;
      case St::Variation:
        if (count > 0)
          for (int c : cols) acc += std::abs(tr.at(r, c) - tr.at(prev, c));
        break;
    }
    prev = r;
    ++count;
  }
  if (count == 0) return NAN;  // no sample: a value no threshold credits
  switch (m.stat) {
    case St::Rms: return std::sqrt(acc / double(count));
    case St::Mean: return acc / double(count);
    case St::Max: case St::Min: case St::MaxAbs: return extreme;
    case St::Final: return last;
    case St::Settling: return settled < 0 ? t_last - t_first : settled - t_first;
    case St::Variation: return acc;
  }
  return 0.0;
}

}  // namespace dyn::generic
