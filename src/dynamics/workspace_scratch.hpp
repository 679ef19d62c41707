// The algorithms' memory in a Workspace: everything but the results a user
// reads, sized once by the Workspace's constructor (a solve allocates nothing).
// Not installed: the public header holds it by pointer, so its layout can
// change without touching the API.
//
// The members are named after the report's Algorithm 1 (chapter 4.2); index i
// is a body (model.hpp: one per DOF; 0 = the world, or a fixed base), DOF i−1
// moves body i (from its parent). A joint of nv DOFs, a floating base's root
// joint among them, is nv bodies: D_i, u_i, S_i are one DOF's.
#pragma once

#include <memory>
#include <vector>

#include "zwang/workspace.hpp"

#include "dynamics/balance.hpp"

namespace zwang {

namespace internal {
struct FrictionScratch;  // src/friction/friction_scratch.hpp: a layer above this one
}

struct WorkspaceScratch {
  // Sized for `model` with room for `columns` solver columns and `balance_rows`
  // balance rows (Workspace::columnCapacity, balanceCapacity). Defined in
  // src/workspace.cpp, which sees the friction layer's scratch too.
  WorkspaceScratch(const Model& model, int columns, int balance_rows);
  ~WorkspaceScratch();
  WorkspaceScratch(const WorkspaceScratch&) = delete;
  WorkspaceScratch& operator=(const WorkspaceScratch&) = delete;

  // Every spatial quantity below is in BASE coordinates: world axes, referred
  // to the world origin (docs/solver.md, "Coordinates"). Algorithm 1's
  // transforms ⁱX_{i−1} between bodies are then identities.

  // --- outward sweep: poses, velocities, bias terms (Algorithm 1, lines 2–10)
  std::vector<Transform> Xworld;  // ⁱX₀, world → body i
  std::vector<Vec6> S;            // S_i, motion subspace
  std::vector<RigidInertia> I;    // I_i, body inertia
  std::vector<Vec6> v;            // Ẋ_i
  std::vector<Vec6> c;            // Ẍ_bias,i = Ẋ_i × S_i q̇_i
  std::vector<Vec6> Fbias;        // F_bias,i = Ẋ_i ×* I_i Ẋ_i − F_ext,i

  // --- the DOF modes the sweeps run with: the task's (bindTaskModes at the start of a solve), or another
  // source's of the same sizes (a stick pattern's locked DOFs)
  const DofMode* dof_modes = nullptr;      // nv entries
  const double* prescribed_qdd = nullptr;  // nv entries, read on the prescribed DOFs only
  int prescribed_count = 0;                // how many are prescribed (0: the sweeps take their plain loops)

  // --- inward sweep: articulated quantities (lines 11–22)
  std::vector<Mat6> IA;           // I^A_i
  std::vector<Vec6> FA;           // F^A_bias,i
  std::vector<Vec6> IAS;          // I^A_i S_i
  std::vector<double> D;          // D_i = d_i + S_iᵀ I^A_i S_i (a joint's D: these pivots are its LDLᵀ factor)
  std::vector<double> inverse_D;  // 1 / D_i (the sweeps multiply)
  std::vector<double> u;          // τ_i − S_iᵀ(F^A_bias,i + I^A_i Ẍ_bias,i)
  Eigen::MatrixXd SA;             // column i: (S_iᵀ A_i)ᵀ, capacity × bodies
  ConstraintMatrix Ahat;          // A_i (6 × capacity), updated in place from A_N down to A_0
  // U_0, acceleration energy of bias forces and torques: the report's U (not
  // Featherstone's or Pinocchio's U = I^A S, which is IAS here).
  Eigen::VectorXd U;
  Eigen::VectorXd L_scale;  // Σ_i |S_i|²|A_i col|²/D_i: the size 𝓛's diagonal rounding is relative to
  Eigen::MatrixXd L;        // 𝓛_0, the balance matrix of line 25 (solver columns², lower triangle)

  // --- the task in sweep form, solver column order (see Task::groups)
  ConstraintMatrix A_body;  // columns of each constraint, as unit forces on its body
  Eigen::VectorXd b_body;   // set points as the sweep's (gravity-shifted, spatial) accelerations

  // --- balance (line 25), src/dynamics/balance.cpp
  internal::BalanceFactorisation balance_factorisation;  // the last balance's factorisation
  Eigen::VectorXd rhs;                                   // b − A_0ᵀẌ_0 − U_0, per balance row
  Eigen::VectorXd nu_columns;                            // ν per solver column (what the sweeps read)
  Eigen::VectorXd nu_motors;                             // ν per solver column with the contacts' set to 0 (τ_c)
  // With relative constraints the balance works on rows, each the sum of its
  // solver columns: 𝓛, its rounding scale, ν and the unit-torque columns per row.
  Eigen::MatrixXd L_rows;
  Eigen::VectorXd L_scale_rows;  // L_scale per balance row (relative constraints)
  Eigen::VectorXd nu_rows;       // ν per balance row (relative constraints)
  Eigen::MatrixXd dU_rows;       // −δU₀ per balance row and unit torque (relative constraints)
  Eigen::MatrixXd dnu_rows;      // δν per balance row and unit torque (relative constraints)
  Eigen::VectorXd row_error;     // Aᵀ Ẍ − b per balance row (taskResidual)
  Eigen::VectorXd row_size;      // the size of the terms of each row's error (taskResidual)

  // --- final outward sweep (lines 26–30) and the constraint-torque pass
  std::vector<Vec6> a;          // Ẍ_i of the sweep: true acceleration + [−g; 0] (a[0], the world's: [−g; 0])
  Vec6 a_world = Vec6::Zero();  // the world's acceleration in the sweep, [−g; 0]: what a is shifted by
  std::vector<Vec6> f;          // accumulated forces (RNEA)
  // The constraint wrenches A ν on each body and its subtree (constraint torques)
  std::vector<Vec6> constraint_wrench;

  // --- other algorithms
  std::vector<Mat6> Ic;  // composite inertias (CRBA)

  // Scratch of the friction extension (src/friction/friction.cpp).
  std::unique_ptr<internal::FrictionScratch> friction_scratch;
};

// The scratch of a workspace: fetched once per function, so that the loops
// index its arrays directly.
inline WorkspaceScratch& scratchOf(Workspace& ws) { return *ws.scratch_; }
inline const WorkspaceScratch& scratchOf(const Workspace& ws) { return *ws.scratch_; }

}  // namespace zwang
