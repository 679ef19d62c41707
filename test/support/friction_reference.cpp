#include "support/friction_reference.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/QR>
#include <Eigen/SVD>

#include "support/random_chain.hpp"
#include "support/random_problem.hpp"

namespace zwang::testing {

namespace {

using LongMatrix = Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>;
using LongVector = Eigen::Matrix<long double, Eigen::Dynamic, 1>;

void checkSetup(const ChainSpec& spec, const DynamicsInput& input, const FrictionSetup& setup) {
  const auto n = static_cast<Eigen::Index>(spec.dof());
  if (input.q.size() != n || input.qd.size() != n || input.tau.size() != n)
    throw std::invalid_argument("friction reference: q, qd, tau must have spec.dof() entries");
  if (setup.breakaway.size() != n || setup.kinetic.size() != n || setup.viscous.size() != n)
    throw std::invalid_argument("friction reference: breakaway, kinetic, viscous must have spec.dof() entries");
  if (setup.limit_side.size() != 0 && setup.limit_side.size() != n)
    throw std::invalid_argument("friction reference: limit_side must be empty or have spec.dof() entries");
  for (std::size_t s = 0; s < setup.stuck.size(); ++s) {
    const int j = setup.stuck[s];
    if (j < 0 || j >= n || (s > 0 && j <= setup.stuck[s - 1]))
      throw std::invalid_argument("friction reference: stuck joints must be ascending dof indices");
  }
}

int limitSide(const FrictionSetup& setup, int j) { return setup.limit_side.size() == 0 ? 0 : setup.limit_side(j); }

// The input with τ replaced by τ + τ_kinetic (the torque Z is written with).
DynamicsInput withKinetic(const DynamicsInput& input, const FrictionSetup& setup) {
  DynamicsInput in = input;
  in.tau = input.tau + kineticTorque(setup, input.qd);
  return in;
}

// Full-pivot LU in long double with one refinement step (as the dense reference).
struct LongSolver {
  LongMatrix K;
  Eigen::FullPivLU<LongMatrix> lu;
  explicit LongSolver(const LongMatrix& matrix) : K(matrix), lu(matrix) {}
  Eigen::VectorXd solve(const Eigen::VectorXd& rhs_double) const {
    const LongVector rhs = rhs_double.cast<long double>();
    LongVector x = lu.solve(rhs);
    x += lu.solve(LongVector(rhs - K * x));
    return x.cast<double>();
  }
};

// [H −Gᵀ; G 0] for constraint rows G.
LongMatrix kktMatrix(const Eigen::MatrixXd& H, const Eigen::MatrixXd& G) {
  const Eigen::Index n = H.rows(), m = G.rows();
  LongMatrix K = LongMatrix::Zero(n + m, n + m);
  K.topLeftCorner(n, n) = H.cast<long double>();
  K.topRightCorner(n, m) = -G.transpose().cast<long double>();
  K.bottomLeftCorner(m, n) = G.cast<long double>();
  return K;
}

enum class Choice { Stick, SlipPositive, SlipNegative };

}  // namespace

FrictionSetup frictionSetupFromSpec(const ChainSpec& spec, const Eigen::VectorXd& qd, double velocity_tolerance) {
  const int n = spec.dof();
  FrictionSetup s;
  s.breakaway.resize(n);
  s.kinetic.resize(n);
  s.viscous.resize(n);
  const std::vector<int> moving = spec.movingJoints();
  for (int j = 0; j < n; ++j) {
    const JointSpec& joint = spec.joints[static_cast<std::size_t>(moving[static_cast<std::size_t>(j)])];
    s.breakaway(j) = joint.friction;
    s.kinetic(j) = joint.friction;  // default f_c = f: docs/friction.md, "The model of friction"
    s.viscous(j) = joint.damping;   // URDF <dynamics damping>
    if (std::abs(qd(j)) <= velocity_tolerance && !joint.isMimic()) s.stuck.push_back(j);
  }
  foldMimicFriction(spec, s);
  return s;
}

void foldMimicFriction(const ChainSpec& spec, FrictionSetup& setup) {
  // A mimic joint moves with its leader (q̇_m = a·q̇_l): its friction torque
  // −f_m sign(q̇_m) − b_m q̇_m does the work of a times it at the leader, so it
  // folds into the leader's box: f_l + |a|·f_m (kinetic alike), b_l + a²·b_m.
  for (const MimicLaw& law : spec.mimicLaws()) {
    const double a = law.multiplier;
    setup.breakaway(law.leader) += std::abs(a) * setup.breakaway(law.joint);
    setup.kinetic(law.leader) += std::abs(a) * setup.kinetic(law.joint);
    setup.viscous(law.leader) += a * a * setup.viscous(law.joint);
    setup.breakaway(law.joint) = setup.kinetic(law.joint) = setup.viscous(law.joint) = 0.0;
    setup.stuck.erase(std::remove(setup.stuck.begin(), setup.stuck.end(), law.joint), setup.stuck.end());
  }
}

Eigen::VectorXd kineticTorque(const FrictionSetup& setup, const Eigen::VectorXd& qd) {
  Eigen::VectorXd t = Eigen::VectorXd::Zero(qd.size());
  for (Eigen::Index j = 0; j < qd.size(); ++j) {
    if (std::find(setup.stuck.begin(), setup.stuck.end(), static_cast<int>(j)) != setup.stuck.end()) continue;
    const double sign = qd(j) > 0.0 ? 1.0 : (qd(j) < 0.0 ? -1.0 : 0.0);
    t(j) = -setup.kinetic(j) * sign - setup.viscous(j) * qd(j);
  }
  return t;
}

namespace {

// The choices of each stuck coordinate (docs/friction.md, "Joint position limits").
std::vector<std::vector<Choice>> patternChoices(const FrictionSystem& system) {
  std::vector<std::vector<Choice>> choices(system.stuck.size());
  for (std::size_t s = 0; s < system.stuck.size(); ++s) {
    const int side = system.limit_side.size() == 0 ? 0 : system.limit_side(system.stuck[s]);
    choices[s].push_back(Choice::Stick);
    if (side != 1) choices[s].push_back(Choice::SlipPositive);   // not into the upper limit
    if (side != -1) choices[s].push_back(Choice::SlipNegative);  // not into the lower limit
  }
  return choices;
}

// The next pattern (mixed radix); false after the last.
bool nextPattern(const std::vector<std::vector<Choice>>& choices, std::vector<int>& digit) {
  for (std::size_t s = 0; s < digit.size(); ++s) {
    if (++digit[s] < static_cast<int>(choices[s].size())) return true;
    digit[s] = 0;
  }
  return false;
}

// True when [G; E_S] is rank deficient: its coupling matrix [G; E_S] H⁻¹ [G; E_S]ᵀ has
// λ_min ≤ threshold·λ_max.
bool singularRows(const Eigen::MatrixXd& rows, const Eigen::MatrixXd& Hinv, double threshold) {
  if (rows.rows() == 0) return false;
  const Eigen::MatrixXd L = rows * Hinv * rows.transpose();
  const Eigen::VectorXd ev =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(0.5 * (L + L.transpose()), Eigen::EigenvaluesOnly).eigenvalues();
  return !(ev(0) > threshold * ev(ev.size() - 1));
}

// τ_control of a pattern: the motors' τ plus the force of the rows they carry, the
// leaders carrying their mimic joints' share.
Eigen::VectorXd controlTorque(const FrictionSystem& system, const Eigen::VectorXd& nu) {
  Eigen::VectorXd tau = system.tau_motor + system.G.transpose() * system.motor.cwiseProduct(nu);
  for (const MimicLaw& law : system.mimic_laws) {  // resolved leaders are independent: any order
    tau(law.leader) += law.multiplier * tau(law.joint);
    tau(law.joint) = 0.0;
  }
  return tau;
}

// Maximum dissipation for a solved pattern (docs/theory.md §5; docs/friction.md,
// "Joint position limits"); writes the pattern's letters.
bool dissipates(const FrictionSystem& system, const std::vector<Choice>& chosen, const Eigen::VectorXd& qdd,
                const Eigen::VectorXd& mu, const BruteForceOptions& options, std::string& pattern) {
  const double f_scale = std::max(1.0, system.stuck.empty() ? 0.0 : system.breakaway.maxCoeff());
  const double t_tol = options.torque_tolerance * std::max(f_scale, mu.cwiseAbs().maxCoeff());
  const double a_tol = options.acceleration_tolerance * std::max(1.0, qdd.cwiseAbs().maxCoeff());
  bool valid = true;
  pattern.clear();
  for (std::size_t s = 0; s < system.stuck.size(); ++s) {
    const int j = system.stuck[s];
    const int side = system.limit_side.size() == 0 ? 0 : system.limit_side(j);
    const double f = system.breakaway(j);
    if (chosen[s] == Choice::Stick) {
      const bool above = mu(j) > f + t_tol, below = mu(j) < -f - t_tol;
      if ((above && side <= 0) || (below && side >= 0)) valid = false;
      pattern += (above || below) ? 'L' : 's';
    } else if (chosen[s] == Choice::SlipPositive) {
      if (qdd(j) < -a_tol) valid = false;
      pattern += '+';
    } else {
      if (qdd(j) > a_tol) valid = false;
      pattern += '-';
    }
  }
  return valid;
}

// Record a valid pattern: the first becomes the reference's answer, the others
// measure the spread.
void addValidPattern(FrictionPattern pattern, FrictionReference& out) {
  if (out.valid.empty()) {
    out.feasible = true;
    out.qdd = pattern.qdd;
    out.mu = pattern.mu;
    out.nu = pattern.nu;
    out.tau_control = pattern.tau_control;
    out.gauss_dual = pattern.gauss_dual;
    out.pattern = pattern.pattern;
  } else {
    const Eigen::VectorXd d = pattern.qdd - out.qdd;
    out.qdd_spread = std::max(out.qdd_spread, d.cwiseAbs().maxCoeff() / std::max(1.0, out.qdd.cwiseAbs().maxCoeff()));
    out.gauss_spread = std::max(out.gauss_spread, std::abs(pattern.gauss_dual - out.gauss_dual) /
                                                      std::max(1.0, std::abs(out.gauss_dual)));
    out.mu_spread = std::max(out.mu_spread, (pattern.mu - out.mu).cwiseAbs().maxCoeff());
  }
  out.valid.push_back(std::move(pattern));
  out.valid_patterns = static_cast<int>(out.valid.size());
}

// FrictionReference::pinned: the rows [G; e_jᵀ for every sticking j] rank deficient.
bool pinnedSticking(const FrictionSystem& system, const Eigen::VectorXd& qdd, const Eigen::MatrixXd& Hinv,
                    const BruteForceOptions& options) {
  const double a_tol = options.acceleration_tolerance * std::max(1.0, qdd.cwiseAbs().maxCoeff());
  std::vector<int> sticking;
  for (const int j : system.stuck)
    if (std::abs(qdd(j)) <= a_tol) sticking.push_back(j);
  if (sticking.empty()) return false;
  const auto m = system.G.rows();
  Eigen::MatrixXd rows = Eigen::MatrixXd::Zero(m + static_cast<Eigen::Index>(sticking.size()), system.H.rows());
  rows.topRows(m) = system.G;
  for (std::size_t s = 0; s < sticking.size(); ++s) rows(m + static_cast<Eigen::Index>(s), sticking[s]) = 1.0;
  return singularRows(rows, Hinv, options.singular_threshold);
}

}  // namespace

FrictionReference bruteForceFriction(const FrictionSystem& system, const BruteForceOptions& options) {
  const auto n = static_cast<int>(system.H.rows());
  const auto m = static_cast<int>(system.G.rows());
  const auto k = static_cast<int>(system.stuck.size());
  const Eigen::MatrixXd Hinv = system.H.llt().solve(Eigen::MatrixXd::Identity(n, n));
  const std::vector<std::vector<Choice>> choices = patternChoices(system);

  FrictionReference out;
  std::vector<int> digit(static_cast<std::size_t>(k), 0);
  std::vector<Choice> chosen(static_cast<std::size_t>(k));
  do {
    ++out.patterns;
    // The pattern's system: slipping coordinates get ∓f as a torque, sticking ones a row e_jᵀ ẍ = 0.
    std::vector<int> stick;
    Eigen::VectorXd tau = system.tau;
    Eigen::VectorXd mu = Eigen::VectorXd::Zero(n);
    for (int s = 0; s < k; ++s) {
      const auto su = static_cast<std::size_t>(s);
      const int j = system.stuck[su];
      chosen[su] = choices[su][static_cast<std::size_t>(digit[su])];
      if (chosen[su] == Choice::Stick) {
        stick.push_back(j);
      } else {
        mu(j) = chosen[su] == Choice::SlipPositive ? system.breakaway(j) : -system.breakaway(j);
        tau(j) -= mu(j);  // the coordinate feels −μ_j
      }
    }
    const int r = m + static_cast<int>(stick.size());
    Eigen::MatrixXd rows = Eigen::MatrixXd::Zero(r, n);
    Eigen::VectorXd gamma = Eigen::VectorXd::Zero(r);
    rows.topRows(m) = system.G;
    gamma.head(m) = system.gamma;
    for (std::size_t s = 0; s < stick.size(); ++s) rows(m + static_cast<int>(s), stick[s]) = 1.0;
    if (singularRows(rows, Hinv, options.singular_threshold)) {
      ++out.singular_patterns;
      continue;
    }
    const LongSolver solver(kktMatrix(system.H, rows));
    Eigen::VectorXd rhs(n + r);
    rhs << tau - system.C, gamma;
    const Eigen::VectorXd x = solver.solve(rhs);
    FrictionPattern pattern;
    pattern.qdd = x.head(n);
    for (std::size_t s = 0; s < stick.size(); ++s) mu(stick[s]) = -x(n + m + static_cast<int>(s));
    if (!dissipates(system, chosen, pattern.qdd, mu, options, pattern.pattern)) continue;
    pattern.mu = mu;
    pattern.nu = x.segment(n, m);
    pattern.tau_control = controlTorque(system, pattern.nu);
    // g(μ) = Z(ẍ) + μᵀWẍ, Z the quadratic of the system (with τ + τ_kinetic).
    pattern.gauss_dual = system.gauss_at_rest + 0.5 * pattern.qdd.dot(system.H * pattern.qdd) +
                         (system.C - system.tau).dot(pattern.qdd) + mu.dot(pattern.qdd);
    addValidPattern(std::move(pattern), out);
  } while (nextPattern(choices, digit));
  if (out.feasible) out.pinned = pinnedSticking(system, out.qdd, Hinv, options);
  if (!out.feasible) {
    out.qdd = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::quiet_NaN());
    out.mu = out.qdd;
    out.gauss_dual = std::numeric_limits<double>::quiet_NaN();
  }
  return out;
}

