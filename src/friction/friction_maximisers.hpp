// When μ* is not unique (docs/friction.md, "When μ* is not unique"): every
// maximiser of g gives the same q̈*, so they differ only along null(K_ΣΣ), Σ
// the stuck joints that stick at μ*. Among them pick the one that minimises
// the motors' effort within the margin box.
#pragma once

#include <Eigen/Core>

#include "qp/box_qp.hpp"

namespace zwang::internal {

// How the joints' τ_control moves on the set of maximisers μ = μ_ref + N z.
enum class EffortChange {
  // Each sticking joint's own torque moves one for one with its friction, the
  // rest stays: τ_control,a = h_a + μ_a on Σ. Exact when no contact takes a
  // share that moves with μ (every row's force is in τ_control).
  Own,
  // τ_control = c + B z, B = ∂τ_control/∂z (MaximiserChoiceScratch::
  // effort_gradient) on every joint: contacts take a share that moves with μ.
  Shared,
  // τ_control does not move (B ≈ 0, e.g. every row a contact): no effort to
  // choose by, the reference point stays.
  Fixed,
};

// Scratch of the choice, sized once for n joints and a task's `columns`
// solver columns (nv velocity coordinates). Indices a run over Θ₀ (the k
// stuck joints), s over Σ ⊆ Θ₀ (the ns sticking ones), e over the nullity.
struct MaximiserChoiceScratch {
  MaximiserChoiceScratch(int n, int columns, int nv)
      : qdd_star(n),
        sticking(n),
        K_sticking(n, n),
        null_basis(n, n),
        pivots(n),
        mu_first(n),
        lo(n),
        hi(n),
        curvature_direction(n),
        mu_chosen(n),
        target(n),
        z(n),
        z_target(n),
        qp(n),
        nu_direction(columns),
        tau_direction(nv),
        effort_first(n),
        effort_gradient(n, n),
        effort_at_reference(n),
        effort_curvature(n, n),
        effort_factor(n, n),
        bounded_directions(n, n),
        effort_slope(n),
        z_anchor(n),
        mu_pass(n) {}
  Eigen::VectorXd qdd_star;             // q̈*_Θ = q̈_Θ(0) − K_ΘΘ μ* (k)
  Eigen::VectorXi sticking;             // position in Θ₀ of each sticking joint (ns)
  Eigen::MatrixXd K_sticking;           // K_ΣΣ (ns × ns, lower triangle), factored in place by nearNullSpace
  Eigen::MatrixXd null_basis;           // N: orthonormal basis of null(K_ΣΣ) (ns × nullity)
  Eigen::VectorXi pivots;               // nearNullSpace's pivot exchanges
  Eigen::VectorXd mu_first;             // μ* on Σ as the maximiser returned it
  Eigen::VectorXd lo, hi;               // Λ on Σ, then the margin box
  Eigen::VectorXd curvature_direction;  // v ⟂ N when K_ΣΣ has rank one
  Eigen::VectorXd mu_chosen;            // the maximiser being moved (on Σ)
  Eigen::VectorXd target;               // the point it is moved closest to
  Eigen::VectorXd z, z_target;          // μ = μ_chosen + N z, and Nᵀ(target − μ_chosen)
  QpScratch qp;                         // of the least-distance solvers
  // EffortChange::Shared: min ‖c + B z‖² over the margin box, as the
  // least-distance problem min ‖w − w_t‖² with w = Lᵀz (z, z_target hold w, w_t).
  Eigen::VectorXd nu_direction;         // δν along one flat direction, per solver column
  Eigen::VectorXd tau_direction;        // τ_c of nu_direction (nv), the mimic joints' carried
  Eigen::VectorXd effort_first;         // the joints' τ_control at μ* as the QP returned it (n)
  Eigen::MatrixXd effort_gradient;      // B = ∂τ_control/∂z: n joints × nullity
  Eigen::VectorXd effort_at_reference;  // c: the joints' τ_control at μ_ref (n)
  Eigen::MatrixXd effort_curvature;     // BᵀB + ridge (nullity², lower triangle)
  Eigen::MatrixXd effort_factor;        // L, its lower Cholesky factor
  Eigen::MatrixXd bounded_directions;   // N L⁻ᵀ: how μ on Σ moves with w (ns × nullity)
  Eigen::VectorXd effort_slope;         // Bᵀc (nullity)
  Eigen::VectorXd z_anchor;             // the ridge's centre: the last pass's z (nullity)
  Eigen::VectorXd mu_pass;              // the last pass's pick on Σ (ns)
};

// Step 1: the sticking joints Σ (|q̈*_j| ≤ acc_tolerance) and the directions
// of K_ΣΣ along which g is flat to within acc_tolerance over the whole box.
// K (k × k), the QP's linear term qdd0_stuck (q̈_Θ(0)), its result mu and the
// box Λ = [lo, hi] are on Θ₀, as curvature_terms (the size of the terms each
// column of K is a sum of: a coupling at rounding of them is taken as zero).
// Returns the nullity (0: μ* is unique); fills
// s.sticking, s.null_basis and the count of sticking joints `ns`.
Eigen::Index flatDirections(const Eigen::Ref<const Eigen::MatrixXd>& K,
                            const Eigen::Ref<const Eigen::VectorXd>& qdd0_stuck,
                            const Eigen::Ref<const Eigen::VectorXd>& mu, const Eigen::Ref<const Eigen::VectorXd>& lo,
                            const Eigen::Ref<const Eigen::VectorXd>& hi,
                            const Eigen::Ref<const Eigen::VectorXd>& curvature_terms, double acc_tolerance,
                            MaximiserChoiceScratch& s, Eigen::Index& ns);

// Step 2, when flatDirections found a nullity > 0: (a) the smallest maximiser
// as a reference point μ_ref, (b) the one with the least ‖τ_control‖² of the
// joints within the margin box |μ_j| ≤ margin_limit_j:
//  * EffortChange::Own: min ‖h + μ‖² on Σ, where h_a = τ_control,a − μ*_a is
//    what the motor of stuck joint a would carry without friction (fixed on
//    the set);
//  * Shared: min ‖c + B z‖², B = s.effort_gradient (n_joints × nullity), c the
//    joints' τ_control at μ_ref from s.effort_first (at μ*);
//  * Fixed: (b) is skipped.
// Overwrites mu on Σ; returns whether the maximisers form more than a point
// (indeterminate). margin_limit and effort_offset are on Θ₀; mu_scale is the
// size below which two maximisers count as the same.
bool leastEffortMaximiser(const Eigen::Ref<const Eigen::VectorXd>& lo, const Eigen::Ref<const Eigen::VectorXd>& hi,
                          const Eigen::Ref<const Eigen::VectorXd>& margin_limit,
                          const Eigen::Ref<const Eigen::VectorXd>& effort_offset, Eigen::Index ns, Eigen::Index nullity,
                          EffortChange change, Eigen::Index joints, double mu_scale, int max_iterations,
                          Eigen::Ref<Eigen::VectorXd> mu, MaximiserChoiceScratch& s);

}  // namespace zwang::internal
