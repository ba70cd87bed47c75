// A model file as a lab: see model_lab.h.
#include "labs/generic/model_lab.h"

#include <cctype>
#include <deque>
#include <filesystem>

#include "labs/generic/model_loops.h"
#include "labs/generic/model_description.h"
#include "labs/generic/model_run.h"
#include "labs/model_scene.h"
#include "physics/bullet/bullet_mechanism.h"
#include "labs/trace.h"
#include "physics/model_file/actuators.h"
#include "physics/model_file/model_file.h"

namespace dyn::app {

std::string join(const std::vector<std::string>& v, const char* sep) {
  std::string out;
  for (std::size_t i = 0; i < v.size(); ++i) out += (i ? sep : "") + v[i];
  return out;
}

namespace {

// A run made whole at its start (model_run.h: the same runs `dynlab model` writes), its rows handed
// out one per step, each with the force each joint's bearing carries (load_JOINT_x|y|z: its parent on
// it, world axes; the description's solve at the row's state, its contacts open).
class ReplaySimulation final : public Simulation {
 public:
  ReplaySimulation(const model_file::LoadedModel& m, Engine engine, double dt, double duration) {
    ConstrainedMechanism<Spatial> desc(m.mechanism);
    const VecN tau = VecN::Zero(desc.n());
    if (engine == Engine::Bullet) {
      try {
        run_ = runBullet(m, desc, dt, duration, tau);
      } catch (const std::bad_alloc&) {
        throw;
      } catch (const std::exception& e) {  // a description the Bullet builder cannot model: the file's input, named
        throw InputError(m.file, "/", std::string("a model Bullet can build (Bullet: ") + e.what() + ")");
      }
    } else {
      run_ = m.contacts.empty() ? runHand(m, desc, dt, duration, tau) : runHandElements(m, desc, dt, duration, tau);
    }
    const int n = desc.n();
    std::vector<Spatial::Vec> loads;
    for (std::size_t r = 0; r < run_.trace.rows(); ++r) {
      const VecN q = traceQ(run_.trace, r, n);
      VecN v(n);
      for (int i = 0; i < n; ++i) v[i] = run_.trace.at(r, 1 + n + i);
      desc.jointLoads(q, v, desc.solve(q, v, tau + model_file::actuatorTorques(m, q, v)), loads);
      std::vector<double> extra;
      for (int j = 0; j < n; ++j)
        for (int a = 3; a < 6; ++a) extra.push_back(loads[std::size_t(j)][a]);
      loads_.push_back(extra);
    }
  }
  bool step(std::vector<double>& row) override {
    if (next_ >= run_.trace.rows()) return false;
    const double* at = run_.trace.data.data() + next_ * run_.trace.columns.size();
    row.assign(at, at + run_.trace.columns.size());
    row.insert(row.end(), loads_[next_].begin(), loads_[next_].end());
    ++next_;
    return true;
  }
  std::string failure() const override {
    if (next_ < run_.trace.rows() || run_.ok) return "";
    return run_.stopped.empty() ? "the run stopped (the projection failed or the state became non-finite)" : "the run stopped: " + run_.stopped;
  }

