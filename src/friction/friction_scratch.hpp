// Scratch memory of the friction extension, sized once per workspace. Named
// after docs/friction.md's sections; indices a run over Θ₀, the k stuck joints.
#pragma once

#include "dynamics/popov_vereshchagin.hpp"
#include "friction/friction_maximisers.hpp"
#include "qp/box_qp.hpp"
#include "zwang/workspace.hpp"

namespace zwang::internal {

struct FrictionScratch {
  // dof: Model::dof(), the friction entries; nv: velocity coordinates (a floating base's
  // first); capacity: solver columns
  FrictionScratch(int dof, int nv, int bodies, int capacity)
      : breakaway(dof),
        kinetic(dof),
        viscous(dof),
        tau_effective(nv),
        lo(dof),
        hi(dof),
        qdd0(nv),
        nu0(capacity),
        unit_torques(dof, bodies, capacity),
        dnu(capacity, dof),
        dqdd(nv, dof),
        K(dof, dof),
        qdd0_stuck(dof),
        curvature_terms(dof),
        slope_terms(dof),
        mu(dof),
        qp(dof),
        margin_limit(dof),
        effort_offset(dof),
        nu_first(capacity),
        tau_constraint_first(nv),
        tau_control_first(nv),
        choice(dof, capacity, nv),
        tau_joint(nv) {
    is_mimic.assign(static_cast<std::size_t>(dof), 0);
    stuck_dofs.reserve(static_cast<std::size_t>(dof));
    pattern_stuck.reserve(static_cast<std::size_t>(dof));
    pattern_state.reserve(static_cast<std::size_t>(dof));
    locked_dofs.reserve(static_cast<std::size_t>(dof));
    trial_state.reserve(static_cast<std::size_t>(dof));
    pattern_breaks.assign(static_cast<std::size_t>(dof), 0);
    pattern_modes.assign(static_cast<std::size_t>(nv), DofMode::Torque);
    pattern_qdd.setZero(nv);
    pattern_tau.setZero(nv);
    pattern_residual.setZero(nv);
    pattern_direction.setZero(nv);
    free_lambda.setZero(dof, capacity);
    free_factor.setZero(capacity, capacity);
    free_step.setZero(capacity);
    free_target.setZero(dof);
    margin_lo.setZero(dof);
    margin_hi.setZero(dof);
    pattern_nu.setZero(capacity);
    free_bounded.setZero(dof, capacity);
    free_reference.setZero(capacity);
    free_shift.setZero(capacity);
    free_dw.setZero(capacity);
    free_mu.setZero(dof);
    free_lo.setZero(dof);
    free_hi.setZero(dof);
    pattern_rhs.setZero(capacity);
  }

  // The model of friction, per joint (the options' overrides, else the model's)
  Eigen::VectorXd breakaway, kinetic, viscous;  // f_j, f_c,j, b_j
  Eigen::VectorXd tau_effective;                // τ − kinetic and viscous friction of the moving joints
  Eigen::VectorXd lo, hi;                       // Λ on Θ₀ (±∞ where a limit stop pushes)
  std::vector<char> is_mimic;                   // per entry: a mimic joint's (its leader carries its friction)
  std::vector<int> stuck_dofs;                  // Θ₀ as entries of v (the sweeps' DOFs)

  // ∂q̈/∂μ in the same sweeps
  Eigen::VectorXd qdd0;            // q̈(μ = 0)
  Eigen::VectorXd nu0;             // ν(μ = 0), per solver column
  UnitTorqueScratch unit_torques;  // the sweeps' scratch
  Eigen::MatrixXd dnu;             // capacity × k: δν per unit torque
  Eigen::MatrixXd dqdd;            // nv × k: δq̈ per unit torque (a floating base's rows first)

