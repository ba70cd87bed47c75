// Grading you can trust (issue 27), through the real dynlab: concurrent grades into one --out,
// staff errors blamed on the staff, a batch's lab, one submission rule for both graders, limits.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <csignal>

#include "tests/app/cli_run.h"

using namespace dyn::test::cli;
using nlohmann::json;

namespace {
const fs::path kLabs = fs::path(DYNLAB_SOURCE_DIR) / "labs";
const fs::path kGood = kLabs / "grasp/examples/mediocre.json", kOther = kLabs / "slider_crank/examples/mediocre.json";
json results(const fs::path& p) { return json::parse(readFile(p)); }
// Options that run a program in dir with its stdout and stderr both in the file `log` there (2>&1).
ProcessOptions logTo(const TempDir& dir, const std::string& log) {
  ProcessOptions o;
  o.cwd = dir.path.string();
  fs::remove(dir / log);
  o.stdout_file = o.stderr_file = (dir / log).string();
  o.append = true;  // one file, two descriptors: appending, neither overwrites the other
  return o;
}
// Runs argv in dir with stdout and stderr on a FIFO whose reader takes one byte and closes it (as
// `2>&1 | head -c 1` would); returns what it read, once the program has ended.
std::string readOneByte(const TempDir& dir, const std::vector<std::string>& argv) {
  const fs::path fifo = dir / "pipe";
  REQUIRE(::mkfifo(fifo.c_str(), 0600) == 0);
  // The reader opens first (without blocking), so the program's open for writing does not block.
  const int reader = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  REQUIRE(reader >= 0);
  ProcessOptions o;
  o.cwd = dir.path.string();
  o.stdout_file = o.stderr_file = fifo.string();
  dyn::StartedProgram program = dyn::startProgram(argv, o);
  pollfd ready{reader, POLLIN, 0};
  char byte = 0;
  std::string got;
  if (::poll(&ready, 1, 60000) > 0 && ::read(reader, &byte, 1) == 1) got.assign(1, byte);
  ::close(reader);
  dyn::waitProgram(program);
  fs::remove(fifo);
  return got;
}
// gradebook.csv's data rows as text fields (RFC 4180 quotes; the header dropped).
std::vector<std::vector<std::string>> gradebook(const fs::path& p) {
  std::vector<std::vector<std::string>> rows(1, std::vector<std::string>(1));
  bool quoted = false;
  const std::string text = readFile(p);
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted && c == '"' && i + 1 < text.size() && text[i + 1] == '"') rows.back().back() += c, ++i;
    else if (c == '"') quoted = !quoted;
    else if (!quoted && c == ',') rows.back().emplace_back();
    else if (!quoted && c == '\n') rows.emplace_back(1);
    else rows.back().back() += c;
  }
  if (rows.back().size() == 1 && rows.back()[0].empty()) rows.pop_back();
  rows.erase(rows.begin());
  return rows;
}
}  // namespace

TEST_CASE("staging: two concurrent grades into one --out both finish and leave one whole set, never a mix") {
  TempDir dir("trust_concurrent");
  for (int trial = 0; trial < 3; ++trial) {
    dyn::StartedProgram a = dyn::startProgram({DYNLAB_BIN, "grade", kGood.string(), "--out", "out"}, logTo(dir, "a.log"));
    dyn::StartedProgram b = dyn::startProgram({DYNLAB_BIN, "grade", kOther.string(), "--out", "out"}, logTo(dir, "b.log"));
    const dyn::ProcessResult ra = dyn::waitProgram(a), rb = dyn::waitProgram(b);
    CHECK_MESSAGE(ra.code == 0, readFile(dir / "a.log"));
    CHECK_MESSAGE(rb.code == 0, readFile(dir / "b.log"));
    // The set that stands is one student's: results.json, report.md and the plots agree on the lab.
    const std::string md = readFile(dir / "out/report.md");
    const bool grasp = md.find("grasp") != std::string::npos, crank = md.find("slider") != std::string::npos;
    CHECK(grasp != crank);
    std::size_t plots = 0;
    for (const auto& e : fs::directory_iterator(dir / "out/plots")) plots += md.find(e.path().filename().string()) != std::string::npos;
    CHECK(plots == std::size_t(std::distance(fs::directory_iterator(dir / "out/plots"), fs::directory_iterator())));
    for (const auto& e : fs::directory_iterator(dir / "out")) CHECK(e.path().filename().string().rfind(".staging", 0) != 0);
  }
}

