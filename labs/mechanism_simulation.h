// The per-step harness of every mechanism lab, written once: both engines behind one face, the lab's
// controller and trace row plugged in. A step k:
//   (q, v) at t_k → τ = controller(t_k, q, v) → E(q, v), |φ(q)| by the hand model (both engines alike)
//   → the engine steps with τ held, giving the constraint forces of the step (hand: eq. (2) solved at the
//     step's start, the solve its first RK4 stage reuses; Bullet: impulses over the step / dt)
//   → the lab writes the trace row (work: the engine's books up to t_k: the work of τ and of the external
//     forces plus the joint friction's, integrated by the hand engine with the motion's own RK4 stages,
//     estimated by Bullet's as force held × displacement per step) → the controller observes
//   → a non-finite state or row ends the run with a plain sentence.
// A run of duration T = N dt has N + 1 rows, t = 0 … T: the last one is the state the last step reached
// (closingRow), as a model file's trace has it.
// The engine's clock is set to t_k = k dt before each step: external forces (mechanism.h) are functions
// of time and motion that the engines evaluate inside the step, unlike τ, which the controller samples.
#pragma once
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "labs/lab.h"
#include "physics/constrained_mechanism.h"
#include "physics/fixed_size_copy.h"
#include "physics/bullet/bullet_mechanism.h"

namespace dyn {

// One engine advancing a mechanism's state (q, v) = ((θ, x_c), (θ', v_c)) a fixed step at a time.
class MechanismEngine {
 public:
  virtual ~MechanismEngine() = default;
  virtual void state(VecN& q, VecN& v) const = 0;
  // One step with τ held; false (and a sentence in failure()) if the engine could not take it. Without
  // forces (the bench's engine alone), forces() may keep the last step's.
  virtual bool step(const VecN& tau, bool with_forces = true) = 0;
  // The force of each constraint over the last step (body a on body b, world axes at its point).
  virtual const std::vector<VecN>& forces() const = 0;
  // The forces at the present state with τ held, no step taken (the trace's last row). Bullet keeps the
  // last step's (its forces are impulses over a step); the hand engine solves eq. (2) there.
  virtual void forcesNow(const VecN& tau) { (void)tau; }
  virtual std::string failure() const { return {}; }
  // The time of the state the next step starts from.
  virtual void setTime(double t) = 0;
  // The work done on the mechanism since the start (integrate.h Books): of τ and the external forces, of friction.
  virtual Books books() const = 0;
  // What the engine built, in one line (Simulation::describeEngine); empty for the hand engine.
  virtual std::string describe() const { return {}; }
};

// The hand-written engine: eq. (2)/(3) through the generic mechanism M, integrated by physics/integrate.
template <class M>
class HandEngine final : public MechanismEngine {
 public:
  HandEngine(M& mech, const StepOptions& options, VecN q0, VecN v0)
      : mech_(mech), options_(options), q_(std::move(q0)), v_(std::move(v0)), forces_(mech.model().constraints.size()) {}
  // Entry by entry at the mechanism's fixed state size (the bench's engine-alone step ends with this
  // copy): Eigen's copy of a bounded vector loops with size tests.
  void state(VecN& q, VecN& v) const override {
    setFixed<M::kState>(q, q_);
    setFixed<M::kState>(v, v_);
  }
  bool step(const VecN& tau, bool with_forces) override {
    // Unilateral contacts close (with an impact on v) or open at the step's start ...
    mech_.updateContacts(q_, v_, tau);
    // The constraint forces at the step's start: the solve the first RK4 stage reuses.
    if (with_forces) forcesNow(tau);
    // ... and a touchdown inside the step is located and closed there (the step retaken to it).
    if (!mech_.stepLocatingContacts(options_, tau, q_, v_)) failure_ = "the constraint projection failed";
    return failure_.empty();
  }
  const std::vector<VecN>& forces() const override { return forces_; }
  void forcesNow(const VecN& tau) override {
    const auto sol = mech_.solve(q_, v_, tau);
    for (std::size_t i = 0; i < forces_.size(); ++i) forces_[i] = mech_.constraintForce(int(i), sol);
  }
  std::string failure() const override { return failure_; }
  void setTime(double t) override { mech_.setTime(t); }
  Books books() const override { return mech_.books(); }

