// Independent references for static friction (docs/friction.md), built only on the
// dense KKT references (dense_reference.hpp, floating_reference.hpp) — no code of zwang's solver.
//
// Notation (docs/theory.md §3): Θ₀ = the stuck joints (k of them), W the k×n selector of
// their rows, f_j the breakaway torques. A stuck joint feels the torque −μ_j
// (τ_eff = τ − Wᵀμ, μ_j > 0 opposes positive motion); a moving joint the
// kinetic torque −f_c,j sign(q̇_j) − b_j q̇_j, added to τ as a feed-forward.
//   g(μ) = min_q̈ Z(q̈) + μᵀ W q̈  (over the task's constraints G q̈ = γ),
// Z the dense Gauss function with τ + τ_kinetic; μ* = argmax over the box.
//
// 1. bruteForceFriction enumerates every stick / slip+ / slip− pattern of the
//    stuck joints and solves each pattern's augmented KKT system:
//      [H  −Gᵀ −E_Sᵀ] [q̈ ]   [τ + τ_kin − Σ_{slip±} (±f_j) e_j − C]
//      [G   0    0  ] [ν ] = [γ                                   ]
//      [E_S 0    0  ] [λ ]   [0                                   ]
//    (E_S: rows e_jᵀ of the sticking joints). The stick multiplier λ_j is the
//    torque the joint's reaction adds, so μ_j = −λ_j. A pattern is kept when it
//    satisfies maximum dissipation: stick ⇒ |μ_j| ≤ f_j, slip+ ⇒ q̈_j ≥ 0,
//    slip− ⇒ q̈_j ≤ 0 (each a KKT point of the concave maximisation, hence a
//    maximiser).
//    Singular patterns: when [G; E_S] is rank deficient (a stick row the task
//    already implies, e.g. a fully constrained arm) the pattern is SKIPPED.
//    This loses nothing: the maximisers form a polytope (μ* + null K_ΘΘ) ∩ box
//    and null K_ΘΘ = {d : Wᵀd ∈ range Gᵀ}; at a vertex of that polytope no
//    direction supported on the strictly interior (sticking) joints stays in it,
//    i.e. the interior joints' rows are independent of G. Classifying the
//    vertex's bound joints as slip gives a regular, valid pattern. So a valid
//    regular pattern always exists (the task's G itself must have full row rank;
//    tests skip draws where it has not). Rank test: the eigenvalues of the
//    augmented coupling matrix [G; E_S] H⁻¹ [G; E_S]ᵀ, singular below
//    `singular_threshold`·λ_max.
//    Joint limits (docs/friction.md, "Joint position limits"): a stuck joint resting on its lower limit has
//    μ_j ∈ (−∞, f_j]: patterns stick (q̈_j = 0, μ_j ≤ f_j, no lower bound — a
//    μ_j below −f_j is the limit pushing back, "at limit") and slip+ (μ_j = f_j,
//    q̈_j ≥ 0); slip− (into the limit) does not exist. The upper limit mirrors
//    it. No valid pattern at all ⇒ `feasible = false` (the task drives a joint
//    into its limit: g is unbounded).
// 2. sampledFriction is the report's own method (chapter 5, "Implementation"):
//    g(μ) evaluated by a full dense forward-dynamics solve on a regular grid
//    over the box, k = 1 or 2; returns the grid maximiser.
// 3. bruteForceFloatingFriction: the enumeration of 1. on the dense
//    floating-base reference (floating_reference.hpp), whose rows may include
//    joint rows and contacts; leastEffortMaximiser: among the maximisers, the
//    least ‖τ_control‖ (docs/friction.md, "When μ* is not unique"), from the
//    valid patterns alone.
#pragma once

#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "support/chain_spec.hpp"
#include "support/dense_reference.hpp"
#include "support/floating_reference.hpp"
#include "support/random_chain.hpp"