TEST_CASE("staff errors: a broken --config or a rubric naming an unknown metric is an internal error (exit 3)") {
  TempDir dir("trust_staff");
  writeFile(dir / "broken.json", "{not json");
  json cfg = json::parse(readFile(kLabs / "grasp/grasp.json"));
  cfg["rubric"]["tests"][0]["metric"] = "no_such_metric";
  writeFile(dir / "unknown_metric.json", cfg.dump());
  for (const std::string config : {"broken.json", "unknown_metric.json"}) {
    const fs::path full = fs::absolute(dir / config);
    const Result r = dynlab(dir, {"grade", kGood.string(), "--no-plots", "--out", "out", "--config", full.string()});
    CHECK(r.code == 3);
    const json res = results(dir / "out/results.json");
    CHECK(res["extra_data"]["status"] == "internal_error");
    const std::string output = res["output"];
    CHECK(output.find("Fix it") == std::string::npos);  // "Fix it and resubmit" is for the student's own mistakes
    CHECK(output.find(dir.path.string()) == std::string::npos);  // no server path in what the student reads
  }
}

TEST_CASE("batch: the lab is fixed before it starts; a submission for another lab is an invalid row naming both") {
  TempDir dir("trust_batch_lab");
  fs::create_directories(dir / "subs");
  fs::copy_file(kGood, dir / "subs/a.json");
  fs::copy_file(kOther, dir / "subs/b.json");
  const Result r = dynlab(dir, {"grade", "--batch", "subs", "--out", "out", "--no-plots"});
  CHECK(r.code == 0);
  CHECK(r.out.find("lab: grasp (from the first submission naming a lab, a)") != std::string::npos);
  CHECK(readFile(dir / "out/gradebook.md").find("Lab: grasp") != std::string::npos);
  const auto book = gradebook(dir / "out/gradebook.csv");
  REQUIRE(book.size() == 2);
  CHECK(book[0][3].rfind("graded", 0) == 0);  // "graded", or "graded (unstable run)" when a scenario stops
  CHECK(book[1][3] == "invalid submission");
  CHECK(book[1][4].find("grasp") != std::string::npos);
  CHECK(book[1][4].find("slider_crank") != std::string::npos);
}

TEST_CASE("one submission rule: run_autograder and the batch read the same file, refuse the same links") {
  TempDir dir("trust_rule");
  // name → how the upload is laid out
  const std::vector<std::string> cases = {"nested", "folder_named_submission", "editor_files", "link_out", "link_in", "fifo", "two"};
  fs::create_directories(dir / "subs");
  fs::copy_file(kGood, dir / "staff.json");
  for (const auto& c : cases) fs::create_directories(dir / "subs" / c);
  fs::create_directories(dir / "subs/nested/lab3");
  fs::copy_file(kGood, dir / "subs/nested/lab3/gains.json");
  fs::create_directories(dir / "subs/folder_named_submission/submission.json");
  fs::copy_file(kGood, dir / "subs/folder_named_submission/gains.json");
  fs::create_directories(dir / "subs/editor_files/.vscode");
  writeFile(dir / "subs/editor_files/.vscode/settings.json", "{}");
  fs::copy_file(kGood, dir / "subs/editor_files/gains.json");
  fs::create_symlink("../../staff.json", dir / "subs/link_out/submission.json");
  fs::copy_file(kGood, dir / "subs/link_in/mine.json");
  fs::create_symlink("mine.json", dir / "subs/link_in/submission.json");
  REQUIRE(::mkfifo((dir / "subs/fifo/submission.json").c_str(), 0644) == 0);
  fs::copy_file(kGood, dir / "subs/two/a.json");
  fs::copy_file(kGood, dir / "subs/two/b.json");
  const Result batch = dynlab(dir, {"grade", "--batch", "subs", "--out", "out", "--no-plots", "--lab", "grasp"});
  REQUIRE(batch.code == 0);
  std::map<std::string, std::string> batch_scores;
  for (const auto& row : gradebook(dir / "out/gradebook.csv")) batch_scores[row[0].substr(0, row[0].find('/'))] = row[1];
  // run_autograder from the bundle, over each folder as its upload.
  REQUIRE(dynlab(dir, {"autograder", "grasp", "--out", "bundle.zip"}).code == 0);
  REQUIRE(fs::create_directory(dir / "bundle"));
  ProcessOptions in_bundle;
  in_bundle.cwd = (dir / "bundle").string();
  REQUIRE(run(dir, {"unzip", "-q", "../bundle.zip"}, in_bundle).code == 0);
  for (const auto& c : cases) {
    CAPTURE(c);
    const std::string res = "res_" + c;
    run(dir, {"bash", "bundle/run_autograder"},
        withEnv({{"DYNLAB_BIN", DYNLAB_BIN}, {"DYNLAB_SUBMISSION_DIR", "subs/" + c}, {"DYNLAB_RESULTS_DIR", res}}));
    const double score = results(dir / res / "results.json")["score"];
    REQUIRE(batch_scores.count(c));
    CHECK(std::abs(std::stod(batch_scores[c]) - score) < 1e-3);  // the gradebook shows 3 decimals
    if (c == "link_out" || c == "fifo" || c == "two") CHECK(score == 0.0);
    else CHECK(score > 0.0);
  }
}

