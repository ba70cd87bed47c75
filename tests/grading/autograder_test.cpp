// Tests for app/autograder: what the Gradescope zip holds (scripts executable, the source tree
// without build output), byte-identical rewrites, errors naming the path, and run_autograder's
// promise of a valid results.json, run for real against fake dynlab binaries (whose check-results
// is the real one); and `dynlab check-results` itself, through the real binary (DYNLAB_BIN).
#include "app/cli/course/autograder.h"

#include <doctest/doctest.h>

#include "app/shared/process.h"
#include "tests/test_files.h"
#include <sys/stat.h>
#include <zip.h>

#include "tests/app/cli_run.h"

#include <algorithm>
#include <regex>
#include <sstream>
#include <vector>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <thread>

using dyn::app::writeAutograder;
namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string& name) { return dyn::test::scratchDir("dynlab_autograder_test", name); }
using dyn::test::readBytes;

void writeText(const fs::path& p, const std::string& text, bool exec = false) {
  fs::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << text;
  if (exec) fs::permissions(p, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                                   fs::perms::others_read | fs::perms::others_exec);
}

struct ZipEntry {
  std::string data;
  unsigned mode = 0;  // Unix mode from the external attributes
};

// Every entry of a zip, in the order stored, read back with libzip.
std::vector<std::pair<std::string, ZipEntry>> readZip(const fs::path& p) {
  int err = 0;
  zip_t* za = zip_open(p.string().c_str(), ZIP_RDONLY, &err);
  REQUIRE(za != nullptr);
  std::vector<std::pair<std::string, ZipEntry>> out;
  for (zip_int64_t i = 0; i < zip_get_num_entries(za, 0); ++i) {
    zip_stat_t st;
    REQUIRE(zip_stat_index(za, i, 0, &st) == 0);
    ZipEntry e;
    e.data.resize(st.size);
    zip_file_t* f = zip_fopen_index(za, i, 0);
    REQUIRE(f != nullptr);
    REQUIRE(zip_fread(f, e.data.data(), st.size) == static_cast<zip_int64_t>(st.size));
    zip_fclose(f);
    zip_uint8_t os = 0;
    zip_uint32_t attr = 0;
    zip_file_get_external_attributes(za, i, 0, &os, &attr);
    e.mode = (os == ZIP_OPSYS_UNIX) ? (attr >> 16) & 07777 : 0;
    out.push_back({st.name, e});
  }
  zip_close(za);
  return out;
}

std::map<std::string, ZipEntry> asMap(const std::vector<std::pair<std::string, ZipEntry>>& v) {
  return {v.begin(), v.end()};
}

struct Ran {
  int code = -1;
  std::string out, err;
};

// Runs argv (no shell) with stdout and stderr captured (in files of a scratch folder of their own),
// killed after timeout_s (> 0).
Ran captured(const std::vector<std::string>& argv, double timeout_s = 0) {
  static const fs::path dir = scratch("capture");
  const fs::path out = dir / "stdout.txt", err = dir / "stderr.txt";
  dyn::ProcessOptions o;
  o.stdout_file = out.string();
  o.stderr_file = err.string();
  o.timeout_s = timeout_s;
  const dyn::ProcessResult r = dyn::runProgram(argv, o);
  return {r.code, readBytes(out), readBytes(err) + r.error};
}

// The real `dynlab check-results FILE` (under a timeout, so a hang fails instead of blocking the suite).
Ran checkResults(const fs::path& file) { return captured({DYNLAB_BIN, "check-results", file.string()}, 20); }

std::string thrown(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "(no exception)";
}

}  // namespace

