// Fixed-size Eigen types and the 3-D helpers the spatial algebra is built on.
// Spatial vectors are 6-vectors in Plücker coordinates, LINEAR PART FIRST:
// motion [v; ω], force [f; n] (docs/conventions.md, "Spatial vectors: linear part first").
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>  // cross products

namespace zwang {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

namespace spatial {

// The linear (first three) and angular (last three) parts of a spatial vector.
template <class V> inline auto lin(V&& x) { return x.template head<3>(); }
template <class V> inline auto ang(V&& x) { return x.template tail<3>(); }

inline Vec6 stack(const Vec3& linear, const Vec3& angular) {
  Vec6 out;
  out << linear, angular;
  return out;
}

// skew(a) b = a × b
inline Mat3 skew(const Vec3& a) {
  Mat3 s;
  s << 0.0, -a.z(), a.y(),  //
      a.z(), 0.0, -a.x(),   //
      -a.y(), a.x(), 0.0;
  return s;
}

}  // namespace spatial
}  // namespace zwang
