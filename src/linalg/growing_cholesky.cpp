// Cholesky factors that grow and shrink by one index, and a rank-revealing
// null space, for the friction maximiser. Against the textbook updates
// (Golub & Van Loan, Matrix Computations, §6.5):
//  * the factor is of a principal submatrix P_FF chosen index by index, so
//    "adding a column" is one forward substitution (schurPivot) whose Schur
//    pivot the caller judges first: a dependent index never enters;
//  * L is kept as U = Lᵀ so that the substitutions read contiguous columns;
//  * removal shifts U's columns left and folds the sub-diagonal back with one
//    Givens rotation per row (no refactorisation).
#include "linalg/growing_cholesky.hpp"

#include <cmath>
#include <utility>

namespace zwang::internal {

GrowingCholesky::GrowingCholesky(int capacity) : U_(capacity, capacity), index_(capacity), w_(capacity) {}

int GrowingCholesky::positionOf(int j) const {
  for (int a = 0; a < size_; ++a)
    if (index_[a] == j) return a;
  return -1;
}

// L is kept as U = Lᵀ (upper, column-major), so that L's rows, which the
// forward substitutions read, are contiguous columns of U.

double GrowingCholesky::schurPivot(const Eigen::Ref<const Eigen::MatrixXd>& P, int j) {
  double s = P(j, j);
  for (int a = 0; a < size_; ++a) {  // w = L⁻¹ P_Fj, forward substitution
    const double x = P(index_[a], j) - U_.col(a).head(a).dot(w_.head(a));
    w_[a] = x / U_(a, a);
    s -= w_[a] * w_[a];
  }
  return s;
}

void GrowingCholesky::append(int j, double pivot) {
  U_.col(size_).head(size_) = w_.head(size_);
  U_(size_, size_) = std::sqrt(pivot);
  index_[size_++] = j;
}

void GrowingCholesky::nullDirection(Eigen::Ref<Eigen::VectorXd> d_F) const {
  d_F.head(size_) = -w_.head(size_);  // Lᵀ d = U d = −w, backward by columns
  for (int a = size_ - 1; a >= 0; --a) {
    d_F[a] /= U_(a, a);
    d_F.head(a) -= d_F[a] * U_.col(a).head(a);
  }
}

void GrowingCholesky::remove(int position) {
  // Drop L's row (U's column); the rows below then stick out one column to
  // the right of the diagonal, which one Givens rotation per row folds back.
  for (int r = position; r + 1 < size_; ++r) {
    U_.col(r).head(r + 2) = U_.col(r + 1).head(r + 2);
    index_[r] = index_[r + 1];
  }
  --size_;
  for (int t = position; t < size_; ++t) {
    const double a = U_(t, t), b = U_(t + 1, t);
    const double r = std::hypot(a, b);
    const double c = a / r, s = b / r;
    for (int column = t; column < size_; ++column) {  // rotate L's columns t and t + 1 (U's rows)
      const double x = U_(t, column), y = U_(t + 1, column);
      U_(t, column) = c * x + s * y;
      U_(t + 1, column) = -s * x + c * y;
    }
    U_(t + 1, t) = 0.0;
  }
}

void GrowingCholesky::solveInPlace(Eigen::Ref<Eigen::VectorXd> x) const {
  for (int a = 0; a < size_; ++a) x[a] = (x[a] - U_.col(a).head(a).dot(x.head(a))) / U_(a, a);  // L y = x
  for (int a = size_ - 1; a >= 0; --a) {                                                        // U x = y, by columns
    x[a] /= U_(a, a);
    x.head(a) -= x[a] * U_.col(a).head(a);
  }
}

Eigen::Index nearNullSpace(Eigen::Ref<Eigen::MatrixXd> A, double floor, Eigen::Ref<Eigen::MatrixXd> N,
                           Eigen::Ref<Eigen::VectorXi> perm) {
  const Eigen::Index n = A.rows();
  for (Eigen::Index i = 0; i < n; ++i) perm[i] = static_cast<int>(i);
  Eigen::Index r = 0;
  for (; r < n; ++r) {
    Eigen::Index p = r;  // the largest remaining Schur diagonal leads
    for (Eigen::Index i = r + 1; i < n; ++i)
      if (A(i, i) > A(p, p)) p = i;
    if (!(A(p, p) > floor)) break;
    if (p != r) {
      A.row(r).swap(A.row(p));
      A.col(r).swap(A.col(p));
      std::swap(perm[r], perm[p]);
    }
    const double l = std::sqrt(A(r, r));
    A(r, r) = l;
    for (Eigen::Index i = r + 1; i < n; ++i) A(i, r) /= l;
    for (Eigen::Index j = r + 1; j < n; ++j)  // Schur complement, both triangles
      for (Eigen::Index i = r + 1; i < n; ++i) A(i, j) -= A(i, r) * A(j, r);
  }
  // The near null space is the orthogonal complement of the factored
  // columns L (n × r, pivoted order): for d ⟂ range(L), dᵀAd = d₂ᵀ S d₂ with
  // S the remaining Schur complement. Householder QR of L gives it directly
  // as the last n − r columns of Q = H₀…H_{r−1}: O(n·r·(n − r)), no
  // Gram–Schmidt. Each reflector H_j = I − 2 v vᵀ (‖v‖ = 1) is kept in
  // column j of L, rows j…n−1.
  const Eigen::Index nullity = n - r;
  if (nullity == 0) return 0;
  for (Eigen::Index j = 0; j < r; ++j) {
    for (Eigen::Index i = 0; i < j; ++i) A(i, j) = 0.0;  // L is lower trapezoidal (above: scratch)
    for (Eigen::Index h = 0; h < j; ++h) {               // the earlier reflectors act on column j
      double dot = 0.0;
      for (Eigen::Index i = h; i < n; ++i) dot += A(i, h) * A(i, j);
      for (Eigen::Index i = h; i < n; ++i) A(i, j) -= 2.0 * dot * A(i, h);
    }
    double norm2 = 0.0;
    for (Eigen::Index i = j; i < n; ++i) norm2 += A(i, j) * A(i, j);
    const double alpha = A(j, j) >= 0.0 ? std::sqrt(norm2) : -std::sqrt(norm2);
    A(j, j) += alpha;                                        // v = x + sign(x_j)‖x‖ e_j, then normalised
    const double v_norm = std::sqrt(2.0 * alpha * A(j, j));  // ‖v‖² = 2α(x_j + α)
    const double scale = v_norm > 0.0 ? 1.0 / v_norm : 0.0;
    for (Eigen::Index i = j; i < n; ++i) A(i, j) *= scale;
  }
  // N = Q [0; I], rows back in the original order: start from the unit
  // columns e_{r+e} and apply H_{r−1}, …, H₀.
  for (Eigen::Index e = 0; e < nullity; ++e) {
    auto d = N.col(e).head(n);
    d.setZero();
    d[perm[r + e]] = 1.0;
    for (Eigen::Index h = r - 1; h >= 0; --h) {
      double dot = 0.0;
      for (Eigen::Index i = h; i < n; ++i) dot += A(i, h) * d[perm[i]];
      for (Eigen::Index i = h; i < n; ++i) d[perm[i]] -= 2.0 * dot * A(i, h);
    }
  }
  return nullity;
}

}  // namespace zwang::internal
