// The friction maximiser's alternative method: accelerated projected
// gradient for  min φ(x) = ½ xᵀ P x − cᵀ x  over lo ≤ x ≤ hi,  P positive
// SEMI-definite. Against textbook FISTA (Beck & Teboulle 2009) with its
// adaptive restart (O'Donoghue & Candès 2015):
//  * steps in the metric of P's diagonal D (Jacobi preconditioning): the box
//    stays a box, so the projection is still the clamp, and the step 1/L̃
//    uses L̃ ≥ λ_max(D^-1/2 P D^-1/2), a Gershgorin or trace bound in O(k²)
//    rather than an eigen-decomposition (jacobiMetric, lambdaMaxBound);
//  * one product with P per iteration: P y = (1 + β) P x − β P x_previous by
//    linearity;
//  * the stopping test is the KKT violation in the units of ∇φ
//    (kktViolation), not a change in x;
//  * a linear variable (P_jj zero to rounding of its terms, where the caller
//    gives them: TermSizes) goes straight to the bound its gradient points
//    to, or stays where that bound is infinite and the gradient within
//    rounding (a flat direction, as in the active set) (linearVertex); the
//    iterations do not step it but send it to the other bound when their
//    motion turns its gradient (followLinear: P is semi-definite only to
//    rounding, so its column need not be); a linear problem (P = 0 to
//    rounding) is solved so entirely;
//  * a variable running off along an infinite bound is reported unbounded
//    (the reach rule, kReach in src/qp/box_qp.hpp).
#include <algorithm>
#include <cmath>
#include <limits>

#include "qp/box_qp.hpp"

