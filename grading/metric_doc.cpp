// Metric definitions for people; see metric_doc.h.
#include "grading/metric_doc.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace dyn {

std::string fmtConfigNumber(double x) {
  char b[40];
  if (std::isfinite(x) && x == std::round(x) && std::abs(x) < 1e12) std::snprintf(b, sizeof b, "%.0f", x);
  else std::snprintf(b, sizeof b, "%.6g", x);
  return b;
}

std::string fillFromConfig(const std::string& text, const JsonView& config, const std::string& path) {
  std::string out;
  for (std::size_t i = 0; i < text.size();) {
    // Copy up to the next "{/", then substitute the pointer inside the braces.
    const std::size_t open = text.find("{/", i);
    if (open == std::string::npos) {
      out += text.substr(i);
      break;
    }
    out += text.substr(i, open - i);
    const std::size_t close = text.find('}', open);
    const std::string pointer = text.substr(open + 1, close == std::string::npos ? std::string::npos : close - open - 1);
    const json* value = nullptr;
    try {
      const json::json_pointer ptr(pointer);
      if (close != std::string::npos && config.raw().contains(ptr)) value = &config.raw().at(ptr);
    } catch (const json::exception&) {
    }
    if (!value || !(value->is_number() || value->is_string()))
      throw InputError(config.file(), path, "expected \"{" + pointer + "}\" to name a number or string of the config");
    out += value->is_number() ? fmtConfigNumber(value->get<double>()) : value->get<std::string>();
    i = close + 1;
  }
  return out;
}

namespace {

// A window bound: seconds, or "{/pointer}" naming a number of the config.
double windowBound(const JsonView& v, const JsonView& config) {
  if (v.raw().is_number()) return v.number();
  const std::string expected = "expected a number of seconds or \"{/json/pointer}\" naming one";
  if (!v.raw().is_string()) v.fail(expected);
  const std::string text = v.string();
  if (text.size() < 3 || text.front() != '{' || text.back() != '}') v.fail(expected);
  try {
    const json& value = config.raw().at(json::json_pointer(text.substr(1, text.size() - 2)));
    if (value.is_number() && std::isfinite(value.get<double>())) return value.get<double>();
  } catch (const json::exception&) {
  }
  v.fail(expected + ", got \"" + text + "\" (not a number of the config)");
}

// A bound the window's own words give (placeholders filled): the number after one of the leads
// ("from t = 0.5 s on" → 0.5).
double boundIn(const std::string& window, std::initializer_list<const char*> leads, double none) {
  for (const char* lead : leads) {
    const std::size_t at = window.find(lead);
    if (at == std::string::npos) continue;
    const char* start = window.c_str() + at + std::strlen(lead);
    char* end = nullptr;
    const double v = std::strtod(start, &end);
    if (end != start && std::isfinite(v)) return v;
  }
  return none;
}

// A data-defined metric's window ("metrics": {NAME: {"of", "stat", "from", "to"}}, labs/generic/
// metric_spec.h) in words and numbers, written from the spec so the handout never disagrees with the
// grader. False when NAME is not such a metric (a C++ lab documents its own).
bool specWindow(const JsonView& config, const std::string& name, MetricDoc& doc) {
  if (!config.has("metrics") || !config["metrics"].raw().is_object() || !config["metrics"].has(name)) return false;
  const json& m = config["metrics"][name].raw();
  if (!m.is_object() || !m.contains("of") || !m.contains("stat")) return false;
  const bool final_value = m["stat"] == "final";
  const auto bound = [&](const char* key) -> std::optional<double> {
    if (m.contains(key) && m[key].is_number()) return m[key].get<double>();
    return std::nullopt;
  };
  const auto from = bound("from"), to = bound("to");
  const auto s = [](double x) { return fmtConfigNumber(x); };
  if (final_value) doc.window = to ? "at " + s(*to) + " s" : "the last step";
  else if (from && to) doc.window = s(*from) + "–" + s(*to) + " s";
  else if (to) doc.window = "0–" + s(*to) + " s";
  else if (from) doc.window = "from " + s(*from) + " s to the end";
  else doc.window = "the whole run";
  doc.from = from.value_or(-INFINITY);
  doc.to = to.value_or(INFINITY);
  return true;
}

}  // namespace

