/// \file
/// Fixed-size Eigen types and the 3-D helpers the spatial algebra is built on.
/// Spatial vectors are 6-vectors in Plücker coordinates, LINEAR PART FIRST:
/// motion [v; ω], force [f; n] (docs/conventions.md, "Spatial vectors: linear part first").
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products

/// Inline even where the compiler's size heuristics would not: the small
/// spatial operations of the sweeps (a call costs more than their body).
#if defined(__GNUC__) || defined(__clang__)
#define ZWANG_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define ZWANG_ALWAYS_INLINE inline
#endif

namespace zwang {

using Vec3 = Eigen::Vector3d;              ///< 3-vector: a position, or the linear or angular part of a spatial vector.
using Mat3 = Eigen::Matrix3d;              ///< 3×3 matrix: a rotation or a rotational inertia.
using Vec6 = Eigen::Matrix<double, 6, 1>;  ///< Spatial vector, linear part first: motion [v; ω] or force [f; n].
using Mat6 = Eigen::Matrix<double, 6, 6>;  ///< 6×6 spatial matrix: an inertia or a transform.
/// 6 × k, k ≤ 6, without heap memory: the motion subspace of a multi-DOF joint.
using Matrix6Xmax = Eigen::Matrix<double, 6, Eigen::Dynamic, 0, 6, 6>;
/// k × k, k ≤ 6, without heap memory: a multi-DOF joint's D.
using MatrixXmax6 = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, 6, 6>;
/// k-vector, k ≤ 6, without heap memory: a multi-DOF joint's u or q̈.
using VectorXmax6 = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 6, 1>;

/// Spatial (Plücker) algebra, linear part first; it does not depend on the model.
namespace spatial {

/// The linear (first three) and angular (last three) parts of a spatial vector.
template <class V>
ZWANG_ALWAYS_INLINE auto lin(V&& x) {
  return x.template head<3>();
}
/// The angular part (last three) of a spatial vector.
template <class V>
ZWANG_ALWAYS_INLINE auto ang(V&& x) {
  return x.template tail<3>();
}

/// The spatial vector [linear; angular].
ZWANG_ALWAYS_INLINE Vec6 stack(const Vec3& linear, const Vec3& angular) {
  Vec6 out;
  out.head<3>() = linear;
  out.tail<3>() = angular;
  return out;
}

/// skew(a) b = a × b
inline Mat3 skew(const Vec3& a) {
  Mat3 s;
  s << 0.0, -a.z(), a.y(),  //
      a.z(), 0.0, -a.x(),   //
      -a.y(), a.x(), 0.0;
  return s;
}

}  // namespace spatial
}  // namespace zwang
