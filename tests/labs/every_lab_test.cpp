// The lab contract on every registered lab (tests/labs/lab_checks.h): a new lab folder is checked
// here without a line of test code. The window check is its own ctest entry
// (labs_every_lab_window_test), so a machine without xvfb-run reports only it as skipped.
#include <doctest/doctest.h>

#include "tests/labs/lab_checks.h"

using namespace dyn;

TEST_CASE("every registered lab keeps the lab contract") {
  REQUIRE_FALSE(labRegistry().empty());
  for (const LabEntry& entry : labRegistry()) {
    CAPTURE(entry.name);
    test::checkLab(entry, loadJsonFile(defaultConfigPath(entry.name)));
  }
}

TEST_CASE("every registered lab opens in the tuning window" * doctest::skip()) {
  for (const LabEntry& entry : labRegistry())
    if (!test::checkWindow(entry)) return;
}
