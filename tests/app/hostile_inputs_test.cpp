// Hostile input through the real binary: a corpus built per test (UTF-16, Latin-1, cut UTF-8, a
// NUL, duplicate keys, a FIFO, a directory, a symlink to /etc/passwd, 20 MB, deep nesting, an empty
// file, odd file names) given to grade, grade --replay, run --gains/--config, figure --gains and, as a
// model description, to run.
// Every case runs under a 20 s timeout (a hang is a kill, a failure here), and must give exit 2,
// one line of valid UTF-8 on stderr naming the file and what was wrong, nothing written by
// run/figure, and for grade a results.json that `dynlab check-results` accepts with score 0.
// Then diverging gains through `dynlab run`, a grade cut short by its time budget, and an
// exception that escapes a command.
#include <doctest/doctest.h>
#include <sys/stat.h>

#include <nlohmann/json.hpp>

#include "labs/utf8.h"
#include "tests/app/cli_run.h"

namespace fs = std::filesystem;
using nlohmann::json;
using namespace dyn::test::cli;

namespace {

const std::string kExamples = std::string(DYNLAB_SOURCE_DIR) + "/labs/slider_crank/examples/";
// A valid, stable submission that students have too (the full-credit one stays in instructor/).
const std::string kStable = kExamples + "mediocre.json";

// dynlab ARGS in dir, killed after 20 s: a blocking open() shows up as a kill (exit 137, timed_out).
Result timedDynlab(const TempDir& dir, const std::vector<std::string>& args, ProcessOptions o = {}) {
  o.timeout_s = 20;
  return dynlab(dir, args, o);
}

// One hostile file: its name in the test dir, how the message shows that name, and words the
// message must also hold (the JSON path, what was expected).
struct Hostile {
  std::string name, shown;
  std::vector<std::string> says;
};

std::string utf16(const std::string& ascii, bool little_endian) {
  std::string out = little_endian ? "\xFF\xFE" : "\xFE\xFF";
  for (const char c : ascii) out += little_endian ? std::string{c, '\0'} : std::string{'\0', c};
  return out;
}

std::string offsetOf(const std::string& text, const std::string& bytes) {
  const auto at = text.find(bytes);
  REQUIRE(at != std::string::npos);
  return std::to_string(at);
}

// Writes the corpus into dir.
std::vector<Hostile> buildCorpus(const TempDir& dir) {
  const std::string good = readFile(kStable);
  const std::string dup_gains = R"({"lab": "slider_crank", "gains": {"kp_x": 1, "kd_x": 2, "kp_x": 3}})";
  std::vector<Hostile> c;
  auto add = [&](const std::string& name, const std::string& text, std::vector<std::string> says) {
    writeFile(dir / name, text);
    c.push_back({name, name, std::move(says)});
  };
  add("utf16le.json", utf16(good, true), {"/: ", "UTF-16", "FF FE", "save it as UTF-8"});
  add("utf16be.json", utf16(good, false), {"/: ", "UTF-16", "FE FF"});
  const std::string latin1 = R"({"lab": "slider_crank", "gains": {}, "note": "caf)" "\xE9" R"("})";
  add("latin1.json", latin1, {"expected UTF-8 text, byte 0xE9 at offset " + offsetOf(latin1, "\xE9") + " is not valid UTF-8"});
  const std::string cut = R"({"lab": "slider_crank", "note": "caf)" "\xC3";
  add("cut_utf8.json", cut, {"byte 0xC3 at offset " + offsetOf(cut, "\xC3") + " is not valid UTF-8"});
  const std::string nul = good.substr(0, 10) + std::string(1, '\0') + good.substr(10);
  add("nul.json", nul, {"byte 0x00 (NUL) at offset 10"});
  add("dup_top.json", R"({"lab": "slider_crank", "lab": "slider_crank", "gains": {}})", {"/lab: ", "duplicate key \"lab\""});
  add("dup_gains.json", dup_gains, {"/gains/kp_x: ", "duplicate key \"kp_x\""});
  add("dup_in_array.json", R"({"lab": "slider_crank", "x": [{"a": 1}, {"b": [0, {"a": 1, "a": 2}]}]})",
      {"/x/1/b/1/a: ", "duplicate key \"a\""});
  add("big.json", R"({"lab": "slider_crank", "pad": ")" + std::string(20u << 20, 'x') + "\"}", {"expected at most", "bytes"});
  add("deep.json", R"({"lab": "slider_crank", "gains": )" + std::string(500, '[') + std::string(500, ']') + "}",
      {"/gains/0/0", "nested at most 64 levels"});
  add("empty.json", "", {"the file is empty"});
  REQUIRE(::mkfifo((dir / "fifo.json").c_str(), 0600) == 0);
  c.push_back({"fifo.json", "fifo.json", {"expected a regular file, got a FIFO"}});
  fs::create_directory(dir / "folder.json");
  c.push_back({"folder.json", "folder.json", {"expected a regular file, got a directory"}});
  fs::create_symlink("/etc/passwd", dir / "passwd.json");
  c.push_back({"passwd.json", "passwd.json", {"expected valid JSON"}});
  // Odd names, each holding duplicate gains: the name is shown on one line, as valid UTF-8.
  for (const std::string name : {"my submission.json", "-dash.json", "<img src=x onerror=alert(1)>.json"}) {
    add(name, dup_gains, {"/gains/kp_x: ", "duplicate key"});
  }
  add("new\nline.json", dup_gains, {"/gains/kp_x: "});
  c.back().shown = "new\\nline.json";
  add("bad\xE9name.json", dup_gains, {"/gains/kp_x: "});
  c.back().shown = "bad\\xE9name.json";
  return c;
}