namespace {

// A friction system with the dense reference's H, C, G and γ (a DenseResult
// or a FloatingResult: the same fields); the rest is the caller's.
template <class Dense>
FrictionSystem dynamicsOf(const Dense& dense) {
  FrictionSystem system;
  system.H = dense.H;
  system.C = dense.C;
  system.G = dense.G;
  system.gamma = dense.gamma;
  return system;
}

}  // namespace

FrictionReference bruteForceFriction(const ChainSpec& spec, const DynamicsInput& input, const FrictionSetup& setup,
                                     const BruteForceOptions& options) {
  checkSetup(spec, input, setup);
  const DynamicsInput in = withKinetic(input, setup);  // τ' = τ + τ_kinetic
  const DenseResult dense = denseDynamics(spec, in);   // H, C, G, γ (independent of τ)
  FrictionSystem system = dynamicsOf(dense);
  system.tau = in.tau;
  system.gauss_at_rest = gaussFunction(spec, in, Eigen::VectorXd::Zero(spec.dof()));
  system.stuck = setup.stuck;
  system.breakaway = setup.breakaway;
  system.limit_side = setup.limit_side;
  system.tau_motor = input.tau;
  system.motor = Eigen::VectorXd::Ones(dense.G.rows());
  system.mimic_laws = spec.mimicLaws();
  FrictionReference out = bruteForceFriction(system, options);
  out.tau_kinetic = in.tau - input.tau;
  return out;
}

