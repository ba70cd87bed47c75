// dynlab grade --batch against hostile file names, stale results, a kill -9, a second batch on the
// same OUT, a Gradescope export and graders that fail: always through the real binary (DYNLAB_BIN),
// every command under a timeout so a hang fails the test instead of blocking the suite.
#include <doctest/doctest.h>

#include <cstdio>
#include <cstdlib>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <regex>
#include <set>
#include <thread>

#include <nlohmann/json.hpp>

#include "tests/app/cli_run.h"
#include "tests/grading/csv_rows.h"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace dyn::test::cli;

namespace {

const fs::path kExamples = fs::path(DYNLAB_SOURCE_DIR) / "labs/slider_crank/examples";

using dyn::test::parseCsv;  // tests/grading/csv_rows.h

// The gradebook as maps (column → cell), keyed by the submission column; checks its shape.
std::map<std::string, std::map<std::string, std::string>> readBook(const fs::path& file) {
  const auto rows = parseCsv(readFile(file));
  REQUIRE(!rows.empty());
  const auto& head = rows[0];
  REQUIRE(head.size() >= 6);
  CHECK(std::vector<std::string>(head.begin(), head.begin() + 6) ==
        std::vector<std::string>{"submission", "score", "max_score", "status", "reason", "folder"});
  std::map<std::string, std::map<std::string, std::string>> book;
  for (std::size_t r = 1; r < rows.size(); ++r) {
    REQUIRE(rows[r].size() == head.size());
    for (const auto& cell : rows[r]) {
      // No cell a spreadsheet would run as a formula.
      CHECK_MESSAGE((cell.empty() || std::string("=+-@\t\r").find(cell[0]) == std::string::npos), "cell: " << cell);
    }
    for (std::size_t c = 0; c < head.size(); ++c) book[rows[r][0]][head[c]] = rows[r][c];
  }
  return book;
}

// Every path below dir (files and folders), except those under `except`.
std::set<std::string> tree(const fs::path& dir, const fs::path& except) {
  std::set<std::string> paths;
  for (auto it = fs::recursive_directory_iterator(dir); it != fs::recursive_directory_iterator(); ++it) {
    if (it->path() == except) {
      it.disable_recursion_pending();
      continue;
    }
    std::string entry = fs::relative(it->path(), dir).string();
    entry += it->is_directory() ? std::string("/") : ' ' + readFile(it->path());
    paths.insert(entry);
  }
  return paths;
}

// A file with its folders made first.
void put(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  writeFile(p, text);
}

// One of the students' examples (never the instructor's: these tests run in a student copy too).
void copyExample(const std::string& example, const fs::path& to) {
  fs::create_directories(to.parent_path());
  fs::copy_file(kExamples / (example + ".json"), to, fs::copy_options::overwrite_existing);
}

// The gradebook's score cell (%.4g) of an example graded alone by `dynlab grade`: what the batch
// must give it too.
std::string aloneScore(const std::string& example) {
  static std::map<std::string, std::string> cells;
  if (const auto it = cells.find(example); it != cells.end()) return it->second;
  const TempDir dir("batch_alone_" + example);
  ProcessOptions o;
  o.timeout_s = 60;
  const Result r = dynlab(dir, {"grade", (kExamples / (example + ".json")).string(), "--no-plots", "--out", "out"}, o);
  REQUIRE_MESSAGE(r.code == 0, r.err);
  char cell[32];
  std::snprintf(cell, sizeof cell, "%.4g", json::parse(readFile(dir / "out/results.json")).at("score").get<double>());
  return cells[example] = cell;
}

// Each submission's time budget: 3 s of wall time, for a grade of ~0.1 s of CPU, so a machine
// loaded 20-fold still grades within it (1 s was tripped under heavy load); a hanging grader is
// killed 3 s after it (batch.cpp). scripts/sanitize raises it, since grading is ~10x slower under
// the sanitizers, through DYNLAB_TEST_TIME_BUDGET.
std::string budget() {
  const char* b = std::getenv("DYNLAB_TEST_TIME_BUDGET");
  return b && *b ? b : "3";
}

// The batch's arguments: `grade --batch IN --out OUT` of the slider crank, each grader under budget().
std::vector<std::string> batchArgs(const std::string& in, const std::string& out, const std::string& jobs) {
  return {"grade", "--batch", in, "--out", out, "--lab", "slider_crank", "--no-plots", "--time-budget", budget(), "--jobs", jobs};
}

// `dynlab grade --batch IN --out OUT` in dir, with a time limit and optional fault injection.
Result batch(const TempDir& dir, const std::string& in, const std::string& out, const std::string& faults = "",
             const std::string& jobs = "2") {
  ProcessOptions o;
  o.timeout_s = 300;
  if (!faults.empty()) o.set_env = {{"DYNLAB_FAULT_INJECTION", faults}};
  return dynlab(dir, batchArgs(in, out, jobs), o);
}

// Starts the same batch (one job) in the background, its output in OUT.log; the caller waits for it.
dyn::StartedProgram batchInBackground(const TempDir& dir, const std::string& in, const std::string& out,
                                      const std::string& faults) {
  ProcessOptions o;
  o.cwd = dir.path.string();
  o.set_env = {{"DYNLAB_FAULT_INJECTION", faults}};
  fs::remove(dir / (out + ".log"));
  o.stdout_file = o.stderr_file = (dir / (out + ".log")).string();
  o.append = true;  // both into one file (2>&1)
  return dyn::startProgram(cat({DYNLAB_BIN}, batchArgs(in, out, "1")), o);
}

// Waits (up to 60 s) until a path exists.
bool waitFor(const fs::path& p) {
  for (int i = 0; i < 6000; ++i, std::this_thread::sleep_for(std::chrono::milliseconds(10)))
    if (fs::exists(p)) return true;
  return false;
}

// Any process other than this one working in `dir` (a grader left running: the graders are forks
// of the batch, so their command line is the batch's; their working folder is the test's).
bool processIn(const fs::path& dir) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator("/proc", ec)) {
    if (e.path().filename() == std::to_string(::getpid())) continue;
    const fs::path cwd = fs::read_symlink(e.path() / "cwd", ec);
    if (!ec && cwd == dir) return true;
  }
  return false;
}

