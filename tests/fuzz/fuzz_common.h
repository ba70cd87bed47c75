// Shared pieces of the libFuzzer targets (tests/fuzz/*.cpp): the default slider-crank config and
// an example submission loaded once, and the checks every target applies to what got through
// validation. Bad input must end as dyn::InputError; anything else (another exception type, a
// sanitizer report, a hang, a non-finite value in an unflagged trace) is a bug and aborts here.
#pragma once
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "labs/run.h"
#include "labs/submission.h"

namespace dyn::fuzz {

inline const LabEntry& sliderCrank() {
  static const LabEntry* e = findLab("slider_crank");
  if (!e) std::abort();
  return *e;
}

inline const json& defaultConfig() {
  static const json c = loadJsonFile(defaultConfigPath("slider_crank"));
  return c;
}

inline const json& exampleSubmission() {
  static const json s =
      loadJsonFile(std::string(DYNLAB_SOURCE_DIR) + "/labs/slider_crank/examples/proportional.json");
  return s;
}

[[noreturn]] inline void bug(const std::string& what) {
  std::fprintf(stderr, "FUZZ BUG: %s\n", what.c_str());
  std::fflush(stderr);
  std::abort();
}

// A run that reports no failure must have a finite trace (the README's promise: non-finite
// values are reported, never written silently).
inline void checkFinite(const Trace& t, const std::string& failure, const char* engine) {
  if (!failure.empty()) return;
  for (std::size_t i = 0; i < t.data.size(); ++i)
    if (!std::isfinite(t.data[i]))
      bug(std::string(engine) + ": non-finite " + t.columns[i % t.columns.size()] + " at row " +
          std::to_string(i / t.columns.size()) + " without a failure");
}

}  // namespace dyn::fuzz
