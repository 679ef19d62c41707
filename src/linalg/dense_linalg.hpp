// Small dense symmetric linear algebra on preallocated views: the balance of
// line 25 and the friction maximiser use it. Nothing here allocates.
#pragma once

#include <Eigen/Core>

namespace zwang::internal {

// Lower Cholesky factor C (C Cᵀ = A) of the lower triangle of A; false when a
// pivot is not positive. C may not alias A.
bool cholesky(const Eigen::Ref<const Eigen::MatrixXd>& A, Eigen::Ref<Eigen::MatrixXd> C);

// X ← (C Cᵀ)⁻¹ X, every column of X (a vector is one column), with C from
// cholesky (its lower triangle and diagonal are read, nothing else).
void choleskySolveInPlace(const Eigen::Ref<const Eigen::MatrixXd>& C, Eigen::Ref<Eigen::MatrixXd> X);

// Symmetric eigen-decomposition A = V diag(λ) Vᵀ of the full symmetric A: up
// to 16×16 by tridiagonalisation and QR in fixed-capacity storage, beyond by
// cyclic Jacobi rotations. A is overwritten; the eigenvalues are not sorted.
void symmetricEigen(Eigen::Ref<Eigen::MatrixXd> A, Eigen::Ref<Eigen::VectorXd> lambda, Eigen::Ref<Eigen::MatrixXd> V);

}  // namespace zwang::internal
