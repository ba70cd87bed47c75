// dynlab grade --batch's long-lived graders (app/cli/course/batch_graders.h): each grades submission
// after submission, so one submission must never change another's grade; and a grader that dies
// while drawing plots in place costs the plots of that submission only, as for a lone `dynlab grade`
// (the batch grades it again in a grader that draws them in a child). Through the real binary.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include "tests/app/cli_run.h"
#include "tests/grading/csv_rows.h"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace dyn::test::cli;

namespace {

const fs::path kExamples = fs::path(DYNLAB_SOURCE_DIR) / "labs/slider_crank/examples";

// A results.json without its execution time (the one field that differs from run to run).
json results(const fs::path& folder) {
  json r = json::parse(readFile(folder / "results.json"));
  r.erase("execution_time");
  return r;
}

// `dynlab grade` in dir with a time limit and an optional fault injection.
Result grade(const TempDir& dir, const std::vector<std::string>& args, const std::string& faults = "") {
  dyn::ProcessOptions o;
  o.timeout_s = 300;
  if (!faults.empty()) o.set_env = {{"DYNLAB_FAULT_INJECTION", faults}};
  return dynlab(dir, args, o);
}

std::size_t pngs(const fs::path& folder) {
  std::size_t n = 0;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(folder / "plots", ec)) n += e.path().extension() == ".png";
  return n;
}

}  // namespace

TEST_CASE("one grader, many submissions: each graded as `dynlab grade` grades it alone, plots and all" * doctest::timeout(600)) {
  const TempDir dir("batch_graders_same");
  // One grader (--jobs 1) grades them in name order: the unstable one between two stable ones, and
  // the same file twice.
  const std::vector<std::pair<std::string, std::string>> subs = {
      {"a", "proportional"}, {"b", "unstable_integral"}, {"c", "mediocre"}, {"d", "proportional"}};
  for (const auto& [name, example] : subs) {
    fs::create_directories(dir / "in");
    fs::copy_file(kExamples / (example + ".json"), dir / "in" / (name + ".json"));
  }
  const Result batch = grade(dir, {"grade", "--batch", "in", "--out", "out", "--lab", "slider_crank", "--jobs", "1"});
  REQUIRE_MESSAGE(batch.code == 0, batch.err);
  for (const auto& [name, example] : subs) {
    CAPTURE(name);
    const Result alone = grade(dir, {"grade", "in/" + name + ".json", "--out", "alone/" + name, "--lab", "slider_crank"});
    REQUIRE_MESSAGE((alone.code == 0 || alone.code == 1), alone.err);
    CHECK(results(dir / "out" / name) == results(dir / "alone" / name));
    CHECK(pngs(dir / "out" / name) == pngs(dir / "alone" / name));
    CHECK(pngs(dir / "out" / name) > 0);
  }
  CHECK(results(dir / "out/a") == results(dir / "out/d"));
}

TEST_CASE("a grader that dies drawing plots costs that submission its plots, never its grade" * doctest::timeout(600)) {
  const TempDir dir("batch_graders_trap");
  fs::create_directories(dir / "in");
  for (const char* name : {"a", "b", "c"}) fs::copy_file(kExamples / "proportional.json", dir / "in" / (std::string(name) + ".json"));
  // Drawing b's plots aborts, in the batch and alone alike.
  const std::string faults = "plot-trap:b";
  const Result batch = grade(dir, {"grade", "--batch", "in", "--out", "out", "--lab", "slider_crank", "--jobs", "1"}, faults);
  REQUIRE_MESSAGE(batch.code == 0, batch.err);
  const Result alone = grade(dir, {"grade", "in/b.json", "--out", "alone/b", "--lab", "slider_crank"}, faults);
  REQUIRE_MESSAGE(alone.code == 0, alone.err);

  const json b = results(dir / "out/b");
  CHECK(b == results(dir / "alone/b"));
  REQUIRE(b.at("extra_data").contains("plots_note"));
  CHECK(b.at("extra_data").at("plots_note").get<std::string>().find("could not be drawn") != std::string::npos);
  CHECK(pngs(dir / "out/b") == 0);
  // Graded all the same, as were the others, with their plots.
  const auto rows = dyn::test::parseCsv(readFile(dir / "out/gradebook.csv"));
  REQUIRE(rows.size() == 4);
  for (std::size_t r = 1; r < rows.size(); ++r) CHECK_MESSAGE(rows[r][3] == "graded", rows[r][0]);
  CHECK(rows[1][1] == rows[2][1]);
  CHECK(results(dir / "out/a") == results(dir / "out/c"));
  CHECK(pngs(dir / "out/a") > 0);
  CHECK(pngs(dir / "out/c") == pngs(dir / "out/a"));
}
