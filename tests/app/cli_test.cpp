// The dynlab command line end to end: the real binary (DYNLAB_BIN) run with an argument vector, its exit
// code, stdout/stderr and the files it writes. Every test works in its own directory under the
// build tree, removed afterwards.
//   exit codes: 0 success, 1 a run or write failed, 2 bad input (nothing written).
#include <doctest/doctest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "tests/app/cli_run.h"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace dyn::test::cli;

TEST_CASE("dynlab list and --help") {
  TempDir dir("help");
  const Result list = dynlab(dir, {"list"});
  CHECK(list.code == 0);
  CHECK((list.out.rfind("slider_crank ", 0) == 0 || list.out.find("\nslider_crank ") != std::string::npos));
  CHECK((list.out.rfind("grasp ", 0) == 0 || list.out.find("\ngrasp ") != std::string::npos));
  for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{{"--help"},
                                                                                   {"run", "--help"},
                                                                                   {"figure", "--help"},
                                                                                   {"grade", "--help"},
                                                                                   {"bench", "--help"},
                                                                                   {"schema", "--help"},
                                                                                   {"list", "--help"}}) {
    INFO("dynlab ", shown(args));
    const Result r = dynlab(dir, args);
    CHECK(r.code == 0);
    CHECK(r.out.find("Usage:") != std::string::npos);
    CHECK(r.err.empty());
  }
  CHECK(dynlab(dir, {"run", "--help"}).out.find("--duration") != std::string::npos);
  // No subcommand, an unknown one, or an unknown option: a usage error (2), not a crash.
  CHECK(dynlab(dir, {}).code == 2);
  CHECK(dynlab(dir, {"frobnicate"}).code == 2);
  CHECK(dynlab(dir, {"run", "slider_crank", "--no-such-option"}).code == 2);
  CHECK(dynlab(dir, {"run", "slider_crank", "--engine", "warp"}).code == 2);
  CHECK(snapshot(dir.path).empty());  // none of these wrote anything
}

