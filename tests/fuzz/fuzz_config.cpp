// libFuzzer target: arbitrary bytes as a lab config (slider_crank.json) through the real loading
// path in memory — parse, buildLab, the example gains applied as `--gains` would, the submission
// schema — then a few hundred steps of each engine, the lab's metrics and its linearised loops,
// so the physics sees whatever values got past validation. An object without a "lab" key is
// taken as a merge patch on the default config (as a rubric scenario's patch is), which reaches
// the physics far more often than whole mutated configs. Expected outcome for bad input:
// dyn::InputError. See fuzz_common.h for what counts as a bug.
#include <cstdint>

#include "tests/fuzz/fuzz_common.h"

using namespace dyn;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    json config = parseJsonText(text, "fuzz_config.json");
    if (config.is_object() && !config.contains("lab")) config = mergePatch(fuzz::defaultConfig(), config);
    buildLab(fuzz::sliderCrank(), config, "fuzz_config.json");
    // As loadLab does with --gains: the submission's gains and options on this config.
    const json applied = applySubmission(config, JsonView(fuzz::exampleSubmission(), "proportional.json"), "slider_crank", false);
    const auto lab = buildLab(fuzz::sliderCrank(), applied, "proportional.json");
    (void)submissionSchema(config, "slider_crank").dump();
    for (const Engine engine : {Engine::Hand, Engine::Bullet}) {
      const RunResult r = runEngine(*lab, engine, 200);
      fuzz::checkFinite(r.trace, r.failure, name(engine));
      if (r.failure.empty()) (void)lab->metrics(r.trace).dump();
    }
    for (const LinearLoop& loop : lab->linearise())  // the grader's screening reads these
      for (const Poly* p : {&loop.num, &loop.den})
        for (double c : *p)
          if (!std::isfinite(c)) fuzz::bug("loop " + loop.name + " has a non-finite coefficient");
  } catch (const InputError&) {
  }
  return 0;
}
