// A plant per student (labs/variants.h): the "variants" block refused where it could change what a
// student writes or what is graded, each draw on its range's grid and the same for the same key, the
// keys spread over the whole grid, the nominal plant untouched, corners at the ends, a whole-number
// parameter kept whole, and the five-bar's own variants built into labs that run.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <set>

#include "labs/lab.h"
#include "labs/numbers.h"
#include "labs/run.h"
#include "labs/variants.h"

using namespace dyn;

namespace {

json fivebar() { return loadJsonFile(defaultConfigPath("fivebar")); }

json withVariants(json config, const json& variants) {
  config["variants"] = variants;
  return config;
}

// The message parseVariants refuses `variants` with (empty: accepted).
std::string refusal(const json& variants) {
  const json c = withVariants(fivebar(), variants);
  try {
    parseVariants(JsonView(c, "lab.json"));
  } catch (const InputError& e) {
    return e.what();
  }
  return {};
}

json parameter(const std::string& path, double min, double max, double step) {
  return {{"name", "p"}, {"path", path}, {"min", min}, {"max", max}, {"step", step}};
}

std::string key(int i) {
  char b[17];
  std::snprintf(b, sizeof b, "%016x", 0x9e3779b9u * unsigned(i + 1));
  return b;
}

}  // namespace

TEST_CASE("variants may not touch what a student writes or what is graded") {
  CHECK(refusal(json::array({parameter("/plant/payloads/0/mass", 0, 0.05, 0.005)})).empty());
  for (const std::string path : {"/gains/kp/value", "/rubric/tests/0/full", "/variants/0/min", "/controller/kind",
                                 "/plant/payloads/9/mass", "/plant/payloads/0/body", "plant", ""}) {
    const std::string why = refusal(json::array({parameter(path, 0, 1, 0.5)}));
    CAPTURE(path);
    CHECK(why.find("lab.json: /variants/0/path: expected a JSON pointer to a number of the lab's plant") == 0);
  }
  // The nominal plant lies in its range; the step divides it; a whole-number value stays whole.
  CHECK(refusal(json::array({parameter("/plant/payloads/0/mass", 0.01, 0.05, 0.01)})).find("/variants/0/min: expected a range holding the nominal plant's value 0") != std::string::npos);
  CHECK(refusal(json::array({parameter("/plant/payloads/0/mass", 0, 0.05, 0.03)})).find("/variants/0/step: expected a step that divides") != std::string::npos);
  CHECK(refusal(json::array({parameter("/controller/delay_steps", 0, 2, 0.5)})).find("/variants/0/step: expected a whole number") != std::string::npos);
  CHECK(refusal(json::array({parameter("/plant/payloads/0/mass", 0, 0, 0.01)})).find("/variants/0/max: expected a number above min") != std::string::npos);
  CHECK(refusal(json::array({parameter("/plant/payloads/0/mass", 0, 1e9, 1e-3)})).find("/variants/0/step") != std::string::npos);
  // Each path once, at most 16 parameters, no unknown key.
  const json p = parameter("/plant/payloads/0/mass", 0, 0.05, 0.005);
  CHECK(refusal(json::array({p, p})).find("/variants/1/path: expected each path once") != std::string::npos);
  CHECK(refusal(json(std::vector<json>(17, p))).find("/variants") != std::string::npos);
  json typo = p;
  typo["stepp"] = 1;
  CHECK(refusal(json::array({typo})).find("stepp") != std::string::npos);
  // And buildLab holds every lab to it.
  const json bad = withVariants(fivebar(), json::array({parameter("/gains/kp/value", 0, 1e5, 1)}));
  CHECK_THROWS_AS(buildLab(*findLab("fivebar"), bad, "lab.json"), InputError);
}

