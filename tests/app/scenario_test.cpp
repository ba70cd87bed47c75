// dynlab run/figure/ui --scenario NAME: the lab under one rubric scenario, exactly as the grader
// runs it. Each trace shows what its scenario's patch says (read from the lab's JSON: the payload
// mass in m_c·a = f_Tx, the sensor delay as the shift between f_meas and f_Ty, the sensor noise as
// their difference), and matches the grader's run of the same file bit for bit (trace hash, metrics).
#include <doctest/doctest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "tests/app/cli_run.h"
#include "tests/test_files.h"

using namespace dyn::test::cli;
using json = nlohmann::json;

namespace {

const std::string kExamples = std::string(DYNLAB_SOURCE_DIR) + "/labs/slider_crank/examples/";

json labConfig() { return json::parse(defaultConfigText()); }

// The slope of f_Tx against the slider's acceleration (central differences of v_c): its mass.
double massFromTrace(const Csv& tr, double dt) {
  double num = 0, den = 0;
  for (std::size_t k = 1; k + 1 < tr.rows.size(); ++k) {
    const double a = (tr.at(k + 1, "v_c") - tr.at(k - 1, "v_c")) / (2 * dt);
    num += a * tr.at(k, "f_Tx");
    den += a * a;
  }
  return num / den;
}

// The shift (in steps) at which f_meas best follows f_Ty, and the RMS of what is left (the noise).
std::pair<int, double> sensorShift(const Csv& tr) {
  std::pair<int, double> best{-1, INFINITY};
  for (int d = 0; d <= 60; ++d) {
    double sum = 0, sum2 = 0;
    std::size_t n = 0;
    for (std::size_t k = 60; k < tr.rows.size(); ++k, ++n) {
      const double e = tr.at(k, "f_meas") - tr.at(k - std::size_t(d), "f_Ty");
      sum += e, sum2 += e * e;
    }
    const double rms = std::sqrt(std::max(0.0, sum2 / double(n) - (sum / double(n)) * (sum / double(n))));
    if (rms < best.second) best = {d, rms};
  }
  return best;
}

Csv runScenario(const TempDir& dir, const std::string& scenario, const std::string& out) {
  std::vector<std::string> args = {"run", "slider_crank", "--engine", "hand", "--gains", kExamples + "mediocre.json", "--out",
                                   out};
  if (!scenario.empty()) args = cat(args, {"--scenario", scenario});
  const Result r = dynlab(dir, args);
  INFO(r.err);
  REQUIRE(r.code == 0);
  if (!scenario.empty()) CHECK(r.out.find("under scenario " + scenario) != std::string::npos);
  return readCsv(dir / out / "trace_hand.csv");
}

}  // namespace

TEST_CASE("run --scenario: each trace shows its scenario's patch, read from the lab's JSON") {
  const TempDir dir("scenario_patch");
  const json cfg = labConfig();
  const json& sc = cfg["rubric"]["scenarios"];
  const double dt = cfg["simulation"]["dt"];

  const Csv nominal = runScenario(dir, "", "nominal");
  const Csv heavy = runScenario(dir, "heavy_load", "heavy");
  const Csv delay = runScenario(dir, "long_delay", "delay");
  const Csv noisy = runScenario(dir, "noisy_sensor", "noisy");

  // The payload: m_c x_c'' = f_Tx, with the mass the patch sets (0.5 kg → 0.6 kg).
  CHECK(massFromTrace(nominal, dt) == doctest::Approx(cfg["mechanism"]["load_mass"].get<double>()).epsilon(0.01));
  CHECK(massFromTrace(heavy, dt) == doctest::Approx(sc["heavy_load"]["patch"]["mechanism"]["load_mass"].get<double>()).epsilon(0.01));
  // The sensor: f_meas is f_Ty delayed by the configured delay, exactly; 30 ms under long_delay.
  const auto [d0, e0] = sensorShift(nominal);
  CHECK(d0 == std::lround(cfg["controller"]["delay"].get<double>() / dt));
  CHECK(e0 < 1e-9);
  const auto [d1, e1] = sensorShift(delay);
  CHECK(d1 == std::lround(sc["long_delay"]["patch"]["controller"]["delay"].get<double>() / dt));
  CHECK(e1 < 1e-9);
  // Noise: what is left of f_meas besides the delayed force has the patch's standard deviation.
  const auto [d2, e2] = sensorShift(noisy);
  CHECK(e2 == doctest::Approx(sc["noisy_sensor"]["patch"]["controller"]["noise_std"].get<double>()).epsilon(0.05));
  // The default output of a scenario run is its own folder, beside (not over) the nominal run.
  const Result r = dynlab(dir, {"run", "slider_crank", "--engine", "hand", "--duration", "0.1", "--scenario", "light_load"});
  REQUIRE(r.code == 0);
  CHECK(fs::exists(dir / "out/slider_crank/scenarios/light_load/trace_hand.csv"));
  CHECK(json::parse(readFile(dir / "out/slider_crank/scenarios/light_load/summary.json"))["scenario"] == "light_load");
  CHECK_FALSE(fs::exists(dir / "out/slider_crank/trace_hand.csv"));
}

