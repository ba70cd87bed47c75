// The lab contract's checks on one lab (app/cli/authoring/lab_check.h): each check records the first thing that is
// wrong (or, when all holds, what it measured) as one line; an exception is that check's failure.
#include "app/cli/authoring/lab_check.h"
#include "app/cli/authoring/lab_check_steps.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include "app/shared/process.h"
#include "app/cli/authoring/readme_numbers.h"
#include "grading/grade.h"
#include "grading/rubric.h"
#include "grading/scenario.h"
#include "labs/config.h"
#include "labs/numbers.h"
#include "labs/run.h"
#include "labs/settings.h"
#include "labs/submission.h"
#include "render/gl_context.h"
#include "render/renderer.h"

namespace dyn {

namespace fs = std::filesystem;

namespace lab_check {
namespace {

std::string oneLine(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  return s;
}
bool finiteRows(const Trace& trace) {
  return std::all_of(trace.data.begin(), trace.data.end(), [](double x) { return std::isfinite(x); });
}

// dynlab (the binary at `bin`) run with args in dir, no shell: its exit code and the last line it wrote
// to stderr. A file name among args is one argument, whatever it holds.
std::pair<int, std::string> runDynlab(const fs::path& dir, const std::string& bin, const std::vector<std::string>& args) {
  const fs::path err = dir / ".check_stderr";
  std::vector<std::string> argv = {bin};
  argv.insert(argv.end(), args.begin(), args.end());
  ProcessOptions o;
  o.cwd = dir.string();
  o.stderr_file = err.string();
  const ProcessResult r = runProgram(argv, o);
  if (!r.started()) return {r.code, r.error};
  std::ifstream in(err);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return {r.code, last};
}

}  // namespace

std::string fmt(double x) { return dyn::fmt("%.4g", x); }
std::string percent(double share) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f %%", share * 100);
  return b;
}
std::string fileName(const std::string& path) { return fs::path(path).filename().string(); }

void Step::fail(const std::string& why) {
  if (problem.empty()) problem = oneLine(why);
}

void run(LabCheckReport& report, const std::string& name, const std::function<void(Step&)>& body) {
  Step s;
  try {
    body(s);
  } catch (const std::exception& e) {
    s.fail(e.what());
  }
  report.checks.push_back({name, s.problem.empty(), s.problem.empty() ? s.detail : s.problem});
}

void writeFile(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

// A submission with the config's default gains, and these options.
json defaultSubmission(const std::string& lab, const json& config, const json& options) {
  json sub = {{"lab", lab}, {"gains", json::object()}};
  for (const auto& [name, d] : config.at("gains").items()) sub["gains"][name] = d.at("value");
  for (const auto& [key, value] : options.items()) sub[key] = value;
  return sub;
}

// One submission per choice of each declared option (the others left at the config's), and the
// defaults alone.
std::vector<json> optionSubmissions(const std::string& lab, const json& config) {
  std::vector<json> subs = {defaultSubmission(lab, config)};
  const json options = config.value("submission_options", json::object());
  for (const auto& [key, decl] : options.items())
    for (const auto& choice : decl.at("choices")) subs.push_back(defaultSubmission(lab, config, {{key, choice}}));
  return subs;
}

// What is wrong with a grade's results.json (Gradescope's shape: a finite score that is the sum of
// its tests', each test named and scored within its points), or "".
std::string resultsProblem(const GradeOutcome& g) {
  if (g.input_error) return "not graded: " + g.error;
  const json& r = g.results;
  const std::string output = r.value("output", "");
  if (output.find("expected a metric this lab reports") != std::string::npos) return "results output: " + output;
  if (!r.contains("score")) return "results.json has no score";
  if (!r.contains("tests") || !r.at("tests").is_array() || r.at("tests").empty()) return "results.json has no tests";
  double sum = 0;
  for (const auto& t : r.at("tests")) {
    if (!t.contains("name") || !t.at("name").is_string()) return "a test without a name";
    const std::string name = t.at("name").get<std::string>();
    if (!t.contains("output") || !t.at("output").is_string()) return "test \"" + name + "\" has no output";
    const double score = t.at("score").get<double>(), max = t.at("max_score").get<double>();
    if (!(score >= 0 && score <= max + 1e-9)) return "test \"" + name + "\" scores " + fmt(score) + " of " + fmt(max);
    sum += score;
  }
  const double score = r.at("score").get<double>();
  // As doctest::Approx: relative 1.19e-5 on top of an absolute scale of 1.
  if (!(std::abs(score - sum) < 1.19e-5 * (1 + std::max(std::abs(score), std::abs(sum)))))
    return "score " + fmt(score) + " is not the sum of the tests' " + fmt(sum);
  if (!r.contains("execution_time") || !r.at("execution_time").is_number()) return "results.json has no execution_time";
  return "";
}

double scoreShare(const GradeOutcome& g) {
  double max = 0;
  for (const auto& t : g.results.at("tests")) max += t.at("max_score").get<double>();
  return max > 0 ? g.results.at("score").get<double>() / max : 0.0;
}

// Grades a file and returns its outcome; a malformed results.json fails the step.
GradeOutcome graded(Step& s, const std::string& file, const GradeOptions& o) {
  GradeOutcome g = gradeSubmission(file, o);
  const std::string problem = resultsProblem(g);
  s.expect(problem.empty(), fileName(file) + ": " + problem);
  return g;
}

// The default config builds and its simulation block parses.
void checkConfig(const Checked& chk, LabCheckReport& report) {
  run(report, "config", [&](Step& s) {
    buildLab(chk.entry, chk.config, chk.shown);
    parseSimulation(JsonView(chk.config, chk.shown)["simulation"]);
    s.detail = "builds; the simulation block parses";
  });
}

// The examples (and the instructor's answers) apply strictly and match the submission schema.
void checkExamples(const Checked& chk, LabCheckReport& report) {
  run(report, "examples", [&](Step& s) {
    s.expect(!chk.examples.empty(), "no example submission (labs/" + chk.entry.name + "/chk.examples/*.json)");
    const json schema = submissionSchema(chk.config, chk.entry.name);
    const json& props = schema.at("properties");
    for (const std::string& file : chk.examples) {
      const json sub = loadJsonFile(file);
      try {
        applySubmission(chk.config, JsonView(sub, file), chk.entry.name, true);
      } catch (const std::exception& e) {
        s.fail(e.what());
      }
      for (const auto& [key, value] : sub.items()) {
        if (!s.expect(props.contains(key), fileName(file) + ": key \"" + key + "\" is not in the submission schema")) continue;
        if (props[key].contains("enum"))
          s.expect(std::count(props[key]["enum"].begin(), props[key]["enum"].end(), value) == 1,
                   fileName(file) + ": " + key + " = " + value.dump() + " is not one of " + props[key]["enum"].dump());
      }
      const json gains = sub.value("gains", json::object());
      for (const auto& [gain, _] : gains.items())
        s.expect(props["gains"]["properties"].contains(gain), fileName(file) + ": gain \"" + gain + "\" is not the lab's");
      for (const auto& required : schema.at("required"))
        s.expect(sub.contains(required.get<std::string>()), fileName(file) + ": lacks \"" + required.get<std::string>() + "\"");
    }
    s.detail = std::to_string(chk.examples.size()) + " files apply strictly and match the submission schema";
  });
}

// Both engines run; drift "independent" runs or is refused where it is read; the passive energy holds.
void checkPhysics(const Checked& chk, LabCheckReport& report) {
  const std::string passive_name = chk.shown + " (passive: τ = 0)";
  run(report, "engines", [&](Step& s) {
    const auto lab = buildLab(chk.entry, chk.config, chk.shown);
    const long expected = std::min(200L, std::lround(lab->duration() / lab->dt()));
    for (const Engine e : {Engine::Hand, Engine::Bullet}) {
      const RunResult r = runEngine(*lab, e, 200);
      const std::string who = std::string(dyn::name(e)) + ": ";
      s.expect(r.failure.empty(), who + r.failure);
      s.expect(long(r.trace.rows()) == expected, who + std::to_string(r.trace.rows()) + " rows, expected " + std::to_string(expected));
      s.expect(r.trace.columns == lab->columns(), who + "trace columns are not the lab's columns()");
      s.expect(finiteRows(r.trace), who + "a value is not finite");
    }
    s.detail = "hand and Bullet: " + std::to_string(expected) + " steps, finite";
  });

  // The shared options a lab cannot honour are refused when its chk.config is read, naming the option,
  // not at t = 0: drift "independent" either runs on φ = 0 or is an InputError at /simulation/drift.
  run(report, "drift independent", [&](Step& s) {
    json c = chk.config;
    c["simulation"]["drift"] = "independent";
    std::unique_ptr<Lab> lab;
    try {
      lab = buildLab(chk.entry, c, chk.shown);
    } catch (const InputError& e) {
      s.expect(e.path() == "/simulation/drift", "refused at " + e.path() + ", not at /simulation/drift");
      s.expect(e.expected().find("independent-coordinate form") != std::string::npos,
               "the refusal does not say \"independent-coordinate form\": " + e.expected());
      s.detail = "refused when the chk.config is read, at /simulation/drift";
      return;
    }
    const RunResult r = runEngine(*lab, Engine::Hand, 50);
    s.expect(r.failure.empty(), r.failure);
    s.expect(finiteRows(r.trace), "a value is not finite");
    s.detail = "runs on the independent coordinates (50 steps, finite)";
  });

  run(report, "passive energy", [&](Step& s) {
    json passive = mergePatch(chk.config, passivePatch());
    const Lab::PassiveEnergy stated = buildLab(chk.entry, passive, passive_name)->passiveEnergy();
    passive = mergePatch(passive, stated.conservative);
    if (stated.duration > 0) setRunDuration(passive, stated.duration);
    const auto lab = buildLab(chk.entry, passive, passive_name);
    const RunResult r = runEngine(*lab, Engine::Hand);
    s.expect(r.failure.empty(), r.failure);
    if (!s.expect(r.trace.rows() > 1, "the passive run has fewer than 2 rows")) return;
    const std::vector<double> energy = r.trace.series("energy");  // the contract: a column "energy"
    if (!s.expect(!energy.empty(), "no column \"energy\"")) return;
    double worst = 0;
    for (double e : energy) worst = std::max(worst, std::abs(e - energy.front()));
    const double scale = energy.front() != 0 ? std::abs(energy.front()) : 1.0;
    report.passive_drift = worst, report.passive_e0 = energy.front();
    report.passive_tolerance = stated.tolerance, report.passive_duration = lab->duration();
    const std::string measured = "|E − E0| ≤ " + fmt(worst) + " over " + fmt(lab->duration()) + " s (E0 = " +
                                 fmt(energy.front()) + ", relative " + fmt(worst / scale) + ", tolerance " + fmt(stated.tolerance) + ")";
    s.expect(worst <= stated.tolerance * scale, measured + ": beyond the tolerance");
    s.detail = measured;
  });
}

// A frame renders; the command line runs the lab; the README's measured numbers agree with that run.
void checkOutputs(const Checked& chk, LabCheckReport& report) {
  run(report, "render", [&](Step& s) {
      const auto lab = buildLab(chk.entry, chk.config, chk.shown);
      const RunResult r = runEngine(*lab, Engine::Hand, 50);
      if (!s.expect(r.trace.rows() > 0, "no trace row to draw")) return;
      Scene scene;
      Overlay overlay;
      lab->scene(r.trace, r.trace.rows() - 1, nullptr, scene);
      lab->overlay(r.trace, r.trace.rows() - 1, overlay);
      auto context = makeOffscreenContext(320, 240);
      Renderer renderer(*context);
      const Overlay* const overlays[] = {nullptr, &overlay};  // the scene alone, then with the panel
      std::string counts;
      for (const Overlay* ov : overlays) {
        const Image image = renderer.render(scene, ov);
        long differing = 0;  // pixels unlike the corner's (the background)
        for (int y = 0; y < image.height; ++y)
          for (int x = 0; x < image.width; ++x) differing += !std::equal(image.pixel(x, y), image.pixel(x, y) + 3, image.pixel(0, 0));
        const std::string what = ov ? "with the panel" : "the scene alone";
        s.expect(differing > image.width * image.height / 200, what + ": " + std::to_string(differing) + " pixels unlike the background");
        counts += (counts.empty() ? "" : ", ") + std::to_string(differing) + " " + what;
      }
      s.detail = "320x240 frames, pixels unlike the background: " + counts;
    });

  if (!chk.options.dynlab_binary.empty())
    run(report, "cli", [&](Step& s) {
      const auto lab = buildLab(chk.entry, chk.config, chk.shown);
      const std::vector<std::string> columns = lab->columns();
      if (!s.expect(columns.size() >= 3, "fewer than 3 trace columns")) return;
      const std::string& bin = chk.options.dynlab_binary;
      const std::string plot = columns[1] + "," + columns[2];
      auto [code, err] = runDynlab(chk.dir, bin, {"figure", chk.entry.name, "--plot", plot, "--duration", "0.2", "--format", "png", "--out", "figures"});
      s.expect(code == 0, "dynlab figure exit " + std::to_string(code) + ": " + err);
      s.expect(fs::exists(chk.dir / "figures" / ("plot_" + columns[1] + "+" + columns[2] + ".png")), "dynlab figure wrote no plot");
      // What scripts/demo runs: the default chk.config, both engines, its whole duration, under the
      // rubric's watchdog (which both engines must pass with the shipped gains).
      std::tie(code, err) = runDynlab(chk.dir, bin, {"run", chk.entry.name, "--out", "run"});
      s.expect(code == 0, "dynlab run exit " + std::to_string(code) + ": " + err);
      if (!s.expect(!chk.examples.empty(), "no example to grade")) return;
      std::tie(code, err) = runDynlab(chk.dir, bin, {"grade", chk.examples.front(), "--out", "grade"});
      s.expect(code == 0, "dynlab grade exit " + std::to_string(code) + ": " + err);
      s.expect(fs::exists(chk.dir / "grade" / "results.json"), "dynlab grade wrote no results.json");
      s.detail = "dynlab figure, run (both engines, whole run) and grade exit 0";
    });
  // The README's measured numbers (app/cli/authoring/readme_numbers.h) against that run's summary.json.
  if (!chk.options.dynlab_binary.empty())
    run(report, "readme numbers", [&](Step& s) {
      const fs::path readme = fs::path(chk.lab_dir) / "README.md", summary = chk.dir / "run" / "summary.json";
      if (!fs::is_regular_file(readme)) {
        s.detail = "no README.md";
        return;
      }
      if (!s.expect(fs::is_regular_file(summary), "dynlab run wrote no summary.json")) return;
      const std::string text = readTextFile(readme.string(), 1u << 20);
      for (const std::string& problem : readmeNumberProblems(text, loadJsonFile(summary.string()), readme.string()))
        s.fail(problem);
      s.detail = std::to_string(readmeNumbers(text).size()) + " measured number(s) marked in README.md agree with dynlab run";
    });
}

}  // namespace lab_check

bool LabCheckReport::ok() const {
  return std::all_of(checks.begin(), checks.end(), [](const LabCheck& c) { return c.ok; });
}

std::vector<std::string> jsonFiles(const std::string& dir) {
  std::vector<std::string> files;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.path().extension() == ".json") files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

LabCheckReport checkLab(const LabEntry& entry, const json& config, const LabCheckOptions& options) {
  using namespace lab_check;
  LabCheckReport report;
  Checked c{entry, config, options};
  c.dir = options.work_dir;
  // The file the checks name and the grader reads: the lab's own when given, else a scratch copy.
  c.config_file = options.config_file.empty() ? (c.dir / "config.json").string() : options.config_file;
  if (options.config_file.empty()) writeFile(c.config_file, config.dump(2));
  c.shown = options.config_file.empty() ? "config.json" : options.config_file;
  c.lab_dir = options.lab_dir.empty() ? fs::path(defaultConfigPath(entry.name)).parent_path().string() : options.lab_dir;
  c.examples = jsonFiles(options.examples_dir.empty() ? c.lab_dir + "/examples" : options.examples_dir);
  c.shipped = c.examples.size();  // the students' examples; the instructor's answers follow
  // The instructor's examples (full credit, never shipped to students) are held to the same schema.
  if (options.examples_dir.empty())
    for (const auto& f : jsonFiles(c.lab_dir + "/instructor")) c.examples.push_back(f);
  c.o.config_file = c.config_file;

  checkConfig(c, report);
  // Every other check builds the lab from this config: on a config that does not build each would
  // fail with the same line (a lecturer's first edit once gave 16). One line says they did not run.
  if (!report.checks.back().ok) {
    report.checks.push_back({"other checks", false, "not run: they need the config to build (fix the line above first)"});
    return report;
  }
  checkExamples(c, report);
  for (auto group : {checkPhysics, checkAdviceAndMetrics, checkGrading, checkLessonPairs, checkAnswers, checkOutputs}) group(c, report);
  return report;
}

}  // namespace dyn
