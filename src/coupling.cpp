#include "internal/coupling.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>

namespace zwang::internal {

namespace {
constexpr int kSmallEigen = 8;  // up to this size jacobiEigen uses a fixed-capacity QR solver
}  // namespace

void jacobiEigen(Eigen::Ref<Eigen::MatrixXd> A, Eigen::Ref<Eigen::VectorXd> lambda, Eigen::Ref<Eigen::MatrixXd> V) {
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
  const Eigen::Index m = C.rows(), k = X.cols();
  for (Eigen::Index i = 0; i < m; ++i) {
    const double inverse = 1.0 / C(i, i);
    for (Eigen::Index c = 0; c < k; ++c) {
      double s = X(i, c);
      for (Eigen::Index l = 0; l < i; ++l) s -= C(i, l) * X(l, c);
      X(i, c) = s * inverse;
    }
  }
  for (Eigen::Index i = m - 1; i >= 0; --i) {
    const double inverse = 1.0 / C(i, i);
    for (Eigen::Index c = 0; c < k; ++c) {
      double s = X(i, c);
      for (Eigen::Index l = i + 1; l < m; ++l) s -= C(l, i) * X(l, c);
      X(i, c) = s * inverse;
    }
  }
}

bool certifiedCholesky(const Eigen::Ref<const Eigen::MatrixXd>& A, Eigen::Ref<Eigen::MatrixXd> C,
                       Eigen::Ref<Eigen::VectorXd> tmp, double floor) {
  if (!cholesky(A, C)) return false;
  // ‖C⁻¹‖_F² = trace(A⁻¹) = Σ 1/λ_k ≥ 1/λ_min, one column of C⁻¹ at a time.
  const Eigen::Index m = A.rows();
  double trace_inverse = 0.0;
  for (Eigen::Index j = 0; j < m; ++j) {
    for (Eigen::Index i = j; i < m; ++i) {  // C w = e_j, w zero above j
      double x = i == j ? 1.0 : 0.0;
      for (Eigen::Index k = j; k < i; ++k) x -= C(i, k) * tmp[k];
      tmp[i] = x / C(i, i);
      trace_inverse += tmp[i] * tmp[i];
    }
  }
  return std::isfinite(trace_inverse) && 1.0 > floor * trace_inverse;
}

namespace {

// ‖A‖_F of a symmetric matrix from its lower triangle.
double symmetricFrobenius(const Eigen::Ref<const Eigen::MatrixXd>& A) {
  double s = 0.0;
  for (Eigen::Index j = 0; j < A.cols(); ++j) {
    s += A(j, j) * A(j, j);
    for (Eigen::Index i = j + 1; i < A.rows(); ++i) s += 2.0 * A(i, j) * A(i, j);
  }
  return std::sqrt(s);
}

// ‖(C Cᵀ)⁻¹‖_F = ‖Wᵀ W‖_F with W = C⁻¹ (lower). W overwrites the strict upper
// triangle of C transposed, so C itself stays usable: W(i, j) for i ≥ j is kept
// in C(j, i) for i > j and in `diag`(i) for i = j.
double inverseFrobenius(Eigen::Ref<Eigen::MatrixXd> C, Eigen::Ref<Eigen::VectorXd> diag) {
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
      s += (a == b ? 1.0 : 2.0) * p * p;
    }
  return std::sqrt(s);
}

// The fast path for a task of M ≤ 6 rows in fixed-size arithmetic: Cholesky,
// the certificate κ_F·threshold < 1, ν = 𝓛⁻¹ r and the factor for later
// right-hand sides. False (nothing written but `factor`) when not certified.
template <int M>
bool certifiedSolveFixed(const Eigen::Ref<const Eigen::MatrixXd>& L, const Eigen::Ref<const Eigen::VectorXd>& r,
                         Eigen::Ref<Eigen::VectorXd> nu, Eigen::Ref<Eigen::MatrixXd> factor, double threshold,
                         double& kappa) {
  using MatM = Eigen::Matrix<double, M, M>;
  // Divisions are slow and sit on the substitutions' dependency chains: each
  // pivot is inverted once and the rest multiply.
  MatM C = MatM::Zero();  // 𝓛 = C Cᵀ
  Eigen::Matrix<double, M, 1> inverse_pivot;
  double norm2 = 0.0;  // ‖𝓛‖_F²
  for (int j = 0; j < M; ++j) {
    double d = L(j, j);
    norm2 += d * d;
    for (int k = 0; k < j; ++k) d -= C(j, k) * C(j, k);
    if (!(d > 0.0)) return false;
    C(j, j) = std::sqrt(d);
    inverse_pivot[j] = 1.0 / C(j, j);
    for (int i = j + 1; i < M; ++i) {
      double x = L(i, j);
      norm2 += 2.0 * x * x;
      for (int k = 0; k < j; ++k) x -= C(i, k) * C(j, k);
      C(i, j) = x * inverse_pivot[j];
    }
  }
  MatM W = MatM::Zero();  // C⁻¹, lower
  for (int j = 0; j < M; ++j) {
    W(j, j) = inverse_pivot[j];
    for (int i = j + 1; i < M; ++i) {
      double x = 0.0;
      for (int k = j; k < i; ++k) x += C(i, k) * W(k, j);
      W(i, j) = -x * inverse_pivot[i];
    }
  }
  const MatM inverse = W.transpose() * W;  // 𝓛⁻¹, for κ_F only
  kappa = std::sqrt(norm2) * inverse.norm();
  if (!(std::isfinite(kappa) && kappa * threshold < 1.0)) return false;
  factor = C;
  // ν by forward and backward substitution with C (more accurate than the
  // explicit inverse when 𝓛 is ill-conditioned).
  Eigen::Matrix<double, M, 1> x = r;
  for (int i = 0; i < M; ++i) {
    for (int k = 0; k < i; ++k) x[i] -= C(i, k) * x[k];
    x[i] *= inverse_pivot[i];
  }
  for (int i = M - 1; i >= 0; --i) {
    for (int k = i + 1; k < M; ++k) x[i] -= C(k, i) * x[k];
    x[i] *= inverse_pivot[i];
  }
  nu = x;
  return true;
}

bool certifiedSolveSmall(const Eigen::Ref<const Eigen::MatrixXd>& L, const Eigen::Ref<const Eigen::VectorXd>& r,
                         Eigen::Ref<Eigen::VectorXd> nu, Eigen::Ref<Eigen::MatrixXd> factor, double threshold,
                         double& kappa) {
  switch (L.rows()) {
    case 1: {  // κ_F = 1: regular whenever positive
      if (!(L(0, 0) > 0.0)) return false;
      kappa = 1.0;
      factor(0, 0) = std::sqrt(L(0, 0));
      nu[0] = r[0] / L(0, 0);
      return true;
    }
    case 2: return certifiedSolveFixed<2>(L, r, nu, factor, threshold, kappa);
    case 3: return certifiedSolveFixed<3>(L, r, nu, factor, threshold, kappa);
    case 4: return certifiedSolveFixed<4>(L, r, nu, factor, threshold, kappa);
    case 5: return certifiedSolveFixed<5>(L, r, nu, factor, threshold, kappa);
    case 6: return certifiedSolveFixed<6>(L, r, nu, factor, threshold, kappa);
    default: return false;
  }
}

}  // namespace

