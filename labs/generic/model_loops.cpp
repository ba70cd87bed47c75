// Loop closures beside a model file: see model_loops.h.
#include "labs/generic/model_loops.h"

#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "labs/generic/model_description.h"

namespace dyn::app {
namespace {

using model_file::ModelFileError;
using nlohmann::json;

constexpr std::size_t kMaxLoopsBytes = 1u << 20;  // a loops file is a few lines
constexpr int kMaxDepth = 8;                      // {"loops": [{"point1": [x]}]} is 4 deep
constexpr std::size_t kMaxLoops = 64;

// A value as its error shows it: JSON text, cut short.
std::string shown(const json& v) {
  std::string s = v.dump(-1, ' ', true, json::error_handler_t::replace);
  return s.size() > 40 ? s.substr(0, 37) + "..." : s;
}

std::string text(const json& v, const std::string& at, const std::string& file) {
  if (!v.is_string()) throw ModelFileError(file + ": " + at + ": expected a string, got " + shown(v));
  const std::string s = v.get<std::string>();
  if (s.empty() || s.size() > 200) throw ModelFileError(file + ": " + at + ": expected a name of 1 to 200 characters, got " + shown(v));
  return s;
}

Eigen::Vector3d point(const json& v, const std::string& at, const std::string& file) {
  if (!v.is_array() || v.size() != 3) throw ModelFileError(file + ": " + at + ": expected [x, y, z] in metres, got " + shown(v));
  Eigen::Vector3d p;
  for (int i = 0; i < 3; ++i) {
    const json& x = v[std::size_t(i)];
    if (!x.is_number() || !std::isfinite(x.get<double>()) || std::abs(x.get<double>()) > 1e6)
      throw ModelFileError(file + ": " + at + "[" + std::to_string(i) + "]: expected a finite number of metres within ±1e6, got " + shown(x));
    p[i] = x.get<double>();
  }
  return p;
}

// A number at `at` within [lo, hi] (what: its unit and meaning, for the error).
double number(const json& v, const std::string& at, const std::string& file, double lo, double hi, const std::string& what) {
  if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() < lo || v.get<double>() > hi)
    throw ModelFileError(file + ": " + at + ": expected " + what + ", got " + shown(v));
  return v.get<double>();
}

// A direction: [x, y, z], finite, not zero.
Eigen::Vector3d direction(const json& v, const std::string& at, const std::string& file) {
  if (!v.is_array() || v.size() != 3) throw ModelFileError(file + ": " + at + ": expected a direction [x, y, z], got " + shown(v));
  Eigen::Vector3d d;
  for (int i = 0; i < 3; ++i)
    d[i] = number(v[std::size_t(i)], at + "[" + std::to_string(i) + "]", file, -1e6, 1e6, "a finite number within ±1e6");
  if (!(d.norm() > 1e-12)) throw ModelFileError(file + ": " + at + ": expected a non-zero direction, got " + shown(v));
  return d;
}

// An array of element objects under `key`: each an object with only `keys`, with every key of
// `required`. Returns the elements' JSON paths ("rolling[0]").
std::vector<std::string> elements(const json& j, const char* key, const char* noun, const std::string& file, const std::set<std::string>& keys,
                                  const std::vector<const char*>& required, const std::string& hint) {
  std::vector<std::string> at;
  if (!j.contains(key)) return at;
  const json& list = j[key];
  if (!list.is_array() || list.empty() || list.size() > kMaxLoops)
    throw ModelFileError(file + ": " + key + ": expected an array of 1 to " + std::to_string(kMaxLoops) + " " + noun + ", got " + shown(list));
  std::string expected;
  for (const auto& k : keys) expected += (expected.empty() ? "" : ", ") + k;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string here = std::string(key) + "[" + std::to_string(i) + "]";
    const json& e = list[i];
    if (!e.is_object()) throw ModelFileError(file + ": " + here + ": expected an object {" + expected + "}, got " + shown(e));
    for (const auto& [k, value] : e.items())
      if (!keys.count(k)) throw ModelFileError(file + ": " + here + "." + k + ": unknown key (expected " + expected + ")" + hint);
    for (const char* k : required)
      if (!e.contains(k)) throw ModelFileError(file + ": " + here + "." + k + ": missing");
    at.push_back(here);
  }
  return at;
}

}  // namespace

