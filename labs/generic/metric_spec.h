// Metrics as data (a data-defined lab's "metrics"): each a statistic of one trace column, or of the
// Euclidean norm of several (a tracking error's components, a pin force's rows), over a time window:
//   "name": {"of": "column" | ["c1", "c2", ...], "stat": STAT, "from": t0, "to": t1, "band": b}
//   rms, mean, max, min    of the value over [from, to] (defaults: the whole run)
//   max_abs                max |value|
//   final                  the value at the last row of the window
//   settling               the time from `from` until the value stays within ±band (the window's length
//                          if it never settles)
//   variation              Σ |Δvalue| from row to row (chatter), summed over the columns of a list
// so a rubric needs no code.
#pragma once
#include <map>
#include <string>
#include <vector>

#include "labs/config.h"
#include "labs/trace.h"

namespace dyn::generic {

struct MetricSpec {
  enum class Stat { Rms, Mean, Max, Min, MaxAbs, Final, Settling, Variation };
  std::vector<std::string> of;  // one column, or several combined as a norm
  Stat stat = Stat::Rms;
  double from = 0, to = 1e300, band = 0;
};

// Parses the "metrics" object; every column must be in `columns` (the lab's trace), every window inside
// the run [0, duration] sampled every dt with at least one sample in it (refused at its JSON path).
std::map<std::string, MetricSpec> parseMetrics(const JsonView& j, const std::vector<std::string>& columns, double duration,
                                               double dt);

// The metric over a trace (NaN for a window without a sample, as a run stopped early leaves: no
// threshold credits it).
double evaluate(const MetricSpec& m, const Trace& trace);

}  // namespace dyn::generic
