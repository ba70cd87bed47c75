// Spatial algebra for planar (3-vector) and spatial (6-vector) chains, lecture conventions:
//   planar motion V = (ω, vx, vy), force f = (τ, fx, fy);  spatial V = (ω, v), f = (n, f).
// A Transform X = {E, r} takes coordinates from frame A to frame B, where r is B's origin in A
// and E rotates A-coordinates into B-coordinates (Featherstone's convention):
//   motion  V_B = X V_A = (E ω, E (v − r × ω))        — with E = I this is Φ(r) of the lecture
//   force   f_A = X^T f_B = (E^T n + r × E^T f, E^T f) — power preserved: V_B·f_B = V_A·f_A
// The tree algorithms (chain.h) are written once against this interface.
#pragma once
#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "physics/det/det.h"
#include "physics/det/sincos.h"

// The spatial operations the tree algorithms call in their inner loops: inlined always, so their
// 6-vectors stay in registers (a call returns them through memory, stored 8 bytes at a time and
// reloaded 16 at a time: a store-forwarding stall that was a third of CRBA).
#define DYN_INLINE __attribute__((always_inline)) inline

namespace dyn {

// ---------------------------------------------------------------- planar: 3-vectors
struct Planar {
  static constexpr int kDim = 3;
  using Vec = Eigen::Vector3d;    // (ω, vx, vy) or (τ, fx, fy)
  using Mat = Eigen::Matrix3d;
  using Rot = Eigen::Matrix2d;
  using Pos = Eigen::Vector2d;
  using Axis = Eigen::Vector2d;   // prismatic direction (revolute is always about z)

  struct Transform {
    Rot E = Rot::Identity();
    Pos r = Pos::Zero();
  };

