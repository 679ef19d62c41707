// The friction maximiser's default method: a primal active-set method for
//   min φ(x) = ½ xᵀ P x − cᵀ x  over lo ≤ x ≤ hi,  P positive SEMI-definite.
// Each variable is free (in F) or fixed (on a bound, or where it is until it
// is released). Against the textbook primal active-set method for convex QPs
// (Nocedal & Wright, Numerical Optimization, §16.5), which assumes P positive
// definite and changes the working set by one index per iteration:
//  * P_FF is kept positive definite by construction: a variable joins F only
//    when its Schur pivot is a real curvature, and P_FF's Cholesky factor is
//    updated by one index (GrowingCholesky), so an iteration costs O(k²);
//  * a variable that depends on F (zero curvature: φ falls linearly along it)
//    is not added but moved, with F, along that zero-curvature direction to
//    the next bound (zeroCurvatureMove);
//  * warm start at the clamped Newton point of the largest regular F
//    (warmStart); a Newton step cut at a bound is replaced by Bertsekas'
//    projected Newton step when that is lower (several bounds at once), and
//    a release takes every variable whose gradient points into its room
//    (releaseVariables): few iterations even when the start is far;
//  * a variable running off along an infinite bound is reported unbounded
//    (the reach rule, kReach in src/qp/box_qp.hpp), but a zero-curvature
//    direction whose slope is rounding of its terms is flat, not unbounded
//    (roundingSlope): the variable stays, and is not released again until F
//    changes;
//  * where the caller gives the size of the terms P and c were computed from
//    (TermSizes), curvature and slope are measured against them too: a
//    column of P that is rounding throughout is tiny next to its terms, not
//    next to its own diagonal.
// Stages of one iteration (boxQpActiveSet): ∇φ; a Newton step on F unless F
// is stationary (newtonStep); else release the fixed variable with the most
// to gain (chooseRelease), or stop. Every test is relative to P's own
// diagonal (and to the terms' sizes, which scale alike), so the method does
// not care how the variables are scaled (friction torques from 1e-6 to 1e4
// N·m).
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <limits>

#include "qp/box_qp.hpp"

