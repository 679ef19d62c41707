// Plücker coordinate transforms between two frames, stored as a rotation and
// a translation (never as a 6×6 matrix on the hot path).
//
// Transform X = ᴮX_A takes coordinates in frame A to coordinates in frame B:
//   E : rotation with x_B = E x_A  (so E = ᴮR_A = (ᴬR_B)ᵀ),
//   r : origin of B, expressed in A.
// With linear-first vectors (SPEC):
//   motion  [v; ω]_B = [E(v − r×ω); Eω]
//   force   [f; n]_B = [E f; E(n − r×f)]
// The force transform B → A is Xᵀ, which is what `inverseApplyForce` computes.
#pragma once

#include "zwang/spatial/types.hpp"

namespace zwang::spatial {

struct Transform {
  Mat3 E = Mat3::Identity();
  Vec3 r = Vec3::Zero();

  static Transform identity() { return {}; }
  // ᴮX_A for a frame B whose pose in A is (rotation ᴬR_B, origin p).
  static Transform fromPose(const Mat3& R_AB, const Vec3& p_AB) { return {R_AB.transpose(), p_AB}; }
  static Transform translation(const Vec3& p) { return {Mat3::Identity(), p}; }
  static Transform rotation(const Mat3& R_AB) { return {R_AB.transpose(), Vec3::Zero()}; }

  // Pose of B in A (the inverse reading of the same data).
  Mat3 rotationOfTarget() const { return E.transpose(); }
  const Vec3& originOfTarget() const { return r; }

  // ᶜX_A = ᶜX_B · ᴮX_A  (this = ᶜX_B, rhs = ᴮX_A)
  Transform operator*(const Transform& rhs) const { return {E * rhs.E, rhs.r + rhs.E.transpose() * r}; }

  // ᴬX_B
  Transform inverse() const { return {E.transpose(), -(E * r)}; }

  Vec6 applyMotion(const Vec6& m) const {
    const Vec3 w = ang(m);
    return stack(E * (Vec3(lin(m)) - r.cross(w)), E * w);
  }
  Vec6 inverseApplyMotion(const Vec6& m) const {
    const Vec3 w = E.transpose() * ang(m);
    return stack(E.transpose() * lin(m) + r.cross(w), w);
  }
  Vec6 applyForce(const Vec6& f) const {
    const Vec3 fl = lin(f);
    return stack(E * fl, E * (Vec3(ang(f)) - r.cross(fl)));
  }
  // Xᵀ f: a force given in B, expressed in A.
  Vec6 inverseApplyForce(const Vec6& f) const {
    const Vec3 fl = E.transpose() * lin(f);
    return stack(fl, E.transpose() * ang(f) + r.cross(fl));
  }

  // Columnwise versions for 6×m blocks of force vectors (constraint directions).
  template <class In, class Out>
  void inverseApplyForceColumns(const In& F, Out&& out) const {
    for (Eigen::Index k = 0; k < F.cols(); ++k) out.col(k) = inverseApplyForce(F.col(k));
  }

  // Xᵀ I X: a 6×6 (articulated, symmetric) inertia given in B, expressed in A.
  // Done with 3×3 blocks: X = blkdiag(E,E)·[1 −r×; 0 1].
  Mat6 inverseApplyInertia(const Mat6& I) const {
    const Mat3 Et = E.transpose();
    const Mat3 M11 = Et * I.topLeftCorner<3, 3>() * E;
    const Mat3 M12 = Et * I.topRightCorner<3, 3>() * E;
    const Mat3 M22 = Et * I.bottomRightCorner<3, 3>() * E;
    const Mat3 R = skew(r);
    const Mat3 top_right = M12 - M11 * R;  // M11(−r×) + M12
    Mat6 out;
    out.topLeftCorner<3, 3>() = M11;
    out.topRightCorner<3, 3>() = top_right;
    out.bottomLeftCorner<3, 3>() = top_right.transpose();
    out.bottomRightCorner<3, 3>() = R * top_right - M12.transpose() * R + M22;
    return out;
  }

  // The 6×6 motion transform matrix, for tests and debugging only.
  Mat6 motionMatrix() const {
    Mat6 X = Mat6::Zero();
    X.topLeftCorner<3, 3>() = E;
    X.topRightCorner<3, 3>() = -E * skew(r);
    X.bottomRightCorner<3, 3>() = E;
    return X;
  }
};

}  // namespace zwang::spatial
