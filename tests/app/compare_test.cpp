// dynlab compare A B: both graded by the same rubric as `dynlab grade` grades them; a line per test
// on the terminal (scores and metric with unit, A → B), OUT/comparison.md, one plot per simulated
// test with both responses; a hostile file name stays text everywhere; bad input exits 2 writing
// nothing; the exit codes are app/cli/commands.h's.
#include <doctest/doctest.h>

#include <cstring>

#include <cstdio>
#include <nlohmann/json.hpp>

#include "tests/app/cli_run.h"

using namespace dyn::test::cli;
using json = nlohmann::json;

namespace {

const std::string kLab = std::string(DYNLAB_SOURCE_DIR) + "/labs/slider_crank/";

// A score as the comparison prints it (two decimals, then 4 significant digits).
std::string pts(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", std::round(x * 100) / 100);
  return b;
}

// The rubric's tests that are simulated: their metric is one of the lab's (metric_docs), not screening's.
std::vector<std::size_t> simulatedTests() {
  const json cfg = json::parse(defaultConfigText());
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < cfg["rubric"]["tests"].size(); ++i)
  {
    // A lab metric with a definition, not a screening one (which metric_docs may document for its advice).
    const std::string m = cfg["rubric"]["tests"][i]["metric"];
    bool screening = false;
    for (const char* k : {"_delay_margin", "_damping", "_max_real_pole", "_phase_margin_deg", "_crossover"})
      screening = screening || (m.size() > std::strlen(k) && m.compare(m.size() - std::strlen(k), std::string::npos, k) == 0);
    if (cfg["metric_docs"].contains(m) && !screening) out.push_back(i);
  }
  return out;
}

std::size_t plotCount(const fs::path& dir) {
  std::size_t n = 0;
  for (const auto& e : fs::directory_iterator(dir)) n += e.path().extension() == ".png";
  return n;
}

}  // namespace

TEST_CASE("compare: both graded as dynlab grade grades them, side by side, one plot per simulated test") {
  const TempDir dir("compare");
  // Two of the students' examples (the integral and the proportional law); no instructor file needed.
  const std::string a = kLab + "examples/mediocre.json", b = kLab + "examples/proportional.json";
  REQUIRE(dynlab(dir, {"grade", a, "--no-plots", "--out", "ga"}).code == 0);
  REQUIRE(dynlab(dir, {"grade", b, "--no-plots", "--out", "gb"}).code == 0);
  const json ra = json::parse(readFile(dir / "ga/results.json")), rb = json::parse(readFile(dir / "gb/results.json"));

  const Result r = dynlab(dir, {"compare", a, b, "--out", "cmp"});
  INFO(r.err);
  REQUIRE(r.code == 0);
  const std::string md = readFile(dir / "cmp/comparison.md");
  // The totals, and per test both scores and both metric values, as each grade has them.
  CHECK(r.out.find("Total: " + pts(ra["score"]) + " → " + pts(rb["score"])) != std::string::npos);
  CHECK(md.find("| A | " + a) != std::string::npos);
  CHECK(md.find("| " + pts(ra["score"]) + " / 15 |") != std::string::npos);
  const auto& tests = ra["tests"];
  for (std::size_t i = 0; i < tests.size(); ++i) {
    CAPTURE(i);
    const std::string name = tests[i]["name"], metric = tests[i]["extra_data"]["metric"];
    const std::string sa = pts(tests[i]["score"]), sb = pts(rb["tests"][i]["score"]);
    char va[32], vb[32];
    std::snprintf(va, sizeof va, "%.4g", tests[i]["extra_data"]["value"].get<double>());
    std::snprintf(vb, sizeof vb, "%.4g", rb["tests"][i]["extra_data"]["value"].get<double>());
    // The terminal: "2.1 → 3 / 3  Slider tracks x_d(t) [nominal]: x_rms = 0.01113 m → 0.0002272 m".
    const std::size_t line = r.out.find(name + " [");
    REQUIRE(line != std::string::npos);
    const std::string text = r.out.substr(r.out.rfind('\n', line) + 1, r.out.find('\n', line) - r.out.rfind('\n', line) - 1);
    CHECK(text.find(sa + " → " + sb) != std::string::npos);
    CHECK(text.find(metric + " = " + va) != std::string::npos);
    CHECK(text.find(std::string("→ ") + vb) != std::string::npos);
    // The Markdown: its row with both values and both scores.
    CHECK(md.find("| " + std::to_string(i + 1) + " | ") != std::string::npos);
    CHECK(md.find(std::string(va)) != std::string::npos);
  }
  // Units: metres for tracking, newtons for the force (the lab's metric_docs).
  CHECK(r.out.find(" m → ") != std::string::npos);
  CHECK(r.out.find(" N → ") != std::string::npos);
  CHECK(md.find(" m | ") != std::string::npos);
  // One plot per simulated test, each linked from the Markdown; screening tests have none.
  const std::vector<std::size_t> sim = simulatedTests();
  CHECK(plotCount(dir / "cmp/plots") == sim.size());
  for (std::size_t i : sim) {
    char prefix[8];
    std::snprintf(prefix, sizeof prefix, "%02zu-", i + 1);
    CHECK(md.find(std::string("](plots/") + prefix) != std::string::npos);
  }
  // Both responses are on each plot: comparing A with itself draws other pictures.
  REQUIRE(dynlab(dir, {"compare", a, a, "--out", "same"}).code == 0);
  CHECK(plotCount(dir / "same/plots") == sim.size());
  for (const auto& e : fs::directory_iterator(dir / "cmp/plots"))
    CHECK(readFile(e.path()) != readFile(dir / "same/plots" / e.path().filename()));
  // The same command twice: the same bytes.
  REQUIRE(dynlab(dir, {"compare", a, b, "--out", "again"}).code == 0);
  CHECK(snapshot(dir / "again") == snapshot(dir / "cmp"));
  // --no-plots: the comparison alone.
  REQUIRE(dynlab(dir, {"compare", a, b, "--no-plots", "--out", "bare"}).code == 0);
  CHECK_FALSE(fs::exists(dir / "bare/plots"));
}

