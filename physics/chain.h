// Tree (chain) dynamics, lecture eq. (1):
//     M(θ) θ'' + C(θ,θ') θ' + G(θ) [+ K θ] = τ − J(θ)^T f
// Written once for planar (3-vector) and spatial (6-vector) algebra (spatial.h).
//   forwardKinematics  link transforms, velocities and velocity-product accelerations, in two
//                      stages: positionKinematics (θ alone) then velocityKinematics (θ')
//   rnea               τ = ID(θ, θ', θ'')           (recursive Newton–Euler; θ''=0 gives Cθ'+G)
//   crba               M(θ)                         (composite rigid body algorithm)
//   aba                θ'' = FD(θ, θ', τ)           (articulated body algorithm, O(N))
//   pointJacobian      J (position stage) and J'θ' (velocity stage) of a world-aligned frame at a
//                      point of a link
//   springTorque       K θ, K tridiagonal: P_K = Σ K_i/2 (θ_i − θ_{i−1})²
// Ball joints (spatial, addBall): three consecutive tree bodies, the first two massless carriers,
// turning about the three axes of the child's own frame (MuJoCo's local body frame at q0, columns of
// R0, in dynlab's world-aligned body axes), so that the rates are MuJoCo's qvel of a ball (ω in the
// local frame) and every body's frame stays world-aligned at q0: the relative rotation is
// pre R(Q) R0ᵀ for the joint's unit quaternion Q (w x y z, MuJoCo's qpos, stored once: 4 numbers) —
// pre = R0 for a ball (Q0 = 1), pre = 1 for a free joint's ball (R0 = R(Q0)). The carriers' frames
// coincide with the body's (identity placements), so velocities, M and τ are those of a spherical
// joint; its velocity-product acceleration is v_parent ×m (S ω) as one joint (chained 1-dof joints
// would add the sibling cross terms S_a ω_a ×m S_b ω_b: chain.cpp and chain_world.cpp leave them
// out). A free joint is three slides along world x, y, z (MuJoCo's qpos position, qvel the origin's
// world velocity) then a ball. So q has nq() numbers (a quaternion per ball) and θ' has dof();
// each body reads q[q_index] (chain_configuration.cpp: q̇ = N(q) θ', q ⊕ h θ', normalisation).
// Model (fixed) and Data (per-state scratch) are kept apart, as in MuJoCo.
// Any size: vectors come in as VecIn (a VecN, an Eigen::VectorXd or a contiguous head() binds without
// a copy) and go out into a caller-sized Eigen::Ref<Eigen::VectorXd>; the VecN-returning forms (and
// crba's MatN, pointJacobian) are for chains of at most kMaxDof joints, as the labs use them.
#pragma once
#include <memory>
#include <vector>

#include "physics/spatial.h"
#include "physics/types.h"

namespace dyn {

namespace detail {
// True when x binds to a plain vector without a copy (contiguous, unit stride).
template <class D>
inline constexpr bool kBindsDirectly =
    Eigen::internal::traits<Eigen::Ref<const Eigen::VectorXd>>::template match<D>::MatchAtCompileTime;
}  // namespace detail

// A read-only vector argument of any size. A contiguous vector (VecN, Eigen::VectorXd, a head()) is
// viewed where it lies, at the cost of a pointer; any other expression (VecN::Zero(n), a + b) is
// evaluated into a buffer on the stack when n ≤ kMaxDof (on the heap beyond), so the labs' calls
// never allocate, as Eigen::Ref<const VectorXd> would for an expression. Pass by const reference;
// it may point into its argument, so it is neither copied nor kept.
class VecIn {
 public:
  template <class D>
  VecIn(const Eigen::MatrixBase<D>& x) : n_(x.size()) {  // NOLINT: implicit on purpose
    if constexpr (detail::kBindsDirectly<D>) {
      p_ = x.derived().data();
    } else {
      double* to = buf_;
      if (n_ > kMaxDof) large_.reset(to = new double[std::size_t(n_)]);
      Eigen::Map<Eigen::VectorXd>(to, n_) = x;
      p_ = to;
    }
  }
  VecIn(const VecIn&) = delete;
  VecIn& operator=(const VecIn&) = delete;

  double operator[](Eigen::Index i) const { return p_[i]; }
  Eigen::Index size() const { return n_; }
  const double* data() const { return p_; }
  Eigen::Map<const Eigen::VectorXd> vector() const { return {p_, n_}; }

