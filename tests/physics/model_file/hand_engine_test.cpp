// The hand engine for files with elements at fixed sizes (physics/model_file/hand_engine.h SixJoints:
// six joints fixed, the rows dynamic, the closed rows alone solved) steps the PUMA 560's file with its
// twelve joint-limit rows exactly as the dynamically sized mechanism does, bit for bit, through a run
// that falls onto a stop (a row closed, its impact, the lift-off checks) and with every row open; and
// the solve on the closed rows alone (compacted: J̃, J'θ' and the Baumgarte term of those rows only;
// the closed limits' coordinates eliminated, constrained_solve.h factorLocked) gives what the Schur
// solve over all twelve rows gives with the open ones zeroed at unit compliance, to rounding; and
// the limits' rows computed in place (only limits: J constant) give what their own position() gives.
#include <doctest/doctest.h>

#include "physics/constrained_mechanism_impl.h"
#include "physics/model_file/actuators.h"
#include "physics/model_file/hand_engine.h"
#include "physics/model_file/model_file.h"
#include "tests/physics/model_file/fixtures.h"

using namespace dyn;
using dyn::test_model_file::model;

namespace {
// Steps two mechanisms side by side from the PUMA file's pose (contacts updated, touchdowns located),
// requiring the same rows closed and the same (q, v) at every step, bit for bit (tolerance 0) or to
// within tolerance (|Δ|∞); with solutions, also the same η (over every row) and θ'' solved there (to
// tolerance × their size). Returns how many steps ended with a row closed.
template <class A, class B>
int lockstep(const model_file::LoadedModel& m, Integrator integrator, A& a, B& b, bool solutions, double tolerance = 0.0) {
  StepOptions o;
  o.dt = m.timestep;
  o.integrator = integrator;
  if (integrator == Integrator::SemiImplicitEuler) o.drift.kind = Drift::Baumgarte;
  const VecN tau = VecN::Zero(6);
  VecN q1 = m.start_q, v1 = m.start_v, q2 = q1, v2 = v1;
  int closed_steps = 0;
  for (int k = 0; k < 1500; ++k) {
    a.updateContacts(q1, v1, tau);
    b.updateContacts(q2, v2, tau);
    REQUIRE(a.stepLocatingContacts(o, tau, q1, v1));
    REQUIRE(b.stepLocatingContacts(o, tau, q2, v2));
    bool any = false;
    for (int i = 0; i < 12; ++i) {
      REQUIRE(a.closed(i) == b.closed(i));
      any = any || a.closed(i);
    }
    closed_steps += any;
    auto near = [&](const VecN& x, const VecN& y, double scale) {
      return tolerance == 0.0 ? x == y : (x - y).lpNorm<Eigen::Infinity>() <= tolerance * scale;
    };
    REQUIRE(near(q1, q2, 1.0));
    REQUIRE(near(v1, v2, 1.0));
    if (!solutions) continue;
    const auto s1 = a.solve(q1, v1, tau);
    const auto s2 = b.solve(q2, v2, tau);
    REQUIRE(s1.eta.size() == 12);
    REQUIRE(near(VecN(s1.eta), VecN(s2.eta), 1.0 + VecN(s2.eta).lpNorm<Eigen::Infinity>()));  // 0 on the open rows
    REQUIRE(near(VecN(s1.qdd), VecN(s2.qdd), 1.0 + VecN(s2.qdd).lpNorm<Eigen::Infinity>()));
    if (tolerance > 0.0)
      for (int i = 0; i < 12; ++i)
        if (!a.closed(i)) REQUIRE(s1.eta[i] == 0.0);
  }
  return closed_steps;
}
}  // namespace

TEST_CASE("the six-joint engine with limits steps the PUMA file as the dynamically sized mechanism, bit for bit") {
  const model_file::LoadedModel m = model_file::load(model("puma560.urdf"));
  REQUIRE(model_file::sixJointsFixed(m.mechanism));
  REQUIRE(m.contacts.size() == 12);  // both sides of six joints
  for (Integrator integrator : {Integrator::SemiImplicitEuler, Integrator::RK4}) {
    INFO(int(integrator));
    model_file::DrivenMechanism dynamic(m);
    model_file::DrivenMechanismT<model_file::SixJoints> sized(m);
    const int closed_steps = lockstep(m, integrator, dynamic, sized, false);
    CHECK(closed_steps > 100);         // it came to rest on a stop
    CHECK(closed_steps < 1500);        // and fell freely before
    CHECK(dynamic.impactLoss() > 0);   // with an impact
    CHECK(dynamic.impactLoss() == sized.impactLoss());
  }
}

