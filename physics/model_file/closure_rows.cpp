// Loop closure rows: the choice of independent rows and the check of the dropped ones (closure_rows.h).
#include "physics/model_file/closure_rows.h"

#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "physics/model_file/model_file.h"
#include "physics/model_file/number_text.h"

namespace dyn::model_file {
namespace {

std::string num(double x) { return detail::numberText(x, 3); }

// Ĝ(q) = D_r G(q) D_c: translation rows ÷ L, slide columns × L.
Eigen::MatrixXd scaledJacobian(ConstrainedMechanism<Spatial>& mech, const VecN& q, const RowCandidates& rows) {
  VecN phi;
  MatN G;
  mech.constraint(q, phi, G);
  Eigen::MatrixXd g = G;
  for (Eigen::Index r = 0; r < g.rows(); ++r)
    if (rows.translation[std::size_t(r)]) g.row(r) /= rows.extent;
  for (Eigen::Index c = 0; c < g.cols(); ++c)
    if (rows.slide[std::size_t(c)]) g.col(c) *= rows.extent;
  return g;
}

// Rank by singular values against the absolute tolerance (Ĝ is dimensionless and O(1)).
int absoluteRank(const Eigen::MatrixXd& g) {
  if (g.rows() == 0 || g.cols() == 0) return 0;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(g);
  const auto& s = svd.singularValues();
  return int((s.array() > kIndependentRow).count());
}

// A pose near q0 where every row holds: q0 + δ moved back onto φ = 0 by Gauss–Newton with
// minimum-norm steps (the rows may be redundant). False if it does not converge from this δ. With ball
// joints δ and the steps are rates (G's columns): q0 ⊕ δ, q ⊕ (−step).
bool assemble(ConstrainedMechanism<Spatial>& mech, const VecN& q0, const VecN& delta, const RowCandidates& rows, VecN& q) {
  const bool sphere = mech.nq() != mech.nv();
  q = q0;
  if (sphere) mech.integrateConfiguration(q, delta, 1.0);
  else q = q0 + delta;
  VecN phi;
  MatN G;
  for (int it = 0; it < 50; ++it) {
    mech.constraint(q, phi, G);
    Eigen::VectorXd scaled = phi;
    for (Eigen::Index r = 0; r < scaled.size(); ++r)
      if (rows.translation[std::size_t(r)]) scaled[r] /= rows.extent;
    if (scaled.lpNorm<Eigen::Infinity>() <= 1e-13) return q.allFinite();
    Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(G.rows(), G.cols());
    cod.setThreshold(1e-10);
    cod.compute(G);
    const VecN step = cod.solve(Eigen::VectorXd(phi));
    if (!step.allFinite()) return false;
    if (sphere) mech.integrateConfiguration(q, step, -1.0);
    else q -= step;
  }
  return false;
}

// q0 and up to three assembled poses around it (coordinates moved by up to 0.3 rad or 0.3 L, halved
// when Gauss–Newton does not converge), each as its Ĝ.
std::vector<Eigen::MatrixXd> poses(ConstrainedMechanism<Spatial>& mech, const VecN& q0, const RowCandidates& rows) {
  std::vector<Eigen::MatrixXd> out{scaledJacobian(mech, q0, rows)};
  std::mt19937_64 rng(29);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Index n = mech.nv();  // (the rates: q0.size() less one per ball)
  for (int s = 0; s < 3; ++s) {
    VecN direction(n), q;
    for (Eigen::Index i = 0; i < n; ++i) direction[i] = u(rng) * (rows.slide[std::size_t(i)] ? rows.extent : 1.0);
    for (double size = 0.3; size > 0.01; size *= 0.5)
      if (assemble(mech, q0, size * direction, rows, q)) {
        out.push_back(scaledJacobian(mech, q, rows));
        break;
      }
  }
  return out;
}

// Greedy pivoting on the stacked rows: take the row with the largest part orthogonal to those taken
// (the first of equals), while that part's norm exceeds τ per pose.
std::vector<bool> pivotRows(const std::vector<Eigen::MatrixXd>& g) {
  const Eigen::Index m = g.front().rows(), n = g.front().cols();
  Eigen::MatrixXd R(m, n * Eigen::Index(g.size()));
  for (std::size_t s = 0; s < g.size(); ++s) R.middleCols(Eigen::Index(s) * n, n) = g[s];
  const double tolerance = kIndependentRow * std::sqrt(double(g.size()));
  std::vector<bool> kept(std::size_t(m), false);
  for (;;) {
    Eigen::Index best = -1;
    double best_norm = tolerance;
    for (Eigen::Index r = 0; r < m; ++r)
      if (const double norm = R.row(r).norm(); !kept[std::size_t(r)] && norm > best_norm * (1 + 1e-12)) best = r, best_norm = norm;
    if (best < 0) return kept;
    kept[std::size_t(best)] = true;
    const Eigen::RowVectorXd u = R.row(best) / best_norm;
    for (int pass = 0; pass < 2; ++pass)  // twice: Gram–Schmidt's orthogonality restored
      for (Eigen::Index r = 0; r < m; ++r)
        if (!kept[std::size_t(r)]) R.row(r) -= R.row(r).dot(u) * u;
  }
}

Eigen::MatrixXd keptRowsOf(const Eigen::MatrixXd& g, const std::vector<bool>& kept) {
  Eigen::MatrixXd out(std::count(kept.begin(), kept.end(), true), g.cols());
  for (Eigen::Index r = 0, k = 0; r < g.rows(); ++r)
    if (kept[std::size_t(r)]) out.row(k++) = g.row(r);
  return out;
}

// True when, at every pose, the rows kept are independent and every other row depends on them.
bool holdsAtEveryPose(const std::vector<Eigen::MatrixXd>& g, const std::vector<bool>& kept) {
  const int count = int(std::count(kept.begin(), kept.end(), true));
  for (const Eigen::MatrixXd& gs : g)
    if (absoluteRank(keptRowsOf(gs, kept)) != count || absoluteRank(gs) != count) return false;
  return true;
}

}  // namespace

std::vector<bool> chooseIndependentRows(ConstrainedMechanism<Spatial>& mech, const VecN& q0, const RowCandidates& rows,
                                        const std::string& where) {
  const std::vector<Eigen::MatrixXd> g = poses(mech, q0, rows);
  // The rows independent over every pose together: right for a loop whose plane stays put in the world
  // (the dependent combination of world rows is the same at every pose).
  std::vector<bool> kept = pivotRows(g);
  // A loop carried by moving bodies (a planar loop in a leg that the hip turns: Cassie's plantar rod) has
  // its dependent combination n(q)·φ ≡ 0 turning with them: over several poses every world row counts, so
  // the stacked choice keeps them all. Then the rows independent at q0 (the world rows least aligned with
  // n(q0)), checked at every pose: they hold while the loop's plane turns less than the angle that would
  // lay a dropped world axis in it (the run stops, naming the loop, if a dropped row drifts: EveryClosureRow).
  if (!holdsAtEveryPose(g, kept)) kept = pivotRows({g.front()});
  if (!holdsAtEveryPose(g, kept)) {
    // Name the closures involved: those with a dropped row.
    std::string names;
    for (std::size_t r = 0; r < kept.size(); ++r)
      if (!kept[r] && names.find("'" + rows.names[std::size_t(rows.closure[r])] + "'") == std::string::npos)
        names += std::string(names.empty() ? "" : ", ") + "'" + rows.names[std::size_t(rows.closure[r])] + "'";
    throw ModelFileError(where + ": the loop closure rows of " + (names.empty() ? std::string("the closures") : names) +
                         " depend on each other differently from pose to pose (a singular reference pose, or an over-constrained "
                         "spatial loop); write the file in a pose away from the singularity, or drop the redundant rows (a connect for a weld)");
  }
  return kept;
}

EveryClosureRow::EveryClosureRow(const LoadedModel& m) : model_(m.mechanism) {
  model_.constraints.clear();
  for (const auto& c : m.every_closure_row) {
    model_.constraints.push_back(c.rows);
    names_.push_back(c.name);
    std::string dropped;
    for (const auto& r : c.dropped) dropped += (dropped.empty() ? "" : " ") + r;
    dropped_.push_back(dropped);
  }
  if (!names_.empty()) mech_ = std::make_unique<ConstrainedMechanism<Spatial>>(model_);
}

double EveryClosureRow::residual(const VecN& q) { return mech_ ? mech_->residual(q) : 0.0; }

std::string EveryClosureRow::opened(const VecN& q) {
  for (std::size_t i = 0; mech_ && i < names_.size(); ++i)
    if (const double gap = mech_->residual(int(i), q); !(gap <= kDroppedRowDrift))
      return "loop closure '" + names_[i] + "' opened (|φ|∞ " + num(gap) + " over its rows, more than " + num(kDroppedRowDrift) +
             "): its dropped rows (" + (dropped_[i].empty() ? std::string("none") : dropped_[i]) +
             ") are not held by the rows kept at the reference pose here";
  return "";
}

}  // namespace dyn::model_file
