/// \file
/// What a solve is asked to do, apart from the joint state: gravity, external
/// wrenches and acceleration constraints Aᵀ Ẍ = b on any frames of the tree,
/// absolute or relative to another frame.
/// Build a Task once (this allocates); then change set points and wrench values
/// every control cycle (this does not).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "zwang/model.hpp"
#include "zwang/status.hpp"

namespace zwang {

/// How the components of a user-facing spatial quantity are expressed.
/// Every such quantity refers to the ORIGIN of its frame (a wrench acts there; an
/// acceleration is the classical acceleration of that point), so the choice is
/// only of axes:
///   Local : the frame's own axes;
///   World : the world (base) axes, at the frame origin. KDL calls this
///           "base-aligned"; `Aligned` is the same choice under that name;
///   Reference : for a relative constraint, the axes of the frame it is
///           relative to (for anything else the reference is the world:
///           the same as World).
enum class Expressed { Local, World, Aligned = World, Reference };

/// A: 6×m, one unit constraint force [l; r] (linear part first) per column.
/// A column need not have unit length: scaled by c, its row reads c·(aᵀẌ) = b
/// and its ν comes out divided by c (docs/conventions.md, "Constraints").
using ConstraintMatrix = Eigen::Matrix<double, 6, Eigen::Dynamic>;

/// Options of the balance ν = 𝓛⁺ r of Algorithm 1's line 25 (docs/solver.md,
/// "Singular tasks"). 𝓛 is judged after equilibration, 𝓛̃ = E 𝓛 E with
/// E = diag(1/√𝓛_ii), so that rows in metres and radians, on heavy or light
/// links, weigh alike; its eigenvalues σ̃ lie in [0, m].
///   σ̃ ≥ singular_threshold : solved exactly (every regular task);
///   σ̃ ≤ rank_tolerance     : exact rank loss: no force along it, and the task
///                            is met in the least-squares sense (rows' units);
///   in between             : near-singular: the gain ramps linearly from 0 to
///                            1/σ̃ (and the least-squares projection from full
///                            to none), so ν stays bounded (at most
///                            1/singular_threshold in 𝓛̃'s units) and
///                            continuous as an arm passes through a singularity.
/// After the solve a row counts as met when |Aᵀ Ẍ − b| ≤ residual_tolerance ×
/// the size of the terms it is computed from (BalanceReport::consistent).
struct BalanceOptions {
  // Defaults: exact null directions come out at ~1e-15 (rounding) and regular
  // ones of random chains above ~1e-3 (test_singular measures both): a wide gap.
  double singular_threshold = 1e-6;  ///< equilibrated eigenvalues below it are near-singular (in (0, 1))
  double rank_tolerance = 1e-11;     ///< at or below it: exact rank loss (in [0, singular_threshold))
  double residual_tolerance = 1e-9;  ///< a row is met within this fraction of its terms' size (> 0)
};

/// BadOption naming the field when an option is out of range (every solve
/// checks the task's options this way).
Status checkBalanceOptions(const BalanceOptions& options);

/// How a DOF moves in a solve: joint-level hybrid dynamics (docs/solver.md,
/// "Prescribed and locked joints").
enum class DofMode : std::uint8_t {
  Torque,      ///< driven by its entry of τ (the default): the solve finds its q̈
  Prescribed,  ///< its q̈ is given (Task::prescribedAccelerations): the solve finds the torque it takes
};

/// What a solve is asked to do besides the joint state: see the file comment.
class Task {
 public:
  /// An empty task for `model`: default gravity, no constraints, no wrenches.
  explicit Task(const Model& model);
  /// A copy owns its own constraints: changing one task leaves the other as it was.
  Task(const Task& other) = default;
  /// Copy assignment, likewise. There is no move: a moved-from Task would be
  /// left without its constraints, so a move copies and the source stays whole.
  Task& operator=(const Task& other) = default;

  Vec3 gravity{0.0, 0.0, -9.81};  ///< world axes [m/s²] (docs/conventions.md, "Gravity")
  BalanceOptions balance;         ///< thresholds of the balance (BalanceOptions)

  /// Constrain the classical acceleration of `frame`'s origin along the columns
  /// of A (6×m, unit constraint forces, linear part first): Aᵀ Ẍ = b. b starts
  /// at zero. Returns the index of the constraint's first row in b and ν.
  int addConstraint(int frame, const ConstraintMatrix& A, Expressed expressed = Expressed::Local);
  /// The same, with the frame given by name (ModelError for an unknown name).
  int addConstraint(const std::string& frame, const ConstraintMatrix& A, Expressed expressed = Expressed::Local);

