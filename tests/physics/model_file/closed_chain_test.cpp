// physics/closed_chain.h on the five-bar of assets/models/fivebar.xml (here because it loads a model
// file), against references that do not share its method:
//  * assembly closes the loop to 1e-13 from the actuators moved away from the file's pose;
//  * S against central differences of assembled poses (θ(u + ε e_j) − θ(u − ε e_j)) / 2ε;
//  * M_u u'' + h_u = τ_u against the full constrained solve of eq. (2) with τ = (τ_u, 0): θ'' = S u'' + c;
//  * x'' = J_x u'' + bias against the full solve's θ'' through the point's own Jacobian, and Λ through
//    the solve: τ_u = J_xᵀ F + h_u gives x'' − bias = Λ⁻¹ F;
//  * a configuration with the distal links in line is reported singular.
#include <doctest/doctest.h>

#include <random>

#include "physics/closed_chain.h"
#include "physics/constrained_mechanism.h"
#include "physics/model_file/model_file.h"

using namespace dyn;

namespace {

using Mech = ConstrainedMechanism<Spatial>;

struct FiveBar {
  model_file::LoadedModel file = model_file::load(std::string(DYNLAB_SOURCE_DIR) + "/assets/models/fivebar.xml");
  Mech mech{file.mechanism};
  // Actuated: the two cranks (coordinates 0 and 2 in the file's order left_crank, left_elbow, ...).
  std::vector<int> act{0, 2};
  // The loop closed with the cranks turned by (a, b) from the file's pose.
  VecN pose(double a, double b) {
    VecN q = file.q0;
    q[0] += a, q[2] += b;
    REQUIRE(assemble(mech, q, act));
    return q;
  }
};

}  // namespace

TEST_CASE("assembly closes the five-bar from a guess, holding the actuators") {
  FiveBar f;
  REQUIRE(f.file.joints.size() == 4);
  CHECK(f.file.joints[0].name == "left_crank");
  CHECK(f.file.joints[2].name == "right_crank");
  VecN q = f.file.q0;
  q[0] += 0.2, q[2] -= 0.15;
  REQUIRE(assemble(f.mech, q, f.act));
  CHECK(f.mech.residual(q) <= 1e-13);
  CHECK(q[0] == f.file.q0[0] + 0.2);
  CHECK(q[2] == f.file.q0[2] - 0.15);
  // The left crank turned back 2 rad: its elbow is 0.61 m from the right one, the distal links reach 0.57 m.
  VecN far = f.file.q0;
  far[0] -= 2.0;
  CHECK_FALSE(assemble(f.mech, far, f.act));
}

