/// \file
/// All scratch memory of the algorithms, made once per model (and constraint
/// capacity); a solve writes here and allocates nothing. One workspace per
/// thread: the Model is shared, the Workspace is not.
///
/// The members are named after the report's Algorithm 1 (chapter 4.2); index i
/// is a body (model.hpp: one per DOF; 0 = the world, or a fixed base), DOF i−1
/// moves body i (from its parent). A joint of nv DOFs, a floating base's root
/// joint among them, is nv bodies: D_i, u_i, S_i are one DOF's.
#pragma once

#include <Eigen/Cholesky>
#include <memory>
#include <vector>

#include "zwang/friction_result.hpp"
#include "zwang/task.hpp"

namespace zwang {

namespace internal {
struct FrictionScratch;
}

/// How the balance of line 25 went (docs/solver.md, "Singular tasks"). The
/// eigenvalues meant here are those of the equilibrated 𝓛̃ (see BalanceOptions).
/// `rows` and `rank` are the task's: the internal rows of mimic joints
/// (Task::mimicRows) are not counted; `condition`, `damping` and `singular`
/// are those of the whole balance, mimic rows included.
struct BalanceReport {
  int rows = 0;  ///< the task's constraint rows (Task::constraintRows)
  /// The rank of the task's rows on the robot as its mimic joints couple it:
  /// `rows` minus the directions of exact rank loss (σ̃ ≤ rank_tolerance).
  int rank = 0;
  /// ν is the only one that gives this motion: rank = rows. False when the
  /// rows are dependent, so other constraint forces give the same motion (a
  /// row repeated, the weight split between two feet on the ground: a
  /// statically indeterminate task), and the least-norm ν is returned. With
  /// `consistent` every row is met all the same, which is no failure; without
  /// it the lost rank left rows unmet (least squares).
  bool nu_unique = true;
  /// Frobenius condition number ‖𝓛̃‖_F ‖𝓛̃⁻¹‖_F of the equilibrated matrix
  /// (infinite when 𝓛 is singular): at least σ̃_max/σ̃_min and at most m times
  /// it, m the balance's rows.
  double condition = 1.0;
  /// How far the most damped near-singular direction is from being solved
  /// exactly, in [0, 1): 1 − (σ̃ − rank_tolerance)/(singular_threshold −
  /// rank_tolerance); 0 when every direction was solved exactly or dropped as
  /// exact rank loss.
  double damping = 0.0;
  bool singular = false;  ///< some σ̃ below singular_threshold: a direction was dropped or damped
  /// ‖Aᵀ Ẍ − b‖₂ over the task's rows and the mimic joints' couplings, in the
  /// rows' own units (m/s², rad/s²), measured on the final accelerations.
  double residual = 0.0;
  /// Every row met to within residual_tolerance of its terms' size. False for
  /// an inconsistent task (met in the least-squares sense only: `nu_unique`
  /// false too) and for a damped direction that had to give.
  bool consistent = true;
};

/// The factorisation of the last balance, kept so that further right-hand sides
/// (the friction extension's unit torques) reuse it (src/dynamics/balance.cpp).
struct BalanceFactorisation {
  bool by_eigen = false;          ///< false: 𝓛 = C Cᵀ (certified regular); true: eigenpairs of 𝓛̃
  Eigen::MatrixXd factor;         ///< C (lower), or the eigenvectors V of 𝓛̃ (by_eigen)
  Eigen::VectorXd eigenvalues;    ///< σ̃_k (by_eigen)
  Eigen::VectorXd gain;           ///< what each eigen-direction is multiplied by: 1/σ̃, damped, or 0
  Eigen::VectorXd equilibration;  ///< E_ii = 1/√𝓛_ii (1 on a row nothing moves)
  /// Orthonormal basis of the directions E v_k with σ̃_k below singular_threshold
  /// (the first `near_null_count` columns), and the weight of each in the
  /// Euclidean projection: 1 at exact rank loss, falling to 0 at the threshold.
  Eigen::MatrixXd near_null_basis;
  Eigen::VectorXd near_null_weight;  ///< the weight of each of those directions (see near_null_basis)
  int near_null_count = 0;           ///< columns of near_null_basis in use
  Eigen::VectorXd work;              ///< scratch of balanceApply (V's coordinates)
};

/// What a solve computes (Workspace::solution).
struct Solution {
  /// q̈ (nv entries: a floating base's first, as the derivative of its velocity
  /// coordinates, docs/conventions.md "Floating base"; then one per joint).
  Eigen::VectorXd qdd;
  /// A floating base's classical acceleration [p̈; ω̇] of its origin, world
  /// axes (zero for a fixed base).
  Vec6 base_acceleration_world = Vec6::Zero();
  /// ν, constraint magnitudes, in the task's row order. Sized to the task's
  /// rows; a solve resizes it only when the task's row count changed since the
  /// last solve (the one allocation a solve can make; none for a fixed task).
  Eigen::VectorXd nu;
  /// τ_c = Σ J_iᵀ A_i ν_i, the generalized forces of the constraint forces
  /// (nv: a floating base's first, in its own coordinates).
  Eigen::VectorXd tau_constraint;
  /// τ + τ_c, what is sent to the motors. A floating base's entries are the
  /// generalized force its coordinates would need: no motor gives it, so a
  /// task a robot can do with its joints alone leaves them at τ_base
  /// (normally 0); constraints whose force the ground supplies (contacts)
  /// make up the rest.
  Eigen::VectorXd tau_control;
  double gauss = 0.0;     ///< Z(q̈), the Gauss function (acceleration energy) at the solution
  BalanceReport balance;  ///< how the balance went: rank, condition, damping, residual, consistent
  /// A warning, not an error: joints whose q lies outside [lower, upper]
  /// (solved as given; the limits act only on stuck joints at a stop, in
  /// solveWithFriction). The count, and the first such joint (−1: none).
  int joints_outside_limits = 0;
  int first_joint_outside_limits = -1;  ///< the first joint outside its limits, −1 when none
  // The true classical acceleration of any frame (a body's own frame:
  // model.bodyFrame(b)) is computed on demand from the sweep by
  // frameAcceleration() (kinematics.hpp), so a solve does not pay for it.
};

/// How far the kinematic results in a workspace go (Workspace::kinematics):
/// each stage includes the ones before it.
enum class KinematicsStage {
  None,           ///< nothing: a fresh workspace, or the last call failed before computing any
  Poses,          ///< poses (Xworld, S): framePose
  Velocities,     ///< and velocities (v, c): frameVelocity
  Accelerations,  ///< and accelerations (a): frameAcceleration
};

/// What the kinematic members of a workspace hold: the results of the last
/// call that computes kinematics, as far as it got, for the model and the
/// state it was given. After each call:
///   forwardKinematics(q)                     Poses
///   forwardKinematics(q, qd)                 Velocities
///   frameJacobian, jointSpaceInertia         Poses (their q; velocities are not computed;
///                                            frameJacobian keeps what the workspace held at q)
///   inverseDynamics                          Accelerations (of its q̈)
///   solveHybridDynamics, forwardDynamics,    Accelerations (of the solution; also when
///   solveWithFriction                        solveWithFriction returns Infeasible)
/// A call that returns an error holds what it completed: None when it failed
/// its input checks, Velocities when a solve stopped at Degenerate. The
/// queries of kinematics.hpp take the state they mean and return
/// StatusCode::NotComputed for anything beyond the stage held, for another
/// state, or for a model other than `model`.
struct KinematicsHeld {
  KinematicsStage stage = KinematicsStage::None;  ///< how far the results go
  const Model* model = nullptr;                   ///< the model they were computed for (compared by address)
  /// The q they were computed at (nq entries, sized by the Workspace
  /// constructor: read it, do not resize it).
  Eigen::VectorXd q;
  /// The q̇ (nv entries; meaningful from Velocities on).
  Eigen::VectorXd qd;
};

/// All scratch memory of the algorithms, and the results of the last call: see the file comment.
class Workspace {
 public:
  /// Room for tasks with up to `max_constraint_rows` rows in all.
  explicit Workspace(const Model& model, int max_constraint_rows = 6);
  /// Sized exactly for this task (solution.nu has its row count from the start).
  Workspace(const Model& model, const Task& task);
  /// Frees the scratch memory.
  ~Workspace();
  /// Movable, not copyable (one workspace per thread).
  Workspace(Workspace&&) noexcept;
  /// Move assignment.
  Workspace& operator=(Workspace&&) noexcept;