TEST_CASE("the bundle for slider_crank: scripts, README and the source tree") {
  const fs::path dir = scratch("real");
  const fs::path zip = dir / "autograder.zip";
  writeAutograder("slider_crank", DYNLAB_SOURCE_DIR, zip.string());
  const auto list = readZip(zip);
  const auto entries = asMap(list);

  REQUIRE(entries.count("setup.sh"));
  REQUIRE(entries.count("run_autograder"));
  REQUIRE(entries.count("README.md"));
  CHECK(entries.at("setup.sh").mode == 0755);
  CHECK(entries.at("run_autograder").mode == 0755);
  CHECK(entries.at("README.md").mode == 0644);
  CHECK(entries.count("source/CMakeLists.txt"));
  CHECK(entries.count("source/labs/slider_crank/slider_crank.json"));
  CHECK(entries.count("source/grading/plot.cpp"));
  CHECK(entries.count("source/tests/CMakeLists.txt"));  // the top CMakeLists adds tests/
  CHECK(entries.count("source/scripts/setup"));
  CHECK(entries.at("source/scripts/setup").mode == 0755);
  CHECK(entries.at("source/CMakeLists.txt").data == readBytes(fs::path(DYNLAB_SOURCE_DIR) / "CMakeLists.txt"));

  // Sorted, and nothing from builds, runs, git or temp files.
  for (size_t i = 1; i < list.size(); ++i) CHECK(list[i - 1].first < list[i].first);
  for (const auto& [name, e] : list) {
    INFO(name);
    const fs::path folder = fs::path(name).parent_path();
    for (const auto& part : folder) CHECK(part.string().rfind("build", 0) != 0);
    CHECK(name.find("/out/") == std::string::npos);
    CHECK(name.find("/.") == std::string::npos);
    CHECK(name.find(".tmp") == std::string::npos);
  }

  // The scripts name the lab, the package choice for the image and the one target.
  const std::string run = entries.at("run_autograder").data, setup = entries.at("setup.sh").data;
  CHECK(run.rfind("#!/usr/bin/env bash", 0) == 0);
  CHECK(run.find("lab=\"slider_crank\"") != std::string::npos);
  CHECK(run.find("--lab \"$lab\"") != std::string::npos);
  CHECK(setup.find("scripts/autograder-packages") != std::string::npos);
  CHECK(setup.find("--target dynlab") != std::string::npos);
  CHECK(entries.at("README.md").data.find("\"lab\": \"slider_crank\"") != std::string::npos);
  CHECK(entries.at("README.md").data.find("kp_x") != std::string::npos);
  CHECK(entries.at("README.md").data.find("check-results") != std::string::npos);  // the local check needs no python3

  // Every relative link of the packed README (the course notes, its images) is packed too.
  const std::string top = entries.at("source/README.md").data;
  const std::regex link(R"(\]\(([^)#:]+)(#[^)]*)?\))");
  int links = 0;
  for (auto it = std::sregex_iterator(top.begin(), top.end(), link); it != std::sregex_iterator(); ++it, ++links)
    CHECK_MESSAGE(entries.count("source/" + (*it)[1].str()), "README.md links to " << (*it)[1].str());
  CHECK(links >= 2);
  CHECK(entries.count("source/docs/constrained-dynamics.md"));
}

TEST_CASE("two writes give the same bytes") {
  const fs::path dir = scratch("same");
  writeAutograder("slider_crank", DYNLAB_SOURCE_DIR, (dir / "a.zip").string());
  std::this_thread::sleep_for(std::chrono::milliseconds(2100));  // DOS times have 2 s resolution
  writeAutograder("slider_crank", DYNLAB_SOURCE_DIR, (dir / "b.zip").string());
  const std::string a = readBytes(dir / "a.zip"), b = readBytes(dir / "b.zip");
  CHECK(a.size() > 1000);
  CHECK(a == b);
  CHECK(!fs::exists(dir / "a.zip.tmp"));
}

TEST_CASE("build output, VCS data and temp files stay out of the bundle") {
  const fs::path src = scratch("tree") / "src";
  writeText(src / "CMakeLists.txt", "project(x)\n");
  writeText(src / "README.md", "# x\n");
  writeText(src / "labs/demo/demo.json", "{\"title\": \"Demo\", \"gains\": {\"k\": {\"value\": 1.5}}}\n");
  writeText(src / "labs/build/junk.o", "x");
  writeText(src / "labs/build-debug/junk.o", "x");
  writeText(src / "app/out/trace.csv", "x");
  writeText(src / "app/cli/main.cpp", "int main() {}\n");
  writeText(src / "grading/half.json.tmp", "x");
  writeText(src / "grading/.staging/results.json", "x");
  writeText(src / "physics/.git/HEAD", "x");
  writeText(src / "scripts/build", "#!/bin/sh\n", true);  // a file named build is source, not output
  writeText(src / "build/dynlab", "x");                     // top level: not a listed folder
  writeText(src / "notes.txt", "x");

  const fs::path zip = src.parent_path() / "demo.zip";
  writeAutograder("demo", src.string(), zip.string());
  std::vector<std::string> names;
  for (const auto& [name, e] : readZip(zip)) names.push_back(name);
  const std::vector<std::string> expected = {"README.md",
                                             "run_autograder",
                                             "setup.sh",
                                             "source/CMakeLists.txt",
                                             "source/README.md",
                                             "source/app/cli/main.cpp",
                                             "source/labs/demo/demo.json",
                                             "source/scripts/build"};
  CHECK(names == expected);
  const auto entries = asMap(readZip(zip));
  CHECK(entries.at("source/scripts/build").mode == 0755);
  CHECK(entries.at("source/app/cli/main.cpp").mode == 0644);
  CHECK(entries.at("README.md").data.find("Demo") != std::string::npos);

  // A zip written inside a packed folder does not pack itself.
  writeAutograder("demo", src.string(), (src / "app" / "bundle.zip").string());
  for (const auto& [name, e] : readZip(src / "app" / "bundle.zip")) CHECK(name.find("bundle.zip") == std::string::npos);
}

