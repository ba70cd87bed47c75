// The lab contract (labs/lab.h), checked on one lab: every_lab_test runs it on each registered lab,
// and a test may register a scratch lab (registerLab / unregisterLab) and run it on that too.
//   config     the default config builds; every lab has the shared simulation block
//   examples   the submission schema covers labs/<name>/examples/*.json (and instructor/*.json),
//              each applies strictly
//   engines    hand and Bullet run 200 steps with finite values
//   passive    with passivePatch() (τ = 0) the energy stays within the lab's stated tolerance
//   columns    the rubric's plot and watchdog columns exist; metrics read only columns that exist
//   options    every rubric metric exists for every submission option choice (metrics + screening)
//   grading    every example and every option choice grades to a valid results.json; the default
//              gains score 20–50 % of the points (a weak, stable start); every simulated test has a plot
//   lessons    the rubric states at least one lesson, and each holds (grading/lessons.h: the design the
//              lecture prefers leads its foil by the stated share); doing nothing (every gain at its
//              minimum) scores below the defaults; the instructor's answers score ≥ 90 %
//   render     a frame of the scene renders non-blank (OSMesa)
//   cli        `dynlab run` (the demo: both engines, whole run), `dynlab figure`, `dynlab grade` (and
//              `dynlab ui` under xvfb-run): exit 0
#pragma once
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "grading/grade.h"
#include "grading/lessons.h"
#include "grading/metric_doc.h"
#include "grading/rubric.h"
#include "grading/scenario.h"
#include "labs/run.h"
#include "labs/submission.h"
#include "render/renderer.h"
#include "tests/app/cli_run.h"

namespace dyn::test {

struct LabCheckOptions {
  std::string examples_dir;  // default: <source>/labs/<name>/examples
  bool cli = true;           // the dynlab binary knows the lab (false for a test's scratch lab)
  std::pair<double, double> defaults_band{0.2, 0.5};  // the share of points the default gains score
  std::string lab_dir;       // where the lessons' paths start (default: <source>/labs/<name>)
  std::string instructor_dir;  // the full-credit answers (default: <source>/labs/<name>/instructor; "-": none)
};

// The lab's example submissions (sorted paths).
inline std::vector<std::string> exampleFiles(const std::string& dir) {
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec))
    if (e.path().extension() == ".json") files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

// A submission with the config's default gains, and these options.
inline json defaultSubmission(const std::string& lab, const json& config, const json& options = json::object()) {
  json sub = {{"lab", lab}, {"gains", json::object()}};
  for (const auto& [name, d] : config.at("gains").items()) sub["gains"][name] = d.at("value");
  for (const auto& [key, value] : options.items()) sub[key] = value;
  return sub;
}

// One submission per choice of each declared option (the others left at the config's), and the
// defaults alone.
inline std::vector<json> optionSubmissions(const std::string& lab, const json& config) {
  std::vector<json> subs = {defaultSubmission(lab, config)};
  const json options = config.value("submission_options", json::object());
  for (const auto& [key, decl] : options.items())
    for (const auto& choice : decl.at("choices")) subs.push_back(defaultSubmission(lab, config, {{key, choice}}));
  return subs;
}

inline bool finiteRows(const Trace& trace) {
  return std::all_of(trace.data.begin(), trace.data.end(), [](double x) { return std::isfinite(x); });
}

// Gradescope's results.json: a finite score that is the sum of its tests', each test named and
// scored within its points.
inline void checkResults(const GradeOutcome& g) {
  CHECK_FALSE(g.input_error);
  const json& r = g.results;
  const std::string output = r.value("output", "");
  INFO("output: ", output);
  CHECK(output.find("expected a metric this lab reports") == std::string::npos);
  REQUIRE(r.contains("score"));
  REQUIRE(r.at("tests").is_array());
  CHECK_FALSE(r.at("tests").empty());
  double sum = 0;
  for (const auto& t : r.at("tests")) {
    CHECK(t.at("name").is_string());
    CHECK(t.at("output").is_string());
    const double score = t.at("score").get<double>(), max = t.at("max_score").get<double>();
    CHECK(score >= 0);
    CHECK(score <= max + 1e-9);
    sum += score;
  }
  CHECK(r.at("score").get<double>() == doctest::Approx(sum));
  CHECK(r.at("execution_time").is_number());
}

