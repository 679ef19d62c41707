/// \file
/// Plücker coordinate transforms between two frames, stored as a rotation and
/// a translation (never as a 6×6 matrix on the hot path).
///
/// Transform X = ᴮX_A takes coordinates in frame A to coordinates in frame B:
///   E : rotation with x_B = E x_A  (so E = ᴮR_A = (ᴬR_B)ᵀ),
///   r : origin of B, expressed in A.
/// With linear-first vectors (docs/conventions.md, "Spatial vectors: linear part first"):
///   motion  [v; ω]_B = [E(v − r×ω); Eω]
///   force   [f; n]_B = [E f; E(n − r×f)]
/// The force transform B → A is Xᵀ, which is what `inverseApplyForce` computes.
#pragma once

#include "zwang/spatial/types.hpp"

namespace zwang::spatial {

/// Plücker transform ᴮX_A, stored as the rotation E and the translation r of the file comment.
struct Transform {
  Mat3 E = Mat3::Identity();  ///< E = ᴮR_A: takes A's components to B's.
  Vec3 r = Vec3::Zero();      ///< r: the origin of B, expressed in A.

  /// The identity (B = A).
  static Transform identity() { return {}; }
  /// ᴮX_A for a frame B whose pose in A is (rotation ᴬR_B, origin p).
  static Transform fromPose(const Mat3& R_AB, const Vec3& p_AB) { return {R_AB.transpose(), p_AB}; }
  /// ᴮX_A for a frame B with A's axes and its origin at p in A.
  static Transform translation(const Vec3& p) { return {Mat3::Identity(), p}; }
  /// ᴮX_A for a frame B with A's origin, rotated by ᴬR_B.
  static Transform rotation(const Mat3& R_AB) { return {R_AB.transpose(), Vec3::Zero()}; }

  /// Pose of B in A (the inverse reading of the same data).
  Mat3 rotationOfTarget() const { return E.transpose(); }
  /// Origin of B, expressed in A.
  const Vec3& originOfTarget() const { return r; }

  /// ᶜX_A = ᶜX_B · ᴮX_A  (this = ᶜX_B, rhs = ᴮX_A)
  ZWANG_ALWAYS_INLINE Transform operator*(const Transform& rhs) const {
    return {E * rhs.E, rhs.r + rhs.E.transpose() * r};
  }

  /// ᴬX_B
  Transform inverse() const { return {E.transpose(), -(E * r)}; }

  /// X m: a motion vector given in A, expressed in B.
  Vec6 applyMotion(const Vec6& m) const {
    const Vec3 w = ang(m);
    return stack(E * (Vec3(lin(m)) - r.cross(w)), E * w);
  }
  /// X⁻¹ m: a motion vector given in B, expressed in A.
  Vec6 inverseApplyMotion(const Vec6& m) const {
    const Vec3 w = E.transpose() * ang(m);
    return stack(E.transpose() * lin(m) + r.cross(w), w);
  }
  /// X* f: a force given in A, expressed in B.
  Vec6 applyForce(const Vec6& f) const {
    const Vec3 fl = lin(f);
    return stack(E * fl, E * (Vec3(ang(f)) - r.cross(fl)));
  }
  /// Xᵀ f: a force given in B, expressed in A.
  Vec6 inverseApplyForce(const Vec6& f) const {
    const Vec3 fl = E.transpose() * lin(f);
    return stack(fl, E.transpose() * ang(f) + r.cross(fl));
  }

  /// Xᵀ I X: a 6×6 symmetric (articulated) inertia given in B, expressed in A.
  /// With I = [M H; Hᵀ C] and X = blkdiag(E,E)·[1 −r×; 0 1]: rotate the blocks
  /// (M' = EᵀME, H' = EᵀHE, C' = EᵀCE), then shift:
  ///   Xᵀ I X = [M'  P; Pᵀ  C' + r×P − H'ᵀr×],  P = H' − M' r×.
  /// Only the lower triangle of I's diagonal blocks is read.
  Mat6 inverseApplyInertia(const Mat6& I) const {
    const Mat3 M = rotateSymmetric(I.topLeftCorner<3, 3>());
    const Mat3 C = rotateSymmetric(I.bottomRightCorner<3, 3>());
    Mat3 H;
    H.noalias() = E.transpose() * (I.topRightCorner<3, 3>() * E);
    Mat3 P;  // H' − M' r×: row k of M'·r× is (m_k × r)ᵀ, M' symmetric so m_k = column k
    for (int k = 0; k < 3; ++k) P.row(k) = H.row(k) - M.col(k).cross(r).transpose();
    Mat6 out;
    out.topLeftCorner<3, 3>() = M;
    out.topRightCorner<3, 3>() = P;
    out.bottomLeftCorner<3, 3>() = P.transpose();
    // r×P column j is r × p_j; row i of H'ᵀ r× is (h'_i × r)ᵀ with h'_i column i of H'.
    Mat3 Q;
    for (int j = 0; j < 3; ++j) Q.col(j) = r.cross(P.col(j));
    for (int i = 0; i < 3; ++i) {
      const Vec3 w = H.col(i).cross(r);
      for (int j = 0; j <= i; ++j) {
        const double value = C(i, j) + Q(i, j) - w[j];
        out(3 + i, 3 + j) = value;
        out(3 + j, 3 + i) = value;
      }
    }
    return out;
  }

  /// Eᵀ S E for a symmetric 3×3 S (lower triangle read), symmetric result.
  template <class Sym>
  Mat3 rotateSymmetric(const Sym& S) const {
    Mat3 full;
    full << S(0, 0), S(1, 0), S(2, 0),  //
        S(1, 0), S(1, 1), S(2, 1),      //
        S(2, 0), S(2, 1), S(2, 2);
    Mat3 SE;
    SE.noalias() = full * E;
    Mat3 out;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j <= i; ++j) out(i, j) = out(j, i) = E.col(i).dot(SE.col(j));
    return out;
  }

  /// The 6×6 motion transform matrix, for tests and debugging only.
  Mat6 motionMatrix() const {
    Mat6 X = Mat6::Zero();
    X.topLeftCorner<3, 3>() = E;
    X.topRightCorner<3, 3>() = -E * skew(r);
    X.bottomRightCorner<3, 3>() = E;
    return X;
  }
};

}  // namespace zwang::spatial
