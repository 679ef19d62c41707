// A floating base: the joint of body 0 to the world, with k = 6 (free) or 3
// (planar) unactuated coordinates, as one more step of each sweep of
// Algorithm 1 (src/dynamics/floating_base.cpp). Not installed.
#pragma once

#include "zwang/configuration.hpp"
#include "zwang/status.hpp"
#include "zwang/workspace.hpp"

#include "dynamics/checks.hpp"

namespace zwang::internal {

using VectorRef = Eigen::Ref<const Eigen::VectorXd>;
using Matrix6X = Eigen::Matrix<double, 6, Eigen::Dynamic>;

// Lines 3–6 for the base joint: the base's pose ⁰X₀ (into ws.Xworld[0]), its
// motion subspace S₀ (ws.S_base), velocity Ẋ₀ (ws.v[0]), bias acceleration
// (ws.c[0]) and, when `with_inertia`, its inertia ws.I[0]. `q_base` has
// baseConfigurationSize() entries, `v_base` baseVelocitySize() (or none: at rest).
void baseKinematics(const Model& model, const VectorRef& q_base, const VectorRef& v_base, Workspace& ws,
                    bool with_inertia);

// Lines 13–21 for the base joint, after the joints' inward sweep has summed
// the children's I^a and F^a into body 0: D₀, u₀ (with the generalized force
// `tau_base` on the base coordinates), S₀ᵀA₀, and their terms of U₀ and 𝓛₀;
// the columns projected past the base (zero for a free base). Degenerate when
// D₀ is not positive definite.
Status baseInward(const Model& model, const Task& task, const VectorRef& tau_base, Workspace& ws);

// x ← D₀⁻¹ x (k entries) with the factorisation baseInward made.
void baseSolveInPlace(const Model& model, const Workspace& ws, VectorXmax6& x);
// The same for W right-hand sides side by side: `lanes` is row-major k × W
// (row j: base coordinate j of each). W = 1, 2, 4 or 8 (unitTorqueColumns'
// blocks of columns).
template <int W>
void baseSolveLanesInPlace(const Model& model, const Workspace& ws, double* lanes);

// unitTorqueColumns' base step inward: δu₀ = −S₀ᵀ δF for the wrenches δF
// (6 × n) carried into body 0 (no torque at the base), into the first k rows
// of du_base. A free base's S₀ = 1 is taken literally.
inline void baseUnitTorques(const Model& model, const Workspace& ws, const Eigen::Ref<const Matrix6X>& dF,
                            Eigen::Ref<Eigen::MatrixXd> du_base) {
  const int kb = model.baseVelocitySize();
  if (model.baseType() == BaseType::Free) {
    du_base.topRows<6>() = -dF;  // S₀ = 1
  } else {                       // in two steps: the negated product would be a heap temporary
    du_base.topRows(kb).noalias() = ws.S_base.transpose() * dF;
    du_base.topRows(kb) *= -1.0;
  }
}

// ... and outward, after baseSolveLanesInPlace: from W columns' q̈₀ (`lanes`,
// row-major k × W, the sweep's coordinates), δẌ₀ = S₀ q̈₀ into `da0` (W × 6,
// a column per component) and the base's q̈ in the user's coordinates into
// qdd_base (k × W; linear, as publishBaseAcceleration). Inline: it runs once
// per block of columns, inside the outward pass.
template <int W>
void baseMotionLanes(const Model& model, const Workspace& ws, const double* lanes, double* da0,
                     Eigen::Ref<Eigen::MatrixXd> qdd_base) {
  const int kb = model.baseVelocitySize();
  if (model.baseType() == BaseType::Free) {
    for (int e = 0; e < 6 * W; ++e) da0[e] = lanes[e];  // S₀ = 1: the same layout
    const Eigen::Map<const Eigen::Matrix<double, 6, W, W == 1 ? Eigen::ColMajor : Eigen::RowMajor>> q(lanes);
    Eigen::Map<Eigen::Matrix<double, 6, W>, 0, Eigen::OuterStride<>> out(qdd_base.data(),
                                                                         Eigen::OuterStride<>(qdd_base.outerStride()));
    out.noalias() = ws.Xworld[0].motionMatrix() * q;  // v̇_B = ᴮX₀ Ẍ₀, in fixed sizes
    return;
  }
  for (int l = 0; l < W; ++l) {
    VectorXmax6 q(kb);
    for (int j = 0; j < kb; ++j) q[j] = lanes[j * W + l];
    const Vec6 a = ws.S_base * q;
    for (int e = 0; e < 6; ++e) da0[e * W + l] = a[e];
    qdd_base.col(l) = q;  // planar: the sweep's coordinates are the user's
  }
}

// Lines 28–29 for the base joint, from ws.nu: q̈₀ (ws.qdd_base) and Ẍ₀ (ws.a[0]).
void baseAcceleration(const Model& model, const Task& task, Workspace& ws);

// The base's q̈ in the user's coordinates (the derivative of its velocity
// coordinates) from a q̈₀ in the sweep's coordinates. Linear (no bias term:
// free bases have none, planar ones use the user's coordinates), so it maps
// differences too.
void publishBaseAcceleration(const Model& model, const Workspace& ws, const VectorXmax6& qdd_sweep,
                             Eigen::Ref<Eigen::VectorXd> qdd_base);

// The base's true spatial acceleration (base coordinates of the sweep, without
// gravity's shift) from its q̈ in the user's coordinates.
Vec6 baseTrueAcceleration(const Model& model, const Workspace& ws, const VectorRef& qdd_base);

// The base's classical acceleration [p̈; ω̇] of its origin, world axes, after
// the final sweep (ws.a[0]).
Vec6 baseClassicalAcceleration(const Task& task, const Workspace& ws);

// The generalized force on the base coordinates of a wrench F₀ (base
// coordinates of the sweep: world axes, world origin) acting on body 0.
void baseGeneralizedForce(const Model& model, const Workspace& ws, const Vec6& F0, Eigen::Ref<Eigen::VectorXd> out);

// The base's motion subspace in the USER's coordinates, after baseKinematics:
// column k is the spatial velocity (base coordinates of the sweep) of a unit
// rate of the k-th entry of v_base. Free: ⁰X_B (the sweep's S₀ = 1 uses other
// coordinates); planar: S₀ itself. Its transpose maps a wrench on body 0 to
// the base's generalized force (baseGeneralizedForce), so RNEA's τ_base, the
// CRBA's base rows and the Jacobians' base columns are one family.
void baseMotionColumns(const Model& model, const Workspace& ws, Matrix6Xmax& S_user);

// The input checks of the algorithms besides the solver (RNEA, CRBA,
// kinematics), for q (nq() entries) and the vectors of nv() entries (q̇, q̈).
// A fixed base's are checked inline, exactly as before floating bases came:
// its hot path pays for no call and no extra Status (each one zeroes its
// 240-byte message). A floating base's q goes to checkConfiguration (the
// quaternion too); its velocity vectors' sizes are worded as the solver's
// other state vectors are ("… the model has nv = 9 (3 base velocity
// coordinates + 6 joints)").
Status checkFloatingVelocityVector(const Model& model, const char* name, const VectorRef& x);
inline Status checkStateConfiguration(const Model& model, const VectorRef& q) {
  return model.hasFloatingBase() ? checkConfiguration(model, q) : checkVector("q", q, model.dof());
}
inline Status checkVelocityVector(const Model& model, const char* name, const VectorRef& x) {
  return model.hasFloatingBase() ? checkFloatingVelocityVector(model, name, x) : checkVector(name, x, model.dof());
}

// A workspace made for a model with the same joints but another base (its H
// and τ are nv × nv and nv) must be refused before anything is written:
// Workspace::dof() alone cannot tell a fixed arm from the same arm floating.
inline bool workspaceFitsBase(const Model& model, const Workspace& ws) {
  return ws.tau.size() == model.nv() && ws.H.rows() == model.nv() && ws.H.cols() == model.nv();
}
// The ModelMismatch status for a workspace that does not fit (names both nv),
// or SizeMismatch for a workspace that fits whose H or τ a user resized.
Status workspaceBaseMismatch(const Model& model, const Workspace& ws);

}  // namespace zwang::internal
