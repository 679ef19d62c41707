// The balance of line 25: ν = 𝓛⁺ r (docs/solver.md, "Singular tasks").
//
// How it differs from the report, which inverts 𝓛 and assumes it regular:
//  * regularity is judged on the equilibrated 𝓛̃ = E 𝓛 E, E = diag(1/√𝓛_ii):
//    𝓛's rows mix metres and radians, heavy and light links, so its raw
//    eigenvalues differ by orders of magnitude in perfectly regular tasks; 𝓛̃
//    has a unit diagonal and eigenvalues σ̃ in [0, m], and a small σ̃ means a
//    direction the robot really cannot (or can hardly) move;
//  * a regular 𝓛 (certified: Frobenius condition of 𝓛̃ below
//    1/singular_threshold) is solved by Cholesky of 𝓛 itself, exactly as the
//    report's inverse would be;
//  * a singular 𝓛 whose only loss is exact rank loss beside a certified
//    regular part (feet on the ground with more rows than the coordinates
//    that move them) is solved by a Cholesky of 𝓛̃ with diagonal pivoting
//    (factorByPivots): the same classification and ν as the eigenpairs', at
//    the cost of a Cholesky;
//  * any other singular 𝓛 is solved on the eigenpairs of 𝓛̃: exact along regular
//    directions; across the exact null space the minimum-norm least-squares
//    solution in the rows' own units: r's component along null(𝓛) is what no
//    force can meet (dropped before the solve), and ν gets no component along
//    null(𝓛) (removed after it); near-singular directions ramp between the
//    two (bounded, and continuous in σ̃: factorByEigen).
#include "dynamics/balance.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "linalg/dense_linalg.hpp"

