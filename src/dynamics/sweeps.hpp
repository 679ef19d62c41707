// Pieces shared by several algorithms (not installed).
//
// Every algorithm works in BASE coordinates: spatial vectors and inertias of
// all bodies are expressed in the world axes and referred to the world origin
// (Featherstone, RBDA §4; Pinocchio's "world" convention). The body-to-body
// transforms ⁱX_{i−1} of the recursions are then identities: inertias and
// forces are summed, not transformed, on the way in. Only each body's pose
// ⁱX₀, its motion subspace S_i and its inertia I_i are mapped to the base once
// per sweep.
#pragma once

#include "zwang/workspace.hpp"

#include "dynamics/workspace_scratch.hpp"

// On a per-body step: every call inside it inlined. The compiler's size
// limits otherwise leave Eigen's small fixed-size kernels (a 6-vector sum, a
// 3-vector cross product) as calls in the loops.
#if defined(__GNUC__) || defined(__clang__)
#define ZWANG_FLATTEN __attribute__((flatten))
#else
#define ZWANG_FLATTEN
#endif

namespace zwang::internal {

// Outward sweep (Algorithm 1, lines 3–7, in base coordinates): poses ⁱX₀,
// motion subspaces S_i, velocities Ẋ_i = Ẋ_{i−1} + S_i q̇_i, velocity-product
// accelerations Ẍ_bias,i = Ẋ_i × S_i q̇_i, and, when `with_inertia`, the body
// inertias I_i and bias forces F_bias,i = Ẋ_i ×* I_i Ẋ_i (line 7 without
// F_ext). q̇ may be zero-length to skip velocities (Ẋ, Ẍ_bias, F_bias zero).
void outwardKinematics(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q,
                       const Eigen::Ref<const Eigen::VectorXd>& qd, Workspace& ws, bool with_inertia);

// ᶠX₀ of a frame, after outwardKinematics.
inline Transform framePlacementInBase(const Model& model, const Workspace& ws, int frame) {
  const WorkspaceScratch& sw = scratchOf(ws);
  const Frame& f = model.frame(frame);
  return f.placement * sw.Xworld[static_cast<std::size_t>(f.body)];
}

// A spatial force given at a frame's origin (local or world axes), in base
// coordinates: [f; n + p × f] with p the frame origin, all in world axes.
inline Vec6 wrenchInBase(const Model& model, const Workspace& ws, int frame, Expressed expressed, const Vec6& w) {
  const Transform X = framePlacementInBase(model, ws, frame);
  if (expressed == Expressed::Local) return X.inverseApplyForce(w);
  Vec6 out = w;
  out.tail<3>() += X.r.cross(w.head<3>());
  return out;
}

// Subtract the task's external wrenches from Fbias (line 7: F_bias −= F_ext).
void applyExternalWrenches(const Model& model, const Task& task, Workspace& ws);

// Gravity as the base acceleration Ẍ₀ = [−g; 0] (docs/conventions.md, "Gravity"). In base coordinates it
// is the same 6-vector for every body.
inline Vec6 gravityAcceleration(const Vec3& gravity) {
  Vec6 out;
  out << -gravity, Vec3::Zero();
  return out;
}

// Classical acceleration [linear of point p; angular], world axes, from a
// true spatial acceleration `a` and velocity `v` in base coordinates:
// a_p = a_lin + α × p + ω × (v_lin + ω × p).
inline Vec6 classicalAtPoint(const Vec6& a, const Vec6& v, const Vec3& p) {
  const Vec3 w = v.tail<3>();
  const Vec3 vp = v.head<3>() + w.cross(p);
  Vec6 out;
  out << a.head<3>() + a.tail<3>().cross(p) + w.cross(vp), a.tail<3>();
  return out;
}

}  // namespace zwang::internal