TEST_CASE("errors name the zip path") {
  const fs::path dir = scratch("errors");
  const std::string bad_dir = (dir / "no" / "such" / "dir" / "a.zip").string();
  CHECK(thrown([&] { writeAutograder("slider_crank", DYNLAB_SOURCE_DIR, bad_dir); }).find(bad_dir) != std::string::npos);
  const std::string zip = (dir / "a.zip").string();
  CHECK(thrown([&] { writeAutograder("no_such_lab", DYNLAB_SOURCE_DIR, zip); }).find(zip) != std::string::npos);
  CHECK(thrown([&] { writeAutograder("../slider_crank", DYNLAB_SOURCE_DIR, zip); }).find(zip) != std::string::npos);
  CHECK(thrown([&] { writeAutograder("slider_crank", dir.string(), zip); }).find(zip) != std::string::npos);
  CHECK(!fs::exists(zip));
}

// run_autograder, unpacked from the zip, against fake dynlab binaries.
struct Sandbox {
  fs::path dir, submission, results, script, dynlab;
  explicit Sandbox(const std::string& name) : dir(scratch("run_" + name)) {
    submission = dir / "submission";
    results = dir / "results";
    script = dir / "run_autograder";
    dynlab = dir / "dynlab";
    fs::create_directories(submission);
    writeText(script, runAutograderText(), true);
  }
  // run_autograder as the real bundle holds it (packed once: the zip takes a while).
  static const std::string& runAutograderText() {
    static const std::string text = [] {
      const fs::path zip = scratch("run_bundle") / "bundle.zip";
      writeAutograder("slider_crank", DYNLAB_SOURCE_DIR, zip.string());
      return asMap(readZip(zip)).at("run_autograder").data;
    }();
    return text;
  }
  // A fake `dynlab grade` (body); `dynlab check-results` and `dynlab submission-file` stay the real ones.
  void fakeDynlab(const std::string& body) {
    writeText(dynlab, "#!/usr/bin/env bash\n{ [ \"$1\" = check-results ] || [ \"$1\" = submission-file ]; } && exec '" + std::string(DYNLAB_BIN) + "' \"$@\"\n" +
                          body + "\n", true);
  }
  // A fake that writes `json` as its results.json and exits 0.
  void fakeResults(const std::string& json) {
    writeText(dir / "fake_results.json", json);
    fakeDynlab("out=\"${@: -1}\"; cp '" + (dir / "fake_results.json").string() + "' \"$out/results.json\"; exit 0");
  }
  std::string log() const { return readBytes(dir / "log.txt"); }
  // Runs the script (under a timeout, with env added to its environment; its output in log.txt);
  // returns results.json parsed. It must parse, and the real check-results must accept it.
  nlohmann::json run(const std::vector<std::pair<std::string, std::string>>& env = {}) {
    dyn::ProcessOptions o;
    o.set_env = {{"DYNLAB_BIN", dynlab.string()},
                 {"DYNLAB_SUBMISSION_DIR", submission.string()},
                 {"DYNLAB_RESULTS_DIR", results.string()}};
    o.set_env.insert(o.set_env.end(), env.begin(), env.end());
    o.timeout_s = 60;
    fs::remove(dir / "log.txt");
    o.stdout_file = o.stderr_file = (dir / "log.txt").string();
    o.append = true;  // both into one file (2>&1)
    CHECK(dyn::runProgram({"bash", script.string()}, o).code == 0);
    INFO(log());
    REQUIRE(fs::is_regular_file(results / "results.json"));
    const Ran check = checkResults(results / "results.json");
    CHECK_MESSAGE(check.code == 0, check.err);
    return nlohmann::json::parse(readBytes(results / "results.json"));
  }
};

