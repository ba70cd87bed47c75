// What a metric means, for people (the handout, feedback): its definition, unit and time window.
// Lab metrics are documented by the lab's JSON,
//   "metric_docs": {"x_rms": {"unit": "m", "window": "whole run", "what": "RMS of x_c − x_d"},
//                   "f_rms": {..., "window": "from t = {/metrics/settle_time} s on"}}
// where "{/json/pointer}" in window or what stands for the config's value there (so a window such
// as "from t = {/metrics/settle_time} s on" never disagrees with the grader). The window in
// numbers (the feedback plots hatch the rest of the run) is what its words say — the number after
// "from t = ", "until t = " or " to t = " — or "from"/"to" when given (seconds, or "{/pointer}"
// naming a number); the screening
// metrics (<loop>_delay_margin, <loop>_damping, ... from grading/scenario.h) are documented here,
// once for every lab, from the loops the lab reports. "advice" (optional) is what a student whose
// test on the metric is not at full marks should change: one text, or entries chosen by the law in
// use and why the test lost points (grading/advice.h).
#pragma once
#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "grading/advice.h"
#include "labs/config.h"
#include "physics/linear.h"

namespace dyn {

struct MetricDoc {
  std::string what, unit, window;  // unit "1": dimensionless
  std::vector<AdviceEntry> advice;  // what to change when the test falls short (may be none)
  double from = -INFINITY, to = INFINITY;  // the time window the metric reads (s)
};

// config["metric_docs"] (none: empty), placeholders filled from config; throws InputError naming the
// file and JSON path of a malformed entry or a placeholder pointing at nothing.
std::map<std::string, MetricDoc> parseMetricDocs(const JsonView& config);

// The definition of a screening metric <loop>_<kind> for one of these loops, if it is one.
std::optional<MetricDoc> screeningMetricDoc(const std::string& metric, const std::vector<LinearLoop>& loops);

// A config number as people read it and as the JSON has it: integers plain (20000), else 6
// significant digits (0.003, 0.00167).
std::string fmtConfigNumber(double x);

// Replaces every "{/pointer}" in text by the config's value there (numbers by fmtConfigNumber);
// throws InputError naming the config file and `path` if the pointer is malformed or missing.
std::string fillFromConfig(const std::string& text, const JsonView& config, const std::string& path);

}  // namespace dyn
