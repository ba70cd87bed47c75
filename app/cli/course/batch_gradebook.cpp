// From each grader's results.json to a gradebook row, and the gradebook itself; see batch.h.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>

#include "app/cli/course/batch.h"
#include "app/cli/output.h"
#include "grading/escape.h"
#include "grading/rubric.h"
#include "labs/config.h"
#include "labs/lab.h"

namespace fs = std::filesystem;

namespace dyn::app::batch {

Row failedRow(const Submission& s, const std::string& status, const std::string& reason) {
  return {s.name, s.folder, status, jsonText(clipText(reason, 600)), 0, 0, false, {}, {}};
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
  // Exit 3 with the grader's own account (a staff file's error, a failed plot): that is the reason.
  if (exit_code == 3 && extra.is_object() && extra.value("internal_error", json()).is_string())
    return failedRow(s, "internal error", "internal error: " + extra["internal_error"].get<std::string>());
  // Exit 4: the grader's time budget ran out; what it scored before is in its results.json.
  const bool budget = exit_code == 4;
  if ((exit_code != 0 && !budget) || !error.is_null() || !r.value("score", json()).is_number())
    return failedRow(s, "internal error", "internal error: the grader exited with status " + std::to_string(exit_code) +
                                              (exit_code == 0 ? " but its results.json holds no grade" : "") + said);
  Row row{s.name, s.folder, "graded", "", r.value("score", 0.0), 0, true, {}, {}};
  try {
    for (const auto& t : r.value("tests", json::array())) {
      row.tests.push_back({t.value("name", "?"), t.value("score", 0.0), t.value("max_score", 0.0)});
      row.max_score += row.tests.back().max_score;
    }
    // The written answers, for the TA reading the gradebook.
    if (const json a = extra.value("answers", json::object()); a.is_object())
      for (const auto& [name, text] : a.items())
        if (text.is_string()) row.answers += (row.answers.empty() ? "" : "\n\n") + name + ": " + text.get<std::string>();
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
  row.reason = jsonText(clipText(row.reason, 600));
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
      if (std::find(tests.begin(), tests.end(), t.name) == tests.end()) tests.push_back(t.name);
  const auto number = [](double x) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.4g", x);
    return csvField(buf);
  };
  // The written answers, last, when any submission has some.
  const bool answers = std::any_of(rows.begin(), rows.end(), [](const Row& r) { return !r.answers.empty(); });
  std::string csv = "submission,score,max_score,status,reason,folder";
  for (const auto& t : tests) csv += "," + csvField(t);
  csv += answers ? ",answers\n" : "\n";
  for (const auto& r : rows) {
    csv += csvField(r.name) + "," + number(r.score) + "," + number(r.graded ? r.max_score : lab_max) + "," +
           csvField(r.status) + "," + csvField(r.reason) + "," + csvField(r.folder);
    for (const auto& t : tests) {
      const auto it = std::find_if(r.tests.begin(), r.tests.end(), [&](const TestScore& p) { return p.name == t; });
      csv += ',';
      if (it != r.tests.end()) csv += number(it->score);
    }
    if (answers) csv += "," + csvField(r.answers);
    csv += "\n";
  }
  return csv;
}

namespace {

std::string fmt(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.4g", x);
  return buf;
}

// A reason with every number as # ("t = 0.15 s" → "t = # s"; "f_Ty", "q1" and "UTF-8" stay): the
// same kind of failure, whatever the numbers, is one line of the summary.
std::string reasonKind(const std::string& reason) {
  std::string out;
  const auto wordChar = [](char ch) { return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_'; };
  for (std::size_t i = 0; i < reason.size();) {
    const unsigned char c = static_cast<unsigned char>(reason[i]);
    // Inside a word, or a word's hyphenated part ("UTF-8", "ISO-8859-1"): a name, not a number.
    const bool hyphenated = out.size() >= 2 && out.back() == '-' && wordChar(out[out.size() - 2]);
    const bool word = (!out.empty() && wordChar(out.back())) || hyphenated;
    const bool sign = (c == '-' || c == '+') && i + 1 < reason.size() && std::isdigit(static_cast<unsigned char>(reason[i + 1]));
    if (word || !(std::isdigit(c) || sign)) {
      out += reason[i++];
      continue;
    }
    // A number: sign, digits, a fraction, an exponent.
    std::size_t j = i + (sign ? 1 : 0);
    const auto digits = [&] { while (j < reason.size() && std::isdigit(static_cast<unsigned char>(reason[j]))) ++j; };
    digits();
    if (j + 1 < reason.size() && reason[j] == '.' && std::isdigit(static_cast<unsigned char>(reason[j + 1]))) ++j, digits();
    if (j + 1 < reason.size() && (reason[j] == 'e' || reason[j] == 'E')) {
      std::size_t k = j + 1 + ((reason[j + 1] == '-' || reason[j + 1] == '+') ? 1 : 0);
      if (k < reason.size() && std::isdigit(static_cast<unsigned char>(reason[k]))) j = k, digits();
    }
    out += '#';
    i = j;
  }
  return out;
}

// The reasons of one row as (scenario, reason): a graded row lists one per scenario that did not
// complete ("a: ...; b: ..."), any other row has one reason of no scenario.
std::vector<std::pair<std::string, std::string>> reasonsOf(const Row& r) {
  std::vector<std::pair<std::string, std::string>> out;
  if (r.reason.empty()) return out;
  if (r.status.rfind("graded", 0) != 0 && r.status != "timed out") return {{"", r.reason}};
  for (std::size_t at = 0; at <= r.reason.size();) {
    std::size_t end = r.reason.find("; ", at);
    if (end == std::string::npos) end = r.reason.size();
    const std::string item = r.reason.substr(at, end - at);
    const std::size_t colon = item.find(": ");
    if (colon != std::string::npos) out.emplace_back(item.substr(0, colon), item.substr(colon + 2));
    else if (!item.empty()) out.emplace_back("", item);
    at = end + 2;
  }
  return out;
}

// Sorted by count, most first, then by text: the same rows give the same summary.
template <class Map>
std::vector<std::pair<typename Map::key_type, int>> byCount(const Map& counts) {
  std::vector<std::pair<typename Map::key_type, int>> v(counts.begin(), counts.end());
  std::stable_sort(v.begin(), v.end(), [](const auto& a, const auto& b) { return a.second > b.second; });
  return v;
}

}  // namespace

std::string gradebookMarkdown(std::vector<Row> rows, double lab_max) {
  std::sort(rows.begin(), rows.end(), [](const Row& a, const Row& b) { return a.name < b.name; });
  const std::size_t n = rows.size();
  std::vector<double> scores;
  for (const auto& r : rows) scores.push_back(r.score);
  std::sort(scores.begin(), scores.end());
  double total = lab_max > 0 ? lab_max : (scores.empty() ? 0.0 : scores.back());
  std::string md = "# Gradebook summary\n\n" + std::to_string(n) + " submission" + (n == 1 ? "" : "s") +
                   "; one row each in `gradebook.csv`, with its feedback in its folder.\n\n";

  // How many of each status, and the score statistics over every submission.
  std::map<std::string, int> status;
  for (const auto& r : rows) ++status[r.status];
  md += "| status | submissions |\n|---|---|\n";
  for (const auto& [s, count] : byCount(status)) md += "| " + mdText(s) + " | " + std::to_string(count) + " |\n";
  if (!scores.empty()) {
    double sum = 0;
    for (double x : scores) sum += x;
    const double median = n % 2 ? scores[n / 2] : (scores[n / 2 - 1] + scores[n / 2]) / 2;
    const auto of = [&](double x) { return fmt(x) + (total > 0 ? " (" + fmt(100 * x / total) + " %)" : ""); };
    md += "\n| score (of " + fmt(total) + ") | |\n|---|---|\n| mean | " + of(sum / double(n)) + " |\n| median | " +
          of(median) + " |\n| min | " + of(scores.front()) + " |\n| max | " + of(scores.back()) + " |\n\n" +
          "Over every submission: one that was not graded counts as 0.\n";
  }

  // The histogram: ten bins of a tenth of the total each, the last one holding full marks.
  if (!scores.empty()) {
    constexpr int kBins = 10, kBarMax = 40;
    std::vector<int> bins(kBins, 0);
    for (double x : scores) {
      const int b = total > 0 ? int(std::floor(x / total * kBins)) : 0;
      ++bins[std::size_t(std::clamp(b, 0, kBins - 1))];
    }
    const int most = *std::max_element(bins.begin(), bins.end());
    md += "\n## Scores\n\n| score | submissions | |\n|---|---|---|\n";
    for (int b = 0; b < kBins; ++b) {
      const double lo = total * b / kBins, hi = total * (b + 1) / kBins;
      const int bar = most > kBarMax ? (bins[b] * kBarMax + most - 1) / most : bins[b];
      std::string bars;
      for (int k = 0; k < bar; ++k) bars += "█";
      md += "| " + fmt(lo) + (b + 1 == kBins ? " – " : " – <") + fmt(hi) + " | " + std::to_string(bins[b]) + " | " + bars + " |\n";
    }
  }

  // The most common failure reasons, numbers as #, with the scenarios they happened in.
  struct Kind {
    int submissions = 0;
    std::set<std::string> scenarios;
  };
  std::map<std::pair<std::string, std::string>, Kind> reasons;  // (status, reason kind)
  for (const auto& r : rows) {
    std::set<std::string> seen;  // a row counts once per kind
    for (const auto& [scenario, reason] : reasonsOf(r)) {
      Kind& k = reasons[{r.status, reasonKind(reason)}];
      if (!scenario.empty()) k.scenarios.insert(scenario);
      if (seen.insert(reasonKind(reason)).second) ++k.submissions;
    }
  }
  if (!reasons.empty()) {
    std::map<std::pair<std::string, std::string>, int> counts;
    for (const auto& [key, k] : reasons) counts[key] = k.submissions;
    md += "\n## Most common failure reasons\n\nNumbers are shown as #, so one kind of failure is one line.\n\n"
          "| reason | status | scenarios | submissions |\n|---|---|---|---|\n";
    int shown = 0;
    for (const auto& [key, count] : byCount(counts)) {
      if (++shown > 10) break;
      std::string scenarios;
      for (const auto& s : reasons[key].scenarios) scenarios += (scenarios.empty() ? "" : ", ") + s;
      md += "| " + mdText(key.second) + " | " + mdText(key.first) + " | " + (scenarios.empty() ? "—" : mdText(scenarios)) +
            " | " + std::to_string(count) + " |\n";
    }
    if (reasons.size() > 10) md += "\nand " + std::to_string(reasons.size() - 10) + " more kinds (see the reason column).\n";
  }

  // Each test's mean score over the graded submissions, and how many got full marks or none.
  std::vector<std::string> tests;
  std::map<std::string, std::vector<TestScore>> by_test;
  for (const auto& r : rows)
    for (const auto& t : r.tests) {
      if (!by_test.count(t.name)) tests.push_back(t.name);
      by_test[t.name].push_back(t);
    }
  if (!tests.empty()) {
    md += "\n## Tests\n\nOver the graded submissions.\n\n| test | mean | points | full marks | zero |\n|---|---|---|---|---|\n";
    for (const auto& name : tests) {
      const auto& ts = by_test[name];
      double sum = 0, points = 0;
      int full = 0, zero = 0;
      for (const auto& t : ts) {
        sum += t.score;
        points = std::max(points, t.max_score);
        full += t.score >= t.max_score - 1e-9;
        zero += t.score <= 1e-9;
      }
      md += "| " + mdText(name) + " | " + fmt(sum / double(ts.size())) + " | " + fmt(points) + " | " + std::to_string(full) +
            " | " + std::to_string(zero) + " |\n";
    }
  }

  // Who needs a look: every submission that has no grade of the grader's.
  std::string look;
  for (const auto& r : rows)
    if (!r.graded) look += "| " + mdText(r.name) + " | " + mdText(r.status) + " | " + mdText(r.folder) + " |\n";
  if (!look.empty()) md += "\n## Not graded\n\n| submission | status | folder |\n|---|---|---|\n" + look;
  return md;
}

}  // namespace dyn::app::batch
