// Rolling without slip: the rows, bias and reports; the maths is in rolling.h.
#include "physics/constraints/rolling.h"

#include <cmath>
#include <stdexcept>

#include "physics/det/det.h"

namespace dyn {
namespace {
const Spatial::Pos kUp(0, 0, 1);
// Rows x, y, z of the spatial motion vector (ωx, ωy, ωz, x, y, z).
constexpr std::array<bool, 6> kTranslations{false, false, false, true, true, true};
}  // namespace

Rolling::Rolling(BodyRef wheel, const Pos& centre_b, const Pos& axle_b, double radius, double ground_height, double mu)
    : wheel_(wheel), centre_b_(centre_b), axle_b_(axle_b), radius_(radius), ground_(ground_height), mu_(mu) {
  if (wheel.kind != BodyRef::Kind::Link) throw std::invalid_argument("rolling: the wheel must be a link of the trees");
  if (!(radius > 0) || !std::isfinite(radius)) throw std::invalid_argument("rolling: the radius must be a positive number");
  if (!(axle_b.norm() > 0) || !axle_b.allFinite()) throw std::invalid_argument("rolling: the axle must be a non-zero direction");
  if (!(mu >= 0) || !std::isfinite(ground_height)) throw std::invalid_argument("rolling: mu must be ≥ 0 and the ground height finite");
  axle_b_.normalize();
}

Rolling::Geometry Rolling::geometry(const MechanismKinematics<Spatial>& k) const {
  Geometry g;
  // The wheel is a link (the constructor checks): its world transform read in place, the same sums
  // as k.position and k.direction without their dispatch on the body's kind.
  const Spatial::Transform& X = k.tree->X_world[std::size_t(wheel_.index)];
  g.p = Spatial::worldPoint(X, centre_b_);
  g.a = X.E.transpose() * axle_b_;
  g.u = kUp - kUp.dot(g.a) * g.a;
  g.un = g.u.norm();
  // A disk lying flat has no lowest point: take the one under the centre.
  g.d = g.un > 1e-9 ? Pos(g.u / g.un) : kUp;
  g.P = g.p - radius_ * g.d;
  return g;
}

void Rolling::position(const MechanismKinematics<Spatial>& k, int row, VecN& phi, MatN& J, MatN& A) const {
  const Geometry g = geometry(k);
  // x, y: velocity-level (no φ); z: the rim's lowest point on the ground.
  phi[row] = 0.0;
  phi[row + 1] = 0.0;
  phi[row + 2] = ground_ - g.P.z();
  // J θ' − A v_c = (ground point) − (wheel's material point at P), as a point closure with a = world:
  // column j is minus the linear velocity at P of joint j's unit motion (Spatial::linearAt), for the
  // joints root → wheel (addPointJacobian's translation rows, without its row mask; A has no columns).
  (void)A;
  const auto& bodies = k.model->tree.bodies;
  for (int j = wheel_.index; j >= 0; j = bodies[std::size_t(j)].parent) {
    double u[3];
    Spatial::linearAt(g.P, k.tree->S_w[std::size_t(j)].data(), u);
    double* col = &J(row, j);  // rows row … row + 2 of column j (column-major)
    for (int r = 0; r < 3; ++r) col[r] += -u[r];
  }
}

void Rolling::bias(const MechanismKinematics<Spatial>& k, int row, VecN& b) const {
  const Geometry g = geometry(k);
  // The material point's classical acceleration at θ'' = 0, a_P + ω × v_P (k.linearBias's sums, read
  // in place), and ω itself: the wheel's world velocity (ω, v) and bias acceleration.
  const std::size_t i = std::size_t(wheel_.index);
  const double* v = k.tree->v_w[i].data();
  double ap[3], vp[3], wv[3];
  Spatial::linearAt(g.P, k.tree->a_w[i].data(), ap);
  Spatial::linearAt(g.P, v, vp);
  Spatial::cross3(v, vp, wv);
  const Pos a_mat(ap[0] + wv[0], ap[1] + wv[1], ap[2] + wv[2]);
  const Pos w(v[0], v[1], v[2]), rho = g.P - g.p;
  // ḋ from a' = ω × a (zero for a disk lying flat, whose d is held at n).
  Pos d_dot = Pos::Zero();
  if (g.un > 1e-9) {
    const Pos a_dot = w.cross(g.a);
    const Pos u_dot = -kUp.dot(a_dot) * g.a - kUp.dot(g.a) * a_dot;
    d_dot = (u_dot - g.d * g.d.dot(u_dot)) / g.un;
  }
  // The material point's classical bias acceleration, less its centripetal part, plus ω × (Ṗ − ṗ).
  const Pos a_geo = a_mat - w.cross(w.cross(rho)) + w.cross(-radius_ * d_dot);
  for (int i = 0; i < 3; ++i) b[row + i] = -a_geo[i];
}

Spatial::Vec Rolling::force(const MechanismKinematics<Spatial>& k, const double* eta) const {
  (void)k;
  Vec f = Vec::Zero();
  f.tail<3>() = Pos(eta[0], eta[1], eta[2]);
  return f;
}

Spatial::Pos Rolling::point(const MechanismKinematics<Spatial>& k) const { return geometry(k).P; }

Attachment<Spatial> Rolling::attachment() const {
  Attachment<Spatial> at;
  at.a = BodyRef::world();
  at.b = wheel_;
  at.point_b = centre_b_;
  at.rows = kTranslations;
  return at;
}

Eigen::Matrix3d Rolling::wheelAxes(const Pos& axle_world) {
  Pos lat = axle_world - kUp.dot(axle_world) * kUp;
  lat = lat.norm() > 1e-12 ? Pos(lat.normalized()) : Pos::UnitY();
  Eigen::Matrix3d e;
  e.col(0) = lat.cross(kUp);
  e.col(1) = lat;
  e.col(2) = kUp;
  return e;
}

void Rolling::contactAxes(const Pos& f, const Pos& axle_world, double mu, double* out) {
  const Pos fw = wheelAxes(axle_world).transpose() * f;
  out[0] = fw.x();
  out[1] = fw.y();
  out[2] = fw.z();
  out[3] = mu * fw.z() - det::hypot(fw.x(), fw.y());
}

void Rolling::report(const MechanismKinematics<Spatial>& k, const double* eta, double* out) const {
  const Geometry g = geometry(k);
  contactAxes(Spatial::linear(force(k, eta)), g.a, mu_, out);
  const Pos v = Spatial::linear(k.pointVelocity(wheel_, g.P));
  out[4] = det::hypot(v.x(), v.y());
}

}  // namespace dyn