FrictionReference bruteForceFloatingFriction(const ChainSpec& spec, const FloatingBase& base,
                                             const FloatingInput& input, const FrictionSetup& setup,
                                             const BruteForceOptions& options) {
  const int n = spec.dof(), base_velocity_size = base.baseVelocitySize();
  if (input.v.size() != base_velocity_size + n || input.tau.size() != base_velocity_size + n)
    throw std::invalid_argument("friction reference: v and tau must have nv entries");
  if (setup.breakaway.size() != n || setup.kinetic.size() != n || setup.viscous.size() != n ||
      (setup.limit_side.size() != 0 && setup.limit_side.size() != n))
    throw std::invalid_argument("friction reference: the setup must have spec.dof() entries per joint");
  FloatingInput in = input;
  const Eigen::VectorXd kinetic = kineticTorque(setup, input.v.tail(n));
  in.tau.tail(n) += kinetic;  // τ' = τ + τ_kinetic
  const FloatingResult dense = floatingDynamics(spec, base, in);
  FrictionSystem system = dynamicsOf(dense);
  system.tau = in.tau;
  system.gauss_at_rest = floatingGaussFunction(spec, base, in, Eigen::VectorXd::Zero(base_velocity_size + n));
  for (const int j : setup.stuck) system.stuck.push_back(base_velocity_size + j);  // the base is never stuck
  system.breakaway = Eigen::VectorXd::Zero(base_velocity_size + n);
  system.breakaway.tail(n) = setup.breakaway;
  if (setup.limit_side.size() != 0) {
    system.limit_side = Eigen::VectorXi::Zero(base_velocity_size + n);
    system.limit_side.tail(n) = setup.limit_side;
  }
  system.tau_motor = input.tau;
  system.motor = motorRows(input, static_cast<int>(dense.G.rows()));
  for (MimicLaw law : spec.mimicLaws()) {
    law.joint += base_velocity_size;
    law.leader += base_velocity_size;
    system.mimic_laws.push_back(law);
  }
  FrictionReference out = bruteForceFriction(system, options);
  out.tau_kinetic = kinetic;
  // μ per joint, as the fixed base's (the base has none).
  const Eigen::VectorXd mu = out.mu.tail(n);
  out.mu = mu;
  for (FrictionPattern& p : out.valid) {
    const Eigen::VectorXd joint_mu = p.mu.tail(n);
    p.mu = joint_mu;
  }
  return out;
}

