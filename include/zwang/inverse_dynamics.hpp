/// \file
/// Classic rigid-body algorithms over the same Model/Workspace:
/// RNEA inverse dynamics and CRBA joint-space inertia.
#pragma once

#include "zwang/status.hpp"
#include "zwang/workspace.hpp"

namespace zwang {

/// Recursive Newton–Euler: ws.tau = H(q) q̈ + C(q, q̇) − Σ Jᵀ F_ext, with the
/// task's gravity and wrenches (its constraints are ignored); rotor inertias
/// included (d_j q̈_j).
Status inverseDynamics(const Model& model, const Task& task, const Eigen::Ref<const Eigen::VectorXd>& q,
                       const Eigen::Ref<const Eigen::VectorXd>& qd, const Eigen::Ref<const Eigen::VectorXd>& qdd,
                       Workspace& ws) noexcept;

/// Composite-rigid-body algorithm: ws.H = H(q), including rotor inertias.
Status jointSpaceInertia(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q, Workspace& ws) noexcept;

}  // namespace zwang
