// The lab contract (labs/lab.h), checked on one lab: every_lab_test runs it on each registered lab,
// and a test may register a scratch lab (registerLab / unregisterLab) and run it on that too. The
// checks themselves are app/cli/authoring/lab_check.h (the same ones `dynlab check-lab LAB` prints): config,
// examples, engines, drift independent, passive energy, metrics, grading, defaults (20–50 %), plots,
// lessons (each holds), doing nothing (below the defaults), instructor answers (≥ 90 %), render, and
// cli (`dynlab figure`, `dynlab run`, `dynlab grade`: exit 0). Here each must be ok; a failure
// prints its one-line reason. The window's check (`dynlab ui` under xvfb-run) is below.
#pragma once
#include <doctest/doctest.h>

#include <iostream>
#include <string>
#include <utility>

#include "app/cli/authoring/lab_check.h"
#include "labs/run.h"
#include "tests/app/cli_run.h"

namespace dyn::test {

struct LabCheckOptions {
  std::string examples_dir;  // default: <source>/labs/<name>/examples
  bool cli = true;           // the dynlab binary knows the lab (false for a test's scratch lab)
  std::pair<double, double> defaults_band{0.2, 0.5};  // the share of points the default gains score
  std::string lab_dir;       // where the lessons' paths start (default: <source>/labs/<name>)
  std::string instructor_dir;  // the full-credit answers (default: <source>/labs/<name>/instructor; "-": none)
};

// Runs every check but the window's on one lab (config: its default config); each must hold.
inline void checkLab(const LabEntry& entry, const json& config, const LabCheckOptions& options = {}) {
  const cli::TempDir dir("every_lab_" + entry.name);
  dyn::LabCheckOptions o;
  o.work_dir = dir.path.string();
  o.examples_dir = options.examples_dir;
  o.lab_dir = options.lab_dir.empty() ? std::string(DYNLAB_SOURCE_DIR) + "/labs/" + entry.name : options.lab_dir;
  o.instructor_dir = options.instructor_dir;
  o.defaults_band = options.defaults_band;
  if (options.cli) o.dynlab_binary = DYNLAB_BIN;
  const LabCheckReport report = dyn::checkLab(entry, config, o);
  REQUIRE_FALSE(report.checks.empty());
  for (const LabCheck& c : report.checks) {
    INFO("lab ", entry.name, ": ", c.check);
    CHECK_MESSAGE(c.ok, c.check << ": " << c.detail);
  }
  MESSAGE(entry.name, ": the default gains score ", report.defaults_share * 100, " %; passive |E − E0| ≤ ",
          report.passive_drift, " over ", report.passive_duration, " s (E0 = ", report.passive_e0, ", tolerance ",
          report.passive_tolerance, " relative)");
  for (const auto& [file, share] : report.instructor_shares) MESSAGE(entry.name, ": ", file, " scores ", share * 100, " %");
}

// `dynlab ui LAB --frames 3` in a virtual X display; false (and DYNLAB_TEST_SKIPPED printed, so
// ctest reports the test skipped) when xvfb-run is missing.
inline bool checkWindow(const LabEntry& entry) {
  if (!cli::haveXvfb()) {
    std::cout << "DYNLAB_TEST_SKIPPED: xvfb-run (packages xvfb, xauth) not found; the window checks did not run\n";
    return false;
  }
  INFO("lab ", entry.name, ": dynlab ui");
  const cli::TempDir dir("every_lab_ui_" + entry.name);
  const cli::Result r = cli::run(dir, cli::inXvfb({DYNLAB_BIN, "ui", entry.name, "--frames", "3"}));
  INFO(r.out, r.err);
  CHECK(r.code == 0);
  return true;
}

}  // namespace dyn::test