TEST_CASE("dynlab run writes both traces and a summary that agrees with them") {
  TempDir dir("run");
  const Result r = dynlab(dir, {"run", "slider_crank", "--out", "out", "--duration", "0.5"});
  INFO("stdout: ", r.out, "\nstderr: ", r.err);
  REQUIRE(r.code == 0);
  const fs::path out = dir / "out";
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(out)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  CHECK(names == std::vector<std::string>{"summary.json", "trace_bullet.csv", "trace_hand.csv"});  // no .staging left

  const json summary = json::parse(readFile(out / "summary.json"));
  const double dt = summary.at("dt").get<double>();
  CHECK(summary.at("duration").get<double>() == 0.5);
  CHECK(summary.at("lab") == "slider_crank");
  CHECK(summary.at("status") == "ok");
  // Units of the columns, for whoever reads the CSV.
  CHECK(summary.at("units").at("q1") == "rad");
  CHECK(summary.at("units").at("f_Ty") == "N");
  CHECK(summary.at("units").at("tau1") == "N·m");
  std::map<std::string, Csv> traces;
  for (const char* engine : {"hand", "bullet"}) {
    INFO("engine ", engine);
    const Csv csv = readCsv(out / (std::string("trace_") + engine + ".csv"));
    for (const char* c : {"t", "q1", "q2", "q3", "x_c", "v_c", "f_Tx", "f_Ty", "tau_T", "tau1", "tau2", "tau3",
                          "energy", "constraint_residual"})
      CHECK_MESSAGE(csv.col(c) >= 0, "column " << c);
    // One row per step and one at the end, on the grid t = k dt: t = 0 … duration.
    REQUIRE(csv.rows.size() == std::size_t(std::lround(0.5 / dt)) + 1);
    CHECK(csv.rows.size() == 501);
    for (std::size_t k = 0; k < csv.rows.size(); ++k) REQUIRE(std::abs(csv.at(k, "t") - double(k) * dt) < 1e-12);
    const json& engine_summary = summary.at("engines").at(engine);
    CHECK(engine_summary.at("status") == "ok");
    CHECK(engine_summary.at("trace_hash").is_number_unsigned());
    CHECK(engine_summary.at("metrics").at("steps") == 500);
    traces[engine] = csv;
  }
  // The agreement block, recomputed from the written traces (CSV numbers are round-trip exact).
  const json& ag = summary.at("agreement");
  const Csv &hand = traces["hand"], &bullet = traces["bullet"];
  double dq = 0, dx = 0, df = 0;
  for (std::size_t k = 0; k < hand.rows.size(); ++k) {
    for (const char* c : {"q1", "q2", "q3"}) dq = std::max(dq, std::abs(hand.at(k, c) - bullet.at(k, c)));
    dx = std::max(dx, std::abs(hand.at(k, "x_c") - bullet.at(k, "x_c")));
    for (const char* c : {"f_Tx", "f_Ty"}) df = std::max(df, std::abs(hand.at(k, c) - bullet.at(k, c)));
  }
  CHECK(ag.at("rows_compared") == 501);
  CHECK(ag.at("max_dq").get<double>() == dq);
  CHECK(ag.at("max_dx_c").get<double>() == dx);
  CHECK(ag.at("max_df").get<double>() == df);
  // Hand vs Bullet at dt = 1 ms over the controlled run's first 0.5 s: Bullet's first-order error
  // (see tests/labs: 1.7e-4 rad over 4 s, halving with dt); a loose bound, this is a plumbing test.
  CHECK(dq < 1e-3);
  CHECK(dq > 0);  // two different engines really ran
  for (const char* engine : {"hand", "bullet"}) {
    INFO("engine ", engine);
    const Csv& tr = traces[engine];
    double drift = 0, residual = 0;
    for (std::size_t k = 0; k < tr.rows.size(); ++k) {
      drift = std::max(drift, std::abs(tr.at(k, "energy") - tr.at(0, "energy") - tr.at(k, "work")));
      residual = std::max(residual, tr.at(k, "constraint_residual"));
    }
    CHECK(ag.at(engine).at("energy_drift").get<double>() == doctest::Approx(drift).epsilon(1e-12));
    CHECK(ag.at(engine).at("max_constraint_residual").get<double>() == residual);
  }
  CHECK(ag.at("hand").at("max_constraint_residual").get<double>() < 1e-9);
  // The headline on stdout names the files.
  CHECK(r.out.find("trace_hand.csv") != std::string::npos);
  CHECK(r.out.find("summary.json") != std::string::npos);
}

TEST_CASE("dynlab run --engine hand writes only the hand trace") {
  TempDir dir("engine");
  const Result r = dynlab(dir, {"run", "slider_crank", "--out", "out", "--duration", "0.2", "--engine", "hand"});
  INFO("stderr: ", r.err);
  REQUIRE(r.code == 0);
  CHECK(fs::exists(dir / "out/trace_hand.csv"));
  CHECK_FALSE(fs::exists(dir / "out/trace_bullet.csv"));
  const json summary = json::parse(readFile(dir / "out/summary.json"));
  CHECK(summary.at("engines").size() == 1);
  CHECK(summary.at("engines").contains("hand"));
  CHECK_FALSE(summary.contains("agreement"));
  CHECK(readCsv(dir / "out/trace_hand.csv").rows.size() == 201);  // t = 0 … 0.2 s
}

