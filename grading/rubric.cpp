// Parsing a lab's rubric (see rubric.h) with the same path-aware checks as every other input.
#include "grading/rubric.h"

#include <algorithm>
#include <cmath>

namespace dyn {

const Scenario* Rubric::scenario(const std::string& name) const {
  for (const auto& s : scenarios)
    if (s.name == name) return &s;
  return nullptr;
}

double Rubric::maxScore() const {
  double s = 0;
  for (const auto& t : tests) s += t.points;
  return s;
}

double partialCredit(double m, double full, double zero) {
  if (!std::isfinite(m)) return 0.0;
  if (full == zero) return (m == full) ? 1.0 : 0.0;
  return std::clamp((zero - m) / (zero - full), 0.0, 1.0);
}

Rubric parseRubric(const JsonView& config) {
  Rubric r;
  const JsonView rub = config["rubric"];
  rub.onlyKeys({"seed_target", "scenarios", "watchdog", "tests", "leaderboard"});
  if (rub.has("seed_target")) {
    r.seed_target = rub["seed_target"].string();
    if (r.seed_target.empty() || r.seed_target[0] != '/') rub["seed_target"].fail("expected a JSON pointer such as \"/controller/seed\"");
  }
  // Scenarios: merge patches, "nominal" always exists.
  if (rub.has("scenarios")) {
    rub["scenarios"].requireObject();
    for (const auto& [name, _] : rub["scenarios"].raw().items()) {
      const JsonView sc = rub["scenarios"][name];
      sc.onlyKeys({"about", "patch"});
      Scenario s{name, sc["about"].string(), json::object()};
      if (sc.has("patch")) {
        sc["patch"].requireObject();
        s.patch = sc["patch"].raw();
      }
      r.scenarios.push_back(s);
    }
  }
  // "nominal" first (added if absent), the others by name: JSON objects carry no order.
  std::stable_partition(r.scenarios.begin(), r.scenarios.end(), [](const Scenario& s) { return s.name == "nominal"; });
  if (!r.scenario("nominal")) r.scenarios.insert(r.scenarios.begin(), {"nominal", "the lab as given", json::object()});

  if (rub.has("watchdog")) {
    const JsonView w = rub["watchdog"];
    w.onlyKeys({"max_steps", "limits"});
    if (w.has("max_steps")) r.watchdog.max_steps = w["max_steps"].integer(1, 100000000);
    if (w.has("limits")) {
      for (std::size_t i = 0, n = w["limits"].size(); i < n; ++i) {
        const JsonView l = w["limits"].at(i);
        l.onlyKeys({"column", "min", "max", "what"});
        ColumnLimit lim{l["column"].string(), l.has("what") ? l["what"].string() : l["column"].string()};
        if (l.has("min")) lim.min = l["min"].number();
        if (l.has("max")) lim.max = l["max"].number();
        r.watchdog.limits.push_back(lim);
      }
    }
  }

  const JsonView tests = rub["tests"];
  for (std::size_t i = 0, n = tests.size(1, 200); i < n; ++i) {
    const JsonView t = tests.at(i);
    t.onlyKeys({"name", "scenario", "metric", "full", "zero", "points", "visibility", "plot"});
    RubricTest rt;
    rt.name = t["name"].string();
    rt.scenario = t.has("scenario") ? t["scenario"].string() : "nominal";
    if (!r.scenario(rt.scenario)) t["scenario"].fail("expected one of the rubric's scenarios, got \"" + rt.scenario + "\"");
    rt.metric = t["metric"].string();
    rt.full = t["full"].number();
    rt.zero = t["zero"].number();
    rt.points = t["points"].positive();
    if (t.has("visibility")) rt.visibility = t["visibility"].oneOf({"visible", "hidden", "after_due_date", "after_published"});
    if (t.has("plot")) {
      const JsonView p = t["plot"];
      p.onlyKeys({"columns", "reference", "band", "ylabel"});
      PlotRequest pr;
      for (std::size_t k = 0, m = p["columns"].size(1, 8); k < m; ++k) pr.columns.push_back(p["columns"].at(k).string());
      if (p.has("reference")) pr.reference = p["reference"].string();
      if (p.has("band")) pr.band = p["band"].nonNegative();
      pr.ylabel = p.has("ylabel") ? p["ylabel"].string() : pr.columns[0];
      rt.plot = pr;
    }
    r.tests.push_back(rt);
  }

  if (rub.has("leaderboard")) {
    for (std::size_t i = 0, n = rub["leaderboard"].size(0, 10); i < n; ++i) {
      const JsonView l = rub["leaderboard"].at(i);
      l.onlyKeys({"name", "scenario", "metric", "scale", "order"});
      LeaderboardEntry e{l["name"].string(), l.has("scenario") ? l["scenario"].string() : "nominal",
                         l["metric"].string()};
      if (!r.scenario(e.scenario)) l["scenario"].fail("expected one of the rubric's scenarios");
      if (l.has("order")) e.order = l["order"].oneOf({"asc", "desc"});
      if (l.has("scale")) e.scale = l["scale"].positive();
      r.leaderboard.push_back(e);
    }
  }
  return r;
}

}  // namespace dyn
