// What the box-QP solvers share: their scratch, the scale of the reach rule
// (kReach, src/qp/box_qp.hpp) and the optimality residual they report.
// The solvers themselves: src/qp/box_qp_active_set.cpp,
// src/qp/box_qp_projected_gradient.cpp, src/qp/least_distance.cpp.
#include "qp/box_qp.hpp"

#include <algorithm>
#include <cmath>

namespace zwang::internal {

ActiveSetScratch::ActiveSetScratch(int n)
    : gradient(n),
      gradient_noise(n),
      row_sums(n),
      fixed(n),
      flat(n),
      step(n),
      direction(n),
      delta(n),
      P_delta(n),
      free_factor(n) {}

ProjectedGradientScratch::ProjectedGradientScratch(int n)
    : inverse_diagonal(n),
      root_inverse_diagonal(n),
      gradient(n),
      y(n),
      x_previous(n),
      x_change(n),
      Px(n),
      Px_previous(n),
      Py(n) {}

LeastDistanceScratch::LeastDistanceScratch(int n)
    : rows(n, 2 * n),
      row_bounds(2 * n),
      gram(2 * n, 2 * n),
      row_dot_a(2 * n),
      working(2 * n),
      multipliers(n),
      step(n),
      point(n),
      rate(n),
      working_factor(2 * n) {}

HyperplaneScratch::HyperplaneScratch(int n) : breakpoints(2 * n), breakpoint_kind(2 * n) {}

QpScratch::QpScratch(int n) : active_set(n), projected_gradient(n), least_distance(n), hyperplane(n) {}

namespace {

// lambdaMaxBound with the weight w_j given by weight(j) (no temporary vector).
template <class Weight>
double weightedLambdaMaxBound(const Eigen::Ref<const Eigen::MatrixXd>& P, const Weight& weight) {
  double gershgorin = 0.0, trace = 0.0, largest = 0.0;
  bool diagonal_non_negative = true;
  for (Eigen::Index j = 0; j < P.cols(); ++j) {
    double row_sum = 0.0;  // P symmetric: its contiguous column
    for (Eigen::Index l = 0; l < P.rows(); ++l) {
      const double entry = std::abs(weight(l) * P(l, j) * weight(j));
      row_sum += entry;
      largest = std::max(largest, entry);
    }
    gershgorin = std::max(gershgorin, row_sum);
    const double diagonal = weight(j) * P(j, j) * weight(j);
    diagonal_non_negative = diagonal_non_negative && diagonal >= 0.0;
    trace += diagonal;
  }
  return diagonal_non_negative && trace >= largest ? std::min(gershgorin, trace) : gershgorin;
}

}  // namespace

double lambdaMaxBound(const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& w) {
  return weightedLambdaMaxBound(P, [&w](Eigen::Index j) { return w[j]; });
}

double lambdaMaxBound(const Eigen::Ref<const Eigen::MatrixXd>& P) {
  return weightedLambdaMaxBound(P, [](Eigen::Index) { return 1.0; });
}

double reachScale(const Eigen::Ref<const Eigen::VectorXd>& lo, const Eigen::Ref<const Eigen::VectorXd>& hi,
                  const Eigen::Ref<const Eigen::VectorXd>& c, double lambda_max_bound, double curvature_scale) {
  double scale = 1.0;
  for (Eigen::Index j = 0; j < lo.size(); ++j) {
    if (std::isfinite(lo[j])) scale = std::max(scale, std::abs(lo[j]));
    if (std::isfinite(hi[j])) scale = std::max(scale, std::abs(hi[j]));
  }
  // ‖c‖∞ / curvature: how far the unconstrained minimiser can be along a
  // direction of real curvature (at least λ_max's bound or the caller's scale).
  const double curvature = std::max(lambda_max_bound, curvature_scale);
  if (curvature > 0.0 && c.size() > 0) scale = std::max(scale, c.cwiseAbs().maxCoeff() / curvature);
  return scale;
}

double roundingSlope(const TermSizes& terms, const Eigen::Ref<const Eigen::VectorXd>& x, Eigen::Index j) {
  double slope = terms.slope_of.size() == x.size() ? kSlopeRounding * terms.slope_of[j] : 0.0;
  if (terms.curvature_of.size() == x.size()) {
    double weighted_x = 0.0;  // Σ_l √t_l |x_l|
    for (Eigen::Index l = 0; l < x.size(); ++l) weighted_x += std::sqrt(terms.curvature_of[l]) * std::abs(x[l]);
    slope += kTermRounding * std::sqrt(terms.curvature_of[j]) * weighted_x;
  }
  return slope;
}

double boxQpKktResidual(const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& c,
                        const Eigen::Ref<const Eigen::VectorXd>& lo, const Eigen::Ref<const Eigen::VectorXd>& hi,
                        const Eigen::Ref<const Eigen::VectorXd>& x) {
  double r = 0.0;
  for (Eigen::Index j = 0; j < x.size(); ++j)  // P symmetric: its contiguous column
    r = std::max(r, kktViolation(P.col(j).dot(x) - c[j], x[j], lo[j], hi[j]));
  return r;
}

}  // namespace zwang::internal
