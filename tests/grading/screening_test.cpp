// grading/scenario screenLoops: a loop without feedback (an open-loop law, zero gains) is still
// reported, with every metric present and worth nothing; a pole on the imaginary axis is not
// stable. Generic (a stub lab of given loops) and on the slider crank's submission options.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "grading/grade.h"
#include "grading/scenario.h"
#include "labs/run.h"
#include "labs/submission.h"

using namespace dyn;

namespace {

// A lab that is nothing but its loops (screening reads only linearise()).
class LoopsOnly final : public Lab {
 public:
  explicit LoopsOnly(std::vector<LinearLoop> loops) : loops_(std::move(loops)) {}
  std::vector<std::string> columns() const override { return {"t"}; }
  double dt() const override { return 1e-3; }
  double duration() const override { return 0; }
  std::unique_ptr<Simulation> simulate(Engine) const override { return nullptr; }
  json metrics(const Trace&) const override { return json::object(); }
  json agreement(const Trace&, const Trace&) const override { return json::object(); }
  void scene(const Trace&, std::size_t, const Trace*, Scene&) const override {}
  void overlay(const Trace&, std::size_t, Overlay&) const override {}
  std::vector<LinearLoop> linearise() const override { return loops_; }

 private:
  std::vector<LinearLoop> loops_;
};

const char* const kLoopMetrics[] = {"_max_real_pole", "_damping", "_delay_margin", "_phase_margin_deg", "_crossover"};

// The slider crank with the submission's gains and options applied (no file needed).
std::unique_ptr<Lab> sliderCrank(const json& submission) {
  const LabEntry* entry = findLab("slider_crank");
  REQUIRE(entry != nullptr);
  const json base = loadJsonFile(defaultConfigPath("slider_crank"));
  const json applied = applySubmission(base, JsonView(submission, "submission.json"), "slider_crank", false);
  return buildLab(*entry, applied, "submission.json");
}

}  // namespace

TEST_CASE("a loop without feedback is reported with its metrics at zero and a note, not as unstable") {
  for (const Poly& num : {Poly{}, Poly{0.0}, Poly{0.0, 0.0}}) {
    CAPTURE(num.size());
    const ScreenResult r = screenLoops(LoopsOnly({{"motion", "position loop (PD)", num, {0, 0, 2.0}, 1e-3}}));
    for (const char* m : kLoopMetrics) {
      REQUIRE(r.metrics.contains(std::string("motion") + m));
      CHECK(r.metrics[std::string("motion") + m].get<double>() == 0.0);
    }
    REQUIRE(r.notes.size() == 1);
    CHECK(r.notes[0] == "position loop (PD): no feedback — no margin to award.");
    CHECK_FALSE(r.unstable);
  }
}

TEST_CASE("a pole at 0 is not stable: no damping, no delay margin") {
  // m s² + k_d s: velocity feedback only leaves the position an integrator (a pole at 0).
  const ScreenResult r = screenLoops(LoopsOnly({{"motion", "position loop (D only)", {0, 40}, {0, 0, 2.0}, 5e-4}}));
  CHECK(r.unstable);
  CHECK(r.metrics["motion_damping"].get<double>() == 0.0);
  CHECK(r.metrics["motion_delay_margin"].get<double>() == 0.0);
  CHECK(r.notes[0].find("not stable") != std::string::npos);
  CHECK(r.notes[0].find("at 0 rad/s") != std::string::npos);
  CHECK(r.notes[0].find("destabilises") == std::string::npos);  // it is not the delay's doing
}

TEST_CASE("an unstable loop with real poles earns no damping (ζ of real poles would read 1)") {
  // L = −3/(s + 1) closes to s + 1 − 3 = s − 2: one real pole, at +2.
  const ScreenResult r = screenLoops(LoopsOnly({{"x", "a loop", {-3}, {1, 1}, 0}}));
  CHECK(r.unstable);
  CHECK(r.metrics["x_max_real_pole"].get<double>() == doctest::Approx(2));
  CHECK(r.metrics["x_damping"].get<double>() == 0.0);
}

TEST_CASE("a stable loop keeps its damping and margins") {
  // m s² + k_d s + k_p with m = 1, k_d = 2, k_p = 4: ζ = 0.5.
  const ScreenResult r = screenLoops(LoopsOnly({{"m", "a PD loop", {4, 2}, {0, 0, 1}, 0}}));
  CHECK_FALSE(r.unstable);
  CHECK(r.metrics["m_damping"].get<double>() == doctest::Approx(0.5));
  CHECK(r.metrics["m_delay_margin"].get<double>() > 0);
}

