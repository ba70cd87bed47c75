// dynlab check-lab LAB: the every-lab contract (app/cli/authoring/lab_check.h) on one lab, for whoever writes a
// lab: each check with ok/FAIL and one line, then the shares the grade gives and the passive drift.
// Two checks of the lab's prose follow the contract's: the handout builds as `dynlab handout` builds
// it, and the lab's README.md is there, valid UTF-8, titled, names the lab and links only to files
// that exist.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <sstream>

#include "app/cli/commands.h"
#include "app/cli/course/course.h"
#include "app/cli/authoring/lab_check.h"
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

// The handout, built in memory as `dynlab handout LAB` builds it.
LabCheck handoutCheck(const std::string& lab) {
  try {
    HandoutArgs args;
    args.lab = lab;
    const std::string md = handoutText(args).markdown;
    return {"handout", true, "builds as `dynlab handout " + lab + "` writes it (" +
                                 std::to_string(std::count(md.begin(), md.end(), '\n')) + " lines of Markdown)"};
  } catch (const std::exception& e) {
    return {"handout", false, std::string("`dynlab handout ") + lab + "` fails: " + e.what()};
  }
}

// What is wrong with the lab's README.md, or "" (detail then says what holds).
std::string readmeProblem(const std::string& lab, std::string& detail) {
  const fs::path file = fs::path(labFolder(lab)) / "README.md";
  std::string text;
  try {
    text = readTextFile(file.string(), 1u << 20);  // a regular file, valid UTF-8, no NUL, at most 1 MB
  } catch (const InputError& e) {
    return e.what();
  }
  std::string bare = text;  // without HTML comments (notes to the author)
  for (std::size_t a; (a = bare.find("<!--")) != std::string::npos;) {
    const std::size_t b = bare.find("-->", a);
    bare.erase(a, b == std::string::npos ? std::string::npos : b + 3 - a);
  }
  std::istringstream lines(bare);
  std::string first;
  while (std::getline(lines, first) && first.find_first_not_of(" \t\r") == std::string::npos) {
  }
  if (first.rfind("# ", 0) != 0) return file.string() + ": expected a title line \"# ...\" first";
  // Plain scans, no std::regex: libstdc++'s recurses per character and a README may be 1 MB. The name
  // anywhere (in a path too: motion_control's README names it in motion_control_test.cpp).
  const bool named = bare.find(lab) != std::string::npos;
  if (!named) return file.string() + ": expected the lab's name " + lab + " in it (is it another lab's README?)";
  // Relative links ("[text](path)", "![pic](path)") name files that exist, from the README's folder.
  int links = 0;
  for (std::size_t at = bare.find("]("); at != std::string::npos; at = bare.find("](", at + 2)) {
    const std::size_t end = bare.find_first_of(") \t\r\n", at + 2);
    if (end == std::string::npos || bare[end] != ')' || end == at + 2) continue;
    std::string target = bare.substr(at + 2, end - at - 2);
    if (target.find("://") != std::string::npos || target.rfind("mailto:", 0) == 0 || target[0] == '#') continue;
    target = target.substr(0, target.find('#'));
    std::error_code ec;
    if (!fs::exists(file.parent_path() / target, ec)) return file.string() + ": the link " + target + " names no file";
    ++links;
  }
  detail = "README.md: valid UTF-8, titled, names " + lab + ", " + std::to_string(links) + " relative link(s) resolve";
  return "";
}

LabCheck readmeCheck(const std::string& lab) {
  std::string detail;
  const std::string problem = readmeProblem(lab, detail);
  return {"readme", problem.empty(), problem.empty() ? detail : problem};
}

}  // namespace

int checkLab(const CheckLabArgs& args) {
  const LabEntry* entry = findLab(args.lab);
  if (!entry) {
    std::string list;
    for (const auto& e : labRegistry()) list += (list.empty() ? "" : ", ") + e.name;
    std::fprintf(stderr, "error: <command line>: LAB: unknown lab \"%s\" (known labs: %s; a lab outside the dynlab tree: --labs DIR)\n",
                 termText(args.lab).c_str(), list.c_str());
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
  std::printf("dynlab check-lab %s: the lab contract (%s)\n", entry->name.c_str(), termText(labFolder(entry->name)).c_str());
  std::fflush(stdout);
  LabCheckReport report = dyn::checkLab(*entry, config, options);
  // The handout is built from the config too: only once it builds (else the same error, again).
  if (report.checks.front().ok) report.checks.push_back(handoutCheck(entry->name));
  report.checks.push_back(readmeCheck(entry->name));
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
