// A task path checked against the mechanism's reach: see reach.h.
#include "labs/generic/reach.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "physics/closed_chain.h"
#include "physics/det/det.h"

namespace dyn::generic {
namespace {

constexpr double kReached = 1e-6;     // m: the tool this near the point reaches it
constexpr double kConditioned = 1e-3;  // σ_min/σ_max of J_x below this: singular

std::string num(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", std::abs(x) < 5e-13 ? 0.0 : x);
  return b;
}

// "(x, z) = (0.9, 0.3) m"
std::string pointText(const VecN& x, const std::vector<std::string>& axes) {
  std::string names, values;
  for (int i = 0; i < x.size(); ++i) {
    names += (i ? ", " : "") + axes[std::size_t(i)];
    values += (i ? ", " : "") + num(x[i]);
  }
  return x.size() == 1 ? names + " = " + values + " m" : "(" + names + ") = (" + values + ") m";
}

// The key a moving segment is written with.
std::string keyOf(const JsonView& segment) { return segment.has("circle") ? "circle" : "move"; }

}  // namespace

void checkReach(const JsonView& trajectory, const TaskPath& path, const MechanismModel<Spatial>& model,
                const std::vector<int>& actuated, const controllers::TaskPoint& tool, const std::vector<std::string>& axis_names,
                const VecN& q0) {
  ConstrainedMechanism<Spatial> mech(model);
  ClosedChain<ConstrainedMechanism<Spatial>> chain(mech, actuated);
  const int d = int(tool.axes.size());
  VecN q = q0, x, xd, xdd;
  for (std::size_t i = 0; i < path.segments(); ++i) {
    if (path.segmentHolds(i) || path.segmentTime(i) <= 0) continue;
    const double t0 = path.segmentStart(i), T = path.segmentTime(i);
    // Its length from a coarse sampling, then samples about 2 mm apart.
    double travel = 0;
    VecN last;
    for (int k = 0; k <= 32; ++k) {
      path.at(t0 + T * k / 32.0, x, xd, xdd);
      if (k) travel += (x - last).norm();
      last = x;
    }
    const int samples = std::clamp(int(std::ceil(travel / 2e-3)), 8, 500);
    std::string end;
    for (int a = 0; a < last.size(); ++a) end += (a ? ", " : "(") + num(last[a]);
    end += last.size() ? ")" : "";
    for (int k = 1; k <= samples; ++k) {
      path.at(t0 + T * k / samples, x, xd, xdd);
      const JsonView at = trajectory["segments"].at(i);
      const std::string where = "the point " + pointText(x, axis_names) + (at.has("circle") ? " on this circle" : " on the way to " + end);
      VecN trial = q;
      controllers::inverseKinematics(mech, tool, x, trial);
      if (!trial.allFinite()) at[keyOf(at)].fail(where + " is out of the mechanism's reach (inverse kinematics diverges there)");
      const Eigen::Vector3d p = mech.pointPosition(tool.link, tool.point, trial);
      double miss = 0;
      for (int a = 0; a < d; ++a) miss += det::pow(p[tool.axes[std::size_t(a)] - 3] - x[a], 2);
      miss = std::sqrt(miss);
      if (miss > kReached)
        at[keyOf(at)].fail(where + " is out of the mechanism's reach (the controller's inverse kinematics brings the tool no nearer than " +
                           num(1e3 * miss) + " mm)");
      q = trial;
      if (!chain.update(q, VecN::Zero(q.size())))
        at[keyOf(at)].fail(where + " is reached only at a singular pose of the loop (its passive joints are not determined there)");
      Eigen::Vector3d pos;
      MatN Jx;
      VecN bias;
      chain.task(tool.link, tool.point, tool.axes, pos, Jx, bias);
      const Eigen::JacobiSVD<MatN> svd(Jx);
      const auto& sv = svd.singularValues();
      if (sv.size() < d || sv[sv.size() - 1] < kConditioned * sv[0])
        at[keyOf(at)].fail(where + " is reached only near a singular pose (J_x's smallest singular value " + num(sv[sv.size() - 1] / sv[0]) +
                           " of its largest: the tool cannot move along every task axis there)");
    }
  }
}

}  // namespace dyn::generic
