// The impedance lab's hand-engine arm with the wall (lab.h WallArm): the motion-control arm's three
// joints and the wall's one contact row, sizes fixed so the step's loops unroll.
#include "labs/impedance/lab.h"
#include "physics/constrained_mechanism_impl.h"

namespace dyn {
template class ConstrainedMechanism<Planar, 3, 1, 0>;
}  // namespace dyn
