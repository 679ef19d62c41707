// The friction maximiser's default method: a primal active-set method for
//   min φ(x) = ½ xᵀ P x − cᵀ x  over lo ≤ x ≤ hi,  P positive SEMI-definite.
// Each variable is free (in F) or fixed (on a bound, or where it is until it
// is released). P_FF is kept positive definite, with its Cholesky factor
// updated by one index per iteration, so an iteration costs O(k²):
//  * a Newton step on F, cut at the first bound, which then leaves F;
//  * or, when F is stationary, the fixed variable whose gradient points most
//    into its room is released: it joins F when its Schur pivot is a real
//    curvature, and otherwise (it depends on F: zero curvature, φ falls
//    linearly) it moves, with F, along that zero-curvature direction to the
//    next bound.
// Every test is relative to P's own diagonal, so the method does not care
// how the variables are scaled (friction torques from 1e-6 to 1e4 N·m).
#include <cfloat>
#include <cmath>
#include <limits>

#include "internal/box_qp.hpp"

namespace zwang::internal {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// A Schur pivot at or below this fraction of P_jj is rounding: j depends on F.
constexpr double kDependent = 1e-11;
// ∇φ_j is computed to within this multiple of ε·(Σ_l |P_jl x_l| + |c_j|).
constexpr double kRounding = 64.0 * DBL_EPSILON;
// A variable with an infinite bound that travels this many times the
// problem's own scale, max(1, largest finite bound, ‖c‖∞/L) with L ≥ λ_max(P)
// (or the caller's curvature scale, when larger), is running off to infinity: its curvature is rounding (a zero computed as a
// tiny number next to P's other entries), not physics. The same rule as the
// projected gradient method's, so the two maximisers agree on what is
// unbounded.
constexpr double kReach = 1e12;

// g = P x − c (P symmetric), and a bound on each entry's rounding from the
// absolute row sums of P (computed once).
void gradient(const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& c,
              const Eigen::Ref<const Eigen::VectorXd>& x, const Eigen::Ref<const Eigen::VectorXd>& row_sums,
              Eigen::Ref<Eigen::VectorXd> g, Eigen::Ref<Eigen::VectorXd> noise) {
  g.noalias() = P * x;
  g -= c;
  const double x_max = x.cwiseAbs().maxCoeff();
  for (Eigen::Index j = 0; j < x.size(); ++j) noise[j] = kRounding * (row_sums[j] * x_max + std::abs(c[j]));
}

// Room for x_j along the sign of `rate` (per unit of step), +∞ when unbounded.
double room(double x, double lo, double hi, double rate) {
  if (rate > 0) return (hi - x) / rate;
  if (rate < 0) return (lo - x) / rate;
  return kInf;
}

}  // namespace

