// Loading and running labs; see run.h.
#include "labs/run.h"

#include <algorithm>

#include "labs/submission.h"
#include "labs/variants.h"

namespace dyn {

std::unique_ptr<Lab> buildLab(const LabEntry& entry, const json& config, const std::string& file) {
  const JsonView view(config, file);
  checkSubmissionOptions(view);
  auto lab = entry.create(view);
  // Every lab has the shared simulation block (labs/settings.h); its own parse refused what it cannot honour.
  parseSimulation(view["simulation"], IndependentForm::Yes);
  // A plant per student (variants.h): its ranges checked with the lab (a scenario may move a varied
  // value outside them: the config as written is held to them where it is loaded).
  parseVariants(view, false);
  // The run's trace too (a row of the lab's columns per step): the bound every path shares (settings.h).
  if (const std::string problem = runBoundProblem(lab->dt(), lab->duration(), lab->columns().size()); !problem.empty())
    view["simulation"].fail(problem);
  return lab;
}

LoadedLab loadLab(const std::string& name, const std::string& config_file, const std::string& gains_file,
                  std::optional<double> duration, const PlantChoice& plant) {
  LoadedLab out;
  out.entry = findLab(name);
  if (!out.entry) {
    std::string list;
    for (const auto& e : labRegistry()) list += (list.empty() ? "" : ", ") + e.name;
    throw InputError("<command line>", "LAB", "unknown lab \"" + name + "\" (available: " + list + "; a lab outside the dynlab tree: --labs DIR)");
  }
  out.config_file = config_file.empty() ? defaultConfigPath(name) : config_file;
  out.config = loadJsonFile(out.config_file);
  // Validate the config itself first, so its errors name the config file.
  buildLab(*out.entry, out.config, out.config_file);
  out.config = plantConfig(out.config, plant, name, out.config_file);
  std::string source = out.config_file;
  if (!gains_file.empty()) {
    const json gains = loadJsonFile(gains_file, 1u << 20);
    out.config = applySubmission(out.config, JsonView(gains, gains_file), name, false);
    source = gains_file;
  }
  if (duration) requestRunDuration(out.config, *duration, "<command line>", "--duration");
  out.lab = buildLab(*out.entry, out.config, source);
  return out;
}

RunResult runEngine(const Lab& lab, Engine engine, long max_steps, const std::function<void(long)>& on_steps) {
  // Held again here, for a lab built some other way than buildLab: never a trace past the bound.
  if (max_steps < 0 || double(max_steps) > kMaxSteps)
    if (const std::string problem = runBoundProblem(lab.dt(), lab.duration(), lab.columns().size()); !problem.empty())
      throw InputError("<run>", "/simulation", problem);
  RunResult r;
  r.trace.columns = lab.columns();
  auto sim = lab.simulate(engine);
  std::vector<double> row;
  double rows = lab.duration() / lab.dt() + 1;
  if (max_steps >= 0) rows = std::min(rows, double(max_steps) + 1);
  r.trace.data.reserve(std::size_t(rows) * r.trace.columns.size());
  long k = 0;
  for (; (max_steps < 0 || k < max_steps) && sim->step(row); ++k) {
    r.trace.append(row);
    if (on_steps && (k & 1023) == 1023) on_steps(k + 1);
  }
  if (on_steps) on_steps(k);
  r.failure = sim->failure();
  return r;
}

}  // namespace dyn
