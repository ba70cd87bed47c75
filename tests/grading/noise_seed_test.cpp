// The noise of a scenario cannot be shopped for: its seed is the lab's and the scenario's, never the
// submission's. A gain the law in use never reads, changed, grades identically (puma_impedance with
// force feedback: omega_n is the joint-space law's; it moved the grade by 0.28 of 12 when the seed
// hashed every gain); so do the same gains written another way. A gain the law reads still changes it.
#include <doctest/doctest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "grading/grade.h"

namespace {

namespace fs = std::filesystem;
using json = nlohmann::json;

const fs::path kTmp = fs::path(DYNLAB_TEST_TMP) / ("noise_seed_" + std::to_string(::getpid()));

// The grade of a submission written as `text`; results.json as a string, without its timing.
json gradeText(const std::string& name, const std::string& text) {
  fs::create_directories(kTmp);
  const fs::path file = kTmp / name;
  std::ofstream(file) << text;
  const dyn::GradeOutcome g = dyn::gradeSubmission(file.string(), {});
  REQUIRE_MESSAGE(!g.input_error, g.error);
  json r = g.results;
  r.erase("execution_time");
  return r;
}

double score(const json& r) { return r.at("score").get<double>(); }

}  // namespace

TEST_CASE("a scenario's noise does not depend on the submission: unread gains and spelling change nothing") {
  const std::string head = R"({"lab": "puma_impedance", "kind": "impedance_inverse_dynamics", "gains": {"k_imp": 1000, "d_imp": 62.6, "m_imp": 2, )";
  const json a = gradeText("a.json", head + R"("omega_n": 100, "zeta": 1}})");
  const json b = gradeText("b.json", head + R"("omega_n": 150, "zeta": 1}})");         // omega_n: unread by this law
  const json c = gradeText("c.json", head + R"("omega_n": 100.0, "zeta": 1e0}})");     // the same values, spelled otherwise
  CHECK(score(a) == score(b));
  CHECK(score(a) == score(c));
  CHECK(a.at("tests") == b.at("tests"));
  CHECK(a["extra_data"]["fingerprint"]["trajectory_hash"] == b["extra_data"]["fingerprint"]["trajectory_hash"]);
  CHECK(a["extra_data"]["fingerprint"]["submission_hash"] != b["extra_data"]["fingerprint"]["submission_hash"]);
  // A gain the law reads still matters: the damping programmed.
  const json d = gradeText("d.json", R"({"lab": "puma_impedance", "kind": "impedance_inverse_dynamics", "gains": {"k_imp": 1000, "d_imp": 40, "m_imp": 2, "omega_n": 100, "zeta": 1}})");
  CHECK(score(d) != score(a));
  fs::remove_all(kTmp);
}
