// gradebook.md beside gradebook.csv (through dynlab grade --batch): the number of submissions and of
// each status, mean / median / min / max, the histogram and the per-test means all as the CSV's rows
// give them; failure reasons that differ only in their numbers counted as one kind; every name and
// reason from a submission escaped for Markdown.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "app/shared/process.h"
#include "tests/test_files.h"
#include "tests/grading/csv_rows.h"

namespace fs = std::filesystem;
using dyn::test::readBytes;

namespace {

const fs::path kLab = fs::path(DYNLAB_SOURCE_DIR) / "labs/slider_crank";

void put(const fs::path& p, const std::string& text) { std::ofstream(p, std::ios::binary) << text; }

using dyn::test::parseCsv;  // tests/grading/csv_rows.h

std::string fmt(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", x);
  return b;
}

// The line of md holding `needle` ("" if none).
std::string lineWith(const std::string& md, const std::string& needle) {
  const std::size_t at = md.find(needle);
  if (at == std::string::npos) return "";
  const std::size_t start = md.rfind('\n', at) + 1;
  return md.substr(start, md.find('\n', at) - start);
}

}  // namespace

TEST_CASE("gradebook.md: counts, statistics, histogram and failure reasons as the gradebook's rows give them") {
  const fs::path dir = dyn::test::scratchDir("batch_summary", "class");
  const fs::path in = dir / "in";
  fs::create_directories(in);
  for (const char* n : {"mediocre", "proportional", "unstable_integral"})
    fs::copy_file(kLab / "examples" / (std::string(n) + ".json"), in / (std::string(n) + ".json"));
  // Stable gains of the students' kind (not the instructor's answer).
  put(in / "stable.json", R"({"lab": "slider_crank", "gains": {"kp_x": 300, "kd_x": 12, "kp_f": 0.5, "ki_f": 10}})");
  // Unstable too, with other numbers in its sentences: the same kind of failure.
  put(in / "unstable_too.json", R"({"lab": "slider_crank", "force_law": "integral", "gains": {"kp_x": 400, "kd_x": 40, "kp_f": 0.5, "ki_f": 700}})");
  put(in / "broken.json", R"({"lab": "slider_crank", "gains": {"kp_x": })");
  // A hostile name on a submission that is not graded: it is listed, as text.
  const std::string hostile = "*evil*<b>|x| [a](j:x).json";
  put(in / hostile, R"({"lab": "slider_crank", "gains": {"kp_x": "<b>"}})");

  dyn::ProcessOptions to_log;
  to_log.stdout_file = to_log.stderr_file = (dir / "log").string();
  to_log.append = true;  // both into one file (2>&1); dir is fresh
  REQUIRE(dyn::runProgram(
              {DYNLAB_BIN, "grade", "--batch", in.string(), "--jobs", "2", "--no-plots", "--out", (dir / "out").string()}, to_log)
              .code == 0);
  const std::string md = readBytes(dir / "out/gradebook.md");
  REQUIRE_FALSE(md.empty());
  CHECK(readBytes(dir / "log").find("gradebook.md") != std::string::npos);

  // What the CSV says, recomputed here.
  const auto csv = parseCsv(readBytes(dir / "out/gradebook.csv"));
  REQUIRE(csv.size() == 8);  // header + 7
  const auto& head = csv[0];
  const auto col = [&](const std::string& name) { return std::size_t(std::find(head.begin(), head.end(), name) - head.begin()); };
  std::vector<double> scores;
  std::map<std::string, int> status;
  std::map<std::string, std::string> reason;
  for (std::size_t r = 1; r < csv.size(); ++r) {
    scores.push_back(std::stod(csv[r][col("score")]));
    ++status[csv[r][col("status")]];
    reason[csv[r][col("submission")]] = csv[r][col("reason")];
  }
  const double total = std::stod(csv[1][col("max_score")]);
  std::sort(scores.begin(), scores.end());
  double sum = 0;
  for (double x : scores) sum += x;
  const std::size_t n = scores.size();
  const double median = n % 2 ? scores[n / 2] : (scores[n / 2 - 1] + scores[n / 2]) / 2;

  CHECK(md.find("7 submissions") != std::string::npos);
  for (const auto& [s, count] : status) CHECK(md.find("| " + s + " | " + std::to_string(count) + " |") != std::string::npos);
  // The mean of the CSV's rounded cells (%.4g) may differ from the exact one in its last digit.
  const std::string mean_line = lineWith(md, "| mean | ");
  REQUIRE(mean_line.size() > 9);
  CHECK(std::stod(mean_line.substr(9)) == doctest::Approx(sum / double(n)).epsilon(1e-3));
  CHECK(md.find("| median | " + fmt(median) + " (") != std::string::npos);
  CHECK(md.find("| min | " + fmt(scores.front()) + " (") != std::string::npos);
  CHECK(md.find("| max | " + fmt(scores.back()) + " (") != std::string::npos);
  // The histogram: ten bins of a tenth of the total, the last one holding full marks.
  for (int b = 0; b < 10; ++b) {
    int count = 0;
    for (double x : scores) count += std::min(9, int(std::floor(x / total * 10))) == b;
    const std::string bin = "| " + fmt(total * b / 10) + (b == 9 ? " – " : " – <") + fmt(total * (b + 1) / 10) + " | ";
    const std::string line = lineWith(md, bin);
    CAPTURE(bin);
    REQUIRE_FALSE(line.empty());
    CHECK(line.find(bin + std::to_string(count) + " |") == 0);
    std::size_t bars = 0;
    for (std::size_t at = line.find("█"); at != std::string::npos; at = line.find("█", at + 1)) ++bars;
    CHECK(bars == std::size_t(count));
  }
  // The two unstable submissions stop at other times with other forces: one kind, counted twice.
  REQUIRE(reason.at("unstable_integral.json") != reason.at("unstable_too.json"));
  const std::string unstable = lineWith(md, "left its safe range [#, #] at t = # s");
  CHECK(unstable.find("| graded (unstable run) |") != std::string::npos);
  CHECK(unstable.find("nominal") != std::string::npos);
  CHECK(unstable.substr(unstable.size() - 5) == "| 2 |");
  CHECK(md.find("537.8") == std::string::npos);  // the numbers are gone
  // Each test's mean over the graded submissions.
  const std::size_t first_test = col("folder") + 1;
  REQUIRE(first_test < head.size());
  double test_sum = 0;
  int graded = 0;
  for (std::size_t r = 1; r < csv.size(); ++r)
    if (!csv[r][first_test].empty()) test_sum += std::stod(csv[r][first_test]), ++graded;
  // The CSV's cells are rounded (%.4g): their mean may differ from the exact one in its last digit.
  const std::string test_line = lineWith(md, "| " + head[first_test] + " |");
  REQUIRE(test_line.size() > head[first_test].size() + 4);
  CHECK(std::stod(test_line.substr(head[first_test].size() + 4)) == doctest::Approx(test_sum / graded).epsilon(1e-3));
  // The hostile name is text: no tag, no link, its pipes escaped (the row keeps its three cells).
  CHECK(md.find("<b>") == std::string::npos);
  CHECK(md.find("&lt;b&gt;") != std::string::npos);
  CHECK(md.find("](j:x)") == md.find("\\](j:x)") + 1);  // the ] escaped: no link
  const std::string listed = lineWith(md, "\\*evil\\*");
  CHECK(listed.find("\\|x\\|") != std::string::npos);
  CHECK(listed.find("| invalid submission |") != std::string::npos);
  // The same batch again gives the same summary.
  REQUIRE(dyn::runProgram(
              {DYNLAB_BIN, "grade", "--batch", in.string(), "--jobs", "1", "--no-plots", "--out", (dir / "out2").string()})
              .code == 0);  // stdout and stderr to /dev/null
  CHECK(readBytes(dir / "out2/gradebook.md") == md);
}