TEST_CASE("dynlab run --frames --video: 30 frames per second of simulated time, H.264 yuv420p") {
  TempDir dir("video");
  const double duration = 0.5;
  const Result r = dynlab(dir, {"run", "slider_crank", "--out", "out", "--duration", "0.5", "--frames", "--video"});
  INFO("stdout: ", r.out, "\nstderr: ", r.err);
  REQUIRE(r.code == 0);
  // Frames at k/30 s from t = 0 to the run's last row at t = duration, both included.
  const int expected = int(std::lround(30 * duration)) + 1;
  std::vector<std::string> frames;
  for (const auto& e : fs::directory_iterator(dir / "out/frames")) frames.push_back(e.path().filename().string());
  std::sort(frames.begin(), frames.end());
  CHECK(int(frames.size()) == expected);
  for (int i = 0; i < int(frames.size()); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "%05d.png", i);
    CHECK(frames[std::size_t(i)] == name);
  }
  // PNG signature and the IHDR size (640×480).
  const std::string png = readFile(dir / "out/frames/00000.png");
  REQUIRE(png.size() > 24);
  CHECK(png.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0);
  auto be32 = [&](std::size_t at) {
    return (unsigned(std::uint8_t(png[at])) << 24) | (unsigned(std::uint8_t(png[at + 1])) << 16) |
           (unsigned(std::uint8_t(png[at + 2])) << 8) | unsigned(std::uint8_t(png[at + 3]));
  };
  CHECK(be32(16) == 640u);
  CHECK(be32(20) == 480u);
  // Decode the whole video with ffprobe: every frame is read, not just the header's count.
  CHECK(probeVideo(dir, "out/video.mp4", "nb_read_frames,pix_fmt,codec_name") == "h264,yuv420p," + std::to_string(expected));
  CHECK(r.out.find(std::to_string(expected) + " frames)") != std::string::npos);
}

TEST_CASE("bad input through the CLI: exit 2, one line naming file and JSON path, nothing written") {
  TempDir dir("bad");
  const fs::path out = dir / "out";
  const std::vector<std::string> run = {"run", "slider_crank", "--out", "out", "--duration", "0.2"};

  SUBCASE("config with a negative mass") {
    json c = json::parse(defaultConfigText());
    c["mechanism"]["links"][0]["mass"] = -1.0;
    writeFile(dir / "negative_mass.json", c.dump(2));
    checkBadInput(dir, cat(run, {"--config", "negative_mass.json"}),
                  {"negative_mass.json", "/mechanism/links/0/mass", "positive"}, out);
  }
  SUBCASE("config with a number that overflows a double (1e999)") {
    std::string text = defaultConfigText();
    const std::string key = "\"load_mass\": 0.5";
    REQUIRE(text.find(key) != std::string::npos);
    text.replace(text.find(key), key.size(), "\"load_mass\": 1e999");
    writeFile(dir / "overflow.json", text);
    checkBadInput(dir, cat(run, {"--config", "overflow.json"}), {"overflow.json", "1e999"}, out);
  }
  SUBCASE("malformed and empty config files") {
    writeFile(dir / "malformed.json", "{\"lab\": \"slider_crank\",,}");
    checkBadInput(dir, cat(run, {"--config", "malformed.json"}), {"malformed.json", "expected valid JSON", "line 1"}, out);
    writeFile(dir / "empty.json", "");
    checkBadInput(dir, cat(run, {"--config", "empty.json"}), {"empty.json", "empty"}, out);
  }
  SUBCASE("missing config file") {
    checkBadInput(dir, cat(run, {"--config", "no_such_config.json"}), {"no_such_config.json", "cannot open"}, out);
  }
  SUBCASE("gains out of bounds, unknown gain, wrong type") {
    writeFile(dir / "gains_big.json", R"({"gains": {"kp_x": 1e9}})");
    checkBadInput(dir, cat(run, {"--gains", "gains_big.json"}), {"gains_big.json", "/gains/kp_x", "[0, 20000]"}, out);
    writeFile(dir / "gains_unknown.json", R"({"gains": {"kp_z": 1}})");
    checkBadInput(dir, cat(run, {"--gains", "gains_unknown.json"}), {"gains_unknown.json", "/gains/kp_z", "unknown gain"}, out);
    writeFile(dir / "gains_type.json", R"({"gains": {"ki_f": "NaN"}})");
    checkBadInput(dir, cat(run, {"--gains", "gains_type.json"}), {"gains_type.json", "/gains/ki_f", "expected a number"}, out);
  }
  SUBCASE("unknown lab") {
    checkBadInput(dir, {"run", "no_such_lab", "--out", "out"}, {"unknown lab \"no_such_lab\"", "LAB", "slider_crank"}, out);
  }
  SUBCASE("bad duration") { checkBadInput(dir, {"run", "slider_crank", "--out", "out", "--duration", "0"}, {"--duration"}, out); }
  SUBCASE("a failing run keeps the results of an earlier good run intact") {
    REQUIRE(dynlab(dir, run).code == 0);
    const auto before = snapshot(out);
    REQUIRE(before.size() == 3);
    writeFile(dir / "gains_big.json", R"({"gains": {"kd_x": -5}})");
    const Result r = dynlab(dir, cat(run, {"--gains", "gains_big.json"}));
    INFO("stderr: ", r.err);
    CHECK(r.code == 2);
    CHECK(r.err.find("/gains/kd_x") != std::string::npos);
    CHECK(snapshot(out) == before);
    CHECK_FALSE(fs::exists(out / ".staging"));
  }
}

