// What `dynlab grade` writes, through the real binary: hostile file names and string values stay
// escaped in report.md, report.html, results.json and the terminal; a full disk (a small tmpfs,
// and an injected ENOSPC) is a non-zero exit with the system's error text and no short result left
// as if valid; an internal error (a plot that cannot be written) is not blamed on the student.
#include <doctest/doctest.h>

#include <fcntl.h>
#include <sched.h>
#include <sys/mount.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <nlohmann/json.hpp>

#include "tests/app/cli_run.h"

using namespace dyn::test::cli;

namespace {

// Stable gains that grade normally (the students' mediocre example, not the instructor's answer).
const std::string kGood = readFile(fs::path(DYNLAB_SOURCE_DIR) / "labs/slider_crank/examples/mediocre.json");
// A file name with markup, a line break, backticks and a heading.
const std::string kHostileName = "x`` <img src=x onerror=alert(1)> <script>s\n# injected heading.json";

// Lines of text that start with prefix.
int linesStartingWith(const std::string& text, const std::string& prefix) {
  int n = 0;
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t end = std::min(text.find('\n', at), text.size());
    n += text.compare(at, prefix.size(), prefix) == 0;
    at = end + 1;
  }
  return n;
}

// report.md and report.html of OUT hold none of the hostile markup, and results.json is valid.
void checkEscaped(const TempDir& dir, const fs::path& out) {
  const std::string md = readFile(out / "report.md"), html = readFile(out / "report.html");
  INFO("report.md:\n", md);
  CHECK(md.find("<img") == std::string::npos);
  CHECK(md.find("<script") == std::string::npos);
  CHECK(linesStartingWith(md, "# ") == 1);  // only the report's own title
  CHECK(md.find("&lt;img src=x onerror") != std::string::npos);  // the text is there, as text
  CHECK(html.find("<img") == std::string::npos);
  CHECK(html.find("<script") == std::string::npos);
  CHECK(html.find("<h1>") == html.rfind("<h1>"));
  const Result check = dynlab(dir, {"check-results", (out / "results.json").string()});
  CHECK_MESSAGE(check.code == 0, check.err);
  const auto results = nlohmann::json::parse(readFile(out / "results.json"));
  CHECK(results.at("output").get<std::string>().find("<script") == std::string::npos);
}

// What `unshare -rm` would do for the calling process: a mount namespace of its own (in a user
// namespace where this user is root, unless it is root already), its mounts private.
bool privateMounts(std::string& why) {
  const uid_t uid = ::geteuid();
  const gid_t gid = ::getegid();
  if (::unshare(uid == 0 ? CLONE_NEWNS : CLONE_NEWUSER | CLONE_NEWNS) != 0) return why = std::strerror(errno), false;
  if (uid != 0) {
    writeFile("/proc/self/setgroups", "deny");
    writeFile("/proc/self/uid_map", "0 " + std::to_string(uid) + " 1");
    writeFile("/proc/self/gid_map", "0 " + std::to_string(gid) + " 1");
  }
  if (::mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr) != 0) return why = std::strerror(errno), false;
  return true;
}

// Run in a child of the test (the namespace is its own): mounts a 64 KiB tmpfs at dir/mnt, grades
// into it (first.code, first.json), fills it, grades again (full.code, full.err), then copies what
// stands (after/) and lists the empty files left (empty.list). Without a tmpfs: mount.err, exit 77.
int gradeIntoFullTmpfs(const fs::path& dir) {
  std::string why;
  fs::create_directories(dir / "mnt");
  if (!privateMounts(why) || ::mount("tmpfs", (dir / "mnt").c_str(), "tmpfs", 0, "size=64k") != 0) {
    writeFile(dir / "mount.err", why.empty() ? std::strerror(errno) : why);
    return 77;
  }
  ProcessOptions o;
  o.cwd = dir.string();
  const std::vector<std::string> grade = {DYNLAB_BIN, "grade", "good.json", "--no-plots", "--out", "mnt/out"};
  writeFile(dir / "first.code", std::to_string(runProgram(grade, o).code) + "\n");
  std::error_code ec;
  fs::copy_file(dir / "mnt/out/results.json", dir / "first.json", ec);
  const int fill = ::open((dir / "mnt/fill").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  const std::string zeros(4096, '\0');
  while (fill >= 0 && ::write(fill, zeros.data(), zeros.size()) > 0) {
  }
  ::close(fill);
  o.stderr_file = (dir / "full.err").string();
  writeFile(dir / "full.code", std::to_string(runProgram(grade, o).code) + "\n");
  fs::create_directories(dir / "after");
  fs::copy(dir / "mnt/out", dir / "after", fs::copy_options::recursive, ec);
  std::string empty;
  for (const auto& e : fs::recursive_directory_iterator(dir / "mnt/out", ec))
    if (e.is_regular_file() && e.file_size() == 0) empty += e.path().string() + "\n";
  writeFile(dir / "empty.list", empty);
  return 0;
}

}  // namespace

