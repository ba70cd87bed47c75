// A test's own reference integrator: classic RK4 of q'' = a(q, q') from (q, v) over `steps` steps of dt,
// written out here (not physics/integrate) so that a check against it does not share the engine's code.
#pragma once
#include "physics/types.h"

namespace dyn::test {

template <class Accel>
VecN referenceRk4(const Accel& accel, VecN q, VecN v, double dt, long steps) {
  for (long k = 0; k < steps; ++k) {
    const VecN a1 = accel(q, v);
    const VecN q2 = q + 0.5 * dt * v, v2 = v + 0.5 * dt * a1;
    const VecN a2 = accel(q2, v2);
    const VecN q3 = q + 0.5 * dt * v2, v3 = v + 0.5 * dt * a2;
    const VecN a3 = accel(q3, v3);
    const VecN q4 = q + dt * v3, v4 = v + dt * a3;
    const VecN a4 = accel(q4, v4);
    q += dt / 6 * (v + 2 * v2 + 2 * v3 + v4);
    v += dt / 6 * (a1 + 2 * a2 + 2 * a3 + a4);
  }
  return q;
}

}  // namespace dyn::test
