// Which rows of a model file's loop closures the description holds, and the check that the rows it
// drops stay closed. A closure's rows are world components (wx wy wz x y z) of its two anchors'
// relative motion; a loop in a plane has rows identically dependent on the others (a connect in the
// x-z plane: y ≡ 0; in a plane with normal n: n·φ ≡ 0). Holding them too would make G M⁻¹ Gᵀ
// singular, so they are dropped. Which rows are dependent is decided numerically, the same way in
// any orientation of the file:
//   Ĝ = D_r G D_c   translation rows ÷ L, slide columns × L (L: the model's extent at q0), so that
//                   every entry of Ĝ is O(1) whatever the units
//   poses           q0 and assembled poses near it (Gauss–Newton on every row, minimum-norm steps)
//   choice          greedy pivoting over [Ĝ(q0) Ĝ(q1) …]: the row with the largest part orthogonal
//                   to the rows kept so far, while that part exceeds an ABSOLUTE tolerance τ — a
//                   round-off row (1e-17) never counts, a real row (O(1), however few) always does.
//                   A loop whose plane turns with the bodies carrying it (a leg's planar linkage)
//                   has a dependent combination of world rows that changes with the pose: the
//                   stacked choice fails the check below, and the choice is made on Ĝ(q0) alone
//   check           at every pose, rank Ĝ_kept = rank Ĝ_all = the rows kept; otherwise which rows
//                   depend on which changes with the pose (a singular reference pose, an
//                   over-constrained spatial loop): refused, naming the loop
// A run reports |φ| over every row of every closure (EveryClosureRow) and stops when a dropped row
// drifts past kDroppedRowDrift (a choice that cannot hold further from q0).
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "physics/constrained_mechanism.h"
#include "physics/mechanism.h"
#include "physics/types.h"

namespace dyn::model_file {

struct LoadedModel;

// τ on Ĝ's rows' orthogonal parts (dimensionless): far above round-off (1e-15), far below a row that
// carries the loop (O(1), or at least the sine of the loop plane's tilt to a world axis).
inline constexpr double kIndependentRow = 1e-8;
// |φ|∞ a dropped row may reach in a run (m, rad) before the run stops: the projection holds kept rows
// to 1e-12, so a dropped row past this is a loop opening, not round-off.
inline constexpr double kDroppedRowDrift = 1e-9;

// The candidate rows of closures side by side (all of every closure's rows: mech), what each is, and
// the model's columns: which are slides.
struct RowCandidates {
  std::vector<bool> translation;  // per row of mech: a translation row (x y z), else a rotation row
  std::vector<int> closure;       // per row: which closure it belongs to
  std::vector<std::string> names; // per closure: its name, for messages
  std::vector<bool> slide;        // per coordinate: a slide (m), else a hinge (rad)
  double extent = 1;              // L (m)
};

// The rows kept (true) among mech's rows, by the choice above. Throws ModelFileError (prefixed by
// `where`) when the check fails.
std::vector<bool> chooseIndependentRows(ConstrainedMechanism<Spatial>& mech, const VecN& q0, const RowCandidates& rows,
                                        const std::string& where);

// Every row of every closure of a loaded model, dropped rows included (LoadedModel::every_closure_row).
class EveryClosureRow {
 public:
  explicit EveryClosureRow(const LoadedModel& m);
  bool empty() const { return names_.empty(); }
  // |φ|∞ over every row of every closure at q (0 without closures).
  double residual(const VecN& q);
  // "" while every closure holds within kDroppedRowDrift at q; else a sentence naming the first
  // closure that does not, its |φ|∞ and its dropped rows.
  std::string opened(const VecN& q);

 private:
  MechanismModel<Spatial> model_;
  std::unique_ptr<ConstrainedMechanism<Spatial>> mech_;
  std::vector<std::string> names_, dropped_;
};

}  // namespace dyn::model_file