 private:
  M& mech_;
  StepOptions options_;
  VecN q_, v_;
  std::vector<VecN> forces_;
  std::string failure_;
};

// The Bullet reference, built from the same description.
template <class S>
class BulletEngine final : public MechanismEngine {
 public:
  BulletEngine(const MechanismModel<S>& model, double dt, const VecN& q0, const VecN& v0)
      : world_(model, dt, q0, v0), forces_(model.constraints.size()) {}
  void state(VecN& q, VecN& v) const override { world_.state(q, v); }
  bool step(const VecN& tau, bool with_forces) override {
    (void)with_forces;  // Bullet's impulses come with every step
    world_.step(tau, t_);
    for (std::size_t i = 0; i < forces_.size(); ++i) forces_[i] = world_.constraintForce(int(i));
    return true;
  }
  const std::vector<VecN>& forces() const override { return forces_; }
  void setTime(double t) override { t_ = t; }
  Books books() const override { return world_.books(); }
  std::string describe() const override { return world_.describe(); }

 private:
  bullet::BulletMechanism<S> world_;
  std::vector<VecN> forces_;
  double t_ = 0;
};

// Everything the lab's trace row and sensors may read about one step.
struct StepRecord {
  Engine engine;
  double t;
  const VecN& q;                     // (θ, x_c) at t
  const VecN& v;                     // (θ', v_c) at t
  const VecN& tau;                   // the torque held over the step
  const std::vector<VecN>& forces;   // each constraint's force over the step
  double energy, residual, work;     // E(q, v), |φ(q)|∞ (velocity-level kinds: also |Jθ' − Av_c|∞), W + D up to t (Books)
};

// The lab's part of a run: its control law, its trace row, its sensors.
class StepHooks {
 public:
  virtual ~StepHooks() = default;
  virtual VecN torque(double t, const VecN& q, const VecN& v) = 0;
  virtual void row(const StepRecord& r, std::vector<double>& out) = 0;
  virtual void observe(const StepRecord& r) { (void)r; }
  // The lab's own watchdog, after each row: empty while the step is acceptable, else the whole
  // sentence ("stopped: the grasp slipped at contact 2 at t = 1.24 s (...)"); the run ends there.
  virtual std::string stop(const StepRecord& r) {
    (void)r;
    return {};
  }
};

// A run of one engine: the bookkeeping every lab shares. M is the lab's hand mechanism type; it also
// measures energy and residual of the Bullet run, with the same formulas.
template <class M>
class MechanismSimulation final : public Simulation {
 public:
  MechanismSimulation(Engine engine, std::unique_ptr<M> model, std::unique_ptr<MechanismEngine> stepper,
                      std::unique_ptr<StepHooks> hooks, const std::vector<std::string>& columns, double dt, double duration)
      : engine_(engine), model_(std::move(model)), stepper_(std::move(stepper)), hooks_(std::move(hooks)),
        columns_(columns), dt_(dt), steps_(std::lround(duration / dt)) {
    stepper_->state(q_, v_);
  }

  bool step(std::vector<double>& row) override {
    if (k_ == steps_ && k_ > 0 && failure_.empty() && !closed_) return closingRow(row);
    if (k_ >= steps_ || !failure_.empty()) return false;
    const double t = double(k_) * dt_;
    tau_ = hooks_->torque(t, q_, v_);
    const double energy = model_->energy(q_, v_), residual = residualNow();
    const double work = work_;
    advance(true, t, tau_);
    const StepRecord r{engine_, t, q_, v_, tau_, stepper_->forces(), energy, residual, work};
    hooks_->row(r, row);
    // The next state, the books up to it, then what the sensors saw.
    VecN q1, v1;
    stepper_->state(q1, v1);
    const Books books = stepper_->books();
    work_ = books.work + books.friction;
    hooks_->observe(r);
    if (failure_.empty())
      if (std::string why = hooks_->stop(r); !why.empty()) failure_ = std::move(why);
    q_ = std::move(q1);
    v_ = std::move(v1);
    if (failure_.empty() && (!q_.allFinite() || !v_.allFinite()))
      failure_ = engine_ == Engine::Hand ? "the state became non-finite" : "the Bullet state became non-finite";
    for (std::size_t c = 0; c < row.size() && c < columns_.size() && failure_.empty(); ++c)
      if (!std::isfinite(row[c])) {
        failure_ = columns_[c] + " became non-finite";
        break;
      }
    ++k_;
    return true;
  }

