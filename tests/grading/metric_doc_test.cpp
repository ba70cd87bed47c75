// A data-defined metric's window is written from its spec, never typed (issue 41, item 5): for every
// registered lab, each documented metric that "metrics" defines carries the spec's from/to (the
// feedback plots hatch outside them) and says them in words; a window typed beside the spec is
// refused at its JSON path, naming the window the grader uses. The five-bar's circle window, once
// typed "0.7–2.7 s" against the rubric's 0.7–2.2 s, reads as the rubric does.
#include <doctest/doctest.h>

#include <cmath>

#include "grading/metric_doc.h"
#include "labs/lab.h"

using namespace dyn;

TEST_CASE("every data-defined metric's documented window is its spec's") {
  int checked = 0;
  for (const LabEntry& e : labRegistry()) {
    const std::string file = defaultConfigPath(e.name);
    const json c = loadJsonFile(file);
    if (!c.contains("metrics") || !c.contains("metric_docs")) continue;
    const auto docs = parseMetricDocs(JsonView(c, file));
    for (const auto& [name, spec] : c["metrics"].items()) {
      if (!spec.is_object() || !spec.contains("of") || !docs.count(name)) continue;
      CAPTURE(e.name);
      CAPTURE(name);
      const MetricDoc& d = docs.at(name);
      CHECK(d.from == (spec.contains("from") ? spec["from"].get<double>() : -INFINITY));
      CHECK(d.to == (spec.contains("to") ? spec["to"].get<double>() : INFINITY));
      if (spec.contains("to")) CHECK(d.window.find(fmtConfigNumber(spec["to"].get<double>()) + " s") != std::string::npos);
      if (spec.contains("from") && spec["stat"] != "final")
        CHECK(d.window.find(fmtConfigNumber(spec["from"].get<double>())) != std::string::npos);
      if (!spec.contains("from") && !spec.contains("to"))
        CHECK((d.window == "the whole run" || d.window == "the last step"));
      ++checked;
    }
  }
  CHECK(checked >= 20);  // the five-bar's and both PUMA labs' metrics
}

TEST_CASE("the five-bar's circle window reads as the rubric's, and a typed one is refused") {
  const std::string file = defaultConfigPath("fivebar");
  json c = loadJsonFile(file);
  const auto docs = parseMetricDocs(JsonView(c, file));
  CHECK(docs.at("e_circle_rms").window == "0.7–2.2 s");
  CHECK(docs.at("e_circle_rms").from == 0.7);
  CHECK(docs.at("e_circle_rms").to == 2.2);
  c["metric_docs"]["e_circle_rms"]["window"] = "0.7–2.7 s";
  try {
    parseMetricDocs(JsonView(c, file));
    FAIL("a typed window was accepted");
  } catch (const InputError& e) {
    CHECK(std::string(e.what()) == file + ": /metric_docs/e_circle_rms/window: expected no \"window\": dynlab writes the "
                                          "window of /metrics/e_circle_rms from its spec (0.7–2.2 s)");
  }
}