inline void checkConfigAndExamples(const LabEntry& entry, const json& config, const std::vector<std::string>& examples) {
  INFO("lab ", entry.name, ": config and examples");
  CHECK_NOTHROW(buildLab(entry, config, "config.json"));
  CHECK_NOTHROW(parseSimulation(JsonView(config, "config.json")["simulation"]));
  CHECK_FALSE(examples.empty());
  const json schema = submissionSchema(config, entry.name);
  const json& props = schema.at("properties");
  for (const std::string& file : examples) {
    INFO("example ", file);
    const json sub = loadJsonFile(file);
    CHECK_NOTHROW(applySubmission(config, JsonView(sub, file), entry.name, true));
    for (const auto& [key, value] : sub.items()) {
      INFO("key ", key);
      REQUIRE(props.contains(key));
      if (props[key].contains("enum")) CHECK(std::count(props[key]["enum"].begin(), props[key]["enum"].end(), value) == 1);
    }
    const json gains = sub.value("gains", json::object());
    for (const auto& [gain, _] : gains.items()) CHECK(props["gains"]["properties"].contains(gain));
    for (const auto& required : schema.at("required")) CHECK(sub.contains(required.get<std::string>()));
  }
}

inline void checkEngines(const LabEntry& entry, const json& config) {
  INFO("lab ", entry.name, ": both engines, 200 steps");
  const auto lab = buildLab(entry, config, "config.json");
  const long expected = std::min(200L, std::lround(lab->duration() / lab->dt()));
  for (const Engine e : {Engine::Hand, Engine::Bullet}) {
    INFO("engine ", name(e));
    const RunResult r = runEngine(*lab, e, 200);
    CHECK(r.failure.empty());
    CHECK(long(r.trace.rows()) == expected);
    CHECK(r.trace.columns == lab->columns());
    CHECK(finiteRows(r.trace));
  }
}

// The shared options a lab cannot honour are refused when its config is read, naming the option, not
// at t = 0: drift "independent" either runs on φ = 0 or is an InputError at /simulation/drift.
inline void checkSharedOptions(const LabEntry& entry, const json& config) {
  INFO("lab ", entry.name, ": drift independent");
  json c = config;
  c["simulation"]["drift"] = "independent";
  std::unique_ptr<Lab> lab;
  try {
    lab = buildLab(entry, c, "config.json");
  } catch (const InputError& e) {
    CHECK(e.path() == "/simulation/drift");
    CHECK(e.expected().find("independent-coordinate form") != std::string::npos);
    return;
  }
  const RunResult r = runEngine(*lab, Engine::Hand, 50);
  CHECK(r.failure.empty());
  CHECK(finiteRows(r.trace));
}

inline void checkPassive(const LabEntry& entry, const json& config) {
  INFO("lab ", entry.name, ": passive energy");
  json passive = mergePatch(config, passivePatch());
  const Lab::PassiveEnergy stated = buildLab(entry, passive, "passive.json")->passiveEnergy();
  passive = mergePatch(passive, stated.conservative);
  if (stated.duration > 0) passive["simulation"]["duration"] = stated.duration;
  const auto lab = buildLab(entry, passive, "passive.json");
  const RunResult r = runEngine(*lab, Engine::Hand);
  CHECK(r.failure.empty());
  REQUIRE(r.trace.rows() > 1);
  const std::vector<double> energy = r.trace.series("energy");
  REQUIRE_FALSE(energy.empty());  // the contract: a column "energy"
  double worst = 0;
  for (double e : energy) worst = std::max(worst, std::abs(e - energy.front()));
  const double scale = energy.front() != 0 ? std::abs(energy.front()) : 1.0;
  MESSAGE(entry.name, ": passive |E − E0| ≤ ", worst, " over ", lab->duration(), " s (E0 = ", energy.front(),
          ", tolerance ", stated.tolerance, " relative)");
  CHECK(worst <= stated.tolerance * scale);
}

