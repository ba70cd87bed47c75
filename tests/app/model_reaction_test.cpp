// The reaction force dynlab reports at the four-bar's pin C satisfies the Newton–Euler balance of the
// coupler, the body it joins to the rocker. The coupler hangs from the crank at B (an unknown hinge
// force F_B) and feels −f at C (f: the pin's force on the rocker, as reported) and its weight:
//   Newton:  F_B − f + m g = m a_c                      (gives F_B from the reported f)
//   Euler about B (moving):  [(c − B) × m g + (C − B) × (−f)]_y = I_c α₂ + [(c − B) × m a_c]_y
// and the crank, turning about its fixed pivot A, takes −F_B at B:
//   I_A α₁ = [(c₁ − A) × m₁ g + (B − A) × (−F_B)]_y
// Accelerations from planar rigid-body kinematics written here (not the engine's spatial algebra):
// exactly from the solve, and from `dynlab model`'s trace (q, v, f columns) by central differences.
#include <doctest/doctest.h>

#include <cmath>

#include "physics/constrained_mechanism.h"
#include "physics/model_file/model_file.h"
#include "tests/app/cli_run.h"

using namespace dyn;
using namespace dyn::test::cli;
using Vec3 = Eigen::Vector3d;

namespace {

const std::string kFile = std::string(DYNLAB_SOURCE_DIR) + "/assets/models/fourbar.xml";

// ŷ × r: a rate about the hinges' axis y turning the in-plane arm r.
Vec3 yCross(double w, const Vec3& r) { return Vec3(w * r.z(), 0, -w * r.x()); }

struct FourBar {
  model_file::LoadedModel file = model_file::load(kFile);
  ConstrainedMechanism<Spatial> mech{file.mechanism};
  double m1 = 0, m2 = 0, I_A = 0, I_c = 0;  // crank mass, coupler mass; crank about A, coupler about its centre
  Vec3 c1_body, c2_body, C_body;            // centres of mass and the pin in the bodies' frames
  Vec3 g;
  FourBar() {
    const auto& crank = file.mechanism.tree.bodies[0];
    const auto& coupler = file.mechanism.tree.bodies[1];
    Spatial::massAndCom(crank.inertia, m1, c1_body);
    Spatial::massAndCom(coupler.inertia, m2, c2_body);
    I_A = crank.inertia(1, 1);  // about the frame origin A, axis y
    I_c = coupler.inertia(1, 1) - m2 * (c2_body.x() * c2_body.x() + c2_body.z() * c2_body.z());
    C_body = file.closures.at(0).point1;
    REQUIRE(file.closures.at(0).link1 == 1);  // the pin is on the coupler
    g = file.mechanism.tree.gravity.tail<3>();
  }
  // Points at q.
  struct Pose {
    Vec3 B, c1, c2, C;
  };
  Pose at(const VecN& q) {
    return {mech.pointPosition(1, Vec3::Zero(), q), mech.pointPosition(0, c1_body, q), mech.pointPosition(1, c2_body, q),
            mech.pointPosition(1, C_body, q)};
  }
  // The coupler's centre velocity: A is fixed, the crank turns at v₀, the coupler at v₀ + v₁.
  Vec3 comVelocity(const VecN& q, const VecN& v) {
    const Pose p = at(q);
    return yCross(v[0], p.B) + yCross(v[0] + v[1], p.c2 - p.B);
  }
  // The coupler's and the crank's balance residuals (N·m), given the accelerations and the pin force f.
  std::pair<double, double> residuals(const VecN& q, double alpha1, double alpha2, const Vec3& a_c, const Vec3& f) {
    const Pose p = at(q);
    const Vec3 F_B = m2 * a_c - m2 * g + f;
    const double coupler = ((p.c2 - p.B).cross(m2 * g) - (p.C - p.B).cross(f)).y() - I_c * alpha2 - (p.c2 - p.B).cross(m2 * a_c).y();
    const double crank = (p.c1.cross(m1 * g) - p.B.cross(F_B)).y() - I_A * alpha1;
    return {coupler, crank};
  }
};

}  // namespace

TEST_CASE("the pin force from the solve balances the coupler and the crank (Newton–Euler, to rounding)") {
  FourBar fb;
  const VecN q0 = fb.file.q0;
  double worst = 0, scale = 0;
  for (double t : {0.0, 0.3, 0.7}) {
    // States along a passive swing (on the constraint manifold, J v = 0).
    VecN q = q0, v = VecN::Zero(3);
    StepOptions o;
    o.dt = 1e-3;
    for (int k = 0; k < int(std::lround(t / o.dt)); ++k) REQUIRE(step(fb.mech, o, VecN::Zero(3), q, v));
    const auto s = fb.mech.solve(q, v, VecN::Zero(3));
    const Vec3 f = Spatial::linear(fb.mech.constraintForce(0, s));
    // a_c = α₁ ŷ × (B − A) − ω₁² (B − A) + α₂ ŷ × (c − B) − ω₂² (c − B), ω₂ = v₀ + v₁.
    const auto p = fb.at(q);
    const double w1 = v[0], w2 = v[0] + v[1], a1 = s.qdd[0], a2 = s.qdd[0] + s.qdd[1];
    const Vec3 a_c = yCross(a1, p.B) - w1 * w1 * p.B + yCross(a2, p.c2 - p.B) - w2 * w2 * (p.c2 - p.B);
    const auto [coupler, crank] = fb.residuals(q, a1, a2, a_c, f);
    MESSAGE("t " << t << " s: |f| " << f.norm() << " N, coupler residual " << coupler << " N·m, crank residual " << crank << " N·m");
    worst = std::max({worst, std::abs(coupler), std::abs(crank)});
    scale = std::max(scale, f.norm() * (p.C - p.B).norm());
    // Without the pin's force the coupler does not balance: the check can fail.
    CHECK(std::abs(fb.residuals(q, a1, a2, a_c, Vec3::Zero()).first) > 1e-3);
  }
  CHECK(scale > 0.01);
  CHECK(worst < 1e-12 * std::max(1.0, scale));
}

