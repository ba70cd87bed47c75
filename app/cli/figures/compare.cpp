// dynlab compare A B: two submissions (gain sets) of one lab graded by the same rubric, side by
// side. Each is graded exactly as `dynlab grade` grades it (grading/grade.h, keeping its runs); the
// terminal gets one line per test (score and metric with its unit, A → B), OUT/comparison.md the
// same as tables (every name from a file or a config escaped for Markdown), and OUT/plots/ one plot
// per simulated test with both responses on it (A solid, B dashed) over the reference and its band.
// Nothing is written unless both were graded; output is staged like every command's.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "app/cli/commands.h"
#include "app/cli/output.h"
#include "grading/escape.h"
#include "grading/grade.h"
#include "grading/lessons.h"
#include "grading/plot.h"

namespace fs = std::filesystem;

namespace dyn::app {
namespace {

// One graded submission: its name as given, and what the grader kept.
struct Side {
  std::string file;
  GradeOutcome g;
};

std::string pts(double x) { return fmtNumber(std::round(x * 100) / 100); }

// A metric with its unit ("0.01113 m"); no value: "—". escape is the unit's for where it lands.
std::string valueText(const GradedTest& t, std::string (*escape)(std::string_view)) {
  if (!std::isfinite(t.value)) return "—";
  return fmtNumber(t.value) + (t.unit.empty() || t.unit == "1" ? "" : " " + escape(t.unit));
}

// A file name for a plot legend: its last component, terminal-safe (control characters and bad
// bytes as visible escapes, PLplot's '#' is plot.h's business), at most 32 bytes.
std::string legendName(const std::string& file) {
  std::string s = termText(fs::path(file).filename().string());
  if (s.size() <= 32) return s;
  std::size_t cut = 31;
  while (cut > 0 && (static_cast<unsigned char>(s[cut]) & 0xC0) == 0x80) --cut;  // not inside a character
  return s.substr(0, cut) + "…";
}

// "Slider tracks x_d(t)" → "slider-tracks-x-d-t": a file name from a test name.
std::string slug(const std::string& name) {
  std::string out;
  for (unsigned char c : name) {
    if (std::isalnum(c) && c < 0x80) out += char(std::tolower(c));
    else if (!out.empty() && out.back() != '-') out += '-';
  }
  while (!out.empty() && out.back() == '-') out.pop_back();
  return out.substr(0, 40);
}

// What a test's plot draws: its own request, else the one the rubric draws for the same metric (a
// test without a plot of its own, e.g. tracking under another scenario). None: not plotted.
const PlotRequest* plotFor(const std::vector<GradedTest>& tests, std::size_t i) {
  if (tests[i].test.plot) return &*tests[i].test.plot;
  for (const auto& t : tests)
    if (t.test.metric == tests[i].test.metric && t.test.plot) return &*t.test.plot;
  return nullptr;
}

// A test is simulated when its metric comes from the scenario's run, not from screening the gains.
bool simulated(const GradeOutcome& g, const GradedTest& t) {
  const auto it = g.runs.find(t.test.scenario);
  return it != g.runs.end() && !it->second.screen.metrics.contains(t.test.metric);
}

// Both responses of test i on one plot: the band, each column of A (solid) and of B (dashed; plot.h
// draws dashed lines over solid ones), the reference on top. With a reference, only the first column
// (the response the metric compares with it) is drawn: a further one is a measurement (f_meas under
// sensor noise) whose two noisy copies would hide both responses.
PlotSpec comparisonPlot(const Side& a, const Side& b, std::size_t i, const PlotRequest& p) {
  const GradedTest& t = a.g.graded.tests[i];
  const ScenarioRun& ra = a.g.runs.at(t.test.scenario);
  const ScenarioRun& rb = b.g.runs.at(t.test.scenario);
  PlotSpec spec;
  spec.title = t.test.name + " (" + t.test.scenario + ")";
  spec.xlabel = "t (s)";
  spec.ylabel = p.ylabel;
  const Trace& ref_trace = ra.trace.rows() >= rb.trace.rows() ? ra.trace : rb.trace;  // the longer run's
  const std::vector<double> t_ref = ref_trace.series("t");
  if (!p.reference.empty() && ref_trace.column(p.reference) >= 0) {
    const std::vector<double> ref = ref_trace.series(p.reference);  // the same for A and B: the lab's
    if (p.band > 0) {
      PlotBand band{"tolerance ±" + fmtNumber(p.band), t_ref, ref, ref};
      for (std::size_t k = 0; k < ref.size(); ++k) band.lo[k] -= p.band, band.hi[k] += p.band;
      spec.bands.push_back(band);
    }
  } else if (p.band > 0) {
    spec.bands.push_back({"limit ±" + fmtNumber(p.band), t_ref, std::vector<double>(t_ref.size(), -p.band),
                          std::vector<double>(t_ref.size(), p.band)});
  }
  const std::string la = "A: " + legendName(a.file), lb = "B: " + legendName(b.file);
  const bool has_ref = !p.reference.empty() && ref_trace.column(p.reference) >= 0;
  const std::size_t shown = has_ref ? std::min<std::size_t>(1, p.columns.size()) : p.columns.size();
  for (std::size_t k = 0; k < shown; ++k) {
    const std::string& c = p.columns[k];
    // Each column a pair of colours: A blue and B orange for the first.
    const int ca = int(2 * k), cb = int(2 * k + 1);
    if (ra.trace.rows() >= 2 && ra.trace.column(c) >= 0)
      spec.series.push_back({c + " (" + la + ")", ra.trace.series("t"), ra.trace.series(c), PlotSeries::Style::Solid, ca});
    if (rb.trace.rows() >= 2 && rb.trace.column(c) >= 0)
      spec.series.push_back({c + " (" + lb + ")", rb.trace.series("t"), rb.trace.series(c), PlotSeries::Style::Dashed, cb});
  }
  if (has_ref)
    spec.series.push_back({p.reference + " (reference)", t_ref, ref_trace.series(p.reference), PlotSeries::Style::Dashed, 6});
  for (const ScenarioRun* r : {&ra, &rb})
    if (r->failure_time >= 0) spec.vlines.push_back(r->failure_time);
  if (!spec.vlines.empty()) spec.vline_label = ra.failure_time >= 0 && rb.failure_time >= 0 ? "both runs stopped"
                                               : ra.failure_time >= 0                     ? "A's run stopped"
                                                                                          : "B's run stopped";
  return spec;
}

// The comparison as Markdown: who is who, a table of the tests, why runs stopped, the plots.
std::string markdown(const Side& a, const Side& b, const std::vector<std::string>& plots) {
  const GradeReport& ra = a.g.graded;
  const GradeReport& rb = b.g.graded;
  std::string md = "# dynlab compare: " + mdText(ra.lab) + "\n\n";
  md += "Both graded by the same rubric, exactly as `dynlab grade` grades them.\n\n";
  md += "| | submission | score |\n|---|---|---|\n";
  md += "| A | " + mdText(a.file) + " | " + pts(ra.score()) + " / " + pts(ra.maxScore()) + " |\n";
  md += "| B | " + mdText(b.file) + " | " + pts(rb.score()) + " / " + pts(rb.maxScore()) + " |\n\n";
  md += "## Tests\n\n| # | test | scenario | metric | A | B | A points | B points | B − A |\n"
        "|---|---|---|---|---|---|---|---|---|\n";
  for (std::size_t i = 0; i < ra.tests.size(); ++i) {
    const GradedTest& ta = ra.tests[i];
    const GradedTest& tb = rb.tests[i];
    const double d = tb.score - ta.score;
    md += "| " + std::to_string(i + 1) + " | " + mdText(ta.test.name) + " | " + mdText(ta.test.scenario) + " | " +
          mdText(ta.test.metric) + " | " + valueText(ta, mdText) + " | " + valueText(tb, mdText) + " | " + pts(ta.score) +
          " / " + pts(ta.test.points) + " | " + pts(tb.score) + " / " + pts(tb.test.points) + " | " +
          (d > 0.005 ? "+" : "") + pts(d) + " |\n";
  }
  md += "| | **total** | | | | | **" + pts(ra.score()) + "** | **" + pts(rb.score()) + "** | " +
        (rb.score() - ra.score() > 0.005 ? "+" : "") + pts(rb.score() - ra.score()) + " |\n";
  // A run the watchdog stopped scores nothing in its scenario: say which and why.
  std::string stopped;
  for (const auto* side : {&a, &b})
    for (const auto& s : side->g.graded.scenarios)
      if (!s.failure.empty())
        stopped += "- " + std::string(side == &a ? "A" : "B") + ", scenario " + mdText(s.scenario.name) + ": " + mdText(s.failure) + "\n";
  if (!stopped.empty()) md += "\n## Runs that were stopped\n\n" + stopped;
  if (!plots.empty()) md += "\n## Responses\n\nA solid, B dashed, over the reference and its tolerance band.\n";
  for (std::size_t i = 0; i < ra.tests.size(); ++i) {
    if (plots[i].empty()) continue;
    md += "\n### " + std::to_string(i + 1) + ". " + mdText(ra.tests[i].test.name) + "\n\n![test " + std::to_string(i + 1) +
          ", A and B](" + plots[i] + ")\n";
  }
  return md;
}

// The terminal: one line per test, A → B.
void printTable(const Side& a, const Side& b) {
  const GradeReport& ra = a.g.graded;
  const GradeReport& rb = b.g.graded;
  std::printf("dynlab compare %s (%s points)\n", termText(ra.lab).c_str(), pts(ra.maxScore()).c_str());
  std::printf("  A  %-8s %s\n  B  %-8s %s\n", (pts(ra.score()) + "/" + pts(ra.maxScore())).c_str(), termText(a.file).c_str(),
              (pts(rb.score()) + "/" + pts(rb.maxScore())).c_str(), termText(b.file).c_str());
  for (std::size_t i = 0; i < ra.tests.size(); ++i) {
    const GradedTest& ta = ra.tests[i];
    const GradedTest& tb = rb.tests[i];
    std::printf("  %5s → %-5s / %-3s  %s [%s]: %s = %s → %s\n", pts(ta.score).c_str(), pts(tb.score).c_str(),
                pts(ta.test.points).c_str(), termText(ta.test.name).c_str(), termText(ta.test.scenario).c_str(),
                termText(ta.test.metric).c_str(), valueText(ta, termText).c_str(), valueText(tb, termText).c_str());
  }
  std::printf("  Total: %s → %s / %s\n", pts(ra.score()).c_str(), pts(rb.score()).c_str(), pts(ra.maxScore()).c_str());
}

}  // namespace

int compare(const CompareArgs& args) {
  GradeOptions o;
  o.expected_lab = args.lab;
  o.config_file = args.config;
  o.time_budget = args.time_budget;
  o.keep_runs = true;
  // Grade A, then B against A's lab: both by the same rubric. A submission that cannot be graded
  // stops the comparison before anything is written.
  Side a{args.a, gradeSubmission(args.a, o)};
  const auto failed = [](const Side& s) {
    if (!s.g.input_error && !s.g.internal_error) return 0;
    std::fprintf(stderr, "error: %s\n", s.g.error.c_str());
    return s.g.input_error ? 2 : 3;
  };
  if (const int code = failed(a)) return code;
  o.expected_lab = a.g.graded.lab;
  Side b{args.b, gradeSubmission(args.b, o)};
  if (const int code = failed(b)) return code;
  if (a.g.graded.tests.size() != b.g.graded.tests.size()) {
    std::fprintf(stderr, "error: internal: the two grades have different tests\n");
    return 3;
  }
  printTable(a, b);

  const fs::path out = args.out;
  try {
    Staging staging(out);
    staging.owns({"comparison.md", "plots"});
    std::vector<std::string> plots(a.g.graded.tests.size());
    for (std::size_t i = 0; args.plots && i < plots.size(); ++i) {
      const PlotRequest* p = plotFor(a.g.graded.tests, i);
      if (!p || !simulated(a.g, a.g.graded.tests[i])) continue;
      char name[80];
      std::snprintf(name, sizeof name, "plots/%02zu-%s.png", i + 1, slug(a.g.graded.tests[i].test.name).c_str());
      fs::create_directories(staging.path("plots"));
      writePlot(staging.path(name).string(), comparisonPlot(a, b, i, *p));
      plots[i] = name;
    }
    staging.write("comparison.md", markdown(a, b, plots));
    staging.commit();
  } catch (const std::exception& e) {
    return notWritten("comparison", e, 1);
  }
  std::printf("comparison: %s\n", termText((out / "comparison.md").string()).c_str());
  // A grade the time budget cut short is shown, but it is not a whole grade.
  if (a.g.out_of_time || b.g.out_of_time) {
    const char* who = a.g.out_of_time && b.g.out_of_time ? "A and B" : a.g.out_of_time ? "A" : "B";
    std::fprintf(stderr, "error: the grading time budget of %g s ran out for %s; the grade is incomplete\n",
                 args.time_budget, who);
    return 4;
  }
  return 0;
}

int lessons(const LessonsArgs& args) {
  try {
    // The lab's config and rubric; the pairs live beside the config (labs/LAB/examples/...).
    const LoadedLab loaded = loadLab(args.lab, args.config);
    const Rubric rubric = parseRubric(JsonView(loaded.config, loaded.config_file));
    GradeOptions o;
    o.expected_lab = args.lab;
    o.config_file = loaded.config_file;
    o.time_budget = args.time_budget;
    const std::string dir = fs::path(loaded.config_file).parent_path().string();
    std::printf("dynlab lessons %s: %zu lesson(s), each graded by the rubric\n", termText(args.lab).c_str(), rubric.lessons.size());
    int failed = 0;
    for (const LessonCheck& c : checkLessons(rubric, dir, o)) {
      const std::string names = termText(fs::path(c.lesson.better).stem().string()) + " ahead of " +
                                termText(fs::path(c.lesson.worse).stem().string());
      if (!c.error.empty()) {
        std::printf("  ERROR  %s: %s\n", names.c_str(), termText(c.error).c_str());
      } else {
        std::printf("  %-6s %s: %s vs %s of %s, lead %s (at least %s)\n", c.holds() ? "holds" : "FAILS", names.c_str(),
                    pts(c.better).c_str(), pts(c.worse).c_str(), pts(c.max).c_str(), pts(c.better - c.worse).c_str(),
                    pts(c.lesson.margin * c.max).c_str());
      }
      std::printf("         %s\n", termText(c.lesson.about).c_str());
      failed += !c.holds();
    }
    if (failed) std::fprintf(stderr, "error: %d lesson(s) of %s do not hold: the rubric ranks them against the lecture\n", failed,
                             termText(args.lab).c_str());
    return failed ? 1 : 0;
  } catch (const InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
}

}  // namespace dyn::app
