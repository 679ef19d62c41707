// The balance of acceleration energy at the base (Algorithm 1, line 25):
// ν = 𝓛⁻¹ r, with a damped least-squares fallback when 𝓛 is singular.
#pragma once

#include "zwang/workspace.hpp"

namespace zwang::internal {

// Solves 𝓛 ν = r for the symmetric positive semi-definite m×m matrix `L`
// (overwritten) by a cyclic Jacobi eigen-decomposition into `V`, `lambda`;
// uses `tmp` (m) as scratch. No allocation: all arguments are views of
// preallocated workspace memory.
CouplingDiagnostics solveBalance(Eigen::Ref<Eigen::MatrixXd> L, const Eigen::Ref<const Eigen::VectorXd>& r,
                                 Eigen::Ref<Eigen::VectorXd> nu, Eigen::Ref<Eigen::MatrixXd> V,
                                 Eigen::Ref<Eigen::VectorXd> lambda, Eigen::Ref<Eigen::VectorXd> tmp,
                                 const BalanceOptions& options);

// Symmetric eigen-decomposition A = V diag(λ) Vᵀ by cyclic Jacobi rotations
// (accurate for small matrices, no allocation). A is overwritten.
void jacobiEigen(Eigen::Ref<Eigen::MatrixXd> A, Eigen::Ref<Eigen::VectorXd> lambda, Eigen::Ref<Eigen::MatrixXd> V);

}  // namespace zwang::internal