TEST_CASE("run_autograder: a dynlab that fails without results still leaves a valid results.json") {
  Sandbox box("fails");
  writeText(box.submission / "submission.json", "{\"lab\": \"slider_crank\", \"gains\": {}}");
  writeText(box.results / "results.json", "{\"score\": 100}");  // stale: must not survive
  box.fakeDynlab("echo 'boom \" \\\\ {' >&2; exit 1");
  const auto r = box.run();
  CHECK(r.at("score").get<double>() == 0.0);
  CHECK(r.at("tests").empty());
  CHECK(r.at("output").get<std::string>().find("exit status 1") != std::string::npos);
  // Also when python3 is absent the file is the same (written by printf, not by python).
  CHECK(readBytes(box.results / "results.json").find("\"score\": 0.0") != std::string::npos);
}

TEST_CASE("run_autograder: dynlab's own results.json is kept, and it gets the lab and the file") {
  Sandbox box("ok");
  writeText(box.submission / "my gains.json", "{}");  // the only JSON, not named submission.json
  box.fakeDynlab("printf '%s\\n' \"$@\" > \"$(dirname \"$0\")/args.txt\"\n"
                 "out=\"\"; while [ $# -gt 0 ]; do [ \"$1\" = --out ] && out=\"$2\"; shift; done\n"
                 "echo '{\"score\": 7.5, \"tests\": []}' > \"$out/results.json\"; exit 0");
  const auto r = box.run();
  CHECK(r.at("score").get<double>() == 7.5);
  const std::string args = readBytes(box.dir / "args.txt");
  CHECK(args == "grade\n" + (box.submission / "my gains.json").string() + "\n--time-budget\n300\n--lab\nslider_crank\n--inline-plots\n--out\n" +
                    box.results.string() + "\n");
}

TEST_CASE("run_autograder: garbage, timeouts, a missing binary and missing files become score 0") {
  SUBCASE("dynlab writes a broken results.json") {
    Sandbox box("garbage");
    writeText(box.submission / "submission.json", "{}");
    box.fakeDynlab("out=\"${@: -1}\"; echo '{\"score\": ' > \"$out/results.json\"; exit 0");
    CHECK(box.run().at("score").get<double>() == 0.0);
  }
  SUBCASE("dynlab runs past the time limit") {
    Sandbox box("slow");
    writeText(box.submission / "submission.json", "{}");
    box.fakeDynlab("sleep 30");
    const auto r = box.run({{"DYNLAB_TIME_LIMIT", "1"}});
    CHECK(r.at("score").get<double>() == 0.0);
    CHECK(r.at("output").get<std::string>().find("longer than 1 seconds") != std::string::npos);
  }
  SUBCASE("dynlab was never built") {
    Sandbox box("nobinary");
    writeText(box.submission / "submission.json", "{}");
    CHECK(box.run().at("output").get<std::string>().find("not built") != std::string::npos);
  }
  SUBCASE("no JSON uploaded") {
    Sandbox box("nofile");
    writeText(box.submission / "answer.txt", "kp_x = 400");
    box.fakeDynlab("exit 0");
    const auto r = box.run();
    CHECK(r.at("score").get<double>() == 0.0);
    CHECK(r.at("output").get<std::string>().find("{\"lab\": \"slider_crank\"") != std::string::npos);
  }
  SUBCASE("several JSON files, none named submission.json") {
    Sandbox box("several");
    writeText(box.submission / "a.json", "{}");
    writeText(box.submission / "b.json", "{}");
    box.fakeDynlab("exit 0");
    CHECK(box.run().at("output").get<std::string>().find("several JSON files") != std::string::npos);
  }
}

// --- dynlab check-results, and run_autograder's use of it ---

namespace {

// A results.json using every field Gradescope documents, each with an allowed value.
const char* kValidResults = R"({"score": 7.5, "execution_time": 12, "output": "é ✓ 😀", "output_format": "md",
  "test_output_format": "ansi", "test_name_format": "text", "visibility": "after_due_date",
  "stdout_visibility": "hidden", "extra_data": {"lab": "slider_crank", "n": [1, 2]},
  "tests": [{"name": "a", "number": "1.2", "score": 2, "max_score": 5.0, "status": "failed", "output": "...",
             "output_format": "simple_format", "name_format": "html", "tags": ["nominal"],
             "visibility": "after_published", "extra_data": {}},
            {"name": "b", "status": "passed"}],
  "leaderboard": [{"name": "tracking RMS", "value": 0.012, "order": "asc"}, {"name": "speed", "value": -3}]})";

struct BadCase {
  const char* json;
  const char* pointer;   // where check-results must point
  const char* expected;  // a part of what it must say was expected
};

