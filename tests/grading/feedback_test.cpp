// Feedback a student can read: a plot for every simulated test (derived for any rubric, also one
// without plots or metric definitions), the metric's window hatched, report.html self-contained,
// plots inline in results.json for Gradescope (and --replay still matching), replay hints that
// run as printed, and replay diffs that say was → now.
#include <doctest/doctest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <stb/stb_image.h>

#include "grading/escape.h"
#include "grading/grade.h"
#include "grading/metric_doc.h"
#include "grading/report.h"
#include "grading/test_plot.h"
#include "labs/run.h"
#include "tests/app/cli_run.h"
#include "tests/test_files.h"

namespace fs = std::filesystem;
using namespace dyn;
using dyn::test::readBytes;

namespace {

const std::string kLabDir = std::string(DYNLAB_SOURCE_DIR) + "/labs/slider_crank/";
const std::string kMediocre = kLabDir + "examples/mediocre.json";

json defaultConfig() { return json::parse(std::ifstream(kLabDir + "slider_crank.json")); }

fs::path scratch(const std::string& name) { return dyn::test::scratchDir("dynlab_feedback_test", name); }

std::string write(const fs::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
  return p.string();
}

// Grades with plots into dir (a config of our own when given).
GradeOutcome gradeInto(const fs::path& dir, const std::string& submission, const json* config = nullptr, bool inline_plots = false) {
  GradeOptions o;
  o.out_dir = dir.string();
  o.inline_plots = inline_plots;
  if (config) o.config_file = write(dir / "config.json", config->dump());
  return gradeSubmission(submission, o);
}

// The screening metrics of the lab (tests of these have no simulation, so no plot).
bool screening(const std::string& metric) {
  static const auto loops = buildLab(*findLab("slider_crank"), defaultConfig(), "config.json")->linearise();
  return screeningMetricDoc(metric, loops).has_value();
}

// Every simulated test of a grade has a plot that exists, and report.md shows it.
void checkEverySimulatedTestPlotted(const fs::path& dir, const GradeOutcome& g) {
  REQUIRE_FALSE(g.input_error);
  REQUIRE_FALSE(g.internal_error);
  int plotted = 0;
  for (const auto& t : g.results.at("tests")) {
    INFO("test ", t.at("name"));
    const std::string metric = t.at("extra_data").at("metric");
    if (screening(metric)) {
      CHECK_FALSE(t.at("extra_data").contains("plot"));
      continue;
    }
    REQUIRE(t.at("extra_data").contains("plot"));
    const std::string plot = t["extra_data"]["plot"];
    CHECK(fs::file_size(dir / plot) > 1000);
    CHECK(g.markdown.find("](" + plot + ")") != std::string::npos);
    ++plotted;
  }
  CHECK(plotted == 8);
}

// Hatching pixels (the "not scored" span: a light bluish grey) in a box of fractions of the picture.
int hatch(const fs::path& png, double x0, double x1, double y0, double y1) {
  int w = 0, h = 0, n = 0;
  unsigned char* rgb = stbi_load(png.string().c_str(), &w, &h, &n, 3);
  REQUIRE(rgb);
  int count = 0;
  for (int y = int(y0 * h); y < int(y1 * h); ++y)
    for (int x = int(x0 * w); x < int(x1 * w); ++x) {
      const unsigned char* p = rgb + (std::size_t(y) * w + x) * 3;
      count += p[0] >= 150 && p[0] < 245 && std::abs(p[0] - p[1]) <= 3 && p[2] - p[0] >= 5;
    }
  stbi_image_free(rgb);
  return count;
}

std::string plotOf(const GradeOutcome& g, const std::string& test_name) {
  for (const auto& t : g.results.at("tests"))
    if (t.at("name") == test_name) return t.at("extra_data").value("plot", "");
  return "";
}

// The value of each src= of an HTML text (quoted or not; any case; std::regex overflows its stack
// on a long data: URI, so by hand).
std::vector<std::string> sources(const std::string& html) {
  std::string lower = html;
  for (char& c : lower) c = char(std::tolower(static_cast<unsigned char>(c)));
  std::vector<std::string> out;
  for (std::size_t at = lower.find("src"); at != std::string::npos; at = lower.find("src", at + 3)) {
    std::size_t i = at + 3;
    while (i < html.size() && std::isspace(static_cast<unsigned char>(html[i]))) ++i;
    if (i >= html.size() || html[i] != '=') continue;
    ++i;
    while (i < html.size() && std::isspace(static_cast<unsigned char>(html[i]))) ++i;
    const char quote = i < html.size() && (html[i] == '"' || html[i] == '\'') ? html[i++] : 0;
    std::size_t end = i;
    while (end < html.size() && (quote ? html[end] != quote : !std::isspace(static_cast<unsigned char>(html[end])) && html[end] != '>')) ++end;
    out.push_back(html.substr(i, end - i));
  }
  return out;
}

// Base64 → bytes (the alphabet of data: URIs; stops at '=').
std::string base64Decode(const std::string& s) {
  static const std::string digits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  unsigned v = 0;
  int bits = 0;
  for (char c : s) {
    const auto d = digits.find(c);
    if (d == std::string::npos) break;
    v = v << 6 | unsigned(d);
    if ((bits += 6) >= 8) out += char((v >> (bits -= 8)) & 0xFF);
  }
  return out;
}

}  // namespace

