// Lab configs and gains files (labs/config, labs/run, labs/submission): good input builds the lab;
// every kind of bad input is an InputError that names the file, the JSON path and what was
// expected — never a crash, a silent default or some other exception.
#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <unistd.h>

#include "labs/run.h"
#include "labs/submission.h"

using namespace dyn;
namespace fs = std::filesystem;

namespace {

json defaultConfig() { return loadJsonFile(defaultConfigPath("slider_crank")); }

// The default config's text with "load_mass": 0.5 written as "load_mass": VALUE (what JSON cannot say).
std::string configTextWithLoadMass(const std::string& value) {
  std::string text = defaultConfig().dump(2);
  const std::string key = "\"load_mass\": 0.5";
  REQUIRE(text.find(key) != std::string::npos);
  return text.replace(text.find(key), key.size(), "\"load_mass\": " + value);
}

// A scratch directory unique to this process, removed at the end.
struct TempDir {
  fs::path path = fs::temp_directory_path() / ("dynlab_labs_config_test_" + std::to_string(::getpid()));
  TempDir() {
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string write(const std::string& name, const std::string& text) const {
    const fs::path p = path / name;
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }
};

// Builds the default config with `patch` merged in, expecting an InputError; returns it.
InputError buildError(const json& patch, const std::string& file = "bad_config.json") {
  const LabEntry* entry = findLab("slider_crank");
  REQUIRE(entry != nullptr);
  try {
    buildLab(*entry, mergePatch(defaultConfig(), patch), file);
  } catch (const InputError& e) {
    return e;
  }
  FAIL("expected an InputError for the patch " << patch.dump());
  return InputError("", "", "");
}

// The error names the file and the JSON path (both in the message, as the CLI prints it) and says
// what was expected.
void checkNames(const InputError& e, const std::string& file, const std::string& path, const std::string& expected) {
  const std::string what = e.what();
  INFO("message: ", what);
  CHECK(e.file() == file);
  CHECK(e.path() == path);
  CHECK(what.find(file) != std::string::npos);
  CHECK(what.find(path) != std::string::npos);
  CHECK(what.find(expected) != std::string::npos);
  CHECK(what.find('\n') == std::string::npos);  // one line
}

}  // namespace

TEST_CASE("the default config builds, and loadLab applies gains and a duration override") {
  TempDir tmp;
  const std::string gains = tmp.write("gains.json", R"({"gains": {"kp_x": 123.0}})");
  const LoadedLab l = loadLab("slider_crank", "", gains, 0.25);
  REQUIRE(l.lab);
  CHECK(l.config_file == defaultConfigPath("slider_crank"));
  CHECK(l.config["gains"]["kp_x"]["value"] == 123.0);
  CHECK(l.lab->duration() == 0.25);
  CHECK(l.lab->dt() == defaultConfig()["simulation"]["dt"].get<double>());
}

TEST_CASE("unknown lab") {
  try {
    loadLab("no_such_lab");
    FAIL("expected an InputError");
  } catch (const InputError& e) {
    checkNames(e, "<command line>", "LAB", "unknown lab \"no_such_lab\"");
    CHECK(std::string(e.what()).find("slider_crank") != std::string::npos);  // lists what exists
  }
}

TEST_CASE("bad values in a lab config name the file, the JSON path and what was expected") {
  SUBCASE("missing key") {
    checkNames(buildError({{"mechanism", {{"load_mass", nullptr}}}}), "bad_config.json", "/mechanism",
               "missing key \"load_mass\"");
  }
  SUBCASE("wrong type") {
    json links = defaultConfig()["mechanism"]["links"];
    links[0]["mass"] = "heavy";
    checkNames(buildError({{"mechanism", {{"links", links}}}}), "bad_config.json", "/mechanism/links/0/mass",
               "expected a number, got \"heavy\"");
  }
  SUBCASE("NaN as a string (JSON has no NaN)") {
    checkNames(buildError({{"simulation", {{"dt", "NaN"}}}}), "bad_config.json", "/simulation/dt",
               "expected a number");
  }
  SUBCASE("infinity and NaN held in memory (a config built in code, not parsed)") {
    checkNames(buildError({{"mechanism", {{"load_mass", std::numeric_limits<double>::infinity()}}}}),
               "bad_config.json", "/mechanism/load_mass", "expected a finite number, got inf");
    checkNames(buildError({{"simulation", {{"dt", std::numeric_limits<double>::quiet_NaN()}}}}),
               "bad_config.json", "/simulation/dt", "expected a finite number, got NaN");
  }
  SUBCASE("negative mass") {
    json links = defaultConfig()["mechanism"]["links"];
    links[0]["mass"] = -1.0;
    checkNames(buildError({{"mechanism", {{"links", links}}}}), "bad_config.json", "/mechanism/links/0/mass",
               "expected a positive number, got -1");
  }
  SUBCASE("dt = 0 and dt < 0") {
    checkNames(buildError({{"simulation", {{"dt", 0.0}}}}), "bad_config.json", "/simulation/dt",
               "expected a positive number");
    checkNames(buildError({{"simulation", {{"dt", -1e-3}}}}), "bad_config.json", "/simulation/dt",
               "expected a positive number");
  }
  SUBCASE("unknown controller kind") {
    checkNames(buildError({{"controller", {{"kind", "pid"}}}}), "bad_config.json", "/controller/kind",
               "expected one of \"none\", \"force_control\"");
  }
  SUBCASE("unknown key (a typo must not pass silently)") {
    checkNames(buildError({{"simulation", {{"dtt", 0.002}}}}), "bad_config.json", "/simulation/dtt",
               "unknown key \"dtt\"");
    checkNames(buildError({{"mechansim", json::object()}}), "bad_config.json", "/mechansim", "unknown key \"mechansim\"");
    // The path is a JSON Pointer (RFC 6901): "/" and "~" inside a key are escaped.
    checkNames(buildError({{"simulation", {{"d/t~", 0.002}}}}), "bad_config.json", "/simulation/d~1t~0",
               "unknown key \"d/t~\"");
  }
  SUBCASE("wrong array length") {
    checkNames(buildError({{"mechanism", {{"gravity", {0.0, -9.81, 0.0}}}}}), "bad_config.json",
               "/mechanism/gravity", "expected an array of 2 elements, got 3");
  }
  SUBCASE("a crank angle the rod cannot reach") {
    // |l1 sin θ1| ≤ l2 is needed; make the rod shorter than l1 sin 60°.
    json links = defaultConfig()["mechanism"]["links"];
    links[1]["length"] = 0.2;
    checkNames(buildError({{"mechanism", {{"links", links}}}}), "bad_config.json", "/initial/theta1_deg",
               "expected a crank angle the rod can reach");
  }
}

TEST_CASE("bad files: malformed, empty, missing, a number that overflows, NaN in the text") {
  TempDir tmp;
  auto loadError = [&](const std::string& file) -> InputError {
    try {
      loadLab("slider_crank", file);
    } catch (const InputError& e) {
      return e;
    } catch (const std::exception& e) {
      FAIL("expected an InputError, got another exception: " << std::string(e.what()));
    }
    FAIL("expected an InputError for " << file);
    return InputError("", "", "");
  };
  SUBCASE("malformed") {
    const std::string f = tmp.write("malformed.json", "{\"lab\": \"slider_crank\",\n  \"mechanism\": {,}\n");
    checkNames(loadError(f), f, "", "expected valid JSON");
    CHECK(std::string(loadError(f).what()).find("line 2") != std::string::npos);  // where
  }
  SUBCASE("empty and whitespace only") {
    checkNames(loadError(tmp.write("empty.json", "")), (tmp.path / "empty.json").string(), "", "the file is empty");
    checkNames(loadError(tmp.write("blank.json", " \n\t\n")), (tmp.path / "blank.json").string(), "",
               "the file is empty");
  }
  SUBCASE("missing") {
    const std::string f = (tmp.path / "does_not_exist.json").string();
    checkNames(loadError(f), f, "", "expected a readable file");
  }
  SUBCASE("NaN written in the file is not JSON") {
    const std::string f = tmp.write("nan.json", configTextWithLoadMass("NaN"));
    checkNames(loadError(f), f, "", "expected valid JSON");
  }
  SUBCASE("1e999 overflows a double: an input error, not some other exception") {
    const std::string f = tmp.write("overflow.json", configTextWithLoadMass("1e999"));
    const InputError e = loadError(f);
    checkNames(e, f, "", "1e999");
  }
  SUBCASE("a valid file with a bad value names that file") {
    json c = defaultConfig();
    c["mechanism"]["links"][2]["mass"] = -0.5;
    const std::string f = tmp.write("negative_mass.json", c.dump(2));
    checkNames(loadError(f), f, "/mechanism/links/2/mass", "expected a positive number");
  }
}

TEST_CASE("bad gains files name the gains file and the JSON path") {
  TempDir tmp;
  auto gainsError = [&](const std::string& text) -> InputError {
    const std::string f = tmp.write("gains.json", text);
    try {
      loadLab("slider_crank", "", f);
    } catch (const InputError& e) {
      return e;
    }
    FAIL("expected an InputError for gains " << text);
    return InputError("", "", "");
  };
  const std::string f = (tmp.path / "gains.json").string();
  checkNames(gainsError(R"({"gains": {"kp_x": 1e9}})"), f, "/gains/kp_x", "expected a number in [0, 20000]");
  checkNames(gainsError(R"({"gains": {"kp_x": -1}})"), f, "/gains/kp_x", "expected a number in [0, 20000]");
  checkNames(gainsError(R"({"gains": {"kp_z": 1}})"), f, "/gains/kp_z", "unknown gain \"kp_z\"");
  checkNames(gainsError(R"({"gains": {"ki_f": "fast"}})"), f, "/gains/ki_f", "expected a number");
  checkNames(gainsError(R"({"gain": {}})"), f, "/gain", "unknown key \"gain\"");
  checkNames(gainsError(R"({"lab": "pendulum", "gains": {}})"), f, "/lab", "expected \"slider_crank\"");
  checkNames(gainsError(R"({"force_law": "bang_bang"})"), f, "/force_law", "expected one of");
  // Strict (grading): every declared gain must be present.
  const json config = defaultConfig();
  const json partial = json::parse(R"({"lab": "slider_crank", "gains": {"kp_x": 1, "kd_x": 1, "kp_f": 0.1}})");
  try {
    applySubmission(config, JsonView(partial, "submission.json"), "slider_crank", true);
    FAIL("expected an InputError");
  } catch (const InputError& e) {
    checkNames(e, "submission.json", "/gains", "missing key \"ki_f\"");
  }
}

TEST_CASE("a bad --duration override") {
  for (double d : {0.0, -1.0, 1e9, std::numeric_limits<double>::quiet_NaN()}) {
    INFO("duration ", d);
    try {
      loadLab("slider_crank", "", "", d);
      FAIL("expected an InputError");
    } catch (const InputError& e) {
      checkNames(e, "<command line>", "--duration", "expected a duration");
    }
  }
}

// Regressions from sanitizing and fuzzing the loaders (tests/fuzz, scripts/sanitize): each input
// crashed, hung or slipped past validation before its fix.

TEST_CASE("deeply nested JSON is an input error, not a stack overflow") {
  // Copying or dumping a json recurses once per level: 100k levels of "[" crashed loadLab and the
  // grader (both copy and dump the document) with SIGSEGV.
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  std::string path;  // where the 65th level opens: 64 arrays in, each at element 0
  for (int i = 0; i < 64; ++i) path += "/0";
  try {
    parseJsonText(deep, "deep.json");
    FAIL("expected an InputError");
  } catch (const InputError& e) {
    checkNames(e, "deep.json", path, "expected JSON nested at most 64 levels deep");
  }
  TempDir tmp;
  const std::string f = tmp.write("deep_gains.json", R"({"gains": )" + deep + "}");
  try {
    loadLab("slider_crank", "", f);
    FAIL("expected an InputError");
  } catch (const InputError& e) {
    checkNames(e, f, "/gains" + path.substr(2), "nested at most 64 levels");
  }
  // 64 levels are fine.
  CHECK_NOTHROW(parseJsonText(std::string(64, '[') + std::string(64, ']'), "ok.json"));
}

TEST_CASE("a directory given as a config file") {
  TempDir tmp;
  try {
    loadLab("slider_crank", tmp.path.string());
    FAIL("expected an InputError");
  } catch (const InputError& e) {
    // Was "expected at most 16777216 bytes, the file has 9223372036854775807".
    checkNames(e, tmp.path.string(), "", "expected a regular file, got a directory");
  }
}

TEST_CASE("error messages stay on one line whatever the input holds") {
  const InputError e = buildError({{"simulation", {{"d\nt", 0.001}}}});
  const std::string what = e.what();
  CHECK(what.find('\n') == std::string::npos);
  CHECK(what.find("unknown key \"d\\nt\"") != std::string::npos);
}

TEST_CASE("submission_options and gain declarations are validated with the config") {
  // Each of these passed buildLab and then threw nlohmann::json's type_error or parse_error (not an
  // InputError) from applySubmission or submissionSchema: `dynlab run --gains` and `dynlab schema`
  // terminated, the grader said "internal error".
  SUBCASE("not an object") {
    checkNames(buildError({{"submission_options", 5}}), "bad_config.json", "/submission_options",
               "expected an object, got 5");
  }
  SUBCASE("target is not a JSON pointer") {
    for (const char* target : {"controller/force_law", "/~2", ""}) {
      INFO(target);
      checkNames(buildError({{"submission_options", {{"force_law", {{"target", target}}}}}}), "bad_config.json",
                 "/submission_options/force_law/target", "expected a JSON pointer to a string in the config");
    }
  }
  SUBCASE("target is not a string of the config") {
    for (const char* target : {"/simulation/dt", "/simulation/nothing", "/mechanism/links/x", "/mechanism/links/99999999999999999999999"}) {
      INFO(target);
      checkNames(buildError({{"submission_options", {{"force_law", {{"target", target}}}}}}), "bad_config.json",
                 "/submission_options/force_law/target", "expected a JSON pointer to a string in the config");
    }
  }
  SUBCASE("choices and doc") {
    checkNames(buildError({{"submission_options", {{"force_law", {{"choices", {"integral", 3}}}}}}}), "bad_config.json",
               "/submission_options/force_law/choices/1", "expected a string, got 3");
    checkNames(buildError({{"submission_options", {{"force_law", {{"choices", json::array()}}}}}}), "bad_config.json",
               "/submission_options/force_law/choices", "expected an array of 1 to 64 elements, got 0");
    checkNames(buildError({{"submission_options", {{"force_law", {{"doc", 1}}}}}}), "bad_config.json",
               "/submission_options/force_law/doc", "expected a string, got 1");
    checkNames(buildError({{"submission_options", {{"gains", {{"target", "/controller/force_law"}, {"choices", {"x"}}}}}}}),
               "bad_config.json", "/submission_options/gains", "other than \"lab\" and \"gains\"");
  }
  SUBCASE("gain declarations: doc and unit are strings, min ≤ max, known keys only") {
    checkNames(buildError({{"gains", {{"kp_x", {{"doc", 1}}}}}}), "bad_config.json", "/gains/kp_x/doc",
               "expected a string, got 1");
    checkNames(buildError({{"gains", {{"kp_x", {{"unit", nullptr}, {"units", "N/m"}}}}}}), "bad_config.json",
               "/gains/kp_x/units", "unknown key \"units\"");
    checkNames(buildError({{"gains", {{"kp_x", {{"min", 10.0}, {"max", 5.0}}}}}}), "bad_config.json", "/gains/kp_x/max",
               "expected a number in [10, 1e+09], got 5");
  }
  SUBCASE("loadLab with a gains file over such a config is an InputError too") {
    TempDir tmp;
    json c = defaultConfig();
    c["submission_options"]["force_law"]["target"] = "/simulation/dt/x";  // terminate() in dynlab run
    const std::string cf = tmp.write("config.json", c.dump());
    const std::string gf = tmp.write("gains.json", R"({"force_law": "integral"})");
    CHECK_THROWS_AS(loadLab("slider_crank", cf), InputError);  // the config alone
    try {
      loadLab("slider_crank", cf, gf);
      FAIL("expected an InputError");
    } catch (const InputError& e) {
      checkNames(e, cf, "/submission_options/force_law/target", "expected a JSON pointer");
    }
  }
}

TEST_CASE("physical parameters outside sensible bounds are rejected before they reach the physics") {
  // Each of these built a lab: dt = 1e-12 made the force-delay buffer 1e10 doubles (std::bad_alloc),
  // the others overflowed to inf/NaN in the first steps.
  checkNames(buildError({{"simulation", {{"dt", 1e-12}, {"duration", 1e-6}}}}), "bad_config.json", "/simulation/dt",
             "expected a number in [1e-06, 0.05], got 1e-12");
  checkNames(buildError({{"simulation", {{"dt", 0.1}}}}), "bad_config.json", "/simulation/dt",
             "expected a number in [1e-06, 0.05], got 0.1");
  checkNames(buildError({{"mechanism", {{"load_mass", 1e300}}}}), "bad_config.json", "/mechanism/load_mass",
             "expected a positive number ≤ 1e+06, got 1e+300");
  checkNames(buildError({{"mechanism", {{"gravity", {0.0, -1e300}}}}}), "bad_config.json", "/mechanism/gravity/1",
             "expected a number in [-1000, 1000]");
  checkNames(buildError({{"initial", {{"theta1_rate", 1e200}}}}), "bad_config.json", "/initial/theta1_rate",
             "expected a number in [-1000, 1000]");
  checkNames(buildError({{"reference", {{"period", 1e-300}}}}), "bad_config.json", "/reference/period",
             "expected a number in [0.001, 1e+06]");
  json links = defaultConfig()["mechanism"]["links"];
  links[2]["com"] = {1e300, 0.0};
  checkNames(buildError({{"mechanism", {{"links", links}}}}), "bad_config.json", "/mechanism/links/2/com/0",
             "expected a number in [-100, 100]");
}

TEST_CASE("a run cut short by max_steps reserves only what it needs") {
  // 2e6 steps are allowed (dt = 1 µs, 2 s): runEngine(lab, engine, 5) used to reserve the whole
  // run's trace, ~300 MB, before taking five steps. More steps than that are refused up front.
  const LabEntry* entry = findLab("slider_crank");
  const auto lab = buildLab(*entry, mergePatch(defaultConfig(), {{"simulation", {{"dt", 1e-6}, {"duration", 2.0}}}}), "c.json");
  const RunResult r = runEngine(*lab, Engine::Hand, 5);
  CHECK(r.trace.rows() == 5);
  CHECK(r.trace.data.capacity() <= 6 * r.trace.columns.size());
  checkNames(buildError({{"simulation", {{"dt", 1e-6}, {"duration", 10.0}}}}), "bad_config.json",
             "/simulation/duration", "dt 1e-06 s over 10 s is 1e+07 steps, more than the 2e+06 a run may take");
}