 private:
  ModelRun run_;
  std::vector<std::vector<double>> loads_;
  std::size_t next_ = 0;
};

// A model file as a lab, loaded once: passive, both engines (model_lab.h).
class ModelFileLab final : public Lab {
 public:
  ModelFileLab(std::shared_ptr<const model_file::LoadedModel> m, std::string title, double dt, double duration)
      : m_(std::move(m)), title_(std::move(title)), dt_(dt), duration_(duration), picture_(*m_) {
    columns_ = modelColumns(*m_).columns;
    for (const auto& j : m_->joints)
      for (const char* a : {"_x", "_y", "_z"}) columns_.push_back("load_" + columnName(j.name) + a);
  }
  std::vector<std::string> columns() const override { return columns_; }
  std::string unit(const std::string& c) const override {
    auto starts = [&](const char* p) { return c.rfind(p, 0) == 0; };
    if (c == "t") return "s";
    if (c == "energy" || c == "work" || c == "impacts") return "J";
    if (c == "constraint_residual" || starts("gap_")) return "m";
    if (starts("slip_")) return "m/s";
    if (starts("load_") || starts("skid_margin_")) return "N";
    if (starts("f_")) return c.substr(c.rfind('_') + 1)[0] == 'w' ? "N·m" : "N";
    for (std::size_t i = 0; i < m_->joints.size(); ++i) {
      const bool slide = m_->joints[i].type == "slide";
      if (c == columns_[1 + i]) return slide ? "m" : "rad";
      if (c == columns_[1 + m_->joints.size() + i]) return slide ? "m/s" : "rad/s";
    }
    return {};
  }
  double dt() const override { return dt_; }
  double duration() const override { return duration_; }
  std::unique_ptr<Simulation> simulate(Engine engine) const override {
    return std::make_unique<ReplaySimulation>(*m_, engine, dt_, duration_);
  }
  json metrics(const Trace& tr) const override {
    double drift = 0, residual = 0;
    const double e0 = tr.rows() ? tr.at(0, "energy") : 0;
    for (std::size_t r = 0; r < tr.rows(); ++r) {
      drift = std::max(drift, std::abs(tr.at(r, "energy") - e0 - tr.at(r, "work")));
      residual = std::max(residual, tr.at(r, "constraint_residual"));
    }
    return {{"energy_drift", drift}, {"max_constraint_residual", residual}, {"steps", tr.steps()}};
  }
  json agreement(const Trace& a, const Trace& b) const override {
    double dq = 0, df = 0;
    for (std::size_t r = 0; r < std::min(a.rows(), b.rows()); ++r)
      for (std::size_t c = 1; c < columns_.size(); ++c)
        if (c <= m_->joints.size()) dq = std::max(dq, std::abs(a.at(r, int(c)) - b.at(r, int(c))));
        else if (columns_[c].rfind("f_", 0) == 0) df = std::max(df, std::abs(a.at(r, int(c)) - b.at(r, int(c))));
    json out = {{"rows_compared", std::min(a.rows(), b.rows())}, {"max_dq", dq}, {"max_df", df}};
    out.update(engineHealth(metrics(a), metrics(b)));
    return out;
  }
  std::string agreementUnit(const std::string& key) const override { return key == "max_dq" ? "rad" : key == "max_df" ? "N, N·m" : ""; }
  std::string referenceEngine() const override {
    return bullet::BulletMechanism<Spatial>(m_->mechanism, dt_, m_->q0, VecN::Zero(Eigen::Index(m_->joints.size()))).describe();
  }
  void scene(const Trace& tr, std::size_t row, const Trace* ghost, Scene& out) const override {
    const int n = int(m_->joints.size());
    // The run's bounds frame every picture of it (cached: a video asks for every row).
    if (bounds_of_ != tr.data.data() || bounds_rows_ != tr.rows()) {
      bounds_ = runBounds(picture_, n, tr, ghost);
      points_ = runPoints(picture_, n, tr, ghost);
      bounds_of_ = tr.data.data(), bounds_rows_ = tr.rows();
    }
    VecN gq;
    if (ghost && row < ghost->rows()) gq = traceQ(*ghost, row, n);
    picture_.scene(traceQ(tr, row, n), gq.size() ? &gq : nullptr, bounds_, out, points_);
  }
  void overlay(const Trace& tr, std::size_t row, Overlay& o) const override {
    o.title = title_;
    modelOverlay(o.title, m_->actuators.empty() ? "passive (τ = 0)" : "the file's actuators, ctrl held", tr, row, dt_, nullptr, o);
  }

