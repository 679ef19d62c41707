// The balance of acceleration energy at the base (Algorithm 1, line 25):
// ν = 𝓛⁻¹ r, with a damped least-squares fallback when 𝓛 is singular.
#pragma once

#include "zwang/workspace.hpp"

namespace zwang::internal {

// Solves 𝓛 ν = r for the symmetric positive semi-definite m×m matrix `L`
// (only its lower triangle is read; it is overwritten). Two ways, recorded in
// `by_eigen` so that balanceApply can reuse the factorisation:
//  * Cholesky 𝓛 = C Cᵀ (C lower, into `factor`) when 𝓛 is certified regular:
//    its Frobenius condition number ‖𝓛‖_F‖𝓛⁻¹‖_F, an upper bound of
//    λ_max/λ_min, is below 1/singular_threshold. The usual case, O(m³).
//  * otherwise eigenpairs (σ_k, e_k) by cyclic Jacobi (eigenvectors into
//    `factor`, eigenvalues into `lambda`) and the documented damping rule.
// `tmp` (m) is scratch. No allocation: all arguments are views of
// preallocated workspace memory.
CouplingDiagnostics solveBalance(Eigen::Ref<Eigen::MatrixXd> L, const Eigen::Ref<const Eigen::VectorXd>& r,
                                 Eigen::Ref<Eigen::VectorXd> nu, Eigen::Ref<Eigen::MatrixXd> factor,
                                 Eigen::Ref<Eigen::VectorXd> lambda, Eigen::Ref<Eigen::VectorXd> tmp,
                                 const BalanceOptions& options, bool& by_eigen);

// out = 𝓛⁺_λ r with the factorisation and damping of the last solveBalance
// (exactly 𝓛⁻¹ r when regular). `out` must not alias `r`.
void balanceApply(const Eigen::Ref<const Eigen::MatrixXd>& factor, const Eigen::Ref<const Eigen::VectorXd>& lambda,
                  bool by_eigen, double damping, const Eigen::Ref<const Eigen::VectorXd>& r,
                  Eigen::Ref<Eigen::VectorXd> out);

// The same for the columns of R at once (out: m × k, not aliasing R).
void balanceApplyColumns(const Eigen::Ref<const Eigen::MatrixXd>& factor, const Eigen::Ref<const Eigen::VectorXd>& lambda,
                         bool by_eigen, double damping, const Eigen::Ref<const Eigen::MatrixXd>& R,
                         Eigen::Ref<Eigen::MatrixXd> out);

// Lower Cholesky factor C (C Cᵀ = A) of the lower triangle of A; false when a
// pivot is not positive. C may not alias A.
bool cholesky(const Eigen::Ref<const Eigen::MatrixXd>& A, Eigen::Ref<Eigen::MatrixXd> C);

// X ← (C Cᵀ)⁻¹ X, every column of X (a vector is one column), with C from
// cholesky (its lower triangle is read).
void choleskySolveInPlace(const Eigen::Ref<const Eigen::MatrixXd>& C, Eigen::Ref<Eigen::MatrixXd> X);

// cholesky, plus a certificate that every eigenvalue of A is above `floor`:
// λ_min ≥ 1/trace(A⁻¹) = 1/‖C⁻¹‖_F² > floor. False when either fails (C then
// holds scratch). `tmp` (m) is scratch. O(m³/3).
bool certifiedCholesky(const Eigen::Ref<const Eigen::MatrixXd>& A, Eigen::Ref<Eigen::MatrixXd> C,
                       Eigen::Ref<Eigen::VectorXd> tmp, double floor);

// Symmetric eigen-decomposition A = V diag(λ) Vᵀ, no allocation: up to 8×8 by
// tridiagonalisation and QR in fixed-capacity storage, beyond by cyclic Jacobi
// rotations. A is overwritten.
void jacobiEigen(Eigen::Ref<Eigen::MatrixXd> A, Eigen::Ref<Eigen::VectorXd> lambda, Eigen::Ref<Eigen::MatrixXd> V);

}  // namespace zwang::internal