TEST_CASE("a student's plant: on the grid, the same for the same key, spread over every value by the keys") {
  const json c = withVariants(fivebar(), json::array({parameter("/plant/payloads/0/mass", 0, 0.05, 0.005),
                                                      parameter("/controller/delay_steps", 0, 2, 1)}));
  const JsonView view(c, "lab.json");
  std::set<double> masses, delays;
  for (int i = 0; i < 300; ++i) {
    const PlantChoice who{"s" + std::to_string(i), key(i)};
    const auto a = drawPlant(view, who, "fivebar"), b = drawPlant(view, who, "fivebar");
    REQUIRE(a.size() == 2);
    CHECK(a[0].value == b[0].value);
    CHECK(a[1].value == b[1].value);
    // On the grid: min + k·step, written as a person writes it.
    const double k = a[0].value / 0.005;
    CHECK(std::abs(k - std::round(k)) < 1e-9);
    CHECK(a[0].value == std::stod(exactNumber(a[0].value)));
    masses.insert(a[0].value);
    delays.insert(a[1].value);
  }
  CHECK(masses.size() == 11);  // every one of 0, 0.005, ..., 0.05
  CHECK(*masses.begin() == 0.0);
  CHECK(*masses.rbegin() == 0.05);
  CHECK(delays == std::set<double>{0, 1, 2});
  // Another lab with the same key draws its own plant (the lab's name is in the hash).
  int same = 0;
  for (int i = 0; i < 40; ++i) {
    const PlantChoice who{"s", key(i)};
    same += drawPlant(view, who, "fivebar")[0].value == drawPlant(view, who, "fivebar_copy")[0].value;
  }
  CHECK(same < 20);
}

TEST_CASE("the config on a plant: nominal unchanged, corners at the ends, whole numbers kept whole") {
  const json c = withVariants(fivebar(), json::array({parameter("/plant/payloads/0/mass", 0, 0.05, 0.005),
                                                      parameter("/controller/delay_steps", 0, 2, 1)}));
  CHECK(plantConfig(c, PlantChoice{}, "fivebar", "lab.json") == c);
  const json lo = plantConfig(c, {"", "", PlantChoice::Corner::Min}, "fivebar", "lab.json");
  const json hi = plantConfig(c, {"", "", PlantChoice::Corner::Max}, "fivebar", "lab.json");
  CHECK(lo["plant"]["payloads"][0]["mass"] == 0.0);
  CHECK(hi["plant"]["payloads"][0]["mass"] == 0.05);
  CHECK(hi["controller"]["delay_steps"].is_number_integer());
  CHECK(hi["controller"]["delay_steps"] == 2);
  // Only the varied values change.
  json back = hi;
  back["plant"]["payloads"][0]["mass"] = 0.0;
  back["controller"]["delay_steps"] = 0;
  CHECK(back == c);
  // A lab without variants: one plant for every student.
  json plain = fivebar();
  plain.erase("variants");
  CHECK(plantConfig(plain, {"alice", key(1)}, "fivebar", "lab.json") == plain);
  CHECK(plantText(drawPlant(JsonView(c, "lab.json"), {"", "", PlantChoice::Corner::Max}, "fivebar")) == "p 0.05, p 2");
}

TEST_CASE("the five-bar's variants: every corner and drawn plant builds a lab that runs") {
  const LabEntry& entry = *findLab("fivebar");
  const json c = fivebar();
  REQUIRE(!parseVariants(JsonView(c, "fivebar.json")).empty());
  std::vector<PlantChoice> plants = {{"", "", PlantChoice::Corner::Min}, {"", "", PlantChoice::Corner::Max}};
  for (int i = 0; i < 4; ++i) plants.push_back({"s" + std::to_string(i), key(i)});
  for (const PlantChoice& p : plants) {
    json cfg = plantConfig(c, p, "fivebar", "fivebar.json");
    setRunDuration(cfg, 0.05);
    const auto lab = buildLab(entry, cfg, "fivebar.json");
    const RunResult r = runEngine(*lab, Engine::Hand);
    CAPTURE(p.label());
    CHECK(r.failure.empty());
    CHECK(r.trace.rows() > 10);
  }
}