namespace zwang::internal {

namespace {

// Loops over a compile-time size of at most 6, unrolled whole: constant
// offsets instead of loop counters on these short triangular loops.
#if defined(__GNUC__)
#define ZWANG_UNROLL _Pragma("GCC unroll 8")
#else
#define ZWANG_UNROLL
#endif

// ‖E A E‖_F of a symmetric matrix from its lower triangle, E = diag(e).
double equilibratedFrobenius(const Eigen::Ref<const Eigen::MatrixXd>& A, const Eigen::Ref<const Eigen::VectorXd>& e) {
  double s = 0.0;
  for (Eigen::Index j = 0; j < A.cols(); ++j) {
    const double ajj = A(j, j) * e[j] * e[j];
    s += ajj * ajj;
    for (Eigen::Index i = j + 1; i < A.rows(); ++i) {
      const double aij = A(i, j) * e[i] * e[j];
      s += 2.0 * aij * aij;
    }
  }
  return std::sqrt(s);
}

// ‖(E C Cᵀ E)⁻¹‖_F = ‖E⁻¹ Wᵀ W E⁻¹‖_F with W = C⁻¹ (lower). W overwrites the
// strict upper triangle of C transposed, so C itself stays usable: W(i, j) for
// i ≥ j is kept in C(j, i) for i > j and in `diag`(i) for i = j.
double equilibratedInverseFrobenius(Eigen::Ref<Eigen::MatrixXd> C, const Eigen::Ref<const Eigen::VectorXd>& e,
                                    Eigen::Ref<Eigen::VectorXd> diag) {
  const Eigen::Index m = C.rows();
  auto W = [&](Eigen::Index i, Eigen::Index j) -> double& { return i == j ? diag[i] : C(j, i); };
  for (Eigen::Index j = 0; j < m; ++j) {
    W(j, j) = 1.0 / C(j, j);
    for (Eigen::Index i = j + 1; i < m; ++i) {  // row i of C W = e_i: Σ_k C(i,k) W(k,j) = 0
      double s = 0.0;
      for (Eigen::Index k = j; k < i; ++k) s += C(i, k) * W(k, j);
      W(i, j) = -s / C(i, i);
    }
  }
  double s = 0.0;  // (WᵀW)(a, b) = Σ_{k ≥ max(a,b)} W(k,a) W(k,b)
  for (Eigen::Index a = 0; a < m; ++a)
    for (Eigen::Index b = a; b < m; ++b) {
      double p = 0.0;
      for (Eigen::Index k = b; k < m; ++k) p += W(k, a) * W(k, b);
      p /= e[a] * e[b];
      s += (a == b ? 1.0 : 2.0) * p * p;
    }
  return std::sqrt(s);
}

// The fast path for a task of M ≤ 6 rows in fixed-size arithmetic: Cholesky,
// the certificate κ̃_F·threshold < 1 on the equilibrated matrix, ν = 𝓛⁻¹ r and
// the factor for later right-hand sides. False (nothing written but `factor`)
// when not certified.
template <int M>
bool certifiedSolveFixed(const Eigen::Ref<const Eigen::MatrixXd>& L, const Eigen::Ref<const Eigen::VectorXd>& r,
                         Eigen::Ref<Eigen::VectorXd> nu, Eigen::Ref<Eigen::MatrixXd> factor, double threshold,
                         double& kappa) {
  using MatM = Eigen::Matrix<double, M, M>;
  // Divisions are slow and sit on the substitutions' dependency chains: each
  // pivot is inverted once and the rest multiply.
  const MatM Lf = L;  // fixed size: constant offsets in the unrolled loops below (the upper triangle unused)
  const Eigen::Matrix<double, M, 1> diagonal = Lf.diagonal();
  MatM C = MatM::Zero();  // 𝓛 = C Cᵀ
  Eigen::Matrix<double, M, 1> inverse_pivot, inverse_diagonal;
  ZWANG_UNROLL
  for (int j = 0; j < M; ++j) {
    double d = Lf(j, j);
    ZWANG_UNROLL
    for (int k = 0; k < j; ++k) d -= C(j, k) * C(j, k);
    if (!(d > 0.0)) return false;
    C(j, j) = std::sqrt(d);
    inverse_pivot[j] = 1.0 / C(j, j);
    inverse_diagonal[j] = 1.0 / Lf(j, j);  // L_jj ≥ d > 0
    ZWANG_UNROLL
    for (int i = j + 1; i < M; ++i) {
      double x = Lf(i, j);
      ZWANG_UNROLL
      for (int k = 0; k < j; ++k) x -= C(i, k) * C(j, k);
      C(i, j) = x * inverse_pivot[j];
    }
  }
  // κ̃_F² = ‖E𝓛E‖_F² ‖E⁻¹𝓛⁻¹E⁻¹‖_F² with E² = diag(1/𝓛_jj): no square roots needed.
  double norm2 = 0.0;
  ZWANG_UNROLL
  for (int j = 0; j < M; ++j) {
    norm2 += 1.0;  // (E𝓛E)_jj = 1
    ZWANG_UNROLL
    for (int i = j + 1; i < M; ++i) norm2 += 2.0 * Lf(i, j) * Lf(i, j) * inverse_diagonal[i] * inverse_diagonal[j];
  }
  MatM W = MatM::Zero();  // C⁻¹, lower
  ZWANG_UNROLL
  for (int j = 0; j < M; ++j) {
    W(j, j) = inverse_pivot[j];
    ZWANG_UNROLL
    for (int i = j + 1; i < M; ++i) {
      double x = 0.0;
      ZWANG_UNROLL
      for (int k = j; k < i; ++k) x += C(i, k) * W(k, j);
      W(i, j) = -x * inverse_pivot[i];
    }
  }
  const MatM inverse = W.transpose() * W;  // 𝓛⁻¹, for κ̃_F only
  // ‖E⁻¹𝓛⁻¹E⁻¹‖_F² = Σ_ij (𝓛⁻¹)_ij² 𝓛_ii 𝓛_jj, as one vectorised product.
  const double inverse_norm2 = diagonal.dot(inverse.cwiseAbs2() * diagonal);
  kappa = std::sqrt(norm2 * inverse_norm2);
  if (!(std::isfinite(kappa) && kappa * threshold < 1.0)) return false;
  factor = C;
  // ν by forward and backward substitution with C (more accurate than the
  // explicit inverse when 𝓛 is ill-conditioned).
  Eigen::Matrix<double, M, 1> x = r;
  ZWANG_UNROLL
  for (int i = 0; i < M; ++i) {
    ZWANG_UNROLL
    for (int k = 0; k < i; ++k) x[i] -= C(i, k) * x[k];
    x[i] *= inverse_pivot[i];
  }
  ZWANG_UNROLL
  for (int i = M - 1; i >= 0; --i) {
    ZWANG_UNROLL
    for (int k = i + 1; k < M; ++k) x[i] -= C(k, i) * x[k];
    x[i] *= inverse_pivot[i];
  }
  nu = x;
  return true;
}

// Cholesky and the certificate for any m (fixed-size code up to 6 rows).
bool certifiedSolve(const Eigen::Ref<const Eigen::MatrixXd>& L, const Eigen::Ref<const Eigen::VectorXd>& r,
                    Eigen::Ref<Eigen::VectorXd> nu, BalanceFactorisation& f, double threshold, double& kappa) {
  const Eigen::Index m = L.rows();
  auto factor = f.factor.topLeftCorner(m, m);
  switch (m) {
    case 1:  // κ̃_F = 1: regular whenever positive
      if (!(L(0, 0) > 0.0)) return false;
      kappa = 1.0;
      factor(0, 0) = std::sqrt(L(0, 0));
      nu[0] = r[0] / L(0, 0);
      return true;
    case 2: return certifiedSolveFixed<2>(L, r, nu, factor, threshold, kappa);
    case 3: return certifiedSolveFixed<3>(L, r, nu, factor, threshold, kappa);
    case 4: return certifiedSolveFixed<4>(L, r, nu, factor, threshold, kappa);
    case 5: return certifiedSolveFixed<5>(L, r, nu, factor, threshold, kappa);
    case 6: return certifiedSolveFixed<6>(L, r, nu, factor, threshold, kappa);
    default: break;
  }
  if (!cholesky(L, factor)) return false;
  // A pivot of 𝓛̃'s factor at most the threshold fails the certificate before ‖𝓛̃⁻¹‖_F is formed: the j-th pivot
  // is 1/(B⁻¹)_jj of the leading j × j block B, at least 1/(𝓛̃⁻¹)_jj, so κ̃_F ≥ ‖𝓛̃‖_F/pivot ≥ 1/pivot.
  for (Eigen::Index j = 0; j < m; ++j)
    if (factor(j, j) * factor(j, j) <= threshold * L(j, j)) return false;
  auto e = f.equilibration.head(m);
  for (Eigen::Index i = 0; i < m; ++i) e[i] = 1.0 / std::sqrt(L(i, i));  // positive: Cholesky succeeded
  kappa = equilibratedFrobenius(L, e) * equilibratedInverseFrobenius(factor, e, f.work.head(m));
  if (!(std::isfinite(kappa) && kappa * threshold < 1.0)) return false;
  // The factor's strict upper triangle now holds scratch: choleskySolveInPlace
  // reads the lower triangle and the diagonal only.
  nu = r;
  choleskySolveInPlace(factor, nu);
  return true;
}

// Where σ̃ sits on the ramp between exact rank loss (0) and the threshold (1).
double rampPosition(double sigma, const BalanceOptions& options) {
  const double t = (sigma - options.rank_tolerance) / (options.singular_threshold - options.rank_tolerance);
  return std::clamp(t, 0.0, 1.0);
}

// Z's first `count` columns made orthonormal in place (Gram–Schmidt, twice:
// "twice is enough" for columns as independent as E v_k, E regular, v_k orthonormal).
void orthonormaliseColumns(Eigen::Ref<Eigen::MatrixXd> Z, Eigen::Index count) {
  for (Eigen::Index c = 0; c < count; ++c) {
    for (int pass = 0; pass < 2; ++pass)
      for (Eigen::Index p = 0; p < c; ++p) Z.col(c) -= Z.col(p) * Z.col(p).dot(Z.col(c));
    Z.col(c) /= Z.col(c).norm();
  }
}

// x ← (I − Σ_c w_c z_c z_cᵀ) x over the orthonormal columns z_c of Z.
void removeNearNullComponent(const Eigen::Ref<const Eigen::MatrixXd>& Z, const Eigen::Ref<const Eigen::VectorXd>& w,
                             Eigen::Ref<Eigen::VectorXd> x) {
  for (Eigen::Index c = 0; c < Z.cols(); ++c) x -= Z.col(c) * (w[c] * Z.col(c).dot(x));
}

// The next direction below the threshold in ascending σ̃ not yet taken (−1: none).
Eigen::Index nextNearNull(const Eigen::Ref<const Eigen::VectorXd>& sigma, double above, Eigen::Index after,
                          double threshold) {
  Eigen::Index best = -1;
  for (Eigen::Index k = 0; k < sigma.size(); ++k) {
    const bool later = sigma[k] > above || (sigma[k] == above && k > after);
    if (later && sigma[k] < threshold && (best < 0 || sigma[k] < sigma[best])) best = k;
  }
  return best;
}

// The singular case: eigenpairs of 𝓛̃ and what each direction gets. A
// direction at ramp position t (rampPosition) gets the gain t/threshold — 0 at
// exact rank loss, 1/σ̃ at the threshold, a straight line between — and the
// weight 1 − t in the Euclidean projection that makes exact rank loss the
// minimum-norm least-squares solution in the rows' own units. Both are
// continuous in σ̃, so ν is continuous as an arm passes through a singularity,
// and the operator r ↦ ν stays symmetric positive semi-definite.
BalanceReport factorByEigen(Eigen::Ref<Eigen::MatrixXd> L, BalanceFactorisation& f, const BalanceOptions& options) {
  const Eigen::Index m = L.rows();
  auto e = f.equilibration.head(m);
  for (Eigen::Index i = 0; i < m; ++i) e[i] = L(i, i) > 0.0 ? 1.0 / std::sqrt(L(i, i)) : 1.0;  // a zeroed row: 1
  for (Eigen::Index j = 0; j < m; ++j)  // 𝓛̃ = E 𝓛 E, the full symmetric matrix from the lower triangle
    for (Eigen::Index i = j; i < m; ++i) L(j, i) = L(i, j) = L(i, j) * e[i] * e[j];
  auto V = f.factor.topLeftCorner(m, m);
  auto sigma = f.eigenvalues.head(m);
  symmetricEigen(L, sigma, V);

  BalanceReport report;
  report.rows = static_cast<int>(m);
  report.rank = static_cast<int>(m);
  f.kind = BalanceFactorisation::Kind::Eigen;
  double sum_sigma2 = 0.0, sum_inverse2 = 0.0, kept_sigma2 = 0.0, kept_inverse2 = 0.0;
  for (Eigen::Index k = 0; k < m; ++k) {
    const double s = std::max(0.0, sigma[k]);  // a rounding-level negative eigenvalue is a zero one
    sigma[k] = s;
    sum_sigma2 += s * s;
    sum_inverse2 += s > 0.0 ? 1.0 / (s * s) : std::numeric_limits<double>::infinity();
    if (s >= options.singular_threshold) {
      f.gain[k] = 1.0 / s;
      kept_sigma2 += s * s;
      kept_inverse2 += 1.0 / (s * s);
      continue;
    }
    report.singular = true;
    const double t = rampPosition(s, options);
    f.gain[k] = t / options.singular_threshold;
    if (t == 0.0) {
      --report.rank;
      report.nu_unique = false;  // 𝓛 has a null space: ν plus any of it gives the same motion
    } else
      report.damping = std::max(report.damping, 1.0 - t);
  }
  // The near-null directions E v_k (𝓛 E v = E⁻¹ 𝓛̃ v = σ̃ E⁻¹ v), smallest σ̃
  // first so that Gram–Schmidt keeps the exact null space's span in front.
  f.near_null_count = 0;
  for (Eigen::Index k = nextNearNull(sigma, -1.0, -1, options.singular_threshold); k >= 0;
       k = nextNearNull(sigma, sigma[k], k, options.singular_threshold)) {
    f.near_null_basis.col(f.near_null_count).head(m) = e.cwiseProduct(V.col(k));
    f.near_null_weight[f.near_null_count++] = 1.0 - rampPosition(sigma[k], options);
  }
  orthonormaliseColumns(f.near_null_basis.topLeftCorner(m, f.near_null_count), f.near_null_count);
  // The fast path's κ̃_F, from the eigenvalues; ∞ on exact rank loss, also
  // when every σ̃ is zero (every row immovable), where the product is 0·∞.
  report.condition =
      std::isinf(sum_inverse2) ? std::numeric_limits<double>::infinity() : std::sqrt(sum_sigma2 * sum_inverse2);
  f.regular_condition = std::sqrt(kept_sigma2 * kept_inverse2);
  return report;
}

// With PivotedCholesky: x (m) ← P-ordered solve on the pivoted rows, x's part on the dependent pivots 0; x holds
// the equilibrated right-hand side in 𝓛's row order on entry and ν̃ in the same order on return.
void pivotedSolve(const BalanceFactorisation& f, Eigen::Index m, Eigen::Ref<Eigen::VectorXd> x,
                  Eigen::Ref<Eigen::VectorXd> work) {
  const auto C = f.factor.topLeftCorner(m, m);
  const int k = f.rank;
  for (int i = 0; i < k; ++i) {  // C₁₁ y = x_P
    double value = x[f.pivots[i]];
    for (int l = 0; l < i; ++l) value -= C(i, l) * work[l];
    work[i] = value / C(i, i);
  }
  for (int i = k - 1; i >= 0; --i) {  // C₁₁ᵀ z = y
    double value = work[i];
    for (int l = i + 1; l < k; ++l) value -= C(l, i) * work[l];
    work[i] = value / C(i, i);
  }
  x.setZero();
  for (int i = 0; i < k; ++i) x[f.pivots[i]] = work[i];
}

// Exact rank loss beside a certified regular part, without the eigenpairs. Cholesky of 𝓛̃ with diagonal pivoting
// stops where the largest diagonal left is at most rank_tolerance/m: the Schur complement S left over is PSD with
// ‖S‖ ≤ trace S < rank_tolerance, so (Weyl) the m − k directions it leaves are at most that, which the eigenpairs
// call exact rank loss, while 𝓛̃ ⪰ the rank-k part keeps the other k at least λ_min(B) of the pivoted block B.
// B is certified as the regular path certifies 𝓛̃ (κ̃_F(B)·threshold < 1, and ‖B‖ ≥ 1 with its unit diagonal): so
// λ_min(B) > threshold and no direction is near-singular. Then ν = 𝓛⁺ r as the eigenpairs give it: r's part along
// null(𝓛) dropped, the pivoted rows solved, ν's part along null(𝓛) removed (near_null_basis: E times the null
// vectors [−C₁₁⁻ᵀC₂₁ᵀ; I] unpermuted, made orthonormal). False, nothing decided, when the pivots prove neither.
bool factorByPivots(const Eigen::Ref<const Eigen::MatrixXd>& L, const Eigen::Ref<const Eigen::VectorXd>& r,
                    Eigen::Ref<Eigen::VectorXd> nu, BalanceFactorisation& f, const BalanceOptions& options,
                    BalanceReport& report) {
  const Eigen::Index m = L.rows();
  auto e = f.equilibration.head(m);
  for (Eigen::Index i = 0; i < m; ++i) e[i] = L(i, i) > 0.0 ? 1.0 / std::sqrt(L(i, i)) : 1.0;  // a zeroed row: 1
  auto A = f.factor.topLeftCorner(m, m);  // 𝓛̃ in full, pivoted and factored in place
  for (Eigen::Index j = 0; j < m; ++j)
    for (Eigen::Index i = j; i < m; ++i) A(j, i) = A(i, j) = L(i, j) * e[i] * e[j];
  auto pivots = f.pivots.head(m);
  for (Eigen::Index i = 0; i < m; ++i) pivots[i] = static_cast<int>(i);
  const double floor = options.rank_tolerance / static_cast<double>(m);
  Eigen::Index k = 0;
  for (; k < m; ++k) {
    Eigen::Index p = k;
    for (Eigen::Index i = k + 1; i < m; ++i)
      if (A(i, i) > A(p, p)) p = i;
    if (!(A(p, p) > floor)) break;
    A.row(k).swap(A.row(p));
    A.col(k).swap(A.col(p));
    std::swap(pivots[k], pivots[p]);
    const double pivot = std::sqrt(A(k, k));
    A(k, k) = pivot;
    for (Eigen::Index i = k + 1; i < m; ++i) A(i, k) /= pivot;
    for (Eigen::Index j = k + 1; j < m; ++j)
      for (Eigen::Index i = j; i < m; ++i) A(j, i) = A(i, j) -= A(i, k) * A(j, k);
  }
  if (k == m) return false;  // no rank loss: the certificate failed on conditioning, which the eigenpairs damp
  f.rank = static_cast<int>(k);
  // κ̃_F(B): ‖B‖_F from 𝓛̃'s entries, ‖B⁻¹‖_F column by column through the factor.
  double norm2 = 0.0, inverse_norm2 = 0.0;
  for (Eigen::Index a = 0; a < k; ++a)
    for (Eigen::Index b = 0; b < k; ++b) {
      const Eigen::Index i = pivots[a], j = pivots[b];
      const double entry = (i >= j ? L(i, j) : L(j, i)) * e[i] * e[j];
      norm2 += entry * entry;
    }
  auto column = f.work.head(m);
  for (Eigen::Index c = 0; c < k; ++c) {
    for (Eigen::Index i = 0; i < k; ++i) {  // C₁₁ y = e_c
      double value = i == c ? 1.0 : 0.0;
      for (Eigen::Index l = c; l < i; ++l) value -= A(i, l) * column[l];
      column[i] = i < c ? 0.0 : value / A(i, i);
    }
    for (Eigen::Index i = k - 1; i >= 0; --i) {  // C₁₁ᵀ x = y
      double value = column[i];
      for (Eigen::Index l = i + 1; l < k; ++l) value -= A(l, i) * column[l];
      column[i] = value / A(i, i);
    }
    inverse_norm2 += column.head(k).squaredNorm();
  }
  const double kappa = std::sqrt(norm2 * inverse_norm2);
  if (!(std::isfinite(kappa) && kappa * options.singular_threshold < 1.0)) return false;
  f.kind = BalanceFactorisation::Kind::PivotedCholesky;
  f.regular_condition = kappa;
  // The null directions: for each dependent pivot d, x_d = 1, x on the pivoted rows −C₁₁⁻ᵀ C₂₁ᵀ e_d, ν = E P x.
  f.near_null_count = static_cast<int>(m - k);
  for (Eigen::Index d = k; d < m; ++d) {
    for (Eigen::Index i = k - 1; i >= 0; --i) {
      double value = -A(d, i);
      for (Eigen::Index l = i + 1; l < k; ++l) value -= A(l, i) * column[l];
      column[i] = value / A(i, i);
    }
    auto direction = f.near_null_basis.col(d - k).head(m);
    direction.setZero();
    for (Eigen::Index i = 0; i < k; ++i) direction[pivots[i]] = e[pivots[i]] * column[i];
    direction[pivots[d]] = e[pivots[d]];
    f.near_null_weight[d - k] = 1.0;
  }
  orthonormaliseColumns(f.near_null_basis.topLeftCorner(m, f.near_null_count), f.near_null_count);
  report.rows = static_cast<int>(m);
  report.rank = static_cast<int>(k);
  report.nu_unique = false;  // 𝓛 has a null space: ν plus any of it gives the same motion
  report.singular = true;
  report.damping = 0.0;
  report.condition = std::numeric_limits<double>::infinity();
  balanceApply(f, r, nu, column);
  return true;
}

}  // namespace

BalanceReport solveBalance(Eigen::Ref<Eigen::MatrixXd> L, const Eigen::Ref<const Eigen::VectorXd>& r,
                           Eigen::Ref<Eigen::VectorXd> nu, BalanceFactorisation& f, const BalanceOptions& options) {
  BalanceReport report;
  report.rows = static_cast<int>(L.rows());
  f.kind = BalanceFactorisation::Kind::Cholesky;
  f.near_null_count = 0;
  if (report.rows == 0) return report;
  double kappa = 0.0;
  if (certifiedSolve(L, r, nu, f, options.singular_threshold, kappa)) {
    report.rank = report.rows;
    report.condition = kappa;
    f.regular_condition = kappa;
    return report;
  }
  if (factorByPivots(L, r, nu, f, options, report)) return report;
  report = factorByEigen(L, f, options);
  balanceApply(f, r, nu, f.work.head(report.rows));
  return report;
}

void balanceApply(const BalanceFactorisation& f, const Eigen::Ref<const Eigen::VectorXd>& r,
                  Eigen::Ref<Eigen::VectorXd> out, Eigen::Ref<Eigen::VectorXd> work) {
  const Eigen::Index m = r.size();
  out = r;
  if (f.kind == BalanceFactorisation::Kind::Cholesky) {
    choleskySolveInPlace(f.factor.topLeftCorner(m, m), out);
    return;
  }
  const auto Z = f.near_null_basis.topLeftCorner(m, f.near_null_count);
  const auto w = f.near_null_weight.head(f.near_null_count);
  if (f.kind == BalanceFactorisation::Kind::PivotedCholesky) {
    const auto e = f.equilibration.head(m);
    removeNearNullComponent(Z, w, out);  // r's part along null(𝓛): no force can meet it (least squares)
    out.array() *= e.array();            // 𝓛̃'s right-hand side; ν = E ν̃
    pivotedSolve(f, m, out, work);
    out.array() *= e.array();
    removeNearNullComponent(Z, w, out);  // minimum norm: no force along null(𝓛)
    return;
  }
  const auto V = f.factor.topLeftCorner(m, m);
  const auto e = f.equilibration.head(m);
  removeNearNullComponent(Z, w, out);  // r's part along null(𝓛): no force can meet it (least squares)
  out.array() *= e.array();            // into 𝓛̃'s coordinates: 𝓛⁺ = E 𝓛̃⁺ E on range(𝓛)
  for (Eigen::Index k = 0; k < m; ++k) work[k] = f.gain[k] * V.col(k).dot(out);
  out.setZero();
  for (Eigen::Index k = 0; k < m; ++k) out += V.col(k) * work[k];
  out.array() *= e.array();
  removeNearNullComponent(Z, w, out);  // minimum norm: no force along null(𝓛)
}

void balanceApplyColumns(const BalanceFactorisation& f, const Eigen::Ref<const Eigen::MatrixXd>& R,
                         Eigen::Ref<Eigen::MatrixXd> out, Eigen::Ref<Eigen::VectorXd> work) {
  if (f.kind != BalanceFactorisation::Kind::Cholesky) {
    for (Eigen::Index c = 0; c < R.cols(); ++c) balanceApply(f, R.col(c), out.col(c), work);
    return;
  }
  out = R;
  choleskySolveInPlace(f.factor.topLeftCorner(R.rows(), R.rows()), out);
}

}  // namespace zwang::internal