// Twelve rows fixed: every row in the solve, the open ones zeroed at unit compliance (η = 0 there).
template class dyn::ConstrainedMechanism<Spatial, 6, 12, 0>;

// The closed limits' coordinates eliminated against the Schur route over every row: a different
// formulation, so the same to rounding (1e-9 after 1,500 steps: what moves is ~1e-12), not bit for bit.
TEST_CASE("the PUMA file's closed rows solved alone (locked coordinates eliminated) step as every row solved with the open ones zeroed") {
  const model_file::LoadedModel m = model_file::load(model("puma560.urdf"));
  REQUIRE(m.actuators.empty());
  for (Integrator integrator : {Integrator::SemiImplicitEuler, Integrator::RK4}) {
    INFO(int(integrator));
    model_file::SixJoints selected(m.mechanism);
    ConstrainedMechanism<Spatial, 6, 12, 0> every(m.mechanism);
    CHECK(lockstep(m, integrator, selected, every, true, 1e-9) > 100);
    CHECK(selected.impactLoss() > 0);
    CHECK(selected.impactLoss() == doctest::Approx(every.impactLoss()).epsilon(1e-9));
  }
}

namespace {
// A joint limit the mechanism does not recognise as one (it forwards every call): its rows are asked
// for through the constraint's own position(), as any other kind's.
class ForwardedLimit final : public Constraint<Spatial> {
 public:
  explicit ForwardedLimit(std::shared_ptr<const Constraint<Spatial>> limit) : limit_(std::move(limit)) {}
  const char* kind() const override { return limit_->kind(); }
  int rows() const override { return limit_->rows(); }
  bool unilateral() const override { return limit_->unilateral(); }
  void position(const MechanismKinematics<Spatial>& k, int row, VecN& phi, MatN& J, MatN& A) const override { limit_->position(k, row, phi, J, A); }
  void bias(const MechanismKinematics<Spatial>& k, int row, VecN& b) const override { limit_->bias(k, row, b); }
  Spatial::Vec force(const MechanismKinematics<Spatial>& k, const double* eta) const override { return limit_->force(k, eta); }
  Spatial::Pos point(const MechanismKinematics<Spatial>& k) const override { return limit_->point(k); }
  Attachment<Spatial> attachment() const override { return limit_->attachment(); }

 private:
  std::shared_ptr<const Constraint<Spatial>> limit_;
};
}  // namespace

TEST_CASE("joint limits alone: their rows computed in place (J constant, the selection kept) step as the limits' own rows, bit for bit") {
  const model_file::LoadedModel m = model_file::load(model("puma560.urdf"));
  MechanismModel<Spatial> forwarded = m.mechanism;
  for (auto& c : forwarded.constraints) c = std::make_shared<ForwardedLimit>(c);
  for (Integrator integrator : {Integrator::SemiImplicitEuler, Integrator::RK4}) {
    INFO(int(integrator));
    model_file::SixJoints in_place(m.mechanism);
    ConstrainedMechanism<Spatial> through_rows(forwarded);
    CHECK(lockstep(m, integrator, in_place, through_rows, true) > 100);
    CHECK(in_place.impactLoss() > 0);
    CHECK(in_place.impactLoss() == through_rows.impactLoss());
  }
}

namespace {
// openDepth exposed: the deepest open limit's φ, from q alone where the stage is elsewhere (every rigid
// contact a joint limit), and from the full position stage at q.
class DepthProbe final : public model_file::SixJoints {
 public:
  using ConstrainedMechanism::ConstrainedMechanism;
  bool stagedAt(const VecN& q) const { return have_position_ && same(q, staged_q_); }
  double depth(const VecN& q) { return openDepth(q); }
  double stagedDepth(const VecN& q) {
    stage(q);
    return openDepth(q);
  }
};

// The file's step as `dynlab bench` takes it: semi-implicit Euler + Baumgarte at the file's time step.
StepOptions eulerBaumgarte(const model_file::LoadedModel& m) {
  StepOptions o;
  o.dt = m.timestep;
  o.integrator = Integrator::SemiImplicitEuler;
  o.drift.kind = Drift::Baumgarte;
  return o;
}
}  // namespace

