// The page draws no PLplot pictures (grading/plot.cpp and the forked child of grading/isolated.cpp
// are native only): the two calls the grader's plotting path names, for a grade asked for plots.
// The web front ends grade without plots (GradeOptions::out_dir empty), so neither is reached.
#include <stdexcept>

#include "grading/isolated.h"
#include "grading/plot.h"

namespace dyn {

PlotLayout writePlot(const std::string&, const PlotSpec&, int, int) {
  throw std::runtime_error("plots are not drawn in the web build");
}

IsolatedOutcome runIsolated(const std::function<void()>&, double) {
  return {IsolatedOutcome::Kind::Died, "is not part of the web build"};
}

}  // namespace dyn
