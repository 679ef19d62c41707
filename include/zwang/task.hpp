/// \file
/// What a solve is asked to do, apart from the joint state: gravity, external
/// wrenches and acceleration constraints Aᵀ Ẍ = b on any frames of the chain.
/// Build a Task once (this allocates); then change set points and wrench values
/// every control cycle (this does not).
#pragma once

#include <string>
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
///           "base-aligned"; `Aligned` is the same choice under that name.
enum class Expressed { Local, World, Aligned = World };

/// A: 6×m, one unit constraint force [l; r] (linear part first) per column.
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

/// What a solve is asked to do besides the joint state: see the file comment.
class Task {
 public:
  /// An empty task for `model`: default gravity, no constraints, no wrenches.
  explicit Task(const Model& model);

  Vec3 gravity{0.0, 0.0, -9.81};  ///< world axes [m/s²] (docs/conventions.md, "Gravity")
  BalanceOptions balance;         ///< thresholds of the balance (BalanceOptions)

  /// Constrain the classical acceleration of `frame`'s origin along the columns
  /// of A (6×m, unit constraint forces, linear part first): Aᵀ Ẍ = b. b starts
  /// at zero. Returns the index of the constraint's first row in b and ν.
  int addConstraint(int frame, const ConstraintMatrix& A, Expressed expressed = Expressed::Local);
  /// The same, with the frame given by name (ModelError for an unknown name).
  int addConstraint(const std::string& frame, const ConstraintMatrix& A, Expressed expressed = Expressed::Local);

  /// Apply a wrench [f; n] at `frame`'s origin. Starts at zero. Returns its index.
  int addWrench(int frame, Expressed expressed = Expressed::Local);
  /// The same, with the frame given by name (ModelError for an unknown name).
  int addWrench(const std::string& frame, Expressed expressed = Expressed::Local);

  /// Set points b (true accelerations, gravity is handled inside). Set them freely.
  Eigen::VectorXd& targets() { return b_; }
  /// Set points b, read-only.
  const Eigen::VectorXd& targets() const { return b_; }
  /// Wrench values, one 6-vector per addWrench.
  Vec6& wrench(int index) { return wrenches_.at(static_cast<std::size_t>(index)).value; }
  /// Wrench `index`, read-only.
  const Vec6& wrench(int index) const { return wrenches_.at(static_cast<std::size_t>(index)).value; }

  /// Number of constraint rows m (the length of b and ν).
  int constraintRows() const { return static_cast<int>(b_.size()); }
  /// Number of wrenches added.
  int wrenchCount() const { return static_cast<int>(wrenches_.size()); }

  // --- read by the solver -------------------------------------------------
  /// The constraints on one frame, as the solver reads them.
  struct ConstraintGroup {
    int frame;            ///< frame index
    int body;             ///< the body the frame rides on
    Expressed expressed;  ///< axes of A's columns
    int first_row;        ///< in the user's row order (b, ν)
    int rows;             ///< number of rows (columns of A)
    ConstraintMatrix A;   ///< 6 × rows
  };
  /// One wrench, as the solver reads it.
  struct AppliedWrench {
    int frame;                  ///< frame index
    Expressed expressed;        ///< axes of value
    Vec6 value = Vec6::Zero();  ///< [f; n] at the frame origin
  };
  /// Groups sorted by body, farthest from the base first, so that the
  /// constraints acting on bodies i..N are always a leading block of columns
  /// ("solver order"). `solver_row[k]` is the user row of solver column k.
  const std::vector<ConstraintGroup>& groups() const { return groups_; }
  /// `solver_row[k]`: the user row of solver column k.
  const std::vector<int>& solverRowToUserRow() const { return solver_row_; }
  /// Number of solver columns acting on body b or beyond (a leading block).
  int activeColumns(int body) const { return active_.at(static_cast<std::size_t>(body)); }
  /// The wrenches, in the order of addWrench.
  const std::vector<AppliedWrench>& wrenches() const { return wrenches_; }
  /// Joint count of the model the task was made for (checked by every solve).
  int modelDof() const { return dof_; }
  /// Frame count of the model the task was made for (checked by every solve).
  int modelFrames() const { return frames_; }

 private:
  int dof_;
  int frames_;
  std::vector<std::string> frame_names_;  // copied, so the Task does not dangle
  std::vector<int> frame_bodies_;
  std::vector<ConstraintGroup> groups_;
  std::vector<int> solver_row_;
  std::vector<int> active_;
  std::vector<AppliedWrench> wrenches_;
  Eigen::VectorXd b_;
  void reorder();
};

}  // namespace zwang