// What none of the messages may hold: the start of the symlinked /etc/passwd.
std::string passwdStart() { return readFile("/etc/passwd").substr(0, 12); }

// The bad-input contract for one message: exit 2, one line "error: FILE: PATH: expected ...",
// valid UTF-8, no crash.
void checkMessage(const Result& r, const Hostile& h, const std::string& file_shown) {
  INFO("stderr: ", r.err);
  CHECK(r.code == 2);
  CHECK(std::count(r.err.begin(), r.err.end(), '\n') == 1);
  CHECK(r.err.rfind("error: " + file_shown + ": ", 0) == 0);
  for (const auto& s : h.says) CHECK_MESSAGE(r.err.find(s) != std::string::npos, "missing: " << s);
  CHECK(dyn::utf8ErrorAt(r.err) == std::string::npos);
  CHECK(r.err.find(passwdStart()) == std::string::npos);
}

}  // namespace

TEST_CASE("hostile files given to run --gains/--config and figure --gains: exit 2, one line, nothing written") {
  TempDir dir("hostile_run");
  for (const Hostile& h : buildCorpus(dir)) {
    // (command, option): the file name joined to the option, one argument
    for (const auto& c :
         std::vector<std::pair<std::string, std::string>>{{"run", "--gains="}, {"run", "--config="}, {"figure", "--gains="}}) {
      INFO("dynlab ", c.first, " slider_crank --duration 0.2 ", c.second, h.shown);
      const Result r = timedDynlab(dir, {c.first, "slider_crank", "--duration", "0.2", c.second + h.name, "--out", "out"});
      checkMessage(r, h, h.shown);
      CHECK(r.out.empty());
      CHECK_FALSE(fs::exists(dir / "out"));
    }
  }
}

// The same corpus named where a model file goes (a description: labs/generic/model_description.h):
// `dynlab run FILE.json` reads it as one, and refuses each in one line naming it.
TEST_CASE("hostile files given as a model description to run: exit 2, one line, nothing written") {
  TempDir dir("hostile_description");
  for (const Hostile& h : buildCorpus(dir)) {
    INFO("dynlab run ", h.shown, " --duration 0.2");
    // (after "--": a name that starts with a dash is the file's)
    const Result r = timedDynlab(dir, {"run", "--duration", "0.2", "--out", "out", "--", h.name});
    // A description may be larger than a submission (64 MB: meshes): 20 MB is read, and is not one.
    checkMessage(r, h.name == "big.json" ? Hostile{h.name, h.shown, {"/: ", "missing key \"format\""}} : h, h.shown);
    CHECK(r.out.empty());
    CHECK_FALSE(fs::exists(dir / "out"));
  }
  writeFile(dir / "huge.json", R"({"format": ")" + std::string(65u << 20, 'x') + "\"}");
  const Result r = timedDynlab(dir, {"run", "huge.json", "--out", "out"});
  checkMessage(r, {"huge.json", "huge.json", {"expected at most", "bytes"}}, "huge.json");
}

