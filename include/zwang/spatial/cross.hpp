/// \file
/// Spatial cross products in linear-first Plücker coordinates (docs/conventions.md):
///   v×  = [ω×  v×; 0  ω×]   acting on motion vectors,
///   v×* = -(v×)ᵀ = [ω×  0; v×  ω×]   acting on force vectors.
#pragma once

#include "zwang/spatial/types.hpp"

namespace zwang::spatial {

/// (v×) m for motion vectors v = [v; ω], m = [u; w]:  [ω×u + v×w; ω×w].
inline Vec6 crossMotion(const Vec6& v, const Vec6& m) {
  const Vec3 w = ang(v);
  return stack(w.cross(lin(m)) + Vec3(lin(v)).cross(ang(m)), w.cross(ang(m)));
}

/// (v×*) f for a motion v = [v; ω] and a force f = [f; n]:  [ω×f; ω×n + v×f].
inline Vec6 crossForce(const Vec6& v, const Vec6& f) {
  const Vec3 w = ang(v);
  return stack(w.cross(lin(f)), w.cross(ang(f)) + Vec3(lin(v)).cross(lin(f)));
}

/// The 6×6 matrices, for tests and for code that needs the operator itself.
inline Mat6 crossMotionMatrix(const Vec6& v) {
  Mat6 x = Mat6::Zero();
  x.topLeftCorner<3, 3>() = skew(ang(v));
  x.topRightCorner<3, 3>() = skew(lin(v));
  x.bottomRightCorner<3, 3>() = skew(ang(v));
  return x;
}

/// The 6×6 matrix of v×* = −(v×)ᵀ.
inline Mat6 crossForceMatrix(const Vec6& v) { return -crossMotionMatrix(v).transpose(); }

}  // namespace zwang::spatial
