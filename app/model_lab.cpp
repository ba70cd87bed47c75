// A model file as a lab: see model_lab.h.
#include "app/model_lab.h"

#include <cctype>
#include <deque>
#include <filesystem>

#include "app/model_loops.h"
#include "labs/generic/data_lab.h"
#include "labs/trace.h"
#include "physics/model_file/model_file.h"

namespace dyn::app {

std::string join(const std::vector<std::string>& v, const char* sep) {
  std::string out;
  for (std::size_t i = 0; i < v.size(); ++i) out += (i ? sep : "") + v[i];
  return out;
}

LoadedLab loadModelLab(const std::string& file, std::optional<double> duration) {
  model_file::LoadOptions options;
  model_file::LoadedModel m;
  try {
    if (const std::string beside = loopsBeside(file); !beside.empty()) readBeside(beside, options);
    m = model_file::load(file, options);
  } catch (const model_file::ModelFileError& e) {
    throw InputError(file, "/", std::string("a model file dynlab reads (") + e.what() + ")");
  }
  const std::filesystem::path path(file);
  const std::string stem = path.stem().string(), folder = path.parent_path().empty() ? "." : path.parent_path().string();
  const double dt = m.timestep > 0 ? m.timestep : 1e-3;
  std::vector<std::string> q, f;
  for (const auto& j : m.joints) q.push_back("q_" + columnName(j.name));
  for (const auto& c : m.closures)
    for (const auto& r : c.kept) f.push_back("f_" + columnName(c.name) + "_" + r);
  json figures = json::array({json{{"plot", join(q, ", ")}, {"title", "joint coordinates"}},
                              json{{"plot", "energy, work"}, {"title", "energy E and the work W of friction (E − E0 − W = 0 for exact dynamics)"}}});
  if (!f.empty()) figures.push_back({{"plot", join(f, ", ")}, {"title", "closure forces (body 1 on body 2, world axes)"}});
  json config = {{"lab", stem}, {"title", stem + ": " + path.filename().string() + ", passive"}, {"model_file", path.filename().string()},
                 {"actuated", json::array()}, {"torque_limit", json::array()},
                 {"simulation", {{"dt", dt}, {"duration", duration.value_or(2.0)}, {"integrator", "rk4"}, {"drift", "projection"}}},
                 {"controller", {{"kind", "none"}, {"control_period", dt}}}, {"gains", json::object()}, {"figures", figures}};
  // The lab's entry lives as long as the process (a LoadedLab points at it).
  static std::deque<LabEntry> entries;
  entries.push_back({stem, "a model file, passive", [stem, folder, options](const JsonView& c) -> std::unique_ptr<Lab> {
                       return std::make_unique<generic::DataLab>(generic::parseDataSettings(c, stem, folder, options));
                     }});
  LoadedLab out;
  out.entry = &entries.back();
  out.config = config;
  out.config_file = file;
  out.lab = out.entry->create(JsonView(out.config, file));
  return out;
}

bool isModelFile(const std::string& name) {
  std::string ext = std::filesystem::path(name).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".xml" || ext == ".urdf";
}

}  // namespace dyn::app
