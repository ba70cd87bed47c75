// Loop closures beside a model file: see model_loops.h.
#include "app/model_loops.h"

#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

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

}  // namespace

std::vector<model_file::GivenClosure> readLoops(const std::string& file) {
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
  if (!j.is_object() || !j.contains("loops")) throw ModelFileError(file + ": expected an object {\"loops\": [...]}, got " + shown(j));
  for (const auto& [key, value] : j.items())
    if (key != "loops" && key != "comment") throw ModelFileError(file + ": " + key + ": unknown key (expected \"loops\", \"comment\")");
  const json& loops = j["loops"];
  if (!loops.is_array() || loops.empty() || loops.size() > kMaxLoops)
    throw ModelFileError(file + ": loops: expected an array of 1 to " + std::to_string(kMaxLoops) + " closures, got " + shown(loops));
  std::vector<model_file::GivenClosure> out;
  std::set<std::string> names;
  static const std::set<std::string> kKeys = {"name", "kind", "body1", "point1", "body2", "point2", "comment"};
  for (std::size_t i = 0; i < loops.size(); ++i) {
    const std::string at = "loops[" + std::to_string(i) + "]";
    const json& l = loops[i];
    if (!l.is_object()) throw ModelFileError(file + ": " + at + ": expected an object {\"kind\", \"body1\", \"point1\", \"body2\"}, got " + shown(l));
    for (const auto& [key, value] : l.items())
      if (!kKeys.count(key))
        throw ModelFileError(file + ": " + at + "." + key + ": unknown key (expected name, kind, body1, point1, body2, point2, comment)");
    for (const char* key : {"kind", "body1", "point1", "body2"})
      if (!l.contains(key)) throw ModelFileError(file + ": " + at + "." + key + ": missing");
    model_file::GivenClosure c;
    c.where = file + ": " + at;
    c.name = l.contains("name") ? text(l["name"], at + ".name", file) : "loop" + std::to_string(i);
    if (!names.insert(c.name).second) throw ModelFileError(file + ": " + at + ".name: '" + c.name + "' names an earlier closure too");
    c.kind = text(l["kind"], at + ".kind", file);
    if (c.kind != "connect" && c.kind != "weld")
      throw ModelFileError(file + ": " + at + ".kind: expected \"connect\" (3 translation rows) or \"weld\" (6 rows), got " + shown(l["kind"]));
    c.body1 = text(l["body1"], at + ".body1", file);
    c.body2 = text(l["body2"], at + ".body2", file);
    c.point1 = point(l["point1"], at + ".point1", file);
    if (l.contains("point2")) c.has_point2 = true, c.point2 = point(l["point2"], at + ".point2", file);
    out.push_back(c);
  }
  return out;
}

std::string loopsBeside(const std::string& model) {
  // Beside a URDF only: an MJCF file writes its loops as equalities (and fourbar.xml must not pick up
  // fourbar.urdf's loops).
  std::filesystem::path p(model);
  std::string ext = p.extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".urdf") return "";
  p.replace_extension(".loops.json");
  std::error_code ec;
  return std::filesystem::exists(p, ec) ? p.string() : "";
}

model_file::LoadedModel loadWithLoops(const std::string& model, const std::string& loops, model_file::LoadOptions options) {
  const std::string given = loops.empty() ? loopsBeside(model) : loops;
  if (!given.empty()) {
    options.closures = readLoops(given);
  }
  model_file::LoadedModel m = model_file::load(model, options);
  if (!given.empty()) m.notes.push_back("loop closures from " + given);
  return m;
}

}  // namespace dyn::app
