#include "internal/box_qp.hpp"

#include <cmath>
#include <limits>


namespace zwang::internal {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
using Index = Eigen::Index;
}  // namespace

QpScratch::QpScratch(int n)
    : lambda(n),
      g(n),
      p(n),
      t1(n),
      t2(n),
      Px(n),
      Px_prev(n),
      Py(n),
      Ct(n, 2 * n),
      d(2 * n),
      fixed(n),
      gram(2 * n, 2 * n),
      Ca(2 * n),
      active(2 * n),
      factor(n),
      row_factor(2 * n) {}

namespace {
// How far ∇φ_j = g violates optimality at x_j, in the units of ∇φ
// (accelerations), whatever the units of x: a free variable's gradient, a
// bounded one's gradient pointing into its room.
double kktViolation(double g, double x, double lo, double hi) {
  return lo == hi ? 0.0 : x <= lo ? -g : x >= hi ? g : std::abs(g);
}
}  // namespace

double reachScale(const Eigen::Ref<const Eigen::VectorXd>& lo, const Eigen::Ref<const Eigen::VectorXd>& hi,
                  const Eigen::Ref<const Eigen::VectorXd>& c, double lambda_max_bound, double curvature_scale) {
  double scale = 1.0;
  for (Index j = 0; j < lo.size(); ++j) {
    if (std::isfinite(lo[j])) scale = std::max(scale, std::abs(lo[j]));
    if (std::isfinite(hi[j])) scale = std::max(scale, std::abs(hi[j]));
  }
  const double curvature = std::max(lambda_max_bound, curvature_scale);
  if (curvature > 0.0 && c.size() > 0) scale = std::max(scale, c.cwiseAbs().maxCoeff() / curvature);
  return scale;
}

double boxQpKktResidual(const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& c,
                        const Eigen::Ref<const Eigen::VectorXd>& lo, const Eigen::Ref<const Eigen::VectorXd>& hi,
                        const Eigen::Ref<const Eigen::VectorXd>& x) {
  double r = 0.0;
  for (Index j = 0; j < x.size(); ++j)  // P symmetric: its contiguous column
    r = std::max(r, kktViolation(P.col(j).dot(x) - c[j], x[j], lo[j], hi[j]));
  return r;
}

