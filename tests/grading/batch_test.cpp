// dynlab grade --batch: one grader process per submission, N at a time. A submission that hangs
// its grader or crashes it still gets a results.json and a gradebook row; the others are graded
// exactly as alone, whatever --jobs is.
#include <doctest/doctest.h>

#include "app/shared/process.h"
#include "tests/test_files.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// The students' examples (the full-credit one stays in instructor/, out of a student copy).
const std::string kExamples = std::string(DYNLAB_SOURCE_DIR) + "/labs/slider_crank/examples/";

using dyn::test::readBytes;

json withoutTime(json r) {
  r.erase("execution_time");
  return r;
}

// A submissions folder: two graded, an unstable, a malformed one, plus two that hang and crash the grader.
fs::path makeBatch() {
  const fs::path dir = fs::temp_directory_path() / ("dynlab-batch-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "in");
  for (const char* n : {"mediocre", "proportional", "unstable_integral"})
    fs::copy_file(kExamples + n + ".json", dir / "in" / (std::string(n) + ".json"));
  std::ofstream(dir / "in" / "malformed.json") << "{\"lab\": \"slider_crank\", \"gains\": {\"kp_x\": }";
  fs::copy_file(kExamples + "mediocre.json", dir / "in" / "hangs.json");
  fs::copy_file(kExamples + "mediocre.json", dir / "in" / "crashes.json");
  return dir;
}

// The batch with a hanging and a crashing grader; its exit code, its stdout and stderr in OUT.log.
int runBatch(const fs::path& dir, const std::string& out, int jobs) {
  dyn::ProcessOptions o;
  o.set_env = {{"DYNLAB_FAULT_INJECTION", "hang:hangs,crash:crashes"}};
  fs::remove(dir / (out + ".log"));
  o.stdout_file = o.stderr_file = (dir / (out + ".log")).string();
  o.append = true;  // both into one file (2>&1)
  return dyn::runProgram({DYNLAB_BIN, "grade", "--batch", (dir / "in").string(), "--jobs", std::to_string(jobs), "--time-budget",
                          "2", "--no-plots", "--out", (dir / out).string()},
                         o)
      .code;
}

}  // namespace

TEST_CASE("a batch survives a hanging and a crashing grader, and --jobs does not change a byte") {
  const fs::path dir = makeBatch();
  REQUIRE(runBatch(dir, "one", 1) == 0);
  REQUIRE(runBatch(dir, "two", 2) == 0);

  for (const char* n : {"mediocre", "proportional", "unstable_integral", "malformed", "hangs", "crashes"}) {
    CAPTURE(n);
    const json a = json::parse(readBytes(dir / "one" / n / "results.json"));
    const json b = json::parse(readBytes(dir / "two" / n / "results.json"));
    CHECK(withoutTime(a).dump() == withoutTime(b).dump());
    CHECK(a.at("score").is_number());
  }
  // The gradebook: every submission, its status, identical for any number of jobs.
  const std::string book = readBytes(dir / "one" / "gradebook.csv");
  CHECK(book == readBytes(dir / "two" / "gradebook.csv"));
  CHECK(book.find("submission,score,max_score,status,reason,folder,Slider tracks x_d(t)") == 0);
  // Rows that are not grades still carry the lab's max_score, and the reason.
  CHECK(book.find("hangs.json,0,15,timed out,grading did not finish within 4 s,hangs,,") != std::string::npos);
  CHECK(book.find("crashes.json,0,15,crashed,internal error: the grader stopped with signal 6 (Aborted),crashes,,") !=
        std::string::npos);
  CHECK(book.find("malformed.json,0,15,invalid submission,") != std::string::npos);
  // A graded row: its score as its results.json has it (%.4g), of 15.
  char row[96];
  std::snprintf(row, sizeof row, "proportional.json,%.4g,15,graded,,proportional,",
                json::parse(readBytes(dir / "one" / "proportional" / "results.json")).at("score").get<double>());
  CHECK(book.find(row) != std::string::npos);
  CHECK(book.find("unstable_integral.json") != std::string::npos);
  // The crashed and timed-out submissions say what happened.
  CHECK(readBytes(dir / "one" / "crashes" / "results.json").find("signal 6") != std::string::npos);
  CHECK(readBytes(dir / "one" / "hangs" / "results.json").find("did not finish within 4 s") != std::string::npos);
  // Without a terminal, progress is plain lines.
  CHECK(readBytes(dir / "one.log").find("graded 6/6") != std::string::npos);
  fs::remove_all(dir);
}
