// Advice that fits the law (issue 41, item 4): every lab's advice entries name laws and gains that
// exist (check-lab's look, grading/advice.h); graded with law A and short of full marks, a test's
// "what to change" never names law A as the fix, never a gain law A does not read (unless it names
// the law that reads it), never a value the gain already has. The cases: fivebar graded with
// task_inverse_dynamics in the payload scenario; puma_impedance with k_imp already K_des, and with the
// target programmed exactly.
#include <doctest/doctest.h>

#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include "grading/advice.h"
#include "grading/grade.h"
#include "labs/lab.h"
#include "labs/submission.h"

namespace {

using json = nlohmann::json;

struct Graded {
  json config;                                            // the lab's config with the submission applied
  std::vector<std::pair<dyn::GradedTest, std::string>> short_tests;  // below full marks, with their advice
  double score = 0;
};

Graded grade(const json& sub) {
  dyn::GradeOptions o;
  o.keep_runs = true;
  const dyn::GradeOutcome g = dyn::gradeSubmission(sub, "submission.json", o);
  REQUIRE_MESSAGE(g.error.empty(), g.error);
  const std::string lab = sub.at("lab");
  const json base = dyn::loadJsonFile(dyn::defaultConfigPath(lab));
  Graded out{dyn::applySubmission(base, dyn::JsonView(sub, "submission.json"), lab, true), {}, g.results.at("score").get<double>()};
  for (const auto& t : g.graded.tests)
    if (t.score < t.test.points - 1e-9) out.short_tests.push_back({t, t.advice});
  return out;
}

std::string chosen(const json& config, const std::string& option) {
  const json& o = config.at("submission_options").at(option);
  return config.at(json::json_pointer(o.at("target").get<std::string>())).get<std::string>();
}

// The law-fit checks on every short test's advice of one graded submission; returns how many advised.
int checkFits(const json& sub) {
  const Graded g = grade(sub);
  const json options = g.config.value("submission_options", json::object());
  const std::set<std::string> read = dyn::gainsRead(g.config);
  int advised = 0;
  for (const auto& [t, advice] : g.short_tests) {
    INFO(sub.dump() << ": " << t.test.name << " [" << t.test.scenario << "]: " << advice);
    advised += !advice.empty();
    const std::vector<std::string> ws = dyn::identifierWords(advice);
    std::vector<json> named;  // the laws the advice names (to switch to)
    for (std::size_t i = 0; i < ws.size(); ++i)
      for (const auto& [key, o] : options.items())
        for (const auto& c : o.at("choices"))
          if (ws[i] == c && (ws[i].find('_') != std::string::npos || (i > 0 && ws[i - 1] == key))) {
            CHECK_MESSAGE(chosen(g.config, key) != ws[i], "names the law in use, " << key << " " << ws[i]);
            json other = g.config;
            other[json::json_pointer(o.at("target").get<std::string>())] = c;
            named.push_back(other);
          }
    for (std::size_t i = 0; i < ws.size(); ++i) {
      const std::string& w = ws[i];
      if (!g.config.at("gains").contains(w)) continue;
      bool ok = read.count(w) > 0;
      for (const json& other : named) ok = ok || dyn::gainsRead(other).count(w) > 0;
      CHECK_MESSAGE(ok, "names the gain " << w << ", which the law in use does not read");
      // "gain = <number>": never the value it has.
      if (i + 1 < ws.size() && advice.find(w + " = " + ws[i + 1]) != std::string::npos && std::isdigit(static_cast<unsigned char>(ws[i + 1][0]))) {
        const double asked = std::stod(ws[i + 1]), has = g.config["gains"][w]["value"].get<double>();
        CHECK_MESSAGE(std::abs(asked - has) > 0.01 * std::abs(has), "asks for " << w << " = " << asked << ", the value it has");
      }
    }
  }
  return advised;
}

json load(const std::string& lab, const std::string& file) {
  return dyn::loadJsonFile(std::string(DYNLAB_SOURCE_DIR) + "/labs/" + lab + "/" + file);
}

std::string adviceOf(const Graded& g, const std::string& scenario, const std::string& metric) {
  for (const auto& [t, advice] : g.short_tests)
    if (t.test.scenario == scenario && t.test.metric == metric) return advice;
  return "(at full marks)";
}

}  // namespace

TEST_CASE("every lab's advice names laws that exist and gains those laws read") {
  for (const auto& entry : dyn::labRegistry()) {
    const std::string file = dyn::defaultConfigPath(entry.name);
    for (const auto& p : dyn::adviceProblems(dyn::loadJsonFile(file), file)) FAIL_CHECK(entry.name << ": " << p);
  }
}