TEST_CASE("a PNG's data URI is its bytes in base64, a short last group padded") {
  // RFC 4648's test vectors, and every byte value (0xff, 0x00 and the 6-bit groups' edges).
  const std::pair<std::string, std::string> vectors[] = {{"", ""},         {"f", "Zg=="},         {"fo", "Zm8="},
                                                         {"foo", "Zm9v"},  {"foob", "Zm9vYg=="}, {"fooba", "Zm9vYmE="},
                                                         {"foobar", "Zm9vYmFy"}, {std::string("\xff\x00\xfb", 3), "/wD7"}};
  for (const auto& [bytes, digits] : vectors) CHECK(pngDataUri(bytes) == "data:image/png;base64," + digits);
}

TEST_CASE("every simulated test has a plot: the rubric's, else one derived from the metric and the lab") {
  SUBCASE("the shipped rubric (two of its tests name no plot)") {
    const fs::path dir = scratch("shipped");
    checkEverySimulatedTestPlotted(dir, gradeInto(dir, kMediocre));
  }
  SUBCASE("a rubric with no plots at all") {
    json config = defaultConfig();
    for (auto& t : config["rubric"]["tests"]) t.erase("plot");
    const fs::path dir = scratch("no_plots");
    checkEverySimulatedTestPlotted(dir, gradeInto(dir, kMediocre, &config));
  }
  SUBCASE("no plots, no metric definitions, no watchdog limits") {
    json config = defaultConfig();
    for (auto& t : config["rubric"]["tests"]) t.erase("plot");
    config.erase("metric_docs");
    config["rubric"]["watchdog"]["limits"] = json::array();
    const fs::path dir = scratch("bare");
    checkEverySimulatedTestPlotted(dir, gradeInto(dir, kMediocre, &config));
  }
}