// Every metric the rubric's tests and leaderboard read exists for every option choice: the lab's
// metrics of a short run and the screening of its loops.
inline void checkColumnsAndMetrics(const LabEntry& entry, const json& config) {
  INFO("lab ", entry.name, ": columns and metrics");
  const Rubric rubric = parseRubric(JsonView(config, "config.json"));
  for (const json& sub : optionSubmissions(entry.name, config)) {
    INFO("submission ", sub.dump());
    const json applied = applySubmission(config, JsonView(sub, "submission.json"), entry.name, true);
    const auto lab = buildLab(entry, applied, "submission.json");
    CHECK_NOTHROW(checkColumns(rubric, lab->columns(), "config.json"));
    const RunResult r = runEngine(*lab, Engine::Hand, 200);
    json metrics;
    REQUIRE_NOTHROW(metrics = lab->metrics(r.trace));  // Trace::at throws on a column it lacks
    for (const auto& [key, value] : metrics.items()) {
      INFO("metric ", key);
      CHECK((value.is_number() && std::isfinite(value.get<double>())));
    }
    const ScreenResult screen = screenLoops(*lab);
    for (const auto& [key, value] : screen.metrics.items()) metrics[key] = value;
    for (const auto& t : rubric.tests) CHECK_MESSAGE(metrics.contains(t.metric), "rubric test metric " << t.metric);
    for (const auto& l : rubric.leaderboard) CHECK_MESSAGE(metrics.contains(l.metric), "leaderboard metric " << l.metric);
  }
}

inline void checkGrading(const LabEntry& entry, const std::string& config_file, const json& config,
                         const std::vector<std::string>& examples, const cli::TempDir& dir,
                         std::pair<double, double> defaults_band) {
  INFO("lab ", entry.name, ": grading");
  GradeOptions o;
  o.config_file = config_file;
  for (const std::string& file : examples) {
    INFO("example ", file);
    checkResults(gradeSubmission(file, o));
  }
  // The shipped defaults are a weak, stable start: the exercise is left to the student (20–50 % of
  // the points; the scratch lab in a test states its own band through the options).
  {
    const std::string file = (dir / "defaults.json").string();
    cli::writeFile(file, defaultSubmission(entry.name, config).dump());
    GradeOptions with_plots = o;
    with_plots.out_dir = (dir / "defaults_out").string();
    const GradeOutcome g = gradeSubmission(file, with_plots);
    checkResults(g);
    // Every test of a simulated metric (not the screening's) has its plot on disk.
    const auto loops = buildLab(entry, config, config_file)->linearise();
    for (const auto& t : g.results.at("tests")) {
      INFO("test ", t.at("name"));
      const std::string metric = t.at("extra_data").at("metric");
      if (screeningMetricDoc(metric, loops)) continue;
      REQUIRE(t.at("extra_data").contains("plot"));
      CHECK(std::filesystem::is_regular_file(std::filesystem::path(with_plots.out_dir) / t["extra_data"]["plot"].get<std::string>()));
    }
    double max = 0;
    for (const auto& t : g.results.at("tests")) max += t.at("max_score").get<double>();
    const double share = g.results.at("score").get<double>() / max;
    MESSAGE(entry.name, ": the default gains score ", g.results.at("score").get<double>(), " of ", max);
    CHECK(share >= defaults_band.first);
    CHECK(share <= defaults_band.second);
  }
  int k = 0;
  for (const json& sub : optionSubmissions(entry.name, config)) {
    INFO("submission ", sub.dump());
    const std::string file = (dir / ("option_" + std::to_string(k++) + ".json")).string();
    cli::writeFile(file, sub.dump());
    checkResults(gradeSubmission(file, o));
  }
}