QpReport boxQpProjectedGradient(const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& c,
                                const Eigen::Ref<const Eigen::VectorXd>& lo, const Eigen::Ref<const Eigen::VectorXd>& hi,
                                Eigen::Ref<Eigen::VectorXd> x, QpScratch& s, int max_iterations, double tolerance,
                                double curvature_scale) {
  QpReport report;
  const Index k = x.size();
  if (k == 0) {
    report.converged = true;
    return report;
  }
  auto clamp = [&](Eigen::Ref<Eigen::VectorXd> v) {
    for (Index j = 0; j < k; ++j) v[j] = std::min(hi[j], std::max(lo[j], v[j]));
  };
  // Lipschitz constant of ∇φ: an upper bound of λ_max(P) in O(k²), the
  // smaller of Gershgorin's (largest absolute row sum) and the trace (P is
  // positive semi-definite), rather than an O(k³) eigen-decomposition.
  double gershgorin = 0.0;
  for (Index j = 0; j < k; ++j) gershgorin = std::max(gershgorin, P.row(j).cwiseAbs().sum());
  const double L = std::max(0.0, std::min(gershgorin, P.diagonal().sum()));
  if (L <= 1e-12 * std::max(1.0, c.cwiseAbs().maxCoeff()) && L <= 1e-300 + 1e-12 * P.cwiseAbs().maxCoeff()) {
    // φ is linear: each variable goes to the bound its gradient points away from.
    for (Index j = 0; j < k; ++j) {
      x[j] = c[j] > 0 ? hi[j] : c[j] < 0 ? lo[j] : std::min(hi[j], std::max(lo[j], 0.0));
      if (!std::isfinite(x[j])) {
        report.unbounded = true;
        report.unbounded_index = static_cast<int>(j);
        x[j] = 0.0;
      }
    }
    report.converged = !report.unbounded;
    report.kkt_residual = report.unbounded ? kInf : boxQpKktResidual(P, c, lo, hi, x);
    return report;
  }
  // Steps in the metric of P's diagonal (Jacobi preconditioning): the box
  // stays a box, so the projection is still the clamp, and along a chain
  // whose joints' inertias differ by orders of magnitude the scaled problem
  // D^-1/2 P D^-1/2 is far better conditioned. A zero diagonal (a linear
  // variable) gets a tiny one: it moves straight to its bound.
  auto inverse_d = s.lambda.head(k);
  const double d_floor = 1e-12 * P.diagonal().maxCoeff();
  for (Index j = 0; j < k; ++j) inverse_d[j] = 1.0 / std::max(P(j, j), d_floor);
  // L̃ ≥ λ_max(D^-1/2 P D^-1/2): Gershgorin of the scaled matrix, or its trace (≤ k).
  auto root_inverse_d = s.p.head(k);  // (p is free until the iterations)
  root_inverse_d = inverse_d.cwiseSqrt();
  double scaled_gershgorin = 0.0;
  for (Index j = 0; j < k; ++j)
    scaled_gershgorin =
        std::max(scaled_gershgorin, P.col(j).cwiseAbs().dot(root_inverse_d) * root_inverse_d[j]);
  double scaled_trace = 0.0;  // (a diagonal that is rounding may come out negative)
  for (Index j = 0; j < k; ++j) scaled_trace += std::max(0.0, P(j, j)) * inverse_d[j];
  const double scaled_L = scaled_trace > 0.0 ? std::min(scaled_gershgorin, scaled_trace) : scaled_gershgorin;
  const double step = 1.0 / scaled_L;
  const double x_scale = reachScale(lo, hi, c, L, curvature_scale);
  auto y = s.t1.head(k);       // extrapolated point
  auto x_prev = s.t2.head(k);  // previous iterate
  // One product with P per iteration: P x for the optimality test, and
  // P y = (1 + β) P x − β P x_prev by linearity instead of a second product.
  auto Px = s.Px.head(k), Px_prev = s.Px_prev.head(k), Py = s.Py.head(k);
  y = x;
  x_prev = x;
  Px.noalias() = P * x;
  Px_prev = Px;
  Py = Px;
  double t = 1.0;
  const auto kktAtX = [&] {
    double r = 0.0;
    for (Index j = 0; j < k; ++j) r = std::max(r, kktViolation(Px[j] - c[j], x[j], lo[j], hi[j]));
    return r;
  };
  for (report.iterations = 0; report.iterations < max_iterations; ++report.iterations) {
    s.g.head(k) = Py - c;
    x = y - step * inverse_d.cwiseProduct(s.g.head(k));
    clamp(x);
    if (x.cwiseAbs().maxCoeff() > 1e12 * x_scale) {  // running off along an infinite bound
      report.unbounded = true;
      Index worst = 0;
      for (Index j = 1; j < k; ++j)
        if (std::abs(x[j]) > std::abs(x[worst])) worst = j;
      report.unbounded_index = static_cast<int>(worst);
      break;
    }
    Px.noalias() = P * x;
    if (kktAtX() <= tolerance) {
      report.converged = true;
      ++report.iterations;  // count this gradient step
      break;
    }
    // FISTA momentum, restarted when it stops helping (gradient test).
    const double t_next = 0.5 * (1.0 + std::sqrt(1.0 + 4.0 * t * t));
    s.p.head(k) = x - x_prev;
    if (s.g.head(k).dot(s.p.head(k)) > 0.0) {
      t = 1.0;
      y = x;
      Py = Px;
    } else {
      const double beta = (t - 1.0) / t_next;
      y = x + beta * s.p.head(k);
      Py = (1.0 + beta) * Px - beta * Px_prev;
      t = t_next;
    }
    x_prev = x;
    Px_prev = Px;
  }
  report.kkt_residual = report.unbounded ? kInf : boxQpKktResidual(P, c, lo, hi, x);
  return report;
}