TEST_CASE("the pin force in dynlab model's trace balances the coupler, with accelerations differenced from the trace") {
  // A 1 s passive run's trace: q, v and f_pin_C_x/z per 1 ms row. Accelerations by central
  // differences of the rates over ±h (α = (ω_{k+1} − ω_{k−1}) / 2h, a_c likewise from the centre's
  // velocity): error h²/6 · (third derivative), so the residual r_h is this truncation alone when the
  // force is right. Tolerance, from the trace itself: differencing over ±2h quadruples that error
  // (r_2h ≈ 4 r_h), so (r_2h − r_h)/3 estimates it and Richardson's (4 r_h − r_2h)/3 removes it,
  // leaving the O(h⁴) term, (hω)²/5 of the h² one for motion at ω rad/s: under 1 % while ω < 200
  // rad/s (the four-bar's fastest swing near its toggle pose is ~100), plus rounding (17 digits:
  // ~1e-13 / 2h). A force off by δ is no truncation: it leaves δ · |C − B| in r_h and r_2h alike,
  // so in the extrapolated residual whole; bounding that by 1e-5 of the largest |f| times |C − B|
  // bounds the reported force's error by 1e-5 of its size.
  TempDir dir("model_reaction");
  const Result r = dynlab(dir, {"model", kFile, "--engine", "hand", "--duration", "1", "--out", "out"});
  INFO(r.out, r.err);
  REQUIRE(r.code == 0);
  const Csv csv = readCsv(dir / "out/trace.csv");
  REQUIRE(csv.rows.size() == 1001);
  FourBar fb;
  const double h = csv.at(1, "t") - csv.at(0, "t");
  auto q = [&](std::size_t k) { return VecN(Eigen::Vector3d(csv.at(k, "q_crank"), csv.at(k, "q_coupler"), csv.at(k, "q_rocker"))); };
  auto v = [&](std::size_t k) { return VecN(Eigen::Vector3d(csv.at(k, "v_crank"), csv.at(k, "v_coupler"), csv.at(k, "v_rocker"))); };
  // The balance residuals at row k with differences over ±s rows.
  auto residual = [&](std::size_t k, std::size_t s, double wrong = 1.0) {
    const double span = 2.0 * double(s) * h;
    const VecN vp = v(k + s), vm = v(k - s);
    const double a1 = (vp[0] - vm[0]) / span, a2 = (vp[0] + vp[1] - vm[0] - vm[1]) / span;
    const Vec3 a_c = (fb.comVelocity(q(k + s), vp) - fb.comVelocity(q(k - s), vm)) / span;
    const Vec3 f = wrong * Vec3(csv.at(k, "f_pin_C_x"), 0.0, csv.at(k, "f_pin_C_z"));
    return fb.residuals(q(k), a1, a2, a_c, f);
  };
  const double lever = fb.C_body.norm();  // |C − B|: the pin from the coupler's hinge (its frame origin)
  double raw = 0, extrapolated = 0, force = 0, truncation = 0, off = 0;
  for (std::size_t k = 2; k + 2 < csv.rows.size(); ++k) {
    // The same with the reported force 1 % off: the check can fail.
    const auto [w1, wk1] = residual(k, 1, 1.01);
    const auto [w2, wk2] = residual(k, 2, 1.01);
    off = std::max({off, std::abs(4.0 * w1 - w2) / 3.0, std::abs(4.0 * wk1 - wk2) / 3.0});
    const auto [c1, k1] = residual(k, 1);
    const auto [c2, k2] = residual(k, 2);
    raw = std::max({raw, std::abs(c1), std::abs(k1)});
    truncation = std::max({truncation, std::abs(c2 - c1) / 3.0, std::abs(k2 - k1) / 3.0});  // Richardson's estimate of r_h
    extrapolated = std::max({extrapolated, std::abs(4.0 * c1 - c2) / 3.0, std::abs(4.0 * k1 - k2) / 3.0});
    force = std::max(force, std::hypot(csv.at(k, "f_pin_C_x"), csv.at(k, "f_pin_C_z")));
  }
  MESSAGE("coupler and crank balance over 1 s: |r_h| up to " << raw << " N·m (Richardson's estimate of its truncation "
                                                              << truncation << "), extrapolated " << extrapolated
                                                              << " N·m; |f| up to " << force << " N");
  MESSAGE("with the force 1 % off: extrapolated residual up to " << off << " N·m");
  CHECK(force > 1.0);
  CHECK(raw < 1.5 * truncation + 1e-9);       // the residual is the differences' truncation, no more
  CHECK(extrapolated < 1e-2 * truncation);    // once removed, what is left is O(h⁴)
  CHECK(extrapolated < 1e-5 * force * lever);  // the reported force is right to 1e-5 of its size
  CHECK(off > 1e-5 * force * lever);
}
