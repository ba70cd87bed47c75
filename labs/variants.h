// A plant per student: a lab's "variants" name plant parameters (a mass, a length, the table's
// height, a delay) that each student draws from a stated range, so copying a classmate's gains
// grades them on a plant they were not tuned for.
//   "variants": [{"name": "payload at the pin", "path": "/plant/payloads/0/mass",
//                 "min": 0, "max": 0.05, "step": 0.005, "unit": "kg", "doc": "..."}]
// Parameter i takes one of the n_i + 1 values of its range's grid:
//   value_i = min_i + step_i · k_i,   n_i = (max_i − min_i) / step_i,
//   k_i = splitmix64(FNV-1a("variant/" key "/" lab "/" path_i)) mod (n_i + 1)
// where key is the student's key (16 hex digits: grading/student.h derives it from the course secret
// and the student's ID, so no student can compute another's plant). The nominal plant (no student)
// is the config as written; its values lie in the ranges. A rubric scenario's patch is applied after
// the variant: where both set a value, the scenario's wins.
#pragma once
#include <string>
#include <vector>

#include "labs/config.h"

namespace dyn {

struct VariantParameter {
  std::string name, path, unit, doc;
  double min = 0, max = 0, step = 0;
  long steps() const;  // n: the grid has n + 1 values
};

// Which plant a run is on: the nominal one, a student's (drawn from their key) or a corner of the
// ranges (every parameter at its min or its max: check-lab's samples).
struct PlantChoice {
  enum class Corner { None, Min, Max };
  std::string student;  // the student's ID, as shown ("" and no corner: the nominal plant)
  std::string key;      // 16 hex digits: the draw's seed
  Corner corner = Corner::None;
  bool nominal() const { return student.empty() && corner == Corner::None; }
  std::string label() const;  // "student alice", "every parameter at its min", "the nominal plant"
};

struct PlantValue {
  VariantParameter parameter;
  double value = 0;
};

inline constexpr std::size_t kMaxVariantParameters = 16;
inline constexpr long kMaxVariantSteps = 1000000;

// The config's "variants" (none: empty). Each path must point at a number of the config outside
// "variants", "rubric", "gains" and the submission options' targets, (max − min)/step a whole number
// ≤ kMaxVariantSteps, and (nominal_in_range: the lab's config as written, not one a scenario patched)
// the config's value within [min, max]. Throws InputError naming the path.
std::vector<VariantParameter> parseVariants(const JsonView& config, bool nominal_in_range = true);

// The values `choice` gives each parameter (the config's own for the nominal plant).
std::vector<PlantValue> drawPlant(const JsonView& config, const PlantChoice& choice, const std::string& lab);

// The config with `choice`'s values written at their paths (the nominal plant, or a lab without
// variants: unchanged, one plant for every student).
json plantConfig(const json& config, const PlantChoice& choice, const std::string& lab, const std::string& file);

// "payload at the pin 0.035 kg, delay 2 steps": each value with the fewest digits that read back exactly.
std::string plantText(const std::vector<PlantValue>& values);

// Whether the lab config in `file` declares variants (one it cannot read: no; its own load says why).
bool declaresVariants(const std::string& file);

// Whether a key is 16 hex digits (lowercase).
bool isPlantKey(const std::string& key);

}  // namespace dyn
