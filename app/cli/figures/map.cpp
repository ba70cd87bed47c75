// dynlab map LAB --x NAME=a:b:n --y NAME=a:b:n: a stability (or score) map over two gains or
// parameters. At every grid point the lab is rebuilt with those two values and
//   * screened (grading/scenario.h screenLoops: stable or not, each loop's delay margin), and
//   * with --sim, run on the hand engine under the rubric's watchdog (runScenario): stable if the
//     run completes;
// the picture shows the simulated (else the screened) verdict per cell, with the screening's
// boundary — where the smallest (delay margin − delay) over the loops crosses zero, i.e. the delay
// margin curve when one axis is a delay — drawn over it.
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <set>
#include <thread>

#include "app/cli/commands.h"
#include "app/cli/course/course.h"
#include "app/cli/figures/map_plot.h"
#include "app/cli/output.h"
#include "grading/metric_doc.h"
#include "grading/rubric.h"
#include "grading/scenario.h"
#include "labs/run.h"
#include "labs/submission.h"

namespace fs = std::filesystem;

namespace dyn::app {
namespace {

constexpr int kMaxPoints = 200;  // per axis

// One axis: what is swept (a JSON pointer into the config), over which values, and how to label it.
struct Axis {
  std::string flag, spec, name, target, unit, doc;
  std::string gain;  // the gain's name when a gain is swept
  double a = 0, b = 1;
  int n = 2;
  double at(int i) const { return a + (b - a) * double(i) / double(n - 1); }
  std::string label() const {
    std::string s = name + (doc.empty() ? "" : ": " + doc);
    return unit.empty() || unit == "1" ? s : s + " (" + unit + ")";
  }
};

[[noreturn]] void bad(const std::string& flag, const std::string& what) { throw InputError("<command line>", flag, what); }

double parseNumber(const std::string& flag, const std::string& spec, const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(v))
    bad(flag, "expected NAME=a:b:n with numbers a and b, got \"" + spec + "\"");
  return v;
}

// NAME=a:b:n, NAME a gain, a parameter the lab's JSON declares under map/parameters, or a pointer.
Axis parseAxis(const std::string& flag, const std::string& spec, const json& config, const std::string& file) {
  Axis ax;
  ax.flag = flag;
  ax.spec = spec;
  const std::size_t eq = spec.find('=');
  if (eq == std::string::npos || eq == 0) bad(flag, "expected NAME=a:b:n (e.g. kp_f=0:2:41), got \"" + spec + "\"");
  ax.name = spec.substr(0, eq);
  std::vector<std::string> parts;
  std::string rest = spec.substr(eq + 1);
  for (std::size_t at; (at = rest.find(':')) != std::string::npos; rest.erase(0, at + 1)) parts.push_back(rest.substr(0, at));
  parts.push_back(rest);
  if (parts.size() != 3) bad(flag, "expected NAME=a:b:n (three fields after '='), got \"" + spec + "\"");
  ax.a = parseNumber(flag, spec, parts[0]);
  ax.b = parseNumber(flag, spec, parts[1]);
  char* end = nullptr;
  const long n = std::strtol(parts[2].c_str(), &end, 10);
  if (parts[2].empty() || *end != '\0' || n < 2 || n > kMaxPoints)
    bad(flag, "expected a number of points n in [2, " + std::to_string(kMaxPoints) + "], got \"" + parts[2] + "\" in \"" + spec + "\"");
  ax.n = int(n);
  if (ax.a == ax.b) bad(flag, "expected a ≠ b in \"" + spec + "\"");

  const json& gains = config.at("gains");
  const json params = config.contains("map") ? config["map"].value("parameters", json::object()) : json::object();
  if (gains.contains(ax.name)) {
    // A gain: within its declared bounds.
    const json& g = gains[ax.name];
    ax.gain = ax.name;
    ax.target = "/gains/" + ax.name + "/value";
    ax.unit = g.value("unit", "");
    ax.doc = g.value("doc", "");
    const double lo = g.at("min").get<double>(), hi = g.at("max").get<double>();
    for (double v : {ax.a, ax.b})
      if (v < lo || v > hi)
        bad(flag, fmtConfigNumber(v) + " is outside " + ax.name + "'s bounds [" + fmtConfigNumber(lo) + ", " + fmtConfigNumber(hi) + "]");
    return ax;
  }
  if (params.contains(ax.name)) {
    const JsonView p = JsonView(config, file)["map"]["parameters"][ax.name];
    p.onlyKeys({"target", "unit", "doc"});
    ax.target = p["target"].string();
    ax.unit = p.has("unit") ? p["unit"].string() : "";
    ax.doc = p.has("doc") ? p["doc"].string() : "";
  } else if (ax.name[0] == '/') {
    ax.target = ax.name;
  } else {
    std::string known;
    for (const auto& [k, _] : gains.items()) known += (known.empty() ? "" : ", ") + k;
    for (const auto& [k, _] : params.items()) known += ", " + k;
    bad(flag, "unknown gain or parameter \"" + ax.name + "\" (this lab's: " + known + "; or a JSON pointer such as /controller/delay)");
  }
  bool number = false;
  try {
    const json::json_pointer ptr(ax.target);
    number = config.contains(ptr) && config.at(ptr).is_number();
  } catch (const json::exception&) {
  }
  if (!number) bad(flag, "\"" + ax.target + "\" is not a number of the lab's config");
  return ax;
}

// What was computed at one grid point.
struct Point {
  bool screen_stable = false;
  double margin = 0;        // smallest (delay margin − delay) over the loops with feedback, s
  int sim_stable = -1;      // -1: not simulated
  double value = NAN;       // the --metric, if any
  std::string sim_failure;  // why the run stopped
};

struct Grid {
  Axis x, y;
  json config;
  std::string file;
  const LabEntry* entry = nullptr;
  Rubric rubric;
  std::string metric;
  bool metric_screened = false;  // the metric comes from the screening (else from the run)

