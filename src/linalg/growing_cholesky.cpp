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

namespace {

// The two kernels of the pivoted factor and its reflectors, on contiguous
// column segments of length `length`: plain loops that the compiler
// vectorises, without the per-call set-up of Eigen's expressions, which
// outweighs the arithmetic at these lengths (up to a few tens). The dot
// product keeps two partial sums (even and odd entries) so that the pairs go
// through the vector unit together: one sequential sum cannot be reordered.
double dotSegment(const double* x, const double* y, Eigen::Index length) {
  double even = 0.0, odd = 0.0;
  Eigen::Index i = 0;
  for (; i + 1 < length; i += 2) {
    even += x[i] * y[i];
    odd += x[i + 1] * y[i + 1];
  }
  if (i < length) even += x[i] * y[i];
  return even + odd;
}

// y ← y − a·x.
void subtractScaled(double a, const double* x, double* y, Eigen::Index length) {
  for (Eigen::Index i = 0; i < length; ++i) y[i] -= a * x[i];
}

// Symmetric pivoting of the lower triangle only: rows/columns r and p > r of
// the trailing Schur complement trade places, and with them rows r and p of
// the factored columns 0…r−1 (LAPACK's dpstrf does the same exchanges).
void swapLowerSymmetric(Eigen::Ref<Eigen::MatrixXd> A, Eigen::Index r, Eigen::Index p) {
  const Eigen::Index n = A.rows();
  A.row(r).head(r).swap(A.row(p).head(r));
  std::swap(A(r, r), A(p, p));
  for (Eigen::Index i = r + 1; i < p; ++i) std::swap(A(i, r), A(p, i));
  A.col(r).tail(n - p - 1).swap(A.col(p).tail(n - p - 1));
}

// Diagonally pivoted Cholesky of the lower triangle of A, in place, until every
// remaining Schur-complement diagonal is at most `floor`; returns the rank r.
// pivot_row[t] is the row step t swapped in. Only the lower triangle is read
// or written: the Schur update is one contiguous column segment per column.
Eigen::Index pivotedCholesky(Eigen::Ref<Eigen::MatrixXd> A, double floor, Eigen::Ref<Eigen::VectorXi> pivot_row) {
  const Eigen::Index n = A.rows();
  Eigen::Index r = 0;
  for (; r < n; ++r) {
    Eigen::Index p = r;  // the largest remaining Schur diagonal leads
    for (Eigen::Index i = r + 1; i < n; ++i)
      if (A(i, i) > A(p, p)) p = i;
    if (!(A(p, p) > floor)) break;
    pivot_row[r] = static_cast<int>(p);
    if (p != r) swapLowerSymmetric(A, r, p);
    const double l = std::sqrt(A(r, r));
    A(r, r) = l;
    A.col(r).tail(n - r - 1) /= l;
    const double* l_column = &A(0, r);
    for (Eigen::Index j = r + 1; j < n; ++j) subtractScaled(l_column[j], l_column + j, &A(j, j), n - j);
  }
  return r;
}

// Householder QR of the factored columns L (n × r, lower trapezoidal): each
// reflector H_j = I − 2 v vᵀ (‖v‖ = 1) is kept in column j of A, rows j…n−1.
void householderOfFactor(Eigen::Ref<Eigen::MatrixXd> A, Eigen::Index r) {
  const Eigen::Index n = A.rows();
  for (Eigen::Index j = 0; j < r; ++j) {
    auto column = A.col(j);
    column.head(j).setZero();               // L is lower trapezoidal (above: scratch)
    for (Eigen::Index h = 0; h < j; ++h) {  // the earlier reflectors act on column j
      const double* v = &A(h, h);
      subtractScaled(2.0 * dotSegment(v, &column[h], n - h), v, &column[h], n - h);
    }
    const double norm = column.tail(n - j).norm();
    const double alpha = column[j] >= 0.0 ? norm : -norm;
    column[j] += alpha;                                        // v = x + sign(x_j)‖x‖ e_j, then normalised
    const double v_norm = std::sqrt(2.0 * alpha * column[j]);  // ‖v‖² = 2α(x_j + α)
    column.tail(n - j) *= v_norm > 0.0 ? 1.0 / v_norm : 0.0;
  }
}

// N = Q [0; I] from the reflectors householderOfFactor left in A: the unit
// columns e_{r+e} with H_{r−1}, …, H₀ applied.
void complementByReflectors(const Eigen::Ref<const Eigen::MatrixXd>& A, Eigen::Index r, Eigen::Ref<Eigen::MatrixXd> N) {
  const Eigen::Index n = A.rows();
  for (Eigen::Index e = 0; e < n - r; ++e) {
    double* d = &N(0, e);
    for (Eigen::Index i = 0; i < n; ++i) d[i] = 0.0;
    d[r + e] = 1.0;
    for (Eigen::Index h = r - 1; h >= 0; --h) {
      const double* v = A.data() + h + h * A.outerStride();
      subtractScaled(2.0 * dotSegment(v, d + h, n - h), v, d + h, n - h);
    }
  }
}

// The complement of the factored columns L = [L₁₁; L₂₁] (n × r, pivoted
// order) is null(Lᵀ): the columns [−L₁₁⁻ᵀ L₂₁ᵀ; I]. Column e of N gets the
// one that moves the remaining index r + e: back substitution with L₁₁ᵀ,
// whose rows are L's contiguous columns.
void complementOfFactor(const Eigen::Ref<const Eigen::MatrixXd>& A, Eigen::Index r, Eigen::Ref<Eigen::MatrixXd> N) {
  const Eigen::Index n = A.rows();
  for (Eigen::Index e = 0; e < n - r; ++e) {
    double* d = &N(0, e);
    for (Eigen::Index i = r; i < n; ++i) d[i] = 0.0;
    d[r + e] = 1.0;
    for (Eigen::Index a = r - 1; a >= 0; --a)  // L₁₁ᵀ x = −L₂₁ᵀ e
      d[a] = -(A(r + e, a) + dotSegment(A.col(a).data() + a + 1, d + a + 1, r - a - 1)) / A(a, a);
  }
}

// Modified Gram–Schmidt on the first `count` columns of N (n rows), twice:
// the second pass removes what rounding left of the first's projections, so
// NᵀN = I to rounding (Kahan's "twice is enough"). The columns are
// independent (each has its own unit entry below L₁₁): no norm is zero.
void orthonormaliseTwice(Eigen::Ref<Eigen::MatrixXd> N, Eigen::Index count) {
  const Eigen::Index n = N.rows();
  for (Eigen::Index e = 0; e < count; ++e) {
    double* d = &N(0, e);
    for (int pass = 0; pass < 2; ++pass)
      for (Eigen::Index f = 0; f < e; ++f) {
        const double* q = &N(0, f);
        subtractScaled(dotSegment(q, d, n), q, d, n);
      }
    const double inverse_norm = 1.0 / std::sqrt(dotSegment(d, d, n));
    for (Eigen::Index i = 0; i < n; ++i) d[i] *= inverse_norm;
  }
}

}  // namespace

