// tests/web/web_required.h: how a web test that cannot run here ends. By default it prints
// DYNLAB_TEST_SKIPPED (ctest: skipped), so scripts/test passes on a machine without node, Chromium or
// scripts/web's build/web. With DYNLAB_REQUIRE_WEB=1 in the environment (CI: .ci/run) the same reason is
// a failure, so a CI run cannot pass without the web tests having run.
#pragma once

#include <doctest/doctest.h>

#include <cstdlib>
#include <cstring>
#include <iostream>
#include <string>

namespace dyn::test {

// True when the test must stop here: why is not empty (what cannot run, e.g. "no Chromium"), and
// notDone says what was not checked. Fails the test instead of skipping it under DYNLAB_REQUIRE_WEB=1.
inline bool webTestCannotRun(const std::string& why, const std::string& notDone) {
  if (why.empty()) return false;
  const char* required = std::getenv("DYNLAB_REQUIRE_WEB");
  if (required && std::strcmp(required, "1") == 0)
    FAIL_CHECK("DYNLAB_REQUIRE_WEB=1, but " << why << "; " << notDone);  // never the skip marker
  else
    std::cout << "DYNLAB_TEST_SKIPPED: " << why << "; " << notDone << "\n";
  return true;
}

}  // namespace dyn::test