CouplingDiagnostics solveBalance(Eigen::Ref<Eigen::MatrixXd> L, const Eigen::Ref<const Eigen::VectorXd>& r,
                                 Eigen::Ref<Eigen::VectorXd> nu, Eigen::Ref<Eigen::MatrixXd> factor,
                                 Eigen::Ref<Eigen::VectorXd> lambda, Eigen::Ref<Eigen::VectorXd> tmp,
                                 const BalanceOptions& options, bool& by_eigen) {
  CouplingDiagnostics d;
  d.rows = static_cast<int>(L.rows());
  by_eigen = false;
  if (d.rows == 0) return d;

  // Fast path: a Cholesky factor and a certificate that 𝓛 is regular. With
  // κ_F = ‖𝓛‖_F‖𝓛⁻¹‖_F ≥ λ_max/λ_min, κ_F < 1/threshold means λ_min above
  // threshold·λ_max: not singular, rank m, no damping, ν = 𝓛⁻¹ r exactly.
  if (d.rows <= 6) {
    double kappa = 0.0;
    if (certifiedSolveSmall(L, r, nu, factor, options.singular_threshold, kappa)) {
      d.rank = d.rows;
      d.condition = kappa;
      return d;
    }
  } else if (cholesky(L, factor)) {
    const double kappa = symmetricFrobenius(L) * inverseFrobenius(factor, lambda);
    if (std::isfinite(kappa) && kappa * options.singular_threshold < 1.0) {
      d.rank = d.rows;
      d.condition = kappa;
      nu = r;
      choleskySolveInPlace(factor, nu);
      return d;
    }
  }

  by_eigen = true;
  for (Eigen::Index j = 0; j < L.cols(); ++j)  // the full symmetric matrix from its lower triangle
    for (Eigen::Index i = j + 1; i < L.rows(); ++i) L(j, i) = L(i, j);
  jacobiEigen(L, lambda, factor);
  const double lambda_max = std::max(0.0, lambda.maxCoeff());
  const double lambda_min = std::max(0.0, lambda.minCoeff());
  const double threshold = options.singular_threshold * lambda_max;
  d.rank = 0;
  for (Eigen::Index k = 0; k < lambda.size(); ++k)
    if (lambda_max > 0.0 && lambda[k] > threshold) ++d.rank;
  // The same κ_F as the fast path, from the eigenvalues.
  d.condition = lambda_min > 0.0 ? std::sqrt(lambda.squaredNorm() * lambda.cwiseInverse().squaredNorm())
                                 : std::numeric_limits<double>::infinity();
  d.singular = lambda_max <= 0.0 || lambda_min <= threshold;
  if (d.singular && lambda_max > 0.0) {
    const double x = threshold > 0.0 ? lambda_min / threshold : 0.0;
    d.damping = options.max_damping * lambda_max * std::sqrt(std::max(0.0, 1.0 - x * x));
  }
  (void)tmp;
  balanceApply(factor, lambda, true, d.damping, r, nu);
  return d;
}

