// The stages of the Popov–Vereshchagin solver (Algorithm 1), callable one by
// one so that the friction extension can run the same sweeps with extra
// right-hand sides. Not installed; the public entry is solveHybridDynamics.
#pragma once

#include <vector>

#include "zwang/status.hpp"
#include "zwang/workspace.hpp"

#include "dynamics/workspace_scratch.hpp"

#include "dynamics/checks.hpp"
#include "dynamics/task_solver_order.hpp"

namespace zwang::internal {

using VectorRef = Eigen::Ref<const Eigen::VectorXd>;
using Matrix6X = Eigen::Matrix<double, 6, Eigen::Dynamic>;

// The body DOF k (entry k of v) moves (body 0 is the world), and that DOF's
// articulated inertia D (line 13: its pivot of the joint's D) after the inward sweep.
inline int bodyOfDof(int dof) { return dof + 1; }
inline double dofInertia(const Workspace& ws, int dof) {
  return scratchOf(ws).D[static_cast<std::size_t>(bodyOfDof(dof))];
}

// Whether entry `dof` of v is prescribed in the task (the input checks and the friction layer's set-up).
inline bool isPrescribed(const Task& task, int dof) {
  return task.dofModes()[static_cast<std::size_t>(dof)] == DofMode::Prescribed;
}

// The DOF modes the sweeps run with (WorkspaceScratch::dof_modes): the task's, bound at the start of a solve. The
// hot loops index them unchecked (the input checks sized them).
inline void bindTaskModes(const Task& task, WorkspaceScratch& sw) {
  sw.dof_modes = task.dofModes().data();
  sw.prescribed_qdd = task.prescribedAccelerations().data();
  sw.prescribed_count = task.prescribedCount();
}
inline bool isPrescribed(const WorkspaceScratch& sw, int dof) { return sw.dof_modes[dof] == DofMode::Prescribed; }
inline double prescribedAcceleration(const WorkspaceScratch& sw, int dof) { return sw.prescribed_qdd[dof]; }

// Input checks shared by every solve (the balance options included).
Status checkSolveInputs(const Model& model, const Task& task, const VectorRef& q, const VectorRef& qd,
                        const VectorRef& tau, const Workspace& ws);
// Room in the workspace for the task's rows, made when it has less
// (Workspace::reserve: the scratch is made anew, so take scratchOf(ws) after).
Status roomForTask(const Model& model, const Task& task, Workspace& ws) noexcept;

// Lines 2–10: kinematics, F_bias (with the task's wrenches), I^A = I, F^A = F_bias,
// and the task's constraints in body form.
void outwardSweep(const Model& model, const Task& task, const VectorRef& q, const VectorRef& qd, Workspace& ws);

// Lines 11–22 for the joint torques `tau`: D, I^A S, u, A_i, U_0, 𝓛_0.
// Fails (Degenerate) when a joint has no inertia to move.
Status inwardSweep(const Model& model, const Task& task, const VectorRef& tau, Workspace& ws);

// Line 25: ν = 𝓛⁺(b − A₀ᵀẌ₀ − U₀) into sw.nu_columns (solver order), factoring 𝓛
// (kept in sw.balance_factorisation for unitTorqueColumns) and filling
// ws.solution.balance (all but the residual: see taskResidual).
void balance(const Task& task, Workspace& ws);

// Lines 26–30: q̈ (into `qdd`) and Ẍ (into sw.a) from sw.nu_columns.
void outwardAccelerations(const Model& model, const Task& task, Workspace& ws, Eigen::Ref<Eigen::VectorXd> qdd);

// Line 29 alone: Ẍ (into sw.a) from a known q̈.
void bodyAccelerations(const Model& model, const Task& task, Workspace& ws, const VectorRef& qdd);

// After the accelerations: the base's classical acceleration [p̈; ω̇] of its
// origin, world axes (zero on a fixed base: the world's).
Vec6 baseClassicalAcceleration(const Model& model, const Workspace& ws);

// Scratch of unitTorqueColumns, sized once for up to `dof` columns.
struct UnitTorqueScratch {
  // The outward pass takes the columns this many at a time, side by side:
  // four SSE2 pairs per operation (29 columns: 8 + 8 + 8 + 4 + 1).
  static constexpr int kLanes = 8;
  UnitTorqueScratch(int dof, int bodies, int capacity)
      : du(bodies, dof),
        dU(capacity, dof),
        dF(6, dof),
        joint_rows(6, capacity),
        da(6 * kLanes, bodies),
        dnu_lanes(kLanes, capacity),
        run_begin(bodies),
        run_end(bodies) {}
  Eigen::MatrixXd du;         // bodies × k: δu_i per unit torque
  Eigen::MatrixXd dU;         // capacity × k: δU₀ per unit torque
  Matrix6X dF;                // 6 × k: δF^A carried inward per unit torque
  Matrix6X joint_rows;        // 6 × capacity: a multi-DOF joint's δU₀ per unit δF^A, transposed
  Eigen::MatrixXd da;         // column i: body i's δẌ for up to kLanes columns (kLanes × 6, column-major)
  Eigen::MatrixXd dnu_lanes;  // kLanes × capacity: δν of those columns, one row per column
  // Body i's run of columns [run_begin[i], run_end[i]): those whose DOF's
  // body lies in i's subtree, the only ones with δu_i ≠ 0 (du is set there only).
  Eigen::Matrix<Eigen::Index, Eigen::Dynamic, 1> run_begin, run_end;
};

// k extra right-hand sides through the same sweeps, all at once: column c is
// a unit torque at DOF dofs[c] (entries of v, ascending), everything else
// zero. Gives δν (dnu: solver columns × k) and δq̈ = ∂q̈/∂τ_dof (dqdd: nv × k). Needs inwardSweep and balance first.
// O((N + m²)·k): the sensitivity K_Θ of the friction extension. The inward
// pass visits only each column's path to the base; the balance solve and the
// outward pass take up to kLanes columns side by side.
void unitTorqueColumns(const Model& model, const Task& task, Workspace& ws, const std::vector<int>& dofs,
                       UnitTorqueScratch& scratch, Eigen::Ref<Eigen::MatrixXd> dnu, Eigen::Ref<Eigen::MatrixXd> dqdd);

// The joints whose q lies outside their limits, into the solution (a warning).
void jointsOutsideLimits(const Model& model, const VectorRef& q, Solution& out);

// After the final accelerations (sw.a): ‖Aᵀ Ẍ − b‖ and whether every row is
// met, into ws.solution.balance.
void taskResidual(const Task& task, Workspace& ws);

// τ_c = Σ J_iᵀ A_i ν_i for ν per solver column (one inward pass of the
// wrenches A ν), over the constraints the motors carry: contacts' columns
// count with ν = 0.
void constraintTorques(const Model& model, const Task& task, Workspace& ws, const VectorRef& nu_solver,
                       Eigen::Ref<Eigen::VectorXd> tau_c);

// The prescribed DOFs' entries of τ_c (after constraintTorques): the torque each takes, d q̈ + Sᵀ f with f what
// its joint transmits to its subtree (RNEA's inward pass on the solved motion sw.a, the contacts' forces acting on
// the bodies), less its τ — so that τ + τ_c is what its motor gives, the task's other constraint forces included
// as for every joint. Nothing when no DOF is prescribed.
void prescribedTorques(const Model& model, const Task& task, Workspace& ws, const VectorRef& nu_solver,
                       const VectorRef& qdd, const VectorRef& tau, Eigen::Ref<Eigen::VectorXd> tau_c);
// Their contacts' part alone, −Sᵀ Σ A ν over the subtree's contact columns: how those entries move with ν at a
// fixed motion (the friction's flat directions).
void prescribedContactTorques(const Model& model, const Task& task, Workspace& ws, const VectorRef& nu_solver,
                              Eigen::Ref<Eigen::VectorXd> tau_c);
// Every column's part, −Sᵀ Σ A ν over the subtree: how a prescribed DOF's residual (prescribedDofResiduals) moves
// with ν at a fixed motion.
void prescribedConstraintTorques(const Model& model, const Task& task, Workspace& ws, const VectorRef& nu_solver,
                                 Eigen::Ref<Eigen::VectorXd> tau_c);
// For each DOF the sweeps held prescribed (the modes bound in sw), what the rest of its joint's equation leaves
// over with every constraint force acting: λ = d q̈ + Sᵀ Σ_subtree (I a + F_bias − A ν) − τ, the generalized force
// something else must give it (a locked DOF of a stick pattern: its friction, −λ). Other entries untouched.
void prescribedDofResiduals(const Model& model, const Task& task, Workspace& ws, const VectorRef& nu_solver,
                            const VectorRef& qdd, const VectorRef& tau, Eigen::Ref<Eigen::VectorXd> residual);
// Mimic joints' torques onto their leaders' motors: τ_l += a·τ_m, τ_m = 0.
void carryMimicTorques(const Model& model, Eigen::Ref<Eigen::VectorXd> tau_control);

// τ_control = τ + τ_c with the mimic joints' torques carried by their leaders
// (τ_c adjusted to keep the sum), from out.tau_constraint.
void controlTorques(const Model& model, const VectorRef& tau, Solution& out);

// Gauss function of the true accelerations sw.a − [−g; 0], with joint torques `tau`.
double gaussFunction(const Model& model, const Task& task, const VectorRef& qdd, const VectorRef& tau,
                     const Workspace& ws);

// sw.nu_columns (solver order) into the solution's ν (the task's row order).
void publishNu(const Task& task, Workspace& ws);

}  // namespace zwang::internal
