// The friction maximiser's internals (src/linalg/growing_cholesky.hpp,
// src/qp/box_qp.hpp, src/friction/friction_maximisers.hpp) against
// independent dense references computed with Eigen: LDLT for the Cholesky updates, eigen-decompositions and the SVD
// for the near null space, and brute-force enumeration of every active set
// (3^k patterns, each solved by a complete orthogonal decomposition) for the
// box QP. Fixed seeds; the worst values seen are printed.
#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>
#include <algorithm>
#include <catch2/catch.hpp>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include "friction/friction_maximisers.hpp"
#include "linalg/growing_cholesky.hpp"
#include "qp/box_qp.hpp"

using Eigen::MatrixXd;
using Eigen::VectorXd;
using Eigen::VectorXi;
using zwang::internal::boxQpActiveSet;
using zwang::internal::boxQpKktResidual;
using zwang::internal::boxQpProjectedGradient;
using zwang::internal::EffortChange;
using zwang::internal::flatDirections;
using zwang::internal::GrowingCholesky;
using zwang::internal::leastDistanceOnHyperplane;
using zwang::internal::leastDistanceQp;
using zwang::internal::leastEffortMaximiser;
using zwang::internal::MaximiserChoiceScratch;
using zwang::internal::nearNullSpace;
using zwang::internal::QpReport;
using zwang::internal::QpScratch;
using zwang::internal::TermSizes;

namespace {

using Rng = std::mt19937_64;
constexpr double kEps = DBL_EPSILON;
constexpr double kInf = std::numeric_limits<double>::infinity();

// ---- Tolerances (each with the reason for its size) ----
// Schur pivot s/P_jj vs the dense LDLT value: both are backward stable, so they
// differ by a few ε times the condition number κ of the equilibrated P_FF.
constexpr double kPivotTol = 64.0 * kEps;  // × κ(S_FF) × k
// P_FF⁻¹ b vs dense LDLT, error in the equilibrated norm ‖D(x − x_ref)‖/‖D x_ref‖:
// the forward error of a backward-stable solve is ε·κ times a small constant.
constexpr double kSolveTol = 64.0 * kEps;  // × κ(S_FF) × k
// Residual of the null direction, S [d̃; 1] − (s/P_jj) e_j (equilibrated):
// forward then backward substitution are backward stable, so the residual is
// rounding of the entries involved, ε·k·(1 + ‖d̃‖∞), without any κ.
constexpr double kNullDirTol = 16.0 * kEps;  // × k × (1 + ‖d̃‖∞)
// An index is appended only if its pivot is above this fraction of P_jj (so
// the dense reference on the grown set stays meaningful; brief).
constexpr double kAppendPivot = 1e-8;
// nearNullSpace: NᵀN = I to rounding (modified Gram–Schmidt twice).
constexpr double kOrthonormalTol = 1e-12;
// ‖A N‖_F/‖A‖_F for an exactly rank-deficient B Bᵀ: the directions solve
// triangular systems with the factored part, whose pivots are ≥ 1e-10·trace A,
// so rounding is amplified at most by that part's condition (a few 1e3 here).
constexpr double kNullResidualTol = 1e-10;
// Brute force: a free set's solve counts as stationary when the equilibrated
// residual is below this (exact solves leave ~1e-15; rank threshold is 1e-10).
constexpr double kStationaryTol = 1e-8;
// Rank threshold of the brute force's complete orthogonal decomposition on the
// equilibrated (unit diagonal) free block.
constexpr double kCodThreshold = 1e-10;
// Brute force: a candidate may overshoot its box by this fraction of the box
// width (rounding) before it is clamped back (φ then evaluated at the clamp).
constexpr double kFeasibleSlack = 1e-12;
// φ(x) ≤ φ_brute + kPhiTol·(1 + |φ_brute|), the brief's bound: ours must be
// at least as low as the best candidate, to the rounding of φ.
constexpr double kPhiTol = 1e-9;
// KKT violation of a component j relative to the rounding scale of ∇φ_j,
// Σ_l |P_jl|·‖x‖∞ + |c_j|: the solver stops at tolerance 1e-12·(1 + ‖c‖∞) plus
// 64ε of that scale; 1e-10 leaves room for the stopping rule's own slack.
constexpr double kKktTol = 1e-10;
// Projected gradient vs active set on well-conditioned draws (brief): φ agrees
// to 1e-8 relative; PG's KKT tolerance 1e-10·(1 + ‖c‖∞) gives ~1e-20 in φ.
constexpr double kPgPhiTol = 1e-8;
constexpr double kPgTolerance = 1e-10;
constexpr int kPgMaxIterations = 20000;
// Active-set iteration cap; small problems must finish far below it.
constexpr int kMaxIterations = 200;
// Larger problems (k = 40, 80): iterations must stay at or below k/2 (the
// warm start is the clamped Newton point; each iteration fixes or releases a
// variable, usually several at once).
constexpr double kLargeIterationFraction = 0.5;
// Rank k/2: a zero-curvature move fixes one variable per iteration, so up to
// about one iteration per variable (measured: see the printout); 2k is cycling.
constexpr double kLargeRankDeficientIterations = 2.0;

double uniform(Rng& rng, double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }
int uniformInt(Rng& rng, int a, int b) { return std::uniform_int_distribution<int>(a, b)(rng); }

MatrixXd gaussian(Rng& rng, Eigen::Index rows, Eigen::Index cols) {
  std::normal_distribution<double> normal;
  MatrixXd M(rows, cols);
  for (Eigen::Index j = 0; j < cols; ++j)
    for (Eigen::Index i = 0; i < rows; ++i) M(i, j) = normal(rng);
  return M;
}

MatrixXd randomOrthogonal(Rng& rng, Eigen::Index n) {
  Eigen::HouseholderQR<MatrixXd> qr(gaussian(rng, n, n));
  MatrixXd Q = qr.householderQ();
  return Q;
}

MatrixXd symmetrised(const MatrixXd& A) { return 0.5 * (A + A.transpose()); }

// B Bᵀ with B k × r (r = k: full rank almost surely).
MatrixXd gram(Rng& rng, int k, int r) {
  const MatrixXd B = gaussian(rng, k, r);
  return symmetrised(B * B.transpose());
}

// Q diag(λ) Qᵀ with λ uniform in [lo, hi].
MatrixXd wellConditioned(Rng& rng, int k, double lo, double hi) {
  const MatrixXd Q = randomOrthogonal(rng, k);
  VectorXd lambda(k);
  for (int i = 0; i < k; ++i) lambda[i] = uniform(rng, lo, hi);
  return symmetrised(Q * lambda.asDiagonal() * Q.transpose());
}

VectorXd logUniformDiagonal(Rng& rng, int k, double lo_exp, double hi_exp) {
  VectorXd D(k);
  for (int i = 0; i < k; ++i) D[i] = std::pow(10.0, uniform(rng, lo_exp, hi_exp));
  return D;
}

MatrixXd scaled(const MatrixXd& A, const VectorXd& D) { return symmetrised(D.asDiagonal() * A * D.asDiagonal()); }

// Equilibration D = sqrt(diag P) (1 where the diagonal is zero: P's row is then zero).
VectorXd equilibration(const MatrixXd& P) {
  VectorXd D(P.rows());
  for (Eigen::Index i = 0; i < P.rows(); ++i) D[i] = P(i, i) > 0.0 ? std::sqrt(P(i, i)) : 1.0;
  return D;
}

MatrixXd submatrix(const MatrixXd& A, const std::vector<int>& rows, const std::vector<int>& cols) {
  MatrixXd S(rows.size(), cols.size());
  for (size_t a = 0; a < rows.size(); ++a)
    for (size_t b = 0; b < cols.size(); ++b) S(a, b) = A(rows[a], cols[b]);
  return S;
}

double conditionNumber(const MatrixXd& S) {
  if (S.rows() == 0) return 1.0;
  Eigen::SelfAdjointEigenSolver<MatrixXd> eig(S, Eigen::EigenvaluesOnly);
  const double lmin = eig.eigenvalues().minCoeff(), lmax = eig.eigenvalues().maxCoeff();
  return lmin > 0.0 ? lmax / lmin : kInf;
}

double phi(const MatrixXd& P, const VectorXd& c, const VectorXd& x) { return 0.5 * x.dot(P * x) - c.dot(x); }

struct Worst {
  double value = 0.0;
  void see(double v) { value = std::max(value, v); }
};

}  // namespace

