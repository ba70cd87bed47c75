// app/ui/session (no GL, no display): gains and options as the lab's JSON declares them, --set
// validation, runs identical to `dynlab run`'s, the grader's watchdog sentence for unstable gains,
// "Save gains…" writing a strict, atomic submission that loads back to the same gains, and what
// the panel shows of the run: live plots of every step up to the row on screen, and that row's
// metrics.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "labs/generic/model_lab.h"
#include "app/ui/session.h"
#include "grading/grade.h"
#include "labs/run.h"
#include "labs/submission.h"
#include "tests/test_files.h"

namespace fs = std::filesystem;
using namespace dyn;
using namespace dyn::ui;

namespace {

const std::string kExamples = std::string(DYNLAB_SOURCE_DIR) + "/labs/slider_crank/examples/";

// Advances until the primary run ends (bounded, so a bug cannot hang the test).
void runToEnd(TuningSession& s) {
  for (int i = 0; i < 1000 && !s.finished(); ++i) s.advance(1000);
}

std::string inputError(TuningSession& s, const std::string& assignment) {
  try {
    s.set(assignment);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("gains and options come from the lab's JSON, in its order, with bounds, units and docs") {
  TuningSession s("slider_crank");
  const auto& g = s.gainSpecs();
  REQUIRE(g.size() == 4);
  CHECK(g[0].name == "kp_x");
  CHECK(g[1].name == "kd_x");
  CHECK(g[2].name == "kp_f");
  CHECK(g[3].name == "ki_f");
  CHECK(g[0].min == 0.0);
  CHECK(g[0].max == 20000.0);
  CHECK(g[0].unit == "N/m");
  CHECK(g[0].doc == "slider position stiffness");
  CHECK(s.gain("kp_x") == 150.0);
  REQUIRE(s.optionSpecs().size() == 1);
  CHECK(s.optionSpecs()[0].name == "force_law");
  CHECK(s.optionSpecs()[0].choices == std::vector<std::string>{"open_loop", "proportional", "integral"});
  CHECK(s.option("force_law") == "proportional");
  CHECK(s.title().find("Slider crank") == 0);
  // A run starts at once, with its first row at t = 0.
  CHECK(s.hasRows());
  CHECK(s.time() == 0.0);
  CHECK(s.problem().empty());
  CHECK(s.screening().size() == 2);
}

TEST_CASE("--set NAME=VALUE: gains within bounds, declared options, one clear line otherwise") {
  TuningSession s("slider_crank");
  s.set("kp_x=500");
  s.set("force_law=proportional");
  CHECK(s.gain("kp_x") == 500.0);
  CHECK(s.option("force_law") == "proportional");
  CHECK(inputError(s, "kp_x=1e9").find("--set kp_x=1e9: expected a number in [0, 2e+04] N/m") != std::string::npos);
  CHECK(inputError(s, "kp_x=-1").find("expected a number in") != std::string::npos);
  // The value refused with the digits that show why (%g would print "got 2e+04", inside [0, 2e+04]).
  CHECK(inputError(s, "kp_x=20000.000000000004").find("expected a number in [0, 2e+04] N/m, got 20000.000000000004") != std::string::npos);
  CHECK(inputError(s, "kp_x=abc").find("expected a number, got \"abc\"") != std::string::npos);
  CHECK(inputError(s, "kp_x=nan").find("expected a number") != std::string::npos);
  CHECK(inputError(s, "force_law=bang_bang").find("expected one of open_loop, proportional, integral") != std::string::npos);
  CHECK(inputError(s, "kq_x=1").find("unknown name \"kq_x\" (this lab's gains and options: kp_x, kd_x, kp_f, ki_f, force_law)") !=
        std::string::npos);
  CHECK(inputError(s, "kp_x").find("expected NAME=VALUE") != std::string::npos);
  // Rejected values change nothing.
  CHECK(s.gain("kp_x") == 500.0);
  CHECK(s.option("force_law") == "proportional");
  s.resetToLabDefaults();
  CHECK(s.gain("kp_x") == 150.0);
  CHECK(s.option("force_law") == "proportional");
}

TEST_CASE("the session's runs are the runs `dynlab run` makes with the same gains, step for step") {
  const fs::path dir = test::scratchDir("dynlab_ui_session", "same_runs");
  TuningSession s("slider_crank");
  s.set("kp_x=900");
  s.set("ki_f=25");
  s.setEngine(EngineChoice::Both);
  s.restart();
  runToEnd(s);
  CHECK(s.problem().empty());
  REQUIRE(s.ghost());
  const std::string gains = (dir / "gains.json").string();
  s.saveSubmission(gains);
  const LoadedLab loaded = loadLab("slider_crank", "", gains);
  const RunResult hand = runEngine(*loaded.lab, Engine::Hand), bullet = runEngine(*loaded.lab, Engine::Bullet);
  CHECK(s.primary().rows() == hand.trace.rows());
  CHECK(s.primary().hash() == hand.trace.hash());
  CHECK(s.ghost()->hash() == bullet.trace.hash());
  CHECK(s.time() == doctest::Approx(4.0));  // the last row: t = duration
  // Metrics are the lab's, of the whole run.
  CHECK(s.metrics() == loaded.lab->metrics(hand.trace));
  // Restart: back to t = 0, one row; advancing a finished run does nothing.
  const long more = s.advance(10);
  CHECK(more == 0);
  s.restart();
  CHECK(s.primary().rows() == 1);
  CHECK(s.advance(99) == 99);
  CHECK(s.row() == 99);
}

TEST_CASE("unstable gains stop the run with the grader's sentence, never a throw") {
  TuningSession s("slider_crank", "", kExamples + "unstable_integral.json");
  CHECK(s.gain("ki_f") == 400.0);
  runToEnd(s);
  CHECK(s.finished());
  CHECK(s.problem() == "unstable: the rail force left its safe range [-500, 500] at t = 0.088 s (f_Ty = -550.3)");
  CHECK(s.screeningUnstable());
  // The same words as a graded run of the nominal scenario (shared RowWatch).
  const LoadedLab loaded = loadLab("slider_crank", "", kExamples + "unstable_integral.json");
  const Rubric rubric = parseRubric(JsonView(loaded.config, loaded.config_file));
  const ScenarioRun graded = runScenario(*loaded.lab, rubric.watchdog, Deadline::max(), loaded.config_file);
  CHECK(graded.failure == s.problem());
  CHECK(s.primary().rows() == graded.trace.rows());
  // Back to the lab's defaults: the run is fine again.
  s.resetToLabDefaults();
  s.restart();
  CHECK(s.problem().empty());
  CHECK(s.advance(500) == 500);
}

TEST_CASE("Save gains writes a strict submission atomically, and it loads back to the same gains") {
  const fs::path dir = test::scratchDir("dynlab_ui_session", "save");
  TuningSession s("slider_crank");
  s.set("kp_x=3000");
  s.set("kd_x=90");
  s.set("ki_f=25.125");
  s.set("force_law=integral");
  const fs::path file = dir / "mine.json";
  std::ofstream(file) << "old contents";  // replaced, not appended to
  s.saveSubmission(file.string());
  const std::string text = test::readBytes(file);
  CHECK(text.find("{\n  \"lab\": \"slider_crank\",\n  \"force_law\": \"integral\",\n  \"gains\": {\n    \"kp_x\": 3000.0,") == 0);
  const json sub = loadJsonFile(file.string());
  CHECK(sub == s.submission());
  // Strict, as `dynlab grade` reads it.
  const json config = loadJsonFile(defaultConfigPath("slider_crank"));
  const json applied = applySubmission(config, JsonView(sub, file.string()), "slider_crank", true);
  CHECK(applied["gains"]["ki_f"]["value"] == 25.125);
  // Nothing else left in the directory (the temporary was renamed into place).
  int files = 0;
  for (const auto& e : fs::directory_iterator(dir)) files += e.is_regular_file() ? 1 : 0;
  CHECK(files == 1);
  // A directory that does not exist: an error naming the path, and no file.
  const std::string bad = (dir / "no_such_dir" / "x.json").string();
  CHECK_THROWS_WITH_AS(s.saveSubmission(bad), doctest::Contains(("cannot save " + bad).c_str()), std::runtime_error);
  CHECK_FALSE(fs::exists(dir / "no_such_dir"));
}

TEST_CASE("a config the lab rejects becomes a problem to show, not a crash") {
  const fs::path dir = test::scratchDir("dynlab_ui_session", "bad_config");
  json config = loadJsonFile(defaultConfigPath("slider_crank"));
  config["mechanism"]["links"][0]["mass"] = -1;
  const std::string file = (dir / "bad.json").string();
  std::ofstream(file) << config.dump();
  // Bad input up front is an InputError (dynlab-ui exits 2 before opening a window).
  CHECK_THROWS_AS(TuningSession("slider_crank", file), InputError);
  CHECK_THROWS_AS(TuningSession("no_such_lab"), InputError);
  CHECK_THROWS_AS(parseEngineChoice("warp"), InputError);
}

TEST_CASE("the live plots hold every step up to the row on screen; at a watchdog stop they end on the tripping value") {
  TuningSession s("slider_crank", "", kExamples + "unstable_integral.json");
  const int f_col = s.primary().column("f_Ty");
  REQUIRE(f_col >= 0);
  const std::size_t window = std::size_t(std::lround(2.0 / s.lab()->dt()));
  // Frame by frame as the window plays (1/60 s of 1 ms steps: 16 or 17 steps a frame).
  int frames = 0;
  while (!s.finished() && frames < 1000) {
    s.advance(frames % 3 == 0 ? 16 : 17);
    ++frames;
    const Trace& tr = s.primary();
    const std::size_t row = s.row(), first = row > window ? row - window : 0;
    const std::vector<Series> plots = s.livePlots(f_col);
    REQUIRE(plots.size() == 3);  // the lab's two, then the chosen column
    for (const Series& p : {plots[0], plots[2]}) {
      INFO("frame ", frames, ", row ", row, ", plot ", p.name);
      REQUIRE(p.values.size() == row - first + 1);  // one value per step, none skipped
      for (std::size_t i = 0; i < p.values.size(); i += 7) CHECK(p.values[i] == float(tr.at(first + i, f_col)));
      CHECK(p.values.back() == float(tr.at(row, f_col)));
    }
    CHECK(plots[0].name == "f_Ty (N)");
    CHECK(plots[2].name == "f_Ty (N)");
  }
  // The watchdog stopped it: the plot's last value is the f_Ty the sentence names and the overlay shows.
  REQUIRE(s.finished());
  CHECK(s.problem().find("(f_Ty = -550.3)") != std::string::npos);
  const float last = s.livePlots()[0].values.back();
  CHECK(last == doctest::Approx(-550.3).epsilon(1e-4));
  Overlay overlay;
  s.lab()->overlay(s.primary(), s.row(), overlay);
  char shown[32];
  std::snprintf(shown, sizeof shown, "%.2f", double(last));
  bool found = false;
  for (const auto& [label, value] : overlay.lines) found = found || (label == "f_Ty / f_des" && value.rfind(shown, 0) == 0);
  CHECK_MESSAGE(found, "the overlay's f_Ty line starts with ", shown);
}

TEST_CASE("the metrics the panel shows are the row on screen's: recomputed every frame, and after a restart") {
  TuningSession s("slider_crank");
  for (int frame = 0; frame < 40; ++frame) {
    s.advance(17);
    INFO("frame ", frame, ", row ", s.row());
    CHECK(s.currentMetrics() == s.metrics());
    CHECK(s.currentMetrics()["steps"] == s.primary().steps());
  }
  // A restart with other gains, advanced to the same row: the new run's metrics, never the cached ones.
  const std::size_t row = s.row();
  const json before = s.currentMetrics();
  s.setGain("kp_x", 400);
  s.restart();
  s.advance(long(row));
  REQUIRE(s.row() == row);
  CHECK(s.currentMetrics() == s.metrics());
  CHECK(s.currentMetrics() != before);
}

TEST_CASE("--scenario: the session runs the grader's scenario, and its saved gains grade to what it showed") {
  const fs::path dir = test::scratchDir("dynlab_ui_session", "scenario");
  const json config = loadJsonFile(defaultConfigPath("slider_crank"));
  const json& scenarios = config["rubric"]["scenarios"];
  // The patch is applied: the heavier payload, named in the title.
  TuningSession heavy("slider_crank", "", kExamples + "mediocre.json", "heavy_load");
  CHECK(heavy.scenario() == "heavy_load");
  CHECK(heavy.title().find("heavy_load") != std::string::npos);
  CHECK(heavy.config()["mechanism"]["load_mass"] == scenarios["heavy_load"]["patch"]["mechanism"]["load_mass"]);
  CHECK(TuningSession("slider_crank", "", kExamples + "mediocre.json").config()["mechanism"]["load_mass"] ==
        config["mechanism"]["load_mass"]);
  // Sensor noise seeded as the grader seeds this submission: the whole run's metrics are the grade's.
  TuningSession noisy("slider_crank", "", kExamples + "mediocre.json", "noisy_sensor");
  runToEnd(noisy);
  REQUIRE(noisy.problem().empty());
  const fs::path saved = dir / "saved.json";
  noisy.saveSubmission(saved.string());
  const GradeOutcome g = gradeSubmission(saved.string(), GradeOptions{});
  const json& graded = g.results["extra_data"]["scenarios"]["noisy_sensor"]["metrics"];
  const json shown = noisy.metrics();
  REQUIRE(shown.contains("f_rms"));
  for (const auto& [metric, value] : shown.items())
    if (graded.contains(metric)) CHECK_MESSAGE(graded[metric] == value, metric);
  // An unknown scenario is bad input, listing the rubric's.
  CHECK_THROWS_WITH_AS(TuningSession("slider_crank", "", "", "nope"), doctest::Contains("noisy_sensor"), InputError);
}

TEST_CASE("a model file in the session: its passive run, both engines, nothing to tune, the loop closed") {
  const std::string file = std::string(DYNLAB_SOURCE_DIR) + "/assets/models/fourbar.xml";
  ui::TuningSession s(app::loadModelLab(file, std::nullopt));
  CHECK(s.labName() == "fourbar");
  CHECK(s.gainSpecs().empty());
  CHECK(s.title().find("fourbar.xml") != std::string::npos);
  s.setEngine(ui::EngineChoice::Both);
  s.restart();
  CHECK(s.advance(500) == 500);
  CHECK(s.problem().empty());
  REQUIRE(s.ghost() != nullptr);
  const Trace& t = s.primary();
  CHECK(t.at(s.row(), "t") == doctest::Approx(0.5));
  // The hand engine keeps the pin closed; the four-bar falls from rest, so it has moved.
  for (std::size_t r = 0; r < t.rows(); ++r) CHECK(t.at(r, "constraint_residual") <= 1e-12);
  CHECK(std::abs(t.at(s.row(), "q_crank") - t.at(0, "q_crank")) > 1e-3);
  CHECK_THROWS_AS(s.set("kp=1"), InputError);
}
