/// \file
/// A workspace: the results of the last call (the solution, the friction
/// result, τ of inverse dynamics, H, the kinematics held) and, hidden behind
/// them, all the scratch memory of the algorithms, made once per model (and
/// constraint capacity); a solve writes there and allocates nothing, except
/// once to make room when a task has more constraint rows than the workspace
/// held so far (Workspace(model, task) or reserve() make it up front). One
/// workspace per thread: the Model is shared, the Workspace is not.
#pragma once

#include <Eigen/Cholesky>
#include <memory>
#include <vector>

#include "zwang/friction_result.hpp"
#include "zwang/status.hpp"
#include "zwang/task.hpp"

namespace zwang {

struct WorkspaceScratch;

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
  /// last solve (an allocation, as is making room for more rows than the
  /// workspace had: none for a fixed task).
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
  // frameAcceleration() (kinematics.hpp), and the wrench the task's
  // constraints exert on a frame from `nu` by constraintWrench(), so a solve
  // does not pay for them.
};

/// How far the kinematic results in a workspace go (Workspace::kinematics):
/// each stage includes the ones before it.
enum class KinematicsStage {
  None,           ///< nothing: a fresh workspace, or the last call failed before computing any
  Poses,          ///< poses (and motion subspaces): framePose
  Velocities,     ///< and velocities (and velocity-product terms): frameVelocity
  Accelerations,  ///< and accelerations: frameAcceleration
};

/// What the kinematic results in a workspace are: those of the last call
/// that computes kinematics, as far as it got, for the model and the state it
/// was given. After each call:
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

/// The results of the last call, and the algorithms' scratch memory behind them: see the file comment.
class Workspace {
 public:
  /// Room for tasks with up to `max_constraint_rows` rows in all; a solve of a
  /// task with more makes room itself (reserve), allocating that once.
  explicit Workspace(const Model& model, int max_constraint_rows = 6);
  /// Sized exactly for this task (solution.nu has its row count from the start).
  Workspace(const Model& model, const Task& task);
  /// Frees the scratch memory.
  ~Workspace();
  /// Movable, not copyable (one workspace per thread); a moved-from workspace
  /// may only be assigned to or destroyed.
  Workspace(Workspace&&) noexcept;
  /// Move assignment.
  Workspace& operator=(Workspace&&) noexcept;

  /// Model::dof() of the model the workspace was made for.
  int dof() const { return dof_; }
  /// The most constraint rows a task may have without the solve making room first.
  int constraintCapacity() const { return capacity_; }
  /// Makes room for tasks of up to `constraint_rows` rows on `model` (the
  /// model the workspace was made for), allocating when it has less: what a
  /// solve does itself for a task with more rows than constraintCapacity(), so
  /// a control loop that switches between tasks can make room before its
  /// first cycle. The scratch memory is made anew, so the kinematics held are
  /// dropped (KinematicsStage::None); the results stay. ModelMismatch for
  /// another model, WorkspaceTooSmall when the memory cannot be had.
  Status reserve(const Model& model, int constraint_rows) noexcept;
  /// The most balance rows: the constraint rows and one per mimic joint.
  int balanceCapacity() const { return capacity_ + mimic_rows_; }
  /// The most solver columns: two per row, since a relative row has one on
  /// each side, and four per mimic row (each joint's body and its parent).
  int columnCapacity() const { return 2 * capacity_ + 4 * mimic_rows_; }

  /// The results of the last solve. Read or overwrite the values; keep the
  /// sizes (a solve refuses a result vector of another size: SizeMismatch).
  Solution solution;
  FrictionResult friction;  ///< filled by solveWithFriction (the same rule for its sizes)
  /// How far the kinematic results held in the workspace (poses, velocities,
  /// accelerations) go (KinematicsHeld); set by the calls that compute them,
  /// read by the queries of kinematics.hpp.
  KinematicsHeld kinematics;

  /// Joint-space inertia H(q) (nv × nv) of the last jointSpaceInertia.
  Eigen::MatrixXd H;
  /// Joint torques τ (nv) of the last inverseDynamics.
  Eigen::VectorXd tau;

  /// The task forwardDynamics and inverseDynamics use when given none: Task's
  /// default gravity, no constraints, no wrenches.
  const Task& defaultTask() const { return *default_task_; }

 private:
  int dof_;
  int capacity_;
  int mimic_rows_;
  std::unique_ptr<WorkspaceScratch> scratch_;  // the algorithms' memory (src/dynamics/workspace_scratch.hpp)
  std::unique_ptr<Task> default_task_;         // defaultTask()
  friend WorkspaceScratch& scratchOf(Workspace& ws);
  friend const WorkspaceScratch& scratchOf(const Workspace& ws);
};

}  // namespace zwang