TEST_CASE("compare: a hostile file name is text in the terminal, the Markdown and the plot legends") {
  const TempDir dir("compare_hostile");
  const std::string hostile = "<img src=x onerror=alert(1)> *b* | [l](javascript:x) #h `c`\n\x1b[31m\xff.json";
  writeFile(dir / hostile, readFile(kLab + "examples/mediocre.json"));
  const Result r = dynlab(dir, {"compare", hostile, kLab + "examples/proportional.json", "--out", "cmp"});
  INFO(r.err);
  REQUIRE(r.code == 0);
  // The terminal: control characters and bad bytes as visible escapes.
  CHECK(r.out.find('\x1b') == std::string::npos);
  CHECK(r.out.find("\\n") != std::string::npos);
  CHECK(r.out.find("\xff") == std::string::npos);
  // The Markdown: no tag, no link, no raw line break or bad byte; the table keeps its columns.
  const std::string md = readFile(dir / "cmp/comparison.md");
  CHECK(md.find("<img") == std::string::npos);
  CHECK(md.find("&lt;img") != std::string::npos);
  CHECK(md.find("\\](javascript") != std::string::npos);  // the ] escaped: no link
  CHECK(md.find("](javascript") == md.find("\\](javascript") + 1);
  CHECK(md.find("\xff") == std::string::npos);
  CHECK(md.find('\x1b') == std::string::npos);
  const std::size_t row = md.find("| A | ");
  REQUIRE(row != std::string::npos);
  const std::string line = md.substr(row, md.find('\n', row) - row);
  CHECK(line.find("\\|") != std::string::npos);  // the name's | escaped: three cells, not four
  CHECK(line.find("\\*b\\*") != std::string::npos);
  // The plots were drawn (the legend holds the sanitised name).
  CHECK(plotCount(dir / "cmp/plots") == simulatedTests().size());
}

TEST_CASE("compare: bad input exits 2 with one line and writes nothing; OUT's own files are kept") {
  const TempDir dir("compare_bad");
  const std::string good = kLab + "examples/mediocre.json";
  writeFile(dir / "broken.json", "{\"lab\": \"slider_crank\", \"gains\": {\"kp_x\": }");
  checkBadInput(dir, {"compare", good, "broken.json", "--out", "cmp"}, {"broken.json"}, dir / "cmp");
  checkBadInput(dir, {"compare", "broken.json", good, "--out", "cmp"}, {"broken.json"}, dir / "cmp");
  checkBadInput(dir, {"compare", good, "missing.json", "--out", "cmp"}, {"missing.json"}, dir / "cmp");
  checkBadInput(dir, {"compare", good, good, "--lab", "nope", "--out", "cmp"}, {"/lab", "nope"}, dir / "cmp");
  // A plots/ folder of the user's in OUT: nothing is removed, exit 2.
  fs::create_directories(dir / "mine/plots");
  writeFile(dir / "mine/plots/notes.txt", "mine");
  const Result r = dynlab(dir, {"compare", good, good, "--out", "mine"});
  CHECK(r.code == 2);
  CHECK(r.err.find("notes.txt") != std::string::npos);
  CHECK(readFile(dir / "mine/plots/notes.txt") == "mine");
  CHECK_FALSE(fs::exists(dir / "mine/comparison.md"));
}