TEST_CASE("check-lab's look finds advice that tells a law to use itself or names a gain it does not read") {
  json config = dyn::loadJsonFile(dyn::defaultConfigPath("fivebar"));
  config["metric_docs"]["e_rms"]["advice"] = "raise kp with kd, or use task_inverse_dynamics";
  const auto problems = dyn::adviceProblems(config, "fivebar.json");
  bool itself = false, unread = false;
  for (const auto& p : problems) {
    itself = itself || p.find("to use kind task_inverse_dynamics, the law it uses") != std::string::npos;
    unread = unread || (p.find("names the gain kp, which kind ") != std::string::npos && p.find("does not read") != std::string::npos);
  }
  CHECK(itself);
  CHECK(unread);
  config["metric_docs"]["e_rms"]["advice"] = json::array({{{"when", {{"kind", "no_such_law"}}}, {"text", "x"}}});
  const auto bad = dyn::adviceProblems(config, "fivebar.json");
  REQUIRE(!bad.empty());
  CHECK(bad.front().find("/metric_docs/e_rms/advice/0/when/kind") != std::string::npos);
}

TEST_CASE("fivebar: graded with task_inverse_dynamics, the payload test does not say raise kp or use that law") {
  const json sub = {{"lab", "fivebar"}, {"kind", "task_inverse_dynamics"}, {"gains", {{"kp", 2000}, {"kd", 40}, {"omega_n", 12}, {"zeta", 0.7}}}};
  CHECK(checkFits(sub) > 0);
  const std::string advice = adviceOf(grade(sub), "payload", "e_rms");
  INFO(advice);
  CHECK(advice.find("omega_n") != std::string::npos);
  CHECK(advice.find("task_inverse_dynamics") == std::string::npos);
  CHECK(advice.find("kp") == std::string::npos);
  for (const char* f : {"examples/computed_torque.json", "examples/joint_pd.json", "examples/task_pd.json"}) CHECK(checkFits(load("fivebar", f)) > 0);
}

TEST_CASE("puma_impedance: no advice to program what is programmed; the handout's explanation reaches the report") {
  // The target programmed exactly, with force feedback: it loses points to the payload and the noise only.
  const json exact = {{"lab", "puma_impedance"}, {"kind", "impedance_inverse_dynamics"},
                      {"gains", {{"k_imp", 1000}, {"d_imp", 62.61}, {"m_imp", 2}, {"omega_n", 100}, {"zeta", 1}}}};
  const Graded g = grade(exact);
  REQUIRE(!g.short_tests.empty());
  for (const auto& [t, advice] : g.short_tests) {
    INFO(t.test.name << ": " << advice);
    CHECK(advice.find("program the target") == std::string::npos);
    CHECK(advice.find("k_imp = K_des") == std::string::npos);
  }
  const std::string payload = adviceOf(g, "payload", "response_error");
  INFO(payload);
  CHECK(payload.find("amplifies what the sensor does not read") != std::string::npos);
  // impedance_joint with k_imp = K_des: its deflection error is the joint loop's compliance, not k_imp.
  const json joint = load("puma_impedance", "examples/impedance_joint_soft.json");
  const std::string deflection = adviceOf(grade(joint), "nominal", "deflection_error");
  INFO(deflection);
  CHECK(deflection.find("k_imp must be") == std::string::npos);
  CHECK(deflection.find("omega_n") != std::string::npos);
  // A stiffness off the target's is told so.
  json soft = exact;
  soft["gains"]["k_imp"] = 800;
  CHECK(adviceOf(grade(soft), "nominal", "deflection_error").find("k_imp") != std::string::npos);
  for (const char* f : {"examples/impedance_joint_soft.json", "examples/impedance_task.json", "examples/inverse_dynamics_light.json"})
    CHECK(checkFits(load("puma_impedance", f)) > 0);
  CHECK(checkFits(exact) > 0);
}

TEST_CASE("every other lab with laws: graded with law A, the advice fits law A") {
  for (const char* f : {"examples/computed_torque.json", "examples/joint_pd_gravity.json", "examples/pid.json"}) CHECK(checkFits(load("puma_motion", f)) > 0);
  for (const char* f : {"examples/mediocre.json", "examples/spring.json", "examples/stiff_damper.json"}) CHECK(checkFits(load("pen_on_table", f)) > 0);
  for (const char* f : {"examples/mediocre.json", "examples/proportional.json", "examples/unstable_integral.json"}) CHECK(checkFits(load("slider_crank", f)) > 0);
  for (const char* f : {"examples/computed_torque.json", "examples/pd_gravity.json", "examples/pid.json"}) CHECK(checkFits(load("motion_control", f)) > 0);
  for (const char* f : {"examples/joint_space_pid.json", "examples/joint_space_soft.json", "examples/task_space.json"}) CHECK(checkFits(load("impedance", f)) > 0);
  // The labs without a choice of law: every gain is read, the advice still names only the lab's.
  for (const char* f : {"examples/mediocre.json", "examples/slipping.json"}) CHECK(checkFits(load("grasp", f)) > 0);
  for (const char* f : {"examples/mediocre.json", "examples/skidding.json"}) CHECK(checkFits(load("unicycle", f)) > 0);
}

