// Model files in a dynlab configured with -DDYNLAB_WITH_MUJOCO=OFF (an image without libmujoco-dev,
// e.g. the Gradescope autograder on Ubuntu 22.04): the hand-written labs need no model file, and
// reading one (a data lab, dynlab model FILE) stops with one line naming what is missing.
#include "physics/model_file/model_file.h"

namespace dyn::model_file {
namespace {

[[noreturn]] void refuse(const std::string& path) {
  throw ModelFileError(path + ": this dynlab was built without MuJoCo's parser (configured with -DDYNLAB_WITH_MUJOCO=OFF), "
                              "so it reads no MJCF/URDF file; build it where libmujoco-dev is installed, or give it the file's description "
                              "(a .json: `dynlab model FILE --export FILE.json` with a dynlab that has MuJoCo)");
}

}  // namespace

LoadedModel load(const std::string& path, const LoadOptions&) { refuse(path); }

// Never constructed (load refuses first); each member refuses all the same.
MujocoReference::MujocoReference(const LoadedModel& model) : impl_(nullptr) { refuse(model.file); }
MujocoReference::~MujocoReference() = default;
int MujocoReference::nv() const { return 0; }
MatN MujocoReference::massMatrix(const VecN&) { refuse("MujocoReference"); }
VecN MujocoReference::bias(const VecN&, const VecN&) { refuse("MujocoReference"); }
VecN MujocoReference::actuation(const VecN&, const VecN&, const VecN&) { refuse("MujocoReference"); }
VecN MujocoReference::passive(const VecN&, const VecN&) { refuse("MujocoReference"); }
double MujocoReference::closure(const VecN&) { refuse("MujocoReference"); }

MujocoSimulation::MujocoSimulation(const LoadedModel& model, double, bool, bool) : impl_(nullptr) { refuse(model.file); }
MujocoSimulation::~MujocoSimulation() = default;
void MujocoSimulation::reset(const VecN&, const VecN&) { refuse("MujocoSimulation"); }
bool MujocoSimulation::step() { refuse("MujocoSimulation"); }
void MujocoSimulation::state(VecN&, VecN&) const { refuse("MujocoSimulation"); }
std::string MujocoSimulation::describe() const { return "MuJoCo (not built in)"; }

}  // namespace dyn::model_file