namespace zwang::internal {

namespace {

using MatrixRef = Eigen::Ref<const Eigen::MatrixXd>;
using VectorRef = Eigen::Ref<const Eigen::VectorXd>;
using Index = Eigen::Index;

constexpr double kInf = std::numeric_limits<double>::infinity();
// P counts as zero (φ linear) when its λ_max bound is below this fraction of
// ‖c‖∞ (no step would move a variable by a visible amount before it hits a
// bound) and of its own largest entry (it is rounding throughout); 1e-300
// keeps an exactly zero P on that side.
constexpr double kLinear = 1e-12;
constexpr double kTiny = 1e-300;
// A zero (or rounding) diagonal entry of P is raised to this fraction of the
// largest: the variable is nearly linear and moves straight to its bound.
constexpr double kDiagonalFloor = 1e-12;

using Segment = Eigen::VectorBlock<Eigen::VectorXd>;

// The scratch as the iterations use it, k entries each, taken once per
// solve (the loop then indexes them without re-deriving the views).
struct Iterates {
  Segment inverse_d, gradient, y, x_previous, x_change, Px, Px_previous, Py;
};

// x ← clamp(x) to the box.
void clampToBox(const VectorRef& lo, const VectorRef& hi, Eigen::Ref<Eigen::VectorXd>& x) {
  for (Index j = 0; j < x.size(); ++j) x[j] = std::min(hi[j], std::max(lo[j], x[j]));
}

// Is x_j a linear variable: its column of P rounding of the terms it was
// computed from (P_jj at most kTermRounding of them), where the caller knows
// them? The diagonal speaks for the column only where P is positive
// semi-definite; behind a singular task's balance K_ΘΘ is so only roughly,
// and its column may still couple x_j to the others (followLinear).
bool linearVariable(const MatrixRef& P, const TermSizes& terms, Index j) {
  return terms.curvature_of.size() == P.rows() && P(j, j) <= kTermRounding * terms.curvature_of[j];
}

// Is φ linear: P = 0 to rounding of its own entries (kLinear, beside
// ‖c‖∞), or every variable linear?
bool linear(const MatrixRef& P, const VectorRef& c, double L, const TermSizes& terms) {
  if (L <= kLinear * std::max(1.0, c.cwiseAbs().maxCoeff()) && L <= kTiny + kLinear * P.cwiseAbs().maxCoeff())
    return true;
  for (Index j = 0; j < P.rows(); ++j)
    if (!linearVariable(P, terms, j)) return false;
  return true;
}

// Stage 0, the linear variables (all of them when φ is linear): each goes to
// the bound its gradient −c_j points to; towards an infinite one it is
// unbounded (reported), unless c_j is within the tolerance or the rounding
// of its terms (roundingSlope): that direction is flat, and x_j stays. The
// iterations then leave them there. False when one is unbounded.
bool linearVertex(const MatrixRef& P, const VectorRef& c, const VectorRef& lo, const VectorRef& hi, bool all,
                  const TermSizes& terms, double tolerance, Eigen::Ref<Eigen::VectorXd> x, QpReport& report) {
  for (Index j = 0; j < x.size(); ++j) {
    if (!all && !linearVariable(P, terms, j)) continue;
    const double bound = c[j] > 0 ? hi[j] : c[j] < 0 ? lo[j] : x[j];
    const bool flat = std::abs(c[j]) <= tolerance + roundingSlope(terms, x, j);
    if (std::isfinite(bound)) {
      x[j] = bound;
    } else if (!flat && !report.unbounded) {
      report.unbounded = true;
      report.unbounded_index = static_cast<int>(j);
    }
  }
  return !report.unbounded;
}

// Stage 1, the metric: D⁻¹ (inverse_diagonal) and the step 1/L̃ with
// L̃ ≥ λ_max(D^-1/2 P D^-1/2), Gershgorin of the scaled matrix or its trace
// (≤ k), whichever is smaller. A linear variable does not move (D⁻¹ = 0:
// stage 0 placed it), and a diagonal entry at rounding level of P's largest
// is raised to it (that variable is nearly linear, and 1/rounding would
// fling it).
double jacobiMetric(const MatrixRef& P, const TermSizes& terms, ProjectedGradientScratch& s) {
  const Index variables = P.rows();
  auto inverse_d = s.inverse_diagonal.head(variables);
  const double d_floor = kDiagonalFloor * P.diagonal().maxCoeff();
  for (Index j = 0; j < variables; ++j)
    inverse_d[j] = linearVariable(P, terms, j) ? 0.0 : 1.0 / std::max(P(j, j), d_floor);
  auto root_inverse_d = s.root_inverse_diagonal.head(variables);
  root_inverse_d = inverse_d.cwiseSqrt();
  return 1.0 / lambdaMaxBound(P, root_inverse_d);
}

// max_j kktViolation at x over the variables that move (stage 0 settled the
// linear ones), from P x already computed.
double kktAt(const Segment& Px, const VectorRef& c, const VectorRef& lo, const VectorRef& hi,
             const Eigen::Ref<Eigen::VectorXd>& x, const Segment& inverse_d) {
  double r = 0.0;
  for (Index j = 0; j < x.size(); ++j)
    if (inverse_d[j] > 0.0) r = std::max(r, kktViolation(Px[j] - c[j], x[j], lo[j], hi[j]));
  return r;
}

// Stage 3a, the linear variables again: stage 0 placed each by c_j alone,
// which is right while its column of P is rounding. Where it is not (K_ΘΘ
// behind a singular task's balance is positive semi-definite only roughly:
// a diagonal entry at rounding or below zero beside real off-diagonal ones),
// the others' motion turns ∇φ_j = (P x)_j − c_j; once it points into x_j's
// room beyond the tolerance, x_j goes to the bound it now points to (P x
// updated), as stage 0 would send it. Towards an infinite bound it is
// unbounded, unless the slope is rounding of its terms (roundingSlope): flat,
// x_j stays, as in stage 0. True when one moved (the iterations go on from
// there); false otherwise (report.unbounded says whether one ran off).
bool followLinear(const MatrixRef& P, const VectorRef& c, const VectorRef& lo, const VectorRef& hi,
                  const TermSizes& terms, double tolerance, Eigen::Ref<Eigen::VectorXd> x, Iterates& v,
                  QpReport& report) {
  bool moved = false;
  for (Index j = 0; j < x.size(); ++j) {
    if (v.inverse_d[j] > 0.0 || lo[j] == hi[j]) continue;  // moves with the iterations, or cannot move
    const double g = v.Px[j] - c[j];
    const double violation = kktViolation(g, x[j], lo[j], hi[j]);
    if (violation <= tolerance) continue;
    const double bound = g < 0.0 ? hi[j] : lo[j];
    if (!std::isfinite(bound)) {
      if (violation <= tolerance + roundingSlope(terms, x, j)) continue;  // flat
      report.unbounded = true;
      report.unbounded_index = static_cast<int>(j);
      return false;
    }
    v.Px += P.col(j) * (bound - x[j]);
    x[j] = bound;
    moved = true;
  }
  return moved;
}

// The variable farthest out (the one that ran away).
int farthest(const Eigen::Ref<Eigen::VectorXd>& x) {
  Index worst = 0;
  for (Index j = 1; j < x.size(); ++j)
    if (std::abs(x[j]) > std::abs(x[worst])) worst = j;
  return static_cast<int>(worst);
}

// FISTA momentum for the next extrapolated point y (and P y), restarted
// (t = 1, y = x) when it stops helping: the gradient test ∇φ(y)·(x − x_prev) > 0.
void momentum(const Eigen::Ref<Eigen::VectorXd>& x, Iterates& v, double& t) {
  const double t_next = 0.5 * (1.0 + std::sqrt(1.0 + 4.0 * t * t));
  v.x_change = x - v.x_previous;
  if (v.gradient.dot(v.x_change) > 0.0) {
    t = 1.0;
    v.y = x;
    v.Py = v.Px;
  } else {
    const double beta = (t - 1.0) / t_next;
    v.y = x + beta * v.x_change;
    v.Py = (1.0 + beta) * v.Px - beta * v.Px_previous;
    t = t_next;
  }
  v.x_previous = x;
  v.Px_previous = v.Px;
}

}  // namespace

QpReport boxQpProjectedGradient(const Eigen::Ref<const Eigen::MatrixXd>& P, const Eigen::Ref<const Eigen::VectorXd>& c,
                                const Eigen::Ref<const Eigen::VectorXd>& lo,
                                const Eigen::Ref<const Eigen::VectorXd>& hi, Eigen::Ref<Eigen::VectorXd> x,
                                QpScratch& scratch, int max_iterations, double tolerance, const TermSizes& terms) {
  if (x.size() == 0) return QpReport{0, 0.0, true};  // nothing to solve: converged
  QpReport report;
  const Index variables = x.size();
  // Lipschitz constant of ∇φ: an upper bound of λ_max(P) in O(k²) rather
  // than an O(k³) eigen-decomposition, never below P's largest |entry|.
  const double L = lambdaMaxBound(P);
  const bool all_linear = linear(P, c, L, terms);
  ProjectedGradientScratch& s = scratch.projected_gradient;
  Iterates v{s.inverse_diagonal.head(variables), s.gradient.head(variables), s.y.head(variables),
             s.x_previous.head(variables),       s.x_change.head(variables), s.Px.head(variables),
             s.Px_previous.head(variables),      s.Py.head(variables)};
  if (!linearVertex(P, c, lo, hi, all_linear, terms, tolerance, x, report) || all_linear) {  // stage 0
    if (!report.unbounded) {  // every variable linear: each follows the others' coupling (stage 3a) until none moves
      v.inverse_d.setZero();
      v.Px.noalias() = P * x;
      while (report.iterations < max_iterations && followLinear(P, c, lo, hi, terms, tolerance, x, v, report))
        ++report.iterations;
      report.converged = !report.unbounded && report.iterations < max_iterations;
    }
    report.kkt_residual = report.unbounded ? kInf : boxQpKktResidual(P, c, lo, hi, x);
    return report;
  }
  const double step = jacobiMetric(P, terms, s);  // stage 1
  const double reach = kReach * reachScale(lo, hi, c, L, terms.curvature);
  v.y = x;
  v.x_previous = x;
  v.Px.noalias() = P * x;
  v.Px_previous = v.Px;
  v.Py = v.Px;
  double t = 1.0;
  for (report.iterations = 0; report.iterations < max_iterations; ++report.iterations) {
    v.gradient = v.Py - c;  // stage 2: the projected gradient step from y
    x = v.y - step * v.inverse_d.cwiseProduct(v.gradient);
    clampToBox(lo, hi, x);
    if (x.cwiseAbs().maxCoeff() > reach) {  // running off along an infinite bound
      report.unbounded = true;
      report.unbounded_index = farthest(x);
      break;
    }
    v.Px.noalias() = P * x;
    if (followLinear(P, c, lo, hi, terms, tolerance, x, v, report)) {  // stage 3a: restart from there
      t = 1.0;
      v.y = x;
      v.Py = v.Px;
      v.x_previous = x;
      v.Px_previous = v.Px;
      continue;
    }
    if (report.unbounded) break;
    if (kktAt(v.Px, c, lo, hi, x, v.inverse_d) <= tolerance) {  // stage 3: optimal to the tolerance
      report.converged = true;
      ++report.iterations;  // count this gradient step
      break;
    }
    momentum(x, v, t);  // stage 4
  }
  report.kkt_residual = report.unbounded ? kInf : boxQpKktResidual(P, c, lo, hi, x);
  return report;
}

}  // namespace zwang::internal