// The submissions of the kill and lock tests: graded, invalid, crashing, one that hangs (6 s).
void standardBatch(const TempDir& dir) {
  copyExample("proportional", dir / "in" / "fine.json");  // graded before "hangs" (name order)
  for (const char* n : {"mediocre", "unstable_integral"}) copyExample(n, dir / "in" / (std::string(n) + ".json"));
  copyExample("proportional", dir / "in" / "crashes.json");
  copyExample("proportional", dir / "in" / "hangs.json");
  put(dir / "in" / "malformed.json", "{\"lab\": \"slider_crank\", \"gains\": {\"kp_x\": }");
}
const char* kFaults = "crash:crashes,hang:hangs";

}  // namespace

TEST_CASE("hostile submission names: each its own safe folder inside OUT, nothing written outside it" * doctest::timeout(400)) {
  TempDir dir("batch_names");
  const fs::path in = dir / "in", out = dir / "out";
  const std::vector<std::string> names = {
      "...json", "..json", "gradebook.csv.json", "gradebook.json", "a\nb.json", "-rf.json", "--help.json",
      "<img src=x onerror=alert(1)>.json", "=HYPERLINK(1).json", "+1.json", "@SUM(A1).json", "\ttab.json",
      "caf\xe9\xff.json", "a b.json", "a_b.json", "Same.json", "same.json", ".staging.json", "x.json",
      std::string(200, 'L') + ".json", "\xe2\x80\xae" "gnp.json"};
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i % 4 == 0) copyExample("proportional", in / names[i]);
    else put(in / names[i], R"({"lab": "slider_crank", "gains": {"kp_x": "high"}})");
  }
  // Around OUT: a plots/ folder `...json` used to remove, and a folder in OUT that no batch wrote.
  put(dir / "keep.txt", "mine");
  fs::create_directories(dir / "plots");
  put(dir / "plots" / "figure.png", "not dynlab's");
  fs::create_directories(out / "x");
  put(out / "x" / "notes.txt", "the TA's notes");
  const auto before = tree(dir.path, out);

  const Result r = batch(dir, "in", "out");
  INFO("stderr: " << r.err);
  REQUIRE(r.code == 0);
  CHECK(tree(dir.path, out) == before);  // nothing outside OUT changed, nothing new
  CHECK(readFile(out / "x" / "notes.txt") == "the TA's notes");

  const auto book = readBook(out / "gradebook.csv");
  CHECK(book.size() == names.size());
  std::set<std::string> folders;
  const std::regex safe("[A-Za-z0-9_][A-Za-z0-9_.-]{0,80}");
  for (const auto& [name, row] : book) {
    INFO("row " << name);
    const std::string folder = row.at("folder");
    CHECK(std::regex_match(folder, safe));
    for (const char* own : {"gradebook.csv", "gradebook.csv.tmp", "gradebook.md", ".dynlab-batch.lock"}) CHECK(folder != own);
    CHECK(folder != "x");  // the TA's folder is not reused
    CHECK(folders.insert(folder).second);  // one folder each
    const json results = json::parse(readFile(out / folder / "results.json"));
    CHECK(results.at("score").is_number());
    CHECK(row.at("max_score") == "15");
    CHECK((row.at("status") == "graded" || row.at("status") == "invalid submission"));
  }
  // The rows name the submissions, neutralised and as valid UTF-8.
  CHECK(book.count("'=HYPERLINK(1).json"));
  CHECK(book.count("'-rf.json"));
  CHECK(book.count("'+1.json"));
  CHECK(book.count("'@SUM(A1).json"));
  CHECK(book.count("a\nb.json"));
  CHECK(book.count("caf\xef\xbf\xbd\xef\xbf\xbd.json"));
  CHECK(book.at("...json").at("status") == "graded");
  CHECK(book.at("...json").at("score") == aloneScore("proportional"));
  CHECK(book.at("a_b.json").at("reason") == "/gains/kp_x: expected a number, got \"high\"");
  // The summary lists every name that was not graded, as one line of text each: no tag, no control
  // character.
  const std::string md = readFile(out / "gradebook.md");
  CHECK(md.find("<img") == std::string::npos);
  CHECK(md.find("&lt;img src=x onerror=alert(1)&gt;.json") != std::string::npos);
  CHECK(md.find("tab.json") != std::string::npos);  // listed, its tab shown as \t
  CHECK(md.find('\t') == std::string::npos);
  std::size_t listed = 0;
  for (const auto& [name, row] : book) listed += row.at("status") == "invalid submission";
  const std::size_t section = md.find("## Not graded");
  REQUIRE(section != std::string::npos);
  CHECK(std::size_t(std::count(md.begin() + std::ptrdiff_t(section), md.end(), '\n')) == listed + 4);  // heading, blank, header, rule
  // OUT holds the gradebook and its summary, the lock and one folder per submission (plus the TA's), nothing else.
  std::size_t entries = 0;
  for (const auto& e : fs::directory_iterator(out)) {
    ++entries;
    const std::string n = e.path().filename().string();
    CHECK_MESSAGE((n == "gradebook.csv" || n == "gradebook.md" || n == ".dynlab-batch.lock" || n == "x" || folders.count(n)), n);
  }
  CHECK(entries == names.size() + 4);
}

