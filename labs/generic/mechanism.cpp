// The generic mechanism at fixed sizes for a data lab's open trees (data_lab.cpp picks them), compiled
// here as a lab's mechanism.cpp compiles its own (with their compile options, labs/CMakeLists.txt): an
// open 6-joint chain (the PUMA 560: 6 coordinates, no closure rows). The loops' shapes are instantiated
// with the model files' hand engine (physics/model_file/hand_engine.cpp).
#include "physics/constrained_mechanism.h"
#include "physics/constrained_mechanism_impl.h"

namespace dyn {
template class ConstrainedMechanism<Spatial, 6, 0, 0>;
}  // namespace dyn