  // The operations below are written out coefficient by coefficient: on 2- and 3-vectors this is
  // both the shortest code and faster than SIMD packets, whose 16-byte loads of values just stored
  // 8 bytes at a time stall the CPU (store-to-load forwarding fails).
  static Rot rotation(double angle) {  // rotates A-coords into B-coords for B turned by angle
    double c, s;
    det::sincos(angle, s, c);  // det::cos and det::sin, one reduction
    return (Rot() << c, s, -s, c).finished();
  }
  static double crossScalar(const Pos& a, const Pos& b) { return a.x() * b.y() - a.y() * b.x(); }
  static double dot(const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
  static Pos perp(const Pos& a) { return {-a.y(), a.x()}; }  // ẑ × a
  static Pos rotate(const Rot& E, double x, double y) {     // E (x, y)
    return {E(0, 0) * x + E(0, 1) * y, E(1, 0) * x + E(1, 1) * y};
  }
  static Pos rotateBack(const Rot& E, double x, double y) {  // Eᵀ (x, y)
    return {E(0, 0) * x + E(1, 0) * y, E(0, 1) * x + E(1, 1) * y};
  }

  static Vec motion(const Transform& X, const Vec& v) {
    // E (v + ω × r), with ω × r = −ω ẑ×r
    const Pos lin = rotate(X.E, v[1] - v[0] * X.r.y(), v[2] + v[0] * X.r.x());
    return {v[0], lin.x(), lin.y()};
  }
  static Vec motionInverse(const Transform& X, const Vec& v) {  // X^{-1} V_B = V_A
    const Pos lin = rotateBack(X.E, v[1], v[2]);
    return {v[0], lin.x() + v[0] * X.r.y(), lin.y() - v[0] * X.r.x()};
  }
  static Vec forceTranspose(const Transform& X, const Vec& f) {  // X^T f_B = f_A
    const Pos fa = rotateBack(X.E, f[1], f[2]);
    return {f[0] + crossScalar(X.r, fa), fa.x(), fa.y()};
  }
  static Mat motionMatrix(const Transform& X) {
    Mat m = Mat::Zero();
    m(0, 0) = 1;
    m.block<2, 1>(1, 0) = X.E * perp(X.r);
    m.block<2, 2>(1, 1) = X.E;
    return m;
  }
  // X_AC = X_BC ∘ X_AB
  static Transform compose(const Transform& bc, const Transform& ab) {
    const Rot& a = bc.E;
    const Rot& b = ab.E;
    Rot E;
    E << a(0, 0) * b(0, 0) + a(0, 1) * b(1, 0), a(0, 0) * b(0, 1) + a(0, 1) * b(1, 1),
        a(1, 0) * b(0, 0) + a(1, 1) * b(1, 0), a(1, 0) * b(0, 1) + a(1, 1) * b(1, 1);
    const Pos r = rotateBack(b, bc.r.x(), bc.r.y());
    return {E, Pos(ab.r.x() + r.x(), ab.r.y() + r.y())};
  }
  static Transform inverse(const Transform& X) { return {X.E.transpose(), -X.E * X.r}; }
  static Transform translation(const Pos& p) { return {Rot::Identity(), p}; }

  // v ×m w  and  v ×* f  (planar restriction of the 6-D cross products)
  static Vec crossMotion(const Vec& v, const Vec& m) {
    return {0.0, -v[0] * m[2] + v[2] * m[0], v[0] * m[1] - v[1] * m[0]};
  }
  static Vec crossForce(const Vec& v, const Vec& f) {
    return {v[1] * f[2] - v[2] * f[1], -v[0] * f[2], v[0] * f[1]};
  }
  // A planar rigid-body inertia about a frame's origin in its 4 numbers: the other entries of
  // I = [[I_O, gᵀ], [g, m 1]] are m again and zeros (g = m ẑ×c, c the centre of mass). CRBA's composite
  // and world inertias are kept so: adding two of them is 4 sums, the same sums, in the same order, as
  // the 3×3 form's entries that are read (inertiaTimes reads no others).
  struct Inertia {
    double m = 0, gx = 0, gy = 0, io = 0;  // m, g = (g_x, g_y), I_O
    Inertia& operator+=(const Inertia& o) {
      m += o.m, gx += o.gx, gy += o.gy, io += o.io;
      return *this;
    }
    void setZero() { m = gx = gy = io = 0; }
  };
  static Inertia compact(const Mat& I) { return {I(1, 1), I(1, 0), I(2, 0), I(0, 0)}; }
  // I v = (I_O ω + g·v_lin, g ω + m v_lin).
  DYN_INLINE static Vec inertiaTimes(const Inertia& I, const Vec& v) {
    return {I.io * v[0] + I.gx * v[1] + I.gy * v[2], I.gx * v[0] + I.m * v[1], I.gy * v[0] + I.m * v[2]};
  }
  static Vec inertiaTimes(const Mat& I, const Vec& v) { return inertiaTimes(compact(I), v); }
  // RNEA's net force on a body, f = I (a − g) + v ×* (I v) (biasForcesWorld), on lanes T: double for one
  // body, or a GCC/Clang vector of two doubles for two bodies at once. The products and sums of
  // inertiaTimes and crossForce above, in their order, so each lane is their bits (packed SSE2/wasm
  // products and sums round as scalar ones; -ffp-contract=off, no FMA). I: the Inertia's 4 numbers
  // (inertiaNumbers), v, a, g: 3 each.
  static constexpr int kInertiaNumbers = 4;
  DYN_INLINE static void inertiaNumbers(const Inertia& I, double* out) { out[0] = I.m, out[1] = I.gx, out[2] = I.gy, out[3] = I.io; }
  template <class T>
  DYN_INLINE static void netForce(const T* I, const T* v, const T* a, const T* g, T* f) {
    const T m = I[0], gx = I[1], gy = I[2], io = I[3];
    const T x[3] = {a[0] - g[0], a[1] - g[1], a[2] - g[2]};
    const T q[3] = {io * x[0] + gx * x[1] + gy * x[2], gx * x[0] + m * x[1], gy * x[0] + m * x[2]};
    const T p[3] = {io * v[0] + gx * v[1] + gy * v[2], gx * v[0] + m * v[1], gy * v[0] + m * v[2]};
    f[0] = q[0] + (v[1] * p[2] - v[2] * p[1]);
    f[1] = q[1] + -v[0] * p[2];
    f[2] = q[2] + v[0] * p[1];
  }
  // Xᵀ I X: a rigid-body inertia I given in frame B, in frame A. Closed form of the product:
  // g_A = Eᵀ g + m ẑ×r, I_O,A = I_O + 2 (Eᵀ g)·(ẑ×r) + m |r|².
  DYN_INLINE static Inertia inertiaInParent(const Transform& X, const Mat& I) {
    const double m = I(1, 1);
    const Pos g = rotateBack(X.E, I(1, 0), I(2, 0));
    const double px = -X.r.y(), py = X.r.x();  // ẑ × r
    return {m, g.x() + m * px, g.y() + m * py, I(0, 0) + 2.0 * (g.x() * px + g.y() * py) + m * (px * px + py * py)};
  }
  // The same, written number by number into out and its copy (CRBA's composite starts as the body's
  // own): an Inertia copied whole is reloaded 16 bytes at a time from 8-byte stores, a store-forwarding
  // stall (as spatial_lanes.h storeInertia).
  DYN_INLINE static void inertiaInParent(const Transform& X, const Mat& I, Inertia& out, Inertia& copy) {
    const Inertia A = inertiaInParent(X, I);
    out.m = copy.m = A.m;
    out.gx = copy.gx = A.gx;
    out.gy = copy.gy = A.gy;
    out.io = copy.io = A.io;
  }
  // (Spatial's centre-of-mass form; planar transforms the origin form directly.)
  struct Central {};
  static Central central(const Mat&) { return {}; }
  // Rigid-body inertia at the body origin: mass m, centre of mass c, inertia Ic about c.
  static Mat inertia(double m, const Pos& c, double Ic) {
    Mat I;
    I << Ic + m * c.squaredNorm(), -m * c.y(), m * c.x(),  //
        -m * c.y(), m, 0,                                 //
        m * c.x(), 0, m;
    return I;
  }
  // Joint: revolute about z, or prismatic along axis.
  static Vec revoluteAxis() { return {1, 0, 0}; }
  static Vec prismaticAxis(const Axis& a) { return {0, a.x(), a.y()}; }
  static Transform jointTransform(bool revolute, const Axis& axis, double q) {
    if (revolute) return {rotation(q), Pos::Zero()};
    return {Rot::Identity(), axis * q};
  }
  // Classical acceleration of a point from the spatial acceleration and velocity at it.
  static Vec classicalAcceleration(const Vec& a, const Vec& v) {
    return {a[0], a[1] - v[0] * v[2], a[2] + v[0] * v[1]};
  }
  static Pos worldPoint(const Transform& X0, const Pos& p) {
    const Pos w = rotateBack(X0.E, p.x(), p.y());
    return {X0.r.x() + w.x(), X0.r.y() + w.y()};
  }
  // Mass and centre of mass back out of a body inertia.
  // Zero inertia (a rigid-body inertia is positive semi-definite: zero mass and diagonal make it zero).
  static bool massless(const Mat& I) { return I(1, 1) == 0 && I(0, 0) == 0; }
  static void massAndCom(const Mat& I, double& m, Pos& c) {
    m = I(1, 1);
    c = m > 0 ? Pos(I(0, 2) / m, -I(0, 1) / m) : Pos::Zero();
  }
  static Pos linear(const Vec& v) { return v.tail<2>(); }
};

// ---------------------------------------------------------------- spatial: 6-vectors
struct Spatial {
  static constexpr int kDim = 6;
  using Vec = Eigen::Matrix<double, 6, 1>;  // (ω, v) or (n, f)
  using Mat = Eigen::Matrix<double, 6, 6>;
  using Rot = Eigen::Matrix3d;
  using Pos = Eigen::Vector3d;
  using Axis = Eigen::Vector3d;

