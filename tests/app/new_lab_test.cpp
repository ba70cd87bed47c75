// A lab without C++, as the lecturer's walk-through in docs/teaching.md makes one: `dynlab new-lab
// fourbar_lab --from fivebar --labs DIR` into a folder outside the tree, the copy's JSON edited into a
// four-bar exercise (the tree's assets/models/fourbar.xml, found from outside it; one actuated crank, the
// pin's x on a path), and nothing else. The folder's lab is found with --labs (dynlab list), runs on
// both engines with the loop closed to rounding level, grades, and its handout (the prose new-lab
// wrote) builds; the check-lab contract's mechanical checks pass on it. Bad uses of new-lab get one
// line and exit 2, and write nothing.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include "tests/app/cli_run.h"

using namespace dyn::test::cli;
using json = nlohmann::json;

namespace {

// The JSON edits of the walk-through (README "A new exercise without C++").
void makeFourBar(json& d) {
  d["title"] = "Four-bar: move the rocker's pin with the crank";
  d["model_file"] = "assets/models/fourbar.xml";
  d["actuated"] = {"crank"};
  d["torque_limit"] = {10.0};
  d["tool"] = {{"closure", "pin_C"}, {"axes", {"x"}}};
  d["initial"] = {{"actuated_deg", {0.0}}};
  d["trajectory"] = {{"segments", json::parse(R"J([{"hold": 0.2}, {"move": [0.36], "time": 0.6}, {"move": [0.42], "time": 0.8}, {"hold": 0.4}])J")}};
  d["plant"] = {{"payloads", json::parse(R"J([{"body": "coupler", "at": [0.4, 0.0, 0.3], "mass": 0.0}])J")}};
  d["simulation"]["duration"] = 2.0;
  d["metrics"] = json::parse(R"J({"e_rms": {"of": "e_x", "stat": "rms"}, "pin_force_peak": {"of": ["f_pin_C_x", "f_pin_C_z"], "stat": "max"},
                                 "tau_variation": {"of": "tau_crank", "stat": "variation"}})J");
  json docs = json::object();
  for (const char* k : {"e_rms", "pin_force_peak", "tau_variation", "energy_drift", "max_constraint_residual"}) docs[k] = d["metric_docs"][k];
  d["metric_docs"] = docs;
  d["figures"] = json::parse(R"J([{"plot": "e_x", "title": "tracking error of the pin", "ylabel": "e (m)"}, {"plot": "tau_crank", "title": "crank torque", "ylabel": "τ (N·m)"}])J");
  json& r = d["rubric"];
  r["scenarios"]["payload"]["patch"]["plant"]["payloads"][0]["body"] = "coupler";
  r["scenarios"]["payload"]["patch"]["plant"]["payloads"][0]["at"] = {0.4, 0.0, 0.3};
  r["watchdog"]["limits"] = json::parse(R"J([{"column": "e_x", "min": -0.3, "max": 0.3, "what": "the pin's x error"}])J");
  json tests = json::array();
  for (json t : r["tests"]) {
    const std::string m = t["metric"];
    if (m == "e_rms") t["plot"]["columns"] = {"e_x"};
    else if (m == "tau_variation") t["plot"]["columns"] = {"tau_crank"};
    else if (m != "pin_force_peak") continue;
    tests.push_back(t);
  }
  r["tests"] = tests;
}

}  // namespace

