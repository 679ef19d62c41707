/// \file
/// Classic rigid-body algorithms over the same Model/Workspace:
/// RNEA inverse dynamics and CRBA joint-space inertia.
///
/// Fixed and floating bases alike (docs/conventions.md, "Floating base"): q has
/// Model::nq() entries, q̇, q̈, τ and H's sides Model::nv(), the base's
/// coordinates first. Both are noexcept and allocate nothing; bad input comes
/// back as a Status (docs/errors.md) naming what was expected (nq, nv).
#pragma once

#include "zwang/status.hpp"
#include "zwang/workspace.hpp"

namespace zwang {

/// Recursive Newton–Euler: ws.tau = H(q) q̈ + C(q, q̇) − Σ Jᵀ F_ext (nv), with
/// the task's gravity and wrenches (its constraints are ignored); rotor
/// inertias included (d_j q̈_j). A floating base's entries come first: the
/// generalized force its coordinates would need for this motion, in its own
/// coordinates (a free base's is the wrench [f; n] in base axes at the base
/// origin, conjugate to v_B = [v; ω]; a planar base's [f_x, f_y, n_ψ] in the
/// plane's axes). The base's q̈ is the derivative of its velocity
/// coordinates, as solveHybridDynamics returns it. Afterwards
/// frameAcceleration reads the accelerations of this motion.
Status inverseDynamics(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                       const Eigen::Ref<const Eigen::VectorXd>& qd, const Eigen::Ref<const Eigen::VectorXd>& qdd,
                       const Task& task) noexcept;
/// The same with Task's default gravity and no wrenches (Workspace::defaultTask).
Status inverseDynamics(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                       const Eigen::Ref<const Eigen::VectorXd>& qd,
                       const Eigen::Ref<const Eigen::VectorXd>& qdd) noexcept;

/// Composite-rigid-body algorithm: ws.H = H(q) (nv × nv), including rotor
/// inertias. A floating base's rows and columns come first, in its velocity
/// coordinates (a free base's block is the whole robot's composite inertia in
/// base axes at the base origin); entries between joints on different
/// branches are exactly zero.
Status jointSpaceInertia(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q) noexcept;

}  // namespace zwang