QpReport boxQpActiveSet(const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& c,
                        const Eigen::Ref<const Eigen::VectorXd>& lo, const Eigen::Ref<const Eigen::VectorXd>& hi,
                        Eigen::Ref<Eigen::VectorXd> x, QpScratch& s, int max_iterations, double tolerance,
                        double curvature_scale) {
  QpReport report;
  const auto k = static_cast<int>(x.size());
  if (k == 0) {
    report.converged = true;
    return report;
  }
  GrowingCholesky& F = s.factor;
  auto g = s.g.head(k);
  auto noise = s.lambda.head(k);
  auto fixed = s.fixed.head(k);
  auto row_sums = s.t2.head(k);
  for (int j = 0; j < k; ++j) row_sums[j] = P.col(j).cwiseAbs().sum();
  const auto independent = [&](double pivot, int j) { return pivot > kDependent * P(j, j); };
  const auto clampTo = [&](int j, double v) { x[j] = std::min(hi[j], std::max(lo[j], v)); };
  // λ_max(P) ≤ the smaller of Gershgorin's bound and the trace.
  const double x_scale = reachScale(lo, hi, c, std::min(row_sums.maxCoeff(), P.diagonal().sum()), curvature_scale);
  // After a step: has a free variable run off along an infinite bound?
  const auto runAway = [&] {
    for (int a = 0; a < F.size(); ++a)
      if (std::abs(x[F.index(a)]) > kReach * x_scale) {
        report.unbounded = true;
        report.unbounded_index = F.index(a);
        return true;
      }
    return false;
  };
  // F ← every non-fixed variable that keeps P_FF positive definite, in order;
  // the dependent ones are fixed where they are.
  const auto growFree = [&] {
    F.clear();
    for (int j = 0; j < k; ++j) {
      if (fixed[j]) continue;
      const double pivot = F.schurPivot(P, j);
      if (independent(pivot, j))
        F.append(j, pivot);
      else
        fixed[j] = 1;
    }
  };

  // Warm start: the Newton point of the largest regular F, clamped to the
  // box. When P is positive definite this is clamp(P⁻¹c), usually close to
  // the optimal active set, so few iterations follow even for many variables.
  for (int j = 0; j < k; ++j) fixed[j] = lo[j] < hi[j] ? 0 : 1;  // a point box never moves
  growFree();
  if (F.size() > 0) {
    gradient(P, c, x, row_sums, g, noise);
    auto step = s.p.head(F.size());
    for (int a = 0; a < F.size(); ++a) step[a] = -g[F.index(a)];
    F.solveInPlace(step);
    bool clamped = false;
    for (int a = 0; a < F.size(); ++a) {
      const int j = F.index(a);
      clampTo(j, x[j] + step[a]);
      if (x[j] <= lo[j] || x[j] >= hi[j]) {
        fixed[j] = 1;
        clamped = true;
      }
    }
    if (runAway()) {
      report.kkt_residual = boxQpKktResidual(P, c, lo, hi, x);
      return report;
    }
    if (clamped) growFree();
  }

  // A Newton step p on F cut at α < 1 lowers φ by g_Fᵀp (α − α²/2)
  // (P_FF p = −g_F). Is the projected full step clamp(x + p) lower still?
  // φ(x + Δ) − φ(x) = gᵀΔ + ½ ΔᵀPΔ, Δ zero off F.
  const auto projectedStepIsBetter = [&](double alpha) {
    const int nf = F.size();
    auto step = s.p.head(nf);
    auto delta = s.t1.head(k);
    delta.setZero();
    double gp = 0.0;
    for (int a = 0; a < nf; ++a) {
      const int j = F.index(a);
      gp += g[j] * step[a];
      delta[j] = std::min(hi[j], std::max(lo[j], x[j] + step[a])) - x[j];
    }
    const double cut = gp * (alpha - 0.5 * alpha * alpha);
    auto Pdelta = s.lambda.head(k);  // (noise is recomputed with the next gradient)
    Pdelta.noalias() = P * delta;
    return g.dot(delta) + 0.5 * delta.dot(Pdelta) < cut;
  };

  int newton_in_a_row = 0;
  for (report.iterations = 0; report.iterations < max_iterations; ++report.iterations) {
    gradient(P, c, x, row_sums, g, noise);
    const int nf = F.size();

    // ---- Newton step on F, unless F is stationary (to the tolerance; at
    // most one refinement after a full step, whatever rounding leaves).
    double free_excess = 0.0;
    for (int a = 0; a < nf; ++a) free_excess = std::max(free_excess, std::abs(g[F.index(a)]) - noise[F.index(a)]);
    if (nf > 0 && free_excess > tolerance && newton_in_a_row < 2) {
      auto step = s.p.head(nf);
      for (int a = 0; a < nf; ++a) step[a] = -g[F.index(a)];
      F.solveInPlace(step);
      double alpha = 1.0;
      int blocking = -1;
      for (int a = 0; a < nf; ++a) {
        const int j = F.index(a);
        const double t = room(x[j], lo[j], hi[j], step[a]);
        if (t < alpha) {
          alpha = std::max(0.0, t);
          blocking = a;
        }
      }
      if (blocking >= 0 && projectedStepIsBetter(alpha)) {
        // Bertsekas' projected Newton step: all of F's bounds met at once
        // (several variables fixed in one iteration instead of one each).
        for (int a = nf - 1; a >= 0; --a) {
          const int j = F.index(a);
          clampTo(j, x[j] + step[a]);
          if (x[j] <= lo[j] || x[j] >= hi[j]) {
            F.remove(a);
            fixed[j] = 1;
          }
        }
        newton_in_a_row = 0;
        continue;
      }
      for (int a = 0; a < nf; ++a) clampTo(F.index(a), x[F.index(a)] + alpha * step[a]);
      if (blocking >= 0) {
        const int j = F.index(blocking);
        x[j] = step[blocking] > 0 ? hi[j] : lo[j];  // exactly on the bound
        F.remove(blocking);
        fixed[j] = 1;
        newton_in_a_row = 0;
      } else {
        ++newton_in_a_row;
      }
      if (runAway()) break;
      continue;
    }
    newton_in_a_row = 0;

    // ---- F is stationary: release the fixed variable with the most to gain
    // (g_j²/P_jj, the decrease of φ it alone would give; a zero-curvature one
    // first), or stop when none has a gradient pointing into its room.
    int release = -1;
    double best = -1.0;
    for (int j = 0; j < k; ++j) {
      if (!fixed[j] || lo[j] == hi[j]) continue;
      const double into_room = x[j] >= hi[j] ? g[j] : x[j] <= lo[j] ? -g[j] : std::abs(g[j]);
      if (into_room - noise[j] <= tolerance) continue;
      const double gain = P(j, j) > 0.0 ? g[j] * g[j] / P(j, j) : kInf;
      if (gain > best) {
        best = gain;
        release = j;
      }
    }
    if (release < 0) {
      report.converged = true;
      break;
    }
    const int j = release;
    const double pivot = F.schurPivot(P, j);
    if (independent(pivot, j)) {  // a real curvature: the next Newton step moves it
      F.append(j, pivot);
      fixed[j] = 0;
      // Release the others whose gradient points into their room with it
      // (the Newton step on the larger F still descends): one iteration
      // instead of one each, when the warm start fixed too many.
      for (int i = 0; i < k; ++i) {
        if (!fixed[i] || lo[i] == hi[i]) continue;
        const double into_room = x[i] >= hi[i] ? g[i] : x[i] <= lo[i] ? -g[i] : std::abs(g[i]);
        if (into_room - noise[i] <= tolerance) continue;
        const double pivot_i = F.schurPivot(P, i);
        if (!independent(pivot_i, i)) continue;
        F.append(i, pivot_i);
        fixed[i] = 0;
      }
      continue;
    }
    // Zero curvature: d_j = ±1 downhill, d_F = −P_FF⁻¹ P_Fj d_j keeps F
    // stationary; φ falls linearly along d, so go to the first bound.
    const double dir = g[j] > 0 ? -1.0 : 1.0;
    auto d = s.t1.head(nf);
    F.nullDirection(d);
    d *= dir;
    double alpha = room(x[j], lo[j], hi[j], dir);
    int blocking = -1;  // −1: j itself
    for (int a = 0; a < nf; ++a) {
      const int i = F.index(a);
      const double t = room(x[i], lo[i], hi[i], d[a]);
      if (t < alpha) {
        alpha = std::max(0.0, t);
        blocking = a;
      }
    }
    if (!std::isfinite(alpha)) {  // downhill for ever: a bound at infinity
      report.unbounded = true;
      report.unbounded_index = j;
      double largest = std::isfinite(dir > 0 ? hi[j] : lo[j]) ? 0.0 : 1.0;
      for (int a = 0; a < nf; ++a)
        if (std::abs(d[a]) > largest && !std::isfinite(d[a] > 0 ? hi[F.index(a)] : lo[F.index(a)])) {
          largest = std::abs(d[a]);
          report.unbounded_index = F.index(a);
        }
      break;
    }
    for (int a = 0; a < nf; ++a) clampTo(F.index(a), x[F.index(a)] + alpha * d[a]);
    if (blocking < 0) {
      x[j] = dir > 0 ? hi[j] : lo[j];
    } else {
      clampTo(j, x[j] + alpha * dir);
      const int i = F.index(blocking);
      x[i] = d[blocking] > 0 ? hi[i] : lo[i];
      F.remove(blocking);
      fixed[i] = 1;
    }
    if (runAway()) break;
  }
  report.kkt_residual = boxQpKktResidual(P, c, lo, hi, x);
  return report;
}

}  // namespace zwang::internal