TEST_CASE("a remembered screening answers only for the same loop, bit for bit") {
  // ζ of m s² + k_d s + 4 is k_d / 4: loops that differ in one number, in its last bit, in the delay
  // or in a sign of zero, screened in turn and again, each as it was screened alone.
  const double kd = 2.0, kd_next = std::nextafter(2.0, 3.0);
  const std::vector<LinearLoop> loops = {{"m", "a PD loop", {4, kd}, {0, 0, 1}, 0},
                                         {"m", "a PD loop", {4, kd_next}, {0, 0, 1}, 0},
                                         {"m", "a PD loop", {4, kd}, {0, 0, 1}, 0.01},
                                         {"m", "a PD loop", {4, 3.0}, {0, 0, 1}, 0},
                                         {"m", "a PD loop", {4, kd}, {-0.0, 0, 1}, 0}};
  std::vector<json> first;
  for (const auto& l : loops) first.push_back(screenLoops(LoopsOnly({l})).metrics);
  CHECK(first[0]["m_damping"] != first[3]["m_damping"]);
  CHECK(first[0]["m_max_real_pole"] != first[2]["m_max_real_pole"]);  // the delay's Padé poles
  for (int round = 0; round < 2; ++round)
    for (std::size_t i = loops.size(); i-- > 0;) CHECK(screenLoops(LoopsOnly({loops[i]})).metrics == first[i]);
  CHECK(first[1]["m_damping"].get<double>() == doctest::Approx(0.5));
}

TEST_CASE("the slider crank reports both loops for every force law, and with zero motion gains") {
  const json gains = {{"kp_x", 300}, {"kd_x", 12}, {"kp_f", 0.5}, {"ki_f", 10}};
  for (const char* law : {"open_loop", "proportional", "integral"}) {
    CAPTURE(law);
    const ScreenResult r = screenLoops(*sliderCrank({{"force_law", law}, {"gains", gains}}));
    for (const char* loop : {"motion", "force"})
      for (const char* m : kLoopMetrics) CHECK(r.metrics.contains(std::string(loop) + m));
    if (std::string(law) == "open_loop") {
      CHECK(r.metrics["force_delay_margin"].get<double>() == 0.0);
      CHECK(r.notes.back() == "rail-force loop (open loop): no feedback — no margin to award.");
    } else {
      CHECK(r.metrics["force_delay_margin"].get<double>() > 0.0);
    }
  }
  // k_px = k_dx = 0: the slider is a double integrator with no feedback.
  json zero = gains;
  zero["kp_x"] = 0;
  zero["kd_x"] = 0;
  const ScreenResult r = screenLoops(*sliderCrank({{"gains", zero}}));
  CHECK(r.metrics["motion_damping"].get<double>() == 0.0);
  CHECK(r.notes.front().find("no feedback") != std::string::npos);
  // k_px = 0 alone: a pole at 0, not stable.
  zero["kd_x"] = 12;
  const ScreenResult d = screenLoops(*sliderCrank({{"gains", zero}}));
  CHECK(d.metrics["motion_damping"].get<double>() == 0.0);
  CHECK(d.notes.front().find("not stable") != std::string::npos);
}

TEST_CASE("an open-loop submission grades: its screening test is present and scores 0, not a config error") {
  const auto dir = std::filesystem::temp_directory_path() / ("dynlab-screening-test-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string file = (dir / "open_loop.json").string();
  std::ofstream(file) << R"({"lab": "slider_crank", "force_law": "open_loop",
                            "gains": {"kp_x": 300, "kd_x": 12, "kp_f": 0.5, "ki_f": 10}})";
  const GradeOutcome g = gradeSubmission(file, {});
  std::filesystem::remove_all(dir);
  CHECK_FALSE(g.input_error);
  CHECK(g.results.at("output").get<std::string>().find("expected a metric") == std::string::npos);
  bool found = false;
  for (const auto& t : g.results.at("tests")) {
    if (t.at("name").get<std::string>().find("delay margin") == std::string::npos) continue;
    found = true;
    CHECK(t.at("score").get<double>() == 0.0);
  }
  CHECK(found);
  CHECK(g.results.at("output").get<std::string>().find("no feedback") != std::string::npos);
}