TEST_CASE("a rerun grades afresh: a stale results.json never counts, a failing grader is a failure" * doctest::timeout(300)) {
  TempDir dir("batch_stale");
  copyExample("proportional", dir / "in" / "fine.json");
  copyExample("mediocre", dir / "in" / "mediocre.json");
  REQUIRE(batch(dir, "in", "out").code == 0);
  CHECK(readBook(dir / "out" / "gradebook.csv").at("fine.json").at("score") == aloneScore("proportional"));
  REQUIRE(fs::exists(dir / "out" / "fine" / "report.md"));

  SUBCASE("the grader exits 1 without writing anything") {
    const Result r = batch(dir, "in", "out", "fail:fine");
    REQUIRE(r.code == 0);
    const auto row = readBook(dir / "out" / "gradebook.csv").at("fine.json");
    CHECK(row.at("score") == "0");
    CHECK(row.at("max_score") == "15");
    CHECK(row.at("status") == "internal error");
    CHECK(row.at("reason").find("internal error: the grader exited with status 1") == 0);
    const json results = json::parse(readFile(dir / "out" / "fine" / "results.json"));
    CHECK(results.at("score") == 0.0);
    CHECK(results.at("output").get<std::string>().find("exited with status 1") != std::string::npos);
    // Last run's report is not left beside it.
    CHECK(!fs::exists(dir / "out" / "fine" / "report.md"));
    CHECK(!fs::exists(dir / "out" / "fine" / "report.html"));
  }
  SUBCASE("the submission became unreadable bytes") {
    put(dir / "in" / "fine.json", "\xff\xfe{\0\"");
    REQUIRE(batch(dir, "in", "out").code == 0);
    const auto row = readBook(dir / "out" / "gradebook.csv").at("fine.json");
    CHECK(row.at("score") == "0");
    // Invalid once the grader reports bad UTF-8 as such (inputs branch); until then its exit 1 is an internal error.
    CHECK((row.at("status") == "invalid submission" || row.at("status") == "internal error"));
    CHECK(!row.at("reason").empty());
  }
  SUBCASE("the submission became a FIFO: refused, not waited on") {
    fs::remove(dir / "in" / "fine.json");
    REQUIRE(::mkfifo((dir / "in" / "fine.json").c_str(), 0644) == 0);
    const auto started = std::chrono::steady_clock::now();
    REQUIRE(batch(dir, "in", "out").code == 0);
    CHECK(std::chrono::steady_clock::now() - started < std::chrono::seconds(60));
    const auto row = readBook(dir / "out" / "gradebook.csv").at("fine.json");
    CHECK(row.at("score") == "0");
    CHECK(row.at("reason").find("a FIFO, not a regular file") != std::string::npos);
    CHECK(json::parse(readFile(dir / "out" / "fine" / "results.json")).at("score") == 0.0);
  }
  // The other submission is graded as before.
  CHECK(readBook(dir / "out" / "gradebook.csv").at("mediocre.json").at("status") == "graded");
}

