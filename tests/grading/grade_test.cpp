// grading/grade: mediocre, unstable and malformed submissions (and the full-credit one where the
// instructor files are); reproducibility; the Gradescope results.json contract; the watchdog and
// the time budget.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "grading/grade.h"
#include "grading/rubric.h"
#include "tests/instructor.h"

namespace fs = std::filesystem;
using namespace dyn;

namespace {

const std::string kExamples = std::string(DYNLAB_SOURCE_DIR) + "/labs/slider_crank/examples/";
// A stable submission students have (not full credit: the answer stays in instructor/).
const std::string kMediocre = kExamples + "mediocre.json";

fs::path tempDir() {
  const fs::path d = fs::temp_directory_path() / ("dynlab-grade-test-" + std::to_string(::getpid()));
  fs::create_directories(d);
  return d;
}

std::string writeFile(const std::string& name, const std::string& text) {
  const fs::path p = tempDir() / name;
  std::ofstream(p, std::ios::binary) << text;
  return p.string();
}

GradeOutcome grade(const std::string& file, GradeOptions o = {}) { return gradeSubmission(file, o); }

double score(const GradeOutcome& g) { return g.results.at("score").get<double>(); }

double maxScore(const GradeOutcome& g) {
  double m = 0;
  for (const auto& t : g.results.at("tests")) m += t.at("max_score").get<double>();
  return m;
}

bool anyTestSays(const GradeOutcome& g, const std::string& text) {
  for (const auto& t : g.results.at("tests"))
    if (t.at("output").get<std::string>().find(text) != std::string::npos) return true;
  return false;
}

}  // namespace

TEST_CASE("submissions score in their expected ranges, with messages that explain") {
  const GradeOutcome mediocre = grade(kMediocre);
  const GradeOutcome unstable = grade(kExamples + "unstable_integral.json");
  REQUIRE(maxScore(mediocre) == doctest::Approx(15));
  CHECK(score(mediocre) > 3);  // its soft motion loop (kp_x 150) misses the 3 mm tracking thresholds
  CHECK(score(mediocre) < 13);
  CHECK(score(unstable) < 2);
  CHECK_FALSE(mediocre.input_error);
  // The unstable gains: stopped by the watchdog with a time, and explained by the screening.
  CHECK(anyTestSays(unstable, "unstable: the rail force left its safe range"));
  CHECK(anyTestSays(unstable, "at t = "));
  CHECK(unstable.results["output"].get<std::string>().find("unstable, closed-loop pole") != std::string::npos);
  CHECK(unstable.results["output"].get<std::string>().find("the delay alone destabilises it") != std::string::npos);
  // Leaderboard from the nominal run: tracking RMS in mm.
  REQUIRE(mediocre.results.contains("leaderboard"));
  CHECK(mediocre.results["leaderboard"][0]["value"].get<double>() ==
        doctest::Approx(mediocre.results["extra_data"]["scenarios"]["nominal"]["metrics"]["x_rms"].get<double>() * 1000));
}

TEST_CASE("the instructor's submission scores at least 90 %" * doctest::skip(!test::instructorFilesPresent())) {
  const GradeOutcome good = grade(test::instructorDir("slider_crank") + "good.json");
  REQUIRE(maxScore(good) == doctest::Approx(15));
  CHECK(score(good) >= 0.9 * 15);  // no design earns every point: the rubric trades gains against each other
  CHECK_FALSE(good.input_error);
}