TEST_CASE("the same command twice gives byte-identical traces and summary") {
  TempDir dir("repeat");
  const std::vector<std::string> cmd = {"run", "slider_crank", "--out", "out", "--duration", "0.3"};
  REQUIRE(dynlab(dir, cmd).code == 0);
  const auto first = snapshot(dir / "out");
  REQUIRE(dynlab(dir, cmd).code == 0);
  const auto second = snapshot(dir / "out");
  REQUIRE(first.size() == 3);
  CHECK(second.size() == first.size());
  for (const auto& [name, bytes] : first) {
    INFO("file ", name);
    REQUIRE(second.count(name) == 1);
    CHECK(second.at(name) == bytes);
  }
  // And the bytes do depend on the input: a different duration gives a different summary.
  REQUIRE(dynlab(dir, {"run", "slider_crank", "--out", "out2", "--duration", "0.2"}).code == 0);
  CHECK(readFile(dir / "out2/summary.json") != first.at("summary.json"));
}

TEST_CASE("a rerun into the same directory leaves no stale output of the earlier run") {
  TempDir dir("rerun");
  REQUIRE(dynlab(dir, {"run", "slider_crank", "--out", "out", "--duration", "0.2", "--video", "--frames"}).code == 0);
  REQUIRE(fs::exists(dir / "out/video.mp4"));
  REQUIRE(fs::exists(dir / "out/frames"));
  std::ofstream(dir / "out/notes.txt") << "mine";  // the user's own file stays
  REQUIRE(dynlab(dir, {"run", "slider_crank", "--out", "out", "--duration", "0.2", "--engine", "hand"}).code == 0);
  CHECK_FALSE(fs::exists(dir / "out/video.mp4"));
  CHECK_FALSE(fs::exists(dir / "out/frames"));
  CHECK_FALSE(fs::exists(dir / "out/trace_bullet.csv"));
  CHECK(fs::exists(dir / "out/trace_hand.csv"));
  CHECK(readFile(dir / "out/notes.txt") == "mine");
}

