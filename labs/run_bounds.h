// The rows a picture's frame is taken over: a lab's scene() sets scene.framing.bounds to the space the
// mechanism moves through over the run, sampled at every ⌈rows/400⌉-th row of the run and of the other
// engine's run (the ghost, when given), and at each one's last row.
#pragma once
#include <algorithm>
#include <cstddef>

#include "labs/trace.h"

namespace dyn {

// Calls visit(trace, row) for each sampled row of `run` and of `ghost`.
template <class Visit>
void forBoundsRows(const Trace& run, const Trace* ghost, Visit&& visit) {
  for (const Trace* t : {&run, ghost}) {
    if (!t || t->rows() == 0) continue;
    const std::size_t stride = std::max<std::size_t>(1, t->rows() / 400);
    for (std::size_t r = 0; r < t->rows(); r += stride) visit(*t, r);
    visit(*t, t->rows() - 1);
  }
}

}  // namespace dyn
