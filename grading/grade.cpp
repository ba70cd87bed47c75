// Grading a submission against its lab's rubric; see grade.h.
#include "grading/grade.h"

#include <chrono>
#include <cmath>
#include <filesystem>
#include <map>

#include "grading/advice.h"
#include "grading/escape.h"
#include "grading/metric_doc.h"
#include "grading/report.h"
#include "grading/rubric.h"
#include "grading/scenario.h"
#include "grading/test_plot.h"
#include "labs/run.h"
#include "labs/numbers.h"
#include "labs/submission.h"
#include "labs/utf8.h"

namespace dyn {

std::string hashHex(const std::string& bytes) { return hashHexOf(fnv1a(bytes.data(), bytes.size())); }

json canonicalSubmission(const json& submission) {
  json out = submission;
  if (out.is_object()) out.erase("answers");
  // Every number a double: the parser keeps 1000 an integer and 1000.0 a float, one value.
  const auto canonical = [](auto& self, json& j) -> void {
    if (j.is_number()) j = j.get<double>();
    else if (j.is_structured())
      for (auto& v : j) self(self, v);
  };
  canonical(canonical, out);
  return out;
}

std::string submissionHash(const json& submission) { return hashHex(dumpJson(canonicalSubmission(submission))); }

std::string hashHexOf(std::uint64_t h) {
  char out[17];
  std::snprintf(out, sizeof out, "%016llx", static_cast<unsigned long long>(h));
  return out;
}

namespace {

// A results.json for a submission that could not be graded at all: the submission's fault (e is
// its InputError) or an internal error, whose details go to the staff (extra_data, the terminal
// and report.md), not into the student's feedback.
GradeOutcome failedOutcome(const std::string& full_message, const InputError* e) {
  // What the input said is echoed clipped (a 900 KB key is not quoted whole in any output); the
  // student's feedback names their file by its name alone (never the grader's folders).
  const std::string message = clipText(full_message, 600);
  const std::string shown =
      e ? clipText(InputError(std::filesystem::path(e->file()).filename().string(), e->path(), e->expected()).what(), 600) : message;
  GradeOutcome out;
  out.input_error = e != nullptr;
  out.internal_error = e == nullptr;
  const std::string feedback =
      e ? "**Your submission could not be graded.**\n\n" + mdText(shown) + "\n\nFix it and resubmit."
        : "**The grader failed while grading your submission.** This is an internal error, not a problem with your "
          "submission, and no score was given. Please resubmit later, and tell the course staff if it happens again.";
  out.results = {{"score", 0.0},
                 {"execution_time", 0.0},
                 {"output", feedback},
                 {"output_format", "md"},
                 {"tests", json::array()},
                 {"extra_data", {{"dynlab_version", DYNLAB_VERSION}, {"status", out.status()}}}};
  if (e) out.results["extra_data"]["error"] = {{"file", clipText(e->file())}, {"path", e->path().empty() ? "/" : clipText(e->path())}, {"expected", clipText(e->expected())}};
  else out.results["extra_data"]["internal_error"] = message;
  out.results = jsonSanitized(out.results);
  // The terminal: the one-line error goes to stderr (dynlab grade), the report says what kind it was.
  out.error = termText(e ? message : "internal error: " + message);
  out.report = std::string("Score: 0 (not graded") + (e ? "" : ": internal error") + ")\n";
  out.markdown = std::string("# dynlab grade\n\n**Not graded") + (e ? "" : " (internal error)") + ":** " + mdText(shown) + "\n";
  out.html = renderHtml(out.markdown);
  return out;
}

}  // namespace

std::string timeBudgetProblem(double seconds) {
  if (seconds >= kMinTimeBudget && seconds <= kMaxTimeBudget) return "";  // NaN fails both
  return std::string("expected a ") + (std::isfinite(seconds) ? "" : "finite ") + "time budget in [" + exactNumber(kMinTimeBudget) +
         ", " + exactNumber(kMaxTimeBudget) + "] s, got " + exactNumber(seconds);
}

GradeOutcome gradeSubmission(const std::string& file, const GradeOptions& opt) {
  json sub;
  try {
    sub = loadJsonFile(file, 1u << 20);
  } catch (const InputError& e) {
    return failedOutcome(e.what(), &e);
  } catch (const std::exception& e) {
    return failedOutcome(utf8Quotable(e.what()), nullptr);
  }
  return gradeSubmission(sub, file, opt);
}

GradeOutcome gradeSubmission(const json& sub, const std::string& file, const GradeOptions& opt) {
  const auto started = std::chrono::steady_clock::now();
  const Deadline deadline = started + std::chrono::milliseconds(long(opt.time_budget * 1e3));
  std::string staff_file;  // the lab config once known: an error naming it is the staff's
  try {
    // The submission: a JSON object naming a lab; the lab's config with the gains applied.
    const JsonView view(sub, file);
    view.requireObject();
    const std::string lab_name = view["lab"].string();
    if (!opt.expected_lab.empty() && lab_name != opt.expected_lab)
      view["lab"].fail("expected \"" + opt.expected_lab + "\" (this assignment's lab), got \"" + clipText(lab_name) + "\"");
    const LabEntry* entry = findLab(lab_name);
    if (!entry) {
      std::string list;
      for (const auto& e : labRegistry()) list += (list.empty() ? "" : ", ") + e.name;
      view["lab"].fail("expected the name of a dynlab lab (" + list + "), got \"" + clipText(lab_name) + "\"");
    }
    const std::string config_file = opt.config_file.empty() ? defaultConfigPath(lab_name) : opt.config_file;
    staff_file = config_file;
    const json written = loadJsonFile(config_file);
    // The student's plant (labs/variants.h): the config graded from here on; it must build as it is.
    const json base = plantConfig(written, opt.plant, lab_name, config_file);
    const auto base_lab = buildLab(*entry, base, config_file);  // the lab config itself must be valid
    const Rubric rubric = parseRubric(JsonView(base, config_file));
    checkColumns(rubric, base_lab->columns(), config_file);
    const json applied = applySubmission(base, view, lab_name, true);
    buildLab(*entry, applied, file);  // the gains are valid for the lab

    // Fingerprint inputs: canonical dumps (sorted keys), so whitespace does not matter.
    GradeReport rep;
    rep.lab = lab_name;
    rep.submission = utf8Quotable(file);  // a file name is not always UTF-8; results.json must be
    rep.answers = submissionAnswers(view);
    rep.student = opt.plant.student;
    if (!opt.plant.nominal()) rep.plant = drawPlant(JsonView(written, config_file), opt.plant, lab_name);
    rep.fingerprint = {{"dynlab_version", DYNLAB_VERSION},
                       {"lab_config_hash", hashHex(dumpJson(base))},
                       {"submission_hash", submissionHash(sub)}};

    // Run each scenario the tests use, once, in rubric order.
    std::map<std::string, ScenarioRun> runs;
    std::string trajectories;
    for (const Scenario& sc : rubric.scenarios) {
      bool used = false;
      for (const auto& t : rubric.tests) used = used || t.scenario == sc.name;
      for (const auto& l : rubric.leaderboard) used = used || l.scenario == sc.name;
      if (!used) continue;
      const json cfg = scenarioConfig(applied, rubric, sc, lab_name, config_file);
      const auto lab = buildLab(*entry, cfg, config_file + " (scenario " + sc.name + ")");
      ScenarioRun run = runScenario(*lab, rubric.watchdog, deadline, config_file, opt.stop);
      rep.scenarios.push_back({sc, lab->dt(), run.trace.hash(), run.failure, run.failure_time, run.screen.notes,
                               run.metrics, run.out_of_time});
      trajectories += hashHex(std::to_string(rep.scenarios.back().trace_hash));  // hashed once: a pass over every number
      runs.emplace(sc.name, std::move(run));
    }
    rep.fingerprint["trajectory_hash"] = hashHex(trajectories);

    // Score each test on its scenario's metric, shown with its unit (the lab's metric_docs, or the
    // screening's own).
    const std::map<std::string, MetricDoc> docs = parseMetricDocs(JsonView(base, config_file));
    const std::vector<LinearLoop> loops = base_lab->linearise();
    auto docOf = [&](const std::string& metric) {
      if (const auto it = docs.find(metric); it != docs.end()) return it->second;
      return screeningMetricDoc(metric, loops).value_or(MetricDoc{});
    };
    for (std::size_t i = 0; i < rubric.tests.size(); ++i) {
      const RubricTest& t = rubric.tests[i];
      const ScenarioRun& run = runs.at(t.scenario);
      const MetricDoc doc = docOf(t.metric);
      // What to change: chosen by the law the submission uses and by what its run measured.
      GradedTest g{t, 0.0, NAN, "", "", doc.unit, std::nullopt, "", chooseAdvice(doc.advice, {applied, t.scenario, run.metrics})};
      // A test of a simulated metric (not the screening's) gets a plot.
      if (!run.screen.metrics.contains(t.metric)) g.plan = planTestPlot(rubric, i, docs, *base_lab);
      if (run.metrics.contains(t.metric)) {
        g.value = run.metrics[t.metric].get<double>();
        g.score = t.points * partialCredit(g.value, t.full, t.zero);
      } else if (!run.failure.empty()) {
        g.note = run.failure;
      } else {
        // The rubric is the staff's: a metric the lab does not report is never the student's fault.
        throw InputError(config_file, "/rubric/tests/" + std::to_string(i) + "/metric",
                         "expected a metric this lab reports, got \"" + clipText(t.metric) + "\"");
      }
      rep.tests.push_back(g);
    }
    for (const auto& l : rubric.leaderboard) {
      const ScenarioRun& run = runs.at(l.scenario);
      if (run.metrics.contains(l.metric) && std::isfinite(run.metrics[l.metric].get<double>()))
        rep.leaderboard.push_back({{"name", l.name}, {"value", run.metrics[l.metric].get<double>() * l.scale}, {"order", l.order}});
    }

    // Plots of each test's response against its reference and tolerance band.
    if (!opt.out_dir.empty()) writeTestPlots(rep, runs, opt.out_dir, opt.plot_width, opt.plot_height);
    rep.inline_plots = opt.inline_plots;
    if (!opt.results_file.empty()) rep.replay = replayCommand(opt.replay_program, opt.results_file, file, opt, lab_name);

    GradeOutcome out;
    for (const auto& s : rep.scenarios) out.out_of_time = out.out_of_time || s.out_of_time;
    out.results = resultsJson(rep);
    out.results["extra_data"]["status"] = out.status();
    out.report = terminalReport(rep);
    out.markdown = markdownReport(rep);
    out.html = reportHtml(rep, out.markdown, "dynlab grade: " + lab_name);
    out.results["execution_time"] =
        std::round(std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count() * 100) / 100;
    if (opt.keep_runs) {
      out.graded = std::move(rep);
      out.runs = std::move(runs);
    }
    return out;
  } catch (const InputError& e) {
    // Blame follows the file: only an error in the submission itself is the student's to fix; one in
    // the lab config or its rubric (--config, a scenario patch) is the staff's, an internal error.
    if (!staff_file.empty() && e.file().rfind(staff_file, 0) == 0) return failedOutcome(utf8Quotable(std::string("staff file: ") + e.what()), nullptr);
    return failedOutcome(e.what(), &e);
  } catch (const std::exception& e) {
    // Not the input's fault; what() may quote a path that is not UTF-8.
    return failedOutcome(utf8Quotable(e.what()), nullptr);
  }
}

std::vector<std::string> compareResults(const json& expected, const json& actual) {
  json a = expected, b = actual;
  a.erase("execution_time");
  b.erase("execution_time");
  std::vector<std::string> out;
  const auto shown = [](const json& v) {
    std::string s = dumpJson(v);
    return s.size() > 60 ? s.substr(0, 57) + "..." : s;  // may cut a character: shown through termText
  };
  for (const auto& op : json::diff(a, b)) {
    const std::string path = op.at("path"), kind = op.at("op");
    const json::json_pointer ptr(path);
    const std::string was = a.contains(ptr) ? shown(a.at(ptr)) : "", now = op.contains("value") ? shown(op.at("value")) : "";
    if (kind == "replace") out.push_back(path + ": was " + was + " → now " + now);
    else if (kind == "add") out.push_back(path + ": added, now " + now);
    else if (kind == "remove") out.push_back(path + ": removed, was " + was);
    else out.push_back(kind + " " + path);
  }
  return out;
}

std::string replayCommand(const std::string& program, const std::string& results_file, const std::string& submission,
                          const GradeOptions& o, const std::string& lab) {
  const auto path = [](const std::string& p) { return shellWord(std::filesystem::absolute(p).lexically_normal().string()); };
  std::string cmd = program + " grade --replay " + path(results_file) + " " + path(submission);
  if (!o.expected_lab.empty()) cmd += " --lab " + shellWord(o.expected_lab);
  if (!o.config_file.empty()) cmd += " --config " + path(o.config_file);
  if (!o.plant.student.empty()) cmd += " --student " + shellWord(o.plant.student);
  const LabEntry* entry = findLab(lab.empty() ? o.expected_lab : lab);
  if (entry && !entry->labs_folder.empty()) cmd += " --labs " + path(entry->labs_folder);
  return cmd;
}

}  // namespace dyn