TEST_CASE("a malformed advice entry is one line naming the lab file and its JSON path") {
  json config = dyn::loadJsonFile(dyn::defaultConfigPath("puma_impedance"));
  const auto first = [&](const json& advice) {
    config["metric_docs"]["deflection_error"]["advice"] = advice;
    const auto p = dyn::adviceProblems(config, "puma_impedance.json");
    return p.empty() ? std::string("(none)") : p.front();
  };
  CHECK(first(json::array({{{"when", {{"gains_off", {{"k_imp", std::string(200, '(') + "1"}}}}}, {"text", "x"}}})).rfind("/metric_docs/deflection_error/advice/0/when/gains_off/k_imp: expected a number, or an expression", 0) == 0);
  CHECK(first(json::array({{{"when", {{"gains_off", {{"no_gain", 1}}}}}, {"text", "x"}}})).find("a gain of the lab's \"gains\", got \"no_gain\"") != std::string::npos);
  CHECK(first(json::array({{{"when", {{"scenario", "nowhere"}}}, {"text", "x"}}})).find("a scenario of the rubric") != std::string::npos);
  CHECK(first(json::array({{{"when", {{"colour", "red"}}}, {"text", "x"}}})).find("a condition: kind, scenario, gains_at") != std::string::npos);
  CHECK(first(json::array({{{"when", {{"kind", "impedance_joint"}}}, {"text", "raise omega_n"}}})).find("no entry for kind impedance_task") != std::string::npos);
  // The expression of the target's damping evaluates as the handout's D_des.
  config["metric_docs"]["deflection_error"]["advice"] = json::array({{{"when", {{"gains_at", {{"d_imp", "2*{/target/zeta}*sqrt({/target/k}*{/target/m})"}}}}}, {"text", "x"}}, {{"text", "y"}}});
  const auto entries = dyn::parseAdvice(dyn::JsonView(config, "c.json")["metric_docs"]["deflection_error"]["advice"], dyn::JsonView(config, "c.json"));
  CHECK(entries.at(0).when["gains_at"]["d_imp"].get<double>() == doctest::Approx(2 * 0.7 * std::sqrt(2000.0)));
}

// Issue 41, item 9 in the report: the pen's lost-contact test names the cause the run shows.
TEST_CASE("pen_on_table: the report's verdict on lost contact is the bounce on touchdown or the pressed loop, as the run shows") {
  const std::string dir = std::string(DYNLAB_TEST_TMP) + "/advice_pen";
  std::filesystem::create_directories(dir);
  const auto advice = [&](double D_z, double noise) {
    json config = dyn::loadJsonFile(dyn::defaultConfigPath("pen_on_table"));
    config["controller"]["delay"] = 0.03;
    config["controller"]["noise"] = noise;
    config["metrics"]["max_liftoffs"] = 1000;  // every lift-off counted, none stops the run
    const std::string file = dir + "/config.json";
    std::ofstream(file) << config.dump(1);
    dyn::GradeOptions o;
    o.config_file = file;
    o.keep_runs = true;
    const json sub = {{"lab", "pen_on_table"}, {"force_law", "damper"}, {"gains", {{"kp", 5000}, {"kv", 110}, {"D_z", D_z}, {"K_z", 2000}}}};
    const dyn::GradeOutcome g = dyn::gradeSubmission(sub, "submission.json", o);
    REQUIRE_MESSAGE(g.error.empty(), g.error);
    for (const auto& t : g.graded.tests)
      if (t.test.scenario == "nominal" && t.test.metric == "contact_lost_time") return t.advice;
    return std::string("(no such test)");
  };
  const std::string bounce = advice(100, 0.0), pressed = advice(110, 6.0);
  INFO("bounced and settled: " << bounce << "\npressed: " << pressed);
  CHECK(bounce.rfind("the pen bounced on touchdown", 0) == 0);
  CHECK(pressed.rfind("the pressed loop oscillates", 0) == 0);
  std::filesystem::remove_all(dir);
}
