// Model files as users have them, through the real binary on every command that takes one (model, run,
// figure, bench; issue 40): a URDF in robot/urdf/ whose meshes are package://robot/meshes/… loads; a
// package found only through --package-path is a one-line refusal naming where dynlab looked until
// the option names it; a file whose geoms collide loads on each command without a flag (noted once;
// --ignore-contacts silences the note, and is refused in one line for a lab); a file's <option timestep> is the step the run takes, `run
// --dt` another, checked. Never exit 3. The files are written here, at run time.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "tests/app/cli_run.h"
#include "tests/physics/model_file/mesh_files.h"

using namespace dyn::test::cli;

namespace {

using dyn::test_model_file::meshArmUrdf;
using dyn::test_model_file::tetrahedronStl;

// A pendulum: `option` inside <option …/>, and `extra` in the world body.
std::string pendulum(const std::string& option, const std::string& extra = "") {
  return "<mujoco><option " + option + "/><worldbody>" + extra +
         "<body name=\"bob\" pos=\"0 0 1\"><joint name=\"swing\" type=\"hinge\" axis=\"0 1 0\"/>"
         "<geom type=\"capsule\" fromto=\"0 0 0 0.3 0 -0.3\" size=\"0.02\" mass=\"1\" contype=\"1\" conaffinity=\"1\"/></body></worldbody></mujoco>";
}

// Each command on FILE with extra arguments: short runs, a scratch output each.
std::vector<std::vector<std::string>> commands(const TempDir& dir, const std::string& file, const std::vector<std::string>& extra) {
  return {cat({"model", file, "--duration", "0.05", "--out", (dir / "o_model").string()}, extra),
          cat({"run", file, "--duration", "0.05", "--out", (dir / "o_run").string()}, extra),
          cat({"figure", file, "--duration", "0.05", "--plot", "q_j1", "--still", "0", "--format", "png", "--out", (dir / "o_fig").string()}, extra),
          cat({"bench", file, "--steps", "100"}, extra)};
}

// A mesh arm laid out as users lay it out: its STL at `mesh`, its URDF at `urdf` naming the mesh as `ref`.
void layOut(const TempDir& dir, const std::string& mesh, const std::string& urdf, const std::string& ref) {
  fs::create_directories((dir / mesh).parent_path());
  fs::create_directories((dir / urdf).parent_path());
  writeFile(dir / mesh, tetrahedronStl(0.1f));
  writeFile(dir / urdf, meshArmUrdf(ref));
}

// FILE (with extra arguments) loads and runs on every command: exit 0 each.
void loadsOnEveryCommand(const TempDir& dir, const std::string& file, const std::vector<std::string>& extra) {
  for (const auto& args : commands(dir, file, extra)) {
    const Result r = dynlab(dir, args);
    INFO(shown(args), "\n", r.err);
    CHECK(r.code == 0);
  }
}

// The step of a trace: the time between its first two rows.
double stepOf(const fs::path& trace) {
  const Csv c = readCsv(trace);
  REQUIRE(c.rows.size() > 2);
  return c.rows[1][0] - c.rows[0][0];
}

}  // namespace

TEST_CASE("a URDF whose meshes are package://robot/meshes/…, beside its urdf/ folder, runs on model, run, figure and bench") {
  TempDir dir("model_files_layout");
  layOut(dir, "robot/meshes/body.stl", "robot/urdf/arm.urdf", "package://robot/meshes/body.stl");
  loadsOnEveryCommand(dir, "robot/urdf/arm.urdf", {});
}

TEST_CASE("a package found only through --package-path: one line naming where dynlab looked, then it loads on every command") {
  TempDir dir("model_files_package_path");
  layOut(dir, "vendor/parts/meshes/body.stl", "ws/arm.urdf", "package://parts/meshes/body.stl");
  for (const auto& args : commands(dir, "ws/arm.urdf", {})) {
    const Result r = dynlab(dir, args);
    INFO(shown(args), "\n", r.err);
    CHECK(r.code == 2);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    CHECK(r.err.rfind("error: ws/arm.urdf: ", 0) == 0);  // the file named once (figure: "ws/arm.urdf: /: a model file dynlab reads (…")
    CHECK(r.err.find("file 'package://parts/meshes/body.stl' not found (no package folder 'parts' in the folders above ") != std::string::npos);
    CHECK(r.err.find("pass --package-path DIR") != std::string::npos);
  }
  loadsOnEveryCommand(dir, "ws/arm.urdf", {"--package-path", (dir / "vendor").string()});
  // ROS_PACKAGE_PATH, as ROS users set it.
  const Result ros = dynlab(dir, commands(dir, "ws/arm.urdf", {})[0], withEnv({{"ROS_PACKAGE_PATH", (dir / "vendor").string()}}));
  CHECK(ros.code == 0);
}

TEST_CASE("a file whose geoms collide loads on model, run, figure and bench without a flag, noted once; --ignore-contacts silences it") {
  TempDir dir("model_files_contacts");
  writeFile(dir / "floor.xml", pendulum("timestep=\"0.001\"", "<geom name=\"floor\" type=\"plane\" size=\"1 1 0.1\" pos=\"0 0 0.5\"/>"));
  std::vector<std::vector<std::string>> all = commands(dir, "floor.xml", {});
  all[2][5] = "q_swing";  // figure's --plot
  for (const auto& args : all) {
    const Result r = dynlab(dir, args);
    INFO(shown(args), "\n", r.err);
    CHECK(r.code == 0);
    CHECK(r.err.find("--ignore-contacts") == std::string::npos);  // no advice of an option
  }
  const std::string summary = readFile(dir / "o_model/summary.txt");
  const std::string note = "2 geoms collide in MuJoCo but not here (e.g. 'floor' and 'geom #1'): dynlab has no geom–geom contact";
  CHECK(summary.find(note) != std::string::npos);
  CHECK(summary.find(note, summary.find(note) + 1) == std::string::npos);  // once
  const Result quiet = dynlab(dir, {"model", "floor.xml", "--duration", "0.05", "--ignore-contacts", "--out", (dir / "q").string()});
  CHECK(quiet.code == 0);
  CHECK(readFile(dir / "q/summary.txt").find("collide in MuJoCo") == std::string::npos);
  for (const std::string command : {"run", "figure", "bench"}) {
    const Result r = dynlab(dir, {command, "slider_crank", "--ignore-contacts", "--out", (dir / "lab").string()});
    INFO(command, "\n", r.err);
    checkRefused(r, {"--ignore-contacts", "slider_crank"});
  }
}