 private:
  const double* p_;
  Eigen::Index n_;
  double buf_[kMaxDof];              // an evaluated expression of up to kMaxDof values
  std::unique_ptr<double[]> large_;  // or more (large chains only)
};

enum class JointType { Revolute, Prismatic, Ball };

template <class S>
struct TreeModel {
  using Vec = typename S::Vec;
  using Mat = typename S::Mat;
  struct Body {
    int parent;                      // −1: the fixed base
    JointType joint;
    typename S::Axis axis;           // prismatic direction (spatial: also the revolute axis)
    typename S::Transform X_tree;    // parent frame → joint frame at θ = 0
    Mat inertia;                     // spatial inertia at the body origin, body coordinates
    Vec subspace = Vec::Zero();      // motion subspace S_i (set by addBody from joint and axis)
    // Spatial: the inertia about the centre of mass {m, c, I_c} (Spatial::Central, set by addBody).
    typename S::Central central{};
    // Spatial: 0, 1 or 2 when the axis is that coordinate axis ±e_k exactly (set by addBody,
    // markCoordinateAxis), else −1; coordinate_sign −1 for −e_k (a turn by θ about −e_k is one by −θ
    // about e_k), else +1.
    int coordinate_axis = -1;
    int coordinate_sign = 1;
    bool massless = false;           // zero inertia: a carrier (set by addBody)
    int q_index = 0;                 // where its coordinate sits in q (a ball's three: its quaternion's w)
    int ball = -1;                   // a ball's sub-body: index into balls
  };
  // A ball joint's three bodies first..first+2 and its rotation pre R(Q) R0ᵀ (see the top).
  struct Ball {
    int first = 0;
    typename S::Rot pre, post;       // pre and R0
  };
  std::vector<Body> bodies;
  std::vector<Ball> balls;
  Vec gravity = Vec::Zero();         // spatial acceleration of gravity in world coordinates

  int dof() const { return int(bodies.size()); }
  int nq() const { return nq_; }     // dof() plus one per ball joint
  int addBody(int parent, JointType joint, const typename S::Axis& axis,
              const typename S::Transform& X_tree, const Mat& inertia) {
    // Spatial: a unit axis, and placements that do not turn marked so (spatial.h: E is skipped there).
    if constexpr (S::kDim == 6) bodies.push_back({parent, joint, axis.normalized(), S::marked(X_tree), inertia});
    else bodies.push_back({parent, joint, axis, X_tree, inertia});
    bodies.back().q_index = nq_++;
    bodies.back().subspace = motionSubspace(int(bodies.size()) - 1);
    bodies.back().central = S::central(inertia);
    bodies.back().massless = S::massless(inertia);
    if constexpr (S::kDim == 6) markCoordinateAxis(bodies.back());
    return int(bodies.size()) - 1;
  }
  // Spatial: b.coordinate_axis and b.coordinate_sign from b.axis (exactly ±e_k, or neither: −1).
  static void markCoordinateAxis(Body& b) {
    b.coordinate_axis = -1, b.coordinate_sign = 1;
    for (int k = 0; k < 3; ++k)
      if (b.axis == S::Axis::Unit(k)) b.coordinate_axis = k;
      else if (b.axis == -S::Axis::Unit(k)) b.coordinate_axis = k, b.coordinate_sign = -1;
  }
  // A ball joint (spatial): three bodies about the columns of R0 (`post`), the last carrying
  // `inertia`, the first placed by X_tree (which does not turn: frames are world-aligned at q0).
  // Returns the last body's index.
  int addBall(int parent, const typename S::Transform& X_tree, const typename S::Rot& pre, const typename S::Rot& post,
              const Mat& inertia) {
    const int q = nq_;
    for (int k = 0; k < 3; ++k) {
      typename S::Transform X = k == 0 ? X_tree : typename S::Transform{};
      const int i = addBody(k == 0 ? parent : int(bodies.size()) - 1, JointType::Ball, post.col(k), X, k == 2 ? inertia : Mat::Zero());
      bodies[std::size_t(i)].q_index = q;
      bodies[std::size_t(i)].ball = int(balls.size());
    }
    balls.push_back({int(bodies.size()) - 3, pre, post});
    nq_ = q + 4;
    return int(bodies.size()) - 1;
  }
  Vec motionSubspace(int i) const;

