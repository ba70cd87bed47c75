// The same grade to the bit whatever the CPU's libm does (issue 46): every shipped example of every
// lab, noisy scenarios included, graded normally and with glibc's FMA/AVX2 variants switched off (the
// path a CPU without FMA takes), gives the same results.json bytes but execution_time; and `dynlab run`
// writes the same trace. Before physics/det, 0 of the 29 examples agreed.
#include <doctest/doctest.h>

#include "tests/app/cli_run.h"
#include "tests/app/lab_examples.h"

using namespace dyn::test::cli;

namespace {

const std::pair<std::string, std::string> kNoFma = {"GLIBC_TUNABLES", "glibc.cpu.hwcaps=-AVX2_Usable,-FMA_Usable,-AVX2,-FMA"};

std::string withoutTime(const fs::path& results) { return dyn::test::withoutExecutionTime(readFile(results)); }

void checkLab(const std::string& lab) {
  TempDir dir("same_bits_" + lab);
  const auto files = dyn::test::labExamples(lab);
  REQUIRE(!files.empty());
  for (const fs::path& ex : files) {
    CAPTURE(ex);
    const std::string a = (dir / (ex.stem().string() + "_a")).string(), b = (dir / (ex.stem().string() + "_b")).string();
    const Result ra = dynlab(dir, {"grade", ex.string(), "--no-plots", "--out", a});
    const Result rb = dynlab(dir, {"grade", ex.string(), "--no-plots", "--out", b}, withEnv({kNoFma}));
    CHECK(ra.code == rb.code);
    REQUIRE(fs::exists(fs::path(a) / "results.json"));
    REQUIRE(fs::exists(fs::path(b) / "results.json"));
    CHECK(withoutTime(fs::path(a) / "results.json") == withoutTime(fs::path(b) / "results.json"));
  }
  // One plain run (the hand-written engine): the same trace, the same summary.
  const std::string ra = (dir / "run_a").string(), rb = (dir / "run_b").string();
  const std::vector<std::string> run = {"run", lab, "--gains", files.front().string(), "--engine", "hand", "--out"};
  REQUIRE(dynlab(dir, cat(run, {ra})).code == 0);
  REQUIRE(dynlab(dir, cat(run, {rb}), withEnv({kNoFma})).code == 0);
  CHECK(readFile(fs::path(ra) / "trace_hand.csv") == readFile(fs::path(rb) / "trace_hand.csv"));
  CHECK(readFile(fs::path(ra) / "summary.json") == readFile(fs::path(rb) / "summary.json"));
}

}  // namespace

TEST_CASE("slider_crank: the same bits without FMA") { checkLab("slider_crank"); }
TEST_CASE("fivebar: the same bits without FMA") { checkLab("fivebar"); }
TEST_CASE("pen_on_table: the same bits without FMA") { checkLab("pen_on_table"); }
TEST_CASE("unicycle: the same bits without FMA") { checkLab("unicycle"); }
TEST_CASE("grasp: the same bits without FMA") { checkLab("grasp"); }
TEST_CASE("impedance: the same bits without FMA") { checkLab("impedance"); }
TEST_CASE("motion_control: the same bits without FMA") { checkLab("motion_control"); }
TEST_CASE("puma_motion: the same bits without FMA") { checkLab("puma_motion"); }
TEST_CASE("puma_impedance: the same bits without FMA") { checkLab("puma_impedance"); }