TEST_CASE("run --scenario is the grader's run of the same file: same trace hash, same metrics") {
  const TempDir dir("scenario_grade");
  const std::string sub = kExamples + "proportional.json";
  REQUIRE(dynlab(dir, {"grade", sub, "--no-plots", "--out", "graded"}).code == 0);
  const json results = json::parse(readFile(dir / "graded/results.json"));
  for (const auto& [name, graded] : results["extra_data"]["scenarios"].items()) {
    CAPTURE(name);
    const Result r = dynlab(dir, {"run", "slider_crank", "--engine", "hand", "--gains", sub, "--scenario", name, "--out", name});
    REQUIRE(r.code == 0);
    const json summary = json::parse(readFile(dir / name / "summary.json"));
    const json& hand = summary["engines"]["hand"];
    char hash[17];
    std::snprintf(hash, sizeof hash, "%016llx", hand["trace_hash"].get<unsigned long long>());
    CHECK(graded["trace_hash"] == hash);  // noisy_sensor too: the same seed as the grader's
    for (const auto& [metric, value] : hand["metrics"].items())
      if (graded["metrics"].contains(metric)) CHECK_MESSAGE(graded["metrics"][metric] == value, metric);
  }
  // The seed is the lab's and the scenario's, never the submission's: the same gains in another file
  // (the default law left unnamed) give the same runs, noise and all (it gave another noise when the
  // seed hashed the submission: noise a student could re-roll).
  json other = json::parse(readFile(kExamples + "proportional.json"));
  REQUIRE(other["force_law"] == labConfig()["controller"]["force_law"]);
  other.erase("force_law");
  writeFile(dir / "other.json", other.dump());
  for (const std::string name : {"nominal", "noisy_sensor"})
    REQUIRE(dynlab(dir, {"run", "slider_crank", "--engine", "hand", "--gains", "other.json", "--scenario", name, "--out",
                         "other_" + name})
                .code == 0);
  CHECK(readFile(dir / "other_nominal/trace_hand.csv") == readFile(dir / "nominal/trace_hand.csv"));
  CHECK(readFile(dir / "other_noisy_sensor/trace_hand.csv") == readFile(dir / "noisy_sensor/trace_hand.csv"));
}

TEST_CASE("figure --scenario: the scenario's run, in its own folder, named in the title") {
  const TempDir dir("scenario_figure");
  const std::vector<std::string> args = {"figure", "slider_crank", "--engine", "hand",     "--duration",
                                         "0.5",    "--plot",       "f_Tx",     "--format", "svg"};
  REQUIRE(dynlab(dir, cat(args, {"--scenario", "heavy_load"})).code == 0);
  REQUIRE(dynlab(dir, args).code == 0);
  const std::string heavy = dyn::test::svgText(readFile(dir / "out/slider_crank/scenarios/heavy_load/figures/plot_f_Tx.svg"));
  const std::string nominal = dyn::test::svgText(readFile(dir / "out/slider_crank/figures/plot_f_Tx.svg"));
  REQUIRE_FALSE(heavy.empty());
  CHECK(heavy.find("heavy_load") != std::string::npos);
  CHECK(nominal.find("heavy_load") == std::string::npos);
  CHECK(heavy != nominal);
}

TEST_CASE("an unknown scenario: one line listing the rubric's scenarios, exit 2, nothing written") {
  const TempDir dir("scenario_bad");
  std::vector<std::string> names = {"--scenario", "\"nope\""};
  for (const auto& [name, _] : labConfig()["rubric"]["scenarios"].items()) names.push_back(name);
  checkBadInput(dir, {"run", "slider_crank", "--scenario", "nope"}, names, dir / "out");
  checkBadInput(dir, {"figure", "slider_crank", "--scenario", "nope"}, names, dir / "out");
  // A config without a rubric has no scenarios to run.
  json cfg = labConfig();
  cfg.erase("rubric");
  writeFile(dir / "plain.json", cfg.dump());
  checkBadInput(dir, {"run", "slider_crank", "--config", "plain.json", "--scenario", "nominal"}, {"--scenario", "rubric"},
                dir / "out");
#ifdef DYNLAB_UI_BIN
  // The window checks it before opening: no display needed.
  checkBadInput(dir, {"ui", "slider_crank", "--scenario", "nope"}, names, dir / "out");
#endif
}