TEST_CASE("malformed submissions score 0 with a message naming file, JSON path and expectation") {
  struct Case {
    std::string name, text, expect;
  };
  const std::vector<Case> cases = {
      {"not_json.json", "{\"lab\": \"slider_crank\", gains", "expected valid JSON"},
      {"empty.json", "", "the file is empty"},
      {"array.json", "[1, 2]", "/: expected an object"},
      {"unknown_lab.json", R"({"lab": "pendulum", "gains": {}})", "/lab: expected the name of a dynlab lab"},
      {"unknown_gain.json", R"({"lab": "slider_crank", "gains": {"kp_x": 1, "kd_x": 1, "kp_f": 0, "ki_f": 1, "kq": 2}})",
       "/gains/kq: unknown gain"},
      {"missing_gain.json", R"({"lab": "slider_crank", "gains": {"kp_x": 1, "kd_x": 1, "kp_f": 0}})",
       "/gains: missing key \"ki_f\""},
      {"wrong_type.json", R"({"lab": "slider_crank", "gains": {"kp_x": "400", "kd_x": 1, "kp_f": 0, "ki_f": 1}})",
       "/gains/kp_x: expected a number"},
      {"out_of_range.json", R"({"lab": "slider_crank", "gains": {"kp_x": -5, "kd_x": 1, "kp_f": 0, "ki_f": 1}})",
       "/gains/kp_x: expected a number in [0, 20000]"},
      {"infinite.json", R"({"lab": "slider_crank", "gains": {"kp_x": 1e999, "kd_x": 1, "kp_f": 0, "ki_f": 1}})",
       "number overflow parsing '1e999'"},
      {"extra_key.json", R"({"lab": "slider_crank", "gains": {"kp_x": 1, "kd_x": 1, "kp_f": 0, "ki_f": 1}, "code": "rm -rf"})",
       "/code: unknown key"},
      {"bad_option.json", R"({"lab": "slider_crank", "force_law": "magic", "gains": {"kp_x": 1, "kd_x": 1, "kp_f": 0, "ki_f": 1}})",
       "/force_law: expected one of"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.name);
    const std::string file = writeFile(c.name, c.text);
    const GradeOutcome g = grade(file);
    CHECK(g.input_error);
    CHECK(score(g) == 0.0);
    const std::string out = g.results.at("output").get<std::string>();
    // The student's file by its name, never the grader's folders it sits in.
    CHECK(out.find(std::filesystem::path(file).filename().string() + ": ") != std::string::npos);
    CHECK(out.find(std::filesystem::path(file).parent_path().string()) == std::string::npos);
    CHECK(out.find(c.expect) != std::string::npos);
  }
  // A file far too large is refused before it is read.
  const std::string big = writeFile("big.json", std::string(2u << 20, ' ') + "{}");
  const GradeOutcome g = grade(big);
  CHECK(g.input_error);
  CHECK(g.results.at("output").get<std::string>().find("expected at most") != std::string::npos);
  // A submission for another lab than the assignment's.
  GradeOptions o;
  o.expected_lab = "unicycle";
  CHECK(grade(kMediocre, o).results.at("output").get<std::string>().find("this assignment's lab") != std::string::npos);
}

TEST_CASE("grading twice gives the same results apart from execution_time; replay detects a change") {
  const GradeOutcome a = grade(kMediocre), b = grade(kMediocre);
  json ja = a.results, jb = b.results;
  ja.erase("execution_time");
  jb.erase("execution_time");
  CHECK(ja.dump() == jb.dump());
  CHECK(compareResults(a.results, b.results).empty());
  // The noisy scenario's seed comes from the submission: other gains, other trajectories.
  const auto fp = a.results["extra_data"]["fingerprint"];
  CHECK(fp["trajectory_hash"] != grade(kExamples + "proportional.json").results["extra_data"]["fingerprint"]["trajectory_hash"]);
  // A tampered score is reported.
  json tampered = a.results;
  tampered["tests"][0]["score"] = 3.0;
  const auto diff = compareResults(tampered, b.results);
  REQUIRE(diff.size() == 1);
  CHECK(diff[0].find("/tests/0/score") != std::string::npos);
}

TEST_CASE("results.json has Gradescope's field names and types") {
  int partial = 0;  // tests with partial credit seen (the mediocre gains earn some)
  for (const std::string& f : {kMediocre, kExamples + "unstable_integral.json", writeFile("bad.json", "{")}) {
    CAPTURE(f);
    const json r = grade(f).results;
    CHECK(r.at("score").is_number());
    CHECK(r.at("execution_time").is_number());
    CHECK(r.at("output").is_string());
    CHECK(r.at("output_format") == "md");
    REQUIRE(r.at("tests").is_array());
    for (const auto& t : r["tests"]) {
      CHECK(t.at("name").is_string());
      CHECK(t.at("number").is_string());
      CHECK(t.at("score").is_number());
      CHECK(t.at("max_score").is_number());
      CHECK(t.at("score").get<double>() <= t.at("max_score").get<double>() + 1e-12);
      CHECK(t.at("score").get<double>() >= 0.0);
      const std::string status = t.at("status");
      CHECK((status == "passed" || status == "failed"));
      // Gradescope shows "failed" in red: partial credit (0.94 / 1) passed, only no credit failed.
      CHECK(status == (t.at("score").get<double>() > 0 ? "passed" : "failed"));
      partial += t.at("score").get<double>() > 0 && t.at("score").get<double>() < t.at("max_score").get<double>();
      CHECK(t.at("output").is_string());
      const std::string vis = t.at("visibility");
      CHECK((vis == "visible" || vis == "hidden" || vis == "after_due_date" || vis == "after_published"));
    }
    if (r.contains("leaderboard"))
      for (const auto& l : r["leaderboard"]) {
        CHECK(l.at("name").is_string());
        CHECK(l.at("value").is_number());
        CHECK((l.at("order") == "asc" || l.at("order") == "desc"));
      }
  }
  CHECK(partial > 0);
}

