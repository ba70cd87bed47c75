// What `dynlab grade` writes, through the real binary: hostile file names and string values stay
// escaped in report.md, report.html, results.json and the terminal; a full disk (a small tmpfs,
// and an injected ENOSPC) is a non-zero exit with the system's error text and no short result left
// as if valid; an internal error (a plot that cannot be written) is not blamed on the student.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include "tests/app/cli_run.h"

using namespace dyn::test::cli;

namespace {

// Stable gains that grade normally (the students' mediocre example, not the instructor's answer).
const std::string kGood = readFile(fs::path(DYNLAB_SOURCE_DIR) / "labs/slider_crank/examples/mediocre.json");
// A file name with markup, a line break, backticks and a heading (no ' : the tests quote with it).
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
  const Result check = dynlab(dir, "check-results " + quote((out / "results.json").string()));
  CHECK_MESSAGE(check.code == 0, check.err);
  const auto results = nlohmann::json::parse(readFile(out / "results.json"));
  CHECK(results.at("output").get<std::string>().find("<script") == std::string::npos);
}

}  // namespace

TEST_CASE("a hostile file name and string values stay escaped in every report") {
  TempDir dir("hostile_names");
  SUBCASE("graded: the file name is in report.md, the fingerprint line and the terminal") {
    writeFile(dir / kHostileName, kGood);
    const Result r = dynlab(dir, "grade " + quote(kHostileName) + " --no-plots --out out");
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
    const Result r = dynlab(dir, "grade " + quote(kHostileName) + " --no-plots --out out");
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
  REQUIRE(dynlab(dir, "grade good.json --no-plots --out out").code == 0);
  const auto before = snapshot(dir / "out");
  const Result full = shell(dir, "DYNLAB_FAULT_INJECTION=enospc:results.json " + quote(DYNLAB_BIN) +
                                     " grade good.json --no-plots --out out");
  INFO(full.err);
  CHECK(full.code == 3);
  CHECK(std::count(full.err.begin(), full.err.end(), '\n') == 1);
  CHECK(full.err.find("No space left on device") != std::string::npos);
  CHECK(full.err.find("out/results.json") != std::string::npos);
  CHECK(snapshot(dir / "out") == before);  // nothing replaced, nothing half-written beside it
  CHECK_FALSE(fs::exists(dir / "out/.staging"));
  // A fresh OUT: no results.json at all.
  const Result fresh = shell(dir, "DYNLAB_FAULT_INJECTION=enospc:results.json " + quote(DYNLAB_BIN) +
                                      " grade good.json --no-plots --out fresh");
  CHECK(fresh.code == 3);
  CHECK_FALSE(fs::exists(dir / "fresh/results.json"));
}

TEST_CASE("a full disk (a 64 KiB tmpfs): exit 3, the system's words, nothing short left as if valid") {
  TempDir dir("tmpfs");
  writeFile(dir / "good.json", kGood);
  // In a private mount namespace (as root, or as a mapped user): a tmpfs, graded into once, then filled.
  const std::string script =
      "set -u; mkdir -p mnt && mount -t tmpfs -o size=64k tmpfs mnt || exit 77\n" +
      quote(DYNLAB_BIN) + " grade good.json --no-plots --out mnt/out >/dev/null 2>&1; echo $? > first.code\n"
      "cp mnt/out/results.json first.json\n"
      "cat /dev/zero > mnt/fill 2>/dev/null\n" +
      quote(DYNLAB_BIN) + " grade good.json --no-plots --out mnt/out 2> full.err; echo $? > full.code\n"
      "mkdir after && cp -r mnt/out/. after/ && find mnt/out -type f -size 0 > empty.list\n";
  writeFile(dir / "full.sh", script);
  const Result r = shell(dir, "unshare -rm sh full.sh");
  if (!fs::exists(dir / "full.code")) {
    MESSAGE("no tmpfs could be mounted here (", r.err, "): the injected ENOSPC test stands in");
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
  const Result r = shell(dir, "DYNLAB_FAULT_INJECTION=enospc:.png " + quote(DYNLAB_BIN) + " grade good.json --out out");
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
  CHECK(dynlab(dir, "check-results out/results.json").code == 0);
}

TEST_CASE("grade --out . never removes a plots/ folder of the user's; its own plots/ it replaces") {
  TempDir dir("out_dot");
  writeFile(dir / "good.json", kGood);
  fs::create_directories(dir / "plots");
  writeFile(dir / "plots/notes.txt", "mine");
  Result r = shell(dir, quote(DYNLAB_BIN) + " grade good.json --out .");
  INFO(r.out, r.err);
  CHECK(r.code == 2);
  CHECK(r.err.find("plots holds files dynlab did not write (notes.txt)") != std::string::npos);
  CHECK(readFile(dir / "plots/notes.txt") == "mine");
  CHECK_FALSE(fs::exists(dir / "results.json"));  // nothing was written
  // Without the user's file, dynlab writes its plots there, and a rerun replaces them.
  fs::remove(dir / "plots/notes.txt");
  r = shell(dir, quote(DYNLAB_BIN) + " grade good.json --out .");
  CHECK(r.code == 0);
  CHECK(fs::exists(dir / "results.json"));
  r = shell(dir, quote(DYNLAB_BIN) + " grade good.json --out .");
  CHECK(r.code == 0);
  CHECK_FALSE(fs::is_empty(dir / "plots"));
}