// ---------------------------------------------------------------------------
// 1. GrowingCholesky
// ---------------------------------------------------------------------------

namespace {

// Bookkeeping: size, index order and positionOf against our own list of F.
void checkBookkeeping(const GrowingCholesky& chol, const std::vector<int>& F, int k) {
  REQUIRE(chol.size() == static_cast<int>(F.size()));
  for (size_t a = 0; a < F.size(); ++a) {
    REQUIRE(chol.index(static_cast<int>(a)) == F[a]);
    REQUIRE(chol.positionOf(F[a]) == static_cast<int>(a));
  }
  for (int j = 0; j < k; ++j)
    if (std::find(F.begin(), F.end(), j) == F.end()) REQUIRE(chol.positionOf(j) == -1);
}

}  // namespace

TEST_CASE("GrowingCholesky: Schur pivots, null directions and solves against dense LDLT", "[box_qp][cholesky]") {
  Rng rng(0x6c68'6f6c'6573'6b79ULL);
  constexpr int kDraws = 1000;
  Worst pivot_ratio, solve_ratio, null_ratio, kappa_seen;
  int pivots = 0, appends = 0, removes = 0, dependent = 0, solves = 0;
  for (int draw = 0; draw < kDraws; ++draw) {
    const int k = uniformInt(rng, 1, 12);
    const int kind = draw % 3;
    MatrixXd P;
    if (kind == 0) {
      P = gram(rng, k, k);  // full rank (possibly ill-conditioned)
    } else if (kind == 1) {
      P = gram(rng, k, uniformInt(rng, 1, std::max(1, k - 1)));  // rank-deficient B Bᵀ
    } else {
      const MatrixXd A = uniform(rng, 0, 1) < 0.5 ? gram(rng, k, k) : gram(rng, k, uniformInt(rng, 1, k));
      P = scaled(A, logUniformDiagonal(rng, k, -6.0, 6.0));  // badly scaled
    }
    CAPTURE(draw, k, kind);
    const VectorXd D = equilibration(P);
    const MatrixXd S = symmetrised(D.cwiseInverse().asDiagonal() * P * D.cwiseInverse().asDiagonal());

    GrowingCholesky chol(k);
    std::vector<int> F;
    const int operations = 4 * k;
    for (int op = 0; op < operations; ++op) {
      std::vector<int> outside;
      for (int j = 0; j < k; ++j)
        if (std::find(F.begin(), F.end(), j) == F.end()) outside.push_back(j);
      const bool grow = F.empty() || (!outside.empty() && uniform(rng, 0, 1) < 0.65);
      if (grow) {
        const int j = outside[static_cast<size_t>(uniformInt(rng, 0, static_cast<int>(outside.size()) - 1))];
        const double pivot = chol.schurPivot(P, j);
        ++pivots;
        const MatrixXd S_FF = submatrix(S, F, F);
        const double kappa = conditionNumber(S_FF);
        kappa_seen.see(kappa);
        double pivot_ref = 1.0;  // s/P_jj, dense
        if (!F.empty()) {
          const VectorXd S_Fj = submatrix(S, F, {j});
          pivot_ref = 1.0 - S_Fj.dot(S_FF.ldlt().solve(S_Fj));
        }
        const double pivot_err = std::abs(pivot / P(j, j) - pivot_ref);
        CAPTURE(op, j, pivot, pivot_ref, kappa);
        // In units of ε κ k (so that Catch's expansion is readable).
        REQUIRE(pivot_err / (kEps * kappa * k) <= kPivotTol / kEps);
        pivot_ratio.see(pivot_err / (kEps * kappa * k));

        // Null direction: S_{F∪j} [d̃; 1] = (s/P_jj) e_j, d̃ = D_F d / D_j.
        VectorXd d(F.size());
        chol.nullDirection(d);
        std::vector<int> Fj = F;
        Fj.push_back(j);
        VectorXd v(Fj.size());
        for (size_t a = 0; a < F.size(); ++a)
          v[static_cast<Eigen::Index>(a)] = d[static_cast<Eigen::Index>(a)] * D[F[a]] / D[j];
        v[v.size() - 1] = 1.0;
        VectorXd residual = submatrix(S, Fj, Fj) * v;
        residual[residual.size() - 1] -= pivot / P(j, j);
        const double null_err = residual.lpNorm<Eigen::Infinity>();
        const double null_scale = kEps * k * (1.0 + v.lpNorm<Eigen::Infinity>());
        CAPTURE(null_err, v.lpNorm<Eigen::Infinity>());
        REQUIRE(null_err / null_scale <= kNullDirTol / kEps);
        null_ratio.see(null_err / null_scale);

        if (pivot > kAppendPivot * P(j, j)) {
          chol.append(j, pivot);
          F.push_back(j);
          ++appends;
        } else {
          ++dependent;
        }
      } else {
        const int position = uniformInt(rng, 0, static_cast<int>(F.size()) - 1);
        chol.remove(position);
        F.erase(F.begin() + position);
        ++removes;
      }
      checkBookkeeping(chol, F, k);

      // solveInPlace against dense LDLT of the equilibrated P_FF.
      if (!F.empty()) {
        const auto nf = static_cast<Eigen::Index>(F.size());
        const VectorXd b_tilde = gaussian(rng, nf, 1);
        VectorXd x(nf);
        for (Eigen::Index a = 0; a < nf; ++a) x[a] = D[F[static_cast<size_t>(a)]] * b_tilde[a];  // b = D_F b̃
        chol.solveInPlace(x);
        const MatrixXd S_FF = submatrix(S, F, F);
        const VectorXd x_ref = S_FF.ldlt().solve(b_tilde);  // = D_F x
        VectorXd x_tilde(nf);
        for (Eigen::Index a = 0; a < nf; ++a) x_tilde[a] = D[F[static_cast<size_t>(a)]] * x[a];
        const double kappa = conditionNumber(S_FF);
        const double err = (x_tilde - x_ref).norm() / x_ref.norm();
        CAPTURE(op, nf, kappa, err);
        REQUIRE(err / (kEps * kappa * k) <= kSolveTol / kEps);
        solve_ratio.see(err / (kEps * kappa * k));
        ++solves;
      }
    }
  }
  std::printf(
      "GrowingCholesky: %d draws, %d pivots (%d appended, %d not), %d removes, %d solves; worst κ(S_FF) %.3g\n"
      "  worst pivot error / (ε κ k) %.3g (limit %.3g), solve error / (ε κ k) %.3g (limit %.3g), "
      "null-direction residual / (ε k (1+|d|)) %.3g (limit %.3g)\n",
      kDraws, pivots, appends, dependent, removes, solves, kappa_seen.value, pivot_ratio.value, kPivotTol / kEps,
      solve_ratio.value, kSolveTol / kEps, null_ratio.value, kNullDirTol / kEps);
}

// ---------------------------------------------------------------------------
// 2. nearNullSpace
// ---------------------------------------------------------------------------

namespace {

struct NullSpaceResult {
  Eigen::Index nullity;
  MatrixXd N;  // the nullity returned columns
};

NullSpaceResult runNearNullSpace(const MatrixXd& A, double floor) {
  const Eigen::Index n = A.rows();
  MatrixXd work = A;
  MatrixXd N = MatrixXd::Constant(n, n, std::numeric_limits<double>::quiet_NaN());
  VectorXi perm(n);
  const Eigen::Index nullity = nearNullSpace(work, floor, N, perm);
  REQUIRE(nullity >= 0);
  REQUIRE(nullity <= n);
  return {nullity, N.leftCols(nullity)};
}

double orthonormalityError(const MatrixXd& N) {
  return (N.transpose() * N - MatrixXd::Identity(N.cols(), N.cols())).cwiseAbs().maxCoeff();
}

}  // namespace

TEST_CASE("nearNullSpace: nullity, orthonormal basis and curvature bound against SVD/eigen references",
          "[box_qp][null_space]") {
  Rng rng(0x6e75'6c6c'7370'6163ULL);
  Worst orthonormal, residual, angle, curvature_ratio;

  SECTION("B Bᵀ of rank r < n: nullity n − r, basis of null(A)") {
    constexpr int kDraws = 1000;
    for (int draw = 0; draw < kDraws; ++draw) {
      const int n = uniformInt(rng, 2, 10);
      const int r = uniformInt(rng, 1, n - 1);
      const MatrixXd B = gaussian(rng, n, r);
      const MatrixXd A = symmetrised(B * B.transpose());
      const double floor = 1e-10 * A.trace();
      CAPTURE(draw, n, r);
      const NullSpaceResult res = runNearNullSpace(A, floor);
      REQUIRE(res.nullity == n - r);
      const double o = orthonormalityError(res.N);
      REQUIRE(o <= kOrthonormalTol);
      orthonormal.see(o);
      const double rel = (A * res.N).norm() / A.norm();
      REQUIRE(rel <= kNullResidualTol);
      residual.see(rel);
      // Independent: the null space is orthogonal to B's column space (SVD).
      Eigen::JacobiSVD<MatrixXd> svd(B, Eigen::ComputeThinU);
      const double a = (svd.matrixU().transpose() * res.N).norm();
      REQUIRE(a <= kNullResidualTol * A.norm() / (svd.singularValues()[r - 1] * svd.singularValues()[r - 1]));
      angle.see(a);
      for (Eigen::Index e = 0; e < res.nullity; ++e) {
        const double curvature = res.N.col(e).dot(A * res.N.col(e));
        REQUIRE(curvature <= static_cast<double>(res.nullity) * floor);
      }
    }
    std::printf(
        "nearNullSpace, rank-deficient B Bᵀ: %d draws; worst |NᵀN − I| %.3g (limit %.3g), |A N|/|A| %.3g "
        "(limit %.3g), |U_rᵀ N| %.3g\n",
        kDraws, orthonormal.value, kOrthonormalTol, residual.value, kNullResidualTol, angle.value);
  }

  SECTION("full rank: nullity 0 whenever the floor is below λ_min (Schur diagonals are ≥ λ_min)") {
    for (int draw = 0; draw < 500; ++draw) {
      const int n = uniformInt(rng, 1, 10);
      const MatrixXd A = wellConditioned(rng, n, 1.0, 10.0);
      const double lambda_min = Eigen::SelfAdjointEigenSolver<MatrixXd>(A).eigenvalues().minCoeff();
      CAPTURE(draw, n, lambda_min);
      REQUIRE(runNearNullSpace(A, 1e-10 * A.trace()).nullity == 0);
      REQUIRE(runNearNullSpace(A, 0.5 * lambda_min).nullity == 0);
    }
  }

  SECTION("A = 0: nullity n, an orthonormal basis of everything") {
    for (int n = 1; n <= 10; ++n) {
      for (double floor : {0.0, 1e-12, 1.0}) {
        const NullSpaceResult res = runNearNullSpace(MatrixXd::Zero(n, n), floor);
        REQUIRE(res.nullity == n);
        REQUIRE(orthonormalityError(res.N) <= kOrthonormalTol);
      }
    }
  }

  SECTION("eigenvalue clusters {1..10} and {0..1e-9}, floor 1e-6 between them: nullity = small cluster") {
    // The brief's example first, then random cluster sizes.
    constexpr int kDraws = 1000;
    for (int draw = 0; draw < kDraws; ++draw) {
      const int n = draw == 0 ? 4 : uniformInt(rng, 2, 10);
      const int m = draw == 0 ? 2 : uniformInt(rng, 1, n - 1);
      VectorXd lambda(n);
      for (int i = 0; i < n; ++i)
        lambda[i] = draw == 0   ? (i < n - m ? 1.0 : 1e-9)
                    : i < n - m ? uniform(rng, 1.0, 10.0)
                                : uniform(rng, 0.0, 1e-9);
      const MatrixXd Q = randomOrthogonal(rng, n);
      const MatrixXd A = symmetrised(Q * lambda.asDiagonal() * Q.transpose());
      const double floor = 1e-6;
      CAPTURE(draw, n, m);
      const NullSpaceResult res = runNearNullSpace(A, floor);
      REQUIRE(res.nullity == m);
      REQUIRE(orthonormalityError(res.N) <= kOrthonormalTol);
      for (Eigen::Index e = 0; e < res.nullity; ++e) {
        const double curvature = res.N.col(e).dot(A * res.N.col(e));
        CAPTURE(e, curvature);
        REQUIRE(curvature <= static_cast<double>(res.nullity) * floor);  // the documented bound
        curvature_ratio.see(curvature / (static_cast<double>(res.nullity) * floor));
      }
    }
    std::printf("nearNullSpace, eigenvalue clusters: %d draws; worst dᵀAd / ((n−r) floor) %.3g (limit 1)\n", kDraws,
                curvature_ratio.value);
  }
}

// ---------------------------------------------------------------------------
// 3. boxQpActiveSet against brute-force enumeration
// ---------------------------------------------------------------------------

namespace {

struct BoxQp {
  MatrixXd P;
  VectorXd c, lo, hi;
};

// min φ over every pattern (lower / upper / free per variable): the free block
// is solved on its equilibrated form by a complete orthogonal decomposition
// (min-norm least squares), kept when stationary and inside the box. Every
// candidate is a feasible point (clamped after a rounding-size overshoot), so
// the minimum is ≥ the true minimum; the optimal point with the most active
// bounds has a nonsingular free block, so one candidate is that point.
double bruteForceMinimum(const BoxQp& q, int* candidates) {
  const auto k = static_cast<int>(q.c.size());
  int patterns = 1;
  for (int j = 0; j < k; ++j) patterns *= 3;
  double best = kInf;
  *candidates = 0;
  VectorXd x(k);
  for (int pattern = 0; pattern < patterns; ++pattern) {
    std::vector<int> free, bound;
    bool on_infinite_bound = false;
    int code = pattern;
    for (int j = 0; j < k; ++j, code /= 3) {
      const int t = code % 3;
      if (t == 2) {
        free.push_back(j);
      } else {
        x[j] = t == 0 ? q.lo[j] : q.hi[j];
        bound.push_back(j);
        on_infinite_bound = on_infinite_bound || !std::isfinite(x[j]);
      }
    }
    if (on_infinite_bound) continue;  // no point there
    bool feasible = true;
    if (!free.empty()) {
      const auto nf = static_cast<Eigen::Index>(free.size());
      MatrixXd M = submatrix(q.P, free, free);
      VectorXd rhs(nf);
      for (Eigen::Index a = 0; a < nf; ++a) {
        const int i = free[static_cast<size_t>(a)];
        rhs[a] = q.c[i];
        for (int j : bound) rhs[a] -= q.P(i, j) * x[j];
      }
      const VectorXd D = equilibration(M);
      const MatrixXd Mt = D.cwiseInverse().asDiagonal() * M * D.cwiseInverse().asDiagonal();
      const VectorXd rt = D.cwiseInverse().asDiagonal() * rhs;
      Eigen::CompleteOrthogonalDecomposition<MatrixXd> cod;
      cod.setThreshold(kCodThreshold);
      cod.compute(Mt);
      const VectorXd yt = cod.solve(rt);
      const double res = (Mt * yt - rt).lpNorm<Eigen::Infinity>();
      if (!(res <= kStationaryTol * (1.0 + rt.lpNorm<Eigen::Infinity>() + yt.lpNorm<Eigen::Infinity>()))) continue;
      for (Eigen::Index a = 0; a < nf; ++a) {
        const int i = free[static_cast<size_t>(a)];
        const double y = yt[a] / D[a];
        const double width = q.hi[i] - q.lo[i];
        const double slack =
            kFeasibleSlack * (std::isfinite(width) ? width
                                                   : 1.0 + std::max(std::isfinite(q.lo[i]) ? -q.lo[i] : 0.0,
                                                                    std::isfinite(q.hi[i]) ? q.hi[i] : 0.0));
        if (!(y >= q.lo[i] - slack && y <= q.hi[i] + slack)) feasible = false;
        x[i] = std::min(q.hi[i], std::max(q.lo[i], y));
      }
    }
    if (!feasible) continue;
    ++*candidates;
    best = std::min(best, phi(q.P, q.c, x));
  }
  return best;
}

// Box lo ≤ 0 ≤ hi, finite, widths O(1) (divided by D when given); some variables pinned at 0.
void randomBox(Rng& rng, BoxQp& q, const VectorXd* D) {
  const auto k = q.c.size();
  q.lo.resize(k);
  q.hi.resize(k);
  for (Eigen::Index j = 0; j < k; ++j) {
    if (uniform(rng, 0, 1) < 0.12) {
      q.lo[j] = q.hi[j] = 0.0;
      continue;
    }
    const double s = D ? 1.0 / (*D)[j] : 1.0;
    q.lo[j] = -uniform(rng, 0.05, 2.0) * s;
    q.hi[j] = uniform(rng, 0.05, 2.0) * s;
    if (uniform(rng, 0, 1) < 0.1)
      q.lo[j] = 0.0;  // one-sided
    else if (uniform(rng, 0, 1) < 0.1)
      q.hi[j] = 0.0;
  }
}

// Component-wise KKT check: returns the worst violation_j / scale_j with
// scale_j = Σ_l |P_jl|·‖x‖∞ + |c_j| (the rounding scale of ∇φ_j).
double kktViolationRatio(const BoxQp& q, const VectorXd& x) {
  const VectorXd g = q.P * x - q.c;
  const double x_max = x.lpNorm<Eigen::Infinity>();
  double worst = 0.0;
  for (Eigen::Index j = 0; j < x.size(); ++j) {
    const double scale = q.P.row(j).cwiseAbs().sum() * x_max + std::abs(q.c[j]) + DBL_MIN;
    double violation = 0.0;
    if (q.lo[j] == q.hi[j])
      violation = 0.0;
    else if (x[j] <= q.lo[j])
      violation = std::max(0.0, -g[j]);
    else if (x[j] >= q.hi[j])
      violation = std::max(0.0, g[j]);
    else
      violation = std::abs(g[j]);
    worst = std::max(worst, violation / scale);
  }
  return worst;
}

bool insideBox(const BoxQp& q, const VectorXd& x) {
  for (Eigen::Index j = 0; j < x.size(); ++j)
    if (!(q.lo[j] <= x[j] && x[j] <= q.hi[j])) return false;
  return true;
}

}  // namespace

TEST_CASE("boxQpActiveSet: minimum against brute-force enumeration of all 3^k active sets (k ≤ 6)",
          "[box_qp][active_set]") {
  Rng rng(0x626f'7871'7062'7275ULL);
  constexpr int kDraws = 3000;
  constexpr int kKinds = 8;
  const char* kind_names[kKinds] = {"full rank",    "rank-deficient",   "scaled (equivalent)", "scaled (raw c, box)",
                                    "zero row/col", "well-conditioned", "PD, infinite bounds", "nearly dependent"};
  Worst phi_gap[kKinds], kkt_ratio[kKinds], pg_gap;
  int max_iterations_seen[kKinds] = {}, count[kKinds] = {};
  int pg_converged = 0, pg_runs = 0, pg_max_iterations = 0;
  for (int draw = 0; draw < kDraws; ++draw) {
    const int k = uniformInt(rng, 1, 6);
    const int kind = draw % kKinds;
    BoxQp q;
    VectorXd D;
    bool equivalent_scaling = false;
    switch (kind) {
      case 0: q.P = gram(rng, k, k); break;
      case 1: q.P = gram(rng, k, uniformInt(rng, 0, k - 1)); break;
      case 2:
      case 3: {
        const MatrixXd A = uniform(rng, 0, 1) < 0.5 ? gram(rng, k, k) : gram(rng, k, uniformInt(rng, 0, k));
        D = logUniformDiagonal(rng, k, -4.0, 4.0);
        q.P = scaled(A, D);
        equivalent_scaling = kind == 2;
        break;
      }
      case 4: {
        q.P = gram(rng, k, k);
        const int z = uniformInt(rng, 0, k - 1);
        q.P.row(z).setZero();
        q.P.col(z).setZero();
        break;
      }
      case 5: q.P = wellConditioned(rng, k, 1.0, 10.0); break;
      case 6:  // positive definite: bounded whatever the box
        q.P = gram(rng, k, k);
        q.P += (0.1 * q.P.trace() / k) * MatrixXd::Identity(k, k);
        break;
      default: {  // rank r plus a weak but real curvature δ ∈ [1e-8, 1e-3] relative along a random v
        q.P = gram(rng, k, uniformInt(rng, 0, k - 1));
        const VectorXd v = gaussian(rng, k, 1).normalized();
        const double delta = std::pow(10.0, uniform(rng, -8.0, -3.0)) * std::max(1.0, q.P.trace() / k);
        q.P = symmetrised(q.P + delta * v * v.transpose());
        break;
      }
    }
    // c: a few times P's scale so that some bounds are active and some not.
    const double c_scale =
        1.5 *
        std::max(1.0, (equivalent_scaling ? (q.P.diagonal().array() / D.array().square()).sum() : q.P.trace()) / k);
    q.c = gaussian(rng, k, 1) * c_scale;
    if (equivalent_scaling) q.c = D.asDiagonal() * q.c;
    randomBox(rng, q, equivalent_scaling ? &D : nullptr);
    if (kind == 7) {  // c = P x_t + small: the minimiser is near x_t inside the box, along the weak direction too
      VectorXd x_t(k);
      for (int j = 0; j < k; ++j) x_t[j] = uniform(rng, q.lo[j], q.hi[j]);
      q.c = q.P * x_t + 1e-3 * gaussian(rng, k, 1);
    }
    if (kind == 6)
      for (int j = 0; j < k; ++j) {
        if (q.lo[j] == q.hi[j]) continue;
        if (uniform(rng, 0, 1) < 0.35) q.lo[j] = -kInf;
        if (uniform(rng, 0, 1) < 0.35) q.hi[j] = kInf;
      }
    CAPTURE(draw, k, kind_names[kind]);
    CAPTURE(q.P, q.c.transpose(), q.lo.transpose(), q.hi.transpose());

    int candidates = 0;
    const double phi_brute = bruteForceMinimum(q, &candidates);
    REQUIRE(candidates > 0);  // the brute force itself must find points

    QpScratch scratch(k);
    VectorXd x = VectorXd::Zero(k);
    const double tolerance = 1e-12 * (1.0 + q.c.lpNorm<Eigen::Infinity>());
    const QpReport report = boxQpActiveSet(q.P, q.c, q.lo, q.hi, x, scratch, kMaxIterations, tolerance);
    const double phi_ours = phi(q.P, q.c, x);
    CAPTURE(x.transpose(), phi_ours, phi_brute, report.iterations, report.kkt_residual);
    REQUIRE(report.converged);
    REQUIRE_FALSE(report.unbounded);
    REQUIRE(report.iterations < kMaxIterations);
    REQUIRE(insideBox(q, x));
    const double phi_tol = kPhiTol * (1.0 + std::abs(phi_brute));
    REQUIRE(phi_ours <= phi_brute + phi_tol);
    // Ours is feasible, so it cannot be lower than the minimum either: a gap
    // the other way means the brute force missed the optimum (reference check).
    REQUIRE(phi_brute <= phi_ours + phi_tol);
    phi_gap[kind].see(std::abs(phi_ours - phi_brute) / (1.0 + std::abs(phi_brute)));
    const double kkt = kktViolationRatio(q, x);
    REQUIRE(kkt <= kKktTol);
    kkt_ratio[kind].see(kkt);
    // The report's residual is boxQpKktResidual's, small relative to c's scale
    // (in the units of ∇φ; for the raw-scaled draws P's scale enters through Px).
    double grad_scale = q.c.lpNorm<Eigen::Infinity>();
    for (int j = 0; j < k; ++j)
      grad_scale = std::max(grad_scale, q.P.row(j).cwiseAbs().sum() * x.lpNorm<Eigen::Infinity>());
    REQUIRE(report.kkt_residual == boxQpKktResidual(q.P, q.c, q.lo, q.hi, x));
    REQUIRE(report.kkt_residual <= kKktTol * (grad_scale + DBL_MIN));
    max_iterations_seen[kind] = std::max(max_iterations_seen[kind], report.iterations);
    ++count[kind];

    if (kind == 5) {  // projected gradient agrees on the well-conditioned draws
      VectorXd x_pg = VectorXd::Zero(k);
      const double pg_tolerance = kPgTolerance * (1.0 + q.c.lpNorm<Eigen::Infinity>());
      const QpReport pg = boxQpProjectedGradient(q.P, q.c, q.lo, q.hi, x_pg, scratch, kPgMaxIterations, pg_tolerance);
      ++pg_runs;
      REQUIRE(insideBox(q, x_pg));
      if (pg.converged) {
        ++pg_converged;
        const double gap = std::abs(phi(q.P, q.c, x_pg) - phi_ours) / (1.0 + std::abs(phi_ours));
        REQUIRE(gap <= kPgPhiTol);
        pg_gap.see(gap);
        pg_max_iterations = std::max(pg_max_iterations, pg.iterations);
      }
    }
  }
  // Well-conditioned problems: FISTA converges well within its cap.
  REQUIRE(pg_converged == pg_runs);
  std::printf("boxQpActiveSet vs brute force, %d draws (k = 1..6):\n", kDraws);
  for (int kind = 0; kind < kKinds; ++kind)
    std::printf(
        "  %-20s %4d draws: worst |φ − φ_brute|/(1+|φ|) %.3g (limit %.3g), KKT/scale %.3g (limit %.3g), "
        "max iterations %d\n",
        kind_names[kind], count[kind], phi_gap[kind].value, kPhiTol, kkt_ratio[kind].value, kKktTol,
        max_iterations_seen[kind]);
  std::printf("  projected gradient: %d/%d converged, worst φ gap %.3g (limit %.3g), max iterations %d\n", pg_converged,
              pg_runs, pg_gap.value, kPgPhiTol, pg_max_iterations);
}

TEST_CASE("boxQpActiveSet: a zero-curvature descent direction with an infinite bound is unbounded",
          "[box_qp][active_set][unbounded]") {
  Rng rng(0x756e'626f'756e'6465ULL);
  int draws = 0;
  SECTION("P with a zero row/column j, c_j pushing towards an infinite bound") {
    for (int draw = 0; draw < 200; ++draw, ++draws) {
      const int k = uniformInt(rng, 1, 6);
      const int j = uniformInt(rng, 0, k - 1);
      BoxQp q;
      // Half the draws: the others positive definite, some with infinite
      // bounds too (they must not be blamed: only j runs off).
      const bool others_pd = draw % 4 >= 2;
      q.P = others_pd ? gram(rng, k, k) : gram(rng, k, uniformInt(rng, 0, k));
      q.P.row(j).setZero();
      q.P.col(j).setZero();
      q.c = gaussian(rng, k, 1) * 2.0;
      randomBox(rng, q, nullptr);
      if (others_pd)
        for (int i = 0; i < k; ++i) {
          if (q.lo[i] == q.hi[i]) continue;
          if (uniform(rng, 0, 1) < 0.4) q.lo[i] = -kInf;
          if (uniform(rng, 0, 1) < 0.4) q.hi[i] = kInf;
        }
      const bool up = draw % 2 == 0;
      q.c[j] = up ? 0.1 + std::abs(q.c[j]) : -0.1 - std::abs(q.c[j]);
      if (up) {
        q.lo[j] = -uniform(rng, 0.0, 2.0);
        q.hi[j] = kInf;
      } else {
        q.lo[j] = -kInf;
        q.hi[j] = uniform(rng, 0.0, 2.0);
      }
      CAPTURE(draw, k, j, q.P, q.c.transpose(), q.lo.transpose(), q.hi.transpose());
      QpScratch scratch(k);
      VectorXd x = VectorXd::Zero(k);
      const QpReport report = boxQpActiveSet(q.P, q.c, q.lo, q.hi, x, scratch, kMaxIterations,
                                             1e-12 * (1.0 + q.c.lpNorm<Eigen::Infinity>()));
      CAPTURE(report.iterations, report.unbounded_index, x.transpose());
      REQUIRE(report.unbounded);
      REQUIRE_FALSE(report.converged);
      REQUIRE(report.unbounded_index == j);
    }
  }
  SECTION("rounding-level curvature P_jj = 1e-30 (others O(1)): unbounded by the reach rule, not x_j ~ 1e30") {
    // k ≥ 2: "rounding" means small next to P's other curvatures. Alone
    // (k = 1) the problem is a rescaling of a finite one, checked below.
    for (int draw = 0; draw < 200; ++draw, ++draws) {
      const int k = uniformInt(rng, 2, 6);
      const int j = uniformInt(rng, 0, k - 1);
      BoxQp q;
      q.P = MatrixXd::Zero(k, k);
      const MatrixXd A = wellConditioned(rng, k, 1.0, 10.0);
      for (int a = 0; a < k; ++a)
        for (int b = 0; b < k; ++b)
          if (a != j && b != j) q.P(a, b) = A(a, b);
      q.P(j, j) = 1e-30;
      q.c = gaussian(rng, k, 1) * 5.0;
      randomBox(rng, q, nullptr);
      const bool up = draw % 2 == 0;
      q.c[j] = up ? 0.1 + std::abs(q.c[j]) : -0.1 - std::abs(q.c[j]);
      q.lo[j] = up ? -uniform(rng, 0.0, 2.0) : -kInf;
      q.hi[j] = up ? kInf : uniform(rng, 0.0, 2.0);
      CAPTURE(draw, k, j, q.P, q.c.transpose(), q.lo.transpose(), q.hi.transpose());
      QpScratch scratch(k);
      VectorXd x = VectorXd::Zero(k);
      const double tolerance = 1e-12 * (1.0 + q.c.lpNorm<Eigen::Infinity>());
      const QpReport report = boxQpActiveSet(q.P, q.c, q.lo, q.hi, x, scratch, kMaxIterations, tolerance);
      CAPTURE(report.iterations, report.unbounded_index, x.transpose());
      REQUIRE(report.unbounded);
      REQUIRE(report.unbounded_index == j);

      // The same with the downhill bound finite: converged, x_j on that bound.
      (up ? q.hi[j] : q.lo[j]) = up ? 1.5 : -1.5;
      x.setZero();
      const QpReport bounded = boxQpActiveSet(q.P, q.c, q.lo, q.hi, x, scratch, kMaxIterations, tolerance);
      CAPTURE(bounded.iterations, x.transpose());
      REQUIRE(bounded.converged);
      REQUIRE_FALSE(bounded.unbounded);
      REQUIRE(x[j] == (up ? 1.5 : -1.5));
      REQUIRE(kktViolationRatio(q, x) <= kKktTol);
    }
    // One variable, P = 1e-30, c = 1, x ∈ [−1, ∞): the minimiser x = 1e30.
    MatrixXd P1 = MatrixXd::Constant(1, 1, 1e-30);
    VectorXd c1 = VectorXd::Ones(1), lo1 = VectorXd::Constant(1, -1.0), hi1 = VectorXd::Constant(1, kInf);
    VectorXd x1 = VectorXd::Zero(1);
    QpScratch scratch1(1);
    const QpReport alone = boxQpActiveSet(P1, c1, lo1, hi1, x1, scratch1, kMaxIterations, 1e-12);
    CAPTURE(alone.iterations, x1[0]);
    REQUIRE(alone.converged);
    REQUIRE_FALSE(alone.unbounded);
    REQUIRE(x1[0] == Approx(1e30).epsilon(1e-14));
    // The same P computed as the rounding of O(1) terms (the caller says so
    // with curvature_scale = 1): zero curvature, unbounded; the active set
    // and projected gradient agree.
    for (const bool active_set : {true, false}) {
      x1.setZero();
      const QpReport rounding =
          active_set ? boxQpActiveSet(P1, c1, lo1, hi1, x1, scratch1, kMaxIterations, 1e-12, TermSizes{1.0})
                     : boxQpProjectedGradient(P1, c1, lo1, hi1, x1, scratch1, kPgMaxIterations, 1e-12, TermSizes{1.0});
      CAPTURE(active_set, rounding.iterations, x1[0]);
      REQUIRE(rounding.unbounded);
      REQUIRE(rounding.unbounded_index == 0);
    }
  }
  SECTION("rank-deficient P, c ∈ range(P), some bounds infinite: bounded (φ ≥ −½ cᵀP⁺c), converges to a KKT point") {
    Worst kkt;
    int max_iterations = 0;
    for (int draw = 0; draw < 300; ++draw, ++draws) {
      const int k = uniformInt(rng, 2, 8);
      const int r = uniformInt(rng, 1, k - 1);
      const MatrixXd B = gaussian(rng, k, r);
      BoxQp q;
      q.P = symmetrised(B * B.transpose());
      q.c = B * gaussian(rng, r, 1) * 2.0;
      randomBox(rng, q, nullptr);
      for (int j = 0; j < k; ++j) {
        if (q.lo[j] == q.hi[j]) continue;
        if (uniform(rng, 0, 1) < 0.4) q.lo[j] = -kInf;
        if (uniform(rng, 0, 1) < 0.4) q.hi[j] = kInf;
      }
      CAPTURE(draw, k, r, q.P, q.c.transpose(), q.lo.transpose(), q.hi.transpose());
      QpScratch scratch(k);
      VectorXd x = VectorXd::Zero(k);
      const QpReport report = boxQpActiveSet(q.P, q.c, q.lo, q.hi, x, scratch, kMaxIterations,
                                             1e-12 * (1.0 + q.c.lpNorm<Eigen::Infinity>()));
      CAPTURE(report.iterations, report.unbounded_index, x.transpose());
      REQUIRE(report.converged);
      REQUIRE_FALSE(report.unbounded);
      REQUIRE(insideBox(q, x));
      const double ratio = kktViolationRatio(q, x);  // KKT is sufficient: x is a minimiser
      REQUIRE(ratio <= kKktTol);
      kkt.see(ratio);
      max_iterations = std::max(max_iterations, report.iterations);
      // Independent lower bound: the unconstrained minimum −½ cᵀP⁺c (SVD pseudo-inverse).
      const double unconstrained = -0.5 * q.c.dot(q.P.completeOrthogonalDecomposition().solve(q.c));
      REQUIRE(phi(q.P, q.c, x) >= unconstrained - kPhiTol * (1.0 + std::abs(unconstrained)));
    }
    std::printf(
        "rank-deficient, consistent c, mixed infinite bounds: 300 draws, worst KKT/scale %.3g (limit %.3g), "
        "max iterations %d\n",
        kkt.value, kKktTol, max_iterations);
  }
  SECTION("every bound infinite, rank-deficient P: unbounded iff c has a component in null(P)") {
    Worst kkt;
    for (int draw = 0; draw < 200; ++draw, ++draws) {
      const int k = uniformInt(rng, 2, 6);
      const int r = uniformInt(rng, 1, k - 1);
      const MatrixXd B = gaussian(rng, k, r);
      BoxQp q;
      q.P = symmetrised(B * B.transpose());
      const bool consistent = draw % 2 == 0;
      // c ∈ range(P) = range(B), or with a unit component along null(Bᵀ).
      q.c = B * gaussian(rng, r, 1);
      if (!consistent) {
        Eigen::JacobiSVD<MatrixXd> svd(B, Eigen::ComputeFullU);
        q.c += svd.matrixU().col(r) * (draw % 4 == 1 ? 1.0 : -1.0);
      }
      q.lo = VectorXd::Constant(k, -kInf);
      q.hi = VectorXd::Constant(k, kInf);
      CAPTURE(draw, k, r, consistent, q.P, q.c.transpose());
      QpScratch scratch(k);
      VectorXd x = VectorXd::Zero(k);
      const QpReport report = boxQpActiveSet(q.P, q.c, q.lo, q.hi, x, scratch, kMaxIterations,
                                             1e-12 * (1.0 + q.c.lpNorm<Eigen::Infinity>()));
      CAPTURE(report.iterations, report.unbounded_index, x.transpose());
      if (consistent) {
        REQUIRE(report.converged);
        REQUIRE_FALSE(report.unbounded);
        // P x = c, checked by the dense normal residual.
        REQUIRE(kktViolationRatio(q, x) <= kKktTol);
        kkt.see(kktViolationRatio(q, x));
      } else {
        REQUIRE(report.unbounded);
        REQUIRE(report.unbounded_index >= 0);
        REQUIRE(report.unbounded_index < k);
      }
    }
    std::printf("unbounded box, consistent c: worst KKT/scale %.3g (limit %.3g)\n", kkt.value, kKktTol);
  }
  (void)draws;
}

// ---------------------------------------------------------------------------
// 4. Larger problems: the KKT conditions directly
// ---------------------------------------------------------------------------

TEST_CASE("boxQpActiveSet: k = 40, 80 satisfies the KKT conditions in few iterations", "[box_qp][active_set][large]") {
  Rng rng(0x6c61'7267'6562'6f78ULL);
  constexpr int kLargeCap = 1000;
  for (int k : {40, 80}) {
    for (bool rank_deficient : {false, true}) {
      Worst kkt;
      int max_iterations = 0, bound_total = 0, draws = 0;
      for (int draw = 0; draw < 30; ++draw, ++draws) {
        BoxQp q;
        q.P = rank_deficient ? gram(rng, k, k / 2) * (10.0 / k) : wellConditioned(rng, k, 1.0, 100.0);
        q.c = gaussian(rng, k, 1) * (rank_deficient ? 5.0 : 60.0);
        randomBox(rng, q, nullptr);
        CAPTURE(k, rank_deficient, draw);
        QpScratch scratch(k);
        VectorXd x = VectorXd::Zero(k);
        const double tolerance = 1e-12 * (1.0 + q.c.lpNorm<Eigen::Infinity>());
        const QpReport report = boxQpActiveSet(q.P, q.c, q.lo, q.hi, x, scratch, kLargeCap, tolerance);
        CAPTURE(report.iterations, report.kkt_residual);
        REQUIRE(report.converged);
        REQUIRE(insideBox(q, x));
        // KKT, tolerance relative to ‖P‖∞‖x‖∞ + ‖c‖∞.
        const VectorXd g = q.P * x - q.c;
        double P_norm = 0.0;
        for (int j = 0; j < k; ++j) P_norm = std::max(P_norm, q.P.row(j).cwiseAbs().sum());
        const double scale = P_norm * x.lpNorm<Eigen::Infinity>() + q.c.lpNorm<Eigen::Infinity>();
        const double tol = kKktTol * scale;
        double worst = 0.0;
        for (int j = 0; j < k; ++j) {
          CAPTURE(j, x[j], q.lo[j], q.hi[j], g[j]);
          if (q.lo[j] == q.hi[j]) continue;
          if (x[j] == q.lo[j]) {
            REQUIRE(g[j] >= -tol);
            worst = std::max(worst, -g[j]);
            ++bound_total;
          } else if (x[j] == q.hi[j]) {
            REQUIRE(g[j] <= tol);
            worst = std::max(worst, g[j]);
            ++bound_total;
          } else {
            REQUIRE(std::abs(g[j]) <= tol);
            worst = std::max(worst, std::abs(g[j]));
          }
        }
        kkt.see(worst / scale);
        REQUIRE(report.iterations <= (rank_deficient ? kLargeRankDeficientIterations : kLargeIterationFraction) * k);
        max_iterations = std::max(max_iterations, report.iterations);
      }
      std::printf(
          "large k = %d (%s): %d draws, %.1f variables on a bound on average, worst KKT/scale %.3g "
          "(limit %.3g), max iterations %d (cap %d, required ≤ %.0f)\n",
          k, rank_deficient ? "rank k/2" : "well-conditioned", draws, static_cast<double>(bound_total) / draws,
          kkt.value, kKktTol, max_iterations, kLargeCap,
          (rank_deficient ? kLargeRankDeficientIterations : kLargeIterationFraction) * k);
    }
  }
}

// The `kReach` rule once measured travel against max(1, largest finite
// bound) only, whatever P and c: on a perfectly conditioned problem with an
// infinite bound and a large minimiser (P = I, c = (1e13, 0.5), x_0 free,
// x_1 ∈ [−1, 1]) it reported unbounded, while the same problem in y = x/100
// was solved. The scale now includes ‖c‖∞/L (L ≥ λ_max(P)), as the projected
// gradient method's does; the P_jj = 1e-30 case above (a curvature 1e-30 next
// to O(1) ones) is still unbounded.
TEST_CASE("boxQpActiveSet: a large but finite minimiser on an infinite bound is not unbounded",
          "[box_qp][active_set][unbounded]") {
  const MatrixXd P = MatrixXd::Identity(2, 2);
  VectorXd c(2), lo(2), hi(2);
  c << 1e13, 0.5;
  lo << -kInf, -1.0;
  hi << kInf, 1.0;
  QpScratch scratch(2);
  VectorXd x = VectorXd::Zero(2);
  const QpReport report = boxQpActiveSet(P, c, lo, hi, x, scratch, kMaxIterations, 1e-12 * (1.0 + 1e13));
  CAPTURE(report.iterations, report.unbounded, report.unbounded_index, x.transpose());
  CHECK_FALSE(report.unbounded);
  CHECK(report.converged);
  CHECK(x[0] == Approx(1e13).epsilon(1e-12));
  CHECK(x[1] == Approx(0.5).epsilon(1e-12));
  // The projected gradient method solves it (the reference the active set should match).
  VectorXd y = VectorXd::Zero(2);
  const QpReport pg = boxQpProjectedGradient(P, c, lo, hi, y, scratch, kPgMaxIterations, 1e-10 * (1.0 + 1e13));
  CHECK(pg.converged);
  CHECK(y[0] == Approx(1e13).epsilon(1e-12));
  // The diagonally rescaled problem, y = x/100: solved.
  VectorXd z = VectorXd::Zero(2);
  const VectorXd c_y = 100.0 * c, lo_y = lo / 100.0, hi_y = hi / 100.0;
  const QpReport scaled_report =
      boxQpActiveSet(1e4 * P, c_y, lo_y, hi_y, z, scratch, kMaxIterations, 1e-12 * (1.0 + 1e15));
  CHECK(scaled_report.converged);
  CHECK(z[0] == Approx(1e11).epsilon(1e-12));
}

// ---------------------------------------------------------------------------
// 4. The least-distance problems that pick among several friction maximisers:
//   min ½‖μ − t‖²  s.t.  Aᵀμ = b (A n × r, orthonormal columns),  lo ≤ μ ≤ hi,
// with a feasible point x (b = Aᵀx). leastDistanceQp works in μ = x + N z
// (N the orthonormal complement of A); leastDistanceOnHyperplane (r = 1) in
// the dual. Reference: every pattern of lower / upper / free (3^n, n ≤ 6),
// each an equality-constrained least-squares problem solved by a complete
// orthogonal decomposition; the lowest feasible one is the minimiser.

namespace {

struct SliceProblem {
  MatrixXd A;  // n × r, orthonormal columns
  VectorXd t, lo, hi, x;
  double objective(const VectorXd& mu) const { return 0.5 * (mu - t).squaredNorm(); }
};

// Smallest objective over the feasible patterns (+∞ if none).
double bruteForceSlice(const SliceProblem& p, VectorXd& best) {
  const auto n = static_cast<int>(p.t.size());
  int patterns = 1;
  for (int i = 0; i < n; ++i) patterns *= 3;
  const VectorXd b = p.A.transpose() * p.x;
  double best_value = kInf;
  for (int code = 0; code < patterns; ++code) {
    VectorXd mu(n);
    std::vector<int> free_set;
    bool finite = true;
    for (int i = 0, c = code; i < n; ++i, c /= 3) {
      if (c % 3 == 0)
        mu[i] = p.lo[i];
      else if (c % 3 == 1)
        mu[i] = p.hi[i];
      else
        free_set.push_back(i);
      if (c % 3 != 2 && !std::isfinite(mu[i])) finite = false;
    }
    if (!finite) continue;
    // Free part: μ_F = t_F + A_F λ with A_Fᵀ μ_F = b − A_Bᵀ μ_B.
    const auto nf = static_cast<Eigen::Index>(free_set.size());
    VectorXd rhs = b;
    for (int i = 0; i < n; ++i)
      if (std::find(free_set.begin(), free_set.end(), i) == free_set.end()) rhs -= p.A.row(i).transpose() * mu[i];
    MatrixXd AF(nf, p.A.cols());
    VectorXd tF(nf);
    for (Eigen::Index a = 0; a < nf; ++a) {
      AF.row(a) = p.A.row(free_set[static_cast<std::size_t>(a)]);
      tF[a] = p.t[free_set[static_cast<std::size_t>(a)]];
    }
    const MatrixXd G = AF.transpose() * AF;
    const VectorXd lambda = G.completeOrthogonalDecomposition().solve(rhs - AF.transpose() * tF);
    for (Eigen::Index a = 0; a < nf; ++a) mu[free_set[static_cast<std::size_t>(a)]] = tF[a] + AF.row(a).dot(lambda);
    const double scale = 1.0 + p.x.lpNorm<Eigen::Infinity>() + p.t.lpNorm<Eigen::Infinity>();
    if ((p.A.transpose() * mu - b).lpNorm<Eigen::Infinity>() > 1e-9 * scale) continue;  // pattern infeasible
    bool inside = true;
    for (int i = 0; i < n; ++i) inside = inside && mu[i] >= p.lo[i] - 1e-12 * scale && mu[i] <= p.hi[i] + 1e-12 * scale;
    if (!inside) continue;
    if (p.objective(mu) < best_value) {
      best_value = p.objective(mu);
      best = mu;
    }
  }
  return best_value;
}

SliceProblem randomSlice(Rng& rng, int n, int r) {
  SliceProblem p;
  p.A = randomOrthogonal(rng, n).leftCols(r);
  if (uniform(rng, 0, 1) < 0.25)  // a sparse normal: some joints off the hyperplane's constraint
    for (int i = 0; i < n; ++i)
      if (uniform(rng, 0, 1) < 0.3) p.A.row(i).setZero();
  if (p.A.norm() == 0.0) p.A(0, 0) = 1.0;
  Eigen::HouseholderQR<MatrixXd> qr(p.A);  // re-orthonormalise
  p.A = MatrixXd(qr.householderQ()).leftCols(r);
  p.t = gaussian(rng, n, 1) * uniform(rng, 0.1, 4.0);
  p.lo.resize(n);
  p.hi.resize(n);
  p.x.resize(n);
  for (int i = 0; i < n; ++i) {
    p.lo[i] = -uniform(rng, 0.0, 2.0);
    p.hi[i] = uniform(rng, 0.0, 2.0);
    const double u = uniform(rng, 0, 1);
    if (u < 0.1)
      p.lo[i] = p.hi[i] = 0.0;  // a point box
    else if (u < 0.2)
      p.lo[i] = -kInf;  // a limit stop
    else if (u < 0.3)
      p.hi[i] = kInf;
    p.x[i] = uniform(rng, std::max(p.lo[i], -3.0), std::min(p.hi[i], 3.0));
    if (uniform(rng, 0, 1) < 0.2)
      p.x[i] = uniform(rng, 0, 1) < 0.5 && std::isfinite(p.lo[i]) ? p.lo[i] : std::isfinite(p.hi[i]) ? p.hi[i] : p.x[i];
  }
  return p;
}

}  // namespace

TEST_CASE("least-distance problems on a slice of the box: primal and dual against brute force",
          "[box_qp][least_distance]") {
  Rng rng(0x736c'6963'6521'0001ULL);
  double worst_primal = 0.0, worst_dual = 0.0, worst_plane = 0.0, worst_agreement = 0.0;
  int draws = 0;
  for (int draw = 0; draw < 1500; ++draw) {
    const int n = uniformInt(rng, 1, 6);
    const int r = draw % 3 == 0 && n > 1 ? uniformInt(rng, 2, n) : 1;
    const SliceProblem p = randomSlice(rng, n, r);
    VectorXd reference(n);
    const double best = bruteForceSlice(p, reference);
    CAPTURE(draw, n, r, p.A, p.t.transpose(), p.lo.transpose(), p.hi.transpose(), p.x.transpose());
    REQUIRE(std::isfinite(best));  // x itself is feasible
    const double scale = 1.0 + p.x.lpNorm<Eigen::Infinity>() + p.t.lpNorm<Eigen::Infinity>();
    const double tol = 1e-10 * scale * scale;
    ++draws;

    // Primal: the orthonormal complement N of A, z from 0.
    QpScratch scratch(n);
    VectorXd primal = p.x;
    if (r < n) {
      Eigen::HouseholderQR<MatrixXd> qr(p.A);
      const MatrixXd N = MatrixXd(qr.householderQ()).rightCols(n - r);
      VectorXd z = VectorXd::Zero(n - r);
      const VectorXd a = N.transpose() * (p.t - p.x);
      const QpReport report = leastDistanceQp(N, a, p.x, p.lo, p.hi, z, scratch, 1000);
      CAPTURE(report.iterations, z.transpose());
      REQUIRE(report.converged);
      primal = p.x + N * z;
    }
    CAPTURE(primal.transpose(), reference.transpose(), best);
    for (int i = 0; i < n; ++i) {
      REQUIRE(primal[i] >= p.lo[i] - 1e-12 * scale);
      REQUIRE(primal[i] <= p.hi[i] + 1e-12 * scale);
    }
    REQUIRE(p.objective(primal) <= best + tol);
    worst_primal = std::max(worst_primal, (p.objective(primal) - best) / (scale * scale));

    if (r != 1) continue;
    // Dual, on the hyperplane vᵀμ = b.
    VectorXd dual = VectorXd::Constant(n, std::nan(""));
    const VectorXd v = p.A.col(0);
    REQUIRE(leastDistanceOnHyperplane(v, v.dot(p.x), p.t, p.lo, p.hi, dual, scratch));
    CAPTURE(dual.transpose());
    for (int i = 0; i < n; ++i) {  // inside the box exactly (a clamp)
      REQUIRE(dual[i] >= p.lo[i]);
      REQUIRE(dual[i] <= p.hi[i]);
    }
    const double plane = std::abs(v.dot(dual) - v.dot(p.x)) / scale;
    REQUIRE(plane <= 1e-13);
    REQUIRE(p.objective(dual) <= best + tol);
    worst_dual = std::max(worst_dual, (p.objective(dual) - best) / (scale * scale));
    worst_plane = std::max(worst_plane, plane);
    // The minimiser is unique (strictly convex): primal and dual agree.
    const double agreement = (dual - primal).lpNorm<Eigen::Infinity>() / scale;
    REQUIRE(agreement <= 1e-8);
    worst_agreement = std::max(worst_agreement, agreement);
  }
  std::printf(
      "least distance on a slice, %d draws (n ≤ 6, r = 1 and 2..n): objective above brute force / scale²: "
      "primal %.3g, dual %.3g (limit 1e-10); dual |vᵀμ − b|/scale %.3g; |dual − primal|/scale %.3g\n",
      draws, worst_primal, worst_dual, worst_plane, worst_agreement);
}

// Two flat joints (0, 2) whose couplings to a barely curved joint 1 are at
// rounding (5e-16 of terms of size 1, against a curvature 1.3e-12 above the
// flatness floor 1e-8 / (6 · 2e4) ≈ 8e-14), joint 1 on its bound. Moving a flat joint over
// its whole box moves q̈ by 5e-16 · 2e4 = 1e-11, far inside the tolerance, so
// e_0 and e_2 are the flat directions and the least effort ‖h + μ‖² on them
// (EffortChange::Own) is μ_0 = −h_0, μ_2 = −h_2 with the rest as it was. A
// null basis carrying joint 1 by coupling / curvature ≈ 4e-4 would pin them
// on joint 1's bound.
TEST_CASE("flat directions: a coupling at rounding does not tie a flat joint to a curved one on its bound",
          "[box_qp][maximiser]") {
  const int n = 6;
  const double f = 1e4, acc_tolerance = 1e-8;
  MatrixXd K = MatrixXd::Zero(n, n);
  K(1, 1) = 1.3e-12;
  K(0, 1) = K(1, 0) = 5e-16;
  K(2, 1) = K(1, 2) = 5e-16;
  K.bottomRightCorner(3, 3) << 1.5, 0.1, 0.0, 0.1, 1.2, -0.2, 0.0, -0.2, 0.9;
  const VectorXd lo = VectorXd::Constant(n, -f), hi = VectorXd::Constant(n, f);
  VectorXd mu(n);
  mu << 0.0, f, 0.0, 1.0, -2.0, 3.0;
  const VectorXd qdd0 = K * mu;  // q̈* = 0: every joint sticks
  VectorXd h(n);
  h << 40.0, 0.0, -0.5, 0.0, 0.0, 0.0;
  MaximiserChoiceScratch scratch(n, n, n);
  Eigen::Index ns = 0;
  const VectorXd terms = VectorXd::Ones(n);  // K's entries are sums of terms of size 1
  const Eigen::Index nullity = flatDirections(K, qdd0, mu, lo, hi, terms, acc_tolerance, scratch, ns);
  REQUIRE(ns == n);
  REQUIRE(nullity == 2);
  const MatrixXd N = scratch.null_basis.topLeftCorner(n, nullity);
  CAPTURE(N);
  for (const int curved : {1, 3, 4, 5}) CHECK(N.row(curved).norm() <= 1e-12);  // rounding of the basis

  const double mu_scale = 1e-9 * (1.0 + f);  // as the solver's
  REQUIRE(leastEffortMaximiser(lo, hi, hi, h, ns, nullity, EffortChange::Own, n, mu_scale, 100, mu, scratch));
  VectorXd least(n);
  least << -40.0, f, 0.5, 1.0, -2.0, 3.0;
  CAPTURE(mu.transpose(), least.transpose());
  CHECK((mu - least).lpNorm<Eigen::Infinity>() <= 1e-12 * f);  // a few projections' rounding of numbers of size f
}
