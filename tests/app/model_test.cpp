// dynlab model FILE end to end: what it prints about the mechanism it read, the passive run's closure
// residual and energy balance in the trace it writes, byte-identical reruns, and the bad-input contract
// for hostile model files (exit 2, one line naming the file, nothing written); `dynlab run FILE` as the
// same command, with its video (decoded by ffprobe) and frames drawn from the file's geoms.
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>
#include <stb_image.h>

#include <sys/stat.h>

#include <chrono>
#include <cmath>
#include <cstdlib>

#include "tests/app/cli_run.h"

using namespace dyn::test::cli;
using nlohmann::json;

namespace {
std::string model(const char* name) { return std::string(DYNLAB_SOURCE_DIR) + "/assets/models/" + name; }

// Pixels of a frame's right half (the panel fills the top-left) that differ from the background: the
// mechanism drawn, in colour. −1 if the PNG does not load.
int drawnRightOfPanel(const fs::path& png) {
  int w = 0, h = 0, n = 0;
  unsigned char* px = stbi_load(png.string().c_str(), &w, &h, &n, 3);
  if (!px) return -1;
  int drawn = 0;
  for (int y = 0; y < h; ++y)
    for (int x = w / 2; x < w; ++x) {
      const unsigned char* p = px + (std::size_t(y) * w + x) * 3;
      drawn += std::abs(p[0] - 245) + std::abs(p[1] - 245) + std::abs(p[2] - 240) > 60;
    }
  stbi_image_free(px);
  return drawn;
}
}  // namespace

TEST_CASE("dynlab model: the four-bar is read, run passive, and its trace keeps closure and energy") {
  TempDir dir("model_fourbar");
  const Result r = dynlab(dir, {"model", model("fourbar.xml"), "--duration", "1", "--out", "out"});
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
  REQUIRE(dynlab(dir, {"model", model("fourbar.xml"), "--duration", "1", "--out", "out"}).code == 0);
  CHECK(readFile(dir / "out/trace.csv") == first);
  CHECK(readFile(dir / "out/trace_bullet.csv") == first_bt);
  // One engine: only its trace.
  REQUIRE(dynlab(dir, {"model", model("fourbar.xml"), "--duration", "0.1", "--engine", "hand", "--out", "hand_only"}).code == 0);
  CHECK(fs::exists(dir / "hand_only/trace.csv"));
  CHECK_FALSE(fs::exists(dir / "hand_only/trace_bullet.csv"));
}

TEST_CASE("dynlab model: hostile and unsupported files get one line and exit 2, nothing written") {
  TempDir dir("model_bad");
  writeFile(dir / "latin1.xml", "<mujoco model=\"caf\xE9\"/>");
  checkBadInput(dir, {"model", "latin1.xml", "--out", "o"}, {"latin1.xml", "not valid UTF-8"}, dir / "o");
  writeFile(dir / "ball.xml", "<mujoco><worldbody><body name=\"b\"><joint name=\"s\" type=\"ball\" limited=\"true\" range=\"0 30\"/>"
                              "<geom size=\"0.1\"/></body></worldbody></mujoco>");
  checkBadInput(dir, {"model", "ball.xml", "--out", "o"}, {"ball.xml", "joint 's'", "ball joint", "hinge and slide"}, dir / "o");
  checkBadInput(dir, {"model", "missing.xml", "--out", "o"}, {"missing.xml", "no such file"}, dir / "o");
  // A mesh that is a FIFO (MuJoCo would block opening it) and one linked to /dev/zero: refused before
  // MuJoCo reads anything, within a second.
  REQUIRE(::mkfifo((dir / "pipe.stl").c_str(), 0600) == 0);
  fs::create_symlink("/dev/zero", dir / "zero.stl");
  for (const char* mesh : {"pipe.stl", "zero.stl"}) {
    writeFile(dir / "mesh.xml", std::string("<mujoco><asset><mesh name=\"m\" file=\"") + mesh + "\"/></asset><worldbody><body><joint/>"
                                "<geom type=\"mesh\" mesh=\"m\" contype=\"0\" conaffinity=\"0\"/></body></worldbody></mujoco>");
    const auto t0 = std::chrono::steady_clock::now();
    checkBadInput(dir, {"model", "mesh.xml", "--out", "o"}, {"mesh.xml", mesh}, dir / "o");
    CHECK(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() < 1.0);
  }
  checkBadInput(dir, {"model", model("fourbar.xml"), "--duration", "600", "--dt", "1e-5", "--out", "o"},
                {"--duration", "6e+07 steps, more than the 2e+06 a run may take"}, dir / "o");
}

