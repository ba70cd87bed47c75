// dynlab model FILE with dynlab's own elements beside the file (a rolling wheel, unilateral plane
// contacts: STEM.loops.json), end to end through the real binary:
//  * unicycle.xml, driven by constant torques, rolls without slip in both engines (slip speed and the
//    no-slip rows' residual at rounding level in the hand engine), its ground carries m g, its lateral
//    force is m v φ' (an upright wheel's closed form) and its energy balances the torques' work;
//  * pen_drop.xml, a pen dropped flat-ish on a table: it lands (plastic touchdowns: their energy in the
//    books), comes to rest flat, and the table carries m g, half at each end;
//  * pen.xml (the pen-on-table lab's arm) falls onto its table: the contact never pulls or sinks;
//  * a bad element in the JSON is one line naming the file and the JSON path, exit 2, nothing written;
//  * `dynlab figure pen_drop.xml` plots the contacts' forces and books the touchdowns (the model file's
//    lab, read once: it runs after the file is gone), and `dynlab bench` times files with elements.
#include <doctest/doctest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "labs/generic/model_lab.h"
#include "tests/app/cli_run.h"

using namespace dyn::test::cli;

namespace {
std::string model(const char* name) { return std::string(DYNLAB_SOURCE_DIR) + "/assets/models/" + name; }

double maxAbsColumn(const Csv& csv, const std::string& c) {
  double m = 0;
  for (std::size_t i = 0; i < csv.rows.size(); ++i) m = std::max(m, std::abs(csv.at(i, c)));
  return m;
}
}  // namespace

TEST_CASE("dynlab model unicycle.xml: the wheel beside the file rolls without slip, m v φ' sideways, in both engines") {
  TempDir dir("model_unicycle");
  const Result r = dynlab(dir, {"model", model("unicycle.xml"), "--duration", "2", "--torque", "spin=0.05", "--torque",
                                "heading=0.002", "--out", "out"});
  INFO(r.out, r.err);
  REQUIRE(r.code == 0);
  CHECK(r.out.find("5 joints, 0 closures (0 of 0 rows kept), 2 degrees of freedom after closure") != std::string::npos);
  CHECK(r.out.find("rolling wheel: body wheel, radius 0.1 m on the ground z = 0") != std::string::npos);
  const Csv hand = readCsv(dir / "out/trace.csv"), bullet = readCsv(dir / "out/trace_bullet.csv");
  REQUIRE(hand.rows.size() == 2001);
  CHECK(bullet.header == hand.header);
  for (const char* c : {"f_wheel_long", "f_wheel_lat", "f_wheel_normal", "skid_margin_wheel", "slip_wheel", "constraint_residual"})
    CHECK_MESSAGE(hand.col(c) >= 0, c);
  const std::size_t last = hand.rows.size() - 1;
  // It moved: rolled some 20 cm and turned.
  const double travel = std::hypot(hand.at(last, "q_x"), hand.at(last, "q_y"));
  MESSAGE("unicycle: travel " << travel << " m, heading " << hand.at(last, "q_heading") << " rad");
  CHECK(travel > 0.1);
  CHECK(std::abs(hand.at(last, "q_heading")) > 0.1);
  // No slip: the contact's material speed and every row (x, y velocity-level; z on the ground).
  const double slip = maxAbsColumn(hand, "slip_wheel"), phi = maxAbsColumn(hand, "constraint_residual");
  MESSAGE("hand: max slip " << slip << " m/s, max residual " << phi << "; Bullet: max slip " << maxAbsColumn(bullet, "slip_wheel"));
  CHECK(slip < 1e-12);
  CHECK(phi < 1e-12);
  CHECK(maxAbsColumn(bullet, "slip_wheel") < 1e-9);
  // The ground carries the weight; sideways the centripetal m v φ' (v = r θ'), along the heading m r θ''
  // (the drive torque's share: τ r / (I_a + m r²)).
  const double m = 2.0, r_w = 0.1, g = 9.81, I_a = 0.01;
  double lat = 0, normal = 0, along = 0;
  for (std::size_t i = 0; i < hand.rows.size(); ++i) {
    normal = std::max(normal, std::abs(hand.at(i, "f_wheel_normal") - m * g));
    lat = std::max(lat, std::abs(std::abs(hand.at(i, "f_wheel_lat")) - m * r_w * std::abs(hand.at(i, "v_spin") * hand.at(i, "v_heading"))));
    along = std::max(along, std::abs(std::abs(hand.at(i, "f_wheel_long")) - m * r_w * 0.05 / (I_a + m * r_w * r_w)));
  }
  MESSAGE("|f_normal − m g| " << normal << ", ||f_lat| − m v φ'| " << lat << ", ||f_long| − m r θ''| " << along);
  CHECK(normal < 1e-9);
  CHECK(lat < 1e-9);
  CHECK(along < 1e-9);
  CHECK(std::abs(hand.at(last, "f_wheel_lat")) > 0.1);  // N: it really turned
  // Energy: E − E0 = W (the torques'), to RK4's error.
  double balance = 0;
  for (std::size_t i = 0; i < hand.rows.size(); ++i)
    balance = std::max(balance, std::abs(hand.at(i, "energy") - hand.at(0, "energy") - hand.at(i, "work")));
  CHECK(balance < 1e-9);
}