  /// Model::dof() of the model the workspace was made for.
  int dof() const { return dof_; }
  /// The most constraint rows a task solved here may have.
  int constraintCapacity() const { return capacity_; }
  /// The most balance rows: the constraint rows and one per mimic joint.
  int balanceCapacity() const { return capacity_ + mimic_rows_; }
  /// The most solver columns: two per row, since a relative row has one on
  /// each side, and four per mimic row (each joint's body and its parent).
  int columnCapacity() const { return 2 * capacity_ + 4 * mimic_rows_; }

  /// The results of the last solve. Read or overwrite the values; keep the
  /// sizes (a solve refuses a result vector of another size: SizeMismatch).
  Solution solution;
  FrictionResult friction;  ///< filled by solveWithFriction (the same rule for its sizes)
  /// What the kinematic members below (Xworld, S, v, c, a) hold (KinematicsHeld);
  /// set by the calls that compute them, read by the queries of kinematics.hpp.
  KinematicsHeld kinematics;

  // Everything below is the algorithms' memory, sized once by the constructor:
  // read it, but do not resize it (a solve does not check these sizes).

  // Every spatial quantity below is in BASE coordinates: world axes, referred
  // to the world origin (docs/solver.md, "Coordinates"). Algorithm 1's
  // transforms ⁱX_{i−1} between bodies are then identities.

