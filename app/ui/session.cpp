// The tuning session: gains and options -> config (applySubmission) -> lab -> runs stepped under
// the watchdog; see session.h.
#include "app/ui/session.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "grading/grade.h"
#include "labs/numbers.h"
#include "grading/rubric.h"
#include "labs/run.h"
#include "labs/submission.h"

namespace dyn::ui {
namespace fs = std::filesystem;

const char* name(EngineChoice e) {
  return e == EngineChoice::Hand ? "hand" : e == EngineChoice::Bullet ? "bullet" : "both";
}

EngineChoice parseEngineChoice(const std::string& s) {
  if (s == "hand") return EngineChoice::Hand;
  if (s == "bullet") return EngineChoice::Bullet;
  if (s == "both") return EngineChoice::Both;
  throw InputError("<command line>", "--engine", "expected one of hand, bullet, both, got \"" + s + "\"");
}

TuningSession::TuningSession(const std::string& lab, const std::string& config_file, const std::string& gains_file,
                             const std::string& scenario, const PlantChoice& plant) {
  LoadedLab loaded = loadLab(lab, config_file, gains_file, std::nullopt, plant);
  const std::string config_path = loaded.config_file;
  // The lab's own defaults (before any gains file), for "Lab defaults".
  const json plain = loadJsonFile(config_path);
  // Gains in the order the lab's JSON lists them (json objects sort their keys).
  std::vector<std::string> order;
  {
    // Read as every input is (a regular file, UTF-8): the file was checked above, not trusted since.
    const auto ordered = nlohmann::ordered_json::parse(readTextFile(config_path, 16u << 20), nullptr, false);
    if (ordered.is_object() && ordered.contains("gains") && ordered["gains"].is_object())
      for (const auto& [gname, _] : ordered["gains"].items()) order.push_back(gname);
  }
  init(lab, std::move(loaded), plain, order, gains_file.empty() ? config_path : gains_file, scenario);
}

TuningSession::TuningSession(LoadedLab loaded) {
  // A lab built in memory (a model file's passive run): its config is its own defaults.
  const json plain = loaded.config;
  const std::string name = plain.value("lab", std::string("model")), source = loaded.config_file;
  init(name, std::move(loaded), plain, {}, source, "");
}

void TuningSession::init(const std::string& lab, LoadedLab loaded, const json& plain, std::vector<std::string> order,
                         const std::string& source, const std::string& scenario) {
  lab_name_ = lab;
  entry_ = loaded.entry;
  config_file_ = loaded.config_file;
  source_ = source;
  file_config_ = std::move(loaded.config);
  for (const auto& [gname, _] : file_config_.at("gains").items())
    if (std::find(order.begin(), order.end(), gname) == order.end()) order.push_back(gname);
  for (const std::string& gname : order) {
    if (!file_config_.at("gains").contains(gname)) continue;
    const json& d = file_config_.at("gains").at(gname);
    GainSpec g{gname, d.value("unit", ""), d.value("doc", ""), d.at("min").get<double>(), d.at("max").get<double>(),
               plain.at("gains").at(gname).at("value").get<double>()};
    gain_specs_.push_back(g);
    gains_[gname] = d.at("value").get<double>();
  }
  const json options = file_config_.value("submission_options", json::object());
  for (const auto& [oname, d] : options.items()) {
    OptionSpec o{oname, d.value("doc", ""), d.at("target").get<std::string>(), {}, ""};
    for (const auto& c : d.at("choices")) o.choices.push_back(c.get<std::string>());
    const json::json_pointer target(o.target);
    auto current = [&](const json& config) {
      return config.contains(target) && config.at(target).is_string() ? config.at(target).get<std::string>()
                                                                       : o.choices.front();
    };
    o.lab_default = current(plain);
    options_[oname] = current(file_config_);
    option_specs_.push_back(o);
  }
  if (file_config_.contains("rubric")) {
    rubric_ = parseRubric(JsonView(file_config_, config_file_));
    watchdog_ = rubric_.watchdog;
  }
  if (!scenario.empty()) {
    if (!file_config_.contains("rubric"))
      throw InputError("<command line>", "--scenario", "expected a lab with a rubric; " + config_file_ + " has none");
    scenario_ = findScenario(rubric_, scenario).name;
  }
  restart();
}

std::string TuningSession::title() const {
  const auto it = file_config_.find("title");
  const std::string t = it != file_config_.end() && it->is_string() ? it->get<std::string>() : lab_name_;
  return scenario_.empty() ? t : t + " — scenario " + scenario_;
}

double TuningSession::gain(const std::string& gname) const { return gains_.at(gname).get<double>(); }

const std::string& TuningSession::option(const std::string& oname) const {
  return options_.at(oname).get_ref<const std::string&>();
}

void TuningSession::setGain(const std::string& gname, double value) {
  for (const GainSpec& g : gain_specs_) {
    if (g.name != gname) continue;
    if (!std::isfinite(value) || value < g.min || value > g.max)
      throw InputError("<tuning>", "/gains/" + gname,
                       "expected a number in [" + fmtNumber(g.min) + ", " + fmtNumber(g.max) + "] " + g.unit +
                           ", got " + exactNumber(value));
    gains_[gname] = value;
    return;
  }
  throw InputError("<tuning>", "/gains/" + gname, "unknown gain \"" + gname + "\"");
}

void TuningSession::setOption(const std::string& oname, const std::string& value) {
  for (const OptionSpec& o : option_specs_) {
    if (o.name != oname) continue;
    std::string list;
    for (const auto& c : o.choices) {
      if (c == value) {
        options_[oname] = value;
        return;
      }
      list += (list.empty() ? "" : ", ") + c;
    }
    throw InputError("<tuning>", "/" + oname, "expected one of " + list + ", got \"" + value + "\"");
  }
  throw InputError("<tuning>", "/" + oname, "unknown option \"" + oname + "\"");
}

void TuningSession::set(const std::string& assignment) {
  const auto eq = assignment.find('=');
  const std::string key = assignment.substr(0, eq);
  if (eq == std::string::npos || key.empty())
    throw InputError("<command line>", "--set", "expected NAME=VALUE, got \"" + assignment + "\"");
  const std::string value = assignment.substr(eq + 1);
  try {
    if (gains_.contains(key)) {
      char* end = nullptr;
      const double x = std::strtod(value.c_str(), &end);
      if (value.empty() || *end != '\0' || !std::isfinite(x))
        throw InputError("<tuning>", "", "expected a number, got \"" + value + "\"");
      setGain(key, x);
    } else if (options_.contains(key)) {
      setOption(key, value);
    } else {
      std::string list;
      for (const auto& g : gain_specs_) list += (list.empty() ? "" : ", ") + g.name;
      for (const auto& o : option_specs_) list += ", " + o.name;
      throw InputError("<tuning>", "", "unknown name \"" + key + "\" (this lab's gains and options: " + list + ")");
    }
  } catch (const InputError& e) {
    throw InputError("<command line>", "--set " + assignment, e.expected());
  }
}

void TuningSession::resetToLabDefaults() {
  for (const GainSpec& g : gain_specs_) gains_[g.name] = g.lab_default;
  for (const OptionSpec& o : option_specs_) options_[o.name] = o.lab_default;
}

json TuningSession::submission() const {
  json sub = {{"lab", lab_name_}};
  for (const auto& [oname, value] : options_.items()) sub[oname] = value;
  sub["gains"] = gains_;
  return sub;
}

void TuningSession::saveSubmission(const std::string& path) const {
  const json sub = submission();
  // The same check `dynlab grade` makes (strict: every gain, this lab), before anything is written.
  applySubmission(file_config_, JsonView(sub, path), lab_name_, true);
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  if (target.filename().empty() || !fs::is_directory(dir))
    throw std::runtime_error("cannot save " + path + ": " + dir.string() + " is not a directory");
  fs::path tmp = target;
  tmp += "." + std::to_string(::getpid()) + ".tmp";
  // Written in reading order: lab, options, then the gains as the lab lists them.
  nlohmann::ordered_json text = {{"lab", lab_name_}};
  for (const OptionSpec& o : option_specs_) text[o.name] = option(o.name);
  text["gains"] = nlohmann::ordered_json::object();
  for (const GainSpec& g : gain_specs_) text["gains"][g.name] = gain(g.name);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out << text.dump(2) << "\n";
    out.flush();
    if (!out) {
      const std::string why = std::strerror(errno);
      std::error_code ec;
      fs::remove(tmp, ec);
      throw std::runtime_error("cannot save " + path + ": " + why);
    }
  }
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw std::runtime_error("cannot save " + path + ": " + ec.message());
  }
}

