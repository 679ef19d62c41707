// Least-distance problems of the friction maximiser: which of several
// maximisers μ* + null(K_ΘΘ) to report (the one nearest a reference).
//  * leastDistanceQp: min ½‖z − a‖² s.t. lo ≤ x0 + N z ≤ hi (N any matrix:
//    an orthonormal null basis, or N L⁻ᵀ for the least effort where
//    contacts share the load, friction_maximisers.cpp), by the textbook
//    primal active-set method (Nocedal & Wright, Numerical Optimization,
//    §16.5) specialised to the identity Hessian: the subproblem on the
//    working rows W is z' = a − C_Wᵀ λ with (C_W C_Wᵀ) λ = C_W a − d_W, whose
//    Cholesky factor is grown one row at a time (GrowingCholesky), and the
//    two rows ±N_j of a joint share one ratio test (blockingRow). A blocking
//    row that looks dependent on W is rounding: the method stops there.
//  * leastDistanceOnHyperplane: the same when the set is one hyperplane in
//    the box, exactly, by walking the breakpoints of its one-dimensional dual
//    (as in the O(n log n) projections onto a simplex or a weighted box
//    slice) instead of the active set's n − 1 unknowns and 2n rows.
#include <algorithm>
#include <cmath>
#include <limits>

#include "qp/box_qp.hpp"