TEST_CASE("hostile submissions graded: exit 2, a valid results.json with score 0 and the message; replay agrees") {
  TempDir dir("hostile_grade");
  for (const Hostile& h : buildCorpus(dir)) {
    INFO("dynlab grade ", h.shown);
    const Result r = timedDynlab(dir, {"grade", "--out", "out", "--no-plots", "--", h.name});
    checkMessage(r, h, h.shown);
    // The results set, and nothing else; Gradescope's shape checked by the binary itself.
    const auto written = snapshot(dir / "out");
    CHECK(written.size() == 3);
    CHECK(written.count("results.json") == 1);
    const Result check = timedDynlab(dir, {"check-results", "out/results.json"});
    CHECK_MESSAGE(check.code == 0, check.err);
    const json results = json::parse(readFile(dir / "out/results.json"));
    CHECK(results.at("score") == 0.0);
    const std::string message = r.err.substr(7, r.err.size() - 8);  // without "error: " and "\n"
    CHECK(results.at("output").get<std::string>().find(h.says.front()) != std::string::npos);
    CHECK(results.at("extra_data").at("error").at("expected").get<std::string>().size() > 0);
    CHECK(message.find(results["extra_data"]["error"]["expected"].get<std::string>().substr(0, 20)) != std::string::npos);
    for (const auto& [name, text] : written) CHECK(text.find(passwdStart()) == std::string::npos);

    // --replay re-grades the same failure to the same results: no abort (was exit 134), exit 0.
    const Result replay = timedDynlab(dir, {"grade", "--replay", "out/results.json", "--", h.name});
    INFO("replay: ", replay.out, replay.err);
    CHECK(replay.code == 0);
    CHECK(replay.out.find("replay: match") != std::string::npos);
    fs::remove_all(dir / "out");

    // The same file as the results to replay against: an input error about it.
    const Result as_results = timedDynlab(dir, {"grade", kStable, "--replay=" + h.name});
    checkMessage(as_results, h, h.shown);
  }
}

TEST_CASE("a UTF-8 byte order mark is accepted everywhere; a lone surrogate or overlong form is not UTF-8") {
  TempDir dir("hostile_bom");
  writeFile(dir / "bom.json", "\xEF\xBB\xBF" + readFile(kStable));
  const Result g = timedDynlab(dir, {"grade", "bom.json", "--out", "out", "--no-plots"});
  INFO(g.err);
  CHECK(g.code == 0);
  CHECK(json::parse(readFile(dir / "out/results.json")).at("score").get<double>() > 0);
  CHECK(timedDynlab(dir, {"run", "slider_crank", "--duration", "0.1", "--gains", "bom.json", "--out", "run"}).code == 0);
  // Encoded surrogate (ED A0 80) and overlong "/" (C0 AF): well-formed UTF-8 forbids both.
  for (const std::string bad : {"\xED\xA0\x80", "\xC0\xAF"}) {
    const std::string text = R"({"lab": "slider_crank", "note": ")" + bad + "\"}";
    writeFile(dir / "bad.json", text);
    const Result r = timedDynlab(dir, {"run", "slider_crank", "--gains", "bad.json", "--out", "out2"});
    CHECK(r.code == 2);
    CHECK(r.err.find("at offset " + offsetOf(text, bad) + " is not valid UTF-8") != std::string::npos);
  }
  CHECK(dyn::utf8Quotable("a\xE9z\xE2\x82") == "a\\xE9z\\xE2\\x82");
  CHECK(dyn::utf8Quotable("caf\xC3\xA9 \xF0\x9F\x98\x80") == "caf\xC3\xA9 \xF0\x9F\x98\x80");
}