TEST_CASE("dynlab run FILE.xml --engine both --video --frames: the model command's run, drawn from the file") {
  TempDir dir("model_video");
  const Result r =
      dynlab(dir, {"run", model("fourbar.xml"), "--engine", "both", "--video", "--frames", "--duration", "0.5", "--out", "out"});
  INFO(r.out, r.err);
  REQUIRE(r.code == 0);
  CHECK(r.out.find("1 closure (2 of 3 rows kept)") != std::string::npos);
  // Rows 0..500 (dt 1 ms), one frame each 1/30 s of simulated time: t = 0, 1/30, ..., 0.5 s.
  int expected = 0;
  while (std::lround(expected * 1000.0 / 30) <= 500) ++expected;
  CHECK(r.out.find(std::to_string(expected) + " frames at 30 per second") != std::string::npos);
  std::size_t pngs = 0;
  for (const auto& e : fs::directory_iterator(dir / "out/frames")) pngs += e.path().extension() == ".png";
  CHECK(pngs == std::size_t(expected));
  CHECK(probeVideo(dir, "out/video.mp4", "nb_read_frames,pix_fmt,codec_name,width,height") ==
        "h264,640,480,yuv420p," + std::to_string(expected));
  // The last frame: the mechanism drawn right of the panel (the panel fills the top-left), in colour.
  char name[32];
  std::snprintf(name, sizeof name, "%05d.png", expected - 1);
  CHECK(drawnRightOfPanel(dir / "out/frames" / name) > 2000);
  // `dynlab run FILE` is `dynlab model FILE`: the same trace, byte for byte.
  REQUIRE(dynlab(dir, {"model", model("fourbar.xml"), "--duration", "0.5", "--out", "same"}).code == 0);
  CHECK(readFile(dir / "same/trace.csv") == readFile(dir / "out/trace.csv"));
  CHECK(readFile(dir / "same/trace_bullet.csv") == readFile(dir / "out/trace_bullet.csv"));
  CHECK_FALSE(fs::exists(dir / "same/video.mp4"));
  // Same input, same pixels: the frames of a rerun (hand only: no ghost) twice.
  REQUIRE(dynlab(dir, {"model", model("fourbar.xml"), "--duration", "0.2", "--engine", "hand", "--frames", "--out", "f1"}).code ==
          0);
  REQUIRE(dynlab(dir, {"model", model("fourbar.xml"), "--duration", "0.2", "--engine", "hand", "--frames", "--out", "f2"}).code ==
          0);
  CHECK(snapshot(dir / "f1/frames") == snapshot(dir / "f2/frames"));
  CHECK(snapshot(dir / "f1/frames").size() == 7);
}

TEST_CASE("dynlab figure FILE: plots and stills of the file's passive run, as for a lab") {
  TempDir dir("model_figure");
  const Result r = dynlab(dir, {"figure", model("fourbar.xml"), "--duration", "0.5", "--out", "fig"});
  INFO(r.out, r.err);
  REQUIRE(r.code == 0);
  // The coordinates, the energy books and the closure's force; stills at the start, middle and end.
  for (const char* f : {"plot_q_crank+q_coupler+q_rocker.pdf", "plot_energy+work.pdf", "plot_f_pin_C_x+f_pin_C_z.pdf",
                        "still_0.000.png", "still_0.250.png", "still_0.500.png"}) {
    INFO(f);
    CHECK(fs::file_size(dir / "fig" / f) > 1000);
  }
  // A still draws the mechanism right of its panel, in colour.
  CHECK(drawnRightOfPanel(dir / "fig/still_0.500.png") > 5000);
  // A URDF takes its loops from beside it, as dynlab model does.
  REQUIRE(dynlab(dir, {"figure", model("fourbar.urdf"), "--plot", "f_pin_C_x", "--out", "urdf"}).code == 0);
  CHECK(fs::exists(dir / "urdf/plot_f_pin_C_x.pdf"));
  // Gains, scenarios and configs are a lab's: one line, exit 2, nothing written.
  writeFile(dir / "g.json", R"({"gains": {}})");
  checkBadInput(dir, {"figure", model("fourbar.xml"), "--gains", "g.json", "--out", "o"}, {"--gains", "g.json", "passive"},
                dir / "o");
  checkBadInput(dir, {"figure", "missing.xml", "--out", "o"}, {"missing.xml", "no such file"}, dir / "o");
}

