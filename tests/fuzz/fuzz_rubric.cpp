// libFuzzer target: arbitrary bytes as the "rubric" object of the default slider-crank config —
// parseRubric, then what the grader does with it before and after simulating: each scenario's
// merge patch and derived seed on the config (buildLab), the watchdog's columns (RowWatch), a
// short watched run, and scores from partial credit. Expected outcome: dyn::InputError.
#include <chrono>
#include <cstdint>

#include "grading/rubric.h"
#include "grading/scenario.h"
#include "tests/fuzz/fuzz_common.h"

using namespace dyn;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const std::string file = "fuzz_rubric.json";
  try {
    json config = fuzz::defaultConfig();
    config["rubric"] = parseJsonText(text, file);
    const Rubric rubric = parseRubric(JsonView(config, file));
    checkColumns(rubric, buildLab(fuzz::sliderCrank(), config, file)->columns(), file);  // as the grader does
    const double max_score = rubric.maxScore();
    if (!std::isfinite(max_score)) fuzz::bug("non-finite max score");
    for (const Scenario& sc : rubric.scenarios) {
      json cfg = mergePatch(config, sc.patch);
      writeSeed(cfg, rubric, 12345, file, sc.name);
      const auto lab = buildLab(fuzz::sliderCrank(), cfg, file + " (scenario " + sc.name + ")");
      Watchdog wd = rubric.watchdog;
      wd.max_steps = std::min(wd.max_steps, 100L);
      const ScenarioRun run = runScenario(*lab, wd, std::chrono::steady_clock::now() + std::chrono::seconds(60), file);
      fuzz::checkFinite(run.trace, run.failure, "hand (watched)");
      for (const RubricTest& t : rubric.tests) {
        if (t.scenario != sc.name || !run.metrics.contains(t.metric)) continue;
        const double s = t.points * partialCredit(run.metrics[t.metric].get<double>(), t.full, t.zero);
        if (!std::isfinite(s)) fuzz::bug("non-finite score for test " + t.name);
      }
      for (const LeaderboardEntry& l : rubric.leaderboard)
        if (l.scenario == sc.name && run.metrics.contains(l.metric) &&
            !std::isfinite(run.metrics[l.metric].get<double>() * l.scale) &&
            std::isfinite(run.metrics[l.metric].get<double>()))
          fuzz::bug("non-finite leaderboard value for " + l.name);
    }
  } catch (const InputError&) {
  }
  return 0;
}
