// Tests for app/autograder: what the Gradescope zip holds (scripts executable, the source tree
// without build output), byte-identical rewrites, errors naming the path, and run_autograder's
// promise of a valid results.json, run for real against fake dynlab binaries.
#include "app/autograder.h"

#include <doctest/doctest.h>

#include "tests/test_files.h"
#include <sys/stat.h>
#include <zip.h>

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

  // The scripts name the lab, the one package list and the one target.
  const std::string run = entries.at("run_autograder").data, setup = entries.at("setup.sh").data;
  CHECK(run.rfind("#!/usr/bin/env bash", 0) == 0);
  CHECK(run.find("lab=\"slider_crank\"") != std::string::npos);
  CHECK(run.find("--lab \"$lab\"") != std::string::npos);
  CHECK(setup.find("scripts/setup") != std::string::npos);
  CHECK(setup.find("--target dynlab") != std::string::npos);
  CHECK(entries.at("README.md").data.find("\"lab\": \"slider_crank\"") != std::string::npos);
  CHECK(entries.at("README.md").data.find("kp_x") != std::string::npos);
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
  writeText(src / "app/main.cpp", "int main() {}\n");
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
                                             "source/app/main.cpp",
                                             "source/labs/demo/demo.json",
                                             "source/scripts/build"};
  CHECK(names == expected);
  const auto entries = asMap(readZip(zip));
  CHECK(entries.at("source/scripts/build").mode == 0755);
  CHECK(entries.at("source/app/main.cpp").mode == 0644);
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
    writeAutograder("slider_crank", DYNLAB_SOURCE_DIR, (dir / "bundle.zip").string());
    writeText(script, asMap(readZip(dir / "bundle.zip")).at("run_autograder").data, true);
  }
  void fakeDynlab(const std::string& body) { writeText(dynlab, "#!/usr/bin/env bash\n" + body + "\n", true); }
  // Runs the script; returns results.json parsed (it must parse).
  nlohmann::json run(const std::string& env = "") {
    const std::string cmd = "env DYNLAB_BIN='" + dynlab.string() + "' DYNLAB_SUBMISSION_DIR='" + submission.string() +
                            "' DYNLAB_RESULTS_DIR='" + results.string() + "' " + env + " bash '" + script.string() +
                            "' > '" + (dir / "log.txt").string() + "' 2>&1";
    CHECK(std::system(cmd.c_str()) == 0);
    INFO(readBytes(dir / "log.txt"));
    REQUIRE(fs::exists(results / "results.json"));
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
  CHECK(args == "grade\n" + (box.submission / "my gains.json").string() + "\n--lab\nslider_crank\n--out\n" +
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
    const auto r = box.run("DYNLAB_TIME_LIMIT=1");
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