TEST_CASE("dynlab model pen_drop.xml: the pen lands on the table and at rest the table carries m g, half at each end") {
  TempDir dir("model_pen_drop");
  const Result r = dynlab(dir, {"model", model("pen_drop.xml"), "--duration", "1", "--out", "out"});
  INFO(r.out, r.err);
  REQUIRE(r.code == 0);
  CHECK(r.out.find("contact tip: a ball of radius 0.006 m on body pen against the plane n·x = 0 m") != std::string::npos);
  const Csv hand = readCsv(dir / "out/trace.csv");
  const std::size_t last = hand.rows.size() - 1;
  const double mg = 0.02 * 9.81;
  const double tip = hand.at(last, "f_tip_normal"), cap = hand.at(last, "f_cap_normal");
  MESSAGE("at rest: f_tip " << tip << " N, f_cap " << cap << " N (m g = " << mg << "), touchdowns took " << hand.at(last, "impacts") << " J");
  CHECK(std::abs(tip + cap - mg) < 1e-9);
  CHECK(std::abs(tip - mg / 2) < 1e-9);
  CHECK(std::abs(hand.at(last, "q_pitch") - 20 * M_PI / 180) < 1e-6);  // lying flat
  CHECK(std::abs(hand.at(last, "v_z")) + std::abs(hand.at(last, "v_pitch")) < 1e-9);
  // In the air the table pushes nothing; it never pulls; the ends never sink (touchdowns located to 1e-12).
  CHECK(hand.at(0, "f_tip_normal") == 0.0);
  double pull = 0, sink = 0, balance = 0;
  for (std::size_t i = 0; i < hand.rows.size(); ++i) {
    pull = std::min({pull, hand.at(i, "f_tip_normal"), hand.at(i, "f_cap_normal")});
    sink = std::min({sink, hand.at(i, "gap_tip"), hand.at(i, "gap_cap")});
    balance = std::max(balance, std::abs(hand.at(i, "energy") - hand.at(0, "energy") - hand.at(i, "work")));
  }
  CHECK(pull >= 0.0);
  CHECK(sink > -1e-11);
  // The plastic touchdowns took energy, and the books hold it: E − E0 − W at RK4's error.
  CHECK(hand.at(last, "impacts") > 0.01);
  CHECK(std::abs(hand.at(last, "work") + hand.at(last, "impacts")) < 1e-12);  // no friction: W is the touchdowns' alone
  CHECK(balance < 1e-9);
  // Bullet (balls on a static plane) rests on the table too, carrying m g.
  const Csv bullet = readCsv(dir / "out/trace_bullet.csv");
  CHECK(std::abs(bullet.at(last, "f_tip_normal") + bullet.at(last, "f_cap_normal") - mg) < 1e-6);
}

TEST_CASE("dynlab model pen.xml: the pen-on-table arm falls onto its table, the contact pressing, never pulling or sinking") {
  TempDir dir("model_pen");
  const Result r = dynlab(dir, {"model", model("pen.xml"), "--duration", "1.5", "--engine", "hand", "--out", "out"});
  INFO(r.out, r.err);
  REQUIRE(r.code == 0);
  const Csv hand = readCsv(dir / "out/trace.csv");
  double press = 0, pull = 0, sink = 0;
  for (std::size_t i = 0; i < hand.rows.size(); ++i) {
    press = std::max(press, hand.at(i, "f_tip_normal"));
    pull = std::min(pull, hand.at(i, "f_tip_normal"));
    sink = std::min(sink, hand.at(i, "gap_tip"));
  }
  CHECK(press > 1.0);  // N: it landed and leaned on the table
  CHECK(pull >= 0.0);
  CHECK(sink > -1e-11);
  CHECK(maxAbsColumn(hand, "f_tip_tangent") == 0.0);  // frictionless in the hand engine
}