QpReport leastDistanceQp(const Eigen::Ref<const Eigen::MatrixXd>& N, const Eigen::Ref<const Eigen::VectorXd>& a,
                         const Eigen::Ref<const Eigen::VectorXd>& x0, const Eigen::Ref<const Eigen::VectorXd>& lo,
                         const Eigen::Ref<const Eigen::VectorXd>& hi, Eigen::Ref<Eigen::VectorXd> z, QpScratch& s,
                         int max_iterations) {
  // Constraint rows, each "row·z ≤ bound": for joint j, N_j z ≤ hi_j − x0_j and
  // −N_j z ≤ x0_j − lo_j (rows with an infinite bound are skipped). Row r is
  // kept as column r of Ct (contiguous).
  QpReport report;
  const Index q = N.cols(), k = N.rows();
  Index rows = 0;
  const double* n_data = N.data();  // N_j is strided: gathered element by element
  const Index n_stride = N.outerStride();
  for (Index j = 0; j < k; ++j) {
    if (std::isfinite(hi[j])) {
      double* row_r = s.Ct.col(rows).data();
      for (Index c = 0; c < q; ++c) row_r[c] = n_data[j + c * n_stride];
      s.d[rows++] = hi[j] - x0[j];
    }
    if (std::isfinite(lo[j])) {
      double* row_r = s.Ct.col(rows).data();
      for (Index c = 0; c < q; ++c) row_r[c] = -n_data[j + c * n_stride];
      s.d[rows++] = x0[j] - lo[j];
    }
  }
  // (No rows at all when every bound is infinite: nothing limits z.)
  const double scale = 1.0 + (q > 0 ? a.cwiseAbs().maxCoeff() : 0.0) +
                       (rows > 0 ? s.d.head(rows).cwiseAbs().maxCoeff() : 0.0);
  const double tol = 1e-12 * scale;
  const auto row = [&](Index r) { return s.Ct.col(r).head(q); };
  // The working rows W keep a Cholesky factor of C_W C_Wᵀ updated by one row
  // at a time, so an iteration costs O(rows·q + |W|²). The Gram entries and
  // C a are computed as rows join W (a handful of iterations is usual).
  auto G = s.gram.topLeftCorner(rows, rows);
  auto Ca = s.Ca.head(rows);
  GrowingCholesky& W = s.row_factor;
  W.clear();
  auto active = s.active.head(rows);
  active.setZero();
  // The point x0 + N z and the rate N·step of every joint: joint j's rows are
  // ±N_j, so one rate serves both, and the slacks are hi_j − y_j, y_j − lo_j.
  auto y = s.t2.head(k);
  auto rate = s.g.head(k);
  y = x0;
  for (Index c = 0; c < q; ++c) y += z[c] * N.col(c);
  for (report.iterations = 0; report.iterations < max_iterations; ++report.iterations) {
    // Minimise ½‖z' − a‖² with C_W z' = d_W:  z' = a − C_Wᵀ λ,  (C_W C_Wᵀ) λ = C_W a − d_W.
    const int nw = W.size();
    auto lam = s.p.head(nw);
    for (int u = 0; u < nw; ++u) lam[u] = Ca[W.index(u)] - s.d[W.index(u)];
    W.solveInPlace(lam);
    // Candidate z' and the step towards it.
    auto step = s.t1.head(q);
    step = a - z;
    for (int u = 0; u < nw; ++u) step -= lam[u] * row(W.index(u));
    if (step.cwiseAbs().maxCoeff() <= tol) {
      // At the subproblem's minimum: optimal when every multiplier is ≥ 0.
      int drop = -1;
      double most_negative = -tol;
      for (int u = 0; u < nw; ++u)
        if (lam[u] < most_negative) {
          most_negative = lam[u];
          drop = u;
        }
      if (drop < 0) {
        report.converged = true;
        break;
      }
      active[W.index(drop)] = 0;
      W.remove(drop);
      continue;
    }
    double alpha = 1.0;
    Index blocking = -1;
    rate.setZero();
    for (Index c = 0; c < q; ++c) rate += step[c] * N.col(c);
    const double rate_floor = 1e-15 * scale;
    for (Index j = 0, r = 0; j < k; ++j) {
      const Index r_hi = std::isfinite(hi[j]) ? r++ : -1;  // the rows in the order they were made
      const Index r_lo = std::isfinite(lo[j]) ? r++ : -1;
      Index blocking_row = -1;
      double rate_j = 0.0, slack = 0.0;
      if (r_hi >= 0 && rate[j] > rate_floor && !active[r_hi]) {
        blocking_row = r_hi;
        rate_j = rate[j];
        slack = hi[j] - y[j];
      } else if (r_lo >= 0 && -rate[j] > rate_floor && !active[r_lo]) {
        blocking_row = r_lo;
        rate_j = -rate[j];
        slack = y[j] - lo[j];
      }
      if (blocking_row >= 0 && slack < alpha * rate_j) {  // t = slack/rate < α (divide only then)
        alpha = std::max(0.0, slack / rate_j);
        blocking = blocking_row;
      }
    }
    z += alpha * step;
    y += alpha * rate;
    if (blocking >= 0) {
      // A blocking row is independent of the working rows (the step keeps
      // those at zero rate); one that looks dependent is rounding: stop there.
      const auto b = static_cast<int>(blocking);
      for (int u = 0; u < W.size(); ++u) G(W.index(u), b) = row(W.index(u)).dot(row(b));
      G(b, b) = row(b).squaredNorm();
      Ca[b] = row(b).dot(a);
      const double pivot = W.schurPivot(G, b);
      if (!(pivot > 1e-11 * G(b, b))) break;
      W.append(b, pivot);
      active[b] = 1;
    }
  }
  return report;
}