namespace zwang::testing {

// The friction part of a problem, per dof (length spec.dof()).
struct FrictionSetup {
  std::vector<int> stuck;     // Θ₀, dof indices, ascending
  Eigen::VectorXd breakaway;  // f_j ≥ 0
  Eigen::VectorXd kinetic;    // f_c,j ≥ 0 (moving joints)
  Eigen::VectorXd viscous;    // b_j ≥ 0 (moving joints)
  // −1: stuck on its lower limit, +1: on its upper limit, 0: free. Empty = all free.
  Eigen::VectorXi limit_side;
};

// Friction data as the model would read it from the spec's URDF: breakaway =
// kinetic = <dynamics friction>, damping = <dynamics damping>; Θ₀ = joints
// with |q̇_j| ≤ velocity_tolerance; no limits. A mimic joint (resolved law
// q_m = a·q_l + b) is never in Θ₀ and its friction folds into its leader's:
// breakaway f_l + |a|·f_m, kinetic likewise, viscous b_l + a²·b_m, its own 0
// (the same motion: its torque does a times its work at the leader).
FrictionSetup frictionSetupFromSpec(const ChainSpec& spec, const Eigen::VectorXd& qd, double velocity_tolerance = 1e-6);
// That folding on any setup (per-dof values as given, e.g. a solve's
// overrides): each mimic joint's breakaway, kinetic and viscous friction onto
// its resolved leader (|a|, |a|, a²), its own set to 0, and it leaves Θ₀.
void foldMimicFriction(const ChainSpec& spec, FrictionSetup& setup);

// −f_c,j sign(q̇_j) − b_j q̇_j on the moving joints, 0 on the stuck ones.
Eigen::VectorXd kineticTorque(const FrictionSetup& setup, const Eigen::VectorXd& qd);

struct BruteForceOptions {
  double torque_tolerance = 1e-9;         // slack on |μ_j| ≤ f_j, × max(1, max f, max |μ|)
  double acceleration_tolerance = 1e-10;  // slack on the slip signs, × max(1, max |q̈|)
  double singular_threshold = 1e-10;      // λ_min/λ_max of the augmented coupling matrix
};

// One valid pattern: a maximiser of g (FrictionReference::valid).
struct FrictionPattern {
  std::string pattern;  // as FrictionReference::pattern
  Eigen::VectorXd qdd, mu, nu;
  Eigen::VectorXd tau_control;  // τ + the motors' Gᵀν (the leaders carrying their mimic joints')
  double gauss_dual = 0.0;
};

struct FrictionReference {
  bool feasible = false;        // some pattern is valid
  Eigen::VectorXd qdd;          // q̈*
  Eigen::VectorXd mu;           // a valid μ* (per dof, 0 off Θ₀)
  Eigen::VectorXd nu;           // the task's multipliers for that pattern
  Eigen::VectorXd tau_control;  // τ + the motors' Gᵀν for that pattern
  Eigen::VectorXd tau_kinetic;
  double gauss_dual = 0.0;  // g(μ*) = Z(q̈*) + μ*ᵀ W q̈*
  std::string pattern;  // one char per stuck joint: 's' stick, '+' slip+, '-' slip−, 'L' stick beyond f at a limit
  // Every valid pattern, the first (above) included. The maximisers of g are
  // the convex hull of their μ (every vertex of that polytope is a valid
  // pattern, see the file comment; every valid pattern is a maximiser).
  std::vector<FrictionPattern> valid;
  int patterns = 0;  // enumerated
  int valid_patterns = 0;
  int singular_patterns = 0;  // skipped as rank deficient
  // Spread among the valid patterns (uniqueness checks): q̈ and g must agree;
  // μ differs only when μ* is not unique (statically indeterminate).
  double qdd_spread = 0.0;    // max relativeError between valid patterns' q̈
  double gauss_spread = 0.0;  // max |Δg| / max(1, |g|)
  double mu_spread = 0.0;     // max |Δμ|
  // Some direction of μ on the sticking coordinates (q̈*_j = 0) moves no
  // acceleration: [G; E_Σ] is rank deficient (K_ΣΣ singular). Then μ* is not
  // unique unless the box stops that direction both ways — and where a stuck
  // joint rests on a limit the set of maximisers is unbounded, with one vertex
  // only: mu_spread = 0 does not make μ* unique then.
  bool pinned = false;
};

FrictionReference bruteForceFriction(const ChainSpec& spec, const DynamicsInput& input, const FrictionSetup& setup,
                                     const BruteForceOptions& options = {});

// The enumeration itself, on any dense system in n generalized coordinates x:
//   H ẍ + C = τ + Gᵀν − Σ_{j ∈ Θ₀} μ_j e_j,   G ẍ = γ,
//   Z(ẍ) = Z(0) + ½ ẍᵀHẍ + (C − τ)ᵀẍ   (every dense Gauss function here is this quadratic),
// τ with the kinetic torques in it. Stuck coordinates, breakaway torques and
// limit sides per coordinate (a floating base's coordinates are simply never
// stuck). tau_control = tau_motor + Gᵀ diag(motor) ν, then each mimic pair
// (joint, leader, multiplier) folded onto its leader.
struct FrictionSystem {
  Eigen::MatrixXd H, G;
  Eigen::VectorXd C, tau, gamma;
  double gauss_at_rest = 0.0;        // Z(0)
  std::vector<int> stuck;            // coordinates, ascending
  Eigen::VectorXd breakaway;         // per coordinate
  Eigen::VectorXi limit_side;        // per coordinate (−1 lower, +1 upper, 0 none), or empty
  Eigen::VectorXd tau_motor;         // the user's τ (without the kinetic torques), for tau_control
  Eigen::VectorXd motor;             // per row of G: 1 when the motors carry it, 0 for a contact
  std::vector<MimicLaw> mimic_laws;  // coordinates (a floating base's offset added)
};
FrictionReference bruteForceFriction(const FrictionSystem& system, const BruteForceOptions& options = {});

// The same brute force on a floating base (floating_reference.hpp): the system
// is the dense floating-base one, nv coordinates with the base's first
// (unactuated and frictionless: never stuck); `setup` is per joint (spec.dof()
// entries, as for the fixed base). qdd and tau_control have nv entries, mu one
// per joint, nu one per row of floatingDynamics (the input's rows, joint rows
// and contacts included, then the mimic rows); a contact's force is not in
// tau_control (ConstraintInput::contact).
FrictionReference bruteForceFloatingFriction(const ChainSpec& spec, const FloatingBase& base,
                                             const FloatingInput& input, const FrictionSetup& setup,
                                             const BruteForceOptions& options = {});

// The least-effort maximiser (docs/friction.md, "When μ* is not unique": the
// maximiser with the least ‖τ_control‖ of the joints). On the maximisers q̈*
// is fixed and ν is affine in μ (G of full row rank), so τ_control is affine
// there and the set of its values is the convex hull of the valid patterns'
// τ_control: the answer is the point of least norm in that hull (Wolfe's
// algorithm, exact up to rounding), unique even where μ is not. Only the
// coordinates from `first` on count (a floating base's nb are not motor
// effort: pass nb). Returns them, and one μ that gives them.
struct LeastEffort {
  Eigen::VectorXd tau_control;  // the coordinates from `first` on
  Eigen::VectorXd mu;
  int distinct_points = 0;  // the hull's points after merging repeats
};
LeastEffort leastEffortMaximiser(const FrictionReference& reference, Eigen::Index first = 0);
// The smallest maximiser: the point of least ‖μ‖ in the hull of the valid
// patterns' μ (the maximisers' set, as above), and its τ_control from `first`
// on. The library's choice where τ_control cannot change on the set (every row
// a contact: docs/friction.md, "When μ* is not unique", Fixed).
LeastEffort leastNormMaximiser(const FrictionReference& reference, Eigen::Index first = 0);
// q̈(μ) and g(μ) for a given μ (per dof; entries off Θ₀ ignored) by one full
// dense solve with τ + τ_kinetic − Wᵀμ.
struct FrictionDual {
  Eigen::VectorXd qdd;
  double g = 0.0;
};
FrictionDual denseFrictionDual(const ChainSpec& spec, const DynamicsInput& input, const FrictionSetup& setup,
                               const Eigen::VectorXd& mu);

// K = ∂q̈/∂τ of the constrained dynamics (n×n, symmetric PSD), from the dense
// KKT with unit right-hand sides; q̈(μ) = q̈(0) − K Wᵀ μ.
Eigen::MatrixXd denseConstrainedInverseInertia(const ChainSpec& spec, const DynamicsInput& input);

struct SampledFriction {
  Eigen::VectorXd mu;       // grid maximiser, per dof (0 off Θ₀)
  Eigen::VectorXd qdd;      // q̈ at it
  double g = 0.0;           // g there
  Eigen::VectorXd spacing;  // grid spacing per stuck joint (k)
  int evaluations = 0;
};
// `points` samples per axis (k = 1 or 2; throws otherwise), endpoints included.
// Each sample is one forward-dynamics solve of the dense KKT system (factorised
// once: only the right-hand side changes with μ) and g = Z(q̈) + μᵀWq̈.
SampledFriction sampledFriction(const ChainSpec& spec, const DynamicsInput& input, const FrictionSetup& setup,
                                int points);

// A random friction problem: a chain with min_dof..max_dof moving joints
// (randomChain), a problem with 0..min(max_rows, dof) constraint rows (randomProblem),
// q strictly inside the position limits (at least 5 % of the range away),
// 1..max_stuck stuck joints with q̇_j = 0 exactly and every other joint moving
// with 0.1 ≤ |q̇_j| ≤ 2. Friction from the spec (breakaway 0–5, kinetic =
// breakaway, damping 0–1).
struct FrictionDraw {
  ChainSpec spec;
  DynamicsInput input;
  FrictionSetup setup;
};
FrictionDraw randomFrictionDraw(std::mt19937_64& rng, int min_dof = 2, int max_dof = 7, int min_stuck = 1,
                                int max_stuck = 5, int max_rows = 6);
// The same on a random tree (randomTree), with constraints relative to
// another link with the given probability.
FrictionDraw randomTreeFrictionDraw(std::mt19937_64& rng, int min_dof, int max_dof, int max_stuck, int max_rows,
                                    double relative_probability);

// The same on a random tree with mimic joints (addRandomMimics, drawn after
// the tree): the stuck joints are independent ones, the mimic joints' q and q̇
// follow their leaders, the setup folds their friction into the leaders'
// (frictionSetupFromSpec); rows at most the independent joints.
FrictionDraw randomTreeMimicFrictionDraw(std::mt19937_64& rng, int min_dof, int max_dof, int max_stuck, int max_rows,
                                         double relative_probability, const RandomMimicOptions& mimics = {});

// The task itself is well posed (as test_dense filters): H and the coupling
// matrix conditioned below max_condition and every constraint row independent
// and reachable (smallest singular value of G ≥ 1e-6).
bool wellPosed(const DenseResult& dense, int rows, double max_condition = 1e6);

}  // namespace zwang::testing
