/// \file
/// What a friction-aware solve reports per joint (see friction.hpp).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace zwang {

/// How μ* is found (docs/friction.md, "The maximiser" and "The pattern search").
enum class FrictionMethod {
  /// The pattern search where it is predicted cheaper (many stuck DOFs, or a kept pattern with warm_start), the
  /// active set where it fails or is not tried; the same answer either way.
  Automatic,
  ActiveSet,          ///< K_ΘΘ formed, the box QP by an exact active-set method
  ProjectedGradient,  ///< K_ΘΘ formed, the box QP by projected gradient
  /// One pass of the sweeps per stick/slip pattern, no K formed, pivoting until a pattern holds (then the full
  /// active set when μ* may not be unique or none holds within max_iterations passes).
  StickPatterns,
};
/// "automatic", "active_set", "projected_gradient" or "stick_patterns".
const char* toString(FrictionMethod method);

/// The state of each joint after a friction-aware solve (docs/friction.md).
enum class JointState {
  Moving,        ///< |q̇| above the velocity tolerance: kinetic friction
  Stick,         ///< stuck and stays: q̈ = 0, |μ| ≤ f
  SlipPositive,  ///< stuck, breaks away positively: q̈ > 0, μ = +f
  SlipNegative,  ///< stuck, breaks away negatively: q̈ < 0, μ = −f
  AtLimit,       ///< stuck on a position limit that pushes back beyond friction
  Prescribed,    ///< its q̈ is the task's (Task::prescribe): no friction unknown; kinetic friction when moving
};
/// The name used in JSON and tables: "moving", "stick", "slip+", "slip-", "at-limit" or "prescribed".
const char* toString(JointState state);

/// What solveWithFriction reports besides the motion (Workspace::friction).
struct FrictionResult {
  /// μ*, per DOF below the root (Model::dof() entries, a multi-DOF joint's
  /// one per DOF: a box each; 0 for moving DOFs).
  Eigen::VectorXd mu;
  std::vector<JointState> state;  ///< per DOF, as mu
  Eigen::VectorXd tau_friction;  ///< per DOF, as mu: what friction and limits put on it (−μ, or −f_c sign q̇ − b q̇)
  /// nv × dof(): column j = ∂q̈/∂μ_j = −K e_j for a stuck DOF j, 0 otherwise
  /// (rows: every entry of q̈, a floating base's first). Computed by the
  /// K-based methods only: zero when the pattern search answered (method).
  Eigen::MatrixXd dqdd_dmu;
  std::vector<int> stuck;      ///< Θ₀: the stuck DOFs (indices into mu), ascending
  double gauss_dual = 0.0;     ///< g(μ*) = Z(q̈*) + μ*ᵀ W q̈*
  int iterations = 0;          ///< of the maximiser, or the pattern search's passes of the sweeps
  bool converged = true;       ///< the maximiser met its KKT tolerance within max_iterations
  double kkt_residual = 0.0;   ///< max violation of the optimality conditions [rad/s² or m/s²]
  bool indeterminate = false;  ///< μ* is not unique; the effort-minimising one was chosen
  /// Which method answered: StickPatterns (dqdd_dmu zero: not computed), ActiveSet or ProjectedGradient.
  FrictionMethod method = FrictionMethod::ActiveSet;
  /// The pattern search answered, started from the last solve's pattern (FrictionOptions::warm_start).
  bool warm_started = false;
  bool limit_impact = false;  ///< a joint on a limit moves into it (needs an impulse; not modelled)
  int impact_joint = -1;      ///< the joint of limit_impact, −1 when there is none
};

}  // namespace zwang
