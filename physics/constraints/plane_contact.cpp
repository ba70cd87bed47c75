// A unilateral ball-on-plane contact: the row, bias, compliant force and reports; the maths is in
// plane_contact.h. The mechanism decides when the row is closed (constrained_mechanism_impl.h).
#include "physics/constraints/plane_contact.h"

#include <cmath>
#include <stdexcept>

namespace dyn {
namespace {
// The translation rows of the motion vector: planar (ω, x, y), spatial (ωx, ωy, ωz, x, y, z).
template <class S>
std::array<bool, S::kDim> translations() {
  std::array<bool, S::kDim> rows{};
  for (int i = S::kDim - int(S::Pos::RowsAtCompileTime); i < S::kDim; ++i) rows[std::size_t(i)] = true;
  return rows;
}
}  // namespace

template <class S>
PlaneContact<S>::PlaneContact(BodyRef body, const Pos& centre_b, const Pos& normal, const PlaneContactParams& params)
    : body_(body), centre_b_(centre_b), normal_(normal), params_(params) {
  const auto& p = params;
  if (body.isWorld()) throw std::invalid_argument("plane_contact: the ball must be on a link or a payload");
  if (!centre_b.allFinite()) throw std::invalid_argument("plane_contact: the ball's centre must be finite");
  if (!(normal.norm() > 0) || !normal.allFinite()) throw std::invalid_argument("plane_contact: the normal must be a non-zero direction");
  if (!(p.radius >= 0) || !std::isfinite(p.radius) || !std::isfinite(p.height))
    throw std::invalid_argument("plane_contact: the radius must be ≥ 0 and the height finite");
  if (!(p.mu >= 0) || !std::isfinite(p.mu) || !(p.stiffness >= 0) || !std::isfinite(p.stiffness) || !(p.damping >= 0) ||
      !std::isfinite(p.damping))
    throw std::invalid_argument("plane_contact: mu, stiffness and damping must be finite numbers ≥ 0");
  normal_.normalize();
}

template <class S>
double PlaneContact<S>::gap(const MechanismKinematics<S>& k) const {
  return normal_.dot(k.position(body_, centre_b_)) - params_.radius - params_.height;
}

template <class S>
void PlaneContact<S>::position(const MechanismKinematics<S>& k, int row, VecN& phi, MatN& J, MatN& A) const {
  if constexpr (S::kDim == 6)
    if (body_.kind == BodyRef::Kind::Link) {
      // A spatial link (the pen's tip): the same sums as k.position and k.addDirectionJacobian, read
      // from the tree in place (no dispatch on the body's kind, no calls). Column j: −n · (the linear
      // velocity at c of joint j's unit motion), for the joints root → link.
      const Pos c = S::worldPoint(k.tree->X_world[std::size_t(body_.index)], centre_b_);
      phi[row] = -(normal_.dot(c) - params_.radius - params_.height);
      const double* n = normal_.data();
      const auto& bodies = k.model->tree.bodies;
      for (int j = body_.index; j >= 0; j = bodies[std::size_t(j)].parent) {
        double u[3];
        S::linearAt(c, k.tree->S_w[std::size_t(j)].data(), u);
        J(row, j) += -(n[0] * u[0] + (n[1] * u[1] + n[2] * u[2]));
      }
      return;
    }
  const Pos c = k.position(body_, centre_b_);
  phi[row] = -(normal_.dot(c) - params_.radius - params_.height);
  // −n·v(c): the centre's velocity along n.
  k.addDirectionJacobian(body_, c, normal_, -1.0, row, J, A);
}

template <class S>
void PlaneContact<S>::bias(const MechanismKinematics<S>& k, int row, VecN& b) const {
  if constexpr (S::kDim == 6)
    if (body_.kind == BodyRef::Kind::Link) {
      // −n · (a_c + ω × v_c) at θ'' = 0: k.directionBias's sums on the link's world velocity and bias
      // acceleration, read in place.
      const std::size_t i = std::size_t(body_.index);
      const Pos c = S::worldPoint(k.tree->X_world[i], centre_b_);
      const double* v = k.tree->v_w[i].data();
      double ap[3], vp[3], wv[3];
      S::linearAt(c, k.tree->a_w[i].data(), ap);
      S::linearAt(c, v, vp);
      S::cross3(v, vp, wv);
      const double a[3] = {ap[0] + wv[0], ap[1] + wv[1], ap[2] + wv[2]};
      const double* n = normal_.data();
      b[row] = -(n[0] * a[0] + (n[1] * a[1] + n[2] * a[2]));
      return;
    }
  b[row] = -k.directionBias(body_, k.position(body_, centre_b_), normal_);
}

template <class S>
typename S::Vec PlaneContact<S>::force(const MechanismKinematics<S>& k, const double* eta) const {
  (void)k;
  Vec f = Vec::Zero();
  f.template tail<int(S::Pos::RowsAtCompileTime)>() = eta[0] * normal_;
  return f;
}

template <class S>
typename S::Pos PlaneContact<S>::point(const MechanismKinematics<S>& k) const {
  return k.position(body_, centre_b_) - params_.radius * normal_;
}

template <class S>
double PlaneContact<S>::compliantForce(const MechanismKinematics<S>& k) const {
  const double depth = -gap(k);
  if (!(depth > 0)) return 0.0;
  const Pos c = k.position(body_, centre_b_);
  const double depth_rate = -normal_.dot(S::linear(k.pointVelocity(body_, c)));
  return std::max(0.0, params_.stiffness * depth + params_.damping * depth_rate);
}

template <class S>
Attachment<S> PlaneContact<S>::attachment() const {
  Attachment<S> at;
  at.a = BodyRef::world();
  at.b = body_;
  at.point_b = centre_b_;
  at.rows = translations<S>();
  return at;
}

template <class S>
void PlaneContact<S>::report(const MechanismKinematics<S>& k, const double* eta, double* out) const {
  out[0] = gap(k);
  out[1] = eta[0];
}

template class PlaneContact<Planar>;
template class PlaneContact<Spatial>;

}  // namespace dyn