 private:
  int nq_ = 0;
};

template <class S>
struct TreeData {
  using Vec = typename S::Vec;
  std::vector<typename S::Transform> X_up;     // parent → body i
  std::vector<typename S::Transform> X_world;  // world → body i
  std::vector<Vec> S_i, v, c;                  // joint axis, body velocity, velocity-product accel
  std::vector<Vec> S_w;                        // joint axis in world coordinates (at the world origin)
  std::vector<Vec> a, f;                       // scratch for rnea
  std::vector<typename S::Mat> Ic;             // scratch for aba
  std::vector<typename S::Inertia> Ic_rb;      // scratch for crba (composite rigid-body inertias)
  std::vector<Vec> U, pA;                      // scratch for aba
  // World coordinates (chain_world.h): inertias I_i^w, link velocities V_i and velocity-product
  // accelerations A_i (θ'' = 0, no gravity), all at the world origin.
  std::vector<typename S::Inertia> I_w;
  std::vector<Vec> v_w, a_w;
  std::vector<double> D, u;
  explicit TreeData(const TreeModel<S>& model) { resize(model.dof()); }
  void resize(int n);
};

// Fills X_up, X_world, v, c from (θ, θ'). Every other algorithm reads these.
template <class S>
void forwardKinematics(const TreeModel<S>& model, const VecIn& q, const VecIn& qd, TreeData<S>& data);
// The two stages of forwardKinematics. Position: X_up, X_world, S_i from θ (enough for crba,
// pointPosition, the J of pointJacobian and potentialEnergy). Velocity, after the position stage:
// v and c from θ' (rnea, aba, J'θ', kineticEnergy).
template <class S>
void positionKinematics(const TreeModel<S>& model, const VecIn& q, TreeData<S>& data);
template <class S>
void velocityKinematics(const TreeModel<S>& model, const VecIn& qd, TreeData<S>& data);
// The world part of positionKinematics alone: X_world and S_w (what chain_world.h and point
// positions read; X_up and S_i are left as they were).
template <class S>
void worldKinematics(const TreeModel<S>& model, const VecIn& q, TreeData<S>& data);

// Inverse dynamics τ = M θ'' + C θ' + G with gravity (or without, when with_gravity is false).
// Leaves data.a[i] = each body's acceleration without gravity (at θ'' = 0: its J'θ' bias).
// Into tau (sized n by the caller), or returned (n ≤ kMaxDof).
template <class S>
void rnea(const TreeModel<S>& model, TreeData<S>& data, const VecIn& qd, const VecIn& qdd,
          Eigen::Ref<Eigen::VectorXd> tau, bool with_gravity = true);
template <class S>
VecN rnea(const TreeModel<S>& model, TreeData<S>& data, const VecIn& qd, const VecIn& qdd,
          bool with_gravity = true);

// Joint-space inertia M(θ), symmetric positive definite (into M, sized n × n by the caller, or returned),
// from world-coordinate composite inertias (chain_world.h); leaves data.I_w for biasForcesWorld.
template <class S>
void crba(const TreeModel<S>& model, TreeData<S>& data, Eigen::Ref<Eigen::MatrixXd> M);
template <class S>
MatN crba(const TreeModel<S>& model, TreeData<S>& data);

// Forward dynamics θ'' = M⁻¹ (τ − C θ' − G) in O(N), into qdd (sized n by the caller) or returned
// (n ≤ kMaxDof).
template <class S>
void aba(const TreeModel<S>& model, TreeData<S>& data, const VecIn& qd, const VecIn& tau,
         Eigen::Ref<Eigen::VectorXd> qdd);
template <class S>
VecN aba(const TreeModel<S>& model, TreeData<S>& data, const VecIn& qd, const VecIn& tau);

// A frame at `point` (body coordinates) with world-aligned axes:
//   V_P = J θ',  classical acceleration = J θ'' + J'θ'.  J is kDim × n: n ≤ kMaxDof (std::length_error).
template <class S>
void pointJacobian(const TreeModel<S>& model, const TreeData<S>& data, int body,
                   const typename S::Pos& point, MatN& J, VecN& Jdot_qd);
// J alone (position stage only), and J'θ' alone (velocity stage).
template <class S>
void pointJacobian(const TreeModel<S>& model, const TreeData<S>& data, int body,
                   const typename S::Pos& point, MatN& J);
template <class S>
void pointJacobianDot(const TreeModel<S>& model, const TreeData<S>& data, int body,
                      const typename S::Pos& point, VecN& Jdot_qd);

// Configuration operations (chain_configuration.cpp), identity maps for hinges and slides:
//   configurationRate     q̇ = N(q) θ' (a ball: Q̇ = ½ Q ⊗ (0, ω)), into qdot (sized nq)
//   integrateConfiguration q ← q ⊕ h θ' (a ball: Q ← Q ⊗ exp(h ω / 2), MuJoCo's mj_integratePos)
//   normalizeConfiguration each ball's Q ← Q / |Q|
template <class S>
void configurationRate(const TreeModel<S>& model, const VecIn& q, const VecIn& qd, Eigen::Ref<Eigen::VectorXd> qdot);
template <class S>
void integrateConfiguration(const TreeModel<S>& model, Eigen::Ref<Eigen::VectorXd> q, const VecIn& qd, double h);
template <class S>
void normalizeConfiguration(const TreeModel<S>& model, Eigen::Ref<Eigen::VectorXd> q);

// World position of a point given in body coordinates.
template <class S>
typename S::Pos pointPosition(const TreeData<S>& data, int body, const typename S::Pos& point);

// Kinetic ½ Σ V_i·I_i V_i and gravitational potential −Σ m_i g·c_i (world centre of mass c_i).
template <class S>
double kineticEnergy(const TreeModel<S>& model, const TreeData<S>& data);
template <class S>
double potentialEnergy(const TreeModel<S>& model, const TreeData<S>& data);

// A planar serial chain of n equal uniform rods (length, mass; inertia m l²/12 about the centre),
// joint i revolute at the tip of link i−1, joint 0 at the world origin, gravity g along −y; θ = 0
// is the outstretched chain along +x. The motion-control arm's kind of chain at any n.
TreeModel<Planar> uniformPlanarChain(int n, double length, double mass, double g = 9.81);

// Joint springs between consecutive joints: K θ with K tridiagonal (lecture §1), and P_K.
VecN springTorque(const VecN& stiffness, const VecN& q);
MatN springStiffnessMatrix(const VecN& stiffness);
double springEnergy(const VecN& stiffness, const VecN& q);

}  // namespace dyn
