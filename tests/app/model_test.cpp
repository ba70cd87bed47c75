// dynlab model FILE end to end: what it prints about the mechanism it read, the passive run's closure
// residual and energy balance in the trace it writes, byte-identical reruns, and the bad-input contract
// for hostile model files (exit 2, one line naming the file, nothing written).
#include <doctest/doctest.h>

#include <cmath>

#include "tests/app/cli_run.h"

using namespace dyn::test::cli;

namespace {
std::string model(const char* name) { return quote(std::string(DYNLAB_SOURCE_DIR) + "/assets/models/" + name); }
}  // namespace

TEST_CASE("dynlab model: the four-bar is read, run passive, and its trace keeps closure and energy") {
  TempDir dir("model_fourbar");
  const Result r = dynlab(dir, "model " + model("fourbar.xml") + " --duration 1 --out out");
  INFO(r.out, r.err);
  REQUIRE(r.code == 0);
  CHECK(r.out.find("1 closure (2 of 3 rows kept), 1 degree of freedom after closure") != std::string::npos);
  CHECK(r.out.find("closure pin_C: connect coupler to rocker, rows x z kept, y dropped") != std::string::npos);
  const Csv csv = readCsv(dir / "out/trace.csv");
  REQUIRE(csv.rows.size() == 1001);
  for (const char* c : {"t", "q_crank", "q_coupler", "q_rocker", "v_crank", "energy", "work", "constraint_residual", "f_pin_C_x", "f_pin_C_z"})
    CHECK_MESSAGE(csv.col(c) >= 0, c);
  double phi = 0, de = 0, swing = 0;
  const double e0 = csv.at(0, "energy");
  for (std::size_t i = 0; i < csv.rows.size(); ++i) {
    phi = std::max(phi, csv.at(i, "constraint_residual"));
    de = std::max(de, std::abs(csv.at(i, "energy") - e0));
    swing = std::max(swing, std::abs(csv.at(i, "q_crank") - csv.at(0, "q_crank")));
  }
  CHECK(phi < 1e-12);
  CHECK(de < 1e-6);
  CHECK(swing > 0.5);  // rad: it really moved
  // The pin holds the rocker up: at rest in the first row its force balances gravity with the crank's share.
  CHECK(std::abs(csv.at(0, "f_pin_C_z")) > 0.1);
  // Bullet beside it, from the same state: the same columns; its pin force over the first step from
  // rest is the hand engine's η; its closure drifts but stays small.
  const Csv bt = readCsv(dir / "out/trace_bullet.csv");
  CHECK(bt.header == csv.header);
  REQUIRE(bt.rows.size() == csv.rows.size());
  CHECK(std::abs(bt.at(0, "f_pin_C_z") - csv.at(0, "f_pin_C_z")) < 1e-9);
  double phi_bt = 0;
  for (std::size_t i = 0; i < bt.rows.size(); ++i) phi_bt = std::max(phi_bt, bt.at(i, "constraint_residual"));
  CHECK(phi_bt > 1e-9);
  CHECK(phi_bt < 1e-3);
  CHECK(r.out.find("agreement: max |q_hand − q_bullet|∞") != std::string::npos);
  // Same input, same bytes.
  const std::string first = readFile(dir / "out/trace.csv"), first_bt = readFile(dir / "out/trace_bullet.csv");
  REQUIRE(dynlab(dir, "model " + model("fourbar.xml") + " --duration 1 --out out").code == 0);
  CHECK(readFile(dir / "out/trace.csv") == first);
  CHECK(readFile(dir / "out/trace_bullet.csv") == first_bt);
  // One engine: only its trace.
  REQUIRE(dynlab(dir, "model " + model("fourbar.xml") + " --duration 0.1 --engine hand --out hand_only").code == 0);
  CHECK(fs::exists(dir / "hand_only/trace.csv"));
  CHECK_FALSE(fs::exists(dir / "hand_only/trace_bullet.csv"));
}

TEST_CASE("dynlab model: hostile and unsupported files get one line and exit 2, nothing written") {
  TempDir dir("model_bad");
  writeFile(dir / "latin1.xml", "<mujoco model=\"caf\xE9\"/>");
  checkBadInput(dir, "model latin1.xml --out o", {"latin1.xml", "not valid UTF-8"}, dir / "o");
  writeFile(dir / "ball.xml", "<mujoco><worldbody><body name=\"b\"><joint name=\"s\" type=\"ball\"/>"
                              "<geom size=\"0.1\"/></body></worldbody></mujoco>");
  checkBadInput(dir, "model ball.xml --out o", {"ball.xml", "joint 's'", "ball joint", "hinge and slide"}, dir / "o");
  checkBadInput(dir, "model missing.xml --out o", {"missing.xml", "no such file"}, dir / "o");
  checkBadInput(dir, "model " + model("fourbar.xml") + " --duration 600 --dt 1e-5 --out o", {"60000000 steps", "at most 2000000"}, dir / "o");
}
