// The fastest mode of a model's linearised motion and the sub-steps it asks for (stiff_steps.h).
#include "physics/model_file/stiff_steps.h"

#include <Eigen/Eigenvalues>
#include <cmath>

#include "physics/det/det.h"
#include "physics/model_file/actuators.h"
#include "physics/model_file/hand_engine.h"
#include "physics/model_file/number_text.h"

namespace dyn::model_file {

FastestMode fastestMode(ConstrainedSystem& engine, const LoadedModel& m, const VecN& q, const VecN& v, const VecN& tau) {
  const Eigen::Index n = engine.nv();
  if (n == 0) return {};
  // x = (δq, v) with δq in the rates' tangent space (q ⊕ δq): x' = [0 1; ∂a/∂δq ∂a/∂v] x.
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * n, 2 * n);
  A.topRightCorner(n, n).setIdentity();
  const double h = 1e-7;  // central differences: O(h²) truncation, O(ε/h) round-off, both ≪ the rates read
  double work = 0, friction = 0;
  VecN plus, minus;
  auto accelerations = [&](const VecN& qs, const VecN& vs, VecN& a) { engine.derivatives(qs, vs, tau, nullptr, a, work, friction); };
  for (Eigen::Index j = 0; j < n; ++j) {
    VecN e = VecN::Zero(n);
    e[j] = 1;
    VecN qp = q, qm = q;
    engine.integrateConfiguration(qp, e, h);
    engine.integrateConfiguration(qm, e, -h);
    accelerations(qp, v, plus);
    accelerations(qm, v, minus);
    A.block(n, j, n, 1) = (plus - minus) / (2 * h);
    accelerations(q, v + h * e, plus);
    accelerations(q, v - h * e, minus);
    A.block(n, n + j, n, 1) = (plus - minus) / (2 * h);
  }
  if (!A.allFinite()) return {};
  const Eigen::EigenSolver<Eigen::MatrixXd> modes(A);
  FastestMode out;
  for (Eigen::Index i = 0; i < 2 * n; ++i) {
    // |λ| through det::hypot (std::abs of a complex is libm's hypot, whose last bit differs between
    // libms): the sub-step count, ceil(|λ| dt / kStiffStep), is then the same on every machine.
    const double rate = det::abs(modes.eigenvalues()[i]);
    if (!(rate > out.rate)) continue;
    out.rate = rate;
    // The joint that moves most in it (det::abs again: a tie broken the same way everywhere).
    Eigen::Index most = 0;
    const Eigen::VectorXcd shape = modes.eigenvectors().col(i).tail(n);
    for (Eigen::Index k = 1; k < n; ++k)
      if (det::abs(shape[k]) > det::abs(shape[most])) most = k;
    out.joint = std::size_t(most) < m.joints.size() ? m.joints[std::size_t(most)].name : "";
  }
  return out;
}

FastestMode fastestMode(const LoadedModel& m) {
  const std::unique_ptr<ConstrainedSystem> engine = withActuators(handEngine(m.mechanism), m);
  return fastestMode(*engine, m, m.start_q, m.start_v, VecN::Zero(engine->nv()));
}

int stiffSubsteps(double rate, double dt) {
  const double s = std::ceil(rate * dt / kStiffStep);
  return !(s > 1) ? 1 : s >= kMaxSubsteps ? kMaxSubsteps : int(s);
}

std::string stiffStepNote(const FastestMode& mode, double dt) {
  const int s = stiffSubsteps(mode.rate, dt);
  if (s == 1) return "";
  auto num = [](double x) { return detail::numberText(x, 3); };
  return "the fastest mode at the start (|λ| " + num(mode.rate) + " 1/s, mostly joint '" + mode.joint + "': a damper or spring on a small inertia) has |λ| dt " +
         num(mode.rate * dt) + " at dt " + num(dt) + " s: both engines take " + std::to_string(s) + " sub-steps per step (|λ| h ≤ " + num(kStiffStep) +
         (s == kMaxSubsteps ? ", capped: pass a smaller --dt)" : ")");
}

}  // namespace dyn::model_file
