// The balance of acceleration energy at the base (Algorithm 1, line 25):
// ν = 𝓛⁺ r, exact on the regular part of 𝓛, minimum-norm least squares across
// its null space, damped only in near-singular directions (docs/solver.md,
// "Singular tasks").
#pragma once

#include "zwang/workspace.hpp"

namespace zwang::internal {

// The factorisation of the last balance, kept so that further right-hand sides
// (the friction extension's unit torques) reuse it (src/dynamics/balance.cpp).
struct BalanceFactorisation {
  enum class Kind {
    Cholesky,         // 𝓛 = C Cᵀ, certified regular
    PivotedCholesky,  // Pᵀ 𝓛̃ P = C Cᵀ on its first `rank` pivots, the rest exact rank loss (factorByPivots)
    Eigen,            // eigenpairs of 𝓛̃
  };
  Kind kind = Kind::Cholesky;
  Eigen::MatrixXd factor;        // C (lower: with PivotedCholesky its first `rank` columns), or the eigenvectors V
  Eigen::VectorXi pivots;        // PivotedCholesky: the row of 𝓛 at each pivot position
  int rank = 0;                  // PivotedCholesky: the pivots taken
  double regular_condition = 1;  // κ̃_F of 𝓛̃ on the directions it solves exactly (∞ never: damped ones excluded)
  Eigen::VectorXd eigenvalues;    // σ̃_k (Eigen)
  Eigen::VectorXd gain;           // what each eigen-direction is multiplied by: 1/σ̃, damped, or 0
  Eigen::VectorXd equilibration;  // E_ii = 1/√𝓛_ii (1 on a row nothing moves)
  // Orthonormal basis of the directions E v_k with σ̃_k below singular_threshold
  // (the first `near_null_count` columns), and the weight of each in the
  // Euclidean projection: 1 at exact rank loss, falling to 0 at the threshold.
  Eigen::MatrixXd near_null_basis;
  Eigen::VectorXd near_null_weight;  // the weight of each of those directions (see near_null_basis)
  int near_null_count = 0;           // columns of near_null_basis in use
  Eigen::VectorXd work;              // scratch of balanceApply (V's coordinates)
};

// Solves 𝓛 ν = r for the symmetric positive semi-definite m×m matrix `L`
// (only its lower triangle is read; it is overwritten), m = L.rows(). Two ways,
// recorded in `f` so that balanceApply can reuse them:
//  * Cholesky 𝓛 = C Cᵀ when 𝓛 is certified regular: the Frobenius condition
//    number of the equilibrated 𝓛̃ = E 𝓛 E, an upper bound of σ̃_max/σ̃_min, is
//    below 1/singular_threshold. The usual case, O(m³/3).
//  * Cholesky of 𝓛̃ with diagonal pivoting when that proves exact rank loss
//    with a certified rest (the rows of feet on the ground beyond the
//    coordinates that move them): the eigenpairs' answer without them, O(m³/3).
//  * otherwise the eigenpairs of 𝓛̃, each direction exact, damped or dropped
//    by its eigenvalue (BalanceOptions), and the projections that make the
//    solution the minimum-norm least-squares one in the rows' own units.
// Fills the report's rows, rank, nu_unique, condition, damping and
// singular fields for the m rows of `L` (the caller counts out the mimic rows;
// the residual comes later, from the accelerations). No allocation: `f` was sized
// by the Workspace for the task's capacity.
BalanceReport solveBalance(Eigen::Ref<Eigen::MatrixXd> L, const Eigen::Ref<const Eigen::VectorXd>& r,
                           Eigen::Ref<Eigen::VectorXd> nu, BalanceFactorisation& f, const BalanceOptions& options);

// out = 𝓛⁺ r with the factorisation of the last solveBalance (m = r.size();
// exactly 𝓛⁻¹ r when regular). `out` must not alias `r`; `work` (m) is scratch.
void balanceApply(const BalanceFactorisation& f, const Eigen::Ref<const Eigen::VectorXd>& r,
                  Eigen::Ref<Eigen::VectorXd> out, Eigen::Ref<Eigen::VectorXd> work);

// The same for the columns of R at once (out: m × k, not aliasing R).
void balanceApplyColumns(const BalanceFactorisation& f, const Eigen::Ref<const Eigen::MatrixXd>& R,
                         Eigen::Ref<Eigen::MatrixXd> out, Eigen::Ref<Eigen::VectorXd> work);

}  // namespace zwang::internal
