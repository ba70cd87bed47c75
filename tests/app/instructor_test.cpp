// Full-credit examples stay with the course staff: every lab's examples/ (what students get) holds
// no submission that scores 90 % or more, its instructor/ folder does (the slider crank's full marks), the
// Gradescope bundle (`dynlab autograder`) leaves instructor/ out but keeps examples/, and a student
// copy made with `git archive` leaves it out too (export-ignore).
#include <doctest/doctest.h>

#include <zip.h>

#include <map>
#include <nlohmann/json.hpp>

#include "tests/app/cli_run.h"
#include "tests/instructor.h"

using namespace dyn::test::cli;
using json = nlohmann::json;

namespace {

const fs::path kLabs = fs::path(DYNLAB_SOURCE_DIR) / "labs";

std::vector<fs::path> jsonFiles(const fs::path& dir) {
  std::vector<fs::path> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.path().extension() == ".json") out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

// Score and max score of `dynlab grade FILE`.
std::pair<double, double> grade(const TempDir& dir, const fs::path& file) {
  const Result r = dynlab(dir, {"grade", file.string(), "--no-plots", "--out", "g"});
  INFO(file, "\n", r.err);
  REQUIRE((r.code == 0 || r.code == 2));
  const json res = json::parse(readFile(dir / "g/results.json"));
  double max = 0;
  for (const auto& t : res["tests"]) max += t["max_score"].get<double>();
  return {res["score"].get<double>(), max};
}

// Every entry of a zip (name → bytes), read back with libzip.
std::map<std::string, std::string> readZip(const fs::path& p) {
  int err = 0;
  zip_t* za = zip_open(p.string().c_str(), ZIP_RDONLY, &err);
  REQUIRE(za != nullptr);
  std::map<std::string, std::string> out;
  for (zip_int64_t i = 0; i < zip_get_num_entries(za, 0); ++i) {
    zip_stat_t st;
    REQUIRE(zip_stat_index(za, zip_uint64_t(i), 0, &st) == 0);
    std::string data(st.size, '\0');
    zip_file_t* f = zip_fopen_index(za, zip_uint64_t(i), 0);
    REQUIRE(f != nullptr);
    REQUIRE(zip_fread(f, data.data(), st.size) == static_cast<zip_int64_t>(st.size));
    zip_fclose(f);
    out[st.name] = data;
  }
  zip_close(za);
  return out;
}

}  // namespace

TEST_CASE("students' examples score well below full marks; the instructor's score (close to) them") {
  const TempDir dir("instructor_scores");
  int labs = 0;
  for (const auto& lab : fs::directory_iterator(kLabs)) {
    if (!fs::is_directory(lab.path() / "examples")) continue;
    ++labs;
    // An example at 90 % or more is as good as the answer: it belongs with the instructor's files.
    for (const fs::path& file : jsonFiles(lab.path() / "examples")) {
      const auto [score, max] = grade(dir, file);
      CHECK_MESSAGE(score < 0.9 * max, file.string() << " scores " << score << " of " << max << ": move it to instructor/");
    }
    for (const fs::path& file : jsonFiles(lab.path() / "instructor")) {
      const auto [score, max] = grade(dir, file);
      CHECK_MESSAGE(score >= 0.9 * max, file.string() << " scores " << score << " of " << max);
    }
  }
  CHECK(labs >= 1);
}

// The rubric trades one gain against another (issue 41): no design earns every point, and the tuned
// answer finishes clearly ahead of each design written from the handout alone (instructor/untuned/).
TEST_CASE("the slider crank's instructor/good.json scores ahead of every untuned design" *
          doctest::skip(!dyn::test::instructorFilesPresent())) {
  const TempDir dir("instructor_full");
  const auto [score, max] = grade(dir, kLabs / "slider_crank/instructor/good.json");
  CHECK(max > 0);
  CHECK(score >= 0.9 * max);
  const std::vector<fs::path> untuned = jsonFiles(kLabs / "slider_crank/instructor/untuned");
  CHECK(untuned.size() >= 2);
  for (const fs::path& file : untuned) {
    const auto [u, m] = grade(dir, file);
    // Tuning buys points: the answer at least 2 % of them ahead (before issue 41's calibration the
    // handout's round gains came within 0.2 % of full marks).
    CHECK_MESSAGE(u < score - 0.02 * max, file.string() << " scores " << u << " of " << m << ", the answer " << score);
  }
}

TEST_CASE("the Gradescope bundle has the students' examples and no instructor folder") {
  const TempDir dir("instructor_bundle");
  REQUIRE(dynlab(dir, {"autograder", "slider_crank", "--out", "ag.zip"}).code == 0);
  const std::map<std::string, std::string> zip = readZip(dir / "ag.zip");
  REQUIRE(zip.count("run_autograder") == 1);
  CHECK(zip.count("source/labs/slider_crank/examples/mediocre.json") == 1);
  CHECK(zip.count("source/labs/slider_crank/slider_crank.json") == 1);
  for (const auto& [name, _] : zip) CHECK_MESSAGE(name.find("/instructor/") == std::string::npos, name);
  // Its README sends staff to the handout students work from.
  REQUIRE(zip.count("README.md") == 1);
  CHECK(zip.at("README.md").find("dynlab handout slider_crank") != std::string::npos);
}

TEST_CASE("a student copy made with git archive leaves instructor/ out (export-ignore)") {
  const TempDir dir("instructor_git");
  const std::vector<std::string> git = {"git", "-C", DYNLAB_SOURCE_DIR};
  if (run(dir, cat(git, {"rev-parse", "--is-inside-work-tree"})).code != 0) {
    MESSAGE("not a git checkout: nothing to check");
    return;
  }
  const Result r = run(dir, cat(git, {"check-attr", "export-ignore", "--", "labs/slider_crank/instructor/good.json",
                                      "labs/slider_crank/examples/mediocre.json"}));
  REQUIRE(r.code == 0);
  CHECK(r.out.find("instructor/good.json: export-ignore: set") != std::string::npos);
  CHECK(r.out.find("mediocre.json: export-ignore: unspecified") != std::string::npos);
}

TEST_CASE("the instructor cases are skipped only in a student copy: files git tracks are on disk") {
  // A staff checkout that lost its instructor folders would skip those cases silently: not here.
  const TempDir dir("instructor_present");
  const Result r = run(dir, {"git", "-C", DYNLAB_SOURCE_DIR, "ls-files", "--", "labs/*/instructor/*"});
  if (r.code != 0) {
    MESSAGE("not a git checkout (a student copy): nothing to check");
    return;
  }
  if (r.out.empty()) return;  // a repository of the student copy's files (git init): nothing tracked there
  CHECK(dyn::test::instructorFilesPresent());
  std::istringstream files(r.out);
  for (std::string file; std::getline(files, file);) CHECK_MESSAGE(fs::exists(fs::path(DYNLAB_SOURCE_DIR) / file), file);
}
