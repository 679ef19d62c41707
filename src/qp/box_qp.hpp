// Small dense convex QPs for the friction maximiser (no allocation: all
// memory comes from a scratch sized once for n variables).
//   src/qp/box_qp.cpp                    shared: the reach rule, the KKT residual
//   src/qp/box_qp_active_set.cpp         boxQpActiveSet (the default maximiser)
//   src/qp/box_qp_projected_gradient.cpp boxQpProjectedGradient
//   src/qp/least_distance.cpp            leastDistanceQp, leastDistanceOnHyperplane
#pragma once

#include <cmath>

#include <Eigen/Core>

#include "linalg/growing_cholesky.hpp"

namespace zwang::internal {

// The reach rule of both box-QP maximisers: a variable with an infinite bound
// that travels kReach times the problem's own scale (reachScale) is running
// off to infinity. Its curvature is rounding (a zero computed as a tiny
// number next to P's other entries), not physics: along a curvature κ the
// minimiser lies within ‖c‖∞/κ, so a rounding-level κ ~ ε·L ≈ 1e-16·L sends
// it to ~1e16 times the scale, while 1e12 still admits real curvatures down
// to 1e-12·L: four orders of margin above rounding. One constant, so that
// the two methods agree on what is unbounded.
inline constexpr double kReach = 1e12;

// Rounding of P and c relative to the size of the terms they were computed
// from (TermSizes), where the caller knows it. Measured over the friction
// tests (test_friction, test_friction_limits, test_floating_friction,
// test_mimic, test_singular), per stuck joint: a joint the task holds still
// has its entries of K_ΘΘ at 1e-17..1e-12 of their terms, once 1.2e-11
// (behind a balance of condition 3e5), and its q̈_j(0) at 1e-18..1e-13;
// real ones are above 1e-7 and 1e-5 there, and test_stress's extreme chains
// with damped singular tasks have real ones down to 1e-13 and 2.4e-12.
// kTermRounding: an entry of P (a curvature) this small next to its terms is
// zero; kSlopeRounding: likewise c_j, 10× above its largest rounding seen
// and 2.4× below the smallest real slope seen.
inline constexpr double kTermRounding = 1e-11;
inline constexpr double kSlopeRounding = 1e-12;

// Scratch of boxQpActiveSet (k ≤ n variables).
struct ActiveSetScratch {
  explicit ActiveSetScratch(int n);
  Eigen::VectorXd gradient;        // n, ∇φ = P x − c
  Eigen::VectorXd gradient_noise;  // n, a bound on the rounding of each ∇φ_j
  Eigen::VectorXd row_sums;        // n, Σ_l |P_jl| (for gradient_noise and λ_max(P))
  Eigen::VectorXi fixed;           // n, 1 for a variable not in F
  Eigen::VectorXi flat;            // n, 1 for a fixed variable on a flat direction (roundingSlope): not released
  Eigen::VectorXd step;            // n, the Newton step on F, in F's order
  Eigen::VectorXd direction;       // n, the zero-curvature direction on F, in F's order
  Eigen::VectorXd delta;           // n, the projected Newton step Δ (zero off F)
  Eigen::VectorXd P_delta;         // n, P Δ
  GrowingCholesky free_factor;     // of P_FF, F the free variables
};

// Scratch of boxQpProjectedGradient.
struct ProjectedGradientScratch {
  explicit ProjectedGradientScratch(int n);
  Eigen::VectorXd inverse_diagonal;       // n, D⁻¹ (the Jacobi metric)
  Eigen::VectorXd root_inverse_diagonal;  // n, D^-1/2 (for L̃)
  Eigen::VectorXd gradient;               // n, ∇φ at the extrapolated point y
  Eigen::VectorXd y;                      // n, the extrapolated point
  Eigen::VectorXd x_previous;             // n, the previous iterate
  Eigen::VectorXd x_change;               // n, x − x_previous (momentum and restart test)
  Eigen::VectorXd Px, Px_previous, Py;    // n, products with P
};

// Scratch of leastDistanceQp (k ≤ n joints, q ≤ n unknowns, ≤ 2n rows).
struct LeastDistanceScratch {
  explicit LeastDistanceScratch(int n);
  Eigen::MatrixXd rows;            // n × 2n, constraint row r as column r (contiguous)
  Eigen::VectorXd row_bounds;      // 2n, d_r of "row_r · z ≤ d_r"
  Eigen::MatrixXd gram;            // 2n × 2n, C Cᵀ, filled as rows join W
  Eigen::VectorXd row_dot_a;       // 2n, C a, filled as rows join W
  Eigen::VectorXi working;         // 2n, 1 for a row in W
  Eigen::VectorXd multipliers;     // n, λ_W
  Eigen::VectorXd step;            // n, towards the subproblem's minimum z'
  Eigen::VectorXd point;           // n, x0 + N z, per joint
  Eigen::VectorXd rate;            // n, N·step, per joint
  GrowingCholesky working_factor;  // of C_W C_Wᵀ
};

// Scratch of leastDistanceOnHyperplane.
struct HyperplaneScratch {
  explicit HyperplaneScratch(int n);
  Eigen::VectorXd breakpoints;      // 2n, distances |λ| where a term enters or leaves
  Eigen::VectorXi breakpoint_kind;  // 2n, 2i + (1 when term i becomes free there, 0 when it stops)
};

// All the solvers' scratch: callers construct it with n and pass it on.
struct QpScratch {
  explicit QpScratch(int n = 0);
  ActiveSetScratch active_set;
  ProjectedGradientScratch projected_gradient;
  LeastDistanceScratch least_distance;
  HyperplaneScratch hyperplane;
};

// What the caller knows of how P and c were computed: the size of the terms
// each entry is a sum of. A value at rounding level of its terms (a zero
// computed as a tiny number) is then told from a small real one, which the
// entries' own size cannot do: a column of P that is rounding throughout is
// tiny next to its terms, not next to itself. Zero, or an empty vector: not
// known (the entries' own size stands in).
struct TermSizes {
  double curvature = 0.0;                                      // the largest over P (the reach rule)
  Eigen::Map<const Eigen::VectorXd> curvature_of{nullptr, 0};  // per variable j: of P's row and column j
  Eigen::Map<const Eigen::VectorXd> slope_of{nullptr, 0};      // per variable j: of c_j
};

struct QpReport {
  int iterations = 0;
  double kkt_residual = 0.0;  // boxQpKktResidual at the result
  bool converged = false;
  bool unbounded = false;
  int unbounded_index = -1;  // a variable that runs off to an infinite bound
};

// min φ(x) = ½ xᵀ P x − cᵀ x  over lo ≤ x ≤ hi (entries may be ±∞, lo ≤ 0 ≤ hi),
// P symmetric positive SEMI-definite (k × k). x is the start (feasible) and the
// result. Primal active-set method whose free set F always keeps P_FF
// positive definite, with its Cholesky factor updated by one index per
// iteration (O(k²)): Newton steps on F; a variable whose Schur pivot is at
// rounding level (zero curvature relative to P_jj, and to the size of the
// terms of its column, terms.curvature_of, where given) is not added but
// moved, with F, along the zero-curvature direction straight to the next
// bound. Where there is none within reach, the direction is unbounded if its
// slope is above the rounding of its terms (roundingSlope), and flat (the
// variable stays) otherwise. `tolerance` is on the projected gradient (plus
// the rounding of ∇φ). Invariant under diagonal scaling of the variables:
// badly scaled P is fine. A variable on an infinite bound that travels
// kReach times the problem's scale max(1, largest finite bound, ‖c‖∞ /
// max(L, terms.curvature)), L ≥ λ_max(P), is reported unbounded (its
// curvature is rounding). terms.curvature is the size of the terms P was
// computed from, when the caller knows it: a P that is rounding throughout
// (every entry ≪ that) then counts as zero.
QpReport boxQpActiveSet(const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& c,
                        const Eigen::Ref<const Eigen::VectorXd>& lo, const Eigen::Ref<const Eigen::VectorXd>& hi,
                        Eigen::Ref<Eigen::VectorXd> x, QpScratch& s, int max_iterations, double tolerance,
                        const TermSizes& terms = {});

// The same problem by accelerated projected gradient (FISTA with adaptive
// restart) in the metric of P's diagonal D (Jacobi preconditioning: the box
// stays a box), step 1/L̃ with L̃ ≥ λ_max(D^-1/2 P D^-1/2) (lambdaMaxBound);
// a linear variable (P_jj rounding of its terms, where given) goes to its
// vertex first, and to the other bound whenever the others' motion turns its
// slope beyond the tolerance; a linear problem (P = 0) is solved so.
// Unbounded and flat by the same rules as above.
QpReport boxQpProjectedGradient(const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& c,
                                const Eigen::Ref<const Eigen::VectorXd>& lo,
                                const Eigen::Ref<const Eigen::VectorXd>& hi, Eigen::Ref<Eigen::VectorXd> x,
                                QpScratch& s, int max_iterations, double tolerance, const TermSizes& terms = {});

// An upper bound of λ_max(W P W), W = diag(w) (w = 1: of P itself), in O(k²):
// Gershgorin's (the largest absolute row sum), which holds for any symmetric
// matrix, or the trace where that is smaller and W P W can be positive
// semi-definite. P as computed is so only to rounding, and on a singular
// task far from it (K_ΘΘ behind a damped balance: a diagonal entry below
// zero, an off-diagonal entry above the trace); the trace of such a matrix
// bounds nothing and can be zero or negative, which would make P look like
// zero. So the trace counts only when every diagonal entry is ≥ 0 and no
// entry exceeds it (both necessary for semi-definiteness); the bound is then
// never below the largest |entry|.
double lambdaMaxBound(const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& w);
double lambdaMaxBound(const Eigen::Ref<const Eigen::MatrixXd>& P);

// The scale of the reach rule above: max(1, largest finite |bound|,
// ‖c‖∞ / max(lambda_max_bound, curvature_scale)).
double reachScale(const Eigen::Ref<const Eigen::VectorXd>& lo, const Eigen::Ref<const Eigen::VectorXd>& hi,
                  const Eigen::Ref<const Eigen::VectorXd>& c, double lambda_max_bound, double curvature_scale);

// The largest |∇φ_j| at x that is still rounding of the terms P and c were
// computed from (`terms`; 0 where not given): c_j's, kSlopeRounding·s_j,
// and (P x)_j's, kTermRounding·Σ_l √(t_j t_l)|x_l| (an entry P_jl taken to
// the scale √(t_j t_l), which a symmetric rescaling of the variables keeps).
// Along a direction of zero curvature a gradient this small is no slope: the
// direction is flat (any x_j is a minimiser), not unbounded.
double roundingSlope(const TermSizes& terms, const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::Index j);

// How far ∇φ_j = g violates optimality at x_j, in the units of ∇φ, whatever
// the units of x: a free variable's |g|, a bounded one's g pointing into its
// room (x_j = lo_j needs g ≥ 0, x_j = hi_j needs g ≤ 0); zero on a point box.
// Inline: it runs once per variable in the solvers' inner loops.
inline double kktViolation(double g, double x, double lo, double hi) {
  return lo == hi ? 0.0 : x <= lo ? -g : x >= hi ? g : std::abs(g);
}

// Does ∇φ_j = g point into x_j's room by more than its rounding `noise` plus
// `tolerance`, i.e. would moving x_j lower φ? (NaN counts as yes, so that a
// broken gradient is not mistaken for optimality.)
inline bool pointsIntoRoom(double g, double noise, double x, double lo, double hi, double tolerance) {
  return lo != hi && !(kktViolation(g, x, lo, hi) - noise <= tolerance);
}

// The largest violation of the optimality conditions, max_j kktViolation;
// zero exactly at a minimiser. Unlike ‖x − clamp(x − ∇φ)‖∞ it does not mix
// the units of x and ∇φ.
double boxQpKktResidual(const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& c,
                        const Eigen::Ref<const Eigen::VectorXd>& lo, const Eigen::Ref<const Eigen::VectorXd>& hi,
                        const Eigen::Ref<const Eigen::VectorXd>& x);

// Least-distance problem  min ½‖z − a‖²  s.t.  lo ≤ x0 + N z ≤ hi  (q = N.cols()
// unknowns, k = N.rows() two-sided rows), from the feasible start z (usually 0).
// Primal active set; z is the result; N need not be orthonormal. Used to pick
// among several friction maximisers μ* + null(K_ΘΘ).
QpReport leastDistanceQp(const Eigen::Ref<const Eigen::MatrixXd>& N, const Eigen::Ref<const Eigen::VectorXd>& a,
                         const Eigen::Ref<const Eigen::VectorXd>& x0, const Eigen::Ref<const Eigen::VectorXd>& lo,
                         const Eigen::Ref<const Eigen::VectorXd>& hi, Eigen::Ref<Eigen::VectorXd> z, QpScratch& s,
                         int max_iterations);

// The same kind of problem when the set is a hyperplane in the box:
//   min ½‖μ − t‖²  s.t.  vᵀμ = b,  lo ≤ μ ≤ hi   (v a unit vector, t finite),
// with a feasible point known to exist. Its dual is one monotone piecewise-
// linear equation in the multiplier λ, vᵀ clamp(t + λ v) = b, solved exactly
// by walking its breakpoints in order: O(n log n), against the primal active
// set's n − 1 unknowns and 2n rows. Writes μ = clamp(t + λ v); false (μ
// untouched) if no root is found, i.e. the hyperplane misses the box.
bool leastDistanceOnHyperplane(const Eigen::Ref<const Eigen::VectorXd>& v, double b,
                               const Eigen::Ref<const Eigen::VectorXd>& t, const Eigen::Ref<const Eigen::VectorXd>& lo,
                               const Eigen::Ref<const Eigen::VectorXd>& hi, Eigen::Ref<Eigen::VectorXd> mu,
                               QpScratch& s);

}  // namespace zwang::internal