TEST_CASE("what a test without a plot of its own plots, derived in order") {
  json config = defaultConfig();
  const auto lab = buildLab(*findLab("slider_crank"), config, "config.json");
  const auto plan = [&](const json& c, std::size_t i) {
    return planTestPlot(parseRubric(JsonView(c, "config.json")), i, parseMetricDocs(JsonView(c, "config.json")), *lab);
  };
  // Test 5 (light payload, x_rms) borrows test 1's plot; its band is its own full-credit threshold.
  config["rubric"]["tests"][4]["full"] = 0.004;
  TestPlotPlan p = plan(config, 4);
  CHECK(p.request.columns == std::vector<std::string>{"x_c"});
  CHECK(p.request.reference == "x_d");
  CHECK(p.request.band == doctest::Approx(0.004));
  CHECK(p.band_unit == "m");
  // With no plot anywhere: the columns of the metric's definition ("x_c − x_d"), the reference
  // after the minus sign, a band of the full-credit threshold (same unit), a label with the unit.
  for (auto& t : config["rubric"]["tests"]) t.erase("plot");
  p = plan(config, 0);
  CHECK(p.request.columns == std::vector<std::string>{"x_c"});
  CHECK(p.request.reference == "x_d");
  CHECK(p.request.band == doctest::Approx(config["rubric"]["tests"][0]["full"].get<double>()));
  CHECK(p.request.ylabel == "x_c, x_d (m)");
  CHECK(std::isinf(p.from));
  p = plan(config, 1);  // f_rms: f_Ty against f_des, counted from settle_time on
  CHECK(p.request.columns == std::vector<std::string>{"f_Ty"});
  CHECK(p.request.reference == "f_des");
  CHECK(p.from == doctest::Approx(0.5));
  // "largest |τ_i| of the three joint torques" names no column: the watchdog's columns.
  p = plan(config, 2);
  CHECK(p.request.columns == std::vector<std::string>{"v_c", "f_Ty", "tau1", "constraint_residual"});
  CHECK(p.request.band == 0);
  // Nothing at all to go by: the energy.
  config["rubric"]["watchdog"]["limits"] = json::array();
  CHECK(plan(config, 2).request.columns == std::vector<std::string>{"energy"});
  // The window follows the config value it points at.
  config["metrics"]["settle_time"] = 0.8;
  CHECK(plan(config, 1).from == doctest::Approx(0.8));
}

