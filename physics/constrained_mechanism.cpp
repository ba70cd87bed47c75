// The generic constrained mechanism at bounded (Dynamic) sizes, for planar and spatial trees; labs that
// know their sizes instantiate constrained_mechanism_impl.h at fixed ones.
#include "physics/constrained_mechanism_impl.h"

namespace dyn {

template class ConstrainedMechanism<Planar>;
template class ConstrainedMechanism<Spatial>;

}  // namespace dyn