TEST_CASE("new-lab: a four-bar exercise from the five-bar by editing JSON only") {
  const TempDir dir("new_lab");
  const fs::path labs = dir / "course";
  fs::create_directories(labs);
  const std::vector<std::string> in = {"--labs", labs.string()};

  Result r = dynlab(dir, cat({"new-lab", "fourbar_lab", "--from", "fivebar"}, in));
  INFO(r.out, r.err);
  REQUIRE(r.code == 0);
  const fs::path lab = labs / "fourbar_lab";
  CHECK(fs::exists(lab / "fourbar_lab.json"));
  CHECK_FALSE(fs::exists(lab / "fivebar.json"));
  CHECK(fs::exists(lab / "handout.md"));
  // The staff page is the new lab's stub, not the five-bar's notes on its answer's gains and grade.
  const std::string notes = readFile(lab / "instructor/README.md");
  CHECK(notes.find("# Lab fourbar_lab: instructor files") == 0);
  CHECK(notes.find(readFile(fs::path(DYNLAB_SOURCE_DIR) / "labs/fivebar/instructor/README.md").substr(0, 60)) == std::string::npos);
  // The copy is a lab of its own name, its examples and answers too.
  CHECK(json::parse(readFile(lab / "fourbar_lab.json"))["lab"] == "fourbar_lab");
  CHECK(json::parse(readFile(lab / "examples/task_pd.json"))["lab"] == "fourbar_lab");
  CHECK(json::parse(readFile(lab / "instructor/good.json"))["lab"] == "fourbar_lab");
  // No C++ anywhere in it.
  for (const auto& e : fs::recursive_directory_iterator(lab)) CHECK(e.path().extension() != ".cpp");

  // The lecturer's edits, JSON only; the five-bar's own model file is no longer used.
  json d = json::parse(readFile(lab / "fourbar_lab.json"));
  makeFourBar(d);
  writeFile(lab / "fourbar_lab.json", d.dump(1));
  fs::remove(lab / "fivebar.xml");

  r = dynlab(dir, cat({"list"}, in));
  CHECK(r.out.find("fourbar_lab      Four-bar: move the rocker's pin with the crank") != std::string::npos);

  // Both engines, the whole run; the hand engine keeps the loop closed to rounding level.
  r = dynlab(dir, cat({"run", "fourbar_lab", "--out", "run"}, in));
  INFO(r.out, r.err);
  REQUIRE(r.code == 0);
  const json summary = json::parse(readFile(dir / "run/summary.json"));
  CHECK(summary["engines"]["hand"]["metrics"]["max_constraint_residual"].get<double>() <= 1e-12);
  CHECK(summary["engines"]["hand"]["metrics"]["steps"] == 2000);
  CHECK(summary["agreement"]["max_dq"].get<double>() < 1e-3);
  const Csv trace = readCsv(dir / "run/trace_hand.csv");
  CHECK(std::find(trace.header.begin(), trace.header.end(), "tau_crank") != trace.header.end());
  CHECK(std::find(trace.header.begin(), trace.header.end(), "f_pin_C_x") != trace.header.end());

  // The instructor's answer (task-space inverse dynamics) grades, and tracks the pin's path.
  r = dynlab(dir, cat({"grade", (lab / "instructor/good.json").string(), "--out", "grade", "--no-plots"}, in));
  REQUIRE(r.code == 0);
  const json results = json::parse(readFile(dir / "grade/results.json"));
  double max = 0;
  for (const auto& t : results.at("tests")) max += t.at("max_score").get<double>();
  double stated = 0;  // the points of the tests the lecturer kept (makeFourBar)
  for (const auto& t : d["rubric"]["tests"]) stated += t.at("points").get<double>();
  CHECK(max == stated);
  CHECK(results.at("score").get<double>() > 0.9 * max);

  // The handout builds from the prose new-lab wrote (the five-bar's names its second crank and its
  // circle segment, which the edit removed), and names the lab.
  r = dynlab(dir, cat({"handout", "fourbar_lab", "--out", "handout"}, in));
  INFO(r.err);
  CHECK(r.code == 0);
  CHECK(readFile(dir / "handout/handout.md").find("assets/models/fourbar.xml") != std::string::npos);

  // The contract's mechanical checks hold on it (the rubric's tuning checks are the lecturer's next step),
  // and the handout and README checks.
  r = dynlab(dir, cat({"check-lab", "fourbar_lab", "--skip-cli"}, in));
  for (const char* check : {"config ", "examples ", "engines ", "passive energy ", "metrics ", "grading ", "render ", "handout ", "readme "}) {
    INFO("check ", check, "\n", r.out);
    CHECK(r.out.find("  ok    " + std::string(check)) != std::string::npos);
  }
}

TEST_CASE("new-lab: bad uses get one line and exit 2, and write nothing") {
  const TempDir dir("new_lab_bad");
  fs::create_directories(dir / "labs");
  const std::vector<std::string> to = {"--labs", (dir / "labs").string()};
  struct Case {
    std::vector<std::string> args;
    std::string says;
  };
  for (const Case& c :
       {Case{cat({"new-lab", "copy", "--from", "slider_crank"}, to), "a C++ lab"},
        Case{cat({"new-lab", "Bad", "--from", "fivebar"}, to), "expected a lab name"},
        Case{cat({"new-lab", "../up", "--from", "fivebar"}, to), "expected a lab name"},
        Case{cat({"new-lab", "copy", "--from", "no_such_lab"}, to), "no lab folder"},
        Case{cat({"new-lab", "fivebar", "--from", "fivebar"}, to), "a lab of that name exists"},
        Case{{"new-lab", "copy", "--from", "fivebar", "--labs", (dir / "missing").string()}, "expected an existing folder"}}) {
    INFO(shown(c.args));
    const Result r = dynlab(dir, c.args);
    CHECK(r.code == 2);
    CHECK(r.err.find(c.says) != std::string::npos);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    CHECK(fs::is_empty(dir / "labs"));
  }
  // An existing folder is never overwritten.
  fs::create_directories(dir / "labs/copy");
  writeFile(dir / "labs/copy/keep.txt", "mine");
  const Result r = dynlab(dir, cat({"new-lab", "copy", "--from", "fivebar"}, to));
  CHECK(r.code == 2);
  CHECK(readFile(dir / "labs/copy/keep.txt") == "mine");
  CHECK_FALSE(fs::exists(dir / "labs/copy/copy.json"));
}