// One wrong type or value per field; each must be reported at its JSON pointer.
const BadCase kBadCases[] = {
    {R"({"score": "lots", "tests": 5})", "/score", "a number"},
    {R"({"score": 1, "tests": 5})", "/tests", "an array"},
    {R"({"score": true})", "/score", "a number"},
    {R"({"score": 1, "execution_time": "12 s"})", "/execution_time", "a number"},
    {R"({"score": 1, "output": 3})", "/output", "a string"},
    {R"({"score": 1, "output_format": "markdown"})", "/output_format", "\"md\""},
    {R"({"score": 1, "test_output_format": null})", "/test_output_format", "\"ansi\""},
    {R"({"score": 1, "visibility": "public"})", "/visibility", "\"after_due_date\""},
    {R"({"score": 1, "stdout_visibility": 1})", "/stdout_visibility", "\"hidden\""},
    {R"({"score": 1, "extra_data": []})", "/extra_data", "an object"},
    {R"({"score": 1, "scroe": 2})", "/scroe", "Gradescope's keys"},
    {R"({"score": 1, "tests": [3]})", "/tests/0", "an object"},
    {R"({"score": 1, "tests": [{"name": 1}]})", "/tests/0/name", "a string"},
    {R"({"score": 1, "tests": [{"name": "a"}, {"score": "2"}]})", "/tests/1/score", "a number"},
    {R"({"score": 1, "tests": [{"max_score": [5]}]})", "/tests/0/max_score", "a number"},
    {R"({"score": 1, "tests": [{"status": "ok"}]})", "/tests/0/status", "\"passed\", \"failed\""},
    {R"({"score": 1, "tests": [{"visibility": "later"}]})", "/tests/0/visibility", "\"visible\""},
    {R"({"score": 1, "tests": [{"output_format": "rst"}]})", "/tests/0/output_format", "\"text\""},
    {R"({"score": 1, "tests": [{"extra_data": "x"}]})", "/tests/0/extra_data", "an object"},
    {R"({"score": 1, "tests": [{"tags": ["a", 2]}]})", "/tests/0/tags/1", "a string"},
    {R"({"score": 1, "tests": [{"number": 1.2}]})", "/tests/0/number", "a string"},
    {R"({"score": 1, "tests": [{"naem": "a"}]})", "/tests/0/naem", "Gradescope's keys"},
    {R"({"tests": [{"name": "a"}]})", "/tests/0/score", "a number"},
    {R"({"output": "no score anywhere"})", "/score", "a number"},
    {R"({"score": 1, "leaderboard": {}})", "/leaderboard", "an array"},
    {R"({"score": 1, "leaderboard": [{"name": "a", "value": "fast"}]})", "/leaderboard/0/value", "a number"},
    {R"({"score": 1, "leaderboard": [{"name": "a"}]})", "/leaderboard/0/value", "required"},
    {R"({"score": 1, "leaderboard": [{"value": 1}]})", "/leaderboard/0/name", "required"},
    {R"({"score": 1, "leaderboard": [{"name": "a", "value": 1, "order": "up"}]})", "/leaderboard/0/order", "\"asc\", \"desc\""},
    {R"({"score": 1, "tests": [{"a/b~c": 1}]})", "/tests/0/a~1b~0c", "Gradescope's keys"},
    {R"([{"score": 1}])", "(the whole file)", "a JSON object"},
};

// The bad-input contract: exit 2, nothing on stdout, one line "error: FILE: ..." holding each part.
void checkRejected(const Ran& r, const std::vector<std::string>& parts) { dyn::test::cli::checkRefused(r, parts); }

}  // namespace

TEST_CASE("dynlab check-results: a valid results.json passes, and so do dynlab grade's own") {
  const fs::path dir = scratch("check_valid");
  writeText(dir / "full.json", kValidResults);
  const Ran r = checkResults(dir / "full.json");
  CHECK(r.code == 0);
  CHECK(r.err.empty());
  CHECK(r.out == (dir / "full.json").string() + ": a valid Gradescope results.json\n");
  writeText(dir / "minimal.json", R"({"score": 0})");
  CHECK(checkResults(dir / "minimal.json").code == 0);
  writeText(dir / "tests_only.json", R"({"tests": [{"score": 1}, {"score": 2, "max_score": 2}]})");
  CHECK(checkResults(dir / "tests_only.json").code == 0);

  // The real grader's results: a graded example and a rejected submission.
  const std::string bin = DYNLAB_BIN, src = DYNLAB_SOURCE_DIR;
  writeText(dir / "bad_gains.json", R"({"lab": "slider_crank", "gains": {"kp_x": "high"}})");
  for (const std::string& sub : {src + "/labs/slider_crank/examples/mediocre.json", (dir / "bad_gains.json").string()}) {
    INFO(sub);
    const fs::path out = dir / fs::path(sub).stem();
    captured({bin, "grade", sub, "--no-plots", "--out", out.string()});
    const Ran own = checkResults(out / "results.json");
    CHECK_MESSAGE(own.code == 0, own.err);
  }
}