void TuningSession::restart() {
  ++generation_;
  problem_.clear();
  ghost_problem_.clear();
  screen_notes_.clear();
  screen_unstable_ = false;
  runs_.clear();
  lab_.reset();
  try {
    const json sub = submission();
    effective_config_ = applySubmission(file_config_, JsonView(sub, source_), lab_name_, true);
    // Under a scenario: its patch and the seed grading uses (the lab's and the scenario's).
    if (!scenario_.empty())
      effective_config_ = scenarioConfig(effective_config_, rubric_, *rubric_.scenario(scenario_), lab_name_, config_file_);
    lab_ = buildLab(*entry_, effective_config_, source_);
    watch_ = std::make_unique<RowWatch>(watchdog_, lab_->columns(), config_file_);
    const ScreenResult screen = screenLoops(*lab_);
    screen_notes_ = screen.notes;
    screen_unstable_ = screen.unstable;
    std::vector<Engine> engines = {engine_ == EngineChoice::Bullet ? Engine::Bullet : Engine::Hand};
    if (engine_ == EngineChoice::Both) engines.push_back(Engine::Bullet);
    for (Engine e : engines) {
      Run run{e, lab_->simulate(e), {}, {}, false};
      run.trace.columns = lab_->columns();
      runs_.push_back(std::move(run));
    }
  } catch (const std::exception& e) {
    problem_ = e.what();
    runs_.clear();
    lab_.reset();
    return;
  }
  advance(1);  // the row at t = 0, so there is always something to draw
}

