#include "internal/coupling.hpp"

#include <cmath>
#include <limits>

namespace zwang::internal {

void jacobiEigen(Eigen::Ref<Eigen::MatrixXd> A, Eigen::Ref<Eigen::VectorXd> lambda, Eigen::Ref<Eigen::MatrixXd> V) {
  const Eigen::Index m = A.rows();
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

CouplingDiagnostics solveBalance(Eigen::Ref<Eigen::MatrixXd> L, const Eigen::Ref<const Eigen::VectorXd>& r,
                                 Eigen::Ref<Eigen::VectorXd> nu, Eigen::Ref<Eigen::MatrixXd> V,
                                 Eigen::Ref<Eigen::VectorXd> lambda, Eigen::Ref<Eigen::VectorXd> tmp,
                                 const BalanceOptions& options) {
  CouplingDiagnostics d;
  d.rows = static_cast<int>(L.rows());
  if (d.rows == 0) return d;

  jacobiEigen(L, lambda, V);
  const double lambda_max = std::max(0.0, lambda.maxCoeff());
  const double lambda_min = std::max(0.0, lambda.minCoeff());
  const double threshold = options.singular_threshold * lambda_max;
  d.rank = 0;
  for (Eigen::Index k = 0; k < lambda.size(); ++k)
    if (lambda_max > 0.0 && lambda[k] > threshold) ++d.rank;
  d.condition = lambda_min > 0.0 ? lambda_max / lambda_min : std::numeric_limits<double>::infinity();
  d.singular = lambda_max <= 0.0 || lambda_min <= threshold;
  if (d.singular && lambda_max > 0.0) {
    const double x = threshold > 0.0 ? lambda_min / threshold : 0.0;
    d.damping = options.max_damping * lambda_max * std::sqrt(std::max(0.0, 1.0 - x * x));
  }

  // ν = Σ_k σ_k/(σ_k² + λ²) (e_kᵀ r) e_k; with λ = 0 this is exactly 𝓛⁻¹ r.
  tmp.noalias() = V.transpose() * r;
  const double damping2 = d.damping * d.damping;
  for (Eigen::Index k = 0; k < tmp.size(); ++k) {
    const double s = std::max(0.0, lambda[k]);
    const double denominator = s * s + damping2;
    tmp[k] = denominator > 0.0 ? tmp[k] * s / denominator : 0.0;
  }
  nu.noalias() = V * tmp;
  return d;
}

}  // namespace zwang::internal