TEST_CASE("S, M_u, h_u, J_x and Λ of the five-bar against the full constrained solve") {
  FiveBar f;
  ClosedChain<Mech> chain(f.mech, f.act);
  std::mt19937_64 rng(31);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 5; ++trial) {
    const double a = 0.3 * u(rng), b = 0.3 * u(rng);
    const VecN q = f.pose(a, b);
    Eigen::Vector2d ud(2.0 * u(rng), 2.0 * u(rng));
    REQUIRE(chain.update(q, VecN::Zero(4)));
    const VecN v = chain.S() * ud;
    REQUIRE(chain.update(q, v));
    // S by central differences of assembled poses.
    const double eps = 1e-6;
    MatN Sfd(4, 2);
    Sfd.col(0) = (f.pose(a + eps, b) - f.pose(a - eps, b)) / (2 * eps);
    Sfd.col(1) = (f.pose(a, b + eps) - f.pose(a, b - eps)) / (2 * eps);
    CHECK((Sfd - chain.S()).cwiseAbs().maxCoeff() < 1e-7);
    // The velocity is admissible: J θ' = 0.
    VecN phi;
    MatN G;
    f.mech.constraint(q, phi, G);
    CHECK((G * v).cwiseAbs().maxCoeff() < 1e-12);
    // Reduced dynamics against the full solve with τ = (τ_u on the cranks, 0 on the elbows).
    const Eigen::Vector2d tau_u(3.0 * u(rng), 3.0 * u(rng));
    VecN tau = VecN::Zero(4), full;
    tau[0] = tau_u[0], tau[2] = tau_u[1];
    f.mech.accelerations(q, v, tau, nullptr, full);
    const VecN udd = chain.Mu().ldlt().solve(tau_u - chain.hu());
    const VecN reduced = chain.S() * udd + chain.c();
    CHECK((reduced - full.head(4)).cwiseAbs().maxCoeff() < 1e-10);
    // Gravity alone: at rest, τ_u = G_u holds the chain still.
    VecN hold = VecN::Zero(4), still;
    hold[0] = chain.Gu()[0], hold[2] = chain.Gu()[1];
    f.mech.accelerations(q, VecN::Zero(4), hold, nullptr, still);
    CHECK(still.head(4).cwiseAbs().maxCoeff() < 1e-10);
    // The pin C (on left_link, 0.2 m along it in the file) in x and z.
    const auto& pin = f.file.closures[0];
    Spatial::Pos x;
    MatN Jx;
    VecN bias;
    chain.task(pin.link1, pin.point1, {3, 5}, x, Jx, bias);
    MatN Jp;
    VecN Jdot;
    f.mech.pointJacobian(pin.link1, pin.point1, q, v, Jp, Jdot);
    const VecN xdd_full = Jp * full.head(4) + Jdot;
    CHECK(std::abs(Jx.row(0).dot(udd) + bias[0] - xdd_full[3]) < 1e-10);
    CHECK(std::abs(Jx.row(1).dot(udd) + bias[1] - xdd_full[5]) < 1e-10);
    // Λ through the solve: τ_u = J_xᵀ F + h_u accelerates the pin by x'' = Λ⁻¹ F + bias.
    const MatN L = chain.taskInertia(Jx);
    REQUIRE(L.rows() == 2);
    const Eigen::Vector2d F(1.5 * u(rng), 1.5 * u(rng));
    const VecN tf = Jx.transpose() * F + chain.hu();
    VecN tau_f = VecN::Zero(4), acc;
    tau_f[0] = tf[0], tau_f[2] = tf[1];
    f.mech.accelerations(q, v, tau_f, nullptr, acc);
    const VecN xa = Jp * acc.head(4) + Jdot;
    const Eigen::Vector2d got(xa[3] - bias[0], xa[5] - bias[1]);
    CHECK((got - L.ldlt().solve(F)).cwiseAbs().maxCoeff() < 1e-9);
  }
}

TEST_CASE("the five-bar with its distal links in line is a singular configuration") {
  FiveBar f;
  ClosedChain<Mech> chain(f.mech, f.act);
  // Turning the left crank back stretches the distal links until they line up (|BD| = 2 × 0.283 m);
  // past that the loop cannot close. Bisect the crank angle to that edge: J_w's smallest singular
  // value goes to zero there (as the square root of the distance), and the chain says so.
  auto closes = [&](double a, VecN& q) {
    q = f.file.q0;
    q[0] += a;
    return assemble(f.mech, q, f.act, 1e-13, 200);
  };
  auto smallest = [&](const VecN& q) {
    VecN phi;
    MatN G;
    f.mech.constraint(q, phi, G);
    MatN Jw(G.rows(), 2);
    Jw.col(0) = G.col(1), Jw.col(1) = G.col(3);
    return Eigen::JacobiSVD<MatN>(Jw).singularValues().minCoeff();
  };
  VecN q;
  double in = 0.0, out = -2.0;
  REQUIRE(closes(in, q));
  REQUIRE_FALSE(closes(out, q));
  const double s0 = smallest(f.file.q0);
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (in + out);
    (closes(mid, q) ? in : out) = mid;
  }
  REQUIRE(closes(in, q));
  CHECK(s0 > 0.05);
  CHECK(smallest(q) < 1e-4 * s0);
  CHECK_FALSE(chain.update(q, VecN::Zero(4)));
}
