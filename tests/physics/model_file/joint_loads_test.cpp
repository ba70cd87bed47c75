// ConstrainedMechanism::jointLoads (the load each joint carries) against references that do not use it:
//  * on every joint of the five-bar at random states and torques, the load's part along the joint's
//    axis is the joint's torque net of spring and friction (the solve's τ: this checks the constraint
//    forces are taken off with the right sign and point);
//  * the Newton–Euler balance of the link the pin closes on (a leaf): joint load + pin force + m g =
//    m a_c, a_c = J_c θ'' + J_c'θ' from the point Jacobian of its centre of mass;
//  * an open arm falling from rest: the base joint carries Σ m_k (a_c,k − g).
#include <doctest/doctest.h>

#include <random>

#include "physics/constrained_mechanism.h"
#include "physics/model_file/model_file.h"

using namespace dyn;

namespace {

using Mech = ConstrainedMechanism<Spatial>;

// a_c and m of link k's centre of mass at the solution.
Eigen::Vector3d comAcceleration(Mech& m, int k, const VecN& q, const VecN& v, const VecN& qdd, double& mass) {
  Eigen::Vector3d c;
  Spatial::massAndCom(m.model().tree.bodies[std::size_t(k)].inertia, mass, c);
  MatN J;
  VecN jd;
  m.pointJacobian(k, c, q, v, J, jd);
  return (J * qdd + jd).tail<3>();
}

// The power of a spatial force at the world origin through joint i's unit motion: its axial part.
double axial(Mech& m, int i, const VecN& q, const Spatial::Vec& f) {
  MatN J;
  VecN jd;
  const Eigen::Vector3d p = m.pointPosition(i, Eigen::Vector3d::Zero(), q);
  m.pointJacobian(i, Eigen::Vector3d::Zero(), q, VecN::Zero(q.size()), J, jd);
  const Eigen::Vector3d n_p = f.head<3>() - p.cross(f.tail<3>());  // the moment about the joint's anchor
  return J.col(i).head<3>().dot(n_p) + J.col(i).tail<3>().dot(f.tail<3>());
}

}  // namespace

TEST_CASE("joint loads on the five-bar: axial parts are the joint torques, the pinned link balances") {
  const auto file = model_file::load(std::string(DYNLAB_SOURCE_DIR) + "/labs/fivebar/fivebar.xml");
  Mech m(file.mechanism);
  const int n = m.n();
  const auto at = file.mechanism.constraints[0]->attachment();
  REQUIRE(at.b.kind == BodyRef::Kind::Link);
  const int leaf = at.b.index;
  for (const auto& b : file.mechanism.tree.bodies) REQUIRE(b.parent != leaf);  // nothing hangs from it
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int trial = 0; trial < 5; ++trial) {
    const VecN q = file.q0;  // assembled: the loop holds
    VecN v(n), tau(n);
    // Rates the loop allows: a null-space direction of its Jacobian.
    VecN phi;
    MatN G;
    m.constraint(q, phi, G);
    const MatN N = Eigen::FullPivLU<MatN>(G.leftCols(n)).kernel();
    v = N * VecN::NullaryExpr(N.cols(), [&] { return u(rng); });
    for (int i = 0; i < n; ++i) tau[i] = 5 * u(rng);
    const auto s = m.solve(q, v, tau);
    std::vector<Spatial::Vec> loads;
    m.jointLoads(q, v, s, loads);
    REQUIRE(int(loads.size()) == n);
    for (int i = 0; i < n; ++i) {
      const auto& jp = file.mechanism.joints.empty() ? JointProperties{} : file.mechanism.joints[std::size_t(i)];
      const double net = tau[i] - jp.friction(v[i]) - jp.stiffness * (q[i] - jp.rest);
      CHECK(axial(m, i, q, loads[std::size_t(i)]) == doctest::Approx(net).epsilon(1e-9));
    }
    // The leaf's Newton–Euler balance (forces): joint load + pin force (a on b) + m g = m a_c.
    double mass = 0;
    const Eigen::Vector3d a_c = comAcceleration(m, leaf, q, v, s.qdd, mass);
    const Eigen::Vector3d g = file.mechanism.tree.gravity.tail<3>();
    const Eigen::Vector3d pin = m.constraintForce(0, s).tail<3>();
    const Eigen::Vector3d balance = loads[std::size_t(leaf)].tail<3>() + pin + mass * g - mass * a_c;
    CHECK(balance.norm() < 1e-9 * (1 + mass * g.norm()));
    CHECK(loads[std::size_t(leaf)].tail<3>().norm() > 0.1);  // a real load, not a vacuous balance
  }
}

TEST_CASE("joint loads on an open arm falling from rest: the base carries Σ m (a_c − g)") {
  const auto file = model_file::load(std::string(DYNLAB_SOURCE_DIR) + "/assets/models/planar_arm.urdf");
  Mech m(file.mechanism);
  const int n = m.n();
  const VecN q = (VecN(n) << 0.3, 0.6, -0.4).finished(), v = VecN::Zero(n), tau = VecN::Zero(n);
  const auto s = m.solve(q, v, tau);
  std::vector<Spatial::Vec> loads;
  m.jointLoads(q, v, s, loads);
  const Eigen::Vector3d g = file.mechanism.tree.gravity.tail<3>();
  Eigen::Vector3d need = Eigen::Vector3d::Zero();
  for (int k = 0; k < n; ++k) {
    double mass = 0;
    const Eigen::Vector3d a_c = comAcceleration(m, k, q, v, s.qdd, mass);
    need += mass * (a_c - g);
  }
  CHECK((loads[0].tail<3>() - need).norm() < 1e-10 * need.norm());
  CHECK(need.norm() > 1.0);
  // Free fall with no torque: no joint carries anything about its own axis.
  for (int i = 0; i < n; ++i) CHECK(std::abs(axial(m, i, q, loads[std::size_t(i)])) < 1e-10);
}