  json configAt(int i, int j) const {
    json c = config;
    c[json::json_pointer(x.target)] = x.at(i);
    c[json::json_pointer(y.target)] = y.at(j);
    return c;
  }

  Point evaluate(int i, int j, bool simulate) const {
    const auto lab = buildLab(*entry, configAt(i, j), file);
    Point p;
    const ScreenResult screen = screenLoops(*lab);
    p.screen_stable = !screen.unstable;
    p.margin = kUnboundedDelay;
    for (const LinearLoop& loop : lab->linearise()) {
      bool feedback = false;
      for (double c : loop.num) feedback = feedback || c != 0;
      if (feedback) p.margin = std::min(p.margin, screen.metrics[loop.name + "_delay_margin"].get<double>() - loop.delay);
    }
    // The drawn boundary never contradicts the screening's own verdict.
    p.margin = p.screen_stable ? std::max(p.margin, 1e-12) : std::min(p.margin, -1e-12);
    if (!metric.empty() && metric_screened) p.value = screen.metrics[metric].get<double>();
    if (simulate) {
      const ScenarioRun run = runScenario(*lab, rubric.watchdog, Deadline::max(), file);
      p.sim_stable = run.failure.empty() ? 1 : 0;
      p.sim_failure = run.failure;
      if (!metric.empty() && !metric_screened && run.metrics.contains(metric)) p.value = run.metrics[metric].get<double>();
    }
    return p;
  }
};

// Every point, rows shared out to the threads; each result lands in its own slot, so the map is the
// same whatever the thread count.
std::vector<Point> evaluateAll(const Grid& g, bool simulate, int jobs) {
  std::vector<Point> points(std::size_t(g.x.n) * std::size_t(g.y.n));
  std::atomic<int> next_row{0};
  std::mutex error_mutex;
  std::string error;
  auto work = [&] {
    for (int j; (j = next_row++) < g.y.n;) {
      try {
        for (int i = 0; i < g.x.n; ++i) points[std::size_t(j) * std::size_t(g.x.n) + std::size_t(i)] = g.evaluate(i, j, simulate);
      } catch (const std::exception& e) {
        const std::lock_guard<std::mutex> lock(error_mutex);
        if (error.empty()) error = e.what();
      }
    }
  };
  std::vector<std::thread> threads;
  for (int t = 1; t < jobs; ++t) threads.emplace_back(work);
  work();
  for (auto& t : threads) t.join();
  if (!error.empty()) throw std::runtime_error(error);
  return points;
}

std::string csv(const Grid& g, const std::vector<Point>& points) {
  std::string out = g.x.name + "," + g.y.name + ",screen_stable,screen_margin,sim_stable" + (g.metric.empty() ? "" : "," + g.metric) + "\n";
  char line[256];
  for (int j = 0; j < g.y.n; ++j)
    for (int i = 0; i < g.x.n; ++i) {
      const Point& p = points[std::size_t(j) * std::size_t(g.x.n) + std::size_t(i)];
      std::snprintf(line, sizeof line, "%.17g,%.17g,%d,%.17g,%d", g.x.at(i), g.y.at(j), int(p.screen_stable), p.margin, p.sim_stable);
      out += line;
      if (!g.metric.empty()) {
        std::snprintf(line, sizeof line, ",%.17g", p.value);
        out += line;
      }
      out += "\n";
    }
  return out;
}

// The legend's word for the simulated cells that did not complete, from why they stopped: a
// lab's own watchdog says it ("stopped: the grasp slipped at ..." → "the grasp slipped"), any
// other failure is an unstable run.
std::string stoppedLabel(const std::vector<Point>& points) {
  std::set<std::string> kinds;
  bool unstable = false;
  for (const Point& p : points) {
    if (p.sim_stable != 0) continue;
    const std::string& f = p.sim_failure;
    if (f.rfind("stopped: ", 0) != 0) {
      unstable = true;
      continue;
    }
    const std::size_t at = f.find(" at ", 9);
    kinds.insert(f.substr(9, at == std::string::npos ? std::string::npos : at - 9));
  }
  std::string lab_words;
  for (const auto& k : kinds) lab_words += (lab_words.empty() ? "" : " or ") + k;
  if (lab_words.empty()) return "unstable (watchdog)";
  return unstable ? "unstable, or stopped: " + lab_words : "stopped: " + lab_words;
}

double seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

}  // namespace