TEST_CASE("limits: NaN and infinite options, runs shorter than a step, clipped echoes, full stdout, pipes") {
  TempDir dir("trust_limits");
  for (const std::string budget : {"nan", "inf", "-inf"}) {
    const Result r = dynlab(dir, {"grade", kGood.string(), "--time-budget", budget});
    CHECK(r.code == 2);
    if (budget == "nan") CHECK(r.err.find("finite") != std::string::npos);
  }
  CHECK(dynlab(dir, {"run", "grasp", "--duration", "nan"}).code == 2);
  const Result short_run = dynlab(dir, {"run", "grasp", "--duration", "1e-9", "--out", "run"});
  CHECK(short_run.code == 2);
  CHECK(short_run.err.find("at least one step") != std::string::npos);
  CHECK_FALSE(fs::exists(dir / "run"));
  // A 900 KB unknown key is not quoted whole anywhere.
  json sub = json::parse(readFile(kGood));
  sub["gains"][std::string(900000, 'k')] = 1;
  writeFile(dir / "big.json", sub.dump());
  const Result big = dynlab(dir, {"grade", "big.json", "--no-plots", "--out", "big"});
  CHECK(big.code == 2);
  CHECK(big.err.size() < 4000);
  CHECK(fs::file_size(dir / "big/results.json") < 20000);
  CHECK(readFile(dir / "big/report.md").size() < 20000);
  // ...nor in a message a lab builds (run and compare parse the gains with the lab's own parser).
  for (const std::vector<std::string>& cmd :
       {std::vector<std::string>{"run", "grasp", "--gains", "big.json", "--duration", "0.1", "--out", "runbig"},
        {"compare", "big.json", kGood.string(), "--out", "cmpbig"}}) {
    const Result r = dynlab(dir, cmd);
    INFO(shown(cmd));
    CHECK(r.code == 2);
    CHECK(r.err.size() < 4000);
    CHECK(r.err.find("bytes left out") != std::string::npos);
  }
  // Standard output that cannot be written is an error, not a silent success.
  for (const std::vector<std::string>& cmd :
       {std::vector<std::string>{"schema", "grasp"}, {"list"}, {"grade", kGood.string(), "--no-plots", "--out", "full"}}) {
    INFO(shown(cmd));
    ProcessOptions to_full;
    to_full.stdout_file = "/dev/full";
    const Result r = dynlab(dir, cmd, to_full);
    CHECK(r.code != 0);
    CHECK(r.err.find("cannot write standard output") != std::string::npos);
  }
  // A batch piped into a reader that stops early still writes its gradebook.
  fs::create_directories(dir / "subs");
  for (int i = 0; i < 4; ++i) fs::copy_file(kGood, dir / "subs" / ("s" + std::to_string(i) + ".json"));
  CHECK(readOneByte(dir, {DYNLAB_BIN, "grade", "--batch", "subs", "--out", "pb", "--no-plots"}).size() == 1);
  CHECK(fs::exists(dir / "pb/gradebook.csv"));
  // Past `ulimit -f` a grade ends with an error line and a non-zero exit, not SIGXFSZ.
  ProcessOptions small_files;
  small_files.file_size = 8 * 512;  // `ulimit -f 8` (blocks of 512 bytes)
  const Result fsize = dynlab(dir, {"grade", kGood.string(), "--out", "fs"}, small_files);
  INFO(fsize.err);
  CHECK(fsize.code != 0);
  CHECK(fsize.code != 128 + SIGXFSZ);
  CHECK(fsize.err.find("error:") != std::string::npos);
}