  // The row at t = duration, written as every row is but with no step after it: the state the last step
  // reached, its energy, residual and work, the controller's τ there and the constraint forces with it
  // (the hand engine solves eq. (2) at that state; Bullet's stay its last step's impulses / dt). The
  // sensors see nothing more (no observe) and no watchdog runs.
  bool closingRow(std::vector<double>& row) {
    closed_ = true;
    const double t = double(steps_) * dt_;
    tau_ = hooks_->torque(t, q_, v_);
    stepper_->setTime(t);
    stepper_->forcesNow(tau_);
    const StepRecord r{engine_, t, q_, v_, tau_, stepper_->forces(), model_->energy(q_, v_), residualNow(), work_};
    hooks_->row(r, row);
    return true;
  }

  bool advanceEngine(const VecN& tau) override {
    if (k_ >= steps_ || !failure_.empty()) return false;
    advance(false, double(k_) * dt_, tau);
    stepper_->state(q_, v_);
    ++k_;
    return true;
  }
  VecN appliedTorque() const override { return k_ == 0 || closed_ ? VecN() : tau_; }
  bool engineState(VecN& q, VecN& v) const override {
    q = q_, v = v_;
    return true;
  }

  std::string failure() const override { return failure_; }
  std::string describeEngine() const override { return stepper_->describe(); }
  M& model() { return *model_; }

 private:
  // |φ(q)| of the present state, and for velocity-level kinds (rolling) |J θ' − A v_c| as well: they have no φ.
  double residualNow() const { return model_->holonomic() ? model_->residual(q_) : model_->residual(q_, v_); }
  void advance(bool with_forces, double t, const VecN& tau) {
    stepper_->setTime(t);
    if (!stepper_->step(tau, with_forces) && failure_.empty()) failure_ = stepper_->failure();
  }
  Engine engine_;
  std::unique_ptr<M> model_;
  std::unique_ptr<MechanismEngine> stepper_;
  std::unique_ptr<StepHooks> hooks_;
  std::vector<std::string> columns_;
  double dt_;
  long steps_, k_ = 0;
  bool closed_ = false;  // the row at t = duration written
  VecN q_, v_, tau_;
  double work_ = 0;
  std::string failure_;
};

// The Bullet engine for a description of either algebra (deduced from the model).
template <class S>
std::unique_ptr<MechanismEngine> bulletEngine(const MechanismModel<S>& model, double dt, const VecN& q0, const VecN& v0) {
  return std::make_unique<BulletEngine<S>>(model, dt, q0, v0);
}

// A lab's run: mechanism `mech` from the consistent state (q, v), stepped by the hand engine or by
// Bullet's model of the same description, with the lab's hooks and trace columns.
template <class M>
std::unique_ptr<Simulation> simulateMechanism(Engine engine, std::unique_ptr<M> mech, const StepOptions& step, const VecN& q,
                                              const VecN& v, std::unique_ptr<StepHooks> hooks,
                                              const std::vector<std::string>& columns, double duration) {
  std::unique_ptr<MechanismEngine> stepper;
  if (engine == Engine::Hand) stepper = std::make_unique<HandEngine<M>>(*mech, step, q, v);
  else stepper = bulletEngine(mech->model(), step.dt, q, v);
  return std::make_unique<MechanismSimulation<M>>(engine, std::move(mech), std::move(stepper), std::move(hooks), columns,
                                                  step.dt, duration);
}

}  // namespace dyn
