// dynlab check-lab LAB: the every-lab contract (app/lab_check.h) on one lab, for whoever writes a
// lab: each check with ok/FAIL and one line, then the shares the grade gives and the passive drift.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "app/commands.h"
#include "app/lab_check.h"
#include "grading/escape.h"
#include "labs/config.h"

namespace dyn::app {
namespace {

namespace fs = std::filesystem;

std::string percent(double share) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f %%", share * 100);
  return b;
}

std::string shares(const std::vector<std::pair<std::string, double>>& list) {
  std::string s;
  for (const auto& [file, share] : list) s += (s.empty() ? "" : ", ") + termText(file) + " " + percent(share);
  return s.empty() ? "(none graded)" : s;
}

// A scratch folder for the submissions and runs the checks write, removed afterwards.
struct ScratchDir {
  fs::path path;
  explicit ScratchDir(const std::string& lab)
      : path(fs::temp_directory_path() / ("dynlab_check_lab_" + lab + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~ScratchDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

}  // namespace

int checkLab(const CheckLabArgs& args) {
  const LabEntry* entry = findLab(args.lab);
  if (!entry) {
    std::string list;
    for (const auto& e : labRegistry()) list += (list.empty() ? "" : ", ") + e.name;
    std::fprintf(stderr, "error: <command line>: LAB: unknown lab \"%s\" (known labs: %s)\n", termText(args.lab).c_str(), list.c_str());
    return 2;
  }
  json config;
  try {
    config = loadJsonFile(defaultConfigPath(entry->name));
  } catch (const InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  const auto start = std::chrono::steady_clock::now();
  const ScratchDir dir(entry->name);
  LabCheckOptions options;
  options.work_dir = dir.path.string();
  options.config_file = defaultConfigPath(entry->name);
  if (!args.skip_cli) {
    std::error_code ec;
    options.dynlab_binary = fs::read_symlink("/proc/self/exe", ec).string();
  }
  std::printf("dynlab check-lab %s: the lab contract (%s)\n", entry->name.c_str(),
              fs::path(defaultConfigPath(entry->name)).parent_path().c_str());
  std::fflush(stdout);
  const LabCheckReport report = dyn::checkLab(*entry, config, options);
  int failed = 0;
  std::size_t width = 0;
  for (const LabCheck& c : report.checks) width = std::max(width, c.check.size());
  for (const LabCheck& c : report.checks) {
    std::printf("  %-4s  %-*s  %s\n", c.ok ? "ok" : "FAIL", int(width), termText(c.check).c_str(), termText(c.detail).c_str());
    failed += !c.ok;
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::printf("default gains:       %s of the points\n", std::isnan(report.defaults_share) ? "(not graded)" : percent(report.defaults_share).c_str());
  std::printf("examples:            %s\n", shares(report.example_shares).c_str());
  std::printf("instructor answers:  %s\n", shares(report.instructor_shares).c_str());
  if (std::isnan(report.passive_drift))
    std::printf("passive drift:       (not measured)\n");
  else
    std::printf("passive drift:       max |E − E0| = %.3g over %.3g s, relative %.3g (tolerance %.3g)\n", report.passive_drift,
                report.passive_duration, report.passive_drift / (report.passive_e0 != 0 ? std::abs(report.passive_e0) : 1.0),
                report.passive_tolerance);
  std::printf("%s: %zu of %zu checks pass (%.1f s)\n", entry->name.c_str(), report.checks.size() - failed, report.checks.size(), seconds);
  if (failed) std::fprintf(stderr, "error: %d check(s) of the lab contract fail for %s\n", failed, entry->name.c_str());
  return failed ? 1 : 0;
}

}  // namespace dyn::app
