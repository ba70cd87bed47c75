// From each grader's results.json to a gradebook row, and the gradebook itself; see batch.h.
#include <algorithm>
#include <cstdio>
#include <map>

#include "app/batch.h"
#include "app/output.h"
#include "grading/escape.h"
#include "grading/rubric.h"
#include "labs/config.h"
#include "labs/lab.h"

namespace fs = std::filesystem;

namespace dyn::app::batch {

Row failedRow(const Submission& s, const std::string& status, const std::string& reason) {
  return {s.name, s.folder, status, jsonText(reason), 0, 0, false, {}};
}

Row rowFromResults(const Submission& s, const fs::path& results, int exit_code, const std::string& log_tail) {
  const std::string said = log_tail.empty() ? "" : ": " + log_tail;
  json r;
  try {
    r = loadJsonFile(results.string());
  } catch (const std::exception&) {
    return failedRow(s, "internal error", "internal error: the grader exited with status " + std::to_string(exit_code) +
                                              " and no readable results.json" + said);
  }
  const json extra = r.value("extra_data", json::object());
  const json error = extra.is_object() ? extra.value("error", json()) : json();
  // Exit 2 is an invalid submission: its results.json says what is wrong (where and what was expected).
  if (exit_code == 2 && error.is_object()) {
    const std::string file = error.value("file", ""), where = error.value("path", ""), expected = error.value("expected", "");
    const std::string what = where + (where.empty() ? "" : ": ") + expected;
    // An error in another file (the lab config) is the course's problem, not the student's.
    if (!file.empty() && file != fs::absolute(s.file).string())
      return failedRow(s, "internal error", "internal error: " + file + ": " + what);
    return failedRow(s, "invalid submission", what);
  }
  // Exit 4: the grader's time budget ran out; what it scored before is in its results.json.
  const bool budget = exit_code == 4;
  if ((exit_code != 0 && !budget) || !error.is_null() || !r.value("score", json()).is_number())
    return failedRow(s, "internal error", "internal error: the grader exited with status " + std::to_string(exit_code) +
                                              (exit_code == 0 ? " but its results.json holds no grade" : "") + said);
  Row row{s.name, s.folder, "graded", "", r.value("score", 0.0), 0, true, {}};
  try {
    for (const auto& t : r.value("tests", json::array())) {
      row.tests.emplace_back(t.value("name", "?"), t.value("score", 0.0));
      row.max_score += t.value("max_score", 0.0);
    }
    // A scenario that did not complete: the watchdog's sentence, or the time budget running out.
    const json scenarios = extra.value("scenarios", json::object());
    for (const auto& [name, sc] : scenarios.items()) {
      const std::string st = sc.value("status", "completed");
      if (st == "completed") continue;
      const bool out_of_time = st.rfind("not graded", 0) == 0;
      if (row.status == "graded" || out_of_time) row.status = out_of_time ? "timed out" : "graded (unstable run)";
      row.reason += (row.reason.empty() ? "" : "; ") + name + ": " + st;
    }
  } catch (const json::exception& e) {
    return failedRow(s, "internal error", std::string("internal error: a results.json of an unexpected shape: ") + e.what());
  }
  if (budget && row.status != "timed out") {
    row.status = "timed out";
    row.reason += std::string(row.reason.empty() ? "" : "; ") + "the grading time budget ran out";
  }
  row.reason = jsonText(row.reason);
  return row;
}

void writeFallbackResults(const fs::path& results, const Row& row) {
  const json r = {{"score", 0.0},
                  {"output", "**This submission was not graded:** " + row.reason + "\n\nThe course staff have been told."},
                  {"output_format", "md"},
                  {"tests", json::array()},
                  {"extra_data", {{"status", row.status}, {"reason", row.reason}}}};
  writeFileAtomic(results, dumpJson(r, 2) + "\n");
}

double labMaxScore(const std::string& lab, const std::string& config, const std::vector<Row>& rows) {
  if (!lab.empty() || !config.empty()) {
    try {
      const std::string file = config.empty() ? defaultConfigPath(lab) : config;
      const json cfg = loadJsonFile(file);
      double total = 0;
      for (const auto& t : parseRubric(JsonView(cfg, file)).tests) total += t.points;
      return total;
    } catch (const std::exception&) {
      // A broken config: every submission says so in its own row; fall back to the graded ones.
    }
  }
  // Without --lab: the total every graded row agrees on (0 if they disagree or none was graded).
  double total = -1;
  for (const auto& r : rows)
    if (r.graded) total = total < 0 || total == r.max_score ? r.max_score : 0;
  return std::max(total, 0.0);
}

std::string gradebookCsv(std::vector<Row> rows, double lab_max) {
  std::sort(rows.begin(), rows.end(), [](const Row& a, const Row& b) { return a.name < b.name; });
  // One column per test, in the order the rubric lists them (as the first graded row has them).
  std::vector<std::string> tests;
  for (const auto& r : rows)
    for (const auto& t : r.tests)
      if (std::find(tests.begin(), tests.end(), t.first) == tests.end()) tests.push_back(t.first);
  const auto number = [](double x) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", x);
    return csvField(buf);
  };
  std::string csv = "submission,score,max_score,status,reason,folder";
  for (const auto& t : tests) csv += "," + csvField(t);
  csv += "\n";
  for (const auto& r : rows) {
    csv += csvField(r.name) + "," + number(r.score) + "," + number(r.graded ? r.max_score : lab_max) + "," +
           csvField(r.status) + "," + csvField(r.reason) + "," + csvField(r.folder);
    for (const auto& t : tests) {
      const auto it = std::find_if(r.tests.begin(), r.tests.end(), [&](const auto& p) { return p.first == t; });
      csv += ',';
      if (it != r.tests.end()) csv += number(it->second);
    }
    csv += "\n";
  }
  return csv;
}

}  // namespace dyn::app::batch
