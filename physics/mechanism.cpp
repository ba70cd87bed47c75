// The kinematics every constraint kind reads (mechanism.h): points of links, payloads and the world,
// their velocities, Jacobians and velocity-product ("bias") accelerations.
//   link point:     V_P = Φ(p − o_i) V_i (world-aligned frame at P), columns from the path root → link
//   payload point:  V_P = Φ(p − c) (ω, v_c) with Φ(r) = [[1,0,0],[−r_y,1,0],[r_x,0,1]] (lecture §2),
//                   on the free coordinates only; bias −ω² r (α_c = 0)
// Written once for planar and spatial trees; payloads are planar.
#include "physics/mechanism.h"

#include <cmath>

namespace dyn {
namespace {

// Φ(r) applied to a planar velocity (ω, vx, vy) at the centre of mass: the velocity at c + r.
Eigen::Vector3d shiftPlanar(const Eigen::Vector2d& r, const Eigen::Vector3d& v) {
  return {v[0], v[1] - v[0] * r.y(), v[2] + v[0] * r.x()};
}

// Each free coordinate of a planar payload at pose x (its columns from `col` on): f(column, Φ(p − c) e_c),
// the velocity at world point p that the coordinate's unit rate gives.
template <class F>
void payloadColumns(const Payload& pl, const Eigen::Vector3d& x, int col, const Eigen::Vector2d& p, F&& f) {
  const Eigen::Vector2d r(p.x() - x[1], p.y() - x[2]);
  for (int c = 0; c < 3; ++c)
    if (pl.free[std::size_t(c)]) f(col++, shiftPlanar(r, Eigen::Vector3d::Unit(c)));
}

}  // namespace

template <class S>
std::string MechanismModel<S>::validate() const {
  const int n = tree.dof();
  if (!joints.empty() && int(joints.size()) != n) return "joint properties are given for " + std::to_string(joints.size()) + " of " + std::to_string(n) + " joints";
  for (std::size_t i = 0; i < joints.size(); ++i)
    if (tree.bodies[i].joint == JointType::Ball && joints[i].stiffness != 0) return "joint " + std::to_string(i) + " is a ball joint's: no spring on it";
  for (std::size_t i = 0; i < joints.size(); ++i)
    if (!(joints[i].armature >= 0) || !std::isfinite(joints[i].armature))
      return "joint " + std::to_string(i) + "'s armature must be a finite number ≥ 0";
  if constexpr (S::kDim != 3) {
    if (!payloads.empty()) return "payloads are planar: a spatial mechanism cannot carry one yet";
  }
  for (std::size_t i = 0; i < payloads.size(); ++i) {
    const Payload& p = payloads[i];
    if (!(p.mass > 0) || !(p.inertia > 0)) return "payload " + std::to_string(i) + " needs a positive mass and inertia";
  }
  auto ok = [&](const BodyRef& b) {
    if (b.kind == BodyRef::Kind::Link) return b.index >= 0 && b.index < n;
    if (b.kind == BodyRef::Kind::Payload) return b.index >= 0 && b.index < int(payloads.size());
    return true;
  };
  for (std::size_t i = 0; i < constraints.size(); ++i) {
    const Attachment<S> at = constraints[i]->attachment();
    if (!ok(at.a) || !ok(at.b)) return "constraint " + std::to_string(i) + " names a body the mechanism does not have";
    if (at.a == at.b) return "constraint " + std::to_string(i) + " ties a body to itself";
  }
  for (std::size_t i = 0; i < forces.size(); ++i) {
    if (!forces[i]) return "external force " + std::to_string(i) + " is empty";
    const BodyRef b = forces[i]->body();
    if (b.isWorld() || !ok(b)) return "external force " + std::to_string(i) + " (" + forces[i]->kind() + ") acts on the world or on a body the mechanism does not have";
  }
  for (int j : bullet.cut_joints)
    if (j < 0 || j >= n) return "Bullet cut joint " + std::to_string(j) + " is not a joint of the trees";
  if (tree.nq() + payloadDof() > kMaxDof || rows() > kMaxDof) return "the mechanism is larger than kMaxDof (" + std::to_string(kMaxDof) + ")";
  return {};
}

template <class S>
typename S::Pos MechanismKinematics<S>::position(const BodyRef& b, const Pos& p) const {
  switch (b.kind) {
    case BodyRef::Kind::Link: return pointPosition(*tree, b.index, p);
    case BodyRef::Kind::Payload:
      if constexpr (S::kDim == 3) {
        const Eigen::Vector3d& x = payload_pose[std::size_t(b.index)];
        const double c = payload_cs[std::size_t(b.index)].x(), s = payload_cs[std::size_t(b.index)].y();
        return {x[1] + c * p.x() - s * p.y(), x[2] + s * p.x() + c * p.y()};
      }
      return p;
    default: return p;
  }
}

template <class S>
double MechanismKinematics<S>::angle(const BodyRef& b) const {
  if constexpr (S::kDim == 3) {
    if (b.kind == BodyRef::Kind::Link) return link_angle[std::size_t(b.index)];
    if (b.kind == BodyRef::Kind::Payload) return payload_pose[std::size_t(b.index)][0];
  }
  return 0.0;
}

template <class S>
typename S::Rot MechanismKinematics<S>::rotation(const BodyRef& b) const {
  if (b.kind == BodyRef::Kind::Link) return tree->X_world[std::size_t(b.index)].E.transpose();
  if constexpr (S::kDim == 3) {
    if (b.kind == BodyRef::Kind::Payload) {
      const Eigen::Vector2d& cs = payload_cs[std::size_t(b.index)];
      return (typename S::Rot() << cs.x(), -cs.y(), cs.y(), cs.x()).finished();
    }
  }
  return S::Rot::Identity();
}

template <class S>
void MechanismKinematics<S>::addPointJacobian(const BodyRef& b, const Pos& p_world,
                                              const std::array<bool, S::kDim>& rows, double sign, int row,
                                              MatN& J, MatN& A) const {
  if (b.kind == BodyRef::Kind::Link) {
    if constexpr (S::kDim == 6)
      if (!rows[0] && !rows[1] && !rows[2]) {
        // Spatial, linear rows only (a pin): each column's linear velocity at p, S::linearAt (the
        // same sums as motion()'s linear half).
        for (int j = b.index; j >= 0; j = model->tree.bodies[std::size_t(j)].parent) {
          double u[3];
          S::linearAt(p_world, tree->S_w[std::size_t(j)].data(), u);
          for (int r = 3, out = row; r < 6; ++r)
            if (rows[std::size_t(r)]) J(out++, j) += sign * u[r - 3];
        }
        return;
      }
    // Column j: joint j's axis seen from the world-aligned frame at p, for every joint root → link.
    const typename S::Transform X_pw = S::translation(p_world);
    for (int j = b.index; j >= 0; j = model->tree.bodies[std::size_t(j)].parent) {
      const Vec col = S::motion(X_pw, tree->S_w[std::size_t(j)]);
      for (int r = 0, out = row; r < S::kDim; ++r)
        if (rows[std::size_t(r)]) J(out++, j) += sign * col[r];
    }
  } else if (b.kind == BodyRef::Kind::Payload) {
    if constexpr (S::kDim == 3) {
      // Φ(p − c) on the payload's free coordinates; A enters with the opposite sign (J θ' − A v_c).
      payloadColumns(model->payloads[std::size_t(b.index)], payload_pose[std::size_t(b.index)], model->payloadOffset(b.index), p_world,
                     [&](int col, const Eigen::Vector3d& phi_c) {
                       for (int i = 0, out = row; i < 3; ++i)
                         if (rows[std::size_t(i)]) A(out++, col) -= sign * phi_c[i];
                     });
    }
  }
}

template <class S>
void MechanismKinematics<S>::addDirectionJacobian(const BodyRef& b, const Pos& p_world, const Pos& d, double sign, int row,
                                                  MatN& J, MatN& A) const {
  if (b.kind == BodyRef::Kind::Link) {
    if constexpr (S::kDim == 6) {
      // Spatial: the linear velocity at p of joint j's unit motion, S::linearAt (the dot summed as
      // Eigen's, x0 + (x1 + x2)). p was just stored 8 bytes at a time, and copying it whole into a
      // Transform reloads it 16 bytes at a time, which stalls on store forwarding.
      for (int j = b.index; j >= 0; j = model->tree.bodies[std::size_t(j)].parent) {
        double u[3];
        S::linearAt(p_world, tree->S_w[std::size_t(j)].data(), u);
        J(row, j) += sign * (d[0] * u[0] + (d[1] * u[1] + d[2] * u[2]));
      }
      return;
    }
    // Column j: d · (the linear velocity at p of joint j's unit motion), for every joint root → link.
    const typename S::Transform X_pw = S::translation(p_world);
    for (int j = b.index; j >= 0; j = model->tree.bodies[std::size_t(j)].parent)
      J(row, j) += sign * d.dot(S::linear(S::motion(X_pw, tree->S_w[std::size_t(j)])));
  } else if (b.kind == BodyRef::Kind::Payload) {
    if constexpr (S::kDim == 3) {
      // d · the linear rows of Φ(p − c), on the payload's free coordinates.
      payloadColumns(model->payloads[std::size_t(b.index)], payload_pose[std::size_t(b.index)], model->payloadOffset(b.index), p_world,
                     [&](int col, const Eigen::Vector3d& phi_c) { A(row, col) -= sign * (d.x() * phi_c[1] + d.y() * phi_c[2]); });
    }
  }
}

template <class S>
typename S::Vec MechanismKinematics<S>::pointVelocity(const BodyRef& b, const Pos& p_world) const {
  if (b.kind == BodyRef::Kind::Link) {
    const std::size_t i = std::size_t(b.index);
    return S::motion(S::translation(p_world), tree->v_w[i]);
  }
  if constexpr (S::kDim == 3) {
    if (b.kind == BodyRef::Kind::Payload) {
      const Eigen::Vector3d& x = payload_pose[std::size_t(b.index)];
      return shiftPlanar({p_world.x() - x[1], p_world.y() - x[2]}, payload_rate[std::size_t(b.index)]);
    }
  }
  return Vec::Zero();
}

template <class S>
typename S::Vec MechanismKinematics<S>::pointBias(const BodyRef& b, const Pos& p_world, Vec* velocity) const {
  if (velocity) *velocity = pointVelocity(b, p_world);
  if (b.kind == BodyRef::Kind::Link) {
    // The link's velocity-product acceleration (θ'' = 0), at p, as a classical acceleration.
    const std::size_t i = std::size_t(b.index);
    const typename S::Transform X_pw = S::translation(p_world);
    const Vec v_p = velocity ? *velocity : S::motion(X_pw, tree->v_w[i]);
    const Vec a_p = S::motion(X_pw, tree->a_w[i]);
    return S::classicalAcceleration(a_p, v_p);
  }
  if constexpr (S::kDim == 3) {
    if (b.kind == BodyRef::Kind::Payload) {
      // A point of a rigid body turning at ω with α = 0: −ω² r.
      const Eigen::Vector3d& x = payload_pose[std::size_t(b.index)];
      const double w = payload_rate[std::size_t(b.index)][0];
      return {0.0, -w * w * (p_world.x() - x[1]), -w * w * (p_world.y() - x[2])};
    }
  }
  return Vec::Zero();
}

template <class S>
typename S::Pos MechanismKinematics<S>::linearBias(const BodyRef& b, const Pos& p_world) const {
  if constexpr (S::kDim == 6)
    if (b.kind == BodyRef::Kind::Link) {
      // At p: a_p = (α, a − p × α), v_p = (ω, v − p × ω); the classical acceleration's linear part a_p + ω × v_p.
      const std::size_t i = std::size_t(b.index);
      const double* v = tree->v_w[i].data();
      double ap[3], vp[3], wv[3];
      S::linearAt(p_world, tree->a_w[i].data(), ap);
      S::linearAt(p_world, v, vp);
      S::cross3(v, vp, wv);
      return Pos(ap[0] + wv[0], ap[1] + wv[1], ap[2] + wv[2]);
    }
  return S::linear(pointBias(b, p_world));
}

template <class S>
double MechanismKinematics<S>::directionBias(const BodyRef& b, const Pos& p_world, const Pos& d) const {
  if (b.kind == BodyRef::Kind::Link) {
    // pointBias's link case, only its linear rows along d.
    const std::size_t i = std::size_t(b.index);
    if constexpr (S::kDim == 6) {
      // linearBias's a_p + ω × v_p, along d.
      const Pos a = linearBias(b, p_world);
      return d[0] * a[0] + (d[1] * a[1] + d[2] * a[2]);
    }
    const typename S::Transform X_pw = S::translation(p_world);
    return d.dot(S::linear(S::classicalAcceleration(S::motion(X_pw, tree->a_w[i]), S::motion(X_pw, tree->v_w[i]))));
  }
  return d.dot(S::linear(pointBias(b, p_world)));
}

template struct MechanismModel<Planar>;
template struct MechanismModel<Spatial>;
template struct MechanismKinematics<Planar>;
template struct MechanismKinematics<Spatial>;

}  // namespace dyn