int map(const MapArgs& a) {
  Grid g;
  const fs::path out = a.out.empty() ? fs::path("out") / a.lab / "map.pdf" : fs::path(a.out);
  try {
    // The lab with the user's gains and duration; then the options the swept gains act under.
    LoadedLab loaded = loadLab(a.lab, a.config, a.gains, a.duration);
    g.entry = loaded.entry;
    g.file = loaded.config_file;
    g.config = loaded.config;
    g.x = parseAxis("--x", a.x, g.config, g.file);
    g.y = parseAxis("--y", a.y, g.config, g.file);
    if (g.x.target == g.y.target) bad("--y", "expected another gain or parameter than --x's \"" + g.x.name + "\"");
    const json submitted = a.gains.empty() ? json::object() : loadJsonFile(a.gains, 1u << 20);
    json options = json::object();
    const json gain_options = g.config.contains("map") ? g.config["map"].value("gain_options", json::object()) : json::object();
    for (const Axis* ax : {&g.x, &g.y})
      if (!ax->gain.empty() && gain_options.contains(ax->gain))
        for (const auto& [key, choice] : gain_options[ax->gain].items()) {
          if (submitted.contains(key)) continue;  // the user's own choice wins
          if (options.contains(key) && options[key] != choice)
            bad(ax->flag, g.x.name + " and " + g.y.name + " act under different " + key + " (" + options[key].dump() + ", " + choice.dump() + ")");
          options[key] = choice;
        }
    if (!options.empty()) g.config = applySubmission(g.config, JsonView(options, g.file + ": /map/gain_options"), a.lab, false);
    g.rubric = parseRubric(JsonView(g.config, g.file));
    // The metric: a screening metric, or (with --sim) one the rubric or the lab's docs name.
    const auto corner = buildLab(*g.entry, g.configAt(0, 0), g.file);
    buildLab(*g.entry, g.configAt(g.x.n - 1, g.y.n - 1), g.file);  // both ends of both axes build
    if (!a.metric.empty()) {
      g.metric = a.metric;
      g.metric_screened = screenLoops(*corner).metrics.contains(a.metric);
      std::set<std::string> measured;
      for (const auto& t : g.rubric.tests) measured.insert(t.metric);
      for (const auto& [k, _] : parseMetricDocs(JsonView(g.config, g.file))) measured.insert(k);
      if (!g.metric_screened && !measured.count(a.metric))
        bad("--metric", "unknown metric \"" + a.metric + "\" (a screening metric such as force_delay_margin, or a rubric metric with --sim)");
      if (!g.metric_screened && !a.sim) bad("--metric", "\"" + a.metric + "\" is measured on a run: add --sim");
    }
    if (out.has_parent_path() && !fs::is_directory(out.parent_path()))
      bad("--out", "the folder of \"" + out.string() + "\" does not exist");
    const std::string ext = out.extension().string();
    if (ext != ".pdf" && ext != ".svg" && ext != ".png") bad("--out", "expected a .pdf, .svg or .png file, got \"" + out.string() + "\"");
    if (!a.data.empty() && fs::path(a.data).has_parent_path() && !fs::is_directory(fs::path(a.data).parent_path()))
      bad("--data", "the folder of \"" + a.data + "\" does not exist");
  } catch (const InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }

  try {
    const auto start = std::chrono::steady_clock::now();
    const int jobs = a.jobs > 0 ? a.jobs : std::max(1, int(std::thread::hardware_concurrency()));
    const std::vector<Point> points = evaluateAll(g, a.sim, a.sim ? jobs : 1);
    const double took = seconds(start);

    // The picture: the simulated verdict (else the screened one) per cell, the screening's boundary.
    MapPicture pic;
    for (int i = 0; i < g.x.n; ++i) pic.xs.push_back(g.x.at(i));
    for (int j = 0; j < g.y.n; ++j) pic.ys.push_back(g.y.at(j));
    int stable = 0, agree = 0;
    for (const Point& p : points) {
      const bool s = a.sim ? p.sim_stable == 1 : p.screen_stable;
      pic.stable.push_back(s);
      pic.boundary.push_back(p.margin);
      if (!g.metric.empty()) pic.value.push_back(p.value);
      stable += s;
      agree += s == p.screen_stable;
    }
    const std::string law = g.config.contains("submission_options") ? [&] {
      std::string s;
      for (const auto& [key, o] : g.config["submission_options"].items())
        s += ", " + key + " " + g.config.at(json::json_pointer(o.at("target").get<std::string>())).get<std::string>();
      return s;
    }() : "";
    pic.title = labDisplayName(g.config, a.lab) + (a.sim ? ": simulated, " + fmtConfigNumber(g.config["simulation"]["duration"].get<double>()) + " s per point" : ": screening")
                + law;
    pic.xlabel = g.x.label();
    pic.ylabel = g.y.label();
    pic.stable_label = a.sim ? "stable (run completes)" : "stable";
    pic.unstable_label = a.sim ? stoppedLabel(points) : "unstable";
    pic.boundary_label = "screening boundary";
    if (!g.metric.empty()) {
      const auto docs = parseMetricDocs(JsonView(g.config, g.file));
      std::string unit = docs.count(g.metric) ? docs.at(g.metric).unit : "";
      if (auto d = screeningMetricDoc(g.metric, buildLab(*g.entry, g.configAt(0, 0), g.file)->linearise())) unit = d->unit;
      pic.value_label = g.metric + (unit.empty() || unit == "1" ? "" : " (" + unit + ")");
    }
    writeMapPicture(out.string(), pic);
    if (!a.data.empty()) writeFileAtomic(a.data, csv(g, points));

    std::printf("dynlab map %s: %d × %d points (%s × %s), %s in %.1f s%s\n", a.lab.c_str(), g.x.n, g.y.n, g.x.name.c_str(),
                g.y.name.c_str(), a.sim ? "screened and simulated" : "screened", took,
                a.sim ? (" on " + std::to_string(jobs) + " threads").c_str() : "");
    std::printf("  %d stable, %d %s%s\n", stable, int(points.size()) - stable, pic.unstable_label.c_str(),
                a.sim ? ("; the screening agrees at " + std::to_string(agree) + " points").c_str() : "");
    std::printf("  map   %s\n", out.c_str());
    if (!a.data.empty()) std::printf("  data  %s\n", a.data.c_str());
    return 0;
  } catch (const InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}

}  // namespace dyn::app