TEST_CASE("a file with a ball joint: figure plots its quaternion; a data lab on it is one line") {
  TempDir dir("model_ball");
  const std::string ball = std::string(DYNLAB_SOURCE_DIR) + "/tests/physics/model_file/models/ball_loop.xml";
  const Result r = dynlab(dir, {"figure", ball, "--duration", "0.2", "--out", "fig"});
  INFO(r.out, r.err);
  REQUIRE(r.code == 0);
  // q's columns as the trace names them: the hinges' angles and the ball's quaternion (4 numbers).
  CHECK(fs::file_size(dir / "fig/plot_q_crank+q_rod_ball_qw+q_rod_ball_qx+q_rod_ball_qy+q_rod_ball_qz+q_rocker.pdf") > 1000);
  CHECK(drawnRightOfPanel(dir / "fig/still_0.200.png") > 5000);
  // A data lab's controllers read one angle per joint: a ball joint is refused where the lab names the file.
  fs::create_directories(dir / "labs/balllab");
  fs::copy_file(ball, dir / "labs/balllab/ball_loop.xml");
  writeFile(dir / "labs/balllab/balllab.json",
            R"({"lab": "balllab", "title": "ball", "model_file": "ball_loop.xml", "actuated": ["crank"], "torque_limit": [5],
               "initial": {"actuated_deg": [0]}, "simulation": {"dt": 0.001, "duration": 0.2, "integrator": "rk4", "drift": "projection"},
               "controller": {"kind": "none", "control_period": 0.001}, "gains": {}})");
  checkBadInput(dir, {"run", "balllab", "--labs", (dir / "labs").string(), "--out", "o"}, {"balllab.json", "/model_file", "ball joint"},
                dir / "o");
}

TEST_CASE("dynlab run FILE: a lab's options and a missing file are bad input (one line, exit 2)") {
  TempDir dir("model_run_bad");
  writeFile(dir / "g.json", R"({"gains": {}})");
  checkBadInput(dir, {"run", model("fourbar.xml"), "--gains", "g.json", "--out", "o"}, {"--gains", "fourbar.xml", "passive"},
                dir / "o");
  checkBadInput(dir, {"run", model("fourbar.xml"), "--scenario", "heavy_load", "--out", "o"}, {"--scenario", "passive"},
                dir / "o");
  checkBadInput(dir, {"run", "missing.URDF", "--out", "o"}, {"missing.URDF", "no such file"}, dir / "o");
  checkBadInput(dir, {"run", model("fourbar.xml"), "--duration", "0", "--out", "o"}, {"--duration", "(0, 600]"}, dir / "o");
}

TEST_CASE("dynlab bench FILE: the hand step at both orders, Bullet's and MuJoCo's, each with its accuracy") {
  TempDir dir("model_bench");
  const Result r = dynlab(dir, {"bench", model("fivebar.xml"), "--steps", "200"});
  INFO(r.out, r.err);
  REQUIRE(r.code == 0);
  CHECK(r.out.find("4 coordinates, 2 closure rows, dt 0.001 s") != std::string::npos);
  for (const char* row : {"\n  hand, Euler ", "\n  hand, RK4 ", "\n  Bullet ", "\n  MuJoCo ", "MuJoCo 2.2.2 mj_step, Euler", "semi-implicit Euler + Baumgarte"})
    CHECK_MESSAGE(r.out.find(row) != std::string::npos, row);
  // JSON: four engines, each timed and run 2 s; the RK4 run is the reference and keeps the closure.
  const Result j = dynlab(dir, {"bench", model("fivebar.xml"), "--steps", "100", "--json"});
  REQUIRE(j.code == 0);
  const json out = json::parse(j.out);
  REQUIRE(out["engines"].size() == 4);
  for (const json& e : out["engines"]) {
    CHECK(e["us_per_step"].get<double>() > 0);
    CHECK(e["complete"].get<bool>());
  }
  CHECK(out["engines"][1]["max_q_error_vs_hand_rk4"].get<double>() == 0.0);
  CHECK(out["engines"][1]["max_closure_residual"].get<double>() < 1e-11);
  checkBadInput(dir, {"bench", "missing.xml"}, {"missing.xml", "no such file"}, dir / "out");
  // A URDF with its loops beside it: timed too, MuJoCo left out (its run of the URDF has no loops).
  const Result u = dynlab(dir, {"bench", model("fourbar.urdf"), "--steps", "100"});
  INFO(u.out, u.err);
  REQUIRE(u.code == 0);
  CHECK(u.out.find("MuJoCo not timed") != std::string::npos);
  CHECK(u.out.find("\n  MuJoCo  ") == std::string::npos);  // no engine row
}

