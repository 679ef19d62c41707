// When μ* is not unique (docs/friction.md, "When μ* is not unique").
//
// The report stops at "a" maximiser of g. Here: all maximisers give the same
// q̈*, so they differ by d with K_ΘΘ d = 0; g is linear along d with slope
// q̈*_Θ, so only sticking joints (q̈*_j = 0) can move. The maximisers are
// μ* + N z inside the box, N an orthonormal basis of null(K_ΣΣ). Two
// least-distance problems on that set pick (a) the smallest maximiser, as a
// reference point inside it, then (b) the one with the least motor effort
// within the margin box. With K_ΣΣ of rank one (a 7-joint arm holding a 6-D
// pose, say) the set is a hyperplane and its dual is one scalar equation.
#include "friction/friction_maximisers.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "linalg/growing_cholesky.hpp"

namespace zwang::internal {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Largest t ≥ 0 with lo ≤ x + t·d ≤ hi.
double roomAlong(const Eigen::Ref<const Eigen::VectorXd>& x, const Eigen::Ref<const Eigen::VectorXd>& d,
                 const Eigen::Ref<const Eigen::VectorXd>& lo, const Eigen::Ref<const Eigen::VectorXd>& hi) {
  double t = kInf;
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    if (d[j] > 0) t = std::min(t, (hi[j] - x[j]) / d[j]);
    if (d[j] < 0) t = std::min(t, (lo[j] - x[j]) / d[j]);
  }
  return std::max(0.0, t);
}

// The width W of the box around μ* on Σ: a curvature λ moves q̈ by at most λ·W
// across it.
double boxWidth(const Eigen::Ref<const Eigen::VectorXd>& mu, const Eigen::Ref<const Eigen::VectorXd>& lo,
                const Eigen::Ref<const Eigen::VectorXd>& hi, const Eigen::Ref<const Eigen::VectorXi>& sticking) {
  double width = 0.0;
  for (Eigen::Index s = 0; s < sticking.size(); ++s) {
    const Eigen::Index a = sticking[s];
    width = std::max(width, std::abs(mu[a]));
    if (std::isfinite(lo[a])) width = std::max(width, std::abs(lo[a]));
    if (std::isfinite(hi[a])) width = std::max(width, std::abs(hi[a]));
  }
  return 2.0 * width;
}

// With one curvature direction (ns − nullity = 1) the maximisers are the
// hyperplane vᵀμ = vᵀμ*: v ⟂ N is (1 − N Nᵀ) e_p for the row p of N with the
// least weight. Returns vᵀμ*.
double hyperplaneNormal(const Eigen::Ref<const Eigen::MatrixXd>& N, const Eigen::Ref<const Eigen::VectorXd>& mu_first,
                        Eigen::Ref<Eigen::VectorXd> v) {
  Eigen::Index p = 0;
  for (Eigen::Index s = 1; s < N.rows(); ++s)
    if (N.row(s).squaredNorm() < N.row(p).squaredNorm()) p = s;
  v.noalias() = -N * N.row(p).transpose();
  v[p] += 1.0;
  v.normalize();
  return v.dot(mu_first);
}

// s.mu_chosen ← the maximiser closest to s.target inside [s.lo, s.hi] (which
// holds s.mu_chosen on entry).
void moveClosestTo(Eigen::Index ns, Eigen::Index nullity, bool hyperplane, double plane, int max_iterations,
                   MaximiserChoiceScratch& s) {
  const auto N = s.null_basis.topLeftCorner(ns, nullity);
  auto mu = s.mu_chosen.head(ns);
  const auto target = s.target.head(ns), lo = s.lo.head(ns), hi = s.hi.head(ns);
  if (hyperplane && leastDistanceOnHyperplane(s.curvature_direction.head(ns), plane, target, lo, hi, mu, s.qp)) return;
  auto z = s.z.head(nullity);
  auto z_target = s.z_target.head(nullity);
  z.setZero();
  z_target.noalias() = N.transpose() * target;  // Nᵀ(target − μ), without a temporary
  z_target.noalias() -= N.transpose() * mu;
  leastDistanceQp(N, z_target, mu, lo, hi, z, s.qp, max_iterations);
  mu.noalias() += N * z;
}

}  // namespace