namespace {

// min ‖Σ α_i p_i‖ over Σ α_i = 1 (the affine hull's least-norm point), as
// p₀ + D β with D = [p_i − p₀]: β = −D⁺p₀ by a complete orthogonal
// decomposition of D (the least-norm β if the points are affinely
// dependent), α = (1 − Σβ, β). (Not from the bordered system
// [PᵀP 1; 1ᵀ 0]: with points far from the origin next to their spread — a
// torque of 6e3 N·m that friction moves by 1e2 — PᵀP's entries agree to 1e-3
// and that system's rank is misjudged, which stalled Wolfe's method on the
// draws of "the contacts share the load".)
Eigen::VectorXd affineMinimizer(const Eigen::MatrixXd& P) {
  const Eigen::Index s = P.cols();
  Eigen::VectorXd alpha(s);
  if (s == 1) return Eigen::VectorXd::Ones(1);
  const Eigen::MatrixXd D = P.rightCols(s - 1).colwise() - P.col(0);
  const Eigen::VectorXd beta = -Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(D).solve(P.col(0));
  alpha(0) = 1.0 - beta.sum();
  alpha.tail(s - 1) = beta;
  return alpha;
}

// The columns of `points` named by `set`.
Eigen::MatrixXd columns(const Eigen::MatrixXd& points, const std::vector<int>& set) {
  Eigen::MatrixXd P(points.rows(), static_cast<Eigen::Index>(set.size()));
  for (std::size_t i = 0; i < set.size(); ++i) P.col(static_cast<Eigen::Index>(i)) = points.col(set[i]);
  return P;
}

// Wolfe's minor cycle: from weights w on `set` (all > 0) move to the affine
// minimiser of the set, dropping the points whose weight reaches 0 on the way,
// until the affine minimiser lies inside the simplex.
void wolfeMinorCycle(const Eigen::MatrixXd& points, std::vector<int>& set, Eigen::VectorXd& w) {
  constexpr double kTiny = 1e-14;  // a weight this small is 0: rounding of weights that sum to 1
  for (;;) {
    const Eigen::VectorXd alpha = affineMinimizer(columns(points, set));
    if (alpha.minCoeff() > kTiny) {
      w = alpha;
      return;
    }
    double theta = 1.0;
    for (Eigen::Index i = 0; i < alpha.size(); ++i)
      if (alpha(i) <= kTiny) theta = std::min(theta, w(i) / (w(i) - alpha(i)));
    w = ((1.0 - theta) * w + theta * alpha).eval();
    std::vector<int> kept;
    std::vector<double> kept_w;
    for (Eigen::Index i = 0; i < w.size(); ++i)
      if (w(i) > kTiny) {
        kept.push_back(set[static_cast<std::size_t>(i)]);
        kept_w.push_back(w(i));
      }
    set = kept;
    w = Eigen::Map<const Eigen::VectorXd>(kept_w.data(), static_cast<Eigen::Index>(kept_w.size()));
    w /= w.sum();
  }
}

// The point of least norm in the hull of the valid patterns' `point(p)` (repeats merged), and the τ_control
// coordinates from `first` on and μ of the same combination.
template <class Point>
LeastEffort leastNormOfHull(const FrictionReference& reference, Eigen::Index first, Point point) {
  if (!reference.feasible) throw std::invalid_argument("leastNormOfHull: no valid pattern");
  const Eigen::Index counted = reference.tau_control.size() - first;
  double scale = 1.0;
  for (const FrictionPattern& p : reference.valid) scale = std::max(scale, point(p).cwiseAbs().maxCoeff());
  std::vector<const FrictionPattern*> distinct;
  for (const FrictionPattern& p : reference.valid) {
    bool repeat = false;
    for (const FrictionPattern* d : distinct)
      repeat = repeat || (point(p) - point(*d)).cwiseAbs().maxCoeff() <= 1e-12 * scale;
    if (!repeat) distinct.push_back(&p);
  }
  const auto count = static_cast<Eigen::Index>(distinct.size());
  Eigen::MatrixXd points(point(reference.valid.front()).size(), count);
  for (Eigen::Index i = 0; i < count; ++i) points.col(i) = point(*distinct[static_cast<std::size_t>(i)]);

  // Wolfe (1976): start at the point of least norm; add the point that most
  // lowers xᵀp while it lowers it by more than rounding; re-solve on the set.
  Eigen::Index start = 0;
  points.colwise().squaredNorm().minCoeff(&start);
  std::vector<int> set{static_cast<int>(start)};
  Eigen::VectorXd w = Eigen::VectorXd::Ones(1);
  for (int iteration = 0; iteration < 10 * static_cast<int>(count) + 10; ++iteration) {
    const Eigen::VectorXd x = columns(points, set) * w;
    Eigen::Index best = 0;
    const double lowest = (x.transpose() * points).minCoeff(&best);
    // Stop when no point lowers xᵀp below |x|² by more than rounding of |p|².
    if (x.squaredNorm() - lowest <= 1e-13 * scale * scale) break;
    if (std::find(set.begin(), set.end(), static_cast<int>(best)) != set.end()) break;  // rounding: cannot improve
    set.push_back(static_cast<int>(best));
    w.conservativeResize(w.size() + 1);
    w(w.size() - 1) = 0.0;
    wolfeMinorCycle(points, set, w);
  }
  LeastEffort out;
  out.distinct_points = static_cast<int>(count);
  out.tau_control = Eigen::VectorXd::Zero(counted);
  out.mu = Eigen::VectorXd::Zero(reference.mu.size());
  for (std::size_t i = 0; i < set.size(); ++i) {
    const FrictionPattern& p = *distinct[static_cast<std::size_t>(set[i])];
    out.tau_control += w(static_cast<Eigen::Index>(i)) * p.tau_control.tail(counted);
    out.mu += w(static_cast<Eigen::Index>(i)) * p.mu;
  }
  return out;
}

}  // namespace