  // --- outward sweep: poses, velocities, bias terms (Algorithm 1, lines 2–10)
  std::vector<Transform> Xworld;  ///< ⁱX₀, world → body i
  std::vector<Vec6> S;            ///< S_i, motion subspace
  std::vector<RigidInertia> I;    ///< I_i, body inertia
  std::vector<Vec6> v;            ///< Ẋ_i
  std::vector<Vec6> c;            ///< Ẍ_bias,i = Ẋ_i × S_i q̇_i
  std::vector<Vec6> Fbias;        ///< F_bias,i = Ẋ_i ×* I_i Ẋ_i − F_ext,i

  // --- inward sweep: articulated quantities (lines 11–22)
  std::vector<Mat6> IA;           ///< I^A_i
  std::vector<Vec6> FA;           ///< F^A_bias,i
  std::vector<Vec6> IAS;          ///< I^A_i S_i
  std::vector<double> D;          ///< D_i = d_i + S_iᵀ I^A_i S_i (a joint's D: these pivots are its LDLᵀ factor)
  std::vector<double> inverse_D;  ///< 1 / D_i (the sweeps multiply)
  std::vector<double> u;          ///< τ_i − S_iᵀ(F^A_bias,i + I^A_i Ẍ_bias,i)
  Eigen::MatrixXd SA;             ///< column i: (S_iᵀ A_i)ᵀ, capacity × bodies
  ConstraintMatrix Ahat;          ///< A_i (6 × capacity), updated in place from A_N down to A_0
  /// U_0, acceleration energy of bias forces and torques: the report's U (not
  /// Featherstone's or Pinocchio's U = I^A S, which is IAS here).
  Eigen::VectorXd U;
  Eigen::VectorXd L_scale;  ///< Σ_i |S_i|²|A_i col|²/D_i: the size 𝓛's diagonal rounding is relative to
  Eigen::MatrixXd L;        ///< 𝓛_0, the balance matrix of line 25 (solver columns², lower triangle)

  // --- the task in sweep form, solver column order (see Task::groups)
  ConstraintMatrix A_body;  ///< columns of each constraint, as unit forces on its body
  Eigen::VectorXd b_body;   ///< set points as the sweep's (gravity-shifted, spatial) accelerations

  // --- balance (line 25), src/dynamics/balance.cpp
  BalanceFactorisation balance_factorisation;  ///< the last balance's factorisation
  Eigen::VectorXd rhs;                         ///< b − A_0ᵀẌ_0 − U_0, per balance row
  Eigen::VectorXd nu;                          ///< ν per solver column (what the sweeps read)
  Eigen::VectorXd nu_motors;                   ///< ν per solver column with the contacts' set to 0 (τ_c)
  /// With relative constraints the balance works on rows, each the sum of its
  /// solver columns: 𝓛, its rounding scale, ν and the unit-torque columns per row.
  Eigen::MatrixXd L_rows;
  Eigen::VectorXd L_scale_rows;  ///< L_scale per balance row (relative constraints)
  Eigen::VectorXd nu_rows;       ///< ν per balance row (relative constraints)
  Eigen::MatrixXd dU_rows;       ///< −δU₀ per balance row and unit torque (relative constraints)
  Eigen::MatrixXd dnu_rows;      ///< δν per balance row and unit torque (relative constraints)
  Eigen::VectorXd row_error;     ///< Aᵀ Ẍ − b per balance row (taskResidual)
  Eigen::VectorXd row_size;      ///< the size of the terms of each row's error (taskResidual)

  // --- final outward sweep (lines 26–30) and the constraint-torque pass
  std::vector<Vec6> a;  ///< Ẍ_i of the sweep: true acceleration + [−g; 0] (a[0] = [−g; 0] on a fixed base)
  Vec6 a_world = Vec6::Zero();  ///< the world's acceleration in the sweep, [−g; 0]: what ws.a is shifted by
  std::vector<Vec6> f;          ///< accumulated forces (RNEA)
  /// The constraint wrenches A ν on each body and its subtree (constraint torques)
  std::vector<Vec6> constraint_wrench;

  // --- other algorithms
  std::vector<Mat6> Ic;  ///< composite inertias (CRBA)
  Eigen::MatrixXd H;     ///< joint-space inertia (CRBA)
  Eigen::VectorXd tau;   ///< inverse dynamics result (RNEA)

  /// Scratch of the friction extension (src/friction/friction.cpp).
  internal::FrictionScratch& frictionScratch() { return *friction_scratch_; }

  /// The task forwardDynamics and inverseDynamics use when given none: Task's
  /// default gravity, no constraints, no wrenches.
  const Task& defaultTask() const { return *default_task_; }

 private:
  int dof_;
  int capacity_;
  int mimic_rows_;
  std::unique_ptr<internal::FrictionScratch> friction_scratch_;
  std::unique_ptr<Task> default_task_;
};

}  // namespace zwang