TEST_CASE("the time budget and the step budget stop runs without losing the grade") {
  GradeOptions o;
  o.time_budget = 1e-6;  // already over when the first run starts
  const GradeOutcome late = grade(kMediocre, o);
  CHECK_FALSE(late.input_error);
  CHECK(anyTestSays(late, "not graded: the grading time budget ran out"));
  CHECK(late.results["tests"].size() == 10);
  // Screening needs no simulation: its two tests are still scored, as a full grade scores them.
  const GradeOutcome whole = grade(kMediocre);
  double screened = 0;
  int graded = 0;
  for (std::size_t i = 0; i < late.results["tests"].size(); ++i) {
    if (!late.results["tests"][i]["extra_data"].value("value", json()).is_number()) continue;  // not measured
    screened += whole.results["tests"][i]["score"].get<double>();
    ++graded;
  }
  CHECK(graded == 2);
  CHECK(score(late) == doctest::Approx(screened));

  // A lab config whose watchdog allows 100 steps: every run exceeds it.
  json config = json::parse(std::ifstream(std::string(DYNLAB_SOURCE_DIR) + "/labs/slider_crank/slider_crank.json"));
  config["rubric"]["watchdog"]["max_steps"] = 100;
  GradeOptions s;
  s.config_file = writeFile("short_budget.json", config.dump());
  const GradeOutcome g = grade(kMediocre, s);
  CHECK(anyTestSays(g, "exceeded its step budget of 100 steps"));
}

TEST_CASE("a rubric naming a metric the lab does not report is the staff's error (internal), not the student's") {
  json config = json::parse(std::ifstream(std::string(DYNLAB_SOURCE_DIR) + "/labs/slider_crank/slider_crank.json"));
  config["rubric"]["tests"][0]["metric"] = "x_rsm";
  GradeOptions o;
  o.config_file = writeFile("typo_rubric.json", config.dump());
  const GradeOutcome g = grade(kMediocre, o);
  // An internal error (issue 27): the details for the staff, no server path or "fix it" for the student.
  CHECK(g.internal_error);
  const std::string detail = g.results["extra_data"]["internal_error"], out = g.results["output"];
  CHECK(detail.find("typo_rubric.json") != std::string::npos);
  CHECK(detail.find("/rubric/tests/0/metric") != std::string::npos);
  CHECK(out.find("typo_rubric.json") == std::string::npos);
  CHECK(out.find("Fix it") == std::string::npos);
}

// Regressions from sanitizing and fuzzing the grader's inputs (tests/fuzz, scripts/sanitize).