// The share of the points a graded submission scored.
inline double scoreShare(const GradeOutcome& g) {
  double max = 0;
  for (const auto& t : g.results.at("tests")) max += t.at("max_score").get<double>();
  return max > 0 ? g.results.at("score").get<double>() / max : 0.0;
}

// The grade teaches the lecture: every lesson pair ranks as stated, doing nothing ranks below the
// shipped defaults, and the instructor's answers are near full marks.
inline void checkLessonsAndAnchors(const LabEntry& entry, const std::string& config_file, const json& config,
                                   const cli::TempDir& dir, const std::string& lab_dir, const std::string& instructor_dir) {
  INFO("lab ", entry.name, ": lessons");
  GradeOptions o;
  o.config_file = config_file;
  const Rubric rubric = parseRubric(JsonView(config, config_file));
  CHECK_MESSAGE(!rubric.lessons.empty(), "the rubric states no lesson (rubric/lessons)");
  for (const LessonCheck& c : checkLessons(rubric, lab_dir, o)) {
    INFO("lesson ", c.lesson.better, " ahead of ", c.lesson.worse, ": ", c.lesson.about);
    CHECK_MESSAGE(c.error.empty(), c.error);
    MESSAGE(entry.name, ": lesson ", c.lesson.better, " ", c.better, " vs ", c.lesson.worse, " ", c.worse, " of ", c.max,
            " (lead needed ", c.lesson.margin * c.max, ")");
    CHECK(c.holds());
  }
  // Doing nothing: every gain at its declared minimum, the options as the config sets them.
  json nothing = defaultSubmission(entry.name, config);
  for (const auto& [name, d] : config.at("gains").items()) nothing["gains"][name] = d.at("min");
  cli::writeFile(dir / "nothing.json", nothing.dump());
  cli::writeFile(dir / "defaults_again.json", defaultSubmission(entry.name, config).dump());
  const GradeOutcome none = gradeSubmission((dir / "nothing.json").string(), o);
  const GradeOutcome defaults = gradeSubmission((dir / "defaults_again.json").string(), o);
  checkResults(none);
  MESSAGE(entry.name, ": every gain at its minimum scores ", none.results.at("score").get<double>(), ", the defaults ",
          defaults.results.at("score").get<double>());
  CHECK(none.results.at("score").get<double>() < defaults.results.at("score").get<double>());
  // The instructor's answers.
  if (instructor_dir == "-") return;
  const std::vector<std::string> answers = exampleFiles(instructor_dir);
  CHECK_MESSAGE(!answers.empty(), "no instructor answer in " << instructor_dir);
  for (const std::string& file : answers) {
    INFO("instructor answer ", file);
    const GradeOutcome g = gradeSubmission(file, o);
    checkResults(g);
    MESSAGE(entry.name, ": ", std::filesystem::path(file).filename().string(), " scores ", scoreShare(g) * 100, " %");
    CHECK(scoreShare(g) >= 0.9);
  }
}

inline void checkRender(const LabEntry& entry, const json& config) {
  INFO("lab ", entry.name, ": a rendered frame");
  const auto lab = buildLab(entry, config, "config.json");
  const RunResult r = runEngine(*lab, Engine::Hand, 50);
  REQUIRE(r.trace.rows() > 0);
  Scene scene;
  Overlay overlay;
  lab->scene(r.trace, r.trace.rows() - 1, nullptr, scene);
  lab->overlay(r.trace, r.trace.rows() - 1, overlay);
  auto context = makeOffscreenContext(320, 240);
  Renderer renderer(*context);
  const Overlay* const overlays[] = {nullptr, &overlay};  // the scene alone, then with the panel
  for (const Overlay* o : overlays) {
    const Image image = renderer.render(scene, o);
    long differing = 0;  // pixels unlike the corner's (the background)
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x) differing += !std::equal(image.pixel(x, y), image.pixel(x, y) + 3, image.pixel(0, 0));
    CHECK(differing > image.width * image.height / 200);
  }
}

