/// \file
/// Spatial cross products in linear-first Plücker coordinates (docs/conventions.md):
///   v×  = [ω×  v×; 0  ω×]   acting on motion vectors,
///   v×* = -(v×)ᵀ = [ω×  0; v×  ω×]   acting on force vectors.
#pragma once

#include "zwang/spatial/types.hpp"

namespace zwang::spatial {

/// (v×) m for motion vectors v = [v; ω], m = [u; w]:  [ω×u + v×w; ω×w].
ZWANG_ALWAYS_INLINE Vec6 crossMotion(const Vec6& v, const Vec6& m) {
  const Vec3 w = ang(v);
  return stack(w.cross(lin(m)) + Vec3(lin(v)).cross(ang(m)), w.cross(ang(m)));
}

/// (v×*) f for a motion v = [v; ω] and a force f = [f; n]:  [ω×f; ω×n + v×f].
ZWANG_ALWAYS_INLINE Vec6 crossForce(const Vec6& v, const Vec6& f) {
  const Vec3 w = ang(v);
  return stack(w.cross(lin(f)), w.cross(ang(f)) + Vec3(lin(v)).cross(lin(f)));
}

}  // namespace zwang::spatial
