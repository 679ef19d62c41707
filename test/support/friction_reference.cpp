#include "support/friction_reference.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
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

FrictionReference bruteForceFriction(const ChainSpec& spec, const DynamicsInput& input, const FrictionSetup& setup,
                                     const BruteForceOptions& options) {
  checkSetup(spec, input, setup);
  const int n = spec.dof();
  const int k = static_cast<int>(setup.stuck.size());
  const DynamicsInput in = withKinetic(input, setup);  // τ' = τ + τ_kinetic
  const DenseResult base = denseDynamics(spec, in);    // H, C, G, γ (independent of τ)
  const int m = static_cast<int>(base.G.rows());
  const Eigen::MatrixXd Hinv = base.H.llt().solve(Eigen::MatrixXd::Identity(n, n));

  // The choices of each stuck joint (docs/friction.md, "Joint position limits").
  std::vector<std::vector<Choice>> choices(static_cast<std::size_t>(k));
  for (int s = 0; s < k; ++s) {
    const int side = limitSide(setup, setup.stuck[static_cast<std::size_t>(s)]);
    auto& c = choices[static_cast<std::size_t>(s)];
    c.push_back(Choice::Stick);
    if (side != 1) c.push_back(Choice::SlipPositive);   // not into the upper limit
    if (side != -1) c.push_back(Choice::SlipNegative);  // not into the lower limit
  }

  FrictionReference out;
  out.tau_kinetic = in.tau - input.tau;
  const double f_scale = std::max(1.0, k > 0 ? setup.breakaway.maxCoeff() : 0.0);
  std::vector<int> digit(static_cast<std::size_t>(k), 0);
  for (;;) {
    ++out.patterns;
    // Build the pattern's system.
    std::vector<int> stick;
    Eigen::VectorXd tau = in.tau;
    Eigen::VectorXd mu = Eigen::VectorXd::Zero(n);
    for (int s = 0; s < k; ++s) {
      const int j = setup.stuck[static_cast<std::size_t>(s)];
      const Choice c =
          choices[static_cast<std::size_t>(s)][static_cast<std::size_t>(digit[static_cast<std::size_t>(s)])];
      if (c == Choice::Stick) {
        stick.push_back(j);
      } else {
        mu(j) = c == Choice::SlipPositive ? setup.breakaway(j) : -setup.breakaway(j);
        tau(j) -= mu(j);  // the joint feels −μ_j
      }
    }
    const int r = m + static_cast<int>(stick.size());
    Eigen::MatrixXd Gaug = Eigen::MatrixXd::Zero(r, n);
    Eigen::VectorXd gamma = Eigen::VectorXd::Zero(r);
    Gaug.topRows(m) = base.G;
    gamma.head(m) = base.gamma;
    for (std::size_t s = 0; s < stick.size(); ++s) Gaug(m + static_cast<int>(s), stick[s]) = 1.0;

    bool singular = false;
    if (r > 0) {
      const Eigen::MatrixXd L = Gaug * Hinv * Gaug.transpose();
      const Eigen::VectorXd ev =
          Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(0.5 * (L + L.transpose()), Eigen::EigenvaluesOnly)
              .eigenvalues();
      singular = !(ev(0) > options.singular_threshold * ev(ev.size() - 1));
    }
    if (singular) {
      ++out.singular_patterns;
    } else {
      const LongSolver solver(kktMatrix(base.H, Gaug));
      Eigen::VectorXd rhs(n + r);
      rhs << tau - base.C, gamma;
      const Eigen::VectorXd x = solver.solve(rhs);
      const Eigen::VectorXd qdd = x.head(n);
      for (std::size_t s = 0; s < stick.size(); ++s) mu(stick[s]) = -x(n + m + static_cast<int>(s));

      // Maximum dissipation (docs/theory.md §5; docs/friction.md, "Joint position limits").
      const double t_tol = options.torque_tolerance * std::max(f_scale, mu.cwiseAbs().maxCoeff());
      const double a_tol = options.acceleration_tolerance * std::max(1.0, qdd.cwiseAbs().maxCoeff());
      bool valid = true;
      std::string pattern;
      for (int s = 0; s < k; ++s) {
        const int j = setup.stuck[static_cast<std::size_t>(s)];
        const int side = limitSide(setup, j);
        const double f = setup.breakaway(j);
        const Choice c =
            choices[static_cast<std::size_t>(s)][static_cast<std::size_t>(digit[static_cast<std::size_t>(s)])];
        if (c == Choice::Stick) {
          const bool above = mu(j) > f + t_tol, below = mu(j) < -f - t_tol;
          if ((above && side <= 0) || (below && side >= 0)) valid = false;
          pattern += (above || below) ? 'L' : 's';
        } else if (c == Choice::SlipPositive) {
          if (qdd(j) < -a_tol) valid = false;
          pattern += '+';
        } else {
          if (qdd(j) > a_tol) valid = false;
          pattern += '-';
        }
      }
      if (valid) {
        // g(μ) = Z(q̈) + μᵀWq̈, Z with τ + τ_kinetic.
        const double g = gaussFunction(spec, in, qdd) + mu.dot(qdd);
        if (out.valid_patterns == 0) {
          out.feasible = true;
          out.qdd = qdd;
          out.mu = mu;
          out.nu = x.segment(n, m);
          out.gauss_dual = g;
          out.pattern = pattern;
        } else {
          Eigen::VectorXd d = qdd - out.qdd;
          out.qdd_spread =
              std::max(out.qdd_spread, d.cwiseAbs().maxCoeff() / std::max(1.0, out.qdd.cwiseAbs().maxCoeff()));
          out.gauss_spread =
              std::max(out.gauss_spread, std::abs(g - out.gauss_dual) / std::max(1.0, std::abs(out.gauss_dual)));
          out.mu_spread = std::max(out.mu_spread, (mu - out.mu).cwiseAbs().maxCoeff());
        }
        ++out.valid_patterns;
      }
    }

    // Next pattern (mixed radix).
    int s = 0;
    while (s < k) {
      auto& d = digit[static_cast<std::size_t>(s)];
      if (++d < static_cast<int>(choices[static_cast<std::size_t>(s)].size())) break;
      d = 0;
      ++s;
    }
    if (s == k) break;
  }
  if (!out.feasible) {
    out.qdd = Eigen::VectorXd::Constant(n, std::numeric_limits<double>::quiet_NaN());
    out.mu = out.qdd;
    out.gauss_dual = std::numeric_limits<double>::quiet_NaN();
  }
  return out;
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
