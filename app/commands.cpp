// dynlab list / run / grade / schema.
#include "app/commands.h"

#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <limits>
#include <stdexcept>

#include "app/autograder.h"
#include "app/isolated_draw.h"
#include "app/movie.h"
#include "app/output.h"
#include "grading/escape.h"
#include "grading/grade.h"
#include "grading/report.h"
#include "grading/rubric.h"
#include "grading/scenario.h"
#include "grading/student.h"
#include "labs/run.h"
#include "labs/submission.h"
#include "labs/numbers.h"
#include "labs/utf8.h"

namespace fs = std::filesystem;

namespace dyn::app {

int listLabs() {
  // A data-defined lab's summary is its JSON's title: escaped and clipped like every name from a file.
  // A lab outside the tree (--labs, DYNLAB_LABS) says where it is.
  for (const auto& e : labRegistry()) {
    const std::string where = e.labs_folder.empty() ? "" : "  [" + termText(e.folder) + "]";
    std::printf("%-16s %s%s\n", e.name.c_str(), termName(e.summary).c_str(), where.c_str());
  }
  return 0;
}

std::string describeAgreement(const Lab& lab, const json& agreement) {
  // Every top-level number the lab reports (by key), with the lab's unit.
  std::string s;
  char buf[48];
  for (const auto& [key, v] : agreement.items()) {
    if (!v.is_number()) continue;
    // A count (rows compared) as a whole number, a measure of disagreement to 3 significant digits.
    if (v.is_number_integer() || v.is_number_unsigned()) std::snprintf(buf, sizeof buf, "%lld", v.get<long long>());
    else std::snprintf(buf, sizeof buf, "%.3g", v.get<double>());
    const std::string unit = lab.agreementUnit(key);
    s += (s.empty() ? "" : ", ") + key + " = " + buf + (unit.empty() ? "" : " " + unit);
  }
  return s;
}

std::string labDisplayName(const json& config, const std::string& lab) {
  const auto title = config.find("title");
  if (title == config.end() || !title->is_string() || title->get<std::string>().empty()) return lab;
  const std::string t = title->get<std::string>();
  return t.substr(0, t.find(": "));
}

json defaultsSubmission(const json& config, const std::string& lab) {
  json sub = {{"lab", lab}, {"gains", json::object()}};
  // Gains as numbers in double precision and options as the config sets them, as the tuning window saves them.
  const json gains = config.value("gains", json::object()), options = config.value("submission_options", json::object());
  for (const auto& [name, g] : gains.items())
    if (g.is_object() && g.contains("value") && g["value"].is_number()) sub["gains"][name] = g["value"].get<double>();
  for (const auto& [name, o] : options.items()) {
    if (!o.is_object() || !o.contains("target") || !o["target"].is_string()) continue;
    const json::json_pointer target(o["target"].get<std::string>());
    if (config.contains(target)) sub[name] = config.at(target);
  }
  return sub;
}

void applyScenario(LoadedLab& loaded, const std::string& scenario, std::optional<double> duration) {
  if (scenario.empty()) return;
  if (!loaded.config.contains("rubric"))
    throw InputError("<command line>", "--scenario", "expected a lab with a rubric; " + loaded.config_file + " has none");
  const Rubric rubric = parseRubric(JsonView(loaded.config, loaded.config_file));
  const Scenario& sc = findScenario(rubric, scenario);
  // The grader's seed (the lab's and the scenario's): the noise every submission is graded with.
  json cfg = scenarioConfig(loaded.config, rubric, sc, loaded.entry->name, loaded.config_file);
  if (duration) setRunDuration(cfg, *duration);
  loaded.lab = buildLab(*loaded.entry, cfg, loaded.config_file + " (scenario " + sc.name + ")");
  loaded.config = std::move(cfg);
}

fs::path defaultOut(const std::string& lab, const std::string& scenario, const std::string& sub) {
  fs::path out = fs::path("out") / lab;
  if (!scenario.empty()) {
    // A scenario's name as one folder name: anything but [A-Za-z0-9_-] becomes '_'.
    std::string folder = scenario;
    for (char& c : folder)
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-') c = '_';
    out /= fs::path("scenarios") / folder;
  }
  return sub.empty() ? out : out / sub;
}

// The watchdog `dynlab run` uses: the rubric's limits (so a run stops where a grade would, with
// the same sentence) without its step budget, since a run's length is its own --duration.
static Watchdog runWatchdog(const LoadedLab& loaded) {
  Watchdog wd;
  if (loaded.config.contains("rubric")) {
    const Rubric rubric = parseRubric(JsonView(loaded.config, loaded.config_file));
    checkColumns(rubric, loaded.lab->columns(), loaded.config_file);
    wd = rubric.watchdog;
  }
  wd.max_steps = std::numeric_limits<long>::max();
  return wd;
}

int runLab(const RunArgs& a) {
  LoadedLab loaded;
  Watchdog watchdog;
  try {
    loaded = loadLab(a.lab, a.config, a.gains, a.duration, studentPlant(a.student));
    applyScenario(loaded, a.scenario, a.duration);
    watchdog = runWatchdog(loaded);
    // A run must hold at least one step: a shorter one would report "ok" over an empty trace.
    if (loaded.lab->duration() < loaded.lab->dt()) {
      throw InputError("<command line>", "--duration", "expected at least one step (dt = " + fmt("%g", loaded.lab->dt()) +
                                                           " s), got " + exactNumber(loaded.lab->duration()) + " s");
    }
    if (a.video || a.frames)  // the frames drawn of the run are bounded too (labs/settings.h), before it runs
      if (const std::string problem = frameBoundProblem(loaded.lab->duration(), 30); !problem.empty())
        throw InputError("<command line>", a.video ? "--video" : "--frames", problem);
  } catch (const InputError& e) {
    std::fprintf(stderr, "error: %s\n", termText(e.what()).c_str());
    return 2;
  }
  const Lab& lab = *loaded.lab;
  const fs::path out = a.out.empty() ? defaultOut(a.lab, a.scenario) : fs::path(a.out);
  try {
    // Simulate first, each engine under the grader's watchdog; nothing is written until every run is done.
    std::optional<WatchedRun> hand, bullet;
    const Deadline never = Deadline::max();
    if (a.engine != "bullet") hand = runWatched(lab, Engine::Hand, watchdog, never, loaded.config_file);
    if (a.engine != "hand") bullet = runWatched(lab, Engine::Bullet, watchdog, never, loaded.config_file);

    Staging staging(out);
    staging.owns({"trace_hand.csv", "trace_bullet.csv", "summary.json", "video.mp4", "frames"});
    json summary = {{"lab", a.lab},
                    {"config", loaded.config_file},
                    {"gains", a.gains.empty() ? json(nullptr) : json(a.gains)},
                    {"scenario", a.scenario.empty() ? json(nullptr) : json(a.scenario)},
                    {"dt", lab.dt()},
                    {"duration", lab.duration()},
                    {"dynlab_version", DYNLAB_VERSION}};
    std::string status;
    for (auto* r : {&hand, &bullet}) {
      if (!*r) continue;
      const char* engine = r == &hand ? "hand" : "bullet";
      const bool complete = (*r)->failure.empty();
      staging.write(std::string("trace_") + engine + ".csv", (*r)->trace.csv());
      // A stopped run's trace is kept (it shows the blow-up) but its metrics are omitted: numbers
      // over part of a run read as if they described all of it.
      json& e = summary["engines"][engine];
      e = {{"status", complete ? "ok" : (*r)->failure}, {"complete", complete}, {"trace_hash", (*r)->trace.hash()}};
      if (complete) e["metrics"] = lab.metrics((*r)->trace);
      else {
        e["stopped_at"] = (*r)->failure_time;
        status += (status.empty() ? "" : "; ") + std::string(engine) + ": " + (*r)->failure;
      }
    }
    if (status.empty()) status = "ok";
    if (hand && bullet && hand->failure.empty() && bullet->failure.empty())
      summary["agreement"] = lab.agreement(hand->trace, bullet->trace);
    for (const auto& c : lab.columns())
      if (!lab.unit(c).empty()) summary["units"][c] = lab.unit(c);
    summary["status"] = status;
    staging.write("summary.json", summary.dump(2, ' ', false, json::error_handler_t::replace) + "\n");

    int frames = 0;
    if (a.video || a.frames) {
      const Trace& shown = hand ? hand->trace : bullet->trace;
      const Trace* ghost = hand && bullet ? &bullet->trace : nullptr;
      // Drawn in a child (app/isolated_draw.h): llvmpipe ends the process when memory runs out.
      frames = int(frameRows(shown, lab.dt(), 30).size());
      drawIsolated(a.video ? "video.mp4" : "the frames",
                   [&] { renderRun(lab, shown, ghost, {640, 480, 30, a.video, a.frames}, staging.path("")); });
    }
    staging.commit();

    // Tell the user where things are, how each engine ended and the headline numbers.
    const std::string under = a.scenario.empty() ? "" : " under scenario " + termText(a.scenario);
    std::printf("dynlab run %s%s: %.2f s at dt = %g s (%s)\n", a.lab.c_str(), under.c_str(), lab.duration(), lab.dt(),
                status.c_str());
    for (auto* r : {&hand, &bullet}) {
      if (!*r) continue;
      const char* engine = r == &hand ? "hand" : "bullet";
      std::printf("  %-6s trace    %s\n", engine, (out / (std::string("trace_") + engine + ".csv")).c_str());
      if (!(*r)->failure.empty())
        std::printf("  %-6s STOPPED  %s (trace up to there; metrics omitted)\n", engine, (*r)->failure.c_str());
    }
    std::printf("  summary         %s\n", (out / "summary.json").c_str());
    if (a.video) std::printf("  video           %s (%d frames)\n", (out / "video.mp4").c_str(), frames);
    if (a.frames) std::printf("  frames          %s/ (%d PNG)\n", (out / "frames").c_str(), frames);
    if (summary.contains("agreement")) std::printf("  hand vs Bullet: %s\n", describeAgreement(lab, summary["agreement"]).c_str());
    return status == "ok" ? 0 : 1;
  } catch (const std::bad_alloc&) {
    throw;  // main's one line for it (app/main.cpp)
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}

// Test hook for the robustness tests: DYNLAB_FAULT_INJECTION="crash:NAME,hang:NAME,fail:NAME,throw:NAME"
// makes grading the submission whose file stem is NAME abort, hang, exit 1 writing nothing (as on a
// full disk) or throw past every command's own handler (to main's). Unset in normal use.
static void injectFault(const std::string& submission) {
  const char* spec = std::getenv("DYNLAB_FAULT_INJECTION");
  if (!spec) return;
  const std::string stem = fs::path(submission).stem().string(), s = spec;
  if (s.find("crash:" + stem) != std::string::npos) std::abort();
  if (s.find("hang:" + stem) != std::string::npos)
    for (;;) pause();
  if (s.find("fail:" + stem) != std::string::npos) std::exit(1);
  if (s.find("throw:" + stem) != std::string::npos) throw std::logic_error("injected fault for " + stem);
}

std::string dynlabProgram() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return "dynlab";
  if (const char* path = std::getenv("PATH")) {
    const std::string dirs = path;
    for (std::size_t at = 0; at <= dirs.size();) {
      const std::size_t end = std::min(dirs.find(':', at), dirs.size());
      const fs::path candidate = fs::path(dirs.substr(at, end - at)) / "dynlab";
      if (end > at && fs::equivalent(candidate, self, ec)) return "dynlab";
      at = end + 1;
    }
  }
  return shellWord(self.string());
}

static GradeOptions gradeOptions(const GradeArgs& a, const std::string& out_dir) {
  GradeOptions o;
  o.expected_lab = a.lab;
  o.config_file = a.config;
  o.plant = studentPlant(a.student);
  o.time_budget = a.time_budget;
  if (a.plots) o.out_dir = out_dir;
  o.inline_plots = a.inline_plots && a.plots;
  return o;
}

int gradeOne(const GradeArgs& a) {
  injectFault(a.submission);
  GradeArgs args = a;
  try {
    // Gradescope's submitter, for a lab that gives each student their own plant (else not needed).
    if (!a.student_from.empty() && !a.lab.empty() && declaresVariants(a.config.empty() ? defaultConfigPath(a.lab) : a.config))
      args.student = gradescopeStudent(a.student_from);
    studentPlant(args.student);  // a bad --student, or no key to draw the plant with: nothing is graded
  } catch (const InputError& e) {
    std::fprintf(stderr, "error: %s\n", termText(e.what()).c_str());
    return 2;
  }
  GradeOutcome g;
  try {
    // Everything lands in OUT/.staging first; a failure never leaves a half-written results set.
    Staging staging(a.out);
    staging.owns({"results.json", "report.md", "report.html", "plots"});
    GradeOptions o = gradeOptions(args, staging.path("").string());
    o.replay_program = dynlabProgram();
    o.results_file = (fs::path(a.out) / "results.json").string();
    g = gradeSubmission(a.submission, o);
    // An internal error's plots may be partial: none are published (the old ones are removed).
    if (g.internal_error) fs::remove_all(staging.path("plots"));
    staging.write("results.json", dumpJson(g.results, 2) + "\n");
    staging.write("report.md", g.markdown);
    staging.write("report.html", g.html);
    staging.commit();
  } catch (const OutputConflict& e) {
    // OUT is the user's choice, and something of theirs is in the way: nothing was removed.
    std::fprintf(stderr, "error: results not written: %s\n", termText(e.what()).c_str());
    return 2;
  } catch (const std::exception& e) {
    // A disk or folder error: the grader's fault, not the submission's; the old results stay.
    std::fprintf(stderr, "error: results not written: %s\n", termText(e.what()).c_str());
    return 3;
  }
  if (!g.error.empty()) std::fprintf(stderr, "error: %s\n", g.error.c_str());
  std::fputs(g.report.c_str(), stdout);
  std::printf("results: %s\nreport:  %s\n", termText((fs::path(a.out) / "results.json").string()).c_str(),
              termText((fs::path(a.out) / "report.html").string()).c_str());
  if (!g.input_error && !g.internal_error)
    std::printf("replay:  %s\n", termText(replayCommand(dynlabProgram(), (fs::path(a.out) / "results.json").string(),
                                                         a.submission, gradeOptions(args, ""),
                                                         g.results["extra_data"].value("lab", std::string()))).c_str());
  // A grade the time budget cut short is written (score 0 for what it stopped) but is not a grade.
  if (g.out_of_time) std::fprintf(stderr, "error: %s: the grading time budget of %g s ran out; the grade is incomplete\n",
                                  utf8Quotable(a.submission).c_str(), a.time_budget);
  return g.input_error ? 2 : g.internal_error ? 3 : g.out_of_time ? 4 : 0;
}

// "metric x_rms of test 1 (Slider tracks x_d(t)): was 0.01113 → now 0.012; score was 2.1 → now 2"
// for every test whose metric value or score differs between two results.json.
static std::vector<std::string> metricChanges(const json& expected, const json& actual) {
  std::vector<std::string> out;
  const auto tests = [](const json& r) { return r.contains("tests") && r["tests"].is_array() ? r["tests"] : json::array(); };
  const json a = tests(expected), b = tests(actual);
  const auto field = [](const json& t, const char* key) {
    return t.is_object() && t.contains("extra_data") && t["extra_data"].is_object() ? t["extra_data"].value(key, json()) : json();
  };
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
    const json was = field(a[i], "value"), now = field(b[i], "value");
    const json was_score = a[i].is_object() ? a[i].value("score", json()) : json(), now_score = b[i].value("score", json());
    if (was == now && was_score == now_score) continue;
    const json metric = field(b[i], "metric");
    std::string line = "metric " + (metric.is_string() ? metric.get<std::string>() : "?") + " of test " + std::to_string(i + 1) + " (" +
                       b[i].value("name", std::string()) + "): was " + dumpJson(was) + " → now " + dumpJson(now);
    if (was_score != now_score) line += "; score was " + dumpJson(was_score) + " → now " + dumpJson(now_score);
    out.push_back(line);
  }
  return out;
}