  // `turned` is false when E is exactly the identity (a pure translation: prismatic joints, most
  // placements), so the operations below skip their rotations; {E, r} leaves it true, always safe.
  struct Transform {
    Rot E = Rot::Identity();
    Pos r = Pos::Zero();
    bool turned = true;
  };
  // The same transform, marked unturned when E is exactly the identity.
  static Transform marked(const Transform& X) { return {X.E, X.r, X.E != Rot::Identity()}; }

  DYN_INLINE static double dot(const Vec& a, const Vec& b) {
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4] + a[5] * b[5];
  }
  static Eigen::Matrix3d skew(const Pos& p) {
    Eigen::Matrix3d s;
    s << 0, -p.z(), p.y(), p.z(), 0, -p.x(), -p.y(), p.x(), 0;
    return s;
  }
  // The operations on 6-vectors are written coefficient by coefficient on their 3-vector halves, as
  // the planar ones are: Eigen's comma initializer became an out-of-line call whose 8-byte stores
  // were then copied 16 bytes at a time (a store-forwarding stall: a third of CRBA's time).
  DYN_INLINE static void cross3(const double* a, const double* b, double* o) {
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
  }
  DYN_INLINE static void mul3(const Rot& E, const double* x, double* o) {  // o = E x
    for (int i = 0; i < 3; ++i) o[i] = E(i, 0) * x[0] + E(i, 1) * x[1] + E(i, 2) * x[2];
  }
  DYN_INLINE static void mulT3(const Rot& E, const double* x, double* o) {  // o = Eᵀ x
    for (int i = 0; i < 3; ++i) o[i] = E(0, i) * x[0] + E(1, i) * x[1] + E(2, i) * x[2];
  }
  // The linear part of motion v = (ω, v) seen at point p with unturned axes: v − p × ω (motion() by
  // translation(p) without building the Transform). Entry by entry, from 6 doubles at v.
  DYN_INLINE static void linearAt(const Pos& p, const double* v, double* out) {
    double pw[3];
    cross3(p.data(), v, pw);
    for (int i = 0; i < 3; ++i) out[i] = v[3 + i] - pw[i];
  }
  DYN_INLINE static Vec motion(const Transform& X, const Vec& v) {
    // (E ω, E (v − r × ω))
    double u[3];
    linearAt(X.r, v.data(), u);
    Vec out;
    if (!X.turned) {
      for (int i = 0; i < 3; ++i) out[i] = v[i], out[3 + i] = u[i];
    } else {
      mul3(X.E, v.data(), out.data());
      mul3(X.E, u, out.data() + 3);
    }
    return out;
  }
  DYN_INLINE static Vec motionInverse(const Transform& X, const Vec& v) {
    // (Eᵀ ω, Eᵀ v + r × Eᵀ ω)
    Vec out;
    double u[3], rw[3];
    if (!X.turned) {
      for (int i = 0; i < 3; ++i) out[i] = v[i], u[i] = v[3 + i];
    } else {
      mulT3(X.E, v.data(), out.data());
      mulT3(X.E, v.data() + 3, u);
    }
    cross3(X.r.data(), out.data(), rw);
    for (int i = 0; i < 3; ++i) out[3 + i] = u[i] + rw[i];
    return out;
  }
  DYN_INLINE static Vec forceTranspose(const Transform& X, const Vec& f) {
    // (Eᵀ n + r × Eᵀ f, Eᵀ f)
    Vec out;
    double n[3], rf[3];
    if (!X.turned) {
      for (int i = 0; i < 3; ++i) n[i] = f[i], out[3 + i] = f[3 + i];
    } else {
      mulT3(X.E, f.data(), n);
      mulT3(X.E, f.data() + 3, out.data() + 3);
    }
    cross3(X.r.data(), out.data() + 3, rf);
    for (int i = 0; i < 3; ++i) out[i] = n[i] + rf[i];
    return out;
  }
  static Mat motionMatrix(const Transform& X) {
    Mat m = Mat::Zero();
    m.block<3, 3>(0, 0) = X.E;
    m.block<3, 3>(3, 0) = -X.E * skew(X.r);
    m.block<3, 3>(3, 3) = X.E;
    return m;
  }
  // Entry by entry, each sum as Eigen's 3×3 products sum it (x0 + (x1 + x2)): the same bits as
  // {bc.E ab.E, ab.r + ab.Eᵀ bc.r}, without the out-of-line product call.
  DYN_INLINE static Transform compose(const Transform& bc, const Transform& ab) {
    if (!ab.turned) return {bc.E, ab.r + bc.r, bc.turned};
    Transform out;
    for (int a = 0; a < 3; ++a) out.r[a] = ab.r[a] + (ab.E(0, a) * bc.r[0] + (ab.E(1, a) * bc.r[1] + ab.E(2, a) * bc.r[2]));
    if (!bc.turned) {
      out.E = ab.E;
      return out;
    }
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b) out.E(a, b) = bc.E(a, 0) * ab.E(0, b) + (bc.E(a, 1) * ab.E(1, b) + bc.E(a, 2) * ab.E(2, b));
    return out;
  }
  DYN_INLINE static Transform inverse(const Transform& X) { return {X.E.transpose(), -X.E * X.r, X.turned}; }
  DYN_INLINE static Transform translation(const Pos& p) { return {Rot::Identity(), p, false}; }