 private:
  std::shared_ptr<const model_file::LoadedModel> m_;
  std::string title_;
  double dt_, duration_;
  std::vector<std::string> columns_;
  ModelPicture picture_;
  mutable Eigen::AlignedBox3d bounds_;
  mutable std::vector<Eigen::Vector3d> points_;  // the run's shapes' points (runPoints), cached with bounds_
  mutable const double* bounds_of_ = nullptr;
  mutable std::size_t bounds_rows_ = 0;
};

}  // namespace

LoadedLab loadModelLab(const std::string& file, std::optional<double> duration, const ModelFileFlags& flags, std::vector<std::string>* notes) {
  model_file::LoadOptions options;
  options.ignore_contacts = flags.ignore_contacts;
  options.package_paths = flags.package_paths;
  options.key = flags.key;
  auto m = std::make_shared<model_file::LoadedModel>();
  try {
    if (const std::string beside = loopsBeside(file); !beside.empty()) readBeside(beside, options);
    *m = loadModelOrDescription(file, options);
  } catch (const model_file::ModelFileError& e) {
    // The loader's line starts with the file's name: said once.
    std::string why = e.what();
    if (why.rfind(file + ": ", 0) == 0) why.erase(0, file.size() + 2);
    throw InputError(file, "/", "a model file dynlab reads (" + why + ")");
  }
  const std::filesystem::path path(file);
  const std::string stem = path.stem().string();
  const double dt = m->timestep > 0 ? m->timestep : 1e-3;
  // The run at the file's step is bounded (labs/settings.h), before anything runs; a refusal names the
  // --duration given, else the file's timestep.
  const std::string step = duration ? path.filename().string() + "'s timestep" : "timestep";
  const auto refuse = [&](const std::string& problem) {
    if (duration) throw InputError("<command line>", "--duration", problem);
    throw InputError(file, "<option timestep>", problem);
  };
  if (const std::string problem = runBoundProblem(dt, duration.value_or(2.0), 0, step); !problem.empty()) refuse(problem);
  if (notes) *notes = modelNotes(*m, dt);
  // Its figures: the coordinates, the energy books, each closure's force, each wheel's and contact's.
  const std::vector<std::string> q = coordinateColumns(*m);
  std::vector<std::string> f, c;
  for (const auto& k : m->closures)
    for (const auto& r : k.kept) f.push_back("f_" + columnName(k.name) + "_" + r);
  for (const auto& k : m->contacts)
    for (const char* part : k.kind == "rolling"                                   ? std::vector<const char*>{"_long", "_lat", "_normal"}
                            : k.kind == "plane_contact" || k.kind == "joint_limit" ? std::vector<const char*>{"_normal"}
                                                                                   : std::vector<const char*>{""})  // a coupling: f_NAME
      c.push_back("f_" + columnName(k.name) + part);
  const bool impacts = anyImpacts(*m);
  json figures = json::array(
      {json{{"plot", join(q, ", ")}, {"title", "joint coordinates"}},
       json{{"plot", impacts ? "energy, work, impacts" : "energy, work"},
            {"title", impacts ? "energy E and work W, which holds the touchdowns' losses (impacts)"
                              : "energy E and the work W of friction (E − E0 − W = 0 for exact dynamics)"}}});
  if (!f.empty()) figures.push_back({{"plot", join(f, ", ")}, {"title", "closure forces (body 1 on body 2, world axes)"}});
  if (!c.empty()) figures.push_back({{"plot", join(c, ", ")}, {"title", "contact forces (the ground's or the plane's; a touchdown's step: its impulse / dt)"}});
  // A lab's blocks as a passive data lab's (no actuated joint, no gains: the tuning window shows none).
  json config = {{"lab", stem}, {"title", stem + ": " + path.filename().string() + ", passive"}, {"model_file", path.filename().string()},
                 {"actuated", json::array()}, {"torque_limit", json::array()},
                 {"simulation", {{"dt", dt}, {"duration", duration.value_or(2.0)}, {"integrator", "rk4"}, {"drift", "projection"}}},
                 {"controller", {{"kind", "none"}, {"control_period", dt}}}, {"gains", json::object()}, {"figures", figures}};
  // The lab's entry lives as long as the process (a LoadedLab points at it); it shares the loaded model.
  static std::deque<LabEntry> entries;
  const std::shared_ptr<const model_file::LoadedModel> shared = m;
  entries.push_back({stem, "a model file, passive", [shared, stem](const JsonView& c) -> std::unique_ptr<Lab> {
                       const JsonView sim = c["simulation"];
                       return std::make_unique<ModelFileLab>(shared, stem, sim["dt"].number(), sim["duration"].number());
                     },
                     {}, {}});
  LoadedLab out;
  out.entry = &entries.back();
  out.config = config;
  out.config_file = file;
  out.lab = out.entry->create(JsonView(out.config, file));
  // Its trace: a row of the lab's columns per step (many joints make wide rows).
  if (const std::string problem = runBoundProblem(dt, out.lab->duration(), out.lab->columns().size(), step); !problem.empty())
    refuse(problem);
  return out;
}

bool isModelFile(const std::string& name) {
  std::string ext = std::filesystem::path(name).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".xml" || ext == ".urdf" || isDescription(name);
}

}  // namespace dyn::app
