// Parsing a lab's rubric (see rubric.h) with the same path-aware checks as every other input.
#include "grading/rubric.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

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
  const double f = (zero - m) / (zero - full);
  return std::isnan(f) ? 0.0 : std::clamp(f, 0.0, 1.0);  // NaN: inf/inf at extreme thresholds
}

void checkColumns(const Rubric& r, const std::vector<std::string>& columns, const std::string& file) {
  auto check = [&](const std::string& c, const std::string& path) {
    if (std::find(columns.begin(), columns.end(), c) != columns.end()) return;
    std::string list;
    for (const auto& k : columns) list += (list.empty() ? "" : ", ") + k;
    throw InputError(file, path, "expected a trace column of this lab (" + list + "), got \"" + c + "\"");
  };
  for (std::size_t i = 0; i < r.watchdog.limits.size(); ++i)
    check(r.watchdog.limits[i].column, "/rubric/watchdog/limits/" + std::to_string(i) + "/column");
  for (std::size_t i = 0; i < r.tests.size(); ++i) {
    if (!r.tests[i].plot) continue;
    const std::string at = "/rubric/tests/" + std::to_string(i) + "/plot/";
    const PlotRequest& p = *r.tests[i].plot;
    for (std::size_t k = 0; k < p.columns.size(); ++k) check(p.columns[k], at + "columns/" + std::to_string(k));
    if (!p.reference.empty()) check(p.reference, at + "reference");
    if (!p.x.empty()) check(p.x, at + "x");
    if (!p.reference_x.empty()) check(p.reference_x, at + "reference_x");
  }
}

void writeSeed(json& config, const Rubric& rubric, std::uint64_t seed, const std::string& file,
               const std::string& scenario) {
  if (rubric.seed_target.empty()) return;
  // parseRubric checked the pointer's syntax; a scenario's patch may still have replaced the
  // object it points into (e.g. "controller": 5), which json's operator[] would throw on.
  const json::json_pointer ptr(rubric.seed_target);
  bool ok = false;
  try {
    ok = config.contains(ptr.parent_pointer()) && config.at(ptr.parent_pointer()).is_object();
  } catch (const json::exception&) {  // an array index too large for size_t
  }
  if (!ok)
    throw InputError(file, "/rubric/seed_target",
                     "expected a pointer into an object of the config (scenario " + scenario + "), got \"" +
                         rubric.seed_target + "\"");
  config[ptr] = seed;
}

namespace {

// A lesson's submission: a relative path inside the lab's folder ("examples/a.json"), no "..".
std::string lessonPath(const JsonView& v) {
  const std::string p = v.string();
  const std::filesystem::path path(p);
  bool ok = !p.empty() && path.is_relative() && path.extension() == ".json";
  for (const auto& part : path) ok = ok && part != ".." && part != ".";
  if (!ok) v.fail("expected a relative path to a .json submission inside the lab's folder, such as \"examples/a.json\"");
  return p;
}

}  // namespace

Rubric parseRubric(const JsonView& config) {
  Rubric r;
  const JsonView rub = config["rubric"];
  rub.onlyKeys({"seed_target", "scenarios", "watchdog", "tests", "leaderboard", "lessons"});
  if (rub.has("seed_target")) {
    r.seed_target = rub["seed_target"].string();
    bool ok = r.seed_target.size() > 1 && r.seed_target[0] == '/';
    try {
      (void)json::json_pointer(r.seed_target);
    } catch (const json::exception&) {
      ok = false;
    }
    if (!ok) rub["seed_target"].fail("expected a JSON pointer such as \"/controller/seed\", got \"" + r.seed_target + "\"");
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
        if (lim.min > lim.max) l["max"].fail("expected max ≥ min (" + std::to_string(lim.min) + ")");
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
    rt.points = t["points"].positive(1e4);
    if (t.has("visibility")) rt.visibility = t["visibility"].oneOf({"visible", "hidden", "after_due_date", "after_published"});
    if (t.has("plot")) {
      const JsonView p = t["plot"];
      p.onlyKeys({"columns", "reference", "band", "ylabel", "x", "reference_x", "xlabel"});
      PlotRequest pr;
      for (std::size_t k = 0, m = p["columns"].size(1, 8); k < m; ++k) pr.columns.push_back(p["columns"].at(k).string());
      if (p.has("reference")) pr.reference = p["reference"].string();
      if (p.has("band")) pr.band = p["band"].nonNegative();
      // An x–y plot: the columns against "x", the reference against "reference_x" (else "x"); a
      // band around a path is not a band in y, so none; its labels default to the columns' units.
      if (p.has("x")) {
        pr.x = p["x"].string();
        if (p.has("band")) p["band"].fail("expected no band on an x–y plot (\"x\" is given)");
        pr.reference_x = p.has("reference_x") ? p["reference_x"].string() : pr.reference.empty() ? "" : pr.x;
        if (!pr.reference_x.empty() && pr.reference.empty())
          p["reference_x"].fail("expected a \"reference\" to plot against it");
        if (p.has("xlabel")) pr.xlabel = p["xlabel"].string();
      } else {
        for (const char* key : {"reference_x", "xlabel"})
          if (p.has(key)) p[key].fail("expected \"x\" too (" + std::string(key) + " is for an x–y plot)");
      }
      pr.ylabel = p.has("ylabel") ? p["ylabel"].string() : pr.x.empty() ? pr.columns[0] : "";
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
      if (l.has("scale")) e.scale = l["scale"].positive(1e9);
      r.leaderboard.push_back(e);
    }
  }

  // Lessons: pairs of submission files beside the config, and the lead the better one must keep.
  if (rub.has("lessons")) {
    for (std::size_t i = 0, n = rub["lessons"].size(0, 20); i < n; ++i) {
      const JsonView l = rub["lessons"].at(i);
      l.onlyKeys({"about", "better", "worse", "margin"});
      Lesson lesson{l["about"].string(), lessonPath(l["better"]), lessonPath(l["worse"]), l["margin"].number()};
      if (!(lesson.margin >= 0 && lesson.margin <= 1)) l["margin"].fail("expected a share of the points in [0, 1]");
      if (lesson.better == lesson.worse) l["worse"].fail("expected another submission than \"better\"");
      r.lessons.push_back(lesson);
    }
  }
  return r;
}

}  // namespace dyn
