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
  const Pos c = k.position(body_, centre_b_);
  phi[row] = -(normal_.dot(c) - params_.radius - params_.height);
  // −n·v(c): the centre's velocity along n.
  k.addDirectionJacobian(body_, c, normal_, -1.0, row, J, A);
}

template <class S>
void PlaneContact<S>::bias(const MechanismKinematics<S>& k, int row, VecN& b) const {
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