bool leastDistanceOnHyperplane(const Eigen::Ref<const Eigen::VectorXd>& v, double b,
                               const Eigen::Ref<const Eigen::VectorXd>& t, const Eigen::Ref<const Eigen::VectorXd>& lo,
                               const Eigen::Ref<const Eigen::VectorXd>& hi, Eigen::Ref<Eigen::VectorXd> mu, QpScratch& s) {
  // f(λ) = vᵀ clamp(t + λ v) − b is continuous and nondecreasing (term i
  // grows with slope v_i² while t_i + λ v_i is inside [lo_i, hi_i], else it
  // is flat). From λ = 0 walk the breakpoints towards the root.
  const Index n = v.size();
  const auto clampAt = [&](Index i, double lambda) { return std::min(hi[i], std::max(lo[i], t[i] + lambda * v[i])); };
  double f = -b;
  for (Index i = 0; i < n; ++i) f += v[i] * clampAt(i, 0.0);
  const double scale = 1.0 + std::abs(b) + t.cwiseAbs().maxCoeff();
  double lambda = 0.0;
  if (std::abs(f) > 1e-15 * scale) {
    // Walk up (f < 0) or down (f > 0): in the walking direction σ, term i
    // moves by σ v_i per unit of |λ|; it is free where lo_i < value < hi_i.
    const double sigma = f < 0.0 ? 1.0 : -1.0;
    double slope = 0.0;  // σ d f / d|λ|: Σ v_i² over the free terms just past 0
    Index free_terms = 0;  // (zero slope exactly when none is free)
    Index breaks = 0;
    auto at = s.d;          // 2n breakpoint distances |λ|
    auto kind = s.active;   // 2i + (1 when term i becomes free there, 0 when it stops)
    for (Index i = 0; i < n; ++i) {
      const double rate = sigma * v[i];  // how the unclamped value moves per unit |λ|
      if (rate == 0.0) continue;
      const double value = t[i];
      // Free just past 0: not already at (or beyond) the bound it moves towards.
      const bool below = value < lo[i], above = value > hi[i];
      const bool free_now = rate > 0.0 ? (!below && value < hi[i]) : (!above && value > lo[i]);
      if (free_now) {
        slope += v[i] * v[i];
        ++free_terms;
      }
      // Where it enters: the near bound it comes from (only if outside now).
      if (rate > 0.0 && below) {
        at[breaks] = (lo[i] - value) / rate;
        kind[breaks++] = static_cast<int>(2 * i + 1);
      }
      if (rate < 0.0 && above) {
        at[breaks] = (hi[i] - value) / rate;
        kind[breaks++] = static_cast<int>(2 * i + 1);
      }
      // Where it leaves: the far bound it moves towards.
      const double far = rate > 0.0 ? hi[i] : lo[i];
      if (std::isfinite(far) && (rate > 0.0 ? value < far : value > far)) {
        at[breaks] = (far - value) / rate;
        kind[breaks++] = static_cast<int>(2 * i);
      }
    }
    // Sort the breakpoints by distance (insertion sort on the pairs: n is a
    // handful of joints, and it allocates nothing).
    for (Index a = 1; a < breaks; ++a) {
      const double key = at[a];
      const int key_kind = kind[a];
      Index c = a - 1;
      while (c >= 0 && at[c] > key) {
        at[c + 1] = at[c];
        kind[c + 1] = kind[c];
        --c;
      }
      at[c + 1] = key;
      kind[c + 1] = key_kind;
    }
    const double target = std::abs(f);  // distance to cover, in units of f
    double covered = 0.0, position = 0.0;
    bool found = false;
    for (Index a = 0; a <= breaks && !found; ++a) {
      const double next = a < breaks ? at[a] : std::numeric_limits<double>::infinity();
      if (slope > 0.0 && covered + slope * (next - position) >= target) {
        position += (target - covered) / slope;
        found = true;
        break;
      }
      if (a == breaks) break;
      covered += slope * (next - position);
      position = next;
      const Index i = kind[a] / 2;
      const bool enters = kind[a] % 2 == 1;
      slope += (enters ? 1.0 : -1.0) * v[i] * v[i];
      free_terms += enters ? 1 : -1;
      if (free_terms == 0 || slope < 0.0) slope = 0.0;  // rounding of the running sum
    }
    lambda = sigma * position;
    if (!found) {  // the slice only touches the box (at the last breakpoint): accept up to rounding
      double residual = -b;
      for (Index i = 0; i < n; ++i) residual += v[i] * clampAt(i, lambda);
      if (!(std::abs(residual) <= 1e-12 * scale)) return false;
    }
  }
  for (Index i = 0; i < n; ++i) mu[i] = clampAt(i, lambda);
  return true;
}

}  // namespace zwang::internal