// The look after each step at the open limits (stepToTouchdowns: is a stop crossed?) reads their φ from
// q without a position stage; it must be the stage's own φ bit for bit, or a touchdown would be located
// elsewhere (the lockstep above against ForwardedLimit, whose rows the mechanism does not recognise and
// always stages, checks the located steps themselves).
TEST_CASE("an open joint limit's depth from q alone is the position stage's φ, bit for bit") {
  const model_file::LoadedModel m = model_file::load(model("puma560.urdf"));
  DepthProbe probe(m.mechanism);
  const StepOptions o = eulerBaumgarte(m);
  const VecN tau = VecN::Zero(6);
  VecN q = m.start_q, v = m.start_v;
  int past = 0, compared = 0;
  for (int k = 0; k < 1500; ++k) {
    probe.updateContacts(q, v, tau);
    REQUIRE(probe.stepLocatingContacts(o, tau, q, v));
    if (k % 10) continue;
    // About the step's end, with the stage at the end itself: the depth from q, then the stage's.
    for (double d : {-0.5, -1e-7, 1e-7, 0.5}) {
      VecN qd = q;
      qd.array() += d;
      probe.stage(q);
      REQUIRE(!probe.stagedAt(qd));
      const double from_q = probe.depth(qd);
      REQUIRE(probe.stagedAt(q));  // the stage in place stays
      const double staged = probe.stagedDepth(qd);
      REQUIRE(from_q == staged);
      past += from_q > 0.0;
      ++compared;
    }
  }
  CHECK(compared > 500);
  CHECK(past > 50);  // configurations past a stop (the depth positive) among them
}

namespace {
// What a position stage keeps of the rigid contacts (constrained_mechanism.h open_depth_, rigid_closed_),
// and the scan over every constraint it replaces: the deepest φ of the open ones, whether one is closed.
template <class Base>
class StageProbe final : public Base {
 public:
  using Base::Base;
  bool stagedAt(const VecN& q) const { return this->have_position_ && this->same(q, this->staged_q_); }
  void check(const VecN& q) {
    this->stage(q);
    double depth = -INFINITY;
    bool closed = false;
    for (std::size_t i = 0; i < this->released_.size(); ++i) {
      if (!this->rigid_contact_[i]) continue;
      if (this->released_[i]) depth = std::max(depth, this->phi_full_[this->offsets_[std::size_t(i)]]);
      else closed = true;
    }
    REQUIRE(this->openDepth(q) == depth);  // at the staged q: the stage's
    REQUIRE(this->stagedAt(q));
    REQUIRE(this->open_depth_ == depth);
    REQUIRE(this->rigid_closed_ == closed);
    deepest = std::max(deepest, depth);
    any_closed = any_closed || closed;
  }
  double deepest = -INFINITY;
  bool any_closed = false;
};
}  // namespace

// updateContacts looks for touchdowns only when the stage found an open contact at or past its plane,
// and runs the lift-off check when it found one closed; both read at the stage, for the limits alone
// (the PUMA file's rows computed in place) and for any kind (the same limits through their own rows).
TEST_CASE("the position stage's look at the rigid contacts is the scan over every constraint, in any pattern of open and closed") {
  const model_file::LoadedModel m = model_file::load(model("puma560.urdf"));
  MechanismModel<Spatial> forwarded = m.mechanism;
  for (auto& c : forwarded.constraints) c = std::make_shared<ForwardedLimit>(c);
  model_file::SixJoints run(m.mechanism);
  StageProbe<model_file::SixJoints> in_place(m.mechanism);
  StageProbe<ConstrainedMechanism<Spatial>> through_rows(forwarded);
  const StepOptions o = eulerBaumgarte(m);
  const VecN tau = VecN::Zero(6);
  VecN q = m.start_q, v = m.start_v;
  const int count = int(m.mechanism.constraints.size());
  for (int k = 0; k < 1500; ++k) {
    run.updateContacts(q, v, tau);
    REQUIRE(run.stepLocatingContacts(o, tau, q, v));
    if (k % 10) continue;
    // Closed in turns (every third constraint, shifted each time), then all open, then all closed.
    for (int pattern = 0; pattern < 3; ++pattern)
      for (int i = 0; i < count; ++i) {
        const bool closed = pattern == 0 ? (k / 10 + i) % 3 == 0 : pattern == 2;
        in_place.setClosed(i, closed);
        through_rows.setClosed(i, closed);
        if (i + 1 == count) in_place.check(q), through_rows.check(q);
      }
  }
  CHECK(in_place.deepest > 0.0);  // past a stop among them
  CHECK(in_place.any_closed);
  CHECK(through_rows.deepest == in_place.deepest);
}
