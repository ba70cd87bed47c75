// dynlab bench LAB's MuJoCo run: the lab's mechanism written for MuJoCo (Lab::mujocoTwin, labs/mujoco_twin.h:
// labs/<name>/mujoco.xml, or a data lab's own model file) stepped by mj_step at the lab's dt with MuJoCo's
// Euler integrator (first order: the hand engine's equal is its first-order variant), passive from the
// lab's start in the file's coordinates; a run that blows up starts again there.
#include <cstdio>
#include <filesystem>

#include "app/cli/bench/bench.h"
#include "labs/lab.h"
#include "labs/utf8.h"
#include "physics/model_file/model_file.h"

namespace fs = std::filesystem;

namespace dyn::app {

struct MujocoRun::Impl {
  model_file::LoadedModel own;  // the twin's file, loaded here (a data lab's: the lab's own copy)
  std::unique_ptr<model_file::MujocoSimulation> sim;
  VecN q, v;
};

MujocoRun::MujocoRun() = default;
MujocoRun::~MujocoRun() = default;
MujocoRun::MujocoRun(MujocoRun&&) noexcept = default;

bool MujocoRun::step() { return impl_->sim->step() || (impl_->sim->reset(impl_->q, impl_->v), false); }
void MujocoRun::restart() { impl_->sim->reset(impl_->q, impl_->v); }

MujocoRun mujocoRun(const Lab& lab, const std::string& config_file) {
  MujocoRun run;
  const MujocoTwin twin = lab.mujocoTwin();
  if (twin.file.empty() && !twin.loaded) {
    run.left_out = "the lab has no model written for MuJoCo";
    return run;
  }
  auto impl = std::make_unique<MujocoRun::Impl>();
  const model_file::LoadedModel* model = twin.loaded.get();
  try {
    if (!model) {
      const fs::path path = fs::path(config_file).parent_path() / twin.file;
      impl->own = model_file::load(path.string());
      model = &impl->own;
    }
    impl->sim = std::make_unique<model_file::MujocoSimulation>(*model, lab.dt(), false, twin.contacts);
  } catch (const model_file::ModelFileError& e) {  // MuJoCo not built in, or the file unreadable: the others are timed
    run.left_out = termName(e.what(), 1000);
    return run;
  }
  impl->q = twin.toFile(twin.q), impl->v = twin.toFile(twin.v);
  impl->sim->reset(impl->q, impl->v);
  run.file = model->file;
  run.scheme = impl->sim->describe();
  run.stands_in = twin.stands_in;
  run.impl_ = std::move(impl);
  return run;
}

}  // namespace dyn::app