std::map<std::string, MetricDoc> parseMetricDocs(const JsonView& config) {
  std::map<std::string, MetricDoc> docs;
  if (!config.has("metric_docs")) return docs;
  const JsonView all = config["metric_docs"];
  all.requireObject();
  for (const auto& [name, _] : all.raw().items()) {
    const JsonView d = all[name];
    d.onlyKeys({"what", "unit", "window", "from", "to", "advice"});
    MetricDoc& doc = docs[name];
    doc.what = fillFromConfig(d["what"].string(), config, d["what"].path());
    doc.unit = d["unit"].string();
    if (d.has("advice")) doc.advice = parseAdvice(d["advice"], config);
    // A data-defined metric's window is written from its spec: one typed beside it could disagree.
    if (specWindow(config, name, doc)) {
      for (const char* key : {"window", "from", "to"})
        if (d.has(key))
          d[key].fail("expected no \"" + std::string(key) + "\": dynlab writes the window of /metrics/" + name +
                      " from its spec (" + doc.window + ")");
      continue;
    }
    doc.window = fillFromConfig(d["window"].string(), config, d["window"].path());
    // The window in numbers: "from"/"to" when given, else what its words say ("from t = {/..} s on").
    doc.from = d.has("from") ? windowBound(d["from"], config) : boundIn(doc.window, {"from t = "}, -INFINITY);
    doc.to = d.has("to") ? windowBound(d["to"], config) : boundIn(doc.window, {"until t = ", " to t = "}, INFINITY);
    if (!(doc.from < doc.to))
      (d.has("to") ? d["to"] : d.has("from") ? d["from"] : d["window"])
          .fail("expected the window's end after its start (" + fmtConfigNumber(doc.from) + " s)");
  }
  return docs;
}

std::optional<MetricDoc> screeningMetricDoc(const std::string& metric, const std::vector<LinearLoop>& loops) {
  // Each kind the screening reports, defined as grading/scenario.h computes it.
  struct Kind {
    std::string what, unit, window, advice;
  };
  static const std::vector<std::pair<std::string, Kind>> kinds = {
      {"_delay_margin",
       {"the total measurement delay the loop tolerates before it goes unstable (phase margin / crossover "
        "frequency; reported as 1000 s when |L| < 1 at every frequency, 0 when the loop is not stable even "
        "without delay or closes no feedback)",
        "s", "",
        "a short margin comes from a high loop gain (a fast crossover): lower the loop's gain, the margin grows "
        "roughly as 1/gain"}},
      {"_max_real_pole",
       {"the largest real part of the closed-loop poles (a sampled loop: ln z / dt of its discrete poles, hold "
        "and delay in steps included; else the delay as a Padé approximant): above 0 the loop is unstable",
        "1/s", "", "a slow or unstable pole: raise the loop's proportional gain, or lower it if the delay destabilises it"}},
      {"_damping",
       {"the smallest damping ratio ζ = −Re p / |p| of the closed-loop poles (0 when the loop is not stable "
        "or closes no feedback)",
        "1", "", "too little damping: raise the loop's velocity (derivative) gain, or lower its stiffness"}},
      {"_phase_margin_deg", {"the phase margin of the delay-free loop at its crossover", "°", "",
                             "a small phase margin: add damping (velocity gain) or lower the loop's gain"}},
      {"_crossover", {"the crossover frequency, where |L(jω)| = 1 (0 if it never crosses)", "rad/s", "",
                      "the crossover moves with the loop's gain: higher gain, faster loop, less delay margin"}}};
  for (const auto& loop : loops)
    for (const auto& [suffix, doc] : kinds)
      if (metric == loop.name + suffix) {
        MetricDoc d{doc.what, doc.unit, doc.window, {AdviceEntry{json::object(), doc.advice, ""}}};
        d.what = "screening of the " + loop.what + ": " + d.what;
        d.window = "no simulation: the loop linearised at the start (L(s) with its delay of " +
                   fmtConfigNumber(loop.delay * 1e3) + " ms)";
        return d;
      }
  return std::nullopt;
}

}  // namespace dyn
