// The same grade in WebAssembly as natively (issues 46 and 42): every shipped example of every lab,
// noisy scenarios included, graded by the native `dynlab grade --no-plots` and by the
// core compiled with emscripten (build/web/dynlab-grade.js, run by node), gives the same results.json
// bytes but execution_time. results.json carries each scenario's trace_hash and the fingerprint's
// trajectory_hash, so the traces are compared too. The model-file labs (fivebar, puma_motion,
// puma_impedance) too: the web build has no MuJoCo parser and reads their models' descriptions, which
// scripts/web exports with the native dynlab (docs/model_descriptions.md). Skipped (DYNLAB_TEST_SKIPPED)
// when scripts/web has not been run or node is missing; a failure instead under DYNLAB_REQUIRE_WEB=1 (CI).
#include <doctest/doctest.h>

#include <iostream>

#include "tests/app/cli_run.h"
#include "tests/app/lab_examples.h"
#include "tests/web/web_required.h"

using namespace dyn::test::cli;
using dyn::test::labExamples;
using dyn::test::withoutExecutionTime;

namespace {

const fs::path kGrader = fs::path(DYNLAB_SOURCE_DIR) / "build" / "web" / "dynlab-grade.js";

// A source of the web build changed after it was built ("" when none did): the wasm would grade old code.
std::string newerSource() {
  const auto built = fs::last_write_time(kGrader);
  for (const char* dir : {"physics", "labs", "grading"})
    for (const auto& e : fs::recursive_directory_iterator(fs::path(DYNLAB_SOURCE_DIR) / dir)) {
      const std::string ext = e.path().extension().string();
      if (e.is_regular_file() && (ext == ".cpp" || ext == ".h") && e.last_write_time() > built) return e.path().string();
    }
  // app/web's own sources of the grader (not the page's: they do not relink it).
  for (const char* file : {"grade_main.cpp", "web_no_plots.cpp", "node_env.js"})
    if (const fs::path p = fs::path(DYNLAB_SOURCE_DIR) / "app" / "web" / file; fs::last_write_time(p) > built) return p.string();
  return "";
}

// Why the wasm side cannot run here ("" when it can).
std::string missing() {
  if (!onPath("node")) return "node is not installed (package nodejs)";
  if (!fs::exists(kGrader)) return kGrader.string() + " is not built (run scripts/web)";
  if (const std::string newer = newerSource(); !newer.empty()) return newer + " changed after build/web was built (run scripts/web)";
  return "";
}

bool skipped() { return dyn::test::webTestCannotRun(missing(), "the web grade was not compared"); }

Result webGrade(const TempDir& dir, const std::string& lab, const fs::path& submission) {
  ProcessOptions o;
  o.timeout_s = 600;  // a hang is a failure, not a stuck suite
  return run(dir, {"node", kGrader.string(), lab, submission.string()}, o);
}

void checkLab(const std::string& lab) {
  TempDir dir("web_same_grade_" + lab);
  const auto files = labExamples(lab);
  CHECK(!files.empty());
  for (const fs::path& ex : files) {
    CAPTURE(ex);
    const std::string out = (dir / ex.stem().string()).string();
    const Result native = dynlab(dir, {"grade", ex.string(), "--lab", lab, "--no-plots", "--out", out});
    const Result web = webGrade(dir, lab, ex);
    CAPTURE(web.err);
    CHECK(native.code == web.code);
    CHECK(fs::exists(fs::path(out) / "results.json"));
    const std::string expected = withoutExecutionTime(readFile(fs::path(out) / "results.json")),
                      actual = withoutExecutionTime(web.out);
    CHECK(expected == actual);
    if (expected != actual) writeFile(dir.path.parent_path() / ("web_same_grade_" + lab + "_" + ex.stem().string() + ".json"), web.out);
  }
}

}  // namespace

// All nine labs: the six with C++ code and the three model-file labs, whose models the wasm grader reads
// from the descriptions scripts/web exported (a difference is a failed check, never the end of the loop).
TEST_CASE("every lab: the same results.json in WebAssembly") {
  if (skipped()) return;
  for (const std::string lab : {"slider_crank", "pen_on_table", "unicycle", "grasp", "impedance", "motion_control", "fivebar", "puma_motion",
                                "puma_impedance"}) {
    CAPTURE(lab);
    checkLab(lab);
  }
}

// A lab whose model file has no exported description (a copy of fivebar under DYNLAB_HOME naming its
// model by another name): the wasm grader has no MuJoCo parser, and refuses it in one line saying how to
// export it, exit 3 (the lab's file, not the submission, cannot be read: an internal error).
TEST_CASE("a model file without a description: refused in one line by the web grader, saying how to export it") {
  if (skipped()) return;
  TempDir dir("web_same_grade_models");
  const fs::path home = dir / "home", lab = home / "labs" / "fivebar";
  fs::create_directories(lab.parent_path());
  fs::copy(fs::path(DYNLAB_SOURCE_DIR) / "labs" / "fivebar", lab, fs::copy_options::recursive);
  fs::rename(lab / "fivebar.xml", lab / "other_fivebar.xml");
  std::string config = readFile(lab / "fivebar.json");
  const std::string named = "\"model_file\": \"fivebar.xml\"";
  REQUIRE(config.find(named) != std::string::npos);
  config.replace(config.find(named), named.size(), "\"model_file\": \"other_fivebar.xml\"");
  writeFile(lab / "fivebar.json", config);
  ProcessOptions o = withEnv({{"DYNLAB_HOME", home.string()}});
  o.timeout_s = 600;
  const Result web = run(dir, {"node", kGrader.string(), "fivebar", labExamples("fivebar").front().string()}, o);
  CAPTURE(web.err);
  CHECK(web.code == 3);
  CHECK(std::count(web.err.begin(), web.err.end(), '\n') == 1);
  CHECK(web.err.find("other_fivebar.xml: not a dynlab model description") != std::string::npos);
  CHECK(web.err.find("--export") != std::string::npos);
}