  DYN_INLINE static Vec crossMotion(const Vec& v, const Vec& m) {
    // (ω × m_ω, ω × m_v + v × m_ω)
    Vec out;
    double a[3];
    cross3(v.data(), m.data(), out.data());
    cross3(v.data(), m.data() + 3, out.data() + 3);
    cross3(v.data() + 3, m.data(), a);
    for (int i = 0; i < 3; ++i) out[3 + i] += a[i];
    return out;
  }
  DYN_INLINE static Vec crossForce(const Vec& v, const Vec& f) {
    // (ω × n + v × f, ω × f)
    Vec out;
    double a[3];
    cross3(v.data(), f.data(), out.data());
    cross3(v.data() + 3, f.data() + 3, a);
    for (int i = 0; i < 3; ++i) out[i] += a[i];
    cross3(v.data(), f.data() + 3, out.data() + 3);
    return out;
  }
  DYN_INLINE static Vec inertiaTimes(const Mat& I, const Vec& v) { return I * v; }
  // A rigid-body inertia in its 13 numbers, for the composite inertias of CRBA: the blocks of
  // I = [[I_O, [h]×], [[h]×ᵀ, m 1]] (I_O about the frame's origin, h = m c).
  struct Inertia {
    double m = 0;
    Pos h = Pos::Zero();
    Eigen::Matrix3d Io = Eigen::Matrix3d::Zero();
    Inertia& operator+=(const Inertia& o) {
      m += o.m;
      h += o.h;
      Io += o.Io;
      return *this;
    }
  };
  static Inertia compact(const Mat& I) { return {I(5, 5), Pos(I(2, 4), I(0, 5), I(1, 3)), I.block<3, 3>(0, 0)}; }
  // I v = (I_O ω + h × v, m v − h × ω).
  DYN_INLINE static Vec inertiaTimes(const Inertia& I, const Vec& v) {
    Vec out;
    double hu[3], hw[3];
    mul3(I.Io, v.data(), out.data());
    cross3(I.h.data(), v.data() + 3, hu);
    cross3(I.h.data(), v.data(), hw);
    for (int i = 0; i < 3; ++i) out[i] += hu[i], out[3 + i] = I.m * v[3 + i] - hw[i];
    return out;
  }
  // RNEA's net force on a body, f = I (a − g) + v ×* (I v) (biasForcesWorld), on lanes T: double for one
  // body, or a GCC/Clang vector of two doubles for two bodies at once. The products and sums of
  // inertiaTimes and crossForce above, in their order, so each lane is their bits (packed SSE2/wasm
  // products and sums round as scalar ones; -ffp-contract=off, no FMA). I: the Inertia's 13 numbers
  // (inertiaNumbers: m, h, I_O row by row), v, a, g: 6 each.
  static constexpr int kInertiaNumbers = 13;
  DYN_INLINE static void inertiaNumbers(const Inertia& I, double* out) {
    out[0] = I.m;
    for (int i = 0; i < 3; ++i) out[1 + i] = I.h[i];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) out[4 + 3 * i + j] = I.Io(i, j);
  }
  template <class T>
  DYN_INLINE static void cross3(const T* a, const T* b, T* o) {
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
  }
  template <class T>
  DYN_INLINE static void inertiaTimes(const T* I, const T* v, T* out) {  // inertiaTimes(Inertia, Vec)
    T hu[3], hw[3];
    for (int i = 0; i < 3; ++i) out[i] = I[4 + 3 * i] * v[0] + I[5 + 3 * i] * v[1] + I[6 + 3 * i] * v[2];
    cross3(I + 1, v + 3, hu);
    cross3(I + 1, v, hw);
    for (int i = 0; i < 3; ++i) out[i] = out[i] + hu[i], out[3 + i] = I[0] * v[3 + i] - hw[i];
  }
  template <class T>
  DYN_INLINE static void netForce(const T* I, const T* v, const T* a, const T* g, T* f) {
    T x[6], q[6], p[6], c[6], t[3];
    for (int k = 0; k < 6; ++k) x[k] = a[k] - g[k];
    inertiaTimes(I, x, q);
    inertiaTimes(I, v, p);
    // crossForce(v, p): (ω × n + v × f, ω × f)
    cross3(v, p, c);
    cross3(v + 3, p + 3, t);
    for (int i = 0; i < 3; ++i) c[i] = c[i] + t[i];
    cross3(v, p + 3, c + 3);
    for (int k = 0; k < 6; ++k) f[k] = q[k] + c[k];
  }
  // The same inertia about the centre of mass: mass m, centre c and I_c (body coordinates).
  struct Central {
    double m = 0;
    Pos c = Pos::Zero();
    Eigen::Matrix3d Ic = Eigen::Matrix3d::Zero();
    bool diagonal = true;  // I_c diagonal in body axes (cylinders and boxes along them: most links)
  };
  // A number this small against the unit (an axis' component) or against a body's inertia (a product
  // of inertia against tr I_O) is a rounding residue: models state inertias and directions to a few
  // digits, never to 1e-12 (a tilt of 1e-12 rad, 1e-12 kg m² in 1 kg m²), while the residues of a
  // quarter turn (cos π/2 = 6e-17) or of the round trip I_c → I_O → I_c are a few ε = 2.2e-16, 10^4
  // below it. Such residues are made exact zeros (here, and in physics/model_file's loader), so the
  // coordinate-axis and diagonal-inertia paths take them.
  static constexpr double kResidue = 1e-12;
  // Products of inertia at most kResidue · scale made exact zeros (scale: the inertia's trace).
  static void snapProducts(Eigen::Matrix3d& I, double scale) {
    const double residue = kResidue * scale;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (i != j && std::abs(I(i, j)) <= residue) I(i, j) = 0.0;
  }
  static Central central(const Mat& I) {
    Central out;
    massAndCom(I, out.m, out.c);
    // I_O = I_c + m(|c|² 1 − c cᵀ)
    out.Ic = I.block<3, 3>(0, 0) - out.m * (out.c.squaredNorm() * Eigen::Matrix3d::Identity() - out.c * out.c.transpose());
    // The subtraction leaves products of a few ε m |c_i c_j| (≤ ε tr I_O) where I_c's were exactly 0:
    // below kResidue tr I_O, a product is that residue.
    snapProducts(out.Ic, I(0, 0) + I(1, 1) + I(2, 2));
    out.diagonal = out.Ic(0, 1) == 0 && out.Ic(0, 2) == 0 && out.Ic(1, 2) == 0 && out.Ic(1, 0) == 0 && out.Ic(2, 0) == 0 && out.Ic(2, 1) == 0;
    return out;
  }
  // (Xᵀ I X from this form, one body or two at a time: spatial_lanes.h centralInWorld.)
  static Mat inertia(double m, const Pos& c, const Eigen::Matrix3d& Ic) {
    const Eigen::Matrix3d C = skew(c);
    Mat I;
    I << Ic + m * C * C.transpose(), m * C, m * C.transpose(), m * Eigen::Matrix3d::Identity();
    return I;
  }
  // Joints: the axis a is a unit vector (TreeModel::addBody normalises it).
  static Vec revoluteAxis(const Axis& a) {
    Vec s;
    for (int i = 0; i < 3; ++i) s[i] = a[i], s[3 + i] = 0.0;
    return s;
  }
  static Vec prismaticAxis(const Axis& a) {
    Vec s;
    for (int i = 0; i < 3; ++i) s[i] = 0.0, s[3 + i] = a[i];
    return s;
  }
  // Revolute: E = R(a, q)ᵀ = c 1 + (1 − c) a aᵀ − s [a]× (Rodrigues, transposed); prismatic: r = a q.
  DYN_INLINE static Transform jointTransform(bool revolute, const Axis& a, double q) {
    if (!revolute) return {Rot::Identity(), a * q, false};
    double c, s;
    det::sincos(q, s, c);  // det::cos and det::sin, one reduction
    const double t = 1.0 - c;
    const double x = a[0], y = a[1], z = a[2];
    Rot E;
    E(0, 0) = c + t * x * x, E(0, 1) = t * x * y + s * z, E(0, 2) = t * x * z - s * y;
    E(1, 0) = t * x * y - s * z, E(1, 1) = c + t * y * y, E(1, 2) = t * y * z + s * x;
    E(2, 0) = t * x * z + s * y, E(2, 1) = t * y * z - s * x, E(2, 2) = c + t * z * z;
    return {E, Pos::Zero(), true};
  }
  // A joint turning about coordinate axis k (Featherstone's Rx, Ry, Rz: most joints) after its
  // placement: out = X_J ∘ X_tree ∘ P, P the parent's world transform (null at the root), E_J = R_k(q)ᵀ.
  // E_J mixes two rows of E (i = k+1, j = k+2 mod 3):
  //   row i ← c E_i + s E_j,  row j ← c E_j − s E_i,  row k unchanged  (12 products, not a full 27).
  // Written entry by entry into out: a Transform built on the stack and then copied whole is reloaded
  // 16 bytes at a time from its 8-byte stores, which stalls on store forwarding (a tenth of the step).
  // The axis index a constant in each of three copies, so that the rows mixed stay in registers (a row
  // picked at run time is a stack array's).
  DYN_INLINE static void turnAbout(int k, double c, double s, const Transform& X_tree, const Transform* P, Transform& out) {
    if (k == 0) turnAboutAxis<0>(c, s, X_tree, P, out);
    else if (k == 1) turnAboutAxis<1>(c, s, X_tree, P, out);
    else turnAboutAxis<2>(c, s, X_tree, P, out);
  }
  template <int k>
  DYN_INLINE static void turnAboutAxis(double c, double s, const Transform& X_tree, const Transform* P, Transform& out) {
    constexpr int i = k == 2 ? 0 : k + 1, j = i == 2 ? 0 : i + 1;
    // X_tree ∘ P = {E_tree E_P, r_P + E_Pᵀ r_tree}, summed as Eigen's products sum (x0 + (x1 + x2)): the
    // same bits as compose().
    double E[3][3], r[3];
    bool turned = X_tree.turned;
    if (!P) {
      for (int a = 0; a < 3; ++a) {
        r[a] = X_tree.r[a];
        for (int b = 0; b < 3; ++b) E[a][b] = X_tree.E(a, b);
      }
    } else {
      for (int a = 0; a < 3; ++a)
        r[a] = P->r[a] + (P->turned ? P->E(0, a) * X_tree.r[0] + (P->E(1, a) * X_tree.r[1] + P->E(2, a) * X_tree.r[2]) : X_tree.r[a]);
      const Transform& F = X_tree.turned ? X_tree : *P;  // the one that turns, if only one does
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b)
          E[a][b] = X_tree.turned && P->turned ? X_tree.E(a, 0) * P->E(0, b) + (X_tree.E(a, 1) * P->E(1, b) + X_tree.E(a, 2) * P->E(2, b)) : F.E(a, b);
      turned = X_tree.turned || P->turned;
    }
    for (int a = 0; a < 3; ++a) out.r[a] = r[a];
    out.turned = true;
    if (!turned) {  // E_J itself
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) out.E(a, b) = 0.0;
      out.E(i, i) = out.E(j, j) = c, out.E(i, j) = s, out.E(j, i) = -s, out.E(k, k) = 1.0;
      return;
    }
    for (int col = 0; col < 3; ++col) {
      out.E(i, col) = c * E[i][col] + s * E[j][col];
      out.E(j, col) = c * E[j][col] - s * E[i][col];
      out.E(k, col) = E[k][col];
    }
  }
  // The axis of a revolute joint about coordinate axis k (−e_k when `negative`) of a body at X_world,
  // in world coordinates at the origin: X⁻¹ (±e_k, 0) = (±E_kᵀ, r × ±E_kᵀ) (E_k: row k of E), into out.
  DYN_INLINE static void coordinateAxisInWorld(int k, bool negative, const Transform& X, Vec& out) {
    for (int c = 0; c < 3; ++c) out[c] = X.turned ? X.E(k, c) : (c == k ? 1.0 : 0.0);
    if (negative)
      for (int c = 0; c < 3; ++c) out[c] = -out[c];
    cross3(X.r.data(), out.data(), out.data() + 3);
  }
  DYN_INLINE static Vec classicalAcceleration(const Vec& a, const Vec& v) {
    Vec out;
    double wv[3];
    cross3(v.data(), v.data() + 3, wv);
    for (int i = 0; i < 3; ++i) out[i] = a[i], out[3 + i] = a[3 + i] + wv[i];
    return out;
  }
  DYN_INLINE static Pos worldPoint(const Transform& X0, const Pos& p) { return X0.r + X0.E.transpose() * p; }
  DYN_INLINE static bool massless(const Mat& I) { return I(5, 5) == 0 && I(0, 0) == 0 && I(1, 1) == 0 && I(2, 2) == 0; }
  static void massAndCom(const Mat& I, double& m, Pos& c) {
    m = I(5, 5);
    const Eigen::Matrix3d mC = I.block<3, 3>(0, 3);
    c = m > 0 ? Pos(Pos(mC(2, 1), mC(0, 2), mC(1, 0)) / m) : Pos(Pos::Zero());
  }
  DYN_INLINE static Pos linear(const Vec& v) { return v.tail<3>(); }
};

}  // namespace dyn
