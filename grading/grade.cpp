// Grading a submission against its lab's rubric; see grade.h.
#include "grading/grade.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>

#include "labs/run.h"
#include "labs/submission.h"

namespace dyn {
namespace {

std::string number(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", x);
  return b;
}

json failedResults(const std::string& message) {
  return {{"score", 0.0},
          {"output", "Your submission could not be graded:\n\n    " + message + "\n\nFix it and resubmit."},
          {"output_format", "md"},
          {"tests", json::array()}};
}

}  // namespace

double partialCredit(double m, double full, double zero) {
  if (!std::isfinite(m)) return 0.0;
  if (full == zero) return (m == full) ? 1.0 : 0.0;
  return std::clamp((zero - m) / (zero - full), 0.0, 1.0);
}

GradeOutcome gradeSubmission(const std::string& file) {
  GradeOutcome out;
  try {
    const json sub = loadJsonFile(file, 1u << 20);
    const JsonView view(sub, file);
    view.requireObject();
    const std::string lab_name = view["lab"].string();
    const LabEntry* entry = findLab(lab_name);
    if (!entry) view["lab"].fail("expected the name of a dynlab lab, got \"" + lab_name + "\"");
    const std::string config_file = defaultConfigPath(lab_name);
    const json config = applySubmission(loadJsonFile(config_file), view, lab_name, true);
    const auto lab = buildLab(*entry, config, file);

    // Run the lab once (hand-written engine) and score each rubric test on its metrics.
    const RunResult run = runEngine(*lab, Engine::Hand);
    const json metrics = lab->metrics(run.trace);
    json tests = json::array();
    double total = 0, max_total = 0;
    std::string report = "Grading " + file + " (" + lab_name + ")\n";
    for (const auto& t : config.at("rubric").at("tests")) {
      const double points = t.at("points").get<double>();
      const std::string metric = t.at("metric");
      double score = 0;
      std::string text;
      if (!run.failure.empty()) {
        text = "The simulation did not finish: " + run.failure + ".";
      } else {
        const double m = metrics.at(metric).get<double>();
        const double full = t.at("full").get<double>(), zero = t.at("zero").get<double>();
        score = points * partialCredit(m, full, zero);
        text = metric + " = " + number(m) + " (full credit at " + number(full) + ", zero at " + number(zero) + ")";
      }
      total += score;
      max_total += points;
      tests.push_back({{"name", t.at("name")},
                       {"score", score},
                       {"max_score", points},
                       {"status", score >= points - 1e-9 ? "passed" : "failed"},
                       {"output", text},
                       {"visibility", t.value("visibility", "visible")}});
      report += "  " + number(score) + "/" + number(points) + "  " + t.at("name").get<std::string>() + ": " + text + "\n";
    }
    report += "Total: " + number(total) + "/" + number(max_total) + "\n";
    out.results = {{"score", total},
                   {"output", "dynlab " + lab_name + ": " + number(total) + " / " + number(max_total) + " points."},
                   {"output_format", "md"},
                   {"tests", tests},
                   {"extra_data", {{"lab", lab_name}, {"metrics", metrics}, {"trace_hash", run.trace.hash()}}}};
    out.report = report;
  } catch (const InputError& e) {
    out.input_error = true;
    out.results = failedResults(e.what());
    out.report = std::string("error: ") + e.what() + "\nScore: 0\n";
  } catch (const std::exception& e) {
    out.results = failedResults(std::string("internal error: ") + e.what());
    out.report = std::string("internal error: ") + e.what() + "\n";
  }
  return out;
}

}  // namespace dyn