TEST_CASE("dynlab check-results: each wrong type or value fails, naming the file and the JSON path") {
  const fs::path dir = scratch("check_types");
  for (const BadCase& c : kBadCases) {
    INFO(c.json);
    writeText(dir / "results.json", c.json);
    checkRejected(checkResults(dir / "results.json"),
                  {(dir / "results.json").string() + ": ", std::string(c.pointer) + ": expected ", c.expected});
  }
}

TEST_CASE("dynlab check-results: not UTF-8, not JSON, or not a regular file") {
  const fs::path dir = scratch("check_bytes");
  const std::pair<std::string, std::string> cases[] = {
      {"{\"score\": 1, \"output\": \"\xff\"}", "expected UTF-8 text, got byte 0xff at offset 24"},
      {"{\"score\": 1, \"output\": \"\xc0\x80\"}", "expected UTF-8 text, got byte 0xc0"},      // overlong NUL
      {"{\"score\": 1, \"output\": \"\xed\xa0\x80\"}", "expected UTF-8 text, got byte 0xed"},  // a surrogate
      {"{\"score\": 1, \"output\": \"\xe2\x9c\"}", "expected UTF-8 text, got byte 0xe2"},      // cut short
      {"\xef\xbb\xbf{\"score\": 1}", "byte-order mark"},
      {"", "got an empty file"},
      {"{\"score\": ", "expected JSON, got parse error at line 1"},
      {"{\"score\": 1e400}", "expected JSON, got number overflow"},
      {"{\"score\": 1} {}", "expected JSON, got parse error"},
  };
  for (const auto& [bytes, says] : cases) {
    INFO(bytes);
    writeText(dir / "results.json", bytes);
    checkRejected(checkResults(dir / "results.json"), {(dir / "results.json").string() + ": ", says});
  }
  // A FIFO nobody writes to must be refused at once, not waited on; so must folders and devices.
  REQUIRE(::mkfifo((dir / "fifo.json").c_str(), 0644) == 0);
  const auto started = std::chrono::steady_clock::now();
  checkRejected(checkResults(dir / "fifo.json"), {"fifo.json: expected a regular file, got a FIFO"});
  CHECK(std::chrono::steady_clock::now() - started < std::chrono::seconds(10));
  fs::create_directories(dir / "folder.json");
  checkRejected(checkResults(dir / "folder.json"), {"folder.json: expected a regular file, got a directory"});
  checkRejected(checkResults("/dev/null"), {"/dev/null: expected a regular file, got a device"});
  checkRejected(checkResults(dir / "missing.json"), {"missing.json: expected a readable file, got no such file"});
  CHECK(captured({DYNLAB_BIN, "check-results"}).code == 2);  // FILE is required
}

TEST_CASE("run_autograder: dynlab's results.json of the wrong shape is replaced by a valid one naming the path") {
  SUBCASE("a valid results.json is kept as it is") {
    Sandbox box("kept");
    writeText(box.submission / "submission.json", "{}");
    box.fakeResults(kValidResults);
    CHECK(box.run() == nlohmann::json::parse(kValidResults));
  }
  SUBCASE("each wrong type or value") {
    for (const BadCase& c : kBadCases) {
      INFO(c.json);
      Sandbox box("wrong");
      writeText(box.submission / "submission.json", "{}");
      box.fakeResults(c.json);
      const auto r = box.run();
      CHECK(r.at("score").get<double>() == 0.0);
      const std::string out = r.at("output").get<std::string>();
      CHECK(out.find("would not accept") != std::string::npos);
      CHECK(out.find(std::string(c.pointer) + ": expected ") != std::string::npos);
      CHECK(box.log().find(c.pointer) != std::string::npos);  // the staff's log says why too
    }
  }
  SUBCASE("a results.json that is not UTF-8") {
    Sandbox box("latin1");
    writeText(box.submission / "submission.json", "{}");
    box.fakeResults("{\"score\": 1, \"output\": \"caf\xe9\"}");
    CHECK(box.run().at("output").get<std::string>().find("expected UTF-8 text") != std::string::npos);
  }
  SUBCASE("a FIFO where results.json should be: no hang, and it is replaced") {
    Sandbox box("fifo");
    writeText(box.submission / "submission.json", "{}");
    box.fakeDynlab("out=\"${@: -1}\"; mkfifo \"$out/results.json\"; exit 0");
    CHECK(box.run().at("output").get<std::string>().find("got a FIFO") != std::string::npos);
  }
}

