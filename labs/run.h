// Running a lab: build it from a config file (+ gains), and run one engine into a Trace.
// Shared by the CLI, the grader, the benchmark and the tests.
#pragma once
#include <functional>
#include <optional>

#include "labs/lab.h"
#include "labs/variants.h"

namespace dyn {

struct LoadedLab {
  const LabEntry* entry = nullptr;
  json config;                 // after gains and overrides
  std::string config_file;
  std::unique_ptr<Lab> lab;
};

// Loads LAB's config (default path unless config_file is given), puts it on `plant` (a student's:
// labs/variants.h), applies a gains file and a duration override, and builds the lab. Throws
// InputError on any bad input.
LoadedLab loadLab(const std::string& name, const std::string& config_file = "", const std::string& gains_file = "",
                  std::optional<double> duration = std::nullopt, const PlantChoice& plant = {});
// Builds a lab from a config already in memory (file names the source for error messages).
std::unique_ptr<Lab> buildLab(const LabEntry& entry, const json& config, const std::string& file);

struct RunResult {
  Trace trace;
  std::string failure;  // empty when the run reached its duration
};
// Runs one engine to the lab's duration (or max_steps). on_steps, when given, hears the steps done
// so far every 1024 steps and once at the end (a progress bar's hook; it must not throw).
RunResult runEngine(const Lab& lab, Engine engine, long max_steps = -1,
                    const std::function<void(long steps)>& on_steps = {});

}  // namespace dyn