int gradeReplay(const GradeArgs& a) {
  json expected;
  try {
    expected = loadJsonFile(a.replay);
    JsonView(expected, a.replay).requireObject();  // a results.json is an object
  } catch (const InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  // Re-grade in memory (no plots, nothing written) and compare everything but execution_time.
  GradeArgs quiet = a;
  quiet.plots = false;
  const GradeOutcome g = gradeSubmission(a.submission, gradeOptions(quiet, ""));
  json actual = g.results;
  // Plot paths and inline plots are only present when plots were drawn; they are not the grade.
  expected = withoutInlinePlots(expected);
  for (json* r : {&expected, &actual})
    if (r->contains("tests") && (*r)["tests"].is_array())
      for (auto& t : (*r)["tests"])
        if (t.is_object() && t.contains("extra_data") && t["extra_data"].is_object()) t["extra_data"].erase("plot");
  const auto diff = compareResults(expected, actual);
  if (diff.empty()) {
    std::printf("replay: match (score %s, trajectory hash %s)\n", dumpJson(actual["score"]).c_str(),
                termText(actual["extra_data"].value("fingerprint", json::object()).value("trajectory_hash", "-")).c_str());
    return 0;
  }
  std::printf("replay: MISMATCH, %zu difference(s):\n", diff.size());
  // Each metric first (was → now, with its test), then the differences as JSON paths.
  for (const auto& line : metricChanges(expected, actual)) std::printf("  %s\n", termText(line).c_str());
  for (std::size_t i = 0; i < diff.size() && i < 20; ++i) std::printf("  %s\n", termText(diff[i]).c_str());
  if (diff.size() > 20) std::printf("  ... and %zu more\n", diff.size() - 20);
  return 1;
}

int writeAutograderZip(const std::string& lab, const std::string& out) {
  if (!findLab(lab)) {
    std::fprintf(stderr, "error: <command line>: LAB: unknown lab \"%s\" (see dynlab list)\n", lab.c_str());
    return 2;
  }
  try {
    const LabEntry* entry = findLab(lab);
    writeAutograder(lab, DYNLAB_SOURCE_DIR, out, entry->labs_folder.empty() ? "" : entry->folder);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  std::printf("autograder: %s (upload it as the assignment's autograder on Gradescope)\n", out.c_str());
  return 0;
}

int printSchema(const std::string& lab) {
  try {
    const LoadedLab loaded = loadLab(lab);
    std::cout << submissionSchema(loaded.config, lab).dump(2) << "\n";
    return 0;
  } catch (const InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
}

int openUi(const UiArgs& a) {
  // The window is its own executable (it links libGL; dynlab links OSMesa), installed beside dynlab.
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  const fs::path ui = self.parent_path() / "dynlab-ui";
  if (ec || ::access(ui.c_str(), X_OK) != 0) {
    std::cerr << "error: dynlab ui runs " << ui.string() << ", which is missing: build it with `scripts/build "
              << "dynlab-ui` (scripts/demo builds dynlab alone; the window needs libglfw3-dev, which scripts/setup installs)\n";
    return 1;
  }
  std::vector<std::string> args = {ui.string(), a.lab};
  if (!a.config.empty()) args.insert(args.end(), {"--config", a.config});
  if (!a.gains.empty()) args.insert(args.end(), {"--gains", a.gains});
  if (!a.scenario.empty()) args.insert(args.end(), {"--scenario", a.scenario});
  if (!a.student.empty()) args.insert(args.end(), {"--student", a.student});
  args.insert(args.end(), a.extra.begin(), a.extra.end());
  std::vector<char*> argv;
  for (auto& s : args) argv.push_back(s.data());
  argv.push_back(nullptr);
  std::cout.flush();
  ::execv(ui.c_str(), argv.data());
  std::cerr << "error: cannot run " << ui.string() << ": " << std::strerror(errno) << "\n";
  return 1;
}

}  // namespace dyn::app