// A folder of links to the tools run_autograder and the fakes use, and nothing else: no python3.
fs::path pathWithoutPython(const fs::path& dir) {
  const fs::path bin = dir / "bin";
  fs::create_directories(bin);
  std::vector<std::string> system_path;
  std::stringstream path(std::getenv("PATH") ? std::getenv("PATH") : "/usr/bin:/bin");
  for (std::string d; std::getline(path, d, ':');) system_path.push_back(d);
  for (const char* tool : {"bash", "env", "find", "sort", "mkdir", "rm", "mv", "cp", "timeout", "sed", "tr", "cat", "sleep"}) {
    for (const auto& d : system_path) {
      if (fs::exists(fs::path(d) / tool)) {
        fs::create_symlink(fs::path(d) / tool, bin / tool);
        break;
      }
    }
  }
  return bin;
}

TEST_CASE("run_autograder: with no python3 on PATH, results.json is still checked for real") {
  Sandbox box("nopython");
  const fs::path bin = pathWithoutPython(box.dir);
  const std::vector<std::pair<std::string, std::string>> env = {{"PATH", bin.string()}};
  for (const char* python : {"python3", "python"}) CHECK_FALSE(fs::exists(bin / python));  // `command -v` finds neither
  writeText(box.submission / "submission.json", "{}");

  box.fakeResults(R"({"score": "lots", "tests": 5})");  // starts with '{': the old fallback took it
  auto r = box.run(env);
  CHECK(r.at("score").get<double>() == 0.0);
  CHECK(r.at("output").get<std::string>().find("/score: expected a number, got \"lots\"") != std::string::npos);

  box.fakeResults(kValidResults);
  CHECK(box.run(env).at("score").get<double>() == 7.5);
}

TEST_CASE("run_autograder: DYNLAB_TIME_LIMIT must be whole seconds from 1 to 86400, else the default is used") {
  for (const std::string bad : {"0", "000", "abc", "10m", "-5", "1.5", "86401", "99999999999999999999", " "}) {
    INFO("DYNLAB_TIME_LIMIT=" << bad);
    Sandbox box("limit");
    writeText(box.submission / "submission.json", "{}");
    box.fakeResults(R"({"score": 3})");
    CHECK(box.run({{"DYNLAB_TIME_LIMIT", bad}}).at("score").get<double>() == 3.0);  // graded, under the default
    CHECK(box.log().find("expected whole seconds from 1 to 86400; using the default, 540") != std::string::npos);
  }
  for (const std::string good : {"", "1", "007", "86400"}) {
    INFO("DYNLAB_TIME_LIMIT=" << good);
    Sandbox box("limit_ok");
    writeText(box.submission / "submission.json", "{}");
    box.fakeResults(R"({"score": 3})");
    CHECK(box.run({{"DYNLAB_TIME_LIMIT", good}}).at("score").get<double>() == 3.0);
    CHECK(box.log().find("DYNLAB_TIME_LIMIT") == std::string::npos);
  }
  // 0 no longer turns the limit off: a hanging grader is still stopped (here after a limit of 2 s).
  Sandbox box("limit_applies");
  writeText(box.submission / "submission.json", "{}");
  box.fakeDynlab("sleep 30");
  const auto r = box.run({{"DYNLAB_TIME_LIMIT", "02"}});
  CHECK(r.at("output").get<std::string>().find("longer than 2 seconds") != std::string::npos);
}

TEST_CASE("run_autograder with the real dynlab: an example is graded and its results pass the check") {
  Sandbox box("real");
  box.dynlab = DYNLAB_BIN;
  fs::copy_file(fs::path(DYNLAB_SOURCE_DIR) / "labs/slider_crank/examples/mediocre.json", box.submission / "submission.json");
  const auto r = box.run();
  CHECK(r.at("score").get<double>() > 0.0);
  CHECK(r.at("tests").size() > 3);
  CHECK(box.log().find("no grade from dynlab") == std::string::npos);
  // The student sees each simulated test's plot: HTML output with the PNG inline.
  int inline_plots = 0;
  for (const auto& t : r.at("tests")) {
    CHECK(t.at("output_format") == "html");
    inline_plots += t.at("output").get<std::string>().find("src=\"data:image/png;base64,iVBORw0KGgo") != std::string::npos;
  }
  CHECK(inline_plots == 8);
}