LeastEffort leastEffortMaximiser(const FrictionReference& reference, Eigen::Index first) {
  const Eigen::Index counted = reference.tau_control.size() - first;
  return leastNormOfHull(
      reference, first, [counted](const FrictionPattern& p) -> Eigen::VectorXd { return p.tau_control.tail(counted); });
}

LeastEffort leastNormMaximiser(const FrictionReference& reference, Eigen::Index first) {
  return leastNormOfHull(reference, first, [](const FrictionPattern& p) -> Eigen::VectorXd { return p.mu; });
}

FrictionDual denseFrictionDual(const ChainSpec& spec, const DynamicsInput& input, const FrictionSetup& setup,
                               const Eigen::VectorXd& mu) {
  checkSetup(spec, input, setup);
  DynamicsInput in = withKinetic(input, setup);
  Eigen::VectorXd mu_stuck = Eigen::VectorXd::Zero(spec.dof());
  for (int j : setup.stuck) mu_stuck(j) = mu(j);
  in.tau -= mu_stuck;
  // denseDynamics' Gauss function is written with τ − Wᵀμ, which is exactly
  // Z(q̈) + μᵀWq̈ with Z written with τ (+ τ_kinetic).
  const DenseResult r = denseDynamics(spec, in);
  return {r.qdd, r.gauss};
}

