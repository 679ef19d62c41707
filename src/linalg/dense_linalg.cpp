#include "linalg/dense_linalg.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>

namespace zwang::internal {

namespace {
constexpr int kSmallEigen = 16;  // up to this size symmetricEigen uses a fixed-capacity QR solver
}  // namespace

void symmetricEigen(Eigen::Ref<Eigen::MatrixXd> A, Eigen::Ref<Eigen::VectorXd> lambda, Eigen::Ref<Eigen::MatrixXd> V) {
  const Eigen::Index m = A.rows();
  if (m <= kSmallEigen) {
    // Small matrices (a task's rows, a few stuck joints): Householder
    // tridiagonalisation and implicit QR in fixed-capacity storage, several
    // times cheaper than Jacobi sweeps here and still allocation-free.
    using Small = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kSmallEigen, kSmallEigen>;
    const Small symmetric = A.selfadjointView<Eigen::Lower>();
    const Eigen::SelfAdjointEigenSolver<Small> solver(symmetric);
    lambda = solver.eigenvalues();
    V = solver.eigenvectors();
    A.setZero();
    A.diagonal() = lambda;
    return;
  }
  V.setIdentity();
  const double scale = A.cwiseAbs().maxCoeff();
  for (int sweep = 0; sweep < 64 && scale > 0.0; ++sweep) {
    double off = 0.0;
    for (Eigen::Index p = 0; p < m; ++p)
      for (Eigen::Index q = p + 1; q < m; ++q) off = std::max(off, std::abs(A(p, q)));
    // Off-diagonal at rounding level of the largest entry: the eigenvalues are
    // as accurate as they can be (a tighter test can stall on rank-deficient
    // matrices until the sweep cap).
    if (off <= std::numeric_limits<double>::epsilon() * scale) break;
    for (Eigen::Index p = 0; p < m; ++p) {
      for (Eigen::Index q = p + 1; q < m; ++q) {
        const double apq = A(p, q);
        if (apq == 0.0) continue;
        // Rotation J in the (p, q) plane with (JᵀAJ)_pq = 0: t = tan of the
        // angle, the smaller root of t² + 2θt − 1 = 0, θ = (a_qq − a_pp)/(2a_pq).
        const double theta = (A(q, q) - A(p, p)) / (2.0 * apq);
        const double t = (theta >= 0.0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(1.0 + theta * theta));
        const double c = 1.0 / std::sqrt(1.0 + t * t), s = t * c;
        for (Eigen::Index k = 0; k < m; ++k) {  // A ← A J
          const double akp = A(k, p), akq = A(k, q);
          A(k, p) = c * akp - s * akq;
          A(k, q) = s * akp + c * akq;
        }
        for (Eigen::Index k = 0; k < m; ++k) {  // A ← Jᵀ A
          const double apk = A(p, k), aqk = A(q, k);
          A(p, k) = c * apk - s * aqk;
          A(q, k) = s * apk + c * aqk;
        }
        for (Eigen::Index k = 0; k < m; ++k) {  // V ← V J
          const double vkp = V(k, p), vkq = V(k, q);
          V(k, p) = c * vkp - s * vkq;
          V(k, q) = s * vkp + c * vkq;
        }
      }
    }
  }
  lambda = A.diagonal();
}

// Lower Cholesky factor C of the lower triangle of A (C Cᵀ = A); false when a
// pivot is not positive.
bool cholesky(const Eigen::Ref<const Eigen::MatrixXd>& A, Eigen::Ref<Eigen::MatrixXd> C) {
  const Eigen::Index m = A.rows();
  for (Eigen::Index j = 0; j < m; ++j) {
    double d = A(j, j);
    for (Eigen::Index k = 0; k < j; ++k) d -= C(j, k) * C(j, k);
    if (!(d > 0.0)) return false;
    const double cjj = std::sqrt(d);
    C(j, j) = cjj;
    for (Eigen::Index i = j + 1; i < m; ++i) {
      double s = A(i, j);
      for (Eigen::Index k = 0; k < j; ++k) s -= C(i, k) * C(j, k);
      C(i, j) = s / cjj;
    }
  }
  return true;
}

// X ← (C Cᵀ)⁻¹ X, forward then backward substitution, row by row: the
// columns share each row's reciprocal pivot, and their substitutions run
// side by side instead of one chain of divisions per column.
void choleskySolveInPlace(const Eigen::Ref<const Eigen::MatrixXd>& C, Eigen::Ref<Eigen::MatrixXd> X) {
  const Eigen::Index m = C.rows(), columns = X.cols();
  for (Eigen::Index i = 0; i < m; ++i) {
    const double inverse = 1.0 / C(i, i);
    for (Eigen::Index c = 0; c < columns; ++c) {
      double s = X(i, c);
      for (Eigen::Index l = 0; l < i; ++l) s -= C(i, l) * X(l, c);
      X(i, c) = s * inverse;
    }
  }
  for (Eigen::Index i = m - 1; i >= 0; --i) {
    const double inverse = 1.0 / C(i, i);
    for (Eigen::Index c = 0; c < columns; ++c) {
      double s = X(i, c);
      for (Eigen::Index l = i + 1; l < m; ++l) s -= C(l, i) * X(l, c);
      X(i, c) = s * inverse;
    }
  }
}

}  // namespace zwang::internal