  // The maximiser: min ½ μᵀ K_ΘΘ μ − μᵀ q̈_Θ(0) over Λ
  Eigen::MatrixXd K;                // K_ΘΘ = rows Θ of −∂q̈/∂μ
  Eigen::VectorXd qdd0_stuck;       // q̈_Θ(0)
  Eigen::VectorXd curvature_terms;  // per stuck joint: the size of the terms its column of K_ΘΘ is a sum of
  Eigen::VectorXd slope_terms;      // per stuck joint: the size of the terms its q̈_j(0) is a sum of
  Eigen::VectorXd mu;               // μ* on Θ₀
  QpScratch qp;

  // When μ* is not unique
  Eigen::VectorXd margin_limit;          // margin · f_j on Θ₀
  Eigen::VectorXd effort_offset;         // h = τ + τ_c(μ*) − μ* on Θ₀: the motor torque without friction
  Eigen::VectorXd nu_first;              // ν at the maximiser returned by the QP (per solver column)
  Eigen::VectorXd tau_constraint_first;  // τ_c at that maximiser
  Eigen::VectorXd tau_control_first;     // τ + τ_c there, mimic joints' carried by their leaders
  MaximiserChoiceScratch choice;

  // The pattern search (src/friction/stick_pattern.cpp); the last solve's pattern, where it starts with
  // FrictionOptions::warm_start
  const Model* pattern_model = nullptr;  // what it was found for: nullptr when there is none to try
  const Task* pattern_task = nullptr;
  std::vector<int> pattern_stuck;         // Θ₀ then
  std::vector<JointState> pattern_state;  // per stuck index then: Stick, SlipPositive, SlipNegative or AtLimit
  std::vector<JointState> trial_state;    // per stuck index: the pattern of the search's pass
  std::vector<char> pattern_breaks;       // per stuck index: the pass broke its condition
  std::vector<DofMode> pattern_modes;     // nv: the task's modes with the sticking DOFs locked
  Eigen::VectorXd pattern_qdd;            // nv: the task's prescribed accelerations, 0 on the locked DOFs
  Eigen::VectorXd pattern_tau;            // nv: τ_effective with the slipping DOFs' friction bound applied
  Eigen::VectorXd pattern_residual;       // nv: λ of the locked DOFs (prescribedDofResiduals)
  // Contacts the locks make dependent (leastEffortFriction): ν free along the balance's null directions n
  Eigen::VectorXd pattern_direction;     // nv: λ of the locked DOFs from a unit ν along one n
  Eigen::MatrixXd free_lambda;           // P: locked friction DOFs × nullity, those λ
  Eigen::MatrixXd free_factor;           // nullity × nullity: R, PᵀP = R Rᵀ
  Eigen::VectorXd free_step;             // nullity: z, ν moves by N z and λ by P z
  std::vector<int> locked_dofs;          // the locked friction DOFs, as indices into Θ₀
  Eigen::VectorXd free_target;           // per locked DOF: what Pᵀ is applied to (−λ₀, or h − λ₀)
  Eigen::VectorXd margin_lo, margin_hi;  // on Θ₀: the margin box about the smallest maximiser
  // The bounded least effort (boundedLeastEffort): −Q, z_a, Rᵀ(z_b − z_a), the step in w, μ_ref and the margin box
  // on the locked DOFs
  Eigen::MatrixXd free_bounded;
  Eigen::VectorXd free_reference, free_shift, free_dw, free_mu, free_lo, free_hi;
  Eigen::VectorXd pattern_nu, pattern_rhs;  // the pass's ν and balance right-hand side, kept across freeBalanceRegular
  bool pattern_on_bounds = false;           // its μ was put on the margin box by the bounded least effort
  bool pattern_indeterminate = false;       // the pass's μ was chosen among maximisers (leastEffortFriction)
  bool sensitivities_written = false;       // FrictionResult::dqdd_dmu holds columns of the last full solve

  // Outputs
  Eigen::VectorXd tau_joint;  // τ − kinetic − μ*: what the joints feel (the Gauss function's torques)
};

}  // namespace zwang::internal
