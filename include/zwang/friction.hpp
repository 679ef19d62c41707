/// \file
/// Static friction (docs/friction.md; the report's chapter 5): the exact
/// maximum-dissipation motion for any number of stuck joints.
///
/// The DOFs below the root with |q̇_j| ≤ velocity_tolerance form the stuck set
/// Θ₀ (k of them; a mimic joint is not in it: its leader carries its friction).
/// Moving joints carry kinetic friction −f_c,j sign(q̇_j) − b_j q̇_j as a
/// feed-forward torque. A stuck joint j feels the reaction −μ_j, with
///   μ* = argmax_{μ ∈ Λ} g(μ),  g(μ) = min_q̈ Z(q̈) + μᵀ W q̈,  Λ = Π_j [−f_j, f_j]
/// (eq. 5.2, 5.5, 5.8, 5.9). One pass of the sweeps carries k extra right-hand
/// sides (unit torques at the stuck joints), giving q̈(0) and K_Θ = ∂q̈/∂τ_Θ, so
/// q̈(μ) = q̈(0) − K_Θ μ (the characteristic equation 5.10); g is the concave
/// quadratic g(0) + μᵀ q̈_Θ(0) − ½ μᵀ K_ΘΘ μ, maximised over the box by an exact
/// active-set method (or projected gradient). With many stuck joints, or from
/// the last solve's pattern, a search over stick/slip patterns finds the same
/// μ* at one pass of the sweeps per pattern, no K formed (FrictionMethod).
///
/// A stuck joint resting on a position limit gets a one-sided reaction: at the
/// lower limit μ_j ∈ (−∞, f_j], at the upper μ_j ∈ [−f_j, ∞) (docs/friction.md, "Joint position limits").
///
/// Sign (docs/conventions.md, "Signs of the outputs"): μ_j > 0 opposes positive motion; the joint feels τ_j − μ_j.
#pragma once

#include <vector>

#include "zwang/status.hpp"
#include "zwang/workspace.hpp"

namespace zwang {

/// Options of solveWithFriction; the defaults suit most uses.
struct FrictionOptions {
  double velocity_tolerance = 1e-6;  ///< |q̇| at or below it: stuck [rad/s or m/s]
  double limit_tolerance = 1e-9;     ///< |q − limit| at or below it: on the limit [rad or m]
  bool joint_limits = true;          ///< treat position limits as one-sided reactions
  /// When μ* is not unique, the maximiser that minimises ‖τ_control‖² using at
  /// most margin·f_j of each breakaway torque (where the task allows).
  double margin = 1.0;
  /// The pattern search where it is cheaper, else the active set (exact either way).
  FrictionMethod method = FrictionMethod::Automatic;
  /// Start the pattern search from the stick/slip pattern of the last
  /// solveWithFriction in this workspace (a control loop or a simulation,
  /// whose next state is close to the last), for the same model and task
  /// object, mapped onto this solve's stuck set (a newly stuck DOF starts
  /// sticking): one pass of the sweeps when it still holds (docs/friction.md,
  /// "Warm start"). Also with ActiveSet or ProjectedGradient, which then run
  /// when the search fails. The answer is the same either way;
  /// FrictionResult::warm_started and method tell which path answered.
  bool warm_start = false;
  int max_iterations = 500;      ///< of the maximiser, or passes of the pattern search
  double kkt_tolerance = 1e-12;  ///< relative to 1 + the largest |q̈(0)| on Θ₀
  ///@{
  /// Per-solve overrides of the model's values (empty: use the model's).
  Eigen::VectorXd breakaway, kinetic, viscous;
  ///@}
};

/// Friction-aware hybrid dynamics. Fills ws.solution (q̈*, ν, τ_c, τ_control =
/// τ + τ_c, Z with the friction torques) and ws.friction. Never throws, never
/// allocates. Returns StatusCode::Infeasible (with finite outputs) when the task
/// drives a joint into a limit (the maximisation is unbounded).
Status solveWithFriction(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                         const Eigen::Ref<const Eigen::VectorXd>& qd, const Eigen::Ref<const Eigen::VectorXd>& tau,
                         const Task& task, const FrictionOptions& options = {}) noexcept;

}  // namespace zwang