TEST_CASE("dynlab model: a bad wheel or contact beside the file is one line naming the JSON path, exit 2, nothing written") {
  TempDir dir("model_contact_bad");
  writeFile(dir / "radius.json", R"({"rolling": [{"body": "wheel", "axle": [0, 1, 0], "radius": -0.1}]})");
  checkBadInput(dir, {"model", model("unicycle.xml"), "--loops", "radius.json", "--out", "o"},
                {"radius.json", "rolling[0].radius", "expected the wheel's radius"}, dir / "o");
  writeFile(dir / "bounce.json", R"({"contacts": [{"body": "pen", "point": [0, 0, 0], "restitution": 0.5}]})");
  checkBadInput(dir, {"model", model("pen_drop.xml"), "--loops", "bounce.json", "--out", "o"},
                {"bounce.json", "contacts[0].restitution", "unknown key", "no restitution"}, dir / "o");
  writeFile(dir / "normal.json", R"({"contacts": [{"body": "pen", "point": [0, 0, 0], "normal": [0, 0, "up"]}]})");
  checkBadInput(dir, {"model", model("pen_drop.xml"), "--loops", "normal.json", "--out", "o"},
                {"normal.json", "contacts[0].normal[2]"}, dir / "o");
  writeFile(dir / "body.json", R"({"rolling": [{"body": "hub", "axle": [0, 1, 0], "radius": 0.1}]})");
  checkBadInput(dir, {"model", model("unicycle.xml"), "--loops", "body.json", "--out", "o"},
                {"body.json", "rolling[0].body", "got 'hub'"}, dir / "o");
  writeFile(dir / "text.json", "rolling: yes");
  checkBadInput(dir, {"model", model("unicycle.xml"), "--loops", "text.json", "--out", "o"}, {"text.json", "not JSON"},
                dir / "o");
}

TEST_CASE("dynlab figure pen_drop.xml: the contacts' forces plotted, the touchdowns in the energy books, the file read once") {
  TempDir dir("model_pen_figure");
  const Result r = dynlab(dir, {"figure", model("pen_drop.xml"), "--duration", "1", "--out", "fig"});
  INFO(r.out, r.err);
  REQUIRE(r.code == 0);
  for (const char* f : {"plot_f_tip_normal+f_cap_normal.pdf", "plot_energy+work+impacts.pdf", "still_1.000.png"}) {
    INFO(f);
    CHECK(fs::file_size(dir / "fig" / f) > 1000);
  }
  // In-process, from a copy of the file that is then removed: the lab holds the model it read.
  for (const char* f : {"pen_drop.xml", "pen_drop.loops.json"}) fs::copy_file(fs::path(DYNLAB_SOURCE_DIR) / "assets/models" / f, dir / f);
  const dyn::LoadedLab loaded = dyn::app::loadModelLab((dir / "pen_drop.xml").string(), 1.0);
  fs::remove(dir / "pen_drop.xml");
  const auto lab = loaded.entry->create(dyn::JsonView(loaded.config, "config"));
  const dyn::RunResult hand = dyn::runEngine(*lab, dyn::Engine::Hand);
  REQUIRE(hand.failure.empty());
  const dyn::Trace& t = hand.trace;
  const std::size_t last = t.rows() - 1;
  // At rest the table carries m g; the touchdowns' losses are in W, so E − E0 − W stays at RK4's error
  // although they took most of the drop's energy.
  CHECK(std::abs(t.at(last, "f_tip_normal") + t.at(last, "f_cap_normal") - 0.02 * 9.81) < 1e-9);
  double balance = 0;
  for (std::size_t i = 0; i < t.rows(); ++i) balance = std::max(balance, std::abs(t.at(i, "energy") - t.at(0, "energy") - t.at(i, "work")));
  MESSAGE("figure's run: touchdowns took " << t.at(last, "impacts") << " J, max |E - E0 - W| " << balance << " J");
  CHECK(t.at(last, "impacts") > 0.01);
  CHECK(balance < 1e-9);
  CHECK(lab->metrics(t)["energy_drift"].get<double>() < 1e-9);
}

TEST_CASE("dynlab bench FILE with wheels or contacts beside it: the hand step against Bullet's at equal order") {
  TempDir dir("model_bench_elements");
  for (const char* file : {"pen_drop.xml", "unicycle.xml"}) {
    const Result r = dynlab(dir, {"bench", model(file), "--steps", "200", "--json"});
    INFO(file, r.out, r.err);
    REQUIRE(r.code == 0);
    const auto out = nlohmann::json::parse(r.out);
    // Hand (Euler, RK4) and Bullet; MuJoCo left out (its run would not hold the elements), and said so.
    REQUIRE(out["engines"].size() == 3);
    CHECK(out["engines"][2]["engine"] == "Bullet");
    CHECK(out["beside"]["note"].get<std::string>().find("MuJoCo not timed") != std::string::npos);
    for (const auto& e : out["engines"]) CHECK(e["complete"].get<bool>());
    CHECK(out["engines"][1]["max_q_error_vs_hand_rk4"].get<double>() == 0.0);
  }
}
