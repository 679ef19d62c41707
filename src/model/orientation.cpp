// Rotation vectors and quaternion orders (include/zwang/orientation.hpp). The
// logarithm goes through the quaternion: Eigen's matrix-to-quaternion takes
// the largest of |w|, |x|, |y|, |z| first (Shepperd's method), so no
// component is found by a difference of nearly equal numbers, and
// θ = 2·atan2(|v|, |w|) keeps full relative accuracy at both ends: near 0,
// where acos(w) loses half the digits, and near π, where the axis from
// (R − Rᵀ)/2 vanishes.
#include "zwang/orientation.hpp"

#include <cmath>

#include <Eigen/Geometry>

namespace zwang {

Eigen::Vector4d quaternionWxyzFromXyzw(const Eigen::Vector4d& xyzw) noexcept {
  return {xyzw[3], xyzw[0], xyzw[1], xyzw[2]};
}

Eigen::Vector4d quaternionXyzwFromWxyz(const Eigen::Vector4d& wxyz) noexcept {
  return {wxyz[1], wxyz[2], wxyz[3], wxyz[0]};
}

Eigen::Vector3d quaternionLog(const Eigen::Vector4d& wxyz) noexcept {
  const double norm = wxyz.norm();
  if (!(norm > 0.0)) return Eigen::Vector3d::Zero();
  // The shortest rotation: w ≥ 0 (q and −q are the same rotation).
  const Eigen::Vector4d q = (wxyz[0] < 0.0 ? -wxyz : wxyz) / norm;
  const Eigen::Vector3d v = q.tail<3>();
  const double s = v.norm(), w = q[0];
  // φ = θ/s · v with θ = 2 atan2(s, w). For s < 1e-5, 2 atan2(s, w)/s = 2/w (1 − s²/(3w²)) + O(s⁴): the
  // dropped term is 1e-20 relative, below rounding (w ≈ 1 there).
  if (s < 1e-5) return (2.0 / w) * (1.0 - s * s / (3.0 * w * w)) * v;
  return (2.0 * std::atan2(s, w) / s) * v;
}

Eigen::Vector3d rotationLog(const Eigen::Matrix3d& R) noexcept {
  const Eigen::Quaterniond q(R);
  return quaternionLog(Eigen::Vector4d(q.w(), q.x(), q.y(), q.z()));
}

Eigen::Vector4d quaternionExp(const Eigen::Vector3d& phi) noexcept {
  const double theta = phi.norm();
  // sin(θ/2)/θ = 1/2 − θ²/48 + θ⁴/3840 − …: for θ < 1e-4 the next term is 1e-26 relative, below rounding.
  const double half_sinc = theta < 1e-4 ? 0.5 - theta * theta / 48.0 : std::sin(0.5 * theta) / theta;
  Eigen::Vector4d q;
  q << std::cos(0.5 * theta), half_sinc * phi;
  return q;
}

Eigen::Matrix3d rotationExp(const Eigen::Vector3d& phi) noexcept {
  const Eigen::Vector4d q = quaternionExp(phi);
  return Eigen::Quaterniond(q[0], q[1], q[2], q[3]).toRotationMatrix();
}

Eigen::Vector3d orientationError(const Eigen::Matrix3d& R_current, const Eigen::Matrix3d& R_desired) noexcept {
  return rotationLog(R_desired * R_current.transpose());
}

}  // namespace zwang