Eigen::MatrixXd denseConstrainedInverseInertia(const ChainSpec& spec, const DynamicsInput& input) {
  const DenseResult base = denseDynamics(spec, input);
  const int n = static_cast<int>(base.H.rows()), m = static_cast<int>(base.G.rows());
  const LongSolver solver(kktMatrix(base.H, base.G));
  Eigen::MatrixXd K(n, n);
  for (int j = 0; j < n; ++j) {
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n + m);
    rhs(j) = 1.0;
    K.col(j) = solver.solve(rhs).head(n);
  }
  return K;
}

SampledFriction sampledFriction(const ChainSpec& spec, const DynamicsInput& input, const FrictionSetup& setup,
                                int points) {
  checkSetup(spec, input, setup);
  const int n = spec.dof();
  const int k = static_cast<int>(setup.stuck.size());
  if (k < 1 || k > 2) throw std::invalid_argument("sampledFriction: only k = 1 or 2 stuck joints");
  if (points < 2) throw std::invalid_argument("sampledFriction: at least 2 points per axis");
  for (int j : setup.stuck)
    if (limitSide(setup, j) != 0) throw std::invalid_argument("sampledFriction: no limits (the box must be finite)");

  const DynamicsInput in = withKinetic(input, setup);
  const DenseResult base = denseDynamics(spec, in);
  const int m = static_cast<int>(base.G.rows());
  const LongSolver solver(kktMatrix(base.H, base.G));
  // Z(q̈) = Z(0) + ½ q̈ᵀHq̈ + (C − τ')ᵀq̈ (the dense Gauss function is quadratic in q̈).
  const double Z0 = gaussFunction(spec, in, Eigen::VectorXd::Zero(n));

  SampledFriction out;
  out.spacing.resize(k);
  for (int s = 0; s < k; ++s)
    out.spacing(s) = 2.0 * setup.breakaway(setup.stuck[static_cast<std::size_t>(s)]) / (points - 1);
  out.g = -std::numeric_limits<double>::infinity();
  const int total = k == 1 ? points : points * points;
  for (int idx = 0; idx < total; ++idx) {
    Eigen::VectorXd mu = Eigen::VectorXd::Zero(n);
    int rest = idx;
    for (int s = 0; s < k; ++s) {
      const int j = setup.stuck[static_cast<std::size_t>(s)];
      const int i = rest % points;
      rest /= points;
      mu(j) = -setup.breakaway(j) + i * out.spacing(s);
      if (i == points - 1) mu(j) = setup.breakaway(j);  // endpoints exact
    }
    Eigen::VectorXd rhs(n + m);
    rhs << in.tau - mu - base.C, base.gamma;
    const Eigen::VectorXd qdd = solver.solve(rhs).head(n);
    const double Z = Z0 + 0.5 * qdd.dot(base.H * qdd) + (base.C - in.tau).dot(qdd);
    const double g = Z + mu.dot(qdd);
    ++out.evaluations;
    if (g > out.g) {
      out.g = g;
      out.mu = mu;
      out.qdd = qdd;
    }
  }
  return out;
}

