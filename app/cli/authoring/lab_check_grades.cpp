// The lab contract's grading checks (app/cli/authoring/lab_check.h): advice and metrics, the grades of the
// examples and the defaults, the lessons on every plant, and the instructor's and the untuned answers.
#include <algorithm>
#include <filesystem>
#include <set>

#include "app/cli/authoring/lab_check_steps.h"
#include "grading/advice.h"
#include "grading/lessons.h"
#include "grading/metric_doc.h"
#include "grading/rubric.h"
#include "grading/scenario.h"
#include "grading/student.h"
#include "labs/config.h"
#include "labs/controllers/controller.h"
#include "labs/run.h"
#include "labs/settings.h"
#include "labs/submission.h"
#include "labs/variants.h"

namespace dyn::lab_check {

// Every advice entry fits its law; every metric the rubric reads exists, finite, for every option choice.
void checkAdviceAndMetrics(const Checked& chk, LabCheckReport& report) {
  // Every advice chk.entry names options, choices, scenarios and gains that exist; none tells a law to use
  // itself or names a gain it does not read (grading/advice.h).
  run(report, "advice", [&](Step& s) {
    const std::vector<std::string> problems = adviceProblems(chk.config, chk.shown);
    for (const auto& p : problems) s.fail(p);
    // A data lab's kinds read what the controller library says they read: "reads" must agree.
    const json options = chk.config.value("submission_options", json::object());
    if (options.contains("kind") && options["kind"].value("target", "") == "/controller/kind")
      for (const auto& c : options["kind"].at("choices")) {
        const std::string kind = c.get<std::string>();
        const auto& names = controllers::kindNames();
        if (std::find(names.begin(), names.end(), kind) == names.end()) continue;
        json law = chk.config;
        law["controller"]["kind"] = kind;
        const std::set<std::string> read = gainsRead(law);
        std::set<std::string> library;
        for (const auto& g : controllers::gainsOf(controllers::kindFromName(kind)))
          if (chk.config["gains"].contains(g)) library.insert(g);
        for (const auto& [g, _] : chk.config["gains"].items())
          if (read.count(g) != library.count(g))
            s.fail("/submission_options/kind/reads: kind " + kind + (library.count(g) ? " reads " : " does not read ") + g +
                   " (the controller library's), the lab says otherwise");
      }
    std::size_t entries = 0;
    for (const auto& [_, d] : parseMetricDocs(JsonView(chk.config, chk.shown))) entries += d.advice.size();
    s.detail = std::to_string(entries) + " advice entries: each names a law that exists and gains that law reads";
  });

  // Every metric the rubric's tests and leaderboard read exists for every option choice: the lab's
  // metrics of a short run and the screening of its loops.
  run(report, "metrics", [&](Step& s) {
    const Rubric rubric = parseRubric(JsonView(chk.config, chk.shown));
    const std::vector<json> subs = optionSubmissions(chk.entry.name, chk.config);
    for (const json& sub : subs) {
      const std::string which = "submission " + sub.dump() + ": ";
      const json applied = applySubmission(chk.config, JsonView(sub, "submission.json"), chk.entry.name, true);
      const auto lab = buildLab(chk.entry, applied, chk.shown);
      try {
        checkColumns(rubric, lab->columns(), chk.shown);
      } catch (const std::exception& e) {
        s.fail(which + e.what());
      }
      const RunResult r = runEngine(*lab, Engine::Hand, 200);
      json metrics = lab->metrics(r.trace);  // Trace::at throws on a column it lacks
      // NaN: a window that starts past these 200 steps has no sample yet (metric_spec.h); never ±inf.
      for (const auto& [key, value] : metrics.items())
        s.expect(value.is_number() && !std::isinf(value.get<double>()), which + "metric " + key + " = " + value.dump());
      const ScreenResult screen = screenLoops(*lab);
      for (const auto& [key, value] : screen.metrics.items()) metrics[key] = value;
      for (const auto& t : rubric.tests) s.expect(metrics.contains(t.metric), which + "no metric \"" + t.metric + "\" (a rubric test's)");
      for (const auto& l : rubric.leaderboard) s.expect(metrics.contains(l.metric), which + "no metric \"" + l.metric + "\" (the leaderboard's)");
    }
    s.detail = "every rubric and leaderboard metric, finite, for " + std::to_string(subs.size()) + " option choice(s)";
  });
}

// Every example and option choice grades validly; the defaults score within the band, with their plots.
void checkGrading(const Checked& chk, LabCheckReport& report) {
  run(report, "grading", [&](Step& s) {
    for (std::size_t i = 0; i < chk.examples.size(); ++i) {
      const GradeOutcome g = graded(s, chk.examples[i], chk.o);
      if (i < chk.shipped && resultsProblem(g).empty()) report.example_shares.push_back({fileName(chk.examples[i]), scoreShare(g)});
    }
    int k = 0;
    for (const json& sub : optionSubmissions(chk.entry.name, chk.config)) {
      const std::string file = (chk.dir / ("option_" + std::to_string(k++) + ".json")).string();
      writeFile(file, sub.dump());
      graded(s, file, chk.o);
    }
    s.detail = std::to_string(chk.examples.size()) + " chk.examples and " + std::to_string(k) + " option choice(s) grade to a valid results.json";
  });

  // The chk.shipped defaults are a weak, stable start: the exercise is left to the student.
  GradeOutcome defaults;
  const std::string defaults_file = (chk.dir / "defaults.json").string();
  GradeOptions with_plots = chk.o;
  with_plots.out_dir = (chk.dir / "defaults_out").string();
  run(report, "defaults", [&](Step& s) {
    writeFile(defaults_file, defaultSubmission(chk.entry.name, chk.config).dump());
    defaults = graded(s, defaults_file, with_plots);
    if (!s.problem.empty()) return;
    const double share = scoreShare(defaults);
    report.defaults_share = share;
    const std::string measured = "the default gains score " + percent(share) + " (" + fmt(defaults.results.at("score").get<double>()) +
                                 " points), band " + percent(chk.options.defaults_band.first) + " to " + percent(chk.options.defaults_band.second);
    s.expect(share >= chk.options.defaults_band.first && share <= chk.options.defaults_band.second, measured + ": outside");
    s.detail = measured;
  });

  run(report, "plots", [&](Step& s) {
    if (!s.expect(resultsProblem(defaults).empty(), "the defaults were not graded")) return;
    // Every test of a simulated metric (not the screening's) has its plot on disk.
    const auto loops = buildLab(chk.entry, chk.config, chk.config_file)->linearise();
    int plots = 0;
    for (const auto& t : defaults.results.at("tests")) {
      const std::string metric = t.at("extra_data").at("metric");
      if (screeningMetricDoc(metric, loops)) continue;
      const std::string test = "test \"" + t.at("name").get<std::string>() + "\": ";
      if (!s.expect(t.at("extra_data").contains("plot"), test + "no plot")) continue;
      s.expect(fs::is_regular_file(fs::path(with_plots.out_dir) / t["extra_data"]["plot"].get<std::string>()),
               test + "its plot is not on disk");
      ++plots;
    }
    s.detail = "every simulated test of the defaults' grade has its plot (" + std::to_string(plots) + ")";
  });
}

// The grade teaches the lecture: each lesson pair ranks as stated, on every plant; doing nothing scores less.
void checkLessonPairs(const Checked& chk, LabCheckReport& report) {
  // The grade teaches the lecture: every lesson pair ranks as stated.
  std::vector<LessonCheck> lessons;
  run(report, "lessons", [&](Step& s) {
    const Rubric rubric = parseRubric(JsonView(chk.config, chk.config_file));
    s.expect(!rubric.lessons.empty(), "the rubric states no lesson (rubric/lessons)");
    lessons = checkLessons(rubric, chk.lab_dir, chk.o);
    s.detail = std::to_string(rubric.lessons.size()) + " lesson(s) stated";
  });
  for (const LessonCheck& c : lessons) {
    const std::string pair = fs::path(c.lesson.better).stem().string() + " ahead of " + fs::path(c.lesson.worse).stem().string();
    run(report, "lesson " + pair, [&](Step& l) {
      l.expect(c.error.empty(), c.error);
      const std::string measured = fmt(c.better) + " vs " + fmt(c.worse) + " of " + fmt(c.max) + ", lead needed " +
                                   fmt(c.lesson.margin * c.max);
      l.expect(c.holds(), measured + ": " + c.lesson.about);
      l.detail = measured;
    });
  }

  // A plant per student (labs/variants.h): every lesson holds on each corner of the ranges and on a
  // few drawn plants, not only on the nominal one.
  run(report, "plants per student", [&](Step& s) {
    const Rubric rubric = parseRubric(JsonView(chk.config, chk.config_file));
    const std::size_t n = parseVariants(JsonView(chk.config, chk.config_file)).size();
    if (n == 0) {
      s.detail = "no variants: one plant for every student";
      return;
    }
    std::vector<PlantChoice> plants = {{"", "", PlantChoice::Corner::Min}, {"", "", PlantChoice::Corner::Max}};
    for (int i = 1; i <= 3; ++i) plants.push_back({"sample-" + std::to_string(i), hashHex("check-lab/" + std::to_string(i))});
    int held = 0;
    for (const PlantChoice& plant : plants) {
      GradeOptions on = chk.o;
      on.plant = plant;
      for (const LessonCheck& c : checkLessons(rubric, chk.lab_dir, on)) {
        const std::string pair = fs::path(c.lesson.better).stem().string() + " ahead of " + fs::path(c.lesson.worse).stem().string();
        if (!s.expect(c.error.empty(), plant.label() + ": " + pair + ": " + c.error)) return;
        s.expect(c.holds(), plant.label() + ": lesson " + pair + " fails, " + fmt(c.better) + " vs " + fmt(c.worse) + ": " +
                                c.lesson.about);
        held += c.holds();
      }
    }
    s.detail = std::to_string(held) + " lesson checks hold on " + std::to_string(plants.size()) + " plants (" +
               std::to_string(n) + " varied parameters: both corners of the ranges and 3 drawn)";
  });

  // Doing nothing: every gain at its declared minimum, the options as the chk.config sets them.
  run(report, "doing nothing", [&](Step& s) {
    json nothing = defaultSubmission(chk.entry.name, chk.config);
    for (const auto& [gain, d] : chk.config.at("gains").items()) nothing["gains"][gain] = d.at("min");
    writeFile(chk.dir / "nothing.json", nothing.dump());
    writeFile(chk.dir / "defaults_again.json", defaultSubmission(chk.entry.name, chk.config).dump());
    const GradeOutcome none = graded(s, (chk.dir / "nothing.json").string(), chk.o);
    const GradeOutcome again = graded(s, (chk.dir / "defaults_again.json").string(), chk.o);
    if (!s.problem.empty()) return;
    const double n = none.results.at("score").get<double>(), d = again.results.at("score").get<double>();
    const std::string measured = "every gain at its minimum scores " + fmt(n) + ", the defaults " + fmt(d);
    s.expect(n < d, measured + ": not below");
    s.detail = measured;
  });
}

// Each JSON file of a folder graded as one step, "WHAT FILE": at least 90 % of the points (full) or below
// 90 % (!full); an empty folder is one failed step. shares: each file's share of the points, when given.
void gradeFolder(LabCheckReport& report, const std::string& what, const std::string& folder, bool full,
                 const GradeOptions& o, std::vector<std::pair<std::string, double>>* shares) {
  const std::vector<std::string> files = jsonFiles(folder);
  if (files.empty())
    run(report, what, [&](Step& s) { s.fail(std::string(full ? "no instructor answer in " : "no untuned design in ") + folder); });
  for (const std::string& file : files)
    run(report, what + " " + fileName(file), [&](Step& s) {
      const GradeOutcome g = graded(s, file, o);
      if (!s.problem.empty()) return;
      const double share = scoreShare(g);
      if (shares) shares->push_back({fileName(file), share});
      if (full) s.expect(share >= 0.9, "scores " + percent(share) + ", below 90 %");
      else s.expect(share < 0.9, "scores " + percent(share) + " untuned: full marks without tuning");
      s.detail = "scores " + percent(share);
    });
}

// The instructor's answers score ≥ 90 %; the designs a student writes from the handout alone, textbook
// gains not yet tuned, stay below 90 %: full marks are earned by tuning, not by reading (issue 41).
void checkAnswers(const Checked& chk, LabCheckReport& report) {
  if (chk.options.instructor_dir == "-") return;
  const std::string instructor_dir = chk.options.instructor_dir.empty() ? chk.lab_dir + "/instructor" : chk.options.instructor_dir;
  gradeFolder(report, "instructor", instructor_dir, true, chk.o, &report.instructor_shares);
  gradeFolder(report, "untuned", instructor_dir + "/untuned", false, chk.o, nullptr);
}

}  // namespace dyn::lab_check