TEST_CASE("run_autograder: a link out of the submission, a FIFO or a device is refused unread") {
  // A fake dynlab that leaves a mark: it must not even be started on such a file.
  const auto refused = [](Sandbox& box) {
    box.fakeDynlab("touch '" + (box.dir / "ran").string() + "'; exit 0");
    const auto started = std::chrono::steady_clock::now();
    const auto r = box.run();
    CHECK(std::chrono::steady_clock::now() - started < std::chrono::seconds(30));
    CHECK(!fs::exists(box.dir / "ran"));
    CHECK(r.at("score").get<double>() == 0.0);
    return r.at("output").get<std::string>();
  };
  SUBCASE("submission.json is a symlink to a file outside: none of its content is quoted") {
    Sandbox box("symlink_out");
    writeText(box.dir / "secret.txt", "{\"TOPSECRET-7f3a\": oops");
    fs::create_symlink(box.dir / "secret.txt", box.submission / "submission.json");
    const std::string out = refused(box);
    CHECK(out.find("symbolic link") != std::string::npos);
    CHECK(readBytes(box.results / "results.json").find("TOPSECRET") == std::string::npos);
    CHECK(box.log().find("TOPSECRET") == std::string::npos);
  }
  SUBCASE("the only JSON file is a relative symlink climbing out") {
    Sandbox box("symlink_rel");
    writeText(box.dir / "secret.json", "{\"TOPSECRET-7f3a\": 1}");
    fs::create_symlink("../secret.json", box.submission / "answer.json");
    CHECK(refused(box).find("symbolic link") != std::string::npos);
    CHECK(readBytes(box.results / "results.json").find("TOPSECRET") == std::string::npos);
  }
  SUBCASE("submission.json is a FIFO nobody writes to") {
    Sandbox box("fifo_in");
    REQUIRE(::mkfifo((box.submission / "submission.json").c_str(), 0644) == 0);
    CHECK(refused(box).find("not a regular file") != std::string::npos);
  }
  SUBCASE("submission.json is a link to a device") {
    Sandbox box("device_in");
    fs::create_symlink("/dev/zero", box.submission / "submission.json");
    CHECK(refused(box).find("symbolic link") != std::string::npos);
  }
  SUBCASE("submission.json is a folder: not a file to grade (the shared rule), so none is found") {
    Sandbox box("folder_in");
    fs::create_directories(box.submission / "submission.json");
    CHECK(refused(box).find("no JSON file") != std::string::npos);
  }
}

TEST_CASE("run_autograder: a link inside the submission is graded as its target; macOS leftovers are ignored") {
  Sandbox box("inside");
  writeText(box.submission / "work" / "gains.json", "{}");
  fs::create_symlink("work/gains.json", box.submission / "submission.json");
  box.fakeDynlab("printf '%s\\n' \"$2\" > '" + (box.dir / "file.txt").string() + "'\n" + "out=\"\"; while [ $# -gt 0 ]; do [ \"$1\" = --out ] && out=\"$2\"; shift; done\n" +
                 "echo '{\"score\": 4, \"tests\": []}' > \"$out/results.json\"; exit 0");
  CHECK(box.run().at("score").get<double>() == 4.0);
  CHECK(readBytes(box.dir / "file.txt") == fs::canonical(box.submission / "work" / "gains.json").string() + "\n");

  Sandbox mac("macos");
  writeText(mac.submission / "x.json", "{}");
  writeText(mac.submission / "._x.json", "\x05");
  writeText(mac.submission / "__MACOSX" / "._x.json", "\x05");
  mac.fakeResults(R"({"score": 2})");
  CHECK(mac.run().at("score").get<double>() == 2.0);  // not "several JSON files"
}

TEST_CASE("run_autograder: a grader killed by a signal before the limit is a crash, not a timeout") {
  Sandbox box("killed");
  writeText(box.submission / "submission.json", "{}");
  box.fakeDynlab("kill -KILL $$");
  const std::string out = box.run({{"DYNLAB_TIME_LIMIT", "100"}}).at("output").get<std::string>();
  CHECK(out.find("exit status 137") != std::string::npos);
  CHECK(out.find("longer than") == std::string::npos);
}
