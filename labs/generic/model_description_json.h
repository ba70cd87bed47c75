// The description reader's checked pieces (model_description_read.cpp: the mechanism; model_description.cpp:
// the rest of a LoadedModel): each reads one JSON value through a JsonView, so a malformed field is one
// line naming the file, its JSON path and what was expected (InputError).
#pragma once
#include <string>
#include <vector>

#include "labs/config.h"
#include "physics/mechanism.h"

namespace dyn::app::description {

// Every number of a description lies within ±kLargest (as a model file's: model_file.cpp's checkNumbers).
inline constexpr double kLargest = 1e9;
// A name at most this long; a list of notes or names at most kMaxItems long.
inline constexpr std::size_t kMaxName = 4096, kMaxItems = 100000;

double num(const JsonView& j, double lo = -kLargest, double hi = kLargest);
int index(const JsonView& j, int lo, int hi);  // an integer in [lo, hi]
std::string name(const JsonView& j);
std::vector<std::string> names(const JsonView& j, std::size_t max = kMaxItems);
// A fixed-size array of numbers (within ±kLargest), row by row.
template <class M>
M matrix(const JsonView& j) {
  M m;
  j.size(std::size_t(m.size()), std::size_t(m.size()));
  for (Eigen::Index r = 0, k = 0; r < m.rows(); ++r)
    for (Eigen::Index c = 0; c < m.cols(); ++c) m(r, c) = num(j.at(std::size_t(k++)));
  return m;
}
// A list of numbers of length in [min, max] (≤ kMaxDof: a VecN).
VecN vector(const JsonView& j, std::size_t min, std::size_t max);

// The tree, joint properties, constraints and Bullet hints (/mechanism), checked: q's size nq.
MechanismModel<Spatial> readMechanism(const JsonView& j, int nq);
// One constraint of a tree with `dof` bodies (closures, limits, couplings, wheels, contacts).
ConstraintPtr<Spatial> readConstraint(const JsonView& j, const TreeModel<Spatial>& tree, int nq);

}  // namespace dyn::app::description
