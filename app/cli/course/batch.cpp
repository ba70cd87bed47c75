// dynlab grade --batch DIR --jobs N --out OUT: every submission in DIR graded by one of N grader
// processes (forks running `dynlab grade FILE --out OUT/<folder>`'s code, one submission after
// another: batch_graders.h), under a lock on OUT. A submission whose grade exits with anything but 0
// (graded) or 2 (invalid submission), crashes or hangs (its grader killed after its time budget)
// gets a results.json saying so; a fresh grader takes the next one and the batch goes on. Then OUT/gradebook.csv and
// its summary, OUT/gradebook.md.
#include <fcntl.h>
#include <signal.h>
#include <poll.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <optional>
#include <system_error>

#include "app/cli/course/batch.h"
#include "app/cli/course/batch_graders.h"
#include "app/cli/commands.h"
#include "app/cli/output.h"
#include "labs/config.h"
#include "labs/file_write.h"
#include "labs/lab.h"
#include "grading/escape.h"
#include "grading/plot.h"
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
  std::size_t index = 0;  // in the batch's submissions
  Submission sub;
  fs::path out;  // OUT/<folder>
  Clock::time_point started;
  bool isolated = false;  // graded again after its grader died: plots drawn in a child of the grader
};

// A job slot: its grader process (started when first needed, and again after one ended) and the
// submission it is grading.
struct Slot {
  batch::Grader grader;
  std::optional<Job> job;
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
Row finish(const Job& job, int status, bool killed, double kill_s) {
  const fs::path results = job.out / "results.json";
  Row row;
  if (killed) {
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

// Hands the job to its slot's grader (a fresh one if it has none, or the one it had is gone). False
// (errno set) when no grader could be started.
bool startJob(Slot& slot, Job job, const GradeArgs& args, const batch::Found& found, const fs::path& out,
              std::vector<Slot>& slots) {
  const bool in_place = args.plots && !job.isolated;
  if (slot.grader.running() && slot.grader.in_place != in_place) batch::stopGrader(slot.grader, false);
  for (int attempt = 0; attempt < 2; ++attempt) {
    if (!slot.grader.running()) {
      std::vector<batch::Grader*> others;
      for (Slot& s : slots) others.push_back(&s.grader);
      slot.grader = batch::startGrader(args, found.submissions, out, others, in_place);
      if (!slot.grader.running()) return false;
    }
    job.started = Clock::now();
    if (batch::sendSubmission(slot.grader, job.index)) {
      slot.job = std::move(job);
      return true;
    }
    batch::stopGrader(slot.grader, true);  // it ended while idle: a fresh one
    errno = EPIPE;
  }
  return false;
}

// Waits (at most until the first deadline) for a grader to reply or end, and returns the rows of the
// submissions that finished: graded, failed (its grader ended: a fresh one takes the next), or past
// their deadline (the grader is killed). A submission whose grader drew its plots in place and died
// of a signal goes to `again`, to be graded by a grader that draws them in a child, as a lone
// `dynlab grade` does (a plotting library that dies then costs the plots, not the grade).
std::vector<Row> collect(std::vector<Slot>& slots, Clock::duration kill_after, double kill_s, std::vector<Job>& again) {
  std::vector<pollfd> fds;
  auto wait = std::chrono::milliseconds(1000);
  const auto now = Clock::now();
  for (const Slot& s : slots) {
    if (!s.job) continue;
    fds.push_back({s.grader.from, POLLIN, 0});
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(s.job->started + kill_after - now);
    wait = std::clamp(left + std::chrono::milliseconds(1), std::chrono::milliseconds(0), wait);
  }
  if (::poll(fds.data(), fds.size(), int(wait.count())) < 0 && errno != EINTR) throw std::system_error(errno, std::generic_category(), "poll");
  std::vector<Row> rows;
  std::size_t at = 0;
  for (Slot& s : slots) {
    if (!s.job) continue;
    const short ready = fds[at++].revents;
    if (ready != 0) {
      const int code = batch::readExitCode(s.grader);
      // A grade that ended in an internal error may leave its grader in a bad state: a fresh one.
      if (code < 0 || (code != 0 && code != 2 && code != 4)) {
        const bool in_place = s.grader.in_place;
        const int status = batch::stopGrader(s.grader, false);
        if (code < 0 && WIFSIGNALED(status) && in_place) {
          again.push_back(*s.job);
          again.back().isolated = true;
        } else {
          rows.push_back(finish(*s.job, code < 0 ? status : W_EXITCODE(code, 0), false, kill_s));
        }
      } else {
        rows.push_back(finish(*s.job, W_EXITCODE(code, 0), false, kill_s));
      }
    } else if (Clock::now() - s.job->started > kill_after) {
      batch::stopGrader(s.grader, true);
      rows.push_back(finish(*s.job, 0, true, kill_s));
    } else {
      continue;
    }
    s.job.reset();
  }
  return rows;
}

// Every submission graded, N graders at a time, each submission under its budget (its grader killed
// past it); one row each, in the order they finish, with a bar (a terminal) or a line each (a log).
std::vector<Row> runGraders(const GradeArgs& args, const batch::Found& found, const fs::path& out, std::size_t& problems) {
  const std::size_t total = found.submissions.size();
  const bool tty = isatty(STDERR_FILENO);
  // A submission gets its own budget plus a margin to write its results, then its grader is killed.
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
  // A grader that died must not kill the batch with SIGPIPE when it is sent its next submission.
  const auto old_sigpipe = ::signal(SIGPIPE, SIG_IGN);
  std::vector<Slot> slots(std::size_t(std::max(1, args.jobs)));
  std::size_t next = 0;
  auto busy = [&slots] { return std::any_of(slots.begin(), slots.end(), [](const Slot& s) { return s.job.has_value(); }); };
  std::vector<Job> again;  // to be graded again, plots isolated
  while (next < total || busy() || !again.empty()) {
    // Keep every slot busy; a submission with nothing to grade gets its row (and results.json) at once.
    for (Slot& slot : slots) {
      while (!slot.job && (next < total || !again.empty())) {
        Job j;
        if (!again.empty()) {
          j = std::move(again.back());
          again.pop_back();
        } else {
          j = {next, found.submissions[next], out / found.submissions[next].folder, {}, false};
          ++next;
        }
        std::string problem;
        const int log_fd = prepareFolder(j.out, problem);
        if (log_fd >= 0) ::close(log_fd);
        if (log_fd >= 0 && j.sub.problem.empty()) {
          if (startJob(slot, j, args, found, out, slots)) break;
          problem = std::string("internal error: the grader could not be started (") + std::strerror(errno) + ")";
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
    }
    if (!busy()) continue;
    for (Row& r : collect(slots, kill_after, kill_s, again)) progress(std::move(r));
  }
  for (Slot& slot : slots)
    if (slot.grader.running()) batch::stopGrader(slot.grader, false);
  ::signal(SIGPIPE, old_sigpipe);
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

  // The graders write without fsync (labs/file_write.h: deferDurability): one sync of OUT's file
  // system puts every submission's results on disk before the gradebook that records them.
  try {
    syncFileSystem(out.string());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s: the results could not be put on disk (%s)\n", termText(out.string()).c_str(), termText(e.what()).c_str());
    return 1;
  }
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
