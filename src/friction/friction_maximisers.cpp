// When μ* is not unique (docs/friction.md, "When μ* is not unique").
//
// The report stops at "a" maximiser of g. Here: all maximisers give the same
// q̈*, so they differ by d with K_ΘΘ d = 0; g is linear along d with slope
// q̈*_Θ, so only sticking joints (q̈*_j = 0) can move. The maximisers are
// μ* + N z inside the box, N an orthonormal basis of null(K_ΣΣ). Two
// least-distance problems on that set pick (a) the smallest maximiser, as a
// reference point inside it, then (b) the one with the least motor effort
// ‖τ_control‖² within the margin box. Where each sticking joint's torque
// moves one for one with its own friction (EffortChange::Own), (b) is the
// distance to −h; with K_ΣΣ of rank one (a 7-joint arm holding a 6-D pose,
// say) the set is a hyperplane and its dual is one scalar equation. Where
// contacts take a share that moves with μ (EffortChange::Shared), τ_control
// = c + B z on every joint, and (b) becomes a least-distance problem in the
// metric of BᵀB (a Cholesky factor turns it into one).
#include "friction/friction_maximisers.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <limits>

#include "linalg/dense_linalg.hpp"
#include "linalg/growing_cholesky.hpp"

namespace zwang::internal {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// The ridge of EffortChange::Shared, relative to the largest diagonal of BᵀB:
// each pass minimises ‖c + Bz‖² + ε‖z − z_a‖² instead of ‖c + Bz‖². It makes
// the factor L exist where B has null directions (a flat direction whose
// friction only the contacts feel: τ_control ties along it) and breaks those
// ties towards the reference point. 1e-7 keeps L's condition number near
// 3e3, so the least-distance rows N L⁻ᵀ are far from what leastDistanceQp
// calls dependent (Schur pivots below 1e-11 of a row's ‖·‖²) and its working
// rows hold their bounds to rounding (a smaller ridge lets the pick leave the
// box on test_floating_friction's draws).
constexpr double kSharedRidge = 1e-7;
// A coupling K_ab of K_ΣΣ at or below this multiple of ε·√(t_a t_b) (t the
// size of the terms each column is a sum of, an entry taken to the scale
// √(t_a t_b) as roundingSlope does) is zero: the bound γ_k ≈ k·ε of a sum of
// k ≤ 64 terms. Kept, it would make the flat directions move a barely curved
// joint by coupling / curvature, any amount for rounding over a curvature
// just above the floor, and that joint's bound would pin them short of the
// least effort. Dropped, q̈ moves by no more than K's own rounding times μ.
constexpr double kCouplingRounding = 64.0 * DBL_EPSILON;
// Proximal passes (leastEffortWithSharedLoad): the ridge pulls the pick by
// ε/(λ + ε) of its distance from the anchor along a curvature λ of BᵀB, and
// each pass re-anchors at the last pick, so three passes leave 1e-12 of it
// where λ ≥ 1e-3·λ_max; along flatter directions τ_control hardly moves
// (√λ per unit of z). It stops early once a pass moves the pick by at most
// mu_scale. test_floating_friction checks the pick against brute force.
constexpr int kSharedPasses = 3;

// Largest t ≥ 0 with lo ≤ x + t·sign·d ≤ hi. The sign, not a −d argument: −d bound to a Ref would be a heap
// temporary in the solve.
double roomAlong(const Eigen::Ref<const Eigen::VectorXd>& x, const Eigen::Ref<const Eigen::VectorXd>& d,
                 const Eigen::Ref<const Eigen::VectorXd>& lo, const Eigen::Ref<const Eigen::VectorXd>& hi,
                 double sign) {
  double t = kInf;
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    const double dj = sign * d[j];
    if (dj > 0) t = std::min(t, (hi[j] - x[j]) / dj);
    if (dj < 0) t = std::min(t, (lo[j] - x[j]) / dj);
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

// x ← L⁻¹ x, L lower triangular (forward substitution).
void forwardSubstitute(const Eigen::Ref<const Eigen::MatrixXd>& L, Eigen::Ref<Eigen::VectorXd> x) {
  for (Eigen::Index e = 0; e < x.size(); ++e) {
    double value = x[e];
    for (Eigen::Index f = 0; f < e; ++f) value -= L(e, f) * x[f];
    x[e] = value / L(e, e);
  }
}

// z ← L⁻ᵀ w, L lower triangular (back substitution with Lᵀ).
void backSubstitute(const Eigen::Ref<const Eigen::MatrixXd>& L, const Eigen::Ref<const Eigen::VectorXd>& w,
                    Eigen::Ref<Eigen::VectorXd> z) {
  for (Eigen::Index e = w.size() - 1; e >= 0; --e) {
    double value = w[e];
    for (Eigen::Index f = e + 1; f < w.size(); ++f) value -= L(f, e) * z[f];
    z[e] = value / L(e, e);
  }
}

// P = BᵀB + εI (lower triangle) and its factor L; M = N L⁻ᵀ; s.effort_slope
// = Bᵀc. False only for a B of NaNs (P ≥ εI > 0 otherwise).
bool sharedLoadMetric(Eigen::Index ns, Eigen::Index nullity, Eigen::Index joints, double& ridge,
                      MaximiserChoiceScratch& s) {
  const auto N = s.null_basis.topLeftCorner(ns, nullity);
  const auto B = s.effort_gradient.topLeftCorner(joints, nullity);
  const auto c = s.effort_at_reference.head(joints);
  auto P = s.effort_curvature.topLeftCorner(nullity, nullity);
  auto L = s.effort_factor.topLeftCorner(nullity, nullity);
  double largest = 0.0;
  for (Eigen::Index e = 0; e < nullity; ++e) {
    for (Eigen::Index f = e; f < nullity; ++f) P(f, e) = B.col(f).dot(B.col(e));
    largest = std::max(largest, P(e, e));
    s.effort_slope[e] = B.col(e).dot(c);
  }
  ridge = kSharedRidge * largest;
  for (Eigen::Index e = 0; e < nullity; ++e) P(e, e) += ridge;
  if (!cholesky(P, L)) return false;
  // M Lᵀ = N column by column: M_e = (N_e − Σ_{f<e} L_ef M_f) / L_ee.
  auto M = s.bounded_directions.topLeftCorner(ns, nullity);
  for (Eigen::Index e = 0; e < nullity; ++e) {
    M.col(e) = N.col(e);
    for (Eigen::Index f = 0; f < e; ++f) M.col(e) -= L(e, f) * M.col(f);
    M.col(e) /= L(e, e);
  }
  return true;
}

// s.mu_chosen (μ_ref on entry) ← the maximiser with the least ‖c + B z‖² in
// [s.lo, s.hi], μ = μ_ref + N z. With P = BᵀB + εI = L Lᵀ and w = Lᵀz,
// ‖c + Bz‖² + ε‖z − z_a‖² = ‖w − w_t‖² + const with
// w_t = −L⁻¹(Bᵀc − ε z_a), and the box reads lo ≤ μ_ref + (N L⁻ᵀ) w ≤ hi: a
// least-distance problem whose rows are those of N L⁻ᵀ (leastDistanceQp
// takes any matrix there). The ridge's anchor z_a starts at 0 (μ_ref) and
// moves to each pass's pick (the proximal-point method): its pull, ε‖z*‖ on
// the first pass, shrinks by ε/λ per pass along a curvature λ of BᵀB, while
// along B's null directions (ties) the pick stays where the first pass put
// it. The passes stop when the pick moves by at most mu_scale.
void leastEffortWithSharedLoad(Eigen::Index ns, Eigen::Index nullity, Eigen::Index joints, double mu_scale,
                               int max_iterations, MaximiserChoiceScratch& s) {
  const auto N = s.null_basis.topLeftCorner(ns, nullity);
  const auto B = s.effort_gradient.topLeftCorner(joints, nullity);
  auto mu = s.mu_chosen.head(ns);
  // c, τ_control at μ_ref: at μ* plus B times step (a)'s move Nᵀ(μ_ref − μ*) (N orthonormal).
  auto w = s.z.head(nullity), w_target = s.z_target.head(nullity), anchor = s.z_anchor.head(nullity);
  w.noalias() = N.transpose() * mu;
  w.noalias() -= N.transpose() * s.mu_first.head(ns);
  auto c = s.effort_at_reference.head(joints);
  c = s.effort_first.head(joints);
  c.noalias() += B * w;
  double ridge = 0.0;
  if (!sharedLoadMetric(ns, nullity, joints, ridge, s)) return;  // μ_ref stays
  const auto L = s.effort_factor.topLeftCorner(nullity, nullity);
  const auto M = s.bounded_directions.topLeftCorner(ns, nullity);
  auto mu_pass = s.mu_pass.head(ns);
  mu_pass = mu;
  w.setZero();  // μ_ref: feasible
  anchor.setZero();
  for (int pass = 0; pass < kSharedPasses; ++pass) {
    w_target = ridge * anchor - s.effort_slope.head(nullity);
    forwardSubstitute(L, w_target);
    leastDistanceQp(M, w_target, mu, s.lo.head(ns), s.hi.head(ns), w, s.qp, max_iterations);
    backSubstitute(L, w, anchor);
    double moved = 0.0;  // how far this pass moved the pick
    for (Eigen::Index t = 0; t < ns; ++t) {
      const double mu_t = mu[t] + M.row(t).dot(w);
      moved = std::max(moved, std::abs(mu_t - mu_pass[t]));
      mu_pass[t] = mu_t;
    }
    if (moved <= mu_scale) break;
  }
  // μ_ref + M w, to rounding inside the box it was chosen in.
  mu = mu_pass.cwiseMax(s.lo.head(ns)).cwiseMin(s.hi.head(ns));
}

}  // namespace

Eigen::Index flatDirections(const Eigen::Ref<const Eigen::MatrixXd>& K,
                            const Eigen::Ref<const Eigen::VectorXd>& qdd0_stuck,
                            const Eigen::Ref<const Eigen::VectorXd>& mu, const Eigen::Ref<const Eigen::VectorXd>& lo,
                            const Eigen::Ref<const Eigen::VectorXd>& hi,
                            const Eigen::Ref<const Eigen::VectorXd>& curvature_terms, double acc_tolerance,
                            MaximiserChoiceScratch& s, Eigen::Index& ns) {
  const Eigen::Index stuck_count = K.rows();
  auto qdd_star = s.qdd_star.head(stuck_count);
  qdd_star = qdd0_stuck;
  qdd_star.noalias() -= K * mu;
  ns = 0;
  for (Eigen::Index a = 0; a < stuck_count; ++a)
    if (std::abs(qdd_star[a]) <= acc_tolerance) s.sticking[ns++] = static_cast<int>(a);
  if (ns == 0) return 0;  // every stuck joint slips: μ* is unique
  const auto sticking = s.sticking.head(ns);
  auto K_sticking = s.K_sticking.topLeftCorner(ns, ns);
  const int* sub = sticking.data();
  for (Eigen::Index b = 0; b < ns; ++b) {  // raw gathers of the lower triangle, all nearNullSpace reads
    const double* k_column = K.data() + sub[b] * K.outerStride();
    double* ks_column = K_sticking.data() + b * K_sticking.outerStride();
    ks_column[b] = k_column[sub[b]];
    for (Eigen::Index a = b + 1; a < ns; ++a) {
      const double coupling = k_column[sub[a]];
      const bool rounding =
          std::abs(coupling) <= kCouplingRounding * std::sqrt(curvature_terms[sub[a]] * curvature_terms[sub[b]]);
      ks_column[a] = rounding ? 0.0 : coupling;
    }
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
                          EffortChange change, Eigen::Index joints, double mu_scale, int max_iterations,
                          Eigen::Ref<Eigen::VectorXd> mu, MaximiserChoiceScratch& s) {
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
  // (b) the least effort within the margin box. Where the set cannot honour
  //     the margin (a limit stop carries any load) the reference point's
  //     value stays allowed.
  for (Eigen::Index t = 0; t < ns; ++t) {
    const Eigen::Index a = sticking[t];
    if (std::isfinite(box_lo[t])) box_lo[t] = std::max(box_lo[t], std::min(-margin_limit[a], mu_chosen[t]));
    if (std::isfinite(box_hi[t])) box_hi[t] = std::min(box_hi[t], std::max(margin_limit[a], mu_chosen[t]));
  }
  switch (change) {
    case EffortChange::Own:  // τ_control of a sticking joint is h + μ: minimise ‖h + μ‖²
      for (Eigen::Index t = 0; t < ns; ++t) target[t] = -effort_offset[sticking[t]];
      moveClosestTo(ns, nullity, hyperplane, plane, max_iterations, s);
      break;
    case EffortChange::Shared: leastEffortWithSharedLoad(ns, nullity, joints, mu_scale, max_iterations, s); break;
    case EffortChange::Fixed: break;  // every maximiser costs the same: the reference point stays
  }

  // Indeterminate: the maximisers form more than a point (in Λ, not the margin box).
  for (Eigen::Index t = 0; t < ns; ++t) {
    box_lo[t] = lo[sticking[t]];
    box_hi[t] = hi[sticking[t]];
  }
  bool indeterminate = (mu_chosen - mu_first).cwiseAbs().maxCoeff() > mu_scale;
  for (Eigen::Index e = 0; e < nullity && !indeterminate; ++e)
    indeterminate = roomAlong(mu_first, N.col(e), box_lo, box_hi, 1.0) > mu_scale ||
                    roomAlong(mu_first, N.col(e), box_lo, box_hi, -1.0) > mu_scale;
  for (Eigen::Index t = 0; t < ns; ++t) mu[sticking[t]] = mu_chosen[t];
  return indeterminate;
}

}  // namespace zwang::internal