TEST_CASE("dynlab bench --json: the fields of every lab, and speed with accuracy (no speed asserted)") {
  TempDir dir("bench");
  // Its scratch files in a folder of its own under TMPDIR, whatever already sits there: here the
  // names it once used for them, taken by another user's files (it failed, or wrote among them).
  TempDir tmp("bench_tmpdir");
  std::ofstream(tmp / "dynlab-bench") << "someone else's";
  std::ofstream(tmp / "dynlab-bench-grade") << "someone else's";
  const auto before = snapshot(tmp.path);
  const Result r = dynlab(dir, {"bench", "--json", "--steps", "200", "--frames", "5"}, withEnv({{"TMPDIR", tmp.path.string()}}));
  INFO("stdout: ", r.out, "\nstderr: ", r.err);
  REQUIRE(r.code == 0);
  std::istringstream lines(r.out);
  std::string line;
  int labs = 0;
  while (std::getline(lines, line)) {
    const json j = json::parse(line);
    ++labs;
    for (const char* key : {"hand_us_per_step", "bullet_us_per_step", "render_fps", "render_png_fps",
                            "render_video_fps", "bullet_over_hand"})
      CHECK(j.at(key).get<double>() > 0);
    CHECK(j.at("lab").is_string());
    // MuJoCo timed on every lab's mechanism written for it, its ratio at equal order from the same run.
    for (const char* key : {"mujoco_us_per_step", "mujoco_over_hand_equal_order", "mujoco_hand_us_per_step"})
      CHECK(j.at(key).get<double>() > 0);
    CHECK(j.at("mujoco_hand_scheme") == "semi_implicit_euler + baumgarte");
    if (j.at("lab") != "slider_crank") continue;
    // Bullet and the hand engine at Bullet's order (semi-implicit Euler + Baumgarte, same dt), both
    // against the RK4 reference: first-order errors of the same size (Bullet is first order too,
    // shared/notes/bullet-reference.md), far above RK4's own (~1e-9) and below a visible one.
    CHECK(j.at("hand_scheme") == "rk4 + projection");
    const json& bullet = j.at("bullet_error");
    const json& hand1 = j.at("hand_first_order_error");
    CHECK(j.at("hand_first_order_us_per_step").get<double>() > 0);
    for (const char* key : {"max_dq", "max_dx_c", "max_df"}) {
      INFO(key);
      const double b = bullet.at(key).get<double>(), h = hand1.at(key).get<double>();
      CHECK(b > 1e-7);
      CHECK(b < 1e-2);
      CHECK(h / b > 0.5);
      CHECK(h / b < 2.0);
    }
  }
  CHECK(labs >= 1);
  CHECK(snapshot(dir.path).empty());  // the bench leaves nothing behind
  CHECK(snapshot(tmp.path) == before);  // nor in TMPDIR, whose files it did not touch
}

TEST_CASE("grade --replay: a grade another dynlab version made is said to be one, beside its differences") {
  TempDir dir("replay_version");
  const std::string ex = (fs::path(DYNLAB_SOURCE_DIR) / "labs/slider_crank/examples/proportional.json").string();
  REQUIRE(dynlab(dir, {"grade", ex, "--no-plots", "--out", "g"}).code == 0);
  json r = json::parse(readFile(dir / "g/results.json"));
  // This version's grade, one score edited: a mismatch, and no word of versions.
  r["tests"][0]["score"] = 0.125;
  writeFile(dir / "edited.json", r.dump());
  Result out = dynlab(dir, {"grade", "--replay", "edited.json", ex});
  CHECK(out.code == 1);
  CHECK(out.out.find("replay: MISMATCH") != std::string::npos);
  CHECK(out.out.find("graded by") == std::string::npos);
  // Another version's (its physics may round differently): said, with the version to replay with.
  r["extra_data"]["fingerprint"]["dynlab_version"] = "0.0.9";
  writeFile(dir / "older.json", r.dump());
  out = dynlab(dir, {"grade", "--replay", "older.json", ex});
  CHECK(out.code == 1);
  CHECK(out.out.find("(graded by dynlab 0.0.9, replayed by dynlab ") != std::string::npos);
  CHECK(out.out.find("replay with dynlab 0.0.9 to tell an edited file from a new version") != std::string::npos);
  // A fingerprint that is not an object: still one mismatch report, no crash.
  r["extra_data"]["fingerprint"] = "x";
  writeFile(dir / "odd.json", r.dump());
  out = dynlab(dir, {"grade", "--replay", "odd.json", ex});
  CHECK(out.code == 1);
  CHECK(out.out.find("(graded by an unnamed dynlab version") != std::string::npos);
}