TEST_CASE("dynlab run with diverging gains: the grader's watchdog sentence, truthful statuses, exit 1") {
  TempDir dir("hostile_unstable");
  const std::string gains = kExamples + "unstable_integral.json";
  const Result r = timedDynlab(dir, {"run", "slider_crank", "--gains", gains, "--out", "out"});
  INFO("stdout: ", r.out, "\nstderr: ", r.err);
  CHECK(r.code == 1);
  const std::string sentence = "unstable: the rail force left its safe range [-500, 500] at t = ";
  CHECK(r.out.find("hand   STOPPED  " + sentence) != std::string::npos);
  const json summary = json::parse(readFile(dir / "out/summary.json"));
  CHECK(summary.at("status").get<std::string>().rfind("hand: " + sentence, 0) == 0);
  CHECK_FALSE(summary.contains("agreement"));  // nothing to compare a stopped run with
  for (const char* engine : {"hand", "bullet"}) {
    INFO("engine ", engine);
    const json& e = summary.at("engines").at(engine);
    CHECK(e.at("status") != "ok");
    CHECK(e.at("complete") == false);
    CHECK_FALSE(e.contains("metrics"));  // metrics of a stopped run are omitted, not reported as if complete
    CHECK(e.at("stopped_at").get<double>() < summary.at("duration").get<double>());
    // The trace is kept up to the stop, and no further.
    const Csv trace = readCsv(dir / (std::string("out/trace_") + engine + ".csv"));
    CHECK(trace.rows.back()[std::size_t(trace.col("t"))] == doctest::Approx(e.at("stopped_at").get<double>()));
  }
  // The exact sentence the grader gives the same gains in its nominal scenario.
  const Result g = timedDynlab(dir, {"grade", gains, "--out", "grade", "--no-plots"});
  CHECK(g.code == 0);
  const json results = json::parse(readFile(dir / "grade/results.json"));
  CHECK(summary["engines"]["hand"]["status"] == results["extra_data"]["scenarios"]["nominal"]["status"]);

  // Stable gains: both engines complete, with metrics and their agreement.
  const Result ok = timedDynlab(dir, {"run", "slider_crank", "--duration", "0.5", "--gains", kStable, "--out", "good"});
  CHECK(ok.code == 0);
  const json fine = json::parse(readFile(dir / "good/summary.json"));
  CHECK(fine.at("status") == "ok");
  for (const char* engine : {"hand", "bullet"}) {
    CHECK(fine["engines"][engine]["complete"] == true);
    CHECK(fine["engines"][engine].contains("metrics"));
  }
  CHECK(fine.contains("agreement"));
}

TEST_CASE("a grade cut short by the time budget exits 4 with a valid results.json, not 0") {
  TempDir dir("hostile_budget");
  // Runs of 1.5e6 steps take far longer than the 1 s budget.
  json config = json::parse(defaultConfigText());
  config["simulation"]["dt"] = 1e-5;
  config["simulation"]["duration"] = 15.0;
  config["rubric"]["watchdog"]["max_steps"] = 3000000;
  writeFile(dir / "slow.json", config.dump());
  const Result r =
      timedDynlab(dir, {"grade", kStable, "--config", "slow.json", "--time-budget", "1", "--no-plots", "--out", "out"});
  INFO("stdout: ", r.out, "\nstderr: ", r.err);
  CHECK(r.code == 4);
  CHECK(r.err.find("time budget of 1 s ran out") != std::string::npos);
  CHECK(timedDynlab(dir, {"check-results", "out/results.json"}).code == 0);
  const json results = json::parse(readFile(dir / "out/results.json"));
  CHECK(results.dump().find("not graded: the grading time budget ran out") != std::string::npos);
}

TEST_CASE("an exception that escapes a command: one line 'error: internal: ...', exit 3, no abort") {
  TempDir dir("hostile_internal");
  writeFile(dir / "boom.json", readFile(kStable));
  const Result r = timedDynlab(dir, {"grade", "boom.json", "--out", "out"}, withEnv({{"DYNLAB_FAULT_INJECTION", "throw:boom"}}));
  INFO("stderr: ", r.err);
  CHECK(r.code == 3);
  CHECK(r.err == "error: internal: injected fault for boom\n");
  CHECK_FALSE(fs::exists(dir / "out/results.json"));
}
