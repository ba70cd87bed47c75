// SettingsLab<S>: what every lab's class wrote alike, written once. A lab built from its Settings S
// (S has .step.dt, the run's step, and .duration, its length) keeps them here, and states once, in its
// constructor, the tables the interface reads back:
//   columns_          the trace's columns, in order
//   units_            column → SI unit ("rad", "N·m"; absent: none or dimensionless)
//   agreement_units_  key of agreement() → unit
//   passive_          the passive energy check (Lab::PassiveEnergy: tolerance, window, conservative patch)
// agreement() is shared too: the rows compared and each engine's health around the lab's differences();
// and referenceEngine(): what the Bullet run of simulate() says it built.
// The lab's own class then holds only its own parts: the run (simulate), the grade
// (metrics, differences, linearise), the picture (scene, overlay), and unit() where a rule says more
// than a table (a column per finger or joint).
#pragma once
#include <algorithm>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "labs/lab.h"

namespace dyn {

template <class S>
class SettingsLab : public Lab {
 public:
  std::vector<std::string> columns() const override { return columns_; }
  std::string unit(const std::string& column) const override { return unitIn(units_, column); }
  double dt() const override { return s_.step.dt; }
  double duration() const override { return s_.duration; }
  // Where the engines disagree: the rows compared, the lab's own differences(), and how well each engine
  // kept its own books (lab.h engineHealth).
  json agreement(const Trace& hand, const Trace& bullet) const final {
    const std::size_t rows = std::min(hand.rows(), bullet.rows());
    json out = differences(hand, bullet, rows);
    out["rows_compared"] = rows;
    out.update(engineHealth(metrics(hand), metrics(bullet)));
    return out;
  }
  std::string agreementUnit(const std::string& key) const override { return unitIn(agreement_units_, key); }
  PassiveEnergy passiveEnergy() const override { return passive_; }
  // The Bullet run's own description: the same mechanism, from the same start, as simulate() builds it.
  std::string referenceEngine() const override {
    const std::string built = simulate(Engine::Bullet)->describeEngine();
    return built.empty() ? Lab::referenceEngine() : built;
  }
  const S& settings() const { return s_; }

 protected:
  explicit SettingsLab(S s) : s_(std::move(s)) {}
  // The lab's measures of disagreement over the first `rows` rows of both traces: {key: number}, each
  // key's unit in agreement_units_.
  virtual json differences(const Trace& hand, const Trace& bullet, std::size_t rows) const = 0;

  S s_;
  std::vector<std::string> columns_;
  std::map<std::string, std::string> units_, agreement_units_;
  PassiveEnergy passive_;
};

// The factory DYNLAB_REGISTER_LAB takes, for a lab class L built from what `parse` reads from the config:
//   DYNLAB_REGISTER_LAB(grasp, "...", labFactory<GraspLab>(parseSettings));
template <class L, class Parse>
LabFactory labFactory(Parse parse) {
  return [parse](const JsonView& config) -> std::unique_ptr<Lab> { return std::make_unique<L>(parse(config)); };
}

}  // namespace dyn