namespace {

// The problem, state and stuck set of a friction draw on a given spec.
FrictionDraw frictionDrawOn(std::mt19937_64& rng, ChainSpec spec, int min_stuck, int max_stuck, int max_rows,
                            double relative_probability) {
  FrictionDraw d;
  d.spec = std::move(spec);
  const int n = d.spec.dof();
  RandomProblemOptions problem;
  problem.max_constraint_rows = std::min(max_rows, n);  // more rows than joints can never be met
  problem.relative_probability = relative_probability;
  d.input = randomProblem(rng, d.spec, problem);
  const std::vector<int> moving = d.spec.movingJoints();
  for (int j = 0; j < n; ++j) {
    const JointSpec& joint = d.spec.joints[static_cast<std::size_t>(moving[static_cast<std::size_t>(j)])];
    if (joint.type != "continuous") {
      const double margin = 0.05 * (joint.upper - joint.lower);
      d.input.q(j) = uniform(rng, joint.lower + margin, joint.upper - margin);
    }
    d.input.qd(j) = (uniform01(rng) < 0.5 ? -1.0 : 1.0) * uniform(rng, 0.1, 2.0);
  }
  // Choose the stuck joints among the independent ones (all of them without mimic joints).
  std::vector<int> all;
  for (int j = 0; j < n; ++j)
    if (!d.spec.joints[static_cast<std::size_t>(moving[static_cast<std::size_t>(j)])].isMimic()) all.push_back(j);
  const int free = static_cast<int>(all.size());
  const int k = uniformInt(rng, std::min(min_stuck, free), std::min(max_stuck, free));
  for (int s = 0; s < k; ++s)  // partial Fisher–Yates with the portable uniformInt
    std::swap(all[static_cast<std::size_t>(s)], all[static_cast<std::size_t>(uniformInt(rng, s, free - 1))]);
  std::vector<int> stuck(all.begin(), all.begin() + k);
  std::sort(stuck.begin(), stuck.end());
  for (int j : stuck) d.input.qd(j) = 0.0;
  d.spec.followMimicLaws(d.input.q, d.input.qd);  // mimic joints where their leaders put them
  d.setup = frictionSetupFromSpec(d.spec, d.input.qd);
  return d;
}

}  // namespace

