/// \file
/// Spatial rigid-body inertia, stored compactly as (m, h = m·c, Ī) where c is
/// the centre of mass and Ī the rotational inertia about the frame ORIGIN.
/// Its 6×6 matrix (linear first) is  [m·1  −h×; h×  Ī],  Ī = I_c − m·c×c×.
#pragma once

#include "zwang/spatial/transform.hpp"

namespace zwang::spatial {

/// Spatial rigid-body inertia (m, h = m·c, Ī about the frame origin), as in the file comment.
struct RigidInertia {
  double mass = 0.0;         ///< m [kg]
  Vec3 h = Vec3::Zero();     ///< first mass moment m·c
  Mat3 Ibar = Mat3::Zero();  ///< rotational inertia about the origin

  /// From mass, centre of mass and rotational inertia about the centre of mass,
  /// all in the body frame.
  static RigidInertia fromMassComInertia(double m, const Vec3& com, const Mat3& I_com) {
    const Mat3 C = skew(com);
    return {m, m * com, I_com - m * C * C};
  }

  /// Centre of mass c = h/m (zero for a massless body).
  Vec3 com() const { return mass > 0.0 ? Vec3(h / mass) : Vec3::Zero(); }
  /// Rotational inertia about the centre of mass, I_c = Ī + m·c×c× (Ī for a massless body).
  Mat3 inertiaAboutCom() const {
    if (mass <= 0.0) return Ibar;
    const Mat3 C = skew(com());
    return Ibar + mass * C * C;
  }

  /// I m for a motion vector m: its momentum (a force vector).
  ZWANG_ALWAYS_INLINE Vec6 operator*(const Vec6& m) const {
    const Vec3 v = lin(m), w = ang(m);
    return stack(mass * v - h.cross(w), h.cross(v) + Ibar * w);
  }

  /// Two bodies rigidly joined (both inertias in the same frame).
  RigidInertia operator+(const RigidInertia& o) const { return {mass + o.mass, h + o.h, Ibar + o.Ibar}; }
  /// Adds a body rigidly joined (its inertia in the same frame).
  RigidInertia& operator+=(const RigidInertia& o) { return *this = *this + o; }

  /// M += this inertia's 6×6 matrix.
  void addTo(Mat6& M) const {
    M.diagonal().head<3>().array() += mass;
    M.topRightCorner<3, 3>() -= skew(h);
    M.bottomLeftCorner<3, 3>() += skew(h);
    M.bottomRightCorner<3, 3>() += Ibar;
  }

  /// The 6×6 matrix [m·1  −h×; h×  Ī].
  Mat6 matrix() const {
    Mat6 I;
    I.topLeftCorner<3, 3>() = mass * Mat3::Identity();
    I.topRightCorner<3, 3>() = -skew(h);
    I.bottomLeftCorner<3, 3>() = skew(h);
    I.bottomRightCorner<3, 3>() = Ibar;
    return I;
  }
};

/// The same body's inertia, expressed in frame B, given it in frame A and X = ᴮX_A.
inline RigidInertia transformInertia(const Transform& X, const RigidInertia& I) {
  const Vec3 h_shift = I.h - I.mass * X.r;  // first moment about B's origin, A's axes
  const Mat3 Ibar_shift = I.Ibar + skew(X.r) * skew(I.h) + skew(h_shift) * skew(X.r);
  return {I.mass, X.E * h_shift, X.E * Ibar_shift * X.E.transpose()};
}

/// The inverse: given the inertia in B, express it in A. With R = Eᵀ (B's axes
/// in A) and p = r (B's origin in A): h_A = m p + R h, and the rotational
/// inertia moves from B's origin to A's by the parallel-axis rule with a first
/// moment, Ī_A = R Ī Rᵀ + m(|p|²1 − p pᵀ) + 2(p·h_R)1 − p h_Rᵀ − h_R pᵀ,
/// h_R = R h.
inline RigidInertia inverseTransformInertia(const Transform& X, const RigidInertia& I) {
  const Mat3 R = X.E.transpose();
  const Vec3& p = X.r;
  const Vec3 hR = R * I.h;
  const Mat3 IR = I.Ibar * X.E;  // Ī Rᵀ
  RigidInertia out;
  out.mass = I.mass;
  out.h = I.mass * p + hR;
  const double diagonal = I.mass * p.squaredNorm() + 2.0 * p.dot(hR);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j <= i; ++j) {
      double value = R.row(i).dot(IR.col(j)) - I.mass * p[i] * p[j] - p[i] * hR[j] - hR[i] * p[j];
      if (i == j) value += diagonal;
      out.Ibar(i, j) = out.Ibar(j, i) = value;
    }
  return out;
}

}  // namespace zwang::spatial
