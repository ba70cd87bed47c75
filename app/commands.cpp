// dynlab list / run / grade / schema.
#include "app/commands.h"

#include <cstdio>
#include <iostream>

#include "app/movie.h"
#include "app/output.h"
#include "grading/grade.h"
#include "labs/run.h"
#include "labs/submission.h"

namespace fs = std::filesystem;

namespace dyn::app {

int listLabs() {
  for (const auto& e : labRegistry()) std::printf("%-16s %s\n", e.name.c_str(), e.summary.c_str());
  return 0;
}

int runLab(const RunArgs& a) {
  LoadedLab loaded;
  try {
    loaded = loadLab(a.lab, a.config, a.gains, a.duration);
  } catch (const InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  const Lab& lab = *loaded.lab;
  const fs::path out = a.out.empty() ? fs::path("out") / a.lab : fs::path(a.out);
  try {
    // Simulate first; nothing is written until every run is done.
    std::optional<RunResult> hand, bullet;
    if (a.engine != "bullet") hand = runEngine(lab, Engine::Hand);
    if (a.engine != "hand") bullet = runEngine(lab, Engine::Bullet);

    Staging staging(out);
    json summary = {{"lab", a.lab},
                    {"config", loaded.config_file},
                    {"gains", a.gains.empty() ? json(nullptr) : json(a.gains)},
                    {"dt", lab.dt()},
                    {"duration", lab.duration()},
                    {"dynlab_version", DYNLAB_VERSION}};
    std::string status = "ok";
    for (auto* r : {&hand, &bullet}) {
      if (!*r) continue;
      const char* engine = r == &hand ? "hand" : "bullet";
      staging.write(std::string("trace_") + engine + ".csv", (*r)->trace.csv());
      summary["engines"][engine] = {{"metrics", lab.metrics((*r)->trace)},
                                    {"status", (*r)->failure.empty() ? "ok" : (*r)->failure},
                                    {"trace_hash", (*r)->trace.hash()}};
      if (!(*r)->failure.empty()) status = std::string(engine) + ": " + (*r)->failure;
    }
    if (hand && bullet) summary["agreement"] = lab.agreement(hand->trace, bullet->trace);
    summary["status"] = status;
    staging.write("summary.json", summary.dump(2) + "\n");

    int frames = 0;
    if (a.video || a.frames) {
      const Trace& shown = hand ? hand->trace : bullet->trace;
      const Trace* ghost = hand && bullet ? &bullet->trace : nullptr;
      frames = renderRun(lab, shown, ghost, {640, 480, 30, a.video, a.frames}, staging.path(""));
    }
    staging.commit();

    // Tell the user where things are and the headline numbers.
    std::printf("dynlab run %s: %.2f s at dt = %g s (%s)\n", a.lab.c_str(), lab.duration(), lab.dt(), status.c_str());
    for (auto* r : {&hand, &bullet}) {
      if (!*r) continue;
      const char* engine = r == &hand ? "hand" : "bullet";
      std::printf("  %-6s trace    %s\n", engine, (out / (std::string("trace_") + engine + ".csv")).c_str());
    }
    std::printf("  summary         %s\n", (out / "summary.json").c_str());
    if (a.video) std::printf("  video           %s (%d frames)\n", (out / "video.mp4").c_str(), frames);
    if (a.frames) std::printf("  frames          %s/ (%d PNG)\n", (out / "frames").c_str(), frames);
    if (summary.contains("agreement")) {
      const json& ag = summary["agreement"];
      std::printf("  hand vs Bullet: max |dq| = %.3g rad, max |dx_c| = %.3g m, max |df| = %.3g N\n",
                  ag["max_dq"].get<double>(), ag["max_dx_c"].get<double>(), ag["max_df"].get<double>());
    }
    return status == "ok" ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
}

int gradeOne(const GradeArgs& a) {
  const GradeOutcome g = gradeSubmission(a.submission);
  try {
    fs::create_directories(a.out);
    writeFileAtomic(fs::path(a.out) / "results.json", g.results.dump(2) + "\n");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: cannot write results: %s\n", e.what());
    return 1;
  }
  std::fputs(g.report.c_str(), stdout);
  std::printf("results: %s\n", (fs::path(a.out) / "results.json").c_str());
  return g.input_error ? 2 : 0;
}

int printSchema(const std::string& lab) {
  try {
    const LoadedLab loaded = loadLab(lab);
    std::cout << submissionSchema(loaded.config, lab).dump(2) << "\n";
    return 0;
  } catch (const InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
}

}  // namespace dyn::app