  /// Constrain the acceleration of `frame` relative to `reference` (another
  /// frame, on any body) along the columns of A: the second derivative of the
  /// position of frame's origin and the derivative of the angular velocity, as
  /// an observer riding on `reference` sees them (docs/solver.md, "Relative
  /// constraints"). Zero set points with zero relative velocity keep the two
  /// frames rigidly together: two hands holding a box. The constraint force is
  /// +A ν on frame's body and −A ν on reference's. Axes: Local (frame's),
  /// Reference (reference's) or World. ModelError for the same frame twice.
  int addRelativeConstraint(int frame, int reference, const ConstraintMatrix& A,
                            Expressed expressed = Expressed::Reference);
  /// The same, with the frames given by name (ModelError for an unknown name).
  int addRelativeConstraint(const std::string& frame, const std::string& reference, const ConstraintMatrix& A,
                            Expressed expressed = Expressed::Reference);

  /// Constrain the acceleration of moving joint `joint` (an index in
  /// Model::joints()): q̈_joint = b, one row per DOF of the joint in the order
  /// of its entries of v (b starts at 0). Its force is a torque (a force, for
  /// a translation) along each DOF, equal and opposite on the two bodies it
  /// connects: what the joint's own motor gives. So a posture held joint by
  /// joint is held by the motors, also on a floating base (docs/solver.md,
  /// "Joint rows and contacts"). ModelError for a joint index out of range.
  /// Returns the first row.
  int addJointConstraint(int joint);
  /// The same, with the joint given by name (ModelError for an unknown name).
  int addJointConstraint(const std::string& joint);

  /// A constraint whose force the environment supplies, not the motors: a foot
  /// on the ground, a hand against a wall. It moves the robot like
  /// addConstraint's, its ν is that contact force, and it is left out of
  /// Solution::tau_constraint and tau_control (the motors do not give it).
  /// On a fixed-base model whose base (body 0) carries mass the first contact
  /// records a FixedBaseContact warning (warnings()): the world holds that base
  /// up, so a robot standing on its contacts, loaded without a floating base,
  /// would be solved bolted down.
  int addContact(int frame, const ConstraintMatrix& A, Expressed expressed = Expressed::Local);
  /// The same, with the frame given by name (ModelError for an unknown name).
  int addContact(const std::string& frame, const ConstraintMatrix& A, Expressed expressed = Expressed::Local);

  /// Apply a wrench [f; n] at `frame`'s origin. Starts at zero. Returns its index.
  int addWrench(int frame, Expressed expressed = Expressed::Local);
  /// The same, with the frame given by name (ModelError for an unknown name).
  int addWrench(const std::string& frame, Expressed expressed = Expressed::Local);

  /// Prescribe the acceleration of moving joint `joint` (an index in
  /// Model::joints()): each of its DOFs moves with the q̈ its entries of
  /// prescribedAccelerations() hold (set them every cycle, as the set points),
  /// and the solve returns the torque that takes, in Solution::tau_control
  /// (tau_constraint: that torque less the given τ, which a prescribed DOF
  /// does not read). The sweeps pass such a joint rigidly: no row, no growth
  /// of the balance. A prescribed DOF has no friction unknown (its torque is
  /// what its motor must give; a moving one's kinetic friction is in it).
  /// ModelError for an index out of range or a mimic joint (prescribe its
  /// leader). Changing modes allocates nothing.
  void prescribe(int joint);
  /// The same, with the joint given by name (ModelError for an unknown name).
  void prescribe(const std::string& joint);
  /// Prescribe q̈ = 0 on every DOF of `joint` (its entries of
  /// prescribedAccelerations() are set to 0): the joint is held where it is.
  void lock(int joint);
  /// The same, with the joint given by name (ModelError for an unknown name).
  void lock(const std::string& joint);
  /// Make `joint` torque-driven again (the default).
  void release(int joint);
  /// The same, with the joint given by name (ModelError for an unknown name).
  void release(const std::string& joint);
  /// The mode of one DOF, an entry of v (a floating base's come first: a
  /// base DOF may be prescribed too, a robot on a moving platform). ModelError
  /// for an index out of range or a mimic joint's DOF.
  void setDofMode(int dof, DofMode mode);
  /// The mode of DOF `dof` (an entry of v).
  DofMode dofMode(int dof) const { return dof_modes_.at(static_cast<std::size_t>(dof)); }
  /// The modes of all DOFs, entries of v in order.
  const std::vector<DofMode>& dofModes() const { return dof_modes_; }
  /// How many DOFs are prescribed.
  int prescribedCount() const { return prescribed_count_; }
  /// q̈ of the prescribed DOFs, one entry per entry of v (nv; the entries of
  /// torque-driven DOFs are not read). Starts at zero. Its size is the
  /// model's: a solve refuses any other (SizeMismatch).
  Eigen::VectorXd& prescribedAccelerations() { return prescribed_qdd_; }
  /// q̈ of the prescribed DOFs, read-only.
  const Eigen::VectorXd& prescribedAccelerations() const { return prescribed_qdd_; }