TEST_CASE("a metric's window: hatched where it does not count, read from its metric_docs window") {
  const fs::path dir = scratch("window");
  const GradeOutcome g = gradeInto(dir, kMediocre);
  REQUIRE_FALSE(g.input_error);
  // f_rms counts from 0.5 s of 4 s: the first eighth of the frame is hatched, the rest is not; the
  // x_rms plot (the whole run) has no hatching in its frame.
  const fs::path force = dir / plotOf(g, "Rail force regulated to f_des"), track = dir / plotOf(g, "Slider tracks x_d(t)");
  CHECK(hatch(force, 0.09, 0.16, 0.1, 0.6) > 100);
  CHECK(hatch(force, 0.3, 0.9, 0.1, 0.6) < 5);  // a stray anti-aliased pixel or two
  CHECK(hatch(track, 0.09, 0.16, 0.1, 0.6) < 5);

  // Bad window bounds are the config's error, naming the JSON path.
  const auto error = [](json c) {
    try {
      parseMetricDocs(JsonView(c, "cfg.json"));
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  // The window in numbers is what its words say (placeholders filled), or from/to when given.
  const auto docs = [](const json& c) { return parseMetricDocs(JsonView(c, "cfg.json")); };
  json c = defaultConfig();
  c["metric_docs"]["f_rms"]["window"] = "from t = {/metrics/settle_time} s to t = 3 s";
  CHECK(docs(c).at("f_rms").from == doctest::Approx(0.5));
  CHECK(docs(c).at("f_rms").to == doctest::Approx(3));
  c["metric_docs"]["f_rms"]["window"] = "until t = 2.5 s";
  CHECK(std::isinf(docs(c).at("f_rms").from));
  CHECK(docs(c).at("f_rms").to == doctest::Approx(2.5));
  c["metric_docs"]["f_rms"]["from"] = 1;
  CHECK(docs(c).at("f_rms").from == doctest::Approx(1));
  CHECK(std::isinf(docs(c).at("x_rms").from));  // "the whole run"
  CHECK(std::isinf(docs(c).at("x_rms").to));
  c["metric_docs"]["f_rms"]["window"] = "from t = 3 s until t = 1 s";
  c["metric_docs"]["f_rms"].erase("from");
  CHECK(error(c).find("/metric_docs/f_rms/window: expected the window's end after its start") != std::string::npos);
  c = defaultConfig();
  c["metric_docs"]["f_rms"]["from"] = "{/metrics/nope}";
  CHECK(error(c).find("cfg.json: /metric_docs/f_rms/from: expected a number of seconds") != std::string::npos);
  c["metric_docs"]["f_rms"]["from"] = true;
  CHECK(error(c).find("/metric_docs/f_rms/from") != std::string::npos);
  c["metric_docs"]["f_rms"]["from"] = 2;
  c["metric_docs"]["f_rms"]["to"] = 1;
  CHECK(error(c).find("/metric_docs/f_rms/to: expected the window's end after its start") != std::string::npos);
}

TEST_CASE("report.html is one self-contained file: every image inline, nothing fetched") {
  const fs::path dir = scratch("html");
  const GradeOutcome g = gradeInto(dir, kMediocre);
  REQUIRE_FALSE(g.input_error);
  const std::vector<std::string> srcs = sources(g.html);
  CHECK(srcs.size() == 8);
  for (const auto& s : srcs) {
    CHECK(s.rfind("data:image/png;base64,", 0) == 0);
    CHECK(base64Decode(s.substr(22)).rfind("\x89PNG\r\n\x1a\n", 0) == 0);
  }
  CHECK(g.html.find("href=\"http") == std::string::npos);
  CHECK(g.html.find("<link") == std::string::npos);
}

TEST_CASE("results.json for Gradescope: each simulated test's output is HTML with its plot inline") {
  const fs::path dir = scratch("inline");
  const GradeOutcome with = gradeInto(dir, kMediocre, nullptr, true);
  REQUIRE_FALSE(with.input_error);
  std::size_t images = 0, bytes = 0;
  for (const auto& t : with.results.at("tests")) {
    CHECK(t.at("output_format") == "html");
    const std::string out = t.at("output");
    const auto srcs = sources(out);
    CHECK(srcs.size() == (t.at("extra_data").contains("plot") ? 1u : 0u));
    for (const auto& s : srcs) {
      REQUIRE(s.rfind("data:image/png;base64,", 0) == 0);
      const std::string png = base64Decode(s.substr(22));
      CHECK(png == readBytes(dir / t["extra_data"]["plot"].get<std::string>()));  // the plot on disk
      bytes += s.size(), ++images;
    }
  }
  CHECK(images == 8);
  CHECK(bytes <= kMaxInlinePlotBytes);
  CHECK(with.results.at("test_output_format") == "html");
  // Without the plots, it is the results.json of a grade without --inline-plots.
  const GradeOutcome without = gradeInto(scratch("inline_off"), kMediocre);
  json a = withoutInlinePlots(with.results), b = without.results;
  CHECK(compareResults(a, b).empty());
  CHECK_FALSE(compareResults(with.results, b).empty());
}

TEST_CASE("replay differences say what each value was and is now") {
  const GradeOutcome g = gradeSubmission(kMediocre, {});
  json tampered = g.results;
  tampered["tests"][0]["score"] = 2.5;
  tampered["extra_data"]["scenarios"]["nominal"]["metrics"]["x_rms"] = 0.02;
  tampered["tests"][1].erase("tags");
  const auto diff = compareResults(tampered, g.results);
  REQUIRE(diff.size() == 3);
  const std::string all = diff[0] + "\n" + diff[1] + "\n" + diff[2];
  CHECK(all.find("/extra_data/scenarios/nominal/metrics/x_rms: was 0.02 → now 0.0116") != std::string::npos);
  CHECK(all.find("/tests/0/score: was 2.5 → now 0") != std::string::npos);  // x_rms 0.0116 m: past the zero threshold
  CHECK(all.find("/tests/1/tags: added, now [\"nominal\"]") != std::string::npos);
}

TEST_CASE("dynlab grade: the replay hints run as printed, from any folder, and replay says was → now") {
  using namespace dyn::test::cli;
  TempDir dir("feedback_replay");
  // A folder with a space and a quote, a config of its own (the hint must carry --config).
  const fs::path odd = dir / "it's a dir";
  fs::create_directories(odd);
  write(odd / "my gains.json", readBytes(kMediocre));
  write(odd / "lab config.json", readBytes(kLabDir + "slider_crank.json"));
  const Result r = dynlab(dir, {"grade", (odd / "my gains.json").string(), "--config", (odd / "lab config.json").string(),
                                "--lab", "slider_crank", "--out", (odd / "out put").string(), "--inline-plots"});
  INFO(r.out, r.err);
  REQUIRE(r.code == 0);
  // results.json with inline plots passes Gradescope's shape check.
  const Result check = dynlab(dir, {"check-results", (odd / "out put/results.json").string()});
  CHECK_MESSAGE(check.code == 0, check.err);
  // The terminal's hint and report.md's, each run by a POSIX shell (sh) from another folder.
  ProcessOptions from_root;
  from_root.cwd = "/";
  std::smatch m;
  REQUIRE(std::regex_search(r.out, m, std::regex("replay:  ([^\n]*)\n")));
  const std::string terminal_hint = m[1];
  const std::string md = readBytes(odd / "out put/report.md");
  REQUIRE(std::regex_search(md, m, std::regex("Re-check with `([^`]*)`")));
  const std::string report_hint = m[1];
  CHECK(report_hint == terminal_hint);
  CHECK(report_hint.find("--config") != std::string::npos);
  for (const std::string& hint : {terminal_hint, report_hint}) {
    const Result replay =
        run(dir, {"sh", "-c", hint}, from_root);  // a user's shell: the test checks the command line printed for pasting
    INFO(hint, "\n", replay.out, replay.err);
    CHECK(replay.code == 0);
    CHECK(replay.out.find("replay: match") != std::string::npos);
  }
  // A changed grade: each metric as was → now.
  json results = json::parse(readBytes(odd / "out put/results.json"));
  results["tests"][0]["extra_data"]["value"] = 0.02;
  results["tests"][0]["score"] = 2.5;
  write(odd / "out put/results.json", results.dump());
  const Result changed =
      run(dir, {"sh", "-c", terminal_hint}, from_root);  // a user's shell: the test checks the command line printed for pasting
  CHECK(changed.code == 1);
  CHECK(changed.out.find("metric x_rms of test 1 (Slider tracks x_d(t)): was 0.02 → now 0.0116") != std::string::npos);
  CHECK(changed.out.find("score was 2.5 → now 0") != std::string::npos);
}

TEST_CASE("inline plots stop at their budget: later ones are named as left out, and replay strips both") {
  GradeReport r;
  r.lab = "slider_crank";
  r.inline_plots = true;
  ScenarioSummary s;
  s.scenario.name = "nominal";
  r.scenarios.push_back(s);
  for (int i = 0; i < 3; ++i) {
    GradedTest g;
    g.test.name = "test " + std::to_string(i);
    g.test.scenario = "nominal";
    g.value = 1;
    g.plot = "plots/0" + std::to_string(i + 1) + "-test.png";
    g.plot_png = "\x89PNG\r\n\x1a\n" + std::string(kMaxInlinePlotBytes / 3, 'x');  // 4/9 of the budget as base64
    r.tests.push_back(g);
  }
  const json results = resultsJson(r);
  const auto output = [&](int i) { return results["tests"][i]["output"].get<std::string>(); };
  CHECK(output(0).find("src=\"data:image/png;base64,iVBORw0KGg") != std::string::npos);
  CHECK(output(1).find("src=\"data:image/png;base64,") != std::string::npos);
  CHECK(output(2).find("data:") == std::string::npos);
  CHECK(output(2).find("left out") != std::string::npos);
  // Without them, each output is the test's text alone.
  r.inline_plots = false;
  CHECK(withoutInlinePlots(results) == resultsJson(r));
}
