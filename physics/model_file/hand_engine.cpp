// The hand engine for a loaded model: see hand_engine.h. Each fixed shape is one instantiation of the
// mechanism's template (compiled here, as a lab compiles its own).
#include "physics/model_file/hand_engine.h"

#include "physics/constrained_mechanism.h"
#include "physics/constrained_mechanism_impl.h"

namespace dyn {
template class ConstrainedMechanism<Spatial, 3, 2, 0>;
template class ConstrainedMechanism<Spatial, 4, 2, 0>;
template class ConstrainedMechanism<Spatial, 4, 3, 0>;
template class ConstrainedMechanism<Spatial, 6, Eigen::Dynamic, 0>;
}  // namespace dyn

namespace dyn::model_file {

bool sixJointsFixed(const MechanismModel<Spatial>& model) {
  return model.treeDof() == 6 && model.tree.nq() == 6 && model.payloads.empty();
}

std::unique_ptr<ConstrainedSystem> handEngine(const MechanismModel<Spatial>& model, std::string* sizes) {
  const int n = model.treeDof(), r = model.rows();
  if (sizes) *sizes = "fixed sizes " + std::to_string(n) + " joints, " + std::to_string(r) + " rows";
  if (model.payloads.empty()) {
    if (n == 3 && r == 2) return std::make_unique<ConstrainedMechanism<Spatial, 3, 2, 0>>(model);
    if (n == 4 && r == 2) return std::make_unique<ConstrainedMechanism<Spatial, 4, 2, 0>>(model);
    if (n == 4 && r == 3) return std::make_unique<ConstrainedMechanism<Spatial, 4, 3, 0>>(model);
  }
  if (sizes) *sizes = "dynamic sizes";
  return std::make_unique<ConstrainedMechanism<Spatial>>(model);
}

}  // namespace dyn::model_file