TEST_CASE("dynlab model FILE.urdf: loops beside it (STEM.loops.json or --loops), both engines") {
  TempDir dir("model_urdf_loops");
  // fourbar.loops.json is found beside fourbar.urdf: the same closure, rows and trace columns as fourbar.xml.
  const Result r = dynlab(dir, {"model", model("fourbar.urdf"), "--duration", "0.5", "--out", "out"});
  INFO(r.out, r.err);
  REQUIRE(r.code == 0);
  CHECK(r.out.find("1 closure (2 of 3 rows kept), 1 degree of freedom after closure") != std::string::npos);
  CHECK(r.out.find("closure pin_C: connect coupler to rocker, rows x z kept, y dropped") != std::string::npos);
  CHECK(r.out.find("note: loop closures from ") != std::string::npos);
  // fourbar.xml beside it does not pick them up (its loop is its own equality).
  CHECK(dynlab(dir, {"model", model("fourbar.xml"), "--duration", "0.01", "--out", "x0"}).out.find("loop closures from") ==
        std::string::npos);
  REQUIRE(dynlab(dir, {"model", model("fourbar.xml"), "--duration", "0.5", "--out", "xml"}).code == 0);
  const Csv urdf = readCsv(dir / "out/trace.csv"), xml = readCsv(dir / "xml/trace.csv");
  CHECK(urdf.header == xml.header);
  REQUIRE(urdf.rows.size() == xml.rows.size());
  double diff = 0;
  for (std::size_t i = 0; i < urdf.rows.size(); ++i)
    for (std::size_t c = 0; c < urdf.header.size(); ++c) diff = std::max(diff, std::abs(urdf.rows[i][c] - xml.rows[i][c]));
  MESSAGE("fourbar.urdf + loops vs fourbar.xml, 0.5 s trace: max |difference| " << diff);
  CHECK(diff < 1e-12);
  CHECK(readCsv(dir / "out/trace_bullet.csv").header == urdf.header);
  // Named loops file: a bad one is one line naming it and its JSON path; nothing written.
  writeFile(dir / "bad.json", R"({"loops": [{"kind": "connect", "body1": "coupler", "point1": [0.4, 0, "x"], "body2": "rocker"}]})");
  checkBadInput(dir, {"model", model("fourbar.urdf"), "--loops", "bad.json", "--out", "o"},
                {"bad.json", "loops[0].point1[2]", "expected a finite number"}, dir / "o");
  checkBadInput(dir, {"model", model("fourbar.urdf"), "--loops", "none.json", "--out", "o"}, {"none.json", "no such file"},
                dir / "o");
}

TEST_CASE("dynlab model puma560.urdf: the 6-DoF arm runs in both engines, M and h as MuJoCo's") {
  TempDir dir("model_puma");
  const Result r = dynlab(dir, {"model", model("puma560.urdf"), "--duration", "0.5", "--out", "out"});
  INFO(r.out, r.err);
  REQUIRE(r.code == 0);
  CHECK(r.out.find("6 moving bodies, 6 joints, 0 closures") != std::string::npos);
  const Csv hand = readCsv(dir / "out/trace.csv"), bt = readCsv(dir / "out/trace_bullet.csv");
  REQUIRE(hand.rows.size() == 501);
  REQUIRE(bt.rows.size() == 501);
  // Passive from rest at q = 0 (stretched out): it falls onto its shoulder's stop (<limit lower="-0.785398">),
  // not past it; the hand run keeps E − E0 − W (W: the stops' plastic losses) to RK4's error.
  double de = 0, fall = 0, lowest = 0;
  for (std::size_t i = 0; i < hand.rows.size(); ++i) {
    de = std::max(de, std::abs(hand.at(i, "energy") - hand.at(0, "energy") - hand.at(i, "work")));
    fall = std::max(fall, std::abs(hand.at(i, "q_q2")));
    lowest = std::min(lowest, hand.at(i, "q_q2"));
  }
  MESSAGE("PUMA 560, 0.5 s passive: |E - E0 - W| " << de << " J, |q2| up to " << fall << " rad");
  CHECK(fall > 0.3);
  CHECK(lowest >= -0.785398 - 1e-12);
  CHECK(hand.at(hand.rows.size() - 1, "impacts") > 1.0);
  CHECK(de < 1e-6);
  // Bullet swings the same way at first (its step is first order: the same to a few per cent).
  CHECK(std::abs(bt.at(100, "q_q2") - hand.at(100, "q_q2")) < 0.05 * std::abs(hand.at(100, "q_q2")));
}

