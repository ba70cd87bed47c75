// MuJoCo's handlers while a guard lives (mujoco_call.h), and MuJoCo's own M and bias (model_file.h).
#include "physics/model_file/mujoco_call.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "physics/model_file/model_file.h"

namespace dyn::model_file {
namespace detail {
namespace {
std::string& collected() {
  static std::string warnings;
  return warnings;
}
void onError(const char* message) {
  lastError() = oneLine(message ? message : "error");
  if (std::jmp_buf* to = jumpTarget()) std::longjmp(*to, 1);
  // No guarded call to return to: MuJoCo must not return from its error handler.
  std::fprintf(stderr, "error: MuJoCo: %s\n", lastError().c_str());
  std::_Exit(3);
}
void onWarning(const char* message) {
  if (collected().size() < 4096) collected() += std::string(collected().empty() ? "" : "; ") + (message ? message : "");
}
}  // namespace

std::jmp_buf*& jumpTarget() {
  static std::jmp_buf* target = nullptr;
  return target;
}
std::string& lastError() {
  static std::string error;
  return error;
}

std::string oneLine(const std::string& text) {
  std::string out;
  for (char c : text) {
    const char s = static_cast<unsigned char>(c) < 0x20 ? ' ' : c;
    if (s == ' ' && (out.empty() || out.back() == ' ')) continue;
    out += s;
  }
  while (!out.empty() && out.back() == ' ') out.pop_back();
  return out;
}

MujocoGuard::MujocoGuard() : error_(mju_user_error), warning_(mju_user_warning) {
  collected().clear();
  mju_user_error = onError;
  mju_user_warning = onWarning;
}
MujocoGuard::~MujocoGuard() {
  mju_user_error = error_;
  mju_user_warning = warning_;
}
std::string MujocoGuard::warnings() const { return oneLine(collected()); }
}  // namespace detail

namespace {

// A copy of the model compiled at load (the cross-check and the bench each own one).
mjModel* copyOf(const LoadedModel& model) {
  if (!model.compiled || !model.compiled->m) throw ModelFileError(model.file + ": no compiled model (load the file first)");
  mjModel* m = nullptr;
  MUJOCO_CALL(model.file, m = mj_copyModel(nullptr, model.compiled->m));
  if (!m) throw ModelFileError(model.file + ": MuJoCo could not copy its model");
  return m;
}

// An owned copy of the model and its data, under MuJoCo's handlers while it lives; `adjust` changes
// the copy (its options) before the data is made.
struct OwnedModel {
  detail::MujocoGuard guard;
  std::string file;
  mjModel* m = nullptr;
  mjData* d = nullptr;
  template <class Adjust>
  OwnedModel(const LoadedModel& model, Adjust adjust) : file(model.file) {
    m = copyOf(model);
    try {
      adjust(m);
      MUJOCO_CALL(model.file, d = mj_makeData(m));
      if (!d) throw ModelFileError(model.file + ": MuJoCo could not make its data");
    } catch (...) {
      mj_deleteModel(m);
      throw;
    }
  }
  ~OwnedModel() {
    if (d) mj_deleteData(d);
    if (m) mj_deleteModel(m);
  }
  OwnedModel(const OwnedModel&) = delete;
  OwnedModel& operator=(const OwnedModel&) = delete;
};

}  // namespace

// The cross-check: the model as loaded, its state set and MuJoCo's position (and velocity) stages run.
struct MujocoReference::Impl : OwnedModel {
  explicit Impl(const LoadedModel& model) : OwnedModel(model, [](mjModel*) {}) {}
  void at(const VecN& q, const VecN* v) {
    std::copy(q.data(), q.data() + m->nq, d->qpos);
    if (v) std::copy(v->data(), v->data() + m->nv, d->qvel);
    else std::fill(d->qvel, d->qvel + m->nv, 0.0);
    MUJOCO_CALL(file, mj_fwdPosition(m, d));
    if (v) MUJOCO_CALL(file, mj_fwdVelocity(m, d));
  }
};

MujocoReference::MujocoReference(const LoadedModel& model) : impl_(new Impl(model)) {}

MujocoReference::~MujocoReference() { delete impl_; }

int MujocoReference::nv() const { return impl_->m->nv; }

MatN MujocoReference::massMatrix(const VecN& q) {
  impl_->at(q, nullptr);
  const int n = impl_->m->nv;
  std::vector<mjtNum> M(std::size_t(n * n));
  mj_fullM(impl_->m, M.data(), impl_->d->qM);
  MatN out(n, n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) out(i, j) = M[std::size_t(i * n + j)];
  return out;
}

VecN MujocoReference::bias(const VecN& q, const VecN& v) {
  impl_->at(q, &v);
  VecN out(impl_->m->nv);
  for (int i = 0; i < impl_->m->nv; ++i) out[i] = impl_->d->qfrc_bias[i];
  return out;
}

VecN MujocoReference::actuation(const VecN& q, const VecN& v, const VecN& ctrl) {
  Impl& x = *impl_;
  std::copy(ctrl.data(), ctrl.data() + std::min<Eigen::Index>(ctrl.size(), x.m->nu), x.d->ctrl);
  x.at(q, &v);
  MUJOCO_CALL(x.file, mj_fwdActuation(x.m, x.d));
  return Eigen::Map<const VecN>(x.d->qfrc_actuator, x.m->nv);
}

VecN MujocoReference::passive(const VecN& q, const VecN& v) {
  impl_->at(q, &v);
  return Eigen::Map<const VecN>(impl_->d->qfrc_passive, impl_->m->nv);
}

double MujocoReference::closure(const VecN& q) {
  impl_->at(q, nullptr);
  const mjModel* m = impl_->m;
  const mjData* d = impl_->d;
  double gap = -1;
  for (int e = 0; e < m->neq; ++e) {
    if (!m->eq_active[e] || (m->eq_type[e] != mjEQ_CONNECT && m->eq_type[e] != mjEQ_WELD)) continue;
    // MuJoCo 2.2.2's data: a connect's (anchor in body1, anchor in body2), a weld's (anchor in body2,
    // relpose's point in body1, ...). The world points from its own kinematics: xpos + xmat p.
    const int b[2] = {m->eq_obj1id[e], m->eq_obj2id[e]};
    const bool weld = m->eq_type[e] == mjEQ_WELD;
    const mjtNum* point[2] = {m->eq_data + mjNEQDATA * e + (weld ? 3 : 0), m->eq_data + mjNEQDATA * e + (weld ? 0 : 3)};
    Eigen::Vector3d p[2];
    for (int k = 0; k < 2; ++k) {
      const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> R(d->xmat + 9 * b[k]);
      p[k] = Eigen::Map<const Eigen::Vector3d>(d->xpos + 3 * b[k]) + R * Eigen::Map<const Eigen::Vector3d>(point[k]);
    }
    gap = std::max(gap, (p[0] - p[1]).cwiseAbs().maxCoeff());
  }
  return gap;
}

// The bench's simulation: the model at the given step with the Euler (or RK4) integrator, its controls
// the model's.
struct MujocoSimulation::Impl : OwnedModel {
  Impl(const LoadedModel& model, double dt, bool rk4, bool contacts)
      : OwnedModel(model, [dt, rk4, contacts](mjModel* m) {
          m->opt.timestep = dt;
          m->opt.integrator = rk4 ? mjINT_RK4 : mjINT_EULER;
          if (contacts) m->opt.disableflags &= ~mjDSBL_CONTACT;  // as load found them (it turned them off)
        }),
        ctrl(model.ctrl) {}
  VecN ctrl;
};

MujocoSimulation::MujocoSimulation(const LoadedModel& model, double dt, bool rk4, bool contacts)
    : impl_(new Impl(model, dt, rk4, contacts)) {}

MujocoSimulation::~MujocoSimulation() { delete impl_; }

void MujocoSimulation::reset(const VecN& q, const VecN& v) {
  mjData* d = impl_->d;
  MUJOCO_CALL(impl_->file, mj_resetData(impl_->m, d));
  std::copy(q.data(), q.data() + impl_->m->nq, d->qpos);
  std::copy(v.data(), v.data() + impl_->m->nv, d->qvel);
  std::copy(impl_->ctrl.data(), impl_->ctrl.data() + std::min<Eigen::Index>(impl_->ctrl.size(), impl_->m->nu), d->ctrl);
}

bool MujocoSimulation::step() {
  const int bad = impl_->d->warning[mjWARN_BADQACC].number;
  MUJOCO_CALL(impl_->file, mj_step(impl_->m, impl_->d));
  return impl_->d->warning[mjWARN_BADQACC].number == bad;
}

void MujocoSimulation::state(VecN& q, VecN& v) const {
  q = Eigen::Map<const VecN>(impl_->d->qpos, impl_->m->nq);
  v = Eigen::Map<const VecN>(impl_->d->qvel, impl_->m->nv);
}

std::string MujocoSimulation::describe() const {
  static const char* const kSolver[3] = {"PGS", "CG", "Newton"};
  const int solver = impl_->m->opt.solver;
  const bool rk4 = impl_->m->opt.integrator == mjINT_RK4;
  return std::string("MuJoCo ") + mj_versionString() + " mj_step, " + (rk4 ? "RK4" : "Euler") + ", soft equalities, " +
         (solver >= 0 && solver < 3 ? kSolver[solver] : "?") + " solver (" + std::to_string(impl_->m->opt.iterations) + " iterations)";
}

}  // namespace dyn::model_file
