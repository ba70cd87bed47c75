// The model files' planar linkages (the five-bar, the four-bar, the slider-crank: hinges about one
// world axis, placements that do not turn) take the planar kernels (physics/chain_planar_in_space.h),
// and step as the 6-D kernels step them to rounding: one step from every state of a two-second run
// from the file's pose, first order (semi-implicit Euler + Baumgarte, what `dynlab bench` times) and
// RK4; the whole run within 1e-11 (the five-bar's chaotic fall: within what a 1e-15 change of the
// pose makes of the 6-D run itself); at the end the same M, the same solve (θ'', η), energies, constraint forces and joint
// loads (3-D: the pins' out-of-plane reactions and the bearings' moments included).
#include <doctest/doctest.h>

#include <algorithm>

#include "physics/constrained_mechanism_impl.h"
#include "physics/model_file/model_file.h"
#include "tests/physics/model_file/fixtures.h"

using namespace dyn;
using dyn::test_model_file::model;

namespace {

// The same mechanism with the planar path turned off: the 6-D kernels (the old path).
template <class Mech>
struct SixD : Mech {
  explicit SixD(const MechanismModel<Spatial>& m) : Mech(m) { this->planar_.axis = -1; }
};

double relative(const VecN& a, const VecN& b) { return (a - b).lpNorm<Eigen::Infinity>() / (1.0 + b.lpNorm<Eigen::Infinity>()); }

template <class Mech>
void lockstep(const char* file, int axis) {
  INFO(file);
  const model_file::LoadedModel m = model_file::load(model(file));
  Mech planar(m.mechanism);
  SixD<Mech> old(m.mechanism);
  REQUIRE(planar.planeNormal() == axis);
  REQUIRE(old.planeNormal() == -1);
  for (Integrator integrator : {Integrator::SemiImplicitEuler, Integrator::RK4}) {
    INFO(int(integrator));
    StepOptions o;
    o.dt = m.timestep;
    o.integrator = integrator;
    if (integrator == Integrator::SemiImplicitEuler) o.drift.kind = Drift::Baumgarte;
    const VecN tau = VecN::Zero(planar.n());
    // Free runs side by side (planar, 6-D, and 6-D from the pose moved by 1e-15: how far rounding
    // alone carries a run), and one step of each from the planar run's every state (re-synced).
    VecN q1 = m.start_q, v1 = m.start_v, q2 = q1, v2 = v1, q3 = q1, v3 = v1;
    q3[0] += 1e-15;
    double dq = 0, dv = 0, d_ulp = 0, step_dq = 0, step_dv = 0, travel = 0;
    for (int k = 0; k < 2000; ++k) {
      VecN qs = q1, vs = v1;
      REQUIRE(step(planar, o, tau, q1, v1));
      REQUIRE(step(old, o, tau, qs, vs));
      step_dq = std::max(step_dq, (q1 - qs).lpNorm<Eigen::Infinity>());
      step_dv = std::max(step_dv, (v1 - vs).lpNorm<Eigen::Infinity>() / (1.0 + v1.lpNorm<Eigen::Infinity>()));
      REQUIRE(step(old, o, tau, q2, v2));
      REQUIRE(step(old, o, tau, q3, v3));
      dq = std::max(dq, (q1 - q2).lpNorm<Eigen::Infinity>());
      dv = std::max(dv, (v1 - v2).lpNorm<Eigen::Infinity>());
      d_ulp = std::max(d_ulp, (q3 - q2).lpNorm<Eigen::Infinity>());
      travel = std::max(travel, (q1 - m.start_q).lpNorm<Eigen::Infinity>());
    }
    MESSAGE(file << ": one step max |dq| " << step_dq << ", |dv| (relative) " << step_dv << "; run max |dq| " << dq
                 << ", |dv| " << dv << "; the 6-D run from q0 + 1e-15: max |dq| " << d_ulp);
    CHECK(travel > 0.1);  // it moved (a fall under gravity from rest)
    CHECK(step_dq < 1e-14);
    CHECK(step_dv < 1e-13);
    // Over the run: rounding level, or (the passive five-bar's fall, two degrees of freedom, is
    // chaotic) no further than rounding alone carries the 6-D run itself.
    CHECK(dq < std::max(1e-11, 10.0 * d_ulp));
    CHECK(dv < std::max(1e-11, 1e3 * d_ulp));
    // At the end, the one state: M, the solve, energies and the reactions in 3-D.
    CHECK((planar.massMatrix(q1) - old.massMatrix(q1)).norm() < 1e-14);
    const auto s1 = planar.solve(q1, v1, tau), s2 = old.solve(q1, v1, tau);
    CHECK(relative(VecN(s1.qdd), VecN(s2.qdd)) < 1e-12);
    CHECK(relative(VecN(s1.eta), VecN(s2.eta)) < 1e-12);
    CHECK(planar.kineticEnergy(q1, v1) == doctest::Approx(old.kineticEnergy(q1, v1)).epsilon(1e-13));
    CHECK(planar.potentialEnergy(q1) == old.potentialEnergy(q1));
    for (int c = 0; c < int(m.mechanism.constraints.size()); ++c) {
      const Spatial::Vec f1 = planar.constraintForce(c, s1), f2 = old.constraintForce(c, s2);
      CHECK((f1 - f2).norm() < 1e-12 * (1.0 + f2.norm()));
    }
    std::vector<Spatial::Vec> l1, l2;
    planar.jointLoads(q1, v1, s1, l1);
    old.jointLoads(q1, v1, s2, l2);
    for (std::size_t j = 0; j < l1.size(); ++j) CHECK((l1[j] - l2[j]).norm() < 1e-12 * (1.0 + l2[j].norm()));
  }
}

}  // namespace

TEST_CASE("the planar linkages' files take the planar kernels and step as the 6-D kernels, to rounding") {
  lockstep<ConstrainedMechanism<Spatial, 4, 2, 0>>("fivebar.xml", 1);  // the hand engine's (hand_engine.cpp)
  lockstep<ConstrainedMechanism<Spatial>>("fivebar.xml", 1);
  lockstep<ConstrainedMechanism<Spatial>>("fourbar.xml", 1);
  lockstep<ConstrainedMechanism<Spatial>>("slider_crank.xml", 2);
}

TEST_CASE("a spatial file does not take the planar path") {
  for (const char* file : {"puma560.urdf", "arm3d.xml"}) {
    INFO(file);
    const model_file::LoadedModel m = model_file::load(model(file));
    CHECK(ConstrainedMechanism<Spatial>(m.mechanism).planeNormal() == -1);
  }
}
