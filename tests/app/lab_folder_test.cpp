// A lab folder is input too: course staff run check-lab on labs they download. A lab made with
// new-lab in a folder outside the tree (--labs) is given a hostile example file name and broken metric
// windows; check-lab and run must treat the name as data (no shell runs it) and refuse the windows at
// their JSON path, naming the lab's own file.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include "app/shared/process.h"
#include "tests/app/cli_run.h"

using json = nlohmann::json;
using namespace dyn::test::cli;

namespace {

// dynlab args in dir (no shell), with the labs of home/labs beside the tree's (--labs; empty: the tree's only).
Result dynlabIn(const TempDir& dir, const fs::path& home, const std::vector<std::string>& args) {
  dyn::ProcessOptions o;
  o.timeout_s = 600;
  return dynlab(dir, home.empty() ? args : cat(args, {"--labs", (home / "labs").string()}), o);
}

// A copy of the five-bar lab as `name` in home/labs (new-lab), its JSON path returned.
fs::path copyFivebar(const TempDir& dir, const fs::path& home, const std::string& name) {
  fs::create_directories(home / "labs");
  const Result r = dynlabIn(dir, {}, {"new-lab", name, "--from", "fivebar", "--labs", (home / "labs").string()});
  INFO(r.err);
  REQUIRE(r.code == 0);
  return home / "labs" / name / (name + ".json");
}

}  // namespace

TEST_CASE("check-lab: an example's file name is one argument, never shell text") {
  const TempDir dir("lab_folder_shell");
  const fs::path home = dir / "home";
  const fs::path config = copyFivebar(dir, home, "hi");
  const fs::path examples = config.parent_path() / "examples";
  // Sorted first among the examples, so the cli check grades it: under a shell it created ./x.
  const std::string hostile = "'$(touch${IFS}x)'.json";
  fs::copy_file(examples / "joint_pd.json", examples / hostile);
  const Result r = dynlabIn(dir, home, {"check-lab", "hi"});
  INFO(r.out, r.err);
  for (const fs::path& where : {dir.path, config.parent_path(), examples, fs::current_path()}) CHECK_FALSE(fs::exists(where / "x"));
  // The cli check graded the file by its name (a shell would have split or expanded it).
  CHECK(r.out.find("  ok    cli") != std::string::npos);
  CHECK(r.out.find(hostile) != std::string::npos);  // listed among the examples' shares
}

TEST_CASE("a data lab's metric window must lie inside its run: refused at the JSON path, in the lab's own file") {
  const TempDir dir("lab_folder_window");
  const fs::path home = dir / "home";
  const fs::path config = copyFivebar(dir, home, "win");
  const json original = json::parse(readFile(config));
  const double duration = original["simulation"]["duration"];
  REQUIRE(duration < 100);
  struct Case {
    const char* key;
    json value;
    const char* expected;
  };
  const Case cases[] = {{"from", 100.0, "expected a start in [0, "},       // after the run: no sample (was full marks)
                        {"from", -1.0, "expected a start in [0, "},        // before it
                        {"to", 100.0, "expected an end in ["},            // past it
                        {"to", 0.7, "expected an end in ["}};              // an empty window: to = from
  for (const Case& c : cases) {
    json d = original;
    d["metrics"]["e_circle_rms"][c.key] = c.value;
    writeFile(config, d.dump(1));
    CAPTURE(c.key);
    CAPTURE(c.value.dump());
    // run: one line, exit 2, naming the file, the path and the run's length.
    const Result run = dynlabIn(dir, home, {"run", "win", "--engine", "hand", "--out", "run"});
    CHECK(run.code == 2);
    CHECK(std::count(run.err.begin(), run.err.end(), '\n') == 1);
    CHECK(run.err.find(config.string()) != std::string::npos);
    CHECK(run.err.find("/metrics/e_circle_rms/" + std::string(c.key)) != std::string::npos);
    CHECK(run.err.find(c.expected) != std::string::npos);
    CHECK(run.err.find("the run lasts") != std::string::npos);
    CHECK_FALSE(fs::exists(dir / "run"));
  }
  // check-lab's failing line names the lab's own file and the metric's path, not a scratch config.json.
  json d = original;
  d["metrics"]["e_circle_rms"]["from"] = 100.0;
  writeFile(config, d.dump(1));
  const Result check = dynlabIn(dir, home, {"check-lab", "win", "--skip-cli"});
  INFO(check.out);
  CHECK(check.code == 1);
  std::istringstream lines(check.out);
  std::string line, config_line;
  while (std::getline(lines, line))
    if (line.find("FAIL  config") != std::string::npos) config_line = line;
  CHECK(config_line.find(config.string()) != std::string::npos);
  CHECK(config_line.find("/metrics/e_circle_rms/from") != std::string::npos);
  CHECK(check.out.find("config.json") == std::string::npos);
  // One bad config is one FAIL line and a line saying the rest did not run, not a FAIL from every check.
  std::size_t fails = 0;
  for (std::size_t at = check.out.find("  FAIL  "); at != std::string::npos; at = check.out.find("  FAIL  ", at + 1)) ++fails;
  CHECK(fails == 2);
  CHECK(check.out.find("FAIL  other checks") != std::string::npos);
}