bool TuningSession::stepRun(Run& run) {
  if (run.done) return false;
  if (std::string why = watch_->budget(long(run.trace.rows())); !why.empty()) {
    run.stopped = why;
    run.done = true;
    return false;
  }
  std::vector<double> row;
  try {
    if (!run.sim->step(row)) {
      run.done = true;
      if (!run.sim->failure().empty()) {
        const double t = run.trace.rows() ? run.trace.at(run.trace.rows() - 1, run.trace.column("t")) : 0.0;
        run.stopped = stoppedSentence(run.sim->failure(), t);
      }
      return false;
    }
  } catch (const std::exception& e) {
    run.stopped = std::string("the simulation failed: ") + e.what();
    run.done = true;
    return false;
  }
  run.trace.append(row);
  const int t_col = run.trace.column("t");
  const double t = t_col >= 0 ? row[std::size_t(t_col)] : double(run.trace.rows() - 1) * lab_->dt();
  if (std::string why = watch_->check(row, t); !why.empty()) {
    run.stopped = why;
    run.done = true;
  }
  return true;
}

long TuningSession::advance(long n) {
  if (runs_.empty()) return 0;
  long taken = 0;
  for (; taken < n; ++taken) {
    if (!stepRun(runs_[0])) break;
    if (runs_.size() > 1) stepRun(runs_[1]);  // the ghost keeps pace with the primary run
  }
  problem_ = runs_[0].stopped;
  if (runs_.size() > 1 && !runs_[1].stopped.empty()) ghost_problem_ = "Bullet ghost: " + runs_[1].stopped;
  return taken;
}

bool TuningSession::finished() const { return runs_.empty() || runs_[0].done; }

const Trace& TuningSession::primary() const { return runs_.empty() ? empty_ : runs_[0].trace; }

const Trace* TuningSession::ghost() const { return runs_.size() > 1 ? &runs_[1].trace : nullptr; }

double TuningSession::time() const {
  const Trace& tr = primary();
  if (!tr.rows()) return 0;
  const int c = tr.column("t");
  return c >= 0 ? tr.at(row(), c) : double(row()) * lab_->dt();
}

json TuningSession::metrics() const {
  if (!lab_ || !hasRows()) return json::object();
  try {
    return lab_->metrics(primary());
  } catch (const std::exception&) {
    return json::object();
  }
}

const json& TuningSession::currentMetrics() {
  const bool fin = finished();
  if (metrics_cache_.generation != generation_ || metrics_cache_.row != row() || metrics_cache_.finished != fin) {
    metrics_cache_.value = metrics();
    metrics_cache_.generation = generation_;
    metrics_cache_.row = row();
    metrics_cache_.finished = fin;
  }
  return metrics_cache_.value;
}

std::vector<Series> TuningSession::livePlots(int column) const {
  std::vector<Series> plots;
  if (!lab_ || !hasRows()) return plots;
  const Trace& tr = primary();
  try {
    Overlay o;
    lab_->overlay(tr, row(), o);
    plots = std::move(o.plots);
  } catch (const std::exception&) {
    plots.clear();  // a lab that cannot draw this row shows no plots rather than stopping the window
  }
  if (column >= 0 && column < int(tr.columns.size())) {
    const std::string unit = lab_->unit(tr.columns[std::size_t(column)]);
    Series s{tr.columns[std::size_t(column)] + (unit.empty() ? "" : " (" + unit + ")"), {}, {0.25f, 0.35f, 0.60f, 1.0f}};
    const std::size_t window = std::size_t(std::lround(2.0 / lab_->dt()));
    for (std::size_t r = row() > window ? row() - window : 0; r <= row(); ++r) s.values.push_back(float(tr.at(r, column)));
    plots.push_back(std::move(s));
  }
  return plots;
}

}  // namespace dyn::ui
