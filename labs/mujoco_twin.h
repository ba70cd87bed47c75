// A lab's mechanism written for MuJoCo (its "twin"): dynlab bench times MuJoCo's mj_step on it beside
// the hand engine and Bullet, and tests/labs/mujoco_twin_test checks that it is the lab's own mechanism
// (MuJoCo's M(q) and bias C(q, v) v + G(q) against the hand model's CRBA and RNEA). A C++ lab's file is
// labs/<name>/mujoco.xml, written from the lab's default parameters; a data lab's is its model file.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "physics/mechanism.h"
#include "physics/model_file/model_file.h"

namespace dyn {

struct MujocoTwin {
  // The model file, beside the lab's JSON ("mujoco.xml"); empty: the lab has none.
  std::string file;
  // A data lab's plant, already loaded from its own model file (then `file` is not read again).
  std::shared_ptr<const model_file::LoadedModel> loaded;
  // What MuJoCo cannot hold of the lab exactly and what the file holds instead (one clause; "" when nothing).
  std::string stands_in;
  // MuJoCo's run keeps the file's geom contacts (the lab's contact written as geoms; dynlab's loader
  // turns them off, its hand engine having no geom contact).
  bool contacts = false;
  // The file's coordinate i is the lab's coordinate order[i] (q and v alike); empty: the same order.
  std::vector<int> order;
  VecN q, v;  // the lab's start, in the lab's coordinates
  // The hand model's M(q) and bias C(q, v) v + G(q) in the lab's coordinates (null: not offered).
  std::function<void(const VecN& q, const VecN& v, MatN& M, VecN& bias)> dynamics;

  // The lab's q (or v) in the file's coordinates, and back.
  VecN toFile(const VecN& x) const;
  VecN fromFile(const VecN& x) const;
};

// The hand model's M and bias of a description: the trees' CRBA and RNEA (inverse dynamics at zero
// acceleration, no springs or friction), then each planar payload's diag(I, m, m) and −m g over its free
// coordinates (Newton–Euler at the centre of mass: no velocity terms).
template <class S>
std::function<void(const VecN&, const VecN&, MatN&, VecN&)> handDynamics(const MechanismModel<S>& description);

}  // namespace dyn
