// A plant per student; see variants.h.
#include "labs/variants.h"

#include <cmath>
#include <cstdint>

#include "labs/numbers.h"
#include "labs/trace.h"

namespace dyn {

namespace {

// A 64-bit mix of the FNV-1a hash (Steele, Lea and Flood's splitmix64 finaliser): FNV alone spreads
// the last bytes of a name poorly over the low bits a modulus reads.
std::uint64_t mixed(const std::string& text) {
  std::uint64_t z = fnv1a(text.data(), text.size()) + 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

// Where a parameter may not point: what the student writes, the grading and the variants themselves.
bool forbiddenPath(const std::string& path, const JsonView& config) {
  for (const char* top : {"/variants", "/rubric", "/gains", "/submission_options", "/lab"})
    if (path == top || path.rfind(std::string(top) + "/", 0) == 0) return true;
  if (config.has("submission_options") && config["submission_options"].raw().is_object())
    for (const auto& [_, o] : config["submission_options"].raw().items())
      if (o.is_object() && o.contains("target") && o["target"] == path) return true;
  return false;
}

VariantParameter parseParameter(const JsonView& p, const JsonView& config, bool nominal_in_range) {
  p.onlyKeys({"name", "path", "min", "max", "step", "unit", "doc"});
  VariantParameter v;
  v.name = p["name"].string();
  if (v.name.empty() || v.name.size() > 80) p["name"].fail("expected a name of 1–80 bytes");
  v.path = p["path"].string();
  const json* at = nullptr;
  try {
    const json::json_pointer ptr(v.path);
    if (!v.path.empty() && config.raw().contains(ptr)) at = &config.raw().at(ptr);
  } catch (const json::exception&) {
  }
  if (!at || !at->is_number() || forbiddenPath(v.path, config))
    p["path"].fail("expected a JSON pointer to a number of the lab's plant, such as \"/plant/payloads/0/mass\" (not in "
                   "gains, rubric, variants or a submission option), got \"" + v.path + "\"");
  v.min = p["min"].number();
  v.max = p["max"].number();
  if (!(v.max > v.min)) p["max"].fail("expected a number above min (" + exactNumber(v.min) + ")");
  v.step = p["step"].positive();
  const double n = (v.max - v.min) / v.step;
  if (!(n <= double(kMaxVariantSteps)) || std::abs(n - std::round(n)) > 1e-6 * std::max(1.0, n))
    p["step"].fail("expected a step that divides max − min into at most " + std::to_string(kMaxVariantSteps) +
                   " whole steps, got " + exactNumber(v.step) + " for " + exactNumber(v.max - v.min));
  if (at->is_number_integer() || at->is_number_unsigned())
    for (const char* key : {"min", "max", "step"})
      if (const double x = p[key].number(); x != std::round(x))
        p[key].fail("expected a whole number (" + v.path + " is one), got " + exactNumber(x));
  const double nominal = at->get<double>();
  if (nominal_in_range && (nominal < v.min || nominal > v.max))
    p["min"].fail("expected a range holding the nominal plant's value " + exactNumber(nominal) + " at " + v.path);
  if (p.has("unit")) v.unit = p["unit"].string();
  if (p.has("doc")) v.doc = p["doc"].string();
  return v;
}

// min + step·k, read back through 12 significant digits so 0.1 + 2·0.05 is 0.2, as a person writes it.
double gridValue(const VariantParameter& v, long k) {
  if (k >= v.steps()) return v.max;
  return std::stod(fmt("%.12g", v.min + v.step * double(k)));
}

}  // namespace

long VariantParameter::steps() const { return std::lround((max - min) / step); }

std::string PlantChoice::label() const {
  if (corner == Corner::Min) return "every varied parameter at its minimum";
  if (corner == Corner::Max) return "every varied parameter at its maximum";
  return student.empty() ? "the nominal plant" : "student " + student;
}

std::string plantText(const std::vector<PlantValue>& values) {
  std::string s;
  for (const PlantValue& v : values)
    s += (s.empty() ? "" : ", ") + v.parameter.name + " " + exactNumber(v.value) +
         (v.parameter.unit.empty() ? "" : " " + v.parameter.unit);
  return s;
}

bool declaresVariants(const std::string& file) {
  try {
    const json c = loadJsonFile(file);
    return !parseVariants(JsonView(c, file)).empty();
  } catch (const InputError&) {
    return false;
  }
}

bool isPlantKey(const std::string& key) {
  if (key.size() != 16) return false;
  for (char c : key)
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  return true;
}

std::vector<VariantParameter> parseVariants(const JsonView& config, bool nominal_in_range) {
  std::vector<VariantParameter> out;
  if (!config.has("variants")) return out;
  const JsonView list = config["variants"];
  const std::size_t n = list.size(1, kMaxVariantParameters);
  for (std::size_t i = 0; i < n; ++i) {
    out.push_back(parseParameter(list.at(i), config, nominal_in_range));
    for (std::size_t j = 0; j < i; ++j)
      if (out[j].path == out[i].path) list.at(i)["path"].fail("expected each path once, got \"" + out[i].path + "\" again");
  }
  return out;
}

std::vector<PlantValue> drawPlant(const JsonView& config, const PlantChoice& choice, const std::string& lab) {
  std::vector<PlantValue> out;
  for (const VariantParameter& p : parseVariants(config)) {
    double value = config.raw().at(json::json_pointer(p.path)).get<double>();
    if (choice.corner == PlantChoice::Corner::Min) value = p.min;
    if (choice.corner == PlantChoice::Corner::Max) value = p.max;
    if (choice.corner == PlantChoice::Corner::None && !choice.student.empty()) {
      const std::uint64_t u = mixed("variant/" + choice.key + "/" + lab + "/" + p.path);
      value = gridValue(p, long(u % std::uint64_t(p.steps() + 1)));
    }
    out.push_back({p, value});
  }
  return out;
}

json plantConfig(const json& config, const PlantChoice& choice, const std::string& lab, const std::string& file) {
  const JsonView view(config, file);
  const std::vector<PlantValue> values = drawPlant(view, choice, lab);  // parses (and checks) the variants
  if (choice.nominal() || values.empty()) return config;  // a lab without variants: one plant for all
  json out = config;
  for (const PlantValue& v : values) {
    json& at = out.at(json::json_pointer(v.parameter.path));
    // A whole-number parameter (a delay in steps) stays an integer, as the lab reads it.
    at = at.is_number_integer() || at.is_number_unsigned() ? json(std::llround(v.value)) : json(v.value);
  }
  return out;
}

}  // namespace dyn
