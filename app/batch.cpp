// dynlab grade --batch DIR --jobs N --out OUT: every submission in DIR graded in its own child
// process (`dynlab grade FILE --out OUT/<name>`), N at a time. A child that crashes or hangs
// (killed after its time budget) still gets a results.json saying so; the batch goes on.
// Then OUT/gradebook.csv: submission, score, max_score, status, one column per test.
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <map>
#include <thread>

#include "app/commands.h"
#include "app/output.h"
#include "labs/config.h"

extern char** environ;

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace dyn::app {
namespace {

struct Job {
  fs::path submission, out;
  pid_t pid = -1;
  Clock::time_point started;
  bool killed = false;
};

std::string selfExe() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  return ec ? std::string("dynlab") : p.string();
}

// Starts `dynlab grade` for one submission, output and errors into OUT/<name>/grade.log.
pid_t spawnGrade(const GradeArgs& a, const Job& job) {
  fs::create_directories(job.out);
  std::vector<std::string> args = {selfExe(), "grade", job.submission.string(), "--out", job.out.string(),
                                   "--time-budget", std::to_string(a.time_budget)};
  if (!a.lab.empty()) args.insert(args.end(), {"--lab", a.lab});
  if (!a.config.empty()) args.insert(args.end(), {"--config", a.config});
  if (!a.plots) args.push_back("--no-plots");
  std::vector<char*> argv;
  for (auto& s : args) argv.push_back(s.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  const std::string log = (job.out / "grade.log").string();
  posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
  pid_t pid = -1;
  const int rc = posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  return rc == 0 ? pid : -1;
}

// A results.json for a submission whose grader process did not produce one.
void writeFallback(const Job& job, const std::string& why, const std::string& status) {
  const json r = {{"score", 0.0},
                  {"output", "**This submission could not be graded:** " + why + "\n\nThe course staff have been told."},
                  {"output_format", "md"},
                  {"tests", json::array()},
                  {"extra_data", {{"status", status}}}};
  writeFileAtomic(job.out / "results.json", r.dump(2) + "\n");
}

std::string csvField(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

// One gradebook row from a results.json (status from how the grade went).
struct Row {
  std::string name, status;
  double score = 0, max_score = 0;
  std::vector<std::pair<std::string, double>> tests;  // in rubric order
};

Row readRow(const Job& job, const std::string& process_status) {
  Row row{job.submission.filename().string(), process_status, 0, 0, {}};
  try {
    const json r = loadJsonFile((job.out / "results.json").string());
    row.score = r.value("score", 0.0);
    for (const auto& t : r.value("tests", json::array())) {
      row.tests.emplace_back(t.value("name", "?"), t.value("score", 0.0));
      row.max_score += t.value("max_score", 0.0);
    }
    const json extra = r.value("extra_data", json::object());
    if (process_status == "graded") {
      if (extra.contains("error")) row.status = "invalid submission";
      else {
        const json scenarios = extra.value("scenarios", json::object());  // kept alive for the loop
        for (const auto& [_, s] : scenarios.items())
          if (s.value("status", "completed") != "completed") row.status = "graded (unstable run)";
      }
    }
  } catch (const std::exception&) {
    row.status = "no results";
  }
  return row;
}

}  // namespace

int gradeBatch(const GradeArgs& a) {
  std::vector<fs::path> files;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(a.batch, ec))
    if (e.path().extension() == ".json" && !e.is_directory()) files.push_back(e.path());
  if (ec) {
    std::fprintf(stderr, "error: %s: cannot read the submissions directory (%s)\n", a.batch.c_str(), ec.message().c_str());
    return 2;
  }
  std::sort(files.begin(), files.end());
  const fs::path out = a.out;
  fs::create_directories(out);
  const bool tty = isatty(STDERR_FILENO);
  // A grader process gets its own budget plus a margin to write its results, then it is killed.
  const double kill_s = a.time_budget + std::clamp(a.time_budget, 2.0, 30.0);
  const auto kill_after = std::chrono::milliseconds(long(kill_s * 1e3));

  std::vector<Job> pending, running;
  for (const auto& f : files) pending.push_back({f, out / f.stem(), -1, {}, false});
  std::reverse(pending.begin(), pending.end());
  std::map<std::string, Row> rows;
  std::size_t done = 0, problems = 0;
  auto progress = [&](const Row& r) {
    ++done;
    if (r.status != "graded") ++problems;
    if (tty) {
      const int width = 30, filled = int(width * done / std::max<std::size_t>(1, files.size()));
      std::fprintf(stderr, "\r[%s%s] %zu/%zu graded, %zu need a look ", std::string(std::size_t(filled), '#').c_str(),
                   std::string(std::size_t(width - filled), ' ').c_str(), done, files.size(), problems);
    } else {
      std::fprintf(stderr, "graded %zu/%zu: %s %.2f/%.2f %s\n", done, files.size(), r.name.c_str(), r.score, r.max_score,
                   r.status.c_str());
    }
  };
  while (!pending.empty() || !running.empty()) {
    // Keep N graders busy.
    while (!pending.empty() && int(running.size()) < std::max(1, a.jobs)) {
      Job j = pending.back();
      pending.pop_back();
      j.started = Clock::now();
      j.pid = spawnGrade(a, j);
      if (j.pid < 0) {
        writeFallback(j, "the grader could not be started", "not started");
        rows[j.submission.filename()] = readRow(j, "not started");
        progress(rows[j.submission.filename()]);
        continue;
      }
      running.push_back(j);
    }
    // Reap finished graders; kill the ones past their budget.
    bool any = false;
    for (auto it = running.begin(); it != running.end();) {
      int status = 0;
      const pid_t r = waitpid(it->pid, &status, WNOHANG);
      if (r == 0) {
        if (!it->killed && Clock::now() - it->started > kill_after) {
          kill(it->pid, SIGKILL);
          it->killed = true;
        }
        ++it;
        continue;
      }
      any = true;
      std::string st = "graded";
      if (it->killed) {
        st = "timed out";
        writeFallback(*it, "grading did not finish within " + std::to_string(long(kill_s)) + " s", st);
      } else if (WIFSIGNALED(status)) {
        st = "crashed";
        writeFallback(*it, std::string("the grader stopped with signal ") + std::to_string(WTERMSIG(status)) + " (" +
                               strsignal(WTERMSIG(status)) + ")", st);
      } else if (!fs::exists(it->out / "results.json")) {
        st = "no results";
        writeFallback(*it, "the grader exited without writing results", st);
      }
      const Row row = readRow(*it, st);
      rows[row.name] = row;
      progress(row);
      it = running.erase(it);
    }
    if (!any) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (tty) std::fprintf(stderr, "\n");

  // The gradebook: one row per submission (sorted), one column per test (rubric order).
  std::vector<std::string> tests;
  for (const auto& [_, r] : rows)
    for (const auto& [t, __] : r.tests)
      if (std::find(tests.begin(), tests.end(), t) == tests.end()) tests.push_back(t);
  std::string csv = "submission,score,max_score,status";
  for (const auto& t : tests) csv += "," + csvField(t);
  csv += "\n";
  char num[32];
  for (const auto& [name, r] : rows) {
    csv += csvField(name);
    for (double x : {r.score, r.max_score}) {
      std::snprintf(num, sizeof num, ",%.4g", x);
      csv += num;
    }
    csv += "," + csvField(r.status);
    for (const auto& t : tests) {
      const auto it = std::find_if(r.tests.begin(), r.tests.end(), [&](const auto& p) { return p.first == t; });
      if (it == r.tests.end()) csv += ",";
      else {
        std::snprintf(num, sizeof num, ",%.4g", it->second);
        csv += num;
      }
    }
    csv += "\n";
  }
  writeFileAtomic(out / "gradebook.csv", csv);
  std::printf("graded %zu submission(s) into %s; gradebook: %s\n", files.size(), out.c_str(), (out / "gradebook.csv").c_str());
  if (problems) std::printf("%zu submission(s) need a look (see the status column)\n", problems);
  return 0;
}

}  // namespace dyn::app