namespace zwang::internal {

namespace {

using MatrixRef = Eigen::Ref<const Eigen::MatrixXd>;
using VectorRef = Eigen::Ref<const Eigen::VectorXd>;
using VectorOut = Eigen::Ref<Eigen::VectorXd>;

constexpr double kInf = std::numeric_limits<double>::infinity();
// A Schur pivot at or below this fraction of P_jj is rounding: j depends on
// F. A pivot computed from entries of size P_jj carries an error of a few
// ε·P_jj·cond(P_FF); 1e-11 leaves room for cond(P_FF) up to ~1e4 before a
// true zero could pass as curvature, and no physical friction curvature is
// 1e-11 of the joint's own inertia term.
constexpr double kDependent = 1e-11;
// ∇φ_j is computed to within this multiple of ε·(Σ_l |P_jl| ‖x‖∞ + |c_j|):
// the worst-case bound γ_k ≈ k·ε of a k-term dot product for k ≤ 64, and far
// above the typical √k·ε beyond.
constexpr double kRounding = 64.0 * DBL_EPSILON;

// The problem, read-only, and the tolerance on the projected gradient.
struct Box {
  const MatrixRef& P;
  const VectorRef& c;
  const VectorRef& lo;
  const VectorRef& hi;
  double tolerance;
  const TermSizes& terms;
};

// value clamped to x_j's bounds.
double clampTo(const Box& box, Eigen::Index j, double value) { return std::min(box.hi[j], std::max(box.lo[j], value)); }

// Is `pivot`, the Schur pivot of adding j to F, a real curvature? Above
// rounding of P_jj, and of the terms P's column j was computed from where
// the caller knows them: a column that is rounding throughout (a joint the
// task holds still) has a P_jj as tiny as its pivot, and only its terms
// tell that both are rounding.
bool independent(const Box& box, double pivot, int j) {
  const bool terms_known = box.terms.curvature_of.size() == box.P.rows();
  return pivot > kDependent * box.P(j, j) && (!terms_known || pivot > kTermRounding * box.terms.curvature_of[j]);
}

// g = P x − c (P symmetric), and a bound on each entry's rounding from the
// absolute row sums of P (computed once).
void gradient(const Box& box, const VectorRef& x, ActiveSetScratch& s) {
  const Eigen::Index variables = x.size();
  auto g = s.gradient.head(variables);
  g.noalias() = box.P * x;
  g -= box.c;
  const double x_max = x.cwiseAbs().maxCoeff();
  for (Eigen::Index j = 0; j < variables; ++j)
    s.gradient_noise[j] = kRounding * (s.row_sums[j] * x_max + std::abs(box.c[j]));
}

// Room for x_j along the sign of `rate` (per unit of step), +∞ when unbounded.
double room(double x, double lo, double hi, double rate) {
  if (rate > 0) return (hi - x) / rate;
  if (rate < 0) return (lo - x) / rate;
  return kInf;
}

// How far F can move along `direction` (F's order) before its first bound:
// `alpha` comes in as the limit set elsewhere (1 for a Newton step) and goes
// out cut; the result is the blocking position in F, or −1 when none cut it.
int cutStep(const Box& box, const VectorRef& x, const GrowingCholesky& F, const Eigen::VectorXd& direction,
            double& alpha) {
  int blocking = -1;
  for (int a = 0; a < F.size(); ++a) {
    const int j = F.index(a);
    const double t = room(x[j], box.lo[j], box.hi[j], direction[a]);
    if (t < alpha) {
      alpha = std::max(0.0, t);
      blocking = a;
    }
  }
  return blocking;
}

// x_F ← clamp(x_F + alpha · direction) (the clamp only absorbs rounding).
void moveFree(const Box& box, const GrowingCholesky& F, const Eigen::VectorXd& direction, double alpha, VectorOut x) {
  for (int a = 0; a < F.size(); ++a) x[F.index(a)] = clampTo(box, F.index(a), x[F.index(a)] + alpha * direction[a]);
}

// The variable at F's `position`, which moved at `rate`, lands exactly on
// the bound it was moving to and leaves F.
void fixAtBound(const Box& box, int position, double rate, VectorOut x, ActiveSetScratch& s) {
  const int j = s.free_factor.index(position);
  x[j] = rate > 0 ? box.hi[j] : box.lo[j];
  s.free_factor.remove(position);
  s.fixed[j] = 1;
}

// The Newton step on F: step = −P_FF⁻¹ g_F (F's order).
void newtonDirection(const ActiveSetScratch& s, Eigen::VectorXd& step) {
  const GrowingCholesky& F = s.free_factor;
  for (int a = 0; a < F.size(); ++a) step[a] = -s.gradient[F.index(a)];
  F.solveInPlace(step.head(F.size()));
}

// After a step: has a free variable run off along an infinite bound
// (|x_j| > reach)? Then the report says which.
bool runAway(const GrowingCholesky& F, const VectorRef& x, double reach, QpReport& report) {
  for (int a = 0; a < F.size(); ++a)
    if (std::abs(x[F.index(a)]) > reach) {
      report.unbounded = true;
      report.unbounded_index = F.index(a);
      return true;
    }
  return false;
}

// F ← every non-fixed variable that keeps P_FF positive definite, in order;
// the dependent ones are fixed where they are.
void growFree(const Box& box, int variables, ActiveSetScratch& s) {
  GrowingCholesky& F = s.free_factor;
  F.clear();
  for (int j = 0; j < variables; ++j) {
    if (s.fixed[j]) continue;
    const double pivot = F.schurPivot(box.P, j);
    if (independent(box, pivot, j))
      F.append(j, pivot);
    else
      s.fixed[j] = 1;
  }
}

// Stage 1, warm start: the Newton point of the largest regular F, clamped to
// the box. When P is positive definite this is clamp(P⁻¹c), usually close to
// the optimal active set, so few iterations follow even for many variables.
// False when a variable ran away (the report says which).
bool warmStart(const Box& box, VectorOut x, ActiveSetScratch& s, double reach, QpReport& report) {
  const auto variables = static_cast<int>(x.size());
  GrowingCholesky& F = s.free_factor;
  for (int j = 0; j < variables; ++j) s.fixed[j] = box.lo[j] < box.hi[j] ? 0 : 1;  // a point box never moves
  s.flat.head(variables).setZero();
  growFree(box, variables, s);
  if (F.size() == 0) return true;
  gradient(box, x, s);
  newtonDirection(s, s.step);
  bool clamped = false;
  for (int a = 0; a < F.size(); ++a) {
    const int j = F.index(a);
    x[j] = clampTo(box, j, x[j] + s.step[a]);
    if (x[j] <= box.lo[j] || x[j] >= box.hi[j]) {
      s.fixed[j] = 1;
      clamped = true;
    }
  }
  if (runAway(F, x, reach, report)) return false;
  if (clamped) growFree(box, variables, s);
  return true;
}

// Is F away from stationarity: some |∇φ_j|, j ∈ F, above its rounding by
// more than the tolerance?
bool freeNotStationary(const Box& box, const ActiveSetScratch& s) {
  const GrowingCholesky& F = s.free_factor;
  double free_excess = 0.0;
  for (int a = 0; a < F.size(); ++a)
    free_excess = std::max(free_excess, std::abs(s.gradient[F.index(a)]) - s.gradient_noise[F.index(a)]);
  return F.size() > 0 && free_excess > box.tolerance;
}

// A Newton step p on F cut at α < 1 lowers φ by g_Fᵀp (α − α²/2)
// (P_FF p = −g_F). Is the projected full step clamp(x + p) lower still?
// φ(x + Δ) − φ(x) = gᵀΔ + ½ ΔᵀPΔ, Δ zero off F.
bool projectedStepIsBetter(const Box& box, const VectorRef& x, double alpha, ActiveSetScratch& s) {
  const GrowingCholesky& F = s.free_factor;
  const Eigen::Index variables = x.size();
  auto delta = s.delta.head(variables);
  delta.setZero();
  double gp = 0.0;
  for (int a = 0; a < F.size(); ++a) {
    const int j = F.index(a);
    gp += s.gradient[j] * s.step[a];
    delta[j] = clampTo(box, j, x[j] + s.step[a]) - x[j];
  }
  const double cut = gp * (alpha - 0.5 * alpha * alpha);
  auto P_delta = s.P_delta.head(variables);
  P_delta.noalias() = box.P * delta;
  return s.gradient.head(variables).dot(delta) + 0.5 * delta.dot(P_delta) < cut;
}

// Bertsekas' projected Newton step: x_F ← clamp(x_F + p), and every variable
// of F that lands on a bound leaves F (several in one iteration instead of
// one each).
void projectedNewtonStep(const Box& box, VectorOut x, ActiveSetScratch& s) {
  GrowingCholesky& F = s.free_factor;
  for (int a = F.size() - 1; a >= 0; --a) {
    const int j = F.index(a);
    x[j] = clampTo(box, j, x[j] + s.step[a]);
    if (x[j] <= box.lo[j] || x[j] >= box.hi[j]) {
      F.remove(a);
      s.fixed[j] = 1;
    }
  }
}

enum class NewtonOutcome { Full, Cut, Projected };

// Stage 2: the Newton step on F, cut at the first bound (which then leaves
// F), or projected when that is lower.
NewtonOutcome newtonStep(const Box& box, VectorOut x, ActiveSetScratch& s) {
  newtonDirection(s, s.step);
  double alpha = 1.0;
  const int blocking = cutStep(box, x, s.free_factor, s.step, alpha);
  if (blocking >= 0 && projectedStepIsBetter(box, x, alpha, s)) {
    projectedNewtonStep(box, x, s);
    return NewtonOutcome::Projected;
  }
  moveFree(box, s.free_factor, s.step, alpha, x);
  if (blocking < 0) return NewtonOutcome::Full;
  fixAtBound(box, blocking, s.step[blocking], x, s);
  return NewtonOutcome::Cut;
}

// Stage 3: the fixed variable with the most to gain (g_j²/P_jj, the decrease
// of φ it alone would give; a zero-curvature one first) among those whose
// gradient points into their room and that are not on a flat direction;
// −1 when none does (x is optimal).
int chooseRelease(const Box& box, const VectorRef& x, const ActiveSetScratch& s) {
  int release = -1;
  double best = -1.0;
  for (int j = 0; j < x.size(); ++j) {
    const double g = s.gradient[j];
    if (!s.fixed[j] || s.flat[j] || !pointsIntoRoom(g, s.gradient_noise[j], x[j], box.lo[j], box.hi[j], box.tolerance))
      continue;
    const double gain = box.P(j, j) > 0.0 ? g * g / box.P(j, j) : kInf;
    if (gain > best) {
      best = gain;
      release = j;
    }
  }
  return release;
}

// j (Schur pivot `pivot`, a real curvature) joins F: the next Newton step
// moves it. The others whose gradient points into their room join with it
// when they keep P_FF regular (the Newton step on the larger F still
// descends): one iteration instead of one each when the warm start fixed
// too many.
void releaseVariables(const Box& box, const VectorRef& x, int j, double pivot, ActiveSetScratch& s) {
  GrowingCholesky& F = s.free_factor;
  F.append(j, pivot);
  s.fixed[j] = 0;
  for (int i = 0; i < x.size(); ++i) {
    if (!s.fixed[i] || !pointsIntoRoom(s.gradient[i], s.gradient_noise[i], x[i], box.lo[i], box.hi[i], box.tolerance))
      continue;
    const double pivot_i = F.schurPivot(box.P, i);
    if (!independent(box, pivot_i, i)) continue;
    F.append(i, pivot_i);
    s.fixed[i] = 0;
  }
}

// Which variable runs off when the zero-curvature direction (d_j = dir, d_F)
// has no bound at all: the one moving fastest towards an infinite bound (j,
// at rate 1, unless a variable of F moves faster).
int unboundedIndex(const Box& box, int j, double dir, const GrowingCholesky& F, const Eigen::VectorXd& d) {
  int index = j;
  double largest = std::isfinite(dir > 0 ? box.hi[j] : box.lo[j]) ? 0.0 : 1.0;
  for (int a = 0; a < F.size(); ++a)
    if (std::abs(d[a]) > largest && !std::isfinite(d[a] > 0 ? box.hi[F.index(a)] : box.lo[F.index(a)])) {
      largest = std::abs(d[a]);
      index = F.index(a);
    }
  return index;
}

// Which variable a zero-curvature direction runs off with, or −1 when it
// meets a bound: none at all (α = ∞), or j only beyond `reach` (a bound of F
// that d_F, rounding where j's column is, meets ~1e15 away; a finite bound
// of j's own is within reach, kReach ≥ 1).
int runsOff(const Box& box, int j, double dir, double alpha, double reach, const VectorRef& x,
            const ActiveSetScratch& s) {
  if (!std::isfinite(alpha)) return unboundedIndex(box, j, dir, s.free_factor, s.direction);
  return std::abs(x[j] + alpha * dir) > reach ? j : -1;
}

enum class ZeroCurvature { Moved, Flat, Unbounded };

// Stage 3, zero curvature (j depends on F, the last schurPivot): d_j = ±1
// downhill, d_F = −P_FF⁻¹ P_Fj d_j keeps F stationary; φ falls linearly
// along d at the slope |g_j|, so go to the first bound, which leaves F (or
// stops j). Where there is none within reach, d is unbounded (the report
// says which variable runs off) if that slope is above the rounding of its
// terms (roundingSlope), and flat otherwise: j is marked and stays.
ZeroCurvature zeroCurvatureMove(const Box& box, int j, double reach, VectorOut x, ActiveSetScratch& s,
                                QpReport& report) {
  GrowingCholesky& F = s.free_factor;
  const double dir = s.gradient[j] > 0 ? -1.0 : 1.0;
  auto d = s.direction.head(F.size());
  F.nullDirection(d);
  d *= dir;
  double alpha = room(x[j], box.lo[j], box.hi[j], dir);
  const int blocking = cutStep(box, x, F, s.direction, alpha);  // −1: j itself
  const int off = runsOff(box, j, dir, alpha, reach, x, s);
  if (off >= 0 && std::abs(s.gradient[j]) <= roundingSlope(box.terms, x, j)) {
    s.flat[j] = 1;
    return ZeroCurvature::Flat;
  }
  if (off >= 0) {
    report.unbounded = true;
    report.unbounded_index = off;
    return ZeroCurvature::Unbounded;
  }
  moveFree(box, F, s.direction, alpha, x);
  if (blocking < 0) {
    x[j] = dir > 0 ? box.hi[j] : box.lo[j];
  } else {
    x[j] = clampTo(box, j, x[j] + alpha * dir);
    fixAtBound(box, blocking, s.direction[blocking], x, s);
  }
  return ZeroCurvature::Moved;
}

}  // namespace

QpReport boxQpActiveSet(const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& c,
                        const Eigen::Ref<const Eigen::VectorXd>& lo, const Eigen::Ref<const Eigen::VectorXd>& hi,
                        Eigen::Ref<Eigen::VectorXd> x, QpScratch& scratch, int max_iterations, double tolerance,
                        const TermSizes& terms) {
  if (x.size() == 0) return QpReport{0, 0.0, true};  // nothing to solve: converged
  QpReport report;
  const auto variables = static_cast<int>(x.size());
  ActiveSetScratch& s = scratch.active_set;
  const Box box{P, c, lo, hi, tolerance, terms};
  for (int j = 0; j < variables; ++j) s.row_sums[j] = P.col(j).cwiseAbs().sum();
  const double reach = kReach * reachScale(lo, hi, c, lambdaMaxBound(P), terms.curvature);
  if (!warmStart(box, x, s, reach, report)) {  // stage 1
    report.kkt_residual = boxQpKktResidual(P, c, lo, hi, x);
    return report;
  }
  int newton_in_a_row = 0;  // at most one refinement after a full step, whatever rounding leaves
  for (report.iterations = 0; report.iterations < max_iterations; ++report.iterations) {
    gradient(box, x, s);
    if (freeNotStationary(box, s) && newton_in_a_row < 2) {  // stage 2
      s.flat.head(variables).setZero();  // F moves: the slopes along zero-curvature directions change
      const NewtonOutcome step = newtonStep(box, x, s);
      newton_in_a_row = step == NewtonOutcome::Full ? newton_in_a_row + 1 : 0;
      if (step != NewtonOutcome::Projected && runAway(s.free_factor, x, reach, report)) break;
      continue;
    }
    newton_in_a_row = 0;
    const int j = chooseRelease(box, x, s);  // stage 3
    if (j < 0) {
      report.converged = true;
      break;
    }
    const double pivot = s.free_factor.schurPivot(P, j);
    if (independent(box, pivot, j)) {
      s.flat.head(variables).setZero();  // F grows: so do the directions of zero curvature
      releaseVariables(box, x, j, pivot, s);
      continue;
    }
    const ZeroCurvature move = zeroCurvatureMove(box, j, reach, x, s, report);
    if (move == ZeroCurvature::Unbounded || runAway(s.free_factor, x, reach, report)) break;
    if (move == ZeroCurvature::Moved) s.flat.head(variables).setZero();
  }
  report.kkt_residual = boxQpKktResidual(P, c, lo, hi, x);
  return report;
}

}  // namespace zwang::internal