Eigen::Index nearNullSpace(Eigen::Ref<Eigen::MatrixXd> A, double floor, Eigen::Ref<Eigen::MatrixXd> N,
                           Eigen::Ref<Eigen::VectorXi> pivot_row) {
  const Eigen::Index n = A.rows();
  const Eigen::Index r = pivotedCholesky(A, floor, pivot_row);
  // The near null space is the orthogonal complement of the factored
  // columns L (n × r, pivoted order): for d ⟂ range(L), dᵀAd = d₂ᵀ S d₂ with
  // S the remaining Schur complement. A triangular solve with L₁₁ gives a
  // basis of it, Gram–Schmidt an orthonormal one: O(r²·(n − r) + n·(n − r)²),
  // cheaper than a Householder QR of L, O(n·r²), when most columns are
  // factored (a humanoid with every joint stuck).
  const Eigen::Index nullity = n - r;
  if (nullity == 0) return 0;
  // Few factored columns and many null directions (a 7-joint arm holding a
  // 6-D pose: r = 1, nullity 6) favour the QR, whose reflectors cost
  // O(n·r²) and give orthonormal columns in O(n·r·nullity); the triangular
  // solve then Gram–Schmidt costs O(r²·nullity + n·nullity²), dearer in that
  // case. Both span the same subspace; the leading terms decide.
  if (n * r * (r + nullity) <= nullity * (r * r + 2 * n * nullity)) {
    householderOfFactor(A, r);
    complementByReflectors(A, r, N);
  } else {
    complementOfFactor(A, r, N);
    orthonormaliseTwice(N, nullity);
  }
  // Rows back in the original order: the pivot exchanges undone, last first.
  for (Eigen::Index t = r - 1; t >= 0; --t)
    if (pivot_row[t] != t) N.row(t).head(nullity).swap(N.row(pivot_row[t]).head(nullity));
  return nullity;
}

}  // namespace zwang::internal