TEST_CASE("a file's servos drive model, run, figure and bench; --key NAME starts each from its keyframe, an unknown name is one line") {
  TempDir dir("model_files_key");
  writeFile(dir / "arm.xml", readFile(fs::path(DYNLAB_SOURCE_DIR) / "tests/physics/model_file/files/servo_arm.xml"));
  std::vector<std::vector<std::string>> all = commands(dir, "arm.xml", {"--key", "reach"});
  all[2][5] = "q_shoulder";  // figure's --plot
  for (const auto& args : all) {
    const Result r = dynlab(dir, args);
    INFO(shown(args), "\n", r.err);
    CHECK(r.code == 0);
  }
  // The run starts at the keyframe's qpos and holds its controls (the shoulder's 0.9 clamped to 0.5 where it acts).
  const Csv trace = readCsv(dir / "o_model/trace.csv");
  REQUIRE(!trace.rows.empty());
  CHECK(trace.rows[0][1] == 0.2);
  CHECK(trace.rows[0][2] == -0.4);
  const std::string summary = readFile(dir / "o_model/summary.txt");
  CHECK(summary.find("run with 4 actuators (shoulder_servo, shoulder_motor, elbow_servo, wrist_drive) at ctrl (0.9, 0.2, -1, 0.03)") !=
        std::string::npos);
  CHECK(summary.find("from keyframe reach") != std::string::npos);
  CHECK(summary.find("actuator shoulder_servo on joint shoulder: force = 40 ctrl − 40 length, gear 1, ctrl in [-0.5, 0.5]") != std::string::npos);
  CHECK(summary.find("max |Δτ_actuators| ") != std::string::npos);
  // From q0 at rest the servos hold their controls at 0: the arm still moves (gravity), from q0.
  REQUIRE(dynlab(dir, {"model", "arm.xml", "--duration", "0.05", "--out", (dir / "rest").string()}).code == 0);
  CHECK(readCsv(dir / "rest/trace.csv").rows[0][1] == 0);
  for (auto args : commands(dir, "arm.xml", {"--key", "home"})) {
    if (args[0] == "figure") args[5] = "q_shoulder";
    const Result r = dynlab(dir, args);
    INFO(shown(args), "\n", r.err);
    CHECK(r.code == 2);
    CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
    CHECK(r.err.find("--key 'home': no such keyframe; the file's keyframes: 'reach'") != std::string::npos);
  }
  checkRefused(dynlab(dir, {"run", "slider_crank", "--key", "reach", "--out", (dir / "lab").string()}), {"--key", "slider_crank"});
}

TEST_CASE("a model file runs at its own <option timestep>; run --dt sets another, checked") {
  TempDir dir("model_files_timestep");
  writeFile(dir / "fine.xml", pendulum("timestep=\"0.0005\" gravity=\"0 0 -3\""));
  REQUIRE(dynlab(dir, {"model", "fine.xml", "--duration", "0.01", "--engine", "hand", "--out", (dir / "m").string()}).code == 0);
  CHECK(stepOf(dir / "m/trace.csv") == doctest::Approx(0.0005).epsilon(1e-9));
  CHECK(readFile(dir / "m/summary.txt").find("gravity (0, 0, -3)") != std::string::npos);
  REQUIRE(dynlab(dir, {"run", "fine.xml", "--duration", "0.01", "--engine", "hand", "--out", (dir / "r").string()}).code == 0);
  CHECK(stepOf(dir / "r/trace.csv") == doctest::Approx(0.0005).epsilon(1e-9));
  REQUIRE(dynlab(dir, {"run", "fine.xml", "--duration", "0.01", "--dt", "0.002", "--engine", "hand", "--out", (dir / "d").string()}).code == 0);
  CHECK(stepOf(dir / "d/trace.csv") == doctest::Approx(0.002).epsilon(1e-9));
  // A bad --dt, a --dt for a lab, a file step outside the bounds: one line each, exit 2.
  checkBadInput(dir, {"run", "fine.xml", "--dt", "1", "--out", (dir / "bad").string()}, {"--dt", "1"}, dir / "bad");
  checkBadInput(dir, {"run", "fine.xml", "--dt", "0", "--out", (dir / "bad").string()}, {"--dt", "0"}, dir / "bad");
  checkBadInput(dir, {"run", "slider_crank", "--dt", "0.001", "--out", (dir / "bad").string()}, {"--dt"}, dir / "bad");
  writeFile(dir / "coarse.xml", pendulum("timestep=\"0.05\""));
  checkBadInput(dir, {"model", "coarse.xml", "--out", (dir / "bad").string()}, {"coarse.xml", "<option timestep>", "--dt"}, dir / "bad");
  CHECK(dynlab(dir, {"model", "coarse.xml", "--dt", "0.001", "--duration", "0.01", "--out", (dir / "ok").string()}).code == 0);
}
