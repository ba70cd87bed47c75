// libFuzzer target: arbitrary bytes as a submission against the default slider-crank config, the
// grader's path in memory — parse, the fingerprint's canonical dump, applySubmission (strict),
// buildLab, screening of the linearised loops, and a short scenario under the rubric's watchdog
// (step budget cut to 300). Expected outcome for bad input: dyn::InputError.
#include <chrono>
#include <cstdint>

#include "grading/rubric.h"
#include "grading/scenario.h"
#include "tests/fuzz/fuzz_common.h"

using namespace dyn;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const Rubric rubric = parseRubric(JsonView(fuzz::defaultConfig(), "slider_crank.json"));
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const json sub = parseJsonText(text, "fuzz_submission.json");
    (void)sub.dump();  // the grader hashes the canonical dump
    const JsonView view(sub, "fuzz_submission.json");
    view.requireObject();
    (void)view["lab"].string();
    const json applied = applySubmission(fuzz::defaultConfig(), view, "slider_crank", true);
    const auto lab = buildLab(fuzz::sliderCrank(), applied, "fuzz_submission.json");
    const ScreenResult screen = screenLoops(*lab);
    for (const auto& [k, v] : screen.metrics.items())
      if (!v.is_number() || std::isnan(v.get<double>())) fuzz::bug("screening metric " + k + " is " + v.dump());
    Watchdog wd = rubric.watchdog;
    wd.max_steps = 300;
    const ScenarioRun run = runScenario(*lab, wd, std::chrono::steady_clock::now() + std::chrono::seconds(60),
                                        "slider_crank.json");
    fuzz::checkFinite(run.trace, run.failure, "hand (watched)");
  } catch (const InputError&) {
  }
  return 0;
}