namespace zwang::internal {

namespace {

using MatrixRef = Eigen::Ref<const Eigen::MatrixXd>;
using VectorRef = Eigen::Ref<const Eigen::VectorXd>;
using Index = Eigen::Index;

// leastDistanceQp's tolerances, relative to the problem's scale
// 1 + ‖a‖∞ + ‖d‖∞ (the sizes z and the slacks are made of):
// the step to the subproblem's minimum is zero (and a multiplier negative)
// beyond rounding of a few hundred operations on numbers of that size;
constexpr double kStepZero = 1e-12;
// a joint whose rate along the step is below this is not moving (a rate of
// rounding would make a blocking row out of nothing);
constexpr double kRateFloor = 1e-15;
// a Schur pivot of C_W C_Wᵀ at or below this fraction of ‖row‖² is a row
// that depends on W (the same rule as the active set's kDependent).
constexpr double kRowDependent = 1e-11;
// leastDistanceOnHyperplane: f(0) within this of zero (relative to
// 1 + |b| + ‖t‖∞) is already the root; a walk that ends on the last
// breakpoint accepts a residual this small (the slice only touches the box).
constexpr double kRootAtZero = 1e-15;
constexpr double kTouchResidual = 1e-12;

// The constraint rows, each "row·z ≤ bound": for joint j, N_j z ≤ hi_j − x0_j
// and −N_j z ≤ x0_j − lo_j (rows with an infinite bound are skipped). Row r
// is kept as column r of s.rows (contiguous). Returns their number.
Index constraintRows(const MatrixRef& N, const VectorRef& x0, const VectorRef& lo, const VectorRef& hi,
                     LeastDistanceScratch& s) {
  const Index q = N.cols(), joints = N.rows();
  Index rows = 0;
  const double* n_data = N.data();  // N_j is strided: gathered element by element
  const Index n_stride = N.outerStride();
  for (Index j = 0; j < joints; ++j) {
    if (std::isfinite(hi[j])) {
      double* row_r = s.rows.col(rows).data();
      for (Index c = 0; c < q; ++c) row_r[c] = n_data[j + c * n_stride];
      s.row_bounds[rows++] = hi[j] - x0[j];
    }
    if (std::isfinite(lo[j])) {
      double* row_r = s.rows.col(rows).data();
      for (Index c = 0; c < q; ++c) row_r[c] = -n_data[j + c * n_stride];
      s.row_bounds[rows++] = x0[j] - lo[j];
    }
  }
  return rows;
}

// The multipliers of the working rows, λ_W = (C_W C_Wᵀ)⁻¹ (C_W a − d_W), and
// the step towards the subproblem's minimum z' = a − C_Wᵀ λ_W.
void subproblemStep(const VectorRef& a, const VectorRef& z, LeastDistanceScratch& s) {
  const GrowingCholesky& W = s.working_factor;
  const int nw = W.size();
  auto lam = s.multipliers.head(nw);
  for (int u = 0; u < nw; ++u) lam[u] = s.row_dot_a[W.index(u)] - s.row_bounds[W.index(u)];
  W.solveInPlace(lam);
  auto step = s.step.head(z.size());
  step = a - z;
  for (int u = 0; u < nw; ++u) step -= lam[u] * s.rows.col(W.index(u)).head(z.size());
}

// The working row with the most negative multiplier (below −tol), or −1 when
// every one is ≥ −tol: then z is optimal.
int rowToDrop(const LeastDistanceScratch& s, double tol) {
  int drop = -1;
  double most_negative = -tol;
  for (int u = 0; u < s.working_factor.size(); ++u)
    if (s.multipliers[u] < most_negative) {
      most_negative = s.multipliers[u];
      drop = u;
    }
  return drop;
}

// The ratio test along the step (rates s.rate = N·step of the k joints): `alpha`
// comes in as 1 and goes out cut at the first row outside W that the step
// reaches; the result is that row, or −1.
Index blockingRow(Index joints, const VectorRef& lo, const VectorRef& hi, double rate_floor,
                  const LeastDistanceScratch& s, double& alpha) {
  Index blocking = -1;
  for (Index j = 0, r = 0; j < joints; ++j) {
    const Index r_hi = std::isfinite(hi[j]) ? r++ : -1;  // the rows in the order they were made
    const Index r_lo = std::isfinite(lo[j]) ? r++ : -1;
    const double rate = s.rate[j];
    Index blocking_row = -1;
    double rate_j = 0.0, slack = 0.0;
    if (r_hi >= 0 && rate > rate_floor && !s.working[r_hi]) {
      blocking_row = r_hi;
      rate_j = rate;
      slack = hi[j] - s.point[j];
    } else if (r_lo >= 0 && -rate > rate_floor && !s.working[r_lo]) {
      blocking_row = r_lo;
      rate_j = -rate;
      slack = s.point[j] - lo[j];
    }
    if (blocking_row >= 0 && slack < alpha * rate_j) {  // t = slack/rate < α (divide only then)
      alpha = std::max(0.0, slack / rate_j);
      blocking = blocking_row;
    }
  }
  return blocking;
}

// Row b joins W, its Gram entries and C a computed now (a handful of
// iterations is usual, so most rows never need them). False when it depends
// on W: the step keeps W's rows at zero rate, so a blocking row is
// independent of them, and one that looks dependent is rounding.
bool addWorkingRow(const VectorRef& a, int b, LeastDistanceScratch& s) {
  const Index q = a.size();
  GrowingCholesky& W = s.working_factor;
  const auto row_b = s.rows.col(b).head(q);
  for (int u = 0; u < W.size(); ++u) s.gram(W.index(u), b) = s.rows.col(W.index(u)).head(q).dot(row_b);
  s.gram(b, b) = row_b.squaredNorm();
  s.row_dot_a[b] = row_b.dot(a);
  const double pivot = W.schurPivot(s.gram, b);
  if (!(pivot > kRowDependent * s.gram(b, b))) return false;
  W.append(b, pivot);
  s.working[b] = 1;
  return true;
}

}  // namespace

QpReport leastDistanceQp(const Eigen::Ref<const Eigen::MatrixXd>& N, const Eigen::Ref<const Eigen::VectorXd>& a,
                         const Eigen::Ref<const Eigen::VectorXd>& x0, const Eigen::Ref<const Eigen::VectorXd>& lo,
                         const Eigen::Ref<const Eigen::VectorXd>& hi, Eigen::Ref<Eigen::VectorXd> z, QpScratch& scratch,
                         int max_iterations) {
  QpReport report;
  LeastDistanceScratch& s = scratch.least_distance;
  const Index q = N.cols(), joints = N.rows();
  const Index rows = constraintRows(N, x0, lo, hi, s);  // stage 1
  // (No rows at all when every bound is infinite: nothing limits z.)
  const double scale =
      1.0 + (q > 0 ? a.cwiseAbs().maxCoeff() : 0.0) + (rows > 0 ? s.row_bounds.head(rows).cwiseAbs().maxCoeff() : 0.0);
  const double tol = kStepZero * scale;
  s.working_factor.clear();
  s.working.head(rows).setZero();
  // The point x0 + N z and the rate N·step of every joint: joint j's rows are
  // ±N_j, so one rate serves both, and the slacks are hi_j − y_j, y_j − lo_j.
  auto y = s.point.head(joints);
  auto rate = s.rate.head(joints);
  y = x0;
  for (Index c = 0; c < q; ++c) y += z[c] * N.col(c);
  for (report.iterations = 0; report.iterations < max_iterations; ++report.iterations) {
    subproblemStep(a, z, s);  // stage 2
    auto step = s.step.head(q);
    if (step.cwiseAbs().maxCoeff() <= tol) {  // stage 3: at the subproblem's minimum
      const int drop = rowToDrop(s, tol);
      if (drop < 0) {  // every multiplier ≥ 0: optimal
        report.converged = true;
        break;
      }
      s.working[s.working_factor.index(drop)] = 0;
      s.working_factor.remove(drop);
      continue;
    }
    rate.setZero();  // stage 4: towards it, up to the first row
    for (Index c = 0; c < q; ++c) rate += step[c] * N.col(c);
    double alpha = 1.0;
    const Index blocking = blockingRow(joints, lo, hi, kRateFloor * scale, s, alpha);
    z += alpha * step;
    y += alpha * rate;
    if (blocking >= 0 && !addWorkingRow(a, static_cast<int>(blocking), s)) break;
  }
  return report;
}

namespace {

// The terms of f(λ) = vᵀ clamp(t + λ v) − b in the walking direction σ:
// their breakpoints (where each enters or leaves the free range, as |λ|) into
// s, and the slope σ df/d|λ| and number of free terms just past λ = 0.
// Returns the number of breakpoints.
Index collectBreakpoints(const VectorRef& v, const VectorRef& t, const VectorRef& lo, const VectorRef& hi, double sigma,
                         HyperplaneScratch& s, double& slope, Index& free_terms) {
  Eigen::VectorXd& at = s.breakpoints;
  Eigen::VectorXi& kind = s.breakpoint_kind;
  Index breaks = 0;
  for (Index i = 0; i < v.size(); ++i) {
    const double rate = sigma * v[i];  // how the unclamped value moves per unit |λ|
    if (rate == 0.0) continue;
    const double value = t[i];
    // Free just past 0: not already at (or beyond) the bound it moves towards.
    const bool below = value<lo[i], above = value> hi[i];
    const bool free_now = rate > 0.0 ? (!below && value < hi[i]) : (!above && value > lo[i]);
    if (free_now) {
      slope += v[i] * v[i];
      ++free_terms;
    }
    // Where it enters: the near bound it comes from (only if outside now).
    if ((rate > 0.0 && below) || (rate < 0.0 && above)) {
      at[breaks] = ((rate > 0.0 ? lo[i] : hi[i]) - value) / rate;
      kind[breaks++] = static_cast<int>(2 * i + 1);
    }
    // Where it leaves: the far bound it moves towards.
    const double far = rate > 0.0 ? hi[i] : lo[i];
    if (std::isfinite(far) && (rate > 0.0 ? value < far : value > far)) {
      at[breaks] = (far - value) / rate;
      kind[breaks++] = static_cast<int>(2 * i);
    }
  }
  return breaks;
}

// Sorts the first `breaks` breakpoints by distance (insertion sort on the
// pairs: n is a handful of joints, and it allocates nothing).
void sortBreakpoints(Index breaks, HyperplaneScratch& s) {
  Eigen::VectorXd& at = s.breakpoints;
  Eigen::VectorXi& kind = s.breakpoint_kind;
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
}

// Walks the sorted breakpoints from |λ| = 0 until f has covered `target`
// (= |f(0)|): `position` is where, as |λ|. False when the slope ends before
// (the root, if any, is the last breakpoint).
bool walkBreakpoints(const VectorRef& v, const HyperplaneScratch& s, Index breaks, double target, double slope,
                     Index free_terms, double& position) {
  double covered = 0.0;
  for (Index a = 0; a <= breaks; ++a) {
    const double next = a < breaks ? s.breakpoints[a] : std::numeric_limits<double>::infinity();
    if (slope > 0.0 && covered + slope * (next - position) >= target) {
      position += (target - covered) / slope;
      return true;
    }
    if (a == breaks) break;
    covered += slope * (next - position);
    position = next;
    const Index i = s.breakpoint_kind[a] / 2;
    const bool enters = s.breakpoint_kind[a] % 2 == 1;
    slope += (enters ? 1.0 : -1.0) * v[i] * v[i];
    free_terms += enters ? 1 : -1;
    if (free_terms == 0 || slope < 0.0) slope = 0.0;  // rounding of the running sum
  }
  return false;
}

// f(λ) = vᵀ clamp(t + λ v) − b.
double hyperplaneResidual(const VectorRef& v, double b, const VectorRef& t, const VectorRef& lo, const VectorRef& hi,
                          double lambda) {
  double f = -b;
  for (Index i = 0; i < v.size(); ++i) f += v[i] * std::min(hi[i], std::max(lo[i], t[i] + lambda * v[i]));
  return f;
}

}  // namespace

bool leastDistanceOnHyperplane(const Eigen::Ref<const Eigen::VectorXd>& v, double b,
                               const Eigen::Ref<const Eigen::VectorXd>& t, const Eigen::Ref<const Eigen::VectorXd>& lo,
                               const Eigen::Ref<const Eigen::VectorXd>& hi, Eigen::Ref<Eigen::VectorXd> mu,
                               QpScratch& scratch) {
  // f(λ) is continuous and nondecreasing (term i grows with slope v_i² while
  // t_i + λ v_i is inside [lo_i, hi_i], else it is flat). From λ = 0 walk
  // the breakpoints towards the root.
  HyperplaneScratch& s = scratch.hyperplane;
  const double f = hyperplaneResidual(v, b, t, lo, hi, 0.0);
  const double scale = 1.0 + std::abs(b) + t.cwiseAbs().maxCoeff();
  double lambda = 0.0;
  if (std::abs(f) > kRootAtZero * scale) {
    // Walk up (f < 0) or down (f > 0): in the walking direction σ, term i
    // moves by σ v_i per unit of |λ|; it is free where lo_i < value < hi_i.
    const double sigma = f < 0.0 ? 1.0 : -1.0;
    double slope = 0.0;    // σ d f / d|λ|: Σ v_i² over the free terms just past 0
    Index free_terms = 0;  // (zero slope exactly when none is free)
    const Index breaks = collectBreakpoints(v, t, lo, hi, sigma, s, slope, free_terms);
    sortBreakpoints(breaks, s);
    double position = 0.0;
    const bool found = walkBreakpoints(v, s, breaks, std::abs(f), slope, free_terms, position);
    lambda = sigma * position;
    // The slice only touches the box (at the last breakpoint): accept up to rounding.
    if (!found && !(std::abs(hyperplaneResidual(v, b, t, lo, hi, lambda)) <= kTouchResidual * scale)) return false;
  }
  for (Index i = 0; i < v.size(); ++i) mu[i] = std::min(hi[i], std::max(lo[i], t[i] + lambda * v[i]));
  return true;
}

}  // namespace zwang::internal