namespace {
json defaultLabConfig() {
  return json::parse(std::ifstream(std::string(DYNLAB_SOURCE_DIR) + "/labs/slider_crank/slider_crank.json"));
}
// parseRubric's InputError for the default config with `rubric` merged into its rubric.
std::string rubricError(const json& rubric_patch) {
  const json config = mergePatch(defaultLabConfig(), {{"rubric", rubric_patch}});
  try {
    parseRubric(JsonView(config, "rubric.json"));
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}
}  // namespace

TEST_CASE("a deeply nested submission scores 0 as bad input (it overflowed the stack)") {
  const std::string f = writeFile("deep.json", std::string(200000, '[') + std::string(200000, ']'));
  const GradeOutcome g = grade(f);
  CHECK(g.input_error);
  CHECK(g.results["output"].get<std::string>().find("expected JSON nested at most 64 levels deep") != std::string::npos);
}

TEST_CASE("bad rubric values name /rubric/... instead of throwing json errors or scoring NaN") {
  CHECK(rubricError({{"seed_target", "/~2"}}) ==
        "rubric.json: /rubric/seed_target: expected a JSON pointer such as \"/controller/seed\", got \"/~2\"");
  CHECK(rubricError({{"seed_target", "/"}}).find("/rubric/seed_target: expected a JSON pointer") != std::string::npos);
  // Points and scale that overflow the total score or the leaderboard to inf (results.json: null).
  json tests = defaultLabConfig()["rubric"]["tests"];
  tests[0]["points"] = 1e308;
  CHECK(rubricError({{"tests", tests}}).find("/rubric/tests/0/points: expected a positive number ≤ 10000") !=
        std::string::npos);
  CHECK(rubricError({{"leaderboard", {{{"name", "x"}, {"metric", "x_rms"}, {"scale", 1e300}}}}})
            .find("/rubric/leaderboard/0/scale: expected a positive number ≤ 1e+09") != std::string::npos);
  CHECK(rubricError({{"watchdog", {{"limits", {{{"column", "v_c"}, {"min", 1.0}, {"max", -1.0}}}}}}})
            .find("/rubric/watchdog/limits/0/max: expected max ≥ min") != std::string::npos);
  // Thresholds at the ends of the double range: (zero − m)/(zero − full) = inf/inf.
  const double credit = partialCredit(-1e308, -1e308, 1e308);
  CHECK_FALSE(std::isnan(credit));
  CHECK(credit >= 0.0);
  CHECK(credit <= 1.0);
}

TEST_CASE("a scenario patch that removes the seed's object is the config's error, not an internal one") {
  // seed_target /controller/seed with "controller": 5 in a patch: json's operator[] threw a
  // type_error and the grader reported "internal error".
  json config = defaultLabConfig();
  config["rubric"]["scenarios"]["long_delay"]["patch"] = {{"controller", 5}};
  GradeOptions o;
  o.config_file = writeFile("seedless_rubric.json", config.dump());
  const GradeOutcome g = grade(kMediocre, o);
  // The staff's file: an internal error (issue 27) whose details name the path, for the staff.
  CHECK(g.internal_error);
  const std::string detail = g.results["extra_data"]["internal_error"];
  CHECK(detail.find("/rubric/seed_target") != std::string::npos);
  CHECK(detail.find("scenario long_delay") != std::string::npos);
}

TEST_CASE("a rubric plot of a column the lab lacks is the config's error, found before any run") {
  // The column was silently left out of the plot (a typo passing unnoticed); a plot with no known
  // column, reference or band failed as an "internal error" after every scenario had run.
  json config = defaultLabConfig();
  config["rubric"]["tests"][1]["plot"]["columns"] = {"f_y"};
  GradeOptions o;
  o.config_file = writeFile("plot_column_rubric.json", config.dump());
  o.out_dir = (tempDir() / "plot_column_out").string();
  const GradeOutcome g = grade(kMediocre, o);
  CHECK(g.internal_error);  // the staff's file (issue 27)
  const std::string detail = g.results["extra_data"]["internal_error"];
  CHECK(detail.find("/rubric/tests/1/plot/columns/0") != std::string::npos);
  CHECK(detail.find("expected a trace column of this lab") != std::string::npos);
}

TEST_CASE("feedback gives every metric its unit: the lab's metric_docs, and the screening's own") {
  const GradeOutcome g = grade(kMediocre);
  REQUIRE_FALSE(g.input_error);
  CHECK(g.report.find("x_rms = 0.01166 m (full 0.0003 m, zero 0.003 m)") != std::string::npos);
  CHECK(g.report.find("f_rms = 0.1496 N (full 0.02 N, zero 0.1 N)") != std::string::npos);
  CHECK(g.report.find("force_delay_margin = 0.1963 s (full 0.03 s, zero 0.01 s)") != std::string::npos);
  CHECK(g.report.find("motion_damping = 0.1981 (full 0.7, zero 0.2)") != std::string::npos);  // dimensionless
  // The student's view (results.json, HTML) and report.md's table say the same.
  bool found = false;
  for (const auto& t : g.results.at("tests"))
    if (t.at("name") == "Slider tracks x_d(t)") found = t.at("output").get<std::string>().find("= <strong>0.01166 m</strong>; full credit at 0.0003 m") != std::string::npos;
  CHECK(found);
  CHECK(g.markdown.find("| 0.01166 m | 0.0003 m | 0.003 m |") != std::string::npos);
}