TEST_CASE("a grade cut by its time budget has its own status, not \"graded\"") {
  TempDir dir("trust_budget");
  // The lab's run made 40× longer, so a 1 s budget runs out mid-grade.
  json cfg = json::parse(readFile(kLabs / "grasp/grasp.json"));
  cfg["simulation"]["duration"] = cfg["simulation"]["duration"].get<double>() * 40;
  writeFile(dir / "long.json", cfg.dump());
  const Result r =
      dynlab(dir, {"grade", kGood.string(), "--config", "long.json", "--no-plots", "--out", "o", "--time-budget", "1"});
  CHECK(r.code == 4);
  CHECK(results(dir / "o/results.json")["extra_data"]["status"] == "out_of_time");
}

TEST_CASE("Markdown output: a URL or an email in reflected text is no link (GFM autolinks on)") {
  TempDir dir("trust_autolink");
  writeFile(dir / "sub.json", R"({"lab": "see https://evil.example/x, www.evil.example or mail me@evil.example", "gains": {}})");
  const Result r = dynlab(dir, {"grade", "sub.json", "--no-plots", "--out", "o"});
  CHECK(r.code == 2);
  const std::string html = readFile(dir / "o/report.html"), md = readFile(dir / "o/report.md");
  CHECK(md.find("evil") != std::string::npos);  // the text is there, shown as text
  CHECK(html.find("href=\"https://") == std::string::npos);
  CHECK(html.find("href=\"http://www.") == std::string::npos);
  CHECK(html.find("mailto:") == std::string::npos);
  CHECK(html.find("evil.example") != std::string::npos);
  CHECK(html.find("me") != std::string::npos);
}

TEST_CASE("A plotting library that dies under a memory limit costs the plots, not the grade") {
  // Under `ulimit -v` GLib traps when pango cannot start a thread: that used to kill the whole grade.
  TempDir dir("trust_low_memory");
  ProcessOptions low_memory;
  low_memory.address_space = 400000LL * 1024;  // `ulimit -v 400000` (KiB)
  const Result r = dynlab(dir, {"grade", kGood.string(), "--out", "o"}, low_memory);
  INFO(r.out, r.err);
  // Never a signal death: graded (with its plots, or none and why), or, if the grade itself ran out
  // of memory first, an internal error (exit 3) with its one line.
  CHECK(r.code < 128);
  if (r.code == 3) {
    CHECK(r.err.find("error: internal error") != std::string::npos);
    return;
  }
  REQUIRE(r.code == 0);
  const json res = results(dir / "o/results.json");
  CHECK(res["score"].get<double>() > 0);
  // Either every plot was drawn, or none is claimed and the reader is told why.
  bool any_plot = false;
  for (const auto& t : res["tests"]) any_plot = any_plot || t["extra_data"].contains("plot");
  if (!any_plot) {
    REQUIRE(res["extra_data"].contains("plots_note"));
    CHECK(res["output"].get<std::string>().find("could not be drawn") != std::string::npos);
    CHECK(readFile(dir / "o/report.md").find("could not be drawn") != std::string::npos);
    CHECK(r.out.find("plots: The plots could not be drawn") != std::string::npos);
  }
  for (const auto& t : res["tests"])
    if (t["extra_data"].contains("plot")) CHECK(fs::exists(dir / "o" / t["extra_data"]["plot"].get<std::string>()));
}
