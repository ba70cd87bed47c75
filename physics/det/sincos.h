// det::sincos: det::sin(x) and det::cos(x) together, bit for bit the two functions' values, from one
// argument reduction (det_trig.cpp): the tree kinematics turns each joint by both (chain_sized.h).
#pragma once

namespace det {

void sincos(double x, double& s, double& c);

}  // namespace det
