// Grading throughput for `dynlab bench`: CPU seconds of one full rubric grade (every scenario,
// screening, scoring; in-process, hand-written engine), without and with the response plots.
// The target: < 0.1 s of CPU, so 1,000 submissions grade in under a minute on two cores.
#include <sys/resource.h>

#include <algorithm>
#include <filesystem>

#include "app/cli/bench/bench.h"
#include "app/cli/commands.h"
#include "grading/grade.h"
#include "labs/lab.h"

namespace dyn::app {
namespace {

// This process's CPU time and its reaped children's: a lone grade draws its plots in a forked child
// (grading/isolated.h), which RUSAGE_SELF alone would leave out (about half of a graded submission).
double cpuSeconds() {
  double s = 0;
  for (int who : {RUSAGE_SELF, RUSAGE_CHILDREN}) {
    rusage u{};
    getrusage(who, &u);
    s += double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
  }
  return s;
}

// Median CPU seconds of grading `file` `repeats` times.
double gradeCpu(const std::string& file, const GradeOptions& o, int repeats) {
  std::vector<double> t;
  for (int i = 0; i < repeats; ++i) {
    const double t0 = cpuSeconds();
    gradeSubmission(file, o);
    t.push_back(cpuSeconds() - t0);
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

}  // namespace

json gradeThroughput(const std::string& lab, int repeats) {
  // The lab's full-credit submission (its instructor folder), if it has one.
  const std::string file = std::filesystem::path(defaultConfigPath(lab)).parent_path() / "instructor" / "good.json";
  if (!std::filesystem::exists(file)) return json::object();
  GradeOptions o;
  const double plain = gradeCpu(file, o, repeats);
  const ScratchDir scratch("dynlab-bench-grade");
  o.out_dir = scratch.path().string();
  const double plots = gradeCpu(file, o, std::max(1, repeats / 2));
  return {{"grade_cpu_s", plain},
          {"grade_cpu_s_with_plots", plots},
          {"grade_per_s_per_core", plain > 0 ? 1.0 / plain : 0.0},
          {"class_of_1000_on_2_cores_s", 1000 * plots / 2}};  // the measure: graded with plots
}

}  // namespace dyn::app
