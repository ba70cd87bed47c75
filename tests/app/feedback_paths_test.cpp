// What a student reads never shows where the grader keeps files: results.json's text (what
// Gradescope shows) and an invalid submission's report name the file alone, whether it was graded
// by an absolute path or in a batch; the gradebook's summary keeps words like "UTF-8" whole while
// it masks numbers.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include "tests/app/cli_run.h"

using namespace dyn::test::cli;
using nlohmann::json;

namespace {

const std::string kMediocre = std::string(DYNLAB_SOURCE_DIR) + "/labs/slider_crank/examples/mediocre.json";

// Every string Gradescope shows the student: the top output and each test's name and output.
std::string studentText(const fs::path& results) {
  const json r = json::parse(readFile(results));
  std::string text = r.value("output", "");
  for (const auto& t : r.value("tests", json::array())) text += "\n" + t.value("name", "") + "\n" + t.value("output", "");
  return text;
}

// No folder of this machine's: not the test's scratch folder, not the source tree, nothing of /tmp.
void checkNoPaths(const TempDir& dir, const std::string& text, const std::string& what) {
  INFO(what, ":\n", text);
  CHECK(text.find(dir.path.string()) == std::string::npos);
  CHECK(text.find(DYNLAB_SOURCE_DIR) == std::string::npos);
  CHECK(text.find(DYNLAB_TEST_TMP) == std::string::npos);
}

}  // namespace

TEST_CASE("an invalid submission graded by its absolute path: the feedback names the file, not its folders") {
  TempDir dir("paths_one");
  fs::create_directories(dir / "ta/course/subs");
  const fs::path bad = dir / "ta/course/subs/alice.json";
  writeFile(bad, R"({"lab": "slider_crank", "gains": {"kp_x": 1e9}})");
  const fs::path out = dir / "ta/out";
  const Result r = dynlab(dir, {"grade", bad.string(), "--out", out.string()});
  REQUIRE(r.code == 2);
  // The staff's terminal keeps the whole path; the student's text has the name and what to fix.
  CHECK(r.err.find(bad.string()) != std::string::npos);
  const std::string text = studentText(out / "results.json");
  CHECK(text.find("alice.json: /gains/kp_x: expected a number in [0, 20000]") != std::string::npos);
  checkNoPaths(dir, text, "results.json");
  checkNoPaths(dir, readFile(out / "report.md"), "report.md");
  checkNoPaths(dir, readFile(out / "report.html"), "report.html");
  // A graded one: Gradescope's text has no path either.
  const Result g = dynlab(dir, {"grade", kMediocre, "--no-plots", "--out", (dir / "ta/graded").string()});
  REQUIRE(g.code == 0);
  checkNoPaths(dir, studentText(dir / "ta/graded/results.json"), "graded results.json");
}

TEST_CASE("a batch: every student's feedback is free of the TA's paths; gradebook.md masks numbers, not UTF-8") {
  TempDir dir("paths_batch");
  fs::create_directories(dir / "subs/alice");
  fs::create_directories(dir / "subs/bob");
  writeFile(dir / "subs/alice/submission.json", readFile(kMediocre));
  writeFile(dir / "subs/bob/submission.json", R"({"lab": "slider_crank", "gains": {"kp_x": 1e9}})");
  writeFile(dir / "subs/carol.json", "{\"lab\": \"slider_crank\", \"gains\": {\"kp_x\": \xE9}}");  // Latin-1, not UTF-8
  const Result r =
      dynlab(dir, {"grade", "--batch", (dir / "subs").string(), "--no-plots", "--jobs", "2", "--out", (dir / "book").string()});
  INFO(r.out, r.err);
  for (const std::string student : {"alice", "bob", "carol"}) {
    INFO("student ", student);
    REQUIRE(fs::exists(dir / "book" / student / "results.json"));
    checkNoPaths(dir, studentText(dir / "book" / student / "results.json"), "results.json");
    if (student != "alice") checkNoPaths(dir, readFile(dir / "book" / student / "report.md"), "report.md");
  }
  const std::string md = readFile(dir / "book/gradebook.md");
  CHECK(md.find("UTF-8") != std::string::npos);
  CHECK(md.find("UTF-#") == std::string::npos);
  CHECK(md.find("at offset #") != std::string::npos);  // the number beside it is still masked
}