TEST_CASE("a batch killed with SIGKILL and rerun gives the gradebook of an uninterrupted one" * doctest::timeout(300)) {
  TempDir dir("batch_kill");
  standardBatch(dir);
  REQUIRE(batch(dir, "in", "clean", kFaults, "1").code == 0);
  const std::string clean = readFile(dir / "clean" / "gradebook.csv");

  // Killed while the hanging submission is being graded (crashes and fine are done by then).
  dyn::StartedProgram killed = batchInBackground(dir, "in", "out", kFaults);
  REQUIRE(killed.pid > 0);
  REQUIRE(waitFor(dir / "out" / "hangs" / "grade.log"));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  REQUIRE(processIn(dir.path));  // the batch and its graders are seen working there
  REQUIRE(::kill(killed.pid, SIGKILL) == 0);
  CHECK(dyn::waitProgram(killed).signal == SIGKILL);
  CHECK(!fs::exists(dir / "out" / "gradebook.csv"));
  CHECK(fs::exists(dir / "out" / "fine" / "results.json"));
  // Its graders died with it: none is left writing into OUT.
  bool gone = false;
  for (int i = 0; i < 200 && !(gone = !processIn(dir.path)); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  CHECK(gone);

  REQUIRE(batch(dir, "in", "out", kFaults, "1").code == 0);
  CHECK(readFile(dir / "out" / "gradebook.csv") == clean);
  for (const char* n : {"fine", "mediocre", "malformed", "crashes", "hangs"}) {
    CAPTURE(n);
    json a = json::parse(readFile(dir / "clean" / n / "results.json")), b = json::parse(readFile(dir / "out" / n / "results.json"));
    a.erase("execution_time");
    b.erase("execution_time");
    CHECK(a == b);
  }
}

TEST_CASE("a second batch into the same OUT refuses at once; the first finishes intact" * doctest::timeout(300)) {
  TempDir dir("batch_lock");
  standardBatch(dir);
  dyn::StartedProgram first = batchInBackground(dir, "in", "out", kFaults);
  REQUIRE(first.pid > 0);
  REQUIRE(waitFor(dir / "out" / "crashes" / "grade.log"));

  const auto started = std::chrono::steady_clock::now();
  const Result second = batch(dir, "in", "out", kFaults);
  CHECK(std::chrono::steady_clock::now() - started < std::chrono::seconds(5));
  INFO("stderr: " << second.err);
  CHECK(second.code == 2);
  CHECK(second.out.empty());
  CHECK(std::count(second.err.begin(), second.err.end(), '\n') == 1);
  CHECK(second.err.rfind("error: out: another dynlab grade --batch is writing into this folder", 0) == 0);

  const dyn::ProcessResult done = dyn::waitProgram(first);
  CHECK((done.signal == 0 && done.code == 0));
  const auto book = readBook(dir / "out" / "gradebook.csv");
  CHECK(book.size() == 6);
  CHECK(book.at("fine.json").at("score") == aloneScore("proportional"));
  CHECK(book.at("hangs.json").at("status") == "timed out");
  CHECK(book.at("crashes.json").at("status") == "crashed");
  CHECK(book.at("malformed.json").at("status") == "invalid submission");
  // Once the first is done, OUT is free again.
  CHECK(batch(dir, "in", "out", kFaults).code == 0);
}

TEST_CASE("a Gradescope export: one folder per student, macOS leftovers ignored" * doctest::timeout(300)) {
  TempDir dir("batch_export");
  const fs::path in = dir / "export";
  put(dir / "submission_metadata.yml", "");
  fs::create_directories(in);
  put(in / "submission_metadata.yml", "submission_1: {}\n");
  copyExample("proportional", in / "submission_1" / "submission.json");
  copyExample("mediocre", in / "submission_1" / "scratch.json");          // submission.json wins
  copyExample("proportional", in / "submission_2" / "my gains.json");     // the only JSON
  put(in / "submission_2" / "._my gains.json", "\x00\x05\x16\x07");  // AppleDouble beside it
  put(in / "__MACOSX" / "submission_2" / "._my gains.json", "\x00\x05\x16\x07");
  copyExample("proportional", in / "submission_3" / "a.json");
  copyExample("proportional", in / "submission_3" / "b.json");
  put(in / "submission_4" / "answer.pdf", "%PDF");
  copyExample("proportional", in / "top.json");  // a file at the top is a submission too

  const Result r = batch(dir, "export", "out");
  INFO("stderr: " << r.err);
  REQUIRE(r.code == 0);
  const auto book = readBook(dir / "out" / "gradebook.csv");
  CHECK(book.size() == 5);
  CHECK(book.at("submission_1/submission.json").at("score") == aloneScore("proportional"));
  CHECK(book.at("submission_1/submission.json").at("folder") == "submission_1");
  CHECK(book.at("submission_2/my gains.json").at("status") == "graded");
  CHECK(book.at("submission_3/").at("reason").find("several JSON files") != std::string::npos);
  CHECK(book.at("submission_4/").at("reason").find("no JSON file") != std::string::npos);
  CHECK(book.at("submission_4/").at("max_score") == "15");
  CHECK(book.at("top.json").at("status") == "graded");
  CHECK(json::parse(readFile(dir / "out" / "submission_4" / "results.json")).at("score") == 0.0);

  // A folder with nothing to grade is an error that says what it found, not an empty success.
  fs::create_directories(dir / "empty" / ".git");
  put(dir / "empty" / "notes.txt", "");
  const Result none = batch(dir, "empty", "out2");
  CHECK(none.code == 2);
  CHECK(none.err.rfind("error: empty: found no submissions", 0) == 0);
  CHECK(none.err.find("1 other file(s)") != std::string::npos);
  CHECK(!fs::exists(dir / "out2"));  // nothing written
  const Result same = batch(dir, "export", "export/.");
  CHECK(same.code == 2);
  CHECK(same.err.find("--out must not be the submissions folder itself") != std::string::npos);
}

TEST_CASE("OUT inside the submissions folder is not taken for a student" * doctest::timeout(300)) {
  TempDir dir("batch_inside");
  copyExample("proportional", dir / "in" / "fine.json");
  REQUIRE(batch(dir, "in", "in/graded").code == 0);
  REQUIRE(batch(dir, "in", "in/graded").code == 0);  // the rerun sees the graded folder again
  const auto book = readBook(dir / "in" / "graded" / "gradebook.csv");
  CHECK(book.size() == 1);
  CHECK(book.at("fine.json").at("score") == aloneScore("proportional"));

  // --out . around the submissions: folders dynlab did not write (plots/, the submissions) are left alone.
  TempDir here("batch_here");
  put(here / "plots" / "figure.png", "not dynlab's");
  copyExample("proportional", here / "in" / "plots.json");
  copyExample("proportional", here / "in" / "in.json");
  const auto before = tree(here.path, here / "nothing");
  REQUIRE(batch(here, "in", ".").code == 0);
  CHECK(readFile(here / "plots" / "figure.png") == "not dynlab's");
  CHECK(std::distance(fs::directory_iterator(here / "plots"), fs::directory_iterator()) == 1);
  CHECK(std::distance(fs::directory_iterator(here / "in"), fs::directory_iterator()) == 2);
  const auto here_book = readBook(here / "gradebook.csv");
  CHECK(here_book.at("plots.json").at("folder").rfind("plots-", 0) == 0);
  CHECK(here_book.at("in.json").at("folder").rfind("in-", 0) == 0);
  const auto after = tree(here.path, here / "nothing");
  for (const auto& p : before) CHECK_MESSAGE(after.count(p), "gone or changed: " << p);
}

TEST_CASE("a broken lab config is an internal error in every row, not the students' mistake" * doctest::timeout(120)) {
  TempDir dir("batch_config");
  copyExample("proportional", dir / "in" / "fine.json");
  json config = json::parse(defaultConfigText());
  config["rubric"]["tests"][0]["points"] = "lots";
  put(dir / "broken.json", config.dump());
  ProcessOptions o;
  o.timeout_s = 120;
  const Result r = dynlab(dir, {"grade", "--batch", "in", "--out", "out", "--config", "broken.json", "--no-plots"}, o);
  REQUIRE(r.code == 0);
  const auto row = readBook(dir / "out" / "gradebook.csv").at("fine.json");
  CHECK(row.at("status") == "internal error");
  CHECK(row.at("reason").find("internal error: ") == 0);
  CHECK(row.at("reason").find("broken.json: /rubric/tests/0/points: expected") != std::string::npos);  // the staff file named, for the staff
}