TEST_CASE("a hostile file name and string values stay escaped in every report") {
  TempDir dir("hostile_names");
  SUBCASE("graded: the file name is in report.md, the fingerprint line and the terminal") {
    writeFile(dir / kHostileName, kGood);
    const Result r = dynlab(dir, {"grade", kHostileName, "--no-plots", "--out", "out"});
    INFO(r.err);
    CHECK(r.code == 0);
    checkEscaped(dir, dir / "out");
    CHECK(linesStartingWith(r.out, "# injected") == 0);  // the terminal shows \n, not a line break
    CHECK(r.out.find("\\n# injected") != std::string::npos);
    CHECK(nlohmann::json::parse(readFile(dir / "out/results.json")).at("extra_data").at("status") == "graded");
  }
  SUBCASE("invalid: a gain given as a string is quoted by the error message") {
    writeFile(dir / kHostileName,
              R"({"lab": "slider_crank", "gains": {"kp_x": "<img src=x onerror=alert(1)>`` \n# injected <script>", "kd_x": 8}})");
    const Result r = dynlab(dir, {"grade", kHostileName, "--no-plots", "--out", "out"});
    INFO(r.out, r.err);
    CHECK(r.code == 2);
    checkEscaped(dir, dir / "out");
    const auto results = nlohmann::json::parse(readFile(dir / "out/results.json"));
    CHECK(results.at("extra_data").at("status") == "invalid_submission");
    CHECK(results.at("output").get<std::string>().find("Fix it and resubmit") != std::string::npos);
  }
}

TEST_CASE("an injected ENOSPC on results.json: exit 3, the system's words, the old results intact") {
  TempDir dir("enospc");
  writeFile(dir / "good.json", kGood);
  REQUIRE(dynlab(dir, {"grade", "good.json", "--no-plots", "--out", "out"}).code == 0);
  const auto before = snapshot(dir / "out");
  const ProcessOptions enospc = withEnv({{"DYNLAB_FAULT_INJECTION", "enospc:results.json"}});
  const Result full = dynlab(dir, {"grade", "good.json", "--no-plots", "--out", "out"}, enospc);
  INFO(full.err);
  CHECK(full.code == 3);
  CHECK(std::count(full.err.begin(), full.err.end(), '\n') == 1);
  CHECK(full.err.find("No space left on device") != std::string::npos);
  CHECK(full.err.find("out/results.json") != std::string::npos);
  CHECK(snapshot(dir / "out") == before);  // nothing replaced, nothing half-written beside it
  CHECK_FALSE(fs::exists(dir / "out/.staging"));
  // A fresh OUT: no results.json at all.
  const Result fresh = dynlab(dir, {"grade", "good.json", "--no-plots", "--out", "fresh"}, enospc);
  CHECK(fresh.code == 3);
  CHECK_FALSE(fs::exists(dir / "fresh/results.json"));
}

TEST_CASE("a full disk (a 64 KiB tmpfs): exit 3, the system's words, nothing short left as if valid") {
  TempDir dir("tmpfs");
  writeFile(dir / "good.json", kGood);
  // In a private mount namespace (as root, or as a mapped user): a tmpfs, graded into once, then filled.
  const pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {  // never back into the test runner: an exception ends the child too
    int code = 1;
    try {
      code = gradeIntoFullTmpfs(dir.path);
    } catch (...) {
    }
    ::_exit(code);
  }
  int status = 0;
  REQUIRE(::waitpid(pid, &status, 0) == pid);
  if (!fs::exists(dir / "full.code")) {
    MESSAGE("no tmpfs could be mounted here (", readFile(dir / "mount.err"), "): the injected ENOSPC test stands in");
    return;
  }
  CHECK(readFile(dir / "first.code") == "0\n");
  const std::string err = readFile(dir / "full.err");
  INFO(err);
  CHECK(readFile(dir / "full.code") == "3\n");
  CHECK(std::count(err.begin(), err.end(), '\n') == 1);
  CHECK(err.find("No space left on device") != std::string::npos);
  CHECK(readFile(dir / "after/results.json") == readFile(dir / "first.json"));  // the previous grade, intact
  CHECK(readFile(dir / "empty.list").empty());
  CHECK_FALSE(fs::exists(dir / "after/.staging"));
}

TEST_CASE("a plot that cannot be written is an internal error, not the student's") {
  TempDir dir("plot_failure");
  writeFile(dir / "good.json", kGood);
  const Result r = dynlab(dir, {"grade", "good.json", "--out", "out"}, withEnv({{"DYNLAB_FAULT_INJECTION", "enospc:.png"}}));
  INFO(r.out, r.err);
  CHECK(r.code == 3);
  CHECK(r.out.find("internal error") != std::string::npos);
  const auto results = nlohmann::json::parse(readFile(dir / "out/results.json"));
  const std::string feedback = results.at("output");
  CHECK(feedback.find("Fix it") == std::string::npos);
  CHECK(feedback.find("could not be graded") == std::string::npos);
  CHECK(feedback.find("not a problem with your submission") != std::string::npos);
  CHECK(results.at("extra_data").at("status") == "internal_error");
  CHECK(results.at("extra_data").at("internal_error").get<std::string>().find(".png") != std::string::npos);
  CHECK_FALSE(fs::exists(dir / "out/plots"));  // no partial plots published
  CHECK(dynlab(dir, {"check-results", "out/results.json"}).code == 0);
}

TEST_CASE("grade --out . never removes a plots/ folder of the user's; its own plots/ it replaces") {
  TempDir dir("out_dot");
  writeFile(dir / "good.json", kGood);
  fs::create_directories(dir / "plots");
  writeFile(dir / "plots/notes.txt", "mine");
  Result r = dynlab(dir, {"grade", "good.json", "--out", "."});
  INFO(r.out, r.err);
  CHECK(r.code == 2);
  CHECK(r.err.find("plots holds files dynlab did not write (notes.txt)") != std::string::npos);
  CHECK(readFile(dir / "plots/notes.txt") == "mine");
  CHECK_FALSE(fs::exists(dir / "results.json"));  // nothing was written
  // Without the user's file, dynlab writes its plots there, and a rerun replaces them.
  fs::remove(dir / "plots/notes.txt");
  r = dynlab(dir, {"grade", "good.json", "--out", "."});
  CHECK(r.code == 0);
  CHECK(fs::exists(dir / "results.json"));
  r = dynlab(dir, {"grade", "good.json", "--out", "."});
  CHECK(r.code == 0);
  CHECK_FALSE(fs::is_empty(dir / "plots"));
}
