// dynlab grade --batch DIR --jobs N --out OUT: every submission in DIR graded in its own child
// process (a fork running `dynlab grade FILE --out OUT/<folder>`'s code), N at a time, under a lock on OUT. A grader
// that exits with anything but 0 (graded) or 2 (invalid submission), crashes or hangs (killed after
// its time budget) gets a results.json saying so; the batch goes on. Then OUT/gradebook.csv and
// its summary, OUT/gradebook.md.
#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <thread>

#include "app/cli/course/batch.h"
#include "app/cli/commands.h"
#include "app/cli/output.h"
#include "labs/config.h"
#include "labs/lab.h"
#include "grading/escape.h"
#include "grading/plot.h"
#include "labs/utf8.h"
#include "grading/student.h"
#include "labs/variants.h"

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace dyn::app {
namespace {

using batch::Row;
using batch::Submission;

// The names a grade writes into its folder: cleared before each grade, so none is left from the last run.
constexpr const char* kGradeOutputs[] = {"results.json", "report.md", "report.html", "plots", ".staging"};

struct Job {
  Submission sub;
  fs::path out;  // OUT/<folder>
  pid_t pid = -1;
  Clock::time_point started;
  bool killed = false;
};

// OUT/.dynlab-batch.lock, flocked for the batch's life (the kernel drops it if the batch is killed).
// Returns the fd, or -1 with `why` set when another batch holds it or it cannot be opened.
int lockOut(const fs::path& out, std::string& why) {
  const fs::path file = out / ".dynlab-batch.lock";
  const int fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (fd < 0) {
    why = "cannot open the lock file " + file.string() + " (" + std::strerror(errno) + ")";
    return -1;
  }
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    why = errno == EWOULDBLOCK ? "another dynlab grade --batch is writing into this folder (" + file.string() +
                                     " is locked); wait for it to finish, or give another --out"
                               : "cannot lock " + file.string() + " (" + std::strerror(errno) + ")";
    ::close(fd);
    return -1;
  }
  return fd;
}

// Empties a submission's folder of the last grade's outputs and opens a fresh grade.log in it.
// Returns the log's fd (-1 with `why` set if the folder cannot be prepared).
int prepareFolder(const fs::path& folder, std::string& why) {
  std::error_code ec;
  fs::create_directories(folder, ec);
  for (const char* name : kGradeOutputs)
    if (!ec) fs::remove_all(folder / name, ec);
  if (ec) {
    why = "cannot prepare " + folder.string() + " (" + ec.message() + ")";
    return -1;
  }
  const int fd = ::open((folder / "grade.log").c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (fd < 0) why = "cannot write " + (folder / "grade.log").string() + " (" + std::strerror(errno) + ")";
  return fd;
}

// Grades one submission in a child process, output and errors into its grade.log: a fork of the
// batch running what `dynlab grade FILE --out OUT/<folder>` runs (gradeOne), without an exec, so
// the ~150 shared libraries are loaded once per batch instead of once per submission (about half
// of a grade's CPU time without plots). A crash or hang still takes only the child. The child dies
// with the batch (PR_SET_PDEATHSIG), so a killed batch leaves no grader writing into OUT.
pid_t spawnGrade(const GradeArgs& a, const Job& job, int log_fd) {
  GradeArgs one;
  one.submission = fs::absolute(job.sub.file).string();
  one.out = job.out.string();
  one.time_budget = a.time_budget;
  one.lab = a.lab;
  one.config = a.config;
  one.student = job.sub.student;
  one.plots = a.plots;
  const pid_t parent = ::getpid();
  std::fflush(nullptr);  // nothing the batch has buffered is written again by the child
  const pid_t pid = ::fork();
  if (pid != 0) return pid;
  // The child (the batch is single-threaded, so it may run anything).
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (::getppid() != parent) ::_exit(127);
  const int null_fd = ::open("/dev/null", O_RDONLY);
  if (null_fd < 0 || ::dup2(null_fd, 0) < 0 || ::dup2(log_fd, 1) < 0 || ::dup2(log_fd, 2) < 0) ::_exit(127);
  int code = 3;
  try {
    code = gradeOne(one);
  } catch (const std::exception& e) {  // as main() reports what escapes a command
    std::string line = utf8Quotable(e.what());
    for (char& c : line)
      if (static_cast<unsigned char>(c) < 0x20) c = ' ';
    std::fprintf(stderr, "error: internal: %s\n", line.c_str());
  } catch (...) {
    std::fprintf(stderr, "error: internal: an exception that is not a std::exception\n");
  }
  std::fflush(nullptr);
  ::_exit(code);
}

// The last non-empty line of a grader's log (what it said before it failed), at most 300 bytes.
std::string logTail(const fs::path& log) {
  std::ifstream in(log, std::ios::binary);
  std::string line, last;
  while (std::getline(in, line))
    if (line.find_first_not_of(" \t\r") != std::string::npos) last = line;
  if (last.size() > 300) last = last.substr(0, 300) + "...";
  return last;
}

// The row of a finished grader, from how it ended; a results.json is written for every failure.
Row finish(const Job& job, int status, double kill_s) {
  const fs::path results = job.out / "results.json";
  Row row;
  if (job.killed) {
    row = batch::failedRow(job.sub, "timed out", "grading did not finish within " + std::to_string(long(kill_s)) + " s");
  } else if (WIFSIGNALED(status)) {
    row = batch::failedRow(job.sub, "crashed", "internal error: the grader stopped with signal " +
                                                   std::to_string(WTERMSIG(status)) + " (" + strsignal(WTERMSIG(status)) + ")");
  } else {
    row = batch::rowFromResults(job.sub, results, WEXITSTATUS(status), logTail(job.out / "grade.log"));
    if (row.status != "internal error") return row;
  }
  try {
    batch::writeFallbackResults(results, row);
  } catch (const std::exception& e) {
    row.reason += " (and its results.json could not be written: " + std::string(e.what()) + ")";
  }
  return row;
}

// The summary with the batch's lab stated under its heading.
std::string withLab(std::string md, const std::string& lab_line) {
  const std::size_t at = md.find("\n\n");
  const std::string line = mdText(lab_line.substr(0, 1).size() ? "Lab" + lab_line.substr(3) : lab_line) + "\n\n";
  return at == std::string::npos ? md + "\n" + line : md.insert(at + 2, line);
}

// The batch's lab, known before the first grade: --lab, else the lab the first submission (in name
// order) that names a known lab names. Every grader gets it, so a submission for another lab is an
// invalid row naming both labs, never graded against its own rubric. source: where it came from.
std::string batchLab(const GradeArgs& a, const batch::Found& found, std::string& source) {
  source = "--lab";
  if (!a.lab.empty()) return a.lab;
  for (const auto& s : found.submissions) {
    if (!s.problem.empty()) continue;
    try {
      const json j = loadJsonFile(s.file.string(), 1u << 20);
      if (j.is_object() && j.contains("lab") && j["lab"].is_string() && findLab(j["lab"].get<std::string>())) {
        source = "the first submission naming a lab, " + s.folder;
        return j["lab"].get<std::string>();
      }
    } catch (const std::exception&) {
      // Not valid: the next one decides.
    }
  }
  return "";
}

// A lab with variants grades each submission on its student's plant: the IDs come first. Throws InputError.
void assignPlants(const GradeArgs& args, const std::string& roster, batch::Found& found) {
  if (!args.lab.empty() && declaresVariants(args.config.empty() ? defaultConfigPath(args.lab) : args.config)) {
    if (courseSecret().empty())
      throw InputError("<command line>", "--batch", "expected DYNLAB_COURSE_SECRET to be set: " + args.lab +
                                                    " gives each student their own plant, drawn from the course secret");
    batch::assignStudents(found.submissions, roster);
  } else if (!roster.empty()) {
    throw InputError("<command line>", "--roster", "expected a lab with variants (a plant per student); " + args.lab + " has none");
  }
}

// Every submission graded, N graders at a time, each in its own process under its budget (killed past
// it); one row each, in the order they finish, with a bar (a terminal) or a line each (a log).
std::vector<Row> runGraders(const GradeArgs& args, const batch::Found& found, const fs::path& out, std::size_t& problems) {
  const std::size_t total = found.submissions.size();
  const bool tty = isatty(STDERR_FILENO);
  // A grader process gets its own budget plus a margin to write its results, then it is killed.
  const double kill_s = args.time_budget + std::clamp(args.time_budget, 2.0, 30.0);
  const auto kill_after = std::chrono::milliseconds(long(kill_s * 1e3));
  std::vector<Row> rows;
  auto progress = [&](Row r) {
    if (r.status != "graded") ++problems;
    if (tty) {
      const int width = 30, filled = int(width * (rows.size() + 1) / std::max<std::size_t>(1, total));
      std::fprintf(stderr, "\r[%s%s] %zu/%zu graded, %zu need a look ", std::string(std::size_t(filled), '#').c_str(),
                   std::string(std::size_t(width - filled), ' ').c_str(), rows.size() + 1, total, problems);
    } else {
      // The folder name, not the raw file name: it is plain ASCII and says where the results are.
      std::fprintf(stderr, "graded %zu/%zu: %s %.2f %s\n", rows.size() + 1, total, r.folder.c_str(), r.score, r.status.c_str());
    }
    rows.push_back(std::move(r));
  };
  std::vector<Job> pending, running;
  for (auto it = found.submissions.rbegin(); it != found.submissions.rend(); ++it)
    pending.push_back({*it, out / it->folder, -1, {}, false});
  while (!pending.empty() || !running.empty()) {
    // Keep N graders busy; a submission with nothing to grade gets its row (and results.json) at once.
    while (!pending.empty() && int(running.size()) < std::max(1, args.jobs)) {
      Job j = std::move(pending.back());
      pending.pop_back();
      std::string problem;
      const int log_fd = prepareFolder(j.out, problem);
      if (log_fd >= 0 && j.sub.problem.empty()) {
        j.started = Clock::now();
        j.pid = spawnGrade(args, j, log_fd);
        if (j.pid < 0) problem = std::string("internal error: the grader could not be started (") + std::strerror(errno) + ")";
      }
      if (log_fd >= 0) ::close(log_fd);
      if (j.pid > 0) {
        running.push_back(std::move(j));
        continue;
      }
      const Row row = j.sub.problem.empty() ? batch::failedRow(j.sub, "internal error", problem)
                                            : batch::failedRow(j.sub, "invalid submission", j.sub.problem);
      try {
        if (log_fd >= 0) batch::writeFallbackResults(j.out / "results.json", row);
      } catch (const std::exception&) {
        // Its row says what happened; the gradebook is the record.
      }
      progress(row);
    }
    // Reap finished graders; kill the ones past their budget.
    bool any = false;
    for (auto it = running.begin(); it != running.end();) {
      int status = 0;
      if (::waitpid(it->pid, &status, WNOHANG) == 0) {
        if (!it->killed && Clock::now() - it->started > kill_after) {
          ::kill(it->pid, SIGKILL);
          it->killed = true;
        }
        ++it;
        continue;
      }
      any = true;
      progress(finish(*it, status, kill_s));
      it = running.erase(it);
    }
    if (!any) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (tty) std::fprintf(stderr, "\n");
  return rows;
}

}  // namespace

int gradeBatch(const GradeArgs& a) {
  const fs::path out = a.out;
  std::error_code ec;
  // OUT must not be DIR itself: its result folders would be taken for students on the next run.
  if (fs::equivalent(a.batch, out, ec)) {
    std::fprintf(stderr, "error: %s: --out must not be the submissions folder itself; give a folder beside or inside it\n",
                 out.c_str());
    return 2;
  }
  // Read-only first: a DIR with nothing to grade is an error that writes nothing.
  batch::Found found = batch::findSubmissions(a.batch, out);
  if (!found.error.empty()) {
    std::fprintf(stderr, "error: %s: %s\n", a.batch.c_str(), found.error.c_str());
    return 2;
  }
  fs::create_directories(out, ec);
  if (ec) {
    std::fprintf(stderr, "error: %s: cannot create the output folder (%s)\n", out.c_str(), ec.message().c_str());
    return 1;
  }
  // One batch per OUT at a time: a second one refuses before touching anything in it.
  std::string why;
  const int lock_fd = lockOut(out, why);
  if (lock_fd < 0) {
    std::fprintf(stderr, "error: %s: %s\n", out.c_str(), why.c_str());
    return 2;
  }
  batch::assignFolders(found.submissions, out);
  GradeArgs args = a;
  std::string lab_source;
  args.lab = batchLab(a, found, lab_source);
  try {
    assignPlants(args, a.roster, found);
  } catch (const InputError& e) {
    ::close(lock_fd);
    std::fprintf(stderr, "error: %s\n", termText(e.what()).c_str());
    return 2;
  }
  const std::string lab_line = args.lab.empty() ? "lab: none (no submission names a known lab)"
                                                 : "lab: " + args.lab + " (from " + lab_source + ")";
  if (a.plots) warmUpPlotting();  // fonts loaded once here, not in every grader
  std::size_t problems = 0;
  const std::vector<Row> rows = runGraders(args, found, out, problems);

  // The gradebook, and its summary beside it (score statistics, histogram, common failure reasons).
  const fs::path book = out / "gradebook.csv", summary = out / "gradebook.md";
  const double lab_max = batch::labMaxScore(args.lab, a.config, rows);
  for (const auto& [path, text] : {std::pair{book, batch::gradebookCsv(rows, lab_max)}, std::pair{summary, withLab(batch::gradebookMarkdown(rows, lab_max), lab_line)}}) {
    try {
      writeFileAtomic(path, text);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "error: %s: cannot write the gradebook (%s)\n", termText(path.string()).c_str(), termText(e.what()).c_str());
      return 1;
    }
  }
  std::printf("graded %zu submission(s) into %s; gradebook: %s (summary: %s)\n%s\n", found.submissions.size(), out.c_str(),
              book.c_str(), summary.c_str(), termText(lab_line).c_str());
  if (problems) std::printf("%zu submission(s) need a look (see the status and reason columns)\n", problems);
  ::close(lock_fd);
  return 0;
}

}  // namespace dyn::app