TEST_CASE("dynlab model --torque: constant joint torques, their work in the energy books of both engines") {
  TempDir dir("model_torque");
  const Result r = dynlab(dir, {"model", model("fourbar.xml"), "--torque", "crank=0.3", "--duration", "1", "--out", "out"});
  INFO(r.out, r.err);
  REQUIRE(r.code == 0);
  CHECK(r.out.find("run with constant torques (crank=0.3)") != std::string::npos);
  // The books: E − E0 = W, the torque's work ∫ τ v dt, to RK4's error (hand) and Euler's (Bullet).
  const Csv hand = readCsv(dir / "out/trace.csv"), bt = readCsv(dir / "out/trace_bullet.csv");
  double balance = 0, balance_bt = 0, work = 0;
  for (std::size_t i = 0; i < hand.rows.size(); ++i) {
    balance = std::max(balance, std::abs(hand.at(i, "energy") - hand.at(0, "energy") - hand.at(i, "work")));
    balance_bt = std::max(balance_bt, std::abs(bt.at(i, "energy") - bt.at(0, "energy") - bt.at(i, "work")));
    work = std::max(work, std::abs(hand.at(i, "work")));
  }
  // The torque's work by the crank's own rate (trapezoid rule on the trace): the same W.
  double w = 0;
  for (std::size_t i = 1; i < hand.rows.size(); ++i)
    w += 0.3 * 0.5 * (hand.at(i, "v_crank") + hand.at(i - 1, "v_crank")) * (hand.at(i, "t") - hand.at(i - 1, "t"));
  MESSAGE("four-bar, crank torque 0.3 N·m for 1 s: W " << hand.at(hand.rows.size() - 1, "work") << " J (trapezoid on the trace " << w
                                                        << "), |E - E0 - W| hand " << balance << " J, Bullet " << balance_bt << " J");
  CHECK(work > 0.1);
  CHECK(std::abs(w - hand.at(hand.rows.size() - 1, "work")) < 1e-4 * work);  // the trapezoid's own h² error
  CHECK(balance < 1e-6);
  // Bullet's balance is its semi-implicit Euler's first-order error (measured 0.087 J at 1 ms): halving
  // the step halves it, so its books count the torque's work right.
  REQUIRE(dynlab(dir, {"model", model("fourbar.xml"), "--torque", "crank=0.3", "--duration", "1", "--dt", "0.0005", "--engine",
                       "bullet", "--out", "half"})
              .code == 0);
  const Csv half = readCsv(dir / "half/trace_bullet.csv");
  double balance_half = 0;
  for (std::size_t i = 0; i < half.rows.size(); ++i)
    balance_half = std::max(balance_half, std::abs(half.at(i, "energy") - half.at(0, "energy") - half.at(i, "work")));
  MESSAGE("Bullet's |E - E0 - W| at dt 1 ms " << balance_bt << " J, at 0.5 ms " << balance_half << " J");
  CHECK(balance_bt < 0.2);
  CHECK(balance_bt / balance_half > 1.6);
  CHECK(balance_bt / balance_half < 2.5);
  // Bad torques: one line naming the joints, exit 2.
  checkBadInput(dir, {"model", model("fourbar.xml"), "--torque", "elbow=1", "--out", "o"},
                {"--torque elbow=1", "crank coupler rocker"}, dir / "o");
  checkBadInput(dir, {"model", model("fourbar.xml"), "--torque", "crank=nan", "--out", "o"}, {"--torque crank=nan", "finite"},
                dir / "o");
  checkBadInput(dir, {"model", model("fourbar.xml"), "--torque", "crank=1", "--torque", "crank=2", "--out", "o"},
                {"--torque crank=2", "once per joint"}, dir / "o");
  // `dynlab run FILE` takes the same torques and loops, and gives the same trace; a lab refuses them.
  REQUIRE(dynlab(dir, {"run", model("fourbar.xml"), "--torque", "crank=0.3", "--duration", "1", "--engine", "hand", "--out",
                       "via_run"})
              .code == 0);
  CHECK(readFile(dir / "via_run" / "trace.csv") == readFile(dir / "out" / "trace.csv"));
  checkBadInput(dir, {"run", "slider_crank", "--torque", "q1=1", "--out", "o"}, {"--torque", "model file"}, dir / "o");
  checkBadInput(dir, {"run", "slider_crank", "--loops", "x.json", "--out", "o"}, {"--loops", "model file"}, dir / "o");
}
