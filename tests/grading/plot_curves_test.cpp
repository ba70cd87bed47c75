// Tests for grading/plot_curves (the --plot grammar "a, b" / "y:x, y_d:x_d", a lab's "figures",
// labels with units, when equal scales apply) and the rubric's x–y plot spec ("x",
// "reference_x", "xlabel"): what parses, and the one-line error naming file and JSON path for
// what does not.
#include "grading/plot_curves.h"

#include <doctest/doctest.h>

#include <fstream>

#include "grading/metric_doc.h"
#include "grading/rubric.h"
#include "grading/test_plot.h"
#include "labs/lab.h"
#include "labs/run.h"

using namespace dyn;

namespace {

const std::string kConfig = std::string(DYNLAB_SOURCE_DIR) + "/labs/slider_crank/slider_crank.json";

json defaultConfig() { return json::parse(std::ifstream(kConfig)); }

const Lab& sliderCrank() {
  static const auto lab = buildLab(*findLab("slider_crank"), defaultConfig(), "config.json");
  return *lab;
}

std::vector<PlotCurve> curves(const std::string& spec) {
  return parsePlotCurves(spec, sliderCrank().columns(), "<command line>", "--plot " + spec);
}

// The message f throws as InputError ("(no error)" when it does not).
template <class F>
std::string error(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

bool has(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

}  // namespace

TEST_CASE("--plot curves: columns against t, or Y:X pairs; repeats dropped, spaces ignored") {
  CHECK(curves("f_Ty,f_des") == std::vector<PlotCurve>{{"f_Ty", "t"}, {"f_des", "t"}});
  CHECK_FALSE(parametric(curves("f_Ty,f_des")));
  const auto xy = curves(" f_Ty : f_Tx ,q2:q1, f_Ty:f_Tx");
  CHECK(xy == std::vector<PlotCurve>{{"f_Ty", "f_Tx"}, {"q2", "q1"}});
  CHECK(parametric(xy));
  CHECK(curvesText(xy) == "f_Ty vs f_Tx, q2 vs q1");
  CHECK(curvesText(curves("x_c, x_d")) == "x_c, x_d");
  CHECK(yColumns(curves("q2:q1, q3:q1")) == std::vector<std::string>{"q2", "q3"});
  CHECK(xColumns(curves("q2:q1, q3:q1")) == std::vector<std::string>{"q1"});
  // "Y:t" is Y against t.
  CHECK_FALSE(parametric(curves("x_c:t, x_d")));
}

TEST_CASE("--plot curves: bad specs are one line naming the option and what was expected") {
  const std::string unknown = error([] { curves("f_Ty:f_Tz"); });
  CHECK(has(unknown, "<command line>: --plot f_Ty:f_Tz: unknown column \"f_Tz\""));
  CHECK(has(unknown, "Y:X for column Y against column X"));
  CHECK(has(unknown, "one of: t, q1, q2"));
  CHECK(has(error([] { curves("f_Ty:"); }), "empty column name"));
  CHECK(has(error([] { curves(":x_c"); }), "empty column name"));
  CHECK(has(error([] { curves("x_c,"); }), "--plot x_c,: empty column name"));
  CHECK(has(error([] { curves("q3:q2:q1"); }), "\"q3:q2:q1\" has two ':'"));
  const std::string mixed = error([] { curves("x_c, f_Ty:f_Tx"); });
  CHECK(has(mixed, "expected every curve of one plot against t or every one against a column"));
  CHECK(has(mixed, "\"x_c\" is against t, \"f_Ty:f_Tx\" is not"));
  CHECK(mixed.find('\n') == std::string::npos);
}

TEST_CASE("axis labels carry the lab's units; equal scales only for one unit on both axes") {
  const Lab& lab = sliderCrank();
  CHECK(axisLabel(lab, {"x_c", "x_d"}) == "x_c, x_d (m)");
  CHECK(axisLabel(lab, {"x_c", "q1"}) == "x_c (m), q1 (rad)");
  CHECK(axisLabel(lab, {}) == "");
  CHECK(sameUnit(lab, {"f_Tx"}, {"f_Ty", "f_des"}));
  CHECK(sameUnit(lab, {"q1"}, {"q2", "q3"}));
  CHECK_FALSE(sameUnit(lab, {"x_c"}, {"v_c"}));         // a phase plot: m/s against m
  CHECK_FALSE(sameUnit(lab, {"x_c", "q1"}, {"x_d"}));   // one x column of another unit
  CHECK_FALSE(sameUnit(lab, {}, {"x_d"}));
}

TEST_CASE("a lab's \"figures\": its default x–y plots, validated with file and JSON path") {
  const auto parse = [](const json& c) { return parseLabFigures(JsonView(c, "lab.json"), sliderCrank().columns()); };
  CHECK(parse(json::object()).empty());
  const auto figs = parse(json::parse(R"j({"figures": [{"plot": "f_Ty:f_Tx, f_des:f_Tx", "title": "the tip force"},
                                                       {"plot": "x_c, x_d", "ylabel": "slider (m)", "xlabel": "time"}]})j"));
  REQUIRE(figs.size() == 2);
  CHECK(figs[0].curves == std::vector<PlotCurve>{{"f_Ty", "f_Tx"}, {"f_des", "f_Tx"}});
  CHECK(figs[0].title == "the tip force");
  CHECK(figs[0].ylabel.empty());
  CHECK(figs[1].curves == std::vector<PlotCurve>{{"x_c", "t"}, {"x_d", "t"}});
  CHECK(figs[1].ylabel == "slider (m)");
  CHECK(figs[1].xlabel == "time");

  const auto bad = [&](const std::string& text) { return error([&] { parse(json::parse(text)); }); };
  CHECK(has(bad(R"j({"figures": {"plot": "x_c"}})j"), "lab.json: /figures: expected an array"));
  CHECK(has(bad(R"j({"figures": []})j"), "lab.json: /figures: expected an array of 1 to 20 elements, got 0"));
  CHECK(has(bad(R"j({"figures": [{"plot": "x_c", "colour": "red"}]})j"), "lab.json: /figures/0/colour: unknown key"));
  CHECK(has(bad(R"j({"figures": [{"title": "no plot"}]})j"), "lab.json: /figures/0"));
  CHECK(has(bad(R"j({"figures": [{"plot": ["y", "x"]}]})j"), "lab.json: /figures/0/plot: expected a string"));
  CHECK(has(bad(R"j({"figures": [{"plot": "x_c"}, {"plot": "y:x"}]})j"),
            "lab.json: /figures/1/plot: unknown column \"y\""));
  CHECK(has(bad(R"j({"figures": [{"plot": "x_c, f_Ty:f_Tx"}]})j"), "lab.json: /figures/0/plot: expected every curve"));
  CHECK(has(bad(R"j({"figures": [{"plot": "x_c", "title": 3}]})j"), "lab.json: /figures/0/title: expected a string"));
  CHECK(has(bad(R"j({"figures": [{"plot": "x_c", "ylabel": "two\nlines"}]})j"),
            "lab.json: /figures/0/ylabel: expected one line of at most 200 bytes"));
  const json long_title = {{"figures", {{{"plot", "x_c"}, {"title", std::string(201, 'a')}}}}};
  CHECK(has(error([&] { parse(long_title); }), "lab.json: /figures/0/title: expected one line"));
  json many = {{"figures", json::array()}};
  for (int i = 0; i < 21; ++i) many["figures"].push_back({{"plot", "x_c"}});
  CHECK(has(error([&] { parse(many); }), "/figures: expected an array of 1 to 20 elements, got 21"));
}

TEST_CASE("a rubric test's x–y plot: x, reference_x (default x), xlabel; no band; columns checked") {
  json c = defaultConfig();
  const auto rubric = [](const json& cfg) { return parseRubric(JsonView(cfg, "cfg.json")); };
  c["rubric"]["tests"][0]["plot"] = json::parse(R"j({"x": "x_d", "columns": ["x_c"], "reference": "x_d"})j");
  PlotRequest p = *rubric(c).tests[0].plot;
  CHECK(p.x == "x_d");
  CHECK(p.reference_x == "x_d");
  CHECK(p.ylabel.empty());  // derived with the units when planned
  c["rubric"]["tests"][0]["plot"]["reference_x"] = "x_c";
  c["rubric"]["tests"][0]["plot"]["xlabel"] = "reference (m)";
  p = *rubric(c).tests[0].plot;
  CHECK(p.reference_x == "x_c");
  CHECK(p.xlabel == "reference (m)");
  // A plot against t is as before: its y label defaults to its first column.
  CHECK(rubric(defaultConfig()).tests[0].plot->x.empty());

  const auto bad = [&](const json& plot) {
    json cfg = defaultConfig();
    cfg["rubric"]["tests"][1]["plot"] = plot;
    return error([&] {
      const Rubric r = rubric(cfg);
      checkColumns(r, sliderCrank().columns(), "cfg.json");
    });
  };
  CHECK(has(bad(json::parse(R"j({"x": "f_Tx", "columns": ["f_Ty"], "band": 0.1})j")),
            "cfg.json: /rubric/tests/1/plot/band: expected no band on an x–y plot"));
  CHECK(has(bad(json::parse(R"j({"x": "f_Tx", "columns": ["f_Ty"], "reference_x": "f_Tx"})j")),
            "/rubric/tests/1/plot/reference_x: expected a \"reference\""));
  CHECK(has(bad(json::parse(R"j({"columns": ["f_Ty"], "reference_x": "f_Tx"})j")),
            "/rubric/tests/1/plot/reference_x: expected \"x\" too"));
  CHECK(has(bad(json::parse(R"j({"columns": ["f_Ty"], "xlabel": "f"})j")), "/rubric/tests/1/plot/xlabel: expected \"x\" too"));
  CHECK(has(bad(json::parse(R"j({"x": 3, "columns": ["f_Ty"]})j")), "/rubric/tests/1/plot/x: expected a string"));
  CHECK(has(bad(json::parse(R"j({"x": "f_Tz", "columns": ["f_Ty"]})j")),
            "cfg.json: /rubric/tests/1/plot/x: expected a trace column of this lab"));
  CHECK(has(bad(json::parse(R"j({"x": "f_Tx", "columns": ["f_Ty"], "reference": "f_des", "reference_x": "nope"})j")),
            "/rubric/tests/1/plot/reference_x: expected a trace column of this lab"));
}

TEST_CASE("planning a test's x–y plot: labels with units, equal scales for one unit, no window") {
  json c = defaultConfig();
  const auto plan = [&](std::size_t i) {
    return planTestPlot(parseRubric(JsonView(c, "cfg.json")), i, parseMetricDocs(JsonView(c, "cfg.json")), sliderCrank());
  };
  c["rubric"]["tests"][1]["plot"] = json::parse(R"j({"x": "f_Tx", "columns": ["f_Ty"], "reference": "f_des"})j");
  TestPlotPlan p = plan(1);
  CHECK(p.request.xlabel == "f_Tx (N)");
  CHECK(p.request.ylabel == "f_Ty, f_des (N)");
  CHECK(p.equal_aspect);
  c["rubric"]["tests"][1]["plot"] = json::parse(R"j({"x": "x_c", "columns": ["v_c"], "ylabel": "speed"})j");
  p = plan(1);
  CHECK(p.request.xlabel == "x_c (m)");
  CHECK(p.request.ylabel == "speed");
  CHECK_FALSE(p.equal_aspect);  // m/s against m
  CHECK_FALSE(plan(0).equal_aspect);  // a plot against t
}
