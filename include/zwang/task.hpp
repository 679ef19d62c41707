/// \file
/// What a solve is asked to do, apart from the joint state: gravity, external
/// wrenches and acceleration constraints Aᵀ Ẍ = b on any frames of the chain.
/// Build a Task once (this allocates); then change set points and wrench values
/// every control cycle (this does not).
#pragma once

#include <string>
#include <vector>

#include "zwang/model.hpp"

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

// Options for the constraint balance ν = L⁻¹(…) (docs/solver.md, "Singular tasks").
// With λ_max, λ_min the extreme eigenvalues of L:
//   singular  ⇔ λ_min < singular_threshold · λ_max  (rank counts the eigenvalues above it);
//   damping   λ = max_damping · λ_max · sqrt(1 − (λ_min / (singular_threshold·λ_max))²) when singular, else 0;
//   ν = Σ_k σ_k/(σ_k² + λ²) (e_kᵀ r) e_k  over the eigenpairs (σ_k, e_k) of L:
// exact when L is regular; when singular, the damped least-squares solution
// (constraints met in the least-squares sense, no force along L's null space).
struct BalanceOptions {
  double singular_threshold = 1e-9;
  double max_damping = 1e-5;
};

/// What a solve is asked to do besides the joint state: see the file comment.
class Task {
 public:
  /// An empty task for `model`: default gravity, no constraints, no wrenches.
  explicit Task(const Model& model);

  Vec3 gravity{0.0, 0.0, -9.81};  ///< world axes [m/s²] (docs/conventions.md, "Gravity")
  BalanceOptions balance;         ///< singular threshold and damping of the balance

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
