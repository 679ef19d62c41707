// The balance of acceleration energy at the base (Algorithm 1, line 25):
// ν = 𝓛⁺ r, exact on the regular part of 𝓛, minimum-norm least squares across
// its null space, damped only in near-singular directions (docs/solver.md,
// "Singular tasks").
#pragma once

#include "zwang/workspace.hpp"

namespace zwang::internal {

// Solves 𝓛 ν = r for the symmetric positive semi-definite m×m matrix `L`
// (only its lower triangle is read; it is overwritten), m = L.rows(). Two ways,
// recorded in `f` so that balanceApply can reuse them:
//  * Cholesky 𝓛 = C Cᵀ when 𝓛 is certified regular: the Frobenius condition
//    number of the equilibrated 𝓛̃ = E 𝓛 E, an upper bound of σ̃_max/σ̃_min, is
//    below 1/singular_threshold. The usual case, O(m³/3).
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