Eigen::Index flatDirections(const Eigen::Ref<const Eigen::MatrixXd>& K,
                            const Eigen::Ref<const Eigen::VectorXd>& qdd0_stuck,
                            const Eigen::Ref<const Eigen::VectorXd>& mu, const Eigen::Ref<const Eigen::VectorXd>& lo,
                            const Eigen::Ref<const Eigen::VectorXd>& hi, double acc_tolerance,
                            MaximiserChoiceScratch& s, Eigen::Index& ns) {
  const Eigen::Index k = K.rows();
  auto qdd_star = s.qdd_star.head(k);
  qdd_star = qdd0_stuck;
  qdd_star.noalias() -= K * mu;
  ns = 0;
  for (Eigen::Index a = 0; a < k; ++a)
    if (std::abs(qdd_star[a]) <= acc_tolerance) s.sticking[ns++] = static_cast<int>(a);
  if (ns == 0) return 0;  // every stuck joint slips: μ* is unique
  const auto sticking = s.sticking.head(ns);
  auto K_sticking = s.K_sticking.topLeftCorner(ns, ns);
  const int* sub = sticking.data();
  for (Eigen::Index b = 0; b < ns; ++b) {  // raw gathers of the lower triangle, all nearNullSpace reads
    const double* k_column = K.data() + sub[b] * K.outerStride();
    double* ks_column = K_sticking.data() + b * K_sticking.outerStride();
    for (Eigen::Index a = b; a < ns; ++a) ks_column[a] = k_column[sub[a]];
  }
  // Flat: a curvature that moves q̈ by at most the acceleration tolerance
  // across the box, shared among the ns directions.
  const double width = boxWidth(mu, lo, hi, sticking);
  const double floor = width > 0.0 ? acc_tolerance / (static_cast<double>(ns) * width) : 0.0;
  return nearNullSpace(K_sticking, floor, s.null_basis.topLeftCorner(ns, ns), s.pivots.head(ns));
}

bool leastEffortMaximiser(const Eigen::Ref<const Eigen::VectorXd>& lo, const Eigen::Ref<const Eigen::VectorXd>& hi,
                          const Eigen::Ref<const Eigen::VectorXd>& margin_limit,
                          const Eigen::Ref<const Eigen::VectorXd>& effort_offset, Eigen::Index ns, Eigen::Index nullity,
                          double mu_scale, int max_iterations, Eigen::Ref<Eigen::VectorXd> mu,
                          MaximiserChoiceScratch& s) {
  const auto N = s.null_basis.topLeftCorner(ns, nullity);
  const auto sticking = s.sticking.head(ns);
  auto mu_first = s.mu_first.head(ns), box_lo = s.lo.head(ns), box_hi = s.hi.head(ns);
  for (Eigen::Index t = 0; t < ns; ++t) {
    mu_first[t] = mu[sticking[t]];
    box_lo[t] = lo[sticking[t]];
    box_hi[t] = hi[sticking[t]];
  }
  const bool hyperplane = ns - nullity == 1;
  const double plane = hyperplane ? hyperplaneNormal(N, mu_first, s.curvature_direction.head(ns)) : 0.0;
  auto mu_chosen = s.mu_chosen.head(ns);
  auto target = s.target.head(ns);

  // (a) the smallest maximiser, as a reference point inside the set;
  mu_chosen = mu_first;
  target.setZero();
  moveClosestTo(ns, nullity, hyperplane, plane, max_iterations, s);
  // (b) on the set, τ_control of a sticking joint is h + μ: minimise ‖h + μ‖²
  //     within the margin box. Where the set cannot honour the margin (a limit
  //     stop carries any load) the reference point's value stays allowed.
  for (Eigen::Index t = 0; t < ns; ++t) {
    const Eigen::Index a = sticking[t];
    target[t] = -effort_offset[a];
    if (std::isfinite(box_lo[t])) box_lo[t] = std::max(box_lo[t], std::min(-margin_limit[a], mu_chosen[t]));
    if (std::isfinite(box_hi[t])) box_hi[t] = std::min(box_hi[t], std::max(margin_limit[a], mu_chosen[t]));
  }
  moveClosestTo(ns, nullity, hyperplane, plane, max_iterations, s);

  // Indeterminate: the maximisers form more than a point (in Λ, not the margin box).
  for (Eigen::Index t = 0; t < ns; ++t) {
    box_lo[t] = lo[sticking[t]];
    box_hi[t] = hi[sticking[t]];
  }
  bool indeterminate = (mu_chosen - mu_first).cwiseAbs().maxCoeff() > mu_scale;
  for (Eigen::Index e = 0; e < nullity && !indeterminate; ++e)
    indeterminate = roomAlong(mu_first, N.col(e), box_lo, box_hi) > mu_scale ||
                    roomAlong(mu_first, -N.col(e), box_lo, box_hi) > mu_scale;
  for (Eigen::Index t = 0; t < ns; ++t) mu[sticking[t]] = mu_chosen[t];
  return indeterminate;
}

}  // namespace zwang::internal