inline void checkCli(const LabEntry& entry, const json& config, const std::vector<std::string>& examples,
                     const cli::TempDir& dir) {
  INFO("lab ", entry.name, ": the dynlab command line");
  const auto lab = buildLab(entry, config, "config.json");
  const std::vector<std::string> columns = lab->columns();
  REQUIRE(columns.size() >= 3);
  const std::string plot = columns[1] + "," + columns[2];
  cli::Result r = cli::dynlab(dir, "figure " + entry.name + " --plot " + plot + " --duration 0.2 --format png --out figures");
  INFO(r.out, r.err);
  CHECK(r.code == 0);
  CHECK(std::filesystem::exists(dir / "figures" / ("plot_" + columns[1] + "+" + columns[2] + ".png")));
  // What scripts/demo runs: the default config, both engines, its whole duration, under the
  // rubric's watchdog (which both engines must pass with the shipped gains).
  r = cli::dynlab(dir, "run " + entry.name + " --out run");
  CHECK_MESSAGE(r.code == 0, r.out << r.err);
  REQUIRE_FALSE(examples.empty());
  r = cli::dynlab(dir, "grade " + cli::quote(examples.front()) + " --out grade");
  CHECK(r.code == 0);
  CHECK(std::filesystem::exists(dir / "grade" / "results.json"));
}

// Runs every check but the window's on one lab (config: its default config).
inline void checkLab(const LabEntry& entry, const json& config, const LabCheckOptions& options = {}) {
  const cli::TempDir dir("every_lab_" + entry.name);
  const std::string config_file = (dir / "config.json").string();
  cli::writeFile(config_file, config.dump(2));
  const std::string examples_dir = options.examples_dir.empty()
                                       ? std::string(DYNLAB_SOURCE_DIR) + "/labs/" + entry.name + "/examples"
                                       : options.examples_dir;
  std::vector<std::string> examples = exampleFiles(examples_dir);
  // The instructor's examples (full credit, never shipped to students) are held to the same schema.
  if (options.examples_dir.empty())
    for (const auto& f : exampleFiles(std::string(DYNLAB_SOURCE_DIR) + "/labs/" + entry.name + "/instructor")) examples.push_back(f);
  checkConfigAndExamples(entry, config, examples);
  checkEngines(entry, config);
  checkSharedOptions(entry, config);
  checkPassive(entry, config);
  checkColumnsAndMetrics(entry, config);
  checkGrading(entry, config_file, config, examples, dir, options.defaults_band);
  const std::string lab_dir = options.lab_dir.empty() ? std::string(DYNLAB_SOURCE_DIR) + "/labs/" + entry.name : options.lab_dir;
  checkLessonsAndAnchors(entry, config_file, config, dir, lab_dir,
                         options.instructor_dir.empty() ? lab_dir + "/instructor" : options.instructor_dir);
  checkRender(entry, config);
  if (options.cli) checkCli(entry, config, examples, dir);
}

// `dynlab ui LAB --frames 3` in a virtual X display; false (and DYNLAB_TEST_SKIPPED printed, so
// ctest reports the test skipped) when xvfb-run is missing.
inline bool checkWindow(const LabEntry& entry) {
  if (std::system("command -v xvfb-run >/dev/null 2>&1 && command -v xauth >/dev/null 2>&1") != 0) {
    std::cout << "DYNLAB_TEST_SKIPPED: xvfb-run (packages xvfb, xauth) not found; the window checks did not run\n";
    return false;
  }
  INFO("lab ", entry.name, ": dynlab ui");
  const cli::TempDir dir("every_lab_ui_" + entry.name);
  const cli::Result r = cli::shell(dir, "xvfb-run -a -s '-screen 0 1600x1000x24' " + cli::quote(DYNLAB_BIN) + " ui " +
                                            entry.name + " --frames 3");
  INFO(r.out, r.err);
  CHECK(r.code == 0);
  return true;
}

}  // namespace dyn::test
