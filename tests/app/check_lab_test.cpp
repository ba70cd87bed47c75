// dynlab check-lab LAB: the lab contract (app/cli/authoring/lab_check.h) on one lab, from the command line: every
// check printed with ok/FAIL and a reason, the shares and the passive drift; exit 0 when all pass,
// 1 when one fails (a lab whose default gains are the instructor's), 2 on bad input.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>

#include "tests/app/cli_run.h"

using namespace dyn::test::cli;
using json = nlohmann::json;

namespace {

// The check lines: "  ok    NAME  detail" or "  FAIL  NAME  detail".
std::vector<std::string> checkLines(const std::string& out, const std::string& status) {
  std::vector<std::string> lines;
  std::istringstream in(out);
  for (std::string line; std::getline(in, line);)
    if (line.rfind("  " + status + " ", 0) == 0) lines.push_back(line);
  return lines;
}

// A copy of the slider crank's folder under DYNLAB_HOME=dir/home, its config changed by edit; the
// options that run dynlab with that DYNLAB_HOME.
template <class Edit>
ProcessOptions homeWith(const TempDir& dir, Edit edit) {
  const fs::path home = dir / "home";
  fs::create_directories(home / "labs");
  fs::copy(fs::path(DYNLAB_SOURCE_DIR) / "labs/slider_crank", home / "labs/slider_crank", fs::copy_options::recursive);
  const fs::path config = home / "labs/slider_crank/slider_crank.json";
  writeFile(config, edit(readFile(config)));
  return withEnv({{"DYNLAB_HOME", home.string()}});
}

}  // namespace

TEST_CASE("check-lab: every check of a shipped lab passes, with its shares and passive drift") {
  const TempDir dir("check_lab_ok");
  const Result r = dynlab(dir, {"check-lab", "slider_crank"});
  INFO(r.out, r.err);
  CHECK(r.code == 0);
  CHECK(r.err.empty());
  CHECK(checkLines(r.out, "FAIL").empty());
  const std::vector<std::string> ok = checkLines(r.out, "ok");
  for (const char* check : {"config ", "examples ", "engines ", "drift independent ", "passive energy ", "metrics ", "grading ",
                            "defaults ", "plots ", "lessons ", "lesson integral ahead of proportional ", "doing nothing ",
                            "instructor good.json ", "render ", "cli "}) {
    INFO("check ", check);
    CHECK(std::count_if(ok.begin(), ok.end(), [&](const std::string& l) { return l.find("  ok    " + std::string(check)) == 0; }) == 1);
  }
  // Each check line has its one-line reason after the name.
  for (const auto& line : ok) CHECK(std::regex_search(line, std::regex("^  ok    \\S.*\\S  +\\S")));
  CHECK(std::regex_search(r.out, std::regex("\ndefault gains: +[0-9.]+ % of the points\n")));
  CHECK(std::regex_search(r.out, std::regex("\nexamples: +mediocre\\.json [0-9.]+ %, proportional\\.json [0-9.]+ %")));
  CHECK(std::regex_search(r.out, std::regex("\ninstructor answers: +good\\.json (9[0-9]|100)\\.[0-9] %\n")));
  CHECK(std::regex_search(r.out, std::regex("\npassive drift: +max \\|E − E0\\| = \\S+ over 4 s, relative \\S+ \\(tolerance 1e-06\\)\n")));
  CHECK(r.out.find("\nslider_crank: " + std::to_string(ok.size()) + " of " + std::to_string(ok.size()) + " checks pass (") != std::string::npos);
  // --skip-cli leaves out only the subprocesses: the cli check and the README numbers read from its run.
  const Result quick = dynlab(dir, {"check-lab", "slider_crank", "--skip-cli"});
  CHECK(quick.code == 0);
  CHECK(checkLines(quick.out, "ok").size() == ok.size() - 2);
  CHECK(quick.out.find("  ok    cli ") == std::string::npos);
  CHECK(quick.out.find("  ok    readme numbers ") == std::string::npos);
}

TEST_CASE("check-lab: default gains that already earn the points fail the defaults check (exit 1), the rest still run") {
  const TempDir dir("check_lab_fail");
  // The instructor's answer as the shipped defaults: no exercise left to the student.
  const ProcessOptions env = homeWith(dir, [](const std::string& text) {
    json config = json::parse(text);
    const json good = json::parse(readFile(fs::path(DYNLAB_SOURCE_DIR) / "labs/slider_crank/instructor/good.json"));
    for (const auto& [gain, value] : good.at("gains").items()) config["gains"][gain]["value"] = value;
    return config.dump(2);
  });
  const Result r = dynlab(dir, {"check-lab", "slider_crank", "--skip-cli"}, env);
  INFO(r.out, r.err);
  CHECK(r.code == 1);
  const std::vector<std::string> failed = checkLines(r.out, "FAIL");
  REQUIRE(failed.size() == 1);
  CHECK(std::regex_search(failed[0], std::regex("^  FAIL  defaults +the default gains score [0-9.]+ % .*band 20\\.0 % to 50\\.0 %: outside$")));
  const std::size_t passed = checkLines(r.out, "ok").size();
  CHECK(passed >= 13);
  CHECK(r.out.find("\nslider_crank: " + std::to_string(passed) + " of " + std::to_string(passed + 1) + " checks pass (") != std::string::npos);
  CHECK(r.err == "error: 1 check(s) of the lab contract fail for slider_crank\n");
}

TEST_CASE("check-lab: an unknown lab, a missing name or an unreadable config is bad input (exit 2, one line)") {
  const TempDir dir("check_lab_bad");
  Result r = dynlab(dir, {"check-lab", "no_such_lab"});
  CHECK(r.code == 2);
  CHECK(r.out.empty());
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  CHECK(r.err.rfind("error: <command line>: LAB: unknown lab \"no_such_lab\" (known labs: ", 0) == 0);
  for (const char* lab : {"slider_crank", "grasp", "unicycle", "pen_on_table", "motion_control", "impedance"})
    CHECK_MESSAGE(r.err.find(lab) != std::string::npos, "not listed: " << lab);
  r = dynlab(dir, {"check-lab"});
  CHECK(r.code == 2);
  CHECK(r.out.empty());
  const ProcessOptions env = homeWith(dir, [](const std::string& text) { return text.substr(0, text.size() / 2); });
  r = dynlab(dir, {"check-lab", "slider_crank"}, env);
  INFO(r.err);
  CHECK(r.code == 2);
  CHECK(r.out.empty());
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  CHECK(r.err.find("slider_crank.json") != std::string::npos);
}