void readBeside(const std::string& file, model_file::LoadOptions& options) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) throw ModelFileError(file + ": no such file (expected a loops JSON file)");
  if (fs::file_size(file, ec) > kMaxLoopsBytes)
    throw ModelFileError(file + ": more than " + std::to_string(kMaxLoopsBytes) + " bytes; a loops file names a few closures");
  std::ifstream in(file, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  json j;
  try {
    // Nesting beyond any loops file's is refused while parsing (no deep recursion on hostile input).
    j = json::parse(bytes.str(), [&](int depth, json::parse_event_t, json&) {
      if (depth > kMaxDepth) throw ModelFileError(file + ": nested deeper than " + std::to_string(kMaxDepth) + " levels (expected {\"loops\": [...]})");
      return true;
    });
  } catch (const json::exception& e) {
    throw ModelFileError(file + ": not JSON (" + std::string(e.what()) + ")");
  }
  if (!j.is_object() || !(j.contains("loops") || j.contains("rolling") || j.contains("contacts")))
    throw ModelFileError(file + ": expected an object {\"loops\": [...]} (or \"rolling\", \"contacts\": at least one of the three), got " + shown(j));
  for (const auto& [key, value] : j.items())
    if (key != "loops" && key != "rolling" && key != "contacts" && key != "comment")
      throw ModelFileError(file + ": " + key + ": unknown key (expected \"loops\", \"rolling\", \"contacts\", \"comment\")");
  // Names head the trace's columns: one per closure, wheel and contact (the loader checks the file's own).
  std::map<std::string, std::string> names;  // name → what it names
  auto name = [&](const json& e, const std::string& at, const std::string& fallback, const char* what) {
    const std::string n = e.contains("name") ? text(e["name"], at + ".name", file) : fallback;
    if (const auto [it, fresh] = names.emplace(n, what); !fresh)
      throw ModelFileError(file + ": " + at + ".name: '" + n + "' names an earlier " + it->second + " too (expected a new name: it heads trace columns)");
    return n;
  };
  // Each element of the array `key` (elements() has checked its keys) into `out`: its where and its
  // name first (the default PREFIX + index), then read(path, object, element) fills in the rest.
  auto readEach = [&]<class T>(const std::vector<std::string>& paths, const char* key, const std::string& prefix, const char* what,
                               std::vector<T>& out, auto&& read) {
    for (std::size_t i = 0; i < paths.size(); ++i) {
      T element;
      element.where = file + ": " + paths[i];
      element.name = name(j[key][i], paths[i], prefix + std::to_string(i), what);
      read(paths[i], j[key][i], element);
      out.push_back(element);
    }
  };
  const std::vector<std::string> loops =
      elements(j, "loops", "closures", file, {"name", "kind", "body1", "point1", "body2", "point2", "comment"}, {"kind", "body1", "point1", "body2"}, "");
  readEach(loops, "loops", "loop", "closure", options.closures, [&](const std::string& at, const json& l, model_file::GivenClosure& c) {
    c.kind = text(l["kind"], at + ".kind", file);
    if (c.kind != "connect" && c.kind != "weld")
      throw ModelFileError(file + ": " + at + ".kind: expected \"connect\" (3 translation rows) or \"weld\" (6 rows), got " + shown(l["kind"]));
    c.body1 = text(l["body1"], at + ".body1", file);
    c.body2 = text(l["body2"], at + ".body2", file);
    c.point1 = point(l["point1"], at + ".point1", file);
    if (l.contains("point2")) c.has_point2 = true, c.point2 = point(l["point2"], at + ".point2", file);
  });
  // A rolling wheel: the rolling kind rolls without slip on a horizontal ground z = height.
  const std::vector<std::string> wheels = elements(j, "rolling", "wheels", file, {"name", "body", "centre", "axle", "radius", "height", "mu", "comment"},
                                                   {"body", "axle", "radius"}, " (the ground is the plane z = height, the wheel never slips)");
  readEach(wheels, "rolling", "wheel", "wheel", options.rolling, [&](const std::string& at, const json& w, model_file::GivenRolling& r) {
    r.body = text(w["body"], at + ".body", file);
    if (w.contains("centre")) r.centre = point(w["centre"], at + ".centre", file);
    r.axle = direction(w["axle"], at + ".axle", file);
    r.radius = number(w["radius"], at + ".radius", file, 1e-6, 1e3, "the wheel's radius in metres, in [1e-6, 1e3]");
    if (w.contains("height")) r.height = number(w["height"], at + ".height", file, -1e6, 1e6, "the ground's height z in metres, within ±1e6");
    if (w.contains("mu")) r.mu = number(w["mu"], at + ".mu", file, 0, 10, "a friction coefficient in [0, 10]");
  });
  // A ball against a plane: one unilateral row; the hand engine's rigid contact is plastic and frictionless.
  const std::vector<std::string> contacts = elements(
      j, "contacts", "contacts", file, {"name", "body", "point", "radius", "normal", "height", "mu", "stiffness", "damping", "comment"}, {"body", "point"},
      " (a rigid contact's touchdown is plastic: no restitution; mu is Coulomb friction in Bullet only)");
  readEach(contacts, "contacts", "contact", "contact", options.contacts, [&](const std::string& at, const json& e, model_file::GivenContact& c) {
    c.body = text(e["body"], at + ".body", file);
    c.point = point(e["point"], at + ".point", file);
    if (e.contains("radius")) c.radius = number(e["radius"], at + ".radius", file, 0, 1e3, "the ball's radius in metres, in [0, 1e3]");
    if (e.contains("normal")) c.normal = direction(e["normal"], at + ".normal", file);
    if (e.contains("height")) c.height = number(e["height"], at + ".height", file, -1e6, 1e6, "the plane's offset n·x = height in metres, within ±1e6");
    if (e.contains("mu")) c.mu = number(e["mu"], at + ".mu", file, 0, 10, "a friction coefficient in [0, 10] (Bullet's contact only)");
    if (e.contains("stiffness")) c.stiffness = number(e["stiffness"], at + ".stiffness", file, 0, 1e9, "a stiffness in N/m in [0, 1e9] (0: rigid)");
    if (e.contains("damping"))
      c.damping = number(e["damping"], at + ".damping", file, 0, 1e9, "a damping in N·s/m in [0, 1e9]");
    if (c.damping > 0 && c.stiffness == 0)
      throw ModelFileError(file + ": " + at + ".damping: expected 0 for a rigid contact (damping acts on a compliant one, stiffness > 0)");
  });
}

std::string loopsBeside(const std::string& model) {
  // Beside a URDF only: an MJCF file writes its loops as equalities (and fourbar.xml must not pick up
  // fourbar.urdf's loops).
  std::filesystem::path p(model);
  std::string ext = p.extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".urdf" && ext != ".xml") return "";
  std::error_code ec;
  // An MJCF file's STEM.loops.json is a URDF's of the same stem when one stands beside it.
  if (ext == ".xml") {
    for (const char* urdf : {".urdf", ".URDF"})
      if (std::filesystem::exists(std::filesystem::path(p).replace_extension(urdf), ec)) return "";
  }
  p.replace_extension(".loops.json");
  return std::filesystem::exists(p, ec) ? p.string() : "";
}

model_file::LoadedModel loadWithLoops(const std::string& model, const std::string& loops, model_file::LoadOptions options) {
  const std::string given = loops.empty() ? loopsBeside(model) : loops;
  if (!given.empty()) readBeside(given, options);
  model_file::LoadedModel m = loadModelOrDescription(model, options);
  if (!given.empty())
    m.notes.push_back((options.rolling.empty() && options.contacts.empty() ? "loop closures from " : "closures, rolling wheels and contacts from ") + given);
  return m;
}

}  // namespace dyn::app
