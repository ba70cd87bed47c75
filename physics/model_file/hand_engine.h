// The hand engine for a loaded model, as the integrators drive it (integrate.h ConstrainedSystem): a
// ConstrainedMechanism whose sizes are fixed at compile time for the shapes of assets/models' loops
// (n coordinates, r kept closure rows, no payloads: the four-bar (3, 2), the five-bar (4, 2), the
// slider crank (4, 3)), so its loops unroll as the labs' do; any other shape the dynamically sized
// one. The same solve either way (physics/constrained_mechanism.h): what `dynlab model` steps and
// `dynlab bench FILE` times.
#pragma once
#include <memory>
#include <string>

#include "physics/constrained_mechanism.h"
#include "physics/integrate.h"
#include "physics/mechanism.h"

namespace dyn::model_file {

// Throws std::invalid_argument as ConstrainedMechanism does. sizes, when given, says which was built
// ("fixed sizes 4 joints, 2 rows" or "dynamic sizes").
std::unique_ptr<ConstrainedSystem> handEngine(const MechanismModel<Spatial>& model, std::string* sizes = nullptr);

// With elements beside the file (joint limits, contacts: rows closed and opened between steps), six
// hinge or slide joints fixed (the PUMA 560's file and its twelve limit rows) and the rows dynamic: the
// closed rows alone are solved (constrained_mechanism.h), the tree's loops unrolled. The same steps bit
// for bit as the dynamically sized mechanism (tests/physics/model_file/hand_engine_test.cpp). (Compiled
// in hand_engine.cpp; sixJointsFixed says whether a description fits it.)
using SixJoints = ConstrainedMechanism<Spatial, 6, Eigen::Dynamic, 0>;
bool sixJointsFixed(const MechanismModel<Spatial>& model);

}  // namespace dyn::model_file
