// Small dense convex QPs for the friction maximiser (no allocation: all
// memory comes from a scratch sized once for n variables).
#pragma once

#include <Eigen/Core>

#include "internal/growing_cholesky.hpp"

namespace zwang::internal {

struct QpScratch {
  explicit QpScratch(int n = 0);
  Eigen::VectorXd lambda, g, p, t1, t2;  // n
  Eigen::VectorXd Px, Px_prev, Py;       // n, products with P (projected gradient)
  Eigen::MatrixXd Ct;                    // n × 2n, constraint rows as columns (least-distance QP)
  Eigen::VectorXd d;                     // 2n
  Eigen::VectorXi fixed;                 // n, 1 for a fixed variable (active set)
  Eigen::MatrixXd gram;                  // 2n × 2n, C Cᵀ (least-distance QP)
  Eigen::VectorXd Ca;                    // 2n
  Eigen::VectorXi active;                // 2n, working rows (least-distance QP)
  GrowingCholesky factor;                // of P_FF, F the free variables (active set)
  GrowingCholesky row_factor;            // of C_W C_Wᵀ, W the working rows (least-distance QP)
};

struct QpReport {
  int iterations = 0;
  double kkt_residual = 0.0;  // boxQpKktResidual at the result
  bool converged = false;
  bool unbounded = false;
  int unbounded_index = -1;   // a variable that runs off to an infinite bound
};

// min φ(x) = ½ xᵀ P x − cᵀ x  over lo ≤ x ≤ hi (entries may be ±∞, lo ≤ 0 ≤ hi),
// P symmetric positive SEMI-definite (k × k). x is the start (feasible) and the
// result. Primal active-set method whose free set F always keeps P_FF
// positive definite, with its Cholesky factor updated by one index per
// iteration (O(k²)): Newton steps on F; a variable whose Schur pivot is at
// rounding level (zero curvature relative to P_jj) is not added but moved,
// with F, along the zero-curvature direction straight to the next bound.
// `tolerance` is on the projected gradient (plus the rounding of ∇φ).
// Invariant under diagonal scaling of the variables: badly scaled P is fine.
// A variable on an infinite bound that travels 1e12 times the problem's scale
// max(1, largest finite bound, ‖c‖∞ / max(L, curvature_scale)), L ≥ λ_max(P),
// is reported unbounded (its curvature is rounding). `curvature_scale` is the
// size of the terms P was computed from, when the caller knows it: a P that
// is rounding throughout (every entry ≪ that) then counts as zero.
QpReport boxQpActiveSet(const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& c,
                        const Eigen::Ref<const Eigen::VectorXd>& lo, const Eigen::Ref<const Eigen::VectorXd>& hi,
                        Eigen::Ref<Eigen::VectorXd> x, QpScratch& s, int max_iterations, double tolerance,
                        double curvature_scale = 0.0);

// The same problem by accelerated projected gradient (FISTA with adaptive
// restart) in the metric of P's diagonal D (Jacobi preconditioning: the box
// stays a box), step 1/L̃ with L̃ ≥ λ_max(D^-1/2 P D^-1/2) (Gershgorin or
// trace bound); a linear problem (P = 0) goes to its vertex. Unbounded by the
// same rule as above.
QpReport boxQpProjectedGradient(const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& c,
                                const Eigen::Ref<const Eigen::VectorXd>& lo, const Eigen::Ref<const Eigen::VectorXd>& hi,
                                Eigen::Ref<Eigen::VectorXd> x, QpScratch& s, int max_iterations, double tolerance,
                                double curvature_scale = 0.0);

// The scale of the reach rule above: max(1, largest finite |bound|,
// ‖c‖∞ / max(lambda_max_bound, curvature_scale)).
double reachScale(const Eigen::Ref<const Eigen::VectorXd>& lo, const Eigen::Ref<const Eigen::VectorXd>& hi,
                  const Eigen::Ref<const Eigen::VectorXd>& c, double lambda_max_bound, double curvature_scale);

// The largest violation of the optimality conditions, in the units of ∇φ:
// |∇φ_j| of a free variable, ∇φ_j pointing into the room of one on a bound
// (x_j = lo_j needs ∇φ_j ≥ 0, x_j = hi_j needs ∇φ_j ≤ 0); zero exactly at a
// minimiser. Unlike ‖x − clamp(x − ∇φ)‖∞ it does not mix the units of x and ∇φ.
double boxQpKktResidual(const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& c,
                        const Eigen::Ref<const Eigen::VectorXd>& lo, const Eigen::Ref<const Eigen::VectorXd>& hi,
                        const Eigen::Ref<const Eigen::VectorXd>& x);

// Least-distance problem  min ½‖z − a‖²  s.t.  lo ≤ x0 + N z ≤ hi  (q = N.cols()
// unknowns, k = N.rows() two-sided rows), from the feasible start z (usually 0).
// Primal active set; z is the result. Used to pick among several friction
// maximisers μ* + null(K_ΘΘ).
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
                               const Eigen::Ref<const Eigen::VectorXd>& hi, Eigen::Ref<Eigen::VectorXd> mu, QpScratch& s);

}  // namespace zwang::internal