  /// Set points b (true accelerations, gravity is handled inside), one per
  /// constraint row. Set their values freely (`targets() << …`, `setZero()`,
  /// `segment(row, n) = …`); their size is the task's: a solve refuses b of
  /// any other length (SizeMismatch "constraint targets b has 3 entries, the
  /// task has 6 constraint rows"), and so does adding a constraint (ModelError).
  Eigen::VectorXd& targets() { return b_; }
  /// Set points b, read-only.
  const Eigen::VectorXd& targets() const { return b_; }
  /// Wrench values, one 6-vector per addWrench.
  Vec6& wrench(int index) { return wrenches_.at(static_cast<std::size_t>(index)).value; }
  /// Wrench `index`, read-only.
  const Vec6& wrench(int index) const { return wrenches_.at(static_cast<std::size_t>(index)).value; }

  /// Number of constraint rows m (the length of b and ν), counted as the
  /// constraints are added (not read from b, whose size a user could change).
  int constraintRows() const { return rows_; }
  /// Internal rows the model's mimic joints add, q̈_m − a·q̈_leader = 0, one per
  /// mimic joint (Model::mimicJoints), after the user's rows in the balance.
  int mimicRows() const { return mimic_rows_; }
  /// True when the mimic rows are those of `model`'s mimic joints (same joints,
  /// leaders and multipliers): every solve checks it.
  bool mimicLawsMatch(const Model& model) const;
  /// Rows of the balance: the user's constraint rows, then the mimic rows.
  int balanceRows() const { return constraintRows() + mimic_rows_; }
  /// Number of wrenches added.
  int wrenchCount() const { return static_cast<int>(wrenches_.size()); }
  /// What is doubtful about the task on its model (each once, in the order
  /// found): FixedBaseContact (addContact). The front ends print them as they
  /// print Model::warnings().
  const std::vector<ModelWarning>& warnings() const { return warnings_; }

  // --- read by the solver -------------------------------------------------
  /// One wrench, as the solver reads it.
  struct AppliedWrench {
    int frame;                  ///< frame index
    Expressed expressed;        ///< axes of value
    Vec6 value = Vec6::Zero();  ///< [f; n] at the frame origin
  };
  /// Number of solver columns: one per row, two for a row of a relative
  /// constraint (one on each side).
  int solverColumns() const { return solver_columns_; }
  /// True when some constraint is a contact (addContact).
  bool hasContacts() const { return has_contacts_; }
  /// The wrenches, in the order of addWrench.
  const std::vector<AppliedWrench>& wrenches() const { return wrenches_; }
  /// Joint count of the model the task was made for (checked by every solve).
  int modelDof() const { return dof_; }
  /// Frame count of the model the task was made for (checked by every solve).
  int modelFrames() const { return frames_; }

 private:
  // --- the solver's view (src/model/task_layout.hpp, read through
  // src/dynamics/task_solver_order.hpp) ------------------------------------
  friend class TaskSolverOrder;
  struct Layout;
  // Owns the layout and copies it with the task (a copied Task is independent;
  // a move copies too, so no Task is left without one). Out of line: Layout is
  // complete only in src/.
  class LayoutPointer {
   public:
    LayoutPointer();
    LayoutPointer(const LayoutPointer& other);
    LayoutPointer& operator=(const LayoutPointer& other);
    ~LayoutPointer();
    Layout* operator->() const { return layout_.get(); }
    Layout& operator*() const { return *layout_; }

   private:
    std::unique_ptr<Layout> layout_;
  };
  LayoutPointer layout_;

  int dof_;
  int frames_;
  std::vector<std::string> frame_names_;  // copied, so the Task does not dangle
  std::vector<std::string> joint_names_;  // likewise
  std::vector<int> frame_bodies_;
  double fixed_base_mass_;  // body 0's mass when the base is fixed (the world holds it), else 0
  std::vector<ModelWarning> warnings_;
  int mimic_rows_ = 0;
  int solver_columns_ = 0;  // the layout's, kept here for the inline accessor
  bool has_contacts_ = false;
  std::vector<std::pair<int, int>> joint_dofs_;  // per joint, its v_index and nv (copied from the model)
  std::vector<int> dof_parent_bodies_;           // per DOF, the parent of the body it moves
  std::vector<int> body_frames_;                 // per body, its frame
  std::vector<Mimic> mimic_laws_;                // the law of each mimic row (its mimic joint below)
  std::vector<int> mimic_joint_of_row_;
  std::vector<AppliedWrench> wrenches_;
  std::vector<DofMode> dof_modes_;  // per entry of v
  std::vector<char> mimic_dof_;     // per entry of v: a mimic joint's (never prescribed)
  int prescribed_count_ = 0;
  Eigen::VectorXd prescribed_qdd_;  // per entry of v
  Eigen::VectorXd b_;
  int rows_ = 0;  // the constraint rows added; b_ must keep this size
  void growTargets(int rows);
  int jointIndex(const std::string& joint) const;
  std::pair<int, int> jointDofs(int joint) const;
  void addMimicRows(const Model& model);
  void reorder();
};

}  // namespace zwang
