// The mechanism of a description (model_description.h): the tree rebuilt body by body through
// TreeModel's own addBody / addBall and then given the stored axis and inertia exactly, so that every
// double of the mechanism is the exported one; each constraint made by its kind's constructor. Every
// field checked: indices in range, sizes bounded by kMaxDof, rotations orthonormal, inertias physical.
#include <Eigen/Eigenvalues>
#include <cmath>

#include "labs/generic/model_description_json.h"
#include "physics/constraints/coupling.h"
#include "physics/constraints/joint_limit.h"
#include "physics/constraints/plane_contact.h"
#include "physics/constraints/point_closure.h"
#include "physics/constraints/rolling.h"

namespace dyn::app::description {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

double num(const JsonView& j, double lo, double hi) {
  const double x = j.number();
  if (!(x >= lo && x <= hi)) j.inRange(lo, hi);  // its one line: "expected a number in [lo, hi], got x"
  return x;
}

int index(const JsonView& j, int lo, int hi) {
  // (an unsigned integer past long long's range would wrap in integer())
  if (j.raw().is_number_unsigned() && j.raw().get<unsigned long long>() > static_cast<unsigned long long>(hi < 0 ? 0 : hi))
    j.fail("expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return int(j.integer(lo, hi));
}

std::string name(const JsonView& j) {
  const std::string s = j.string();
  if (s.size() > kMaxName) j.fail("expected a name of at most " + std::to_string(kMaxName) + " bytes");
  return s;
}

std::vector<std::string> names(const JsonView& j, std::size_t max) {
  std::vector<std::string> out;
  for (std::size_t i = 0, n = j.size(0, max); i < n; ++i) out.push_back(name(j.at(i)));
  return out;
}

VecN vector(const JsonView& j, std::size_t min, std::size_t max) {
  VecN v(Eigen::Index(j.size(min, max)));
  for (Eigen::Index i = 0; i < v.size(); ++i) v[i] = num(j.at(std::size_t(i)));
  return v;
}

namespace {

// A unit vector (within 1e-9) and a rotation (orthonormal, right-handed, within 1e-9).
Vec3 unit(const JsonView& j) {
  const Vec3 a = matrix<Vec3>(j);
  if (!(std::abs(a.norm() - 1) <= 1e-9)) j.fail("expected a unit vector (its length within 1e-9 of 1)");
  return a;
}
Mat3 rotation(const JsonView& j) {
  const Mat3 E = matrix<Mat3>(j);
  if (!((E.transpose() * E - Mat3::Identity()).cwiseAbs().maxCoeff() <= 1e-9) || !(E.determinant() > 0))
    j.fail("expected a rotation matrix (9 numbers row by row, orthonormal within 1e-9, determinant +1)");
  return E;
}

// A 6×6 spatial inertia at the body's origin (moment rows first) that a body can have: symmetric, its
// mass m ≥ 0 on the force block's diagonal, positive semidefinite, and the moments about the centre of
// mass meeting the triangle inequality.
Spatial::Mat inertia(const JsonView& j) {
  const Spatial::Mat I = matrix<Spatial::Mat>(j);
  const double scale = 1 + I.cwiseAbs().maxCoeff(), tol = 1e-9 * scale;
  const double m = I(5, 5);
  bool ok = (I - I.transpose()).cwiseAbs().maxCoeff() <= tol && m >= 0 && std::abs(I(3, 3) - m) <= tol && std::abs(I(4, 4) - m) <= tol;
  if (ok) {
    Eigen::SelfAdjointEigenSolver<Spatial::Mat> all(0.5 * (I + I.transpose()), Eigen::EigenvaluesOnly);
    ok = all.eigenvalues().minCoeff() >= -tol;
  }
  if (ok && m > 0) {
    const Mat3 B = I.block<3, 3>(0, 3), Ic = I.block<3, 3>(0, 0) - B * B.transpose() / m;
    Eigen::SelfAdjointEigenSolver<Mat3> c(0.5 * (Ic + Ic.transpose()), Eigen::EigenvaluesOnly);
    const Vec3 p = c.eigenvalues();  // ascending
    ok = p[0] >= -tol && p[0] + p[1] >= p[2] - 1e-6 * scale;
  }
  if (!ok)
    j.fail("expected a body's spatial inertia (36 numbers, row by row: symmetric, mass m ≥ 0 on the force block's diagonal, positive "
           "semidefinite, principal moments about the centre of mass meeting the triangle inequality)");
  return I;
}

JointType jointType(const JsonView& j) {
  const std::string t = j.oneOf({"revolute", "prismatic", "ball"});
  return t == "revolute" ? JointType::Revolute : t == "prismatic" ? JointType::Prismatic : JointType::Ball;
}

// The stored body's own numbers over what addBody / addBall made (they normalise the axis once more).
void setBody(TreeModel<Spatial>& tree, int i, const Vec3& axis, const Spatial::Mat& I) {
  auto& b = tree.bodies[std::size_t(i)];
  b.axis = axis;
  b.subspace = tree.motionSubspace(i);
  TreeModel<Spatial>::markCoordinateAxis(b);
  b.inertia = I;
  b.central = Spatial::central(I);
  b.massless = Spatial::massless(I);
}

// A ball's three bodies first..first+2 (first carries the placement, the last the inertia).
void addBall(TreeModel<Spatial>& tree, const JsonView& bodies, const JsonView& ball, int first, int parent, const Spatial::Transform& X) {
  const int n = int(bodies.size());
  if (first + 2 >= n) ball["first"].fail("expected a ball joint's first of three bodies (bodies " + std::to_string(first) + " to " + std::to_string(first + 2) + ")");
  for (int k = 1; k < 3; ++k) {
    const JsonView b = bodies.at(std::size_t(first + k));
    if (jointType(b["joint"]) != JointType::Ball || index(b["parent"], -1, n) != first + k - 1 ||
        !(matrix<Mat3>(b["E"]) == Mat3::Identity()) || !(matrix<Vec3>(b["r"]) == Vec3::Zero()))
      b.fail("expected a ball joint's body " + std::to_string(k + 1) + " of 3: joint \"ball\", parent the body before, E the identity, r zero");
  }
  const Mat3 pre = rotation(ball["pre"]), post = rotation(ball["post"]);
  tree.addBall(parent, X, pre, post, Spatial::Mat::Zero());
  tree.balls.back().pre = pre, tree.balls.back().post = post;
}

TreeModel<Spatial> readTree(const JsonView& t, int nq) {
  t.onlyKeys({"gravity", "bodies", "balls"});
  TreeModel<Spatial> tree;
  const JsonView bodies = t["bodies"], balls = t["balls"];
  const int n = int(bodies.size(1, kMaxDof)), nballs = int(balls.size(0, kMaxDof / 3));
  int next_ball = 0, ball_left = 0;  // the balls read, and the bodies of the current one still to come
  for (int i = 0; i < n; ++i) {
    const JsonView b = bodies.at(std::size_t(i));
    b.onlyKeys({"parent", "joint", "axis", "E", "r", "inertia"});
    const int parent = index(b["parent"], -1, i - 1);
    const JointType type = jointType(b["joint"]);
    const Vec3 axis = unit(b["axis"]);
    const Spatial::Transform X{rotation(b["E"]), matrix<Vec3>(b["r"]), true};
    const Spatial::Mat I = inertia(b["inertia"]);
    if (ball_left > 0) {
      --ball_left;  // made with its ball's first body (addBall checked it)
    } else if (type == JointType::Ball) {
      // A ball's first body: the next ball of /balls starts here.
      if (next_ball >= nballs) balls.fail("expected a ball joint (first, pre, post) for each ball's three bodies; body " + std::to_string(i) + " starts one more");
      const JsonView ball = balls.at(std::size_t(next_ball++));
      ball.onlyKeys({"first", "pre", "post"});
      if (index(ball["first"], 0, n - 1) != i) ball["first"].fail("expected the index of the ball's first body, " + std::to_string(i));
      addBall(tree, bodies, ball, i, parent, X);
      ball_left = 2;
    } else {
      tree.addBody(parent, type, axis, X, Spatial::Mat::Zero());
    }
    setBody(tree, i, axis, I);
  }
  if (next_ball != nballs) balls.fail("expected one entry per ball joint of /mechanism/tree/bodies (" + std::to_string(next_ball) + ")");
  if (tree.nq() != nq) bodies.fail("expected a tree whose coordinates match /q0's " + std::to_string(nq) + " (these bodies make " + std::to_string(tree.nq()) + ")");
  tree.gravity = matrix<Spatial::Vec>(t["gravity"]);
  return tree;
}

BodyRef link(const JsonView& j, int dof, bool world) {
  const int i = index(j, world ? -1 : 0, dof - 1);
  return i < 0 ? BodyRef::world() : BodyRef::link(i);
}

Coupling::Form form(const JsonView& j, int dof, std::size_t min) {
  Coupling::Form f;
  for (std::size_t i = 0, n = j.size(min, kMaxDof); i < n; ++i) {
    const JsonView t = j.at(i);
    t.onlyKeys({"joint", "coef"});
    f.push_back({index(t["joint"], 0, dof - 1), num(t["coef"])});
  }
  return f;
}

}  // namespace

namespace {

ConstraintPtr<Spatial> makeConstraint(const JsonView& j, const TreeModel<Spatial>& tree, int nq) {
  const int dof = tree.dof();
  const std::string kind = j["kind"].oneOf({"point_closure", "joint_limit", "joint_coupling", "tendon_coupling", "rolling", "plane_contact"});
  if (kind == "point_closure") {
    j.onlyKeys({"kind", "a", "point_a", "b", "point_b", "rows"});
    PointClosure<Spatial>::Rows rows{};
    int count = 0;
    for (std::size_t k = 0, n = j["rows"].size(6, 6); k < n; ++k) count += rows[k] = j["rows"].at(k).boolean();
    if (count == 0) j["rows"].fail("expected at least one row held (six booleans: wx wy wz x y z)");
    const BodyRef a = link(j["a"], dof, true), b = link(j["b"], dof, true);
    if (a == b) j["b"].fail("expected a body other than a (a closure ties two bodies)");
    return std::make_shared<PointClosure<Spatial>>(a, matrix<Vec3>(j["point_a"]), b, matrix<Vec3>(j["point_b"]), rows);
  }
  if (kind == "joint_limit") {
    j.onlyKeys({"kind", "joint", "parent", "side", "bound"});
    const int joint = index(j["joint"], 0, dof - 1);
    if (index(j["parent"], -1, dof - 1) != tree.bodies[std::size_t(joint)].parent)
      j["parent"].fail("expected the joint's parent in the tree (" + std::to_string(tree.bodies[std::size_t(joint)].parent) + ")");
    const auto side = j["side"].oneOf({"lower", "upper"}) == std::string("lower") ? JointLimit::Side::Lower : JointLimit::Side::Upper;
    return std::make_shared<JointLimit>(joint, tree.bodies[std::size_t(joint)].parent, side, num(j["bound"]));
  }
  if (kind == "joint_coupling" || kind == "tendon_coupling") {
    j.onlyKeys({"kind", "first", "second", "poly", "reference"});
    const std::array<double, 5> poly = [&] {
      const auto v = matrix<Eigen::Matrix<double, 5, 1>>(j["poly"]);
      return std::array<double, 5>{v[0], v[1], v[2], v[3], v[4]};
    }();
    const VecN reference = vector(j["reference"], std::size_t(nq), std::size_t(nq));
    return std::make_shared<Coupling>(kind == "joint_coupling" ? "joint_coupling" : "tendon_coupling", form(j["first"], dof, 1),
                                      form(j["second"], dof, 0), poly, reference);
  }
  if (kind == "rolling") {
    j.onlyKeys({"kind", "wheel", "centre", "axle", "radius", "ground", "mu"});
    return std::make_shared<Rolling>(link(j["wheel"], dof, false), matrix<Vec3>(j["centre"]), unit(j["axle"]), num(j["radius"], 1e-6, 1e3),
                                     num(j["ground"], -1e6, 1e6), num(j["mu"], 0, 10));
  }
  j.onlyKeys({"kind", "body", "centre", "normal", "radius", "height", "mu", "stiffness", "damping"});
  const PlaneContactParams p{num(j["radius"], 0, 1e3), num(j["height"], -1e6, 1e6), num(j["mu"], 0, 10), num(j["stiffness"], 0, 1e9),
                             num(j["damping"], 0, 1e9)};
  return std::make_shared<PlaneContact<Spatial>>(link(j["body"], dof, false), matrix<Vec3>(j["centre"]), unit(j["normal"]), p);
}

}  // namespace

// Each kind's constructor checks what it needs too: its refusal, at the constraint's path.
ConstraintPtr<Spatial> readConstraint(const JsonView& j, const TreeModel<Spatial>& tree, int nq) {
  try {
    return makeConstraint(j, tree, nq);
  } catch (const std::invalid_argument& e) {
    j.fail(std::string("expected a constraint its kind can hold (") + e.what() + ")");
  }
}

MechanismModel<Spatial> readMechanism(const JsonView& j, int nq) {
  j.onlyKeys({"tree", "joints", "constraints", "bullet"});
  MechanismModel<Spatial> mech;
  mech.tree = readTree(j["tree"], nq);
  const int dof = mech.tree.dof();
  const JsonView joints = j["joints"];
  const std::size_t nj = joints.size(0, std::size_t(dof));
  if (nj != 0 && int(nj) != dof) joints.fail("expected none, or one entry per tree body (" + std::to_string(dof) + ")");
  for (std::size_t i = 0; i < nj; ++i) {
    const JsonView p = joints.at(i);
    p.onlyKeys({"stiffness", "rest", "viscous", "coulomb", "coulomb_width", "armature"});
    JointProperties q;
    q.stiffness = num(p["stiffness"]), q.rest = num(p["rest"]), q.viscous = num(p["viscous"], 0, kLargest);
    q.coulomb = num(p["coulomb"], 0, kLargest), q.coulomb_width = num(p["coulomb_width"], 1e-12, kLargest), q.armature = num(p["armature"], 0, kLargest);
    mech.joints.push_back(q);
  }
  const JsonView cs = j["constraints"];
  for (std::size_t i = 0, n = cs.size(0, 4 * kMaxDof); i < n; ++i) mech.constraints.push_back(readConstraint(cs.at(i), mech.tree, nq));
  if (mech.rows() > kMaxDof) cs.fail("expected at most " + std::to_string(kMaxDof) + " constraint rows in all (these make " + std::to_string(mech.rows()) + ")");
  const JsonView b = j["bullet"];
  b.onlyKeys({"cut_joints", "solver_iterations", "rolling"});
  for (std::size_t i = 0, n = b["cut_joints"].size(0, std::size_t(dof)); i < n; ++i) mech.bullet.cut_joints.push_back(index(b["cut_joints"].at(i), 0, dof - 1));
  mech.bullet.solver_iterations = index(b["solver_iterations"], 1, 10000);
  mech.bullet.rolling = b["rolling"].oneOf({"no_slip", "friction"}) == std::string("no_slip") ? RollingModel::NoSlip : RollingModel::Friction;
  if (const std::string why = mech.validate(); !why.empty()) j.fail("expected a mechanism dynlab can run (" + why + ")");
  return mech;
}

}  // namespace dyn::app::description