void balanceApply(const Eigen::Ref<const Eigen::MatrixXd>& factor, const Eigen::Ref<const Eigen::VectorXd>& lambda,
                  bool by_eigen, double damping, const Eigen::Ref<const Eigen::VectorXd>& r,
                  Eigen::Ref<Eigen::VectorXd> out) {
  if (!by_eigen) {
    out = r;
    // The factor's strict upper triangle holds scratch (inverseFrobenius):
    // choleskySolveInPlace reads the lower triangle and the diagonal only.
    choleskySolveInPlace(factor, out);
    return;
  }
  // out = Σ_k σ_k/(σ_k² + λ²) (e_kᵀ r) e_k; with λ = 0 this is exactly 𝓛⁻¹ r.
  const double damping2 = damping * damping;
  out.setZero();
  for (Eigen::Index k = 0; k < lambda.size(); ++k) {
    const double s = std::max(0.0, lambda[k]);
    const double denominator = s * s + damping2;
    if (denominator > 0.0) out += factor.col(k) * (factor.col(k).dot(r) * s / denominator);
  }
}

void balanceApplyColumns(const Eigen::Ref<const Eigen::MatrixXd>& factor, const Eigen::Ref<const Eigen::VectorXd>& lambda,
                         bool by_eigen, double damping, const Eigen::Ref<const Eigen::MatrixXd>& R,
                         Eigen::Ref<Eigen::MatrixXd> out) {
  if (by_eigen) {
    for (Eigen::Index c = 0; c < R.cols(); ++c) balanceApply(factor, lambda, true, damping, R.col(c), out.col(c));
    return;
  }
  out = R;
  choleskySolveInPlace(factor, out);
}

}  // namespace zwang::internal
