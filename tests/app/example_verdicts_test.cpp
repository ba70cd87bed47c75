// Examples named for a verdict get it (a student opens `unstable.json` to see instability): every
// labs/*/examples/*.json whose name says unstable, slipping, skidding or mediocre is graded and
// its report must say so — the screening or a stopped scenario says "unstable", a scenario stopped
// because the grasp slipped, a skid test scores under half, a mediocre one scores 25–75 %.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include "tests/app/cli_run.h"

using namespace dyn::test::cli;
using nlohmann::json;

TEST_CASE("every example named for a verdict gets that verdict") {
  TempDir dir("verdicts");
  int checked = 0;
  std::vector<fs::path> files;
  for (const auto& e : fs::recursive_directory_iterator(fs::path(DYNLAB_SOURCE_DIR) / "labs"))
    if (e.path().parent_path().filename() == "examples" && e.path().extension() == ".json") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  for (const auto& file : files) {
    const std::string name = file.stem().string();
    const bool unstable = name.find("unstable") != std::string::npos, slipping = name.find("slipping") != std::string::npos;
    const bool skidding = name.find("skidding") != std::string::npos, mediocre = name.find("mediocre") != std::string::npos;
    if (!unstable && !slipping && !skidding && !mediocre) continue;
    INFO(file.string());
    const std::string out = "g" + std::to_string(++checked);
    const Result r = dynlab(dir, {"grade", file.string(), "--no-plots", "--out", out});
    REQUIRE_MESSAGE(r.code == 0, r.err);
    const json res = json::parse(readFile(dir / out / "results.json"));
    std::string stopped;
    for (const auto& [_, s] : res["extra_data"]["scenarios"].items())
      if (s["status"] != "completed") stopped += s["status"].get<std::string>() + "\n";
    double max = 0;
    for (const auto& t : res["tests"]) max += t["max_score"].get<double>();
    const double share = res["score"].get<double>() / max;
    INFO("score ", share, "; stopped: ", stopped);
    if (unstable)
      CHECK((res["output"].get<std::string>().find("unstable") != std::string::npos || stopped.find("unstable") != std::string::npos));
    if (slipping) CHECK(stopped.find("slipped") != std::string::npos);
    if (skidding) {
      bool skidded = false;
      for (const auto& t : res["tests"])
        skidded = skidded || (t["name"].get<std::string>().find("skid") != std::string::npos &&
                              t["score"].get<double>() < 0.5 * t["max_score"].get<double>());
      CHECK(skidded);
    }
    if (mediocre) CHECK((share >= 0.25 && share <= 0.75));
  }
  CHECK(checked >= 8);
}
