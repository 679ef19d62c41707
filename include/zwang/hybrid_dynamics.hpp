/// \file
/// The Popov–Vereshchagin constrained hybrid dynamics solver (docs/solver.md; the
/// report's Algorithm 1, extended to constraints on any number of frames).
///
/// Minimises the Gauss function Z(q̈) subject to Aᵀ Ẍ = b on the task's frames
/// and returns q̈, the constraint magnitudes ν, the physical constraint torques
/// τ_c = Σ J_iᵀ A_i ν_i and the control torques τ + τ_c in ws.solution.
/// O(N) for a fixed number of constraint rows m (O(N·m²) in m).
///
/// Never throws and never allocates: a bad input returns a Status naming it.
#pragma once

#include "zwang/status.hpp"
#include "zwang/workspace.hpp"

namespace zwang {

/// The constrained hybrid dynamics of the file comment: q̈, ν, τ_c, τ_control and Z into ws.solution.
Status solveHybridDynamics(const Model& model, const Task& task, const Eigen::Ref<const Eigen::VectorXd>& q,
                           const Eigen::Ref<const Eigen::VectorXd>& qd, const Eigen::Ref<const Eigen::VectorXd>& tau,
                           Workspace& ws) noexcept;

}  // namespace zwang
