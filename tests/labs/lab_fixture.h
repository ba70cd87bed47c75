// What each lab's own test (tests/labs/<lab>_test.cpp) needs to reach the lab through the registry,
// for one lab by name: its default config with a patch merged in (RFC 7386), the lab built from it,
// a whole run that must not fail, and the one line (JSON path: what was expected) a bad input gets.
// Kept apart from lab_checks.h, the contract every lab keeps, which pulls in grading, render and the
// CLI: a lab's physics test needs none of those.
//
//   const dyn::test::LabFixture fixture("grasp");
//   const auto lab = fixture.makeLab({{"simulation", {{"duration", 1.0}}}});
//   CHECK(fixture.inputError({{"mechanism", {{"mu", -1}}}}).find("/mechanism/mu") == 0);
#pragma once
#include <doctest/doctest.h>

#include <cmath>
#include <memory>
#include <string>
#include <utility>

#include "labs/config.h"
#include "labs/lab.h"
#include "labs/run.h"

namespace dyn::test {

class LabFixture {
 public:
  explicit LabFixture(std::string lab) : name(std::move(lab)), file(name + ".json (test)") {}

  const std::string name;  // the lab's registered name
  const std::string file;  // the file name a bad input's message gives the config

  // labs/<name>/<name>.json as shipped.
  json defaults() const { return loadJsonFile(defaultConfigPath(name)); }

  // The default config with `patch` merged in.
  json config(const json& patch) const { return mergePatch(defaults(), patch); }

  // The lab built from config(patch) through the registry (throws InputError on a bad input).
  std::unique_ptr<Lab> makeLab(const json& patch = json::object()) const {
    const LabEntry* entry = findLab(name);
    REQUIRE(entry != nullptr);
    return buildLab(*entry, config(patch), file);
  }

  // "<JSON path>: <what was expected>" for a patch the lab refuses, "accepted" otherwise.
  std::string inputError(const json& patch) const {
    try {
      makeLab(patch);
    } catch (const InputError& e) {
      return e.path() + ": " + e.expected();
    }
    return "accepted";
  }

  // The whole run on one engine: no failure, and one row a step of the lab's duration and one at its end
  // (t = 0, dt, …, duration).
  static Trace run(const Lab& lab, Engine engine) {
    RunResult r = runEngine(lab, engine);
    REQUIRE_MESSAGE(r.failure.empty(), r.failure);
    const long steps = std::lround(lab.duration() / lab.dt());
    REQUIRE(r.trace.rows() == std::size_t(steps + 1));
    REQUIRE(r.trace.at(0, "t") == 0.0);
    REQUIRE(std::abs(r.trace.at(r.trace.rows() - 1, "t") - double(steps) * lab.dt()) <= 1e-12 * lab.duration());
    return std::move(r.trace);
  }
};

}  // namespace dyn::test