FrictionDraw randomFrictionDraw(std::mt19937_64& rng, int min_dof, int max_dof, int min_stuck, int max_stuck,
                                int max_rows) {
  RandomChainOptions chain;
  chain.min_moving_joints = min_dof;
  chain.max_moving_joints = max_dof;
  ChainSpec spec = randomChain(rng, chain);
  return frictionDrawOn(rng, std::move(spec), min_stuck, max_stuck, max_rows, 0.0);
}

FrictionDraw randomTreeFrictionDraw(std::mt19937_64& rng, int min_dof, int max_dof, int max_stuck, int max_rows,
                                    double relative_probability) {
  RandomTreeOptions tree;
  tree.min_moving_joints = min_dof;
  tree.max_moving_joints = max_dof;
  ChainSpec spec = randomTree(rng, tree);
  return frictionDrawOn(rng, std::move(spec), 1, max_stuck, max_rows, relative_probability);
}

FrictionDraw randomTreeMimicFrictionDraw(std::mt19937_64& rng, int min_dof, int max_dof, int max_stuck, int max_rows,
                                         double relative_probability, const RandomMimicOptions& mimics) {
  RandomTreeOptions tree;
  tree.min_moving_joints = min_dof;
  tree.max_moving_joints = max_dof;
  ChainSpec spec = randomTree(rng, tree);
  const int k = addRandomMimics(rng, spec, mimics);
  const int rows = std::min(max_rows, spec.dof() - k);  // more rows than independent joints can never be met
  return frictionDrawOn(rng, std::move(spec), 1, max_stuck, rows, relative_probability);
}

bool wellPosed(const DenseResult& dense, int rows, double max_condition) {
  if (!dense.wellConditioned(max_condition) || dense.constraint_rank < rows) return false;
  if (rows > 0 && Eigen::JacobiSVD<Eigen::MatrixXd>(dense.G).singularValues().minCoeff() < 1e-6) return false;
  return true;
}

}  // namespace zwang::testing
