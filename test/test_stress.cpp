// Numerical stress (issue #6): random chains far outside the comfortable range —
// masses 1e-6 to 1e4 kg, link lengths 1e-3 to 10 m (the same scale on the
// whole chain, or an independent one per link: mass ratios up to 1e10), rotor
// inertias 0 to 1e3, joint speeds up to 1e3 rad/s, breakaway friction 0 to
// 1e4 N·m, torques up to 1e4 — with well-posed, near-singular and exactly
// singular tasks and stuck sets of every size (0 to n).
//
// Every result must be finite (or a documented error status), the friction
// maximiser must stop within its cap, and the results must satisfy their
// optimality conditions, measured as relative residuals (backward errors):
//   closure     ‖ID(q̈) − τ_ctrl − τ_friction‖∞ / (‖H‖∞‖q̈‖∞ + ‖C‖∞ + ‖H‖∞‖q̇‖∞² + ‖τ_ctrl‖∞ + ‖τ_friction‖∞)
//               (the free arm driven by the solver's torques accelerates with q̈);
//   constraint  ‖G q̈ − γ‖∞ / (‖G‖∞(‖q̈‖∞ + ‖H⁻¹Gᵀν‖∞) + ‖γ‖∞), G and γ from the independent dense
//               reference (only when the coupling matrix is regular: a singular task
//               holds in the least-squares sense, test_singular);
//   τ_c         ‖τ_c − Gᵀν‖∞ / (‖G‖∞‖ν‖∞ + ‖τ_c‖∞) (the constraint torques are the
//               physical ones, in the range of Gᵀ);
//   dissipation on the stuck joints (docs/friction.md): |μ_j| ≤ f_j (excess relative to max(1, f));
//               |μ_j| < f_j ⇒ q̈_j = 0;
//               μ_j = f_j ⇒ q̈_j ≥ 0; μ_j = −f_j ⇒ q̈_j ≤ 0, the q̈ violation relative
//               to max(‖q̈(0)_Θ‖∞, ‖K_ΘΘ μ*‖∞) (the accelerations friction acts on);
//   agreement   the two maximisers give the same q̈* (it is unique), relative to ‖q̈*‖∞
//               plus the same acceleration scale.
// The tolerances are stated below; the worst values are printed. Every
// condition is asserted on every draw, as is convergence of the active set
// within its cap (the projected-gradient maximiser is a first-order method: its
// misses at the cap on ill-conditioned draws are counted and printed, and it is
// held to the conditions only when it reports convergence). Until 07b5784 the
// dissipation, convergence and agreement conditions missed on a few draws
// (worst 3.1e-2, two runs at the cap) and were asserted only by a hidden run.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include <catch2/catch.hpp>

#include "support/random_chain.hpp"
#include "support/random_problem.hpp"

using namespace zwang;
using namespace zwang::testing;

namespace {

// Stated tolerances (relative residuals, see the header comment).
constexpr double kClosureTolerance = 1e-9;
// Singular tasks are solved damped, with ν up to ~1/λ larger than the task's
// scale: closure holds to rounding of those larger forces (1.0e-9 seen with
// clang -O1 + ASan against 1.5e-10 with g++ -O3), so one decade more room.
constexpr double kSingularClosureTolerance = 1e-8;
constexpr double kConstraintTolerance = 1e-6;
constexpr double kTauConstraintTolerance = 1e-9;
constexpr double kDissipationTolerance = 1e-6;
// A singular task is solved damped; its ν, up to ~1/λ larger than the task's
// scale, enters every acceleration, so K_ΘΘ and q̈* carry that much more rounding.
constexpr double kSingularDissipationTolerance = 1e-5;
constexpr double kAgreementTolerance = 1e-6;
// The two maximisers' q̈* differ by that rounding too (ZWANG_STRESS_SEED=8: a
// repeated row, 1.1e-6 apart, both KKT residuals below 1e-12).
constexpr double kSingularAgreementTolerance = 1e-5;

double logUniform(std::mt19937_64& rng, double lo, double hi) { return lo * std::pow(hi / lo, uniform01(rng)); }

double inf(const Eigen::MatrixXd& M) { return M.size() == 0 ? 0.0 : M.cwiseAbs().rowwise().sum().maxCoeff(); }
double inf(const Eigen::VectorXd& v) { return v.size() == 0 ? 0.0 : v.cwiseAbs().maxCoeff(); }
double ratio(double num, double den) { return num == 0.0 ? 0.0 : num / std::max(den, 1e-300); }

// A random chain rescaled to the extremes (see the header comment).
ChainSpec extremeChain(std::mt19937_64& rng, int max_dof) {
  RandomChainOptions options;
  options.min_moving_joints = 1;
  options.max_moving_joints = max_dof;
  ChainSpec spec = randomChain(rng, options);
  const bool per_link = uniform01(rng) < 0.5;
  const double chain_mass = logUniform(rng, 1e-6, 1e4), chain_length = logUniform(rng, 1e-3, 10.0);
  for (std::size_t k = 1; k < spec.links.size(); ++k) {
    LinkSpec& link = spec.links[k];
    JointSpec& joint = spec.joints[k - 1];
    const double mass = per_link ? logUniform(rng, 1e-6, 1e4) : chain_mass;
    const double length = per_link ? logUniform(rng, 1e-3, 10.0) : chain_length;
    // The generator's links are about 0.3 m; scale offsets, COM and inertia alike.
    const double s = length / 0.3;
    link.inertia *= (mass / link.mass) * s * s;
    link.inertia = (0.5 * (link.inertia + link.inertia.transpose())).eval();
    link.mass = mass;
    link.com *= s;
    joint.xyz = length * joint.xyz.normalized();
    if (!joint.isFixed()) {
      const double r = uniform01(rng);
      joint.rotor_inertia = r < 0.3 ? 0.0 : logUniform(rng, 1e-6, 1e3);
      joint.gear_ratio = 1.0;
      joint.friction = uniform01(rng) < 0.1 ? 0.0 : logUniform(rng, 1e-3, 1e4);
      joint.damping = uniform01(rng) < 0.3 ? 0.0 : logUniform(rng, 1e-3, 1e2);
    }
  }
  spec.check();
  return spec;
}

enum class TaskKind { Random, NearSingular, RepeatedRow, OnBase, OverConstrained };
const char* kindName(TaskKind k) {
  switch (k) {
    case TaskKind::Random: return "random";
    case TaskKind::NearSingular: return "near-singular";
    case TaskKind::RepeatedRow: return "repeated row";
    case TaskKind::OnBase: return "on the base";
    case TaskKind::OverConstrained: return "over-constrained";
  }
  return "?";
}

Vector6d unitColumn(std::mt19937_64& rng) {
  Vector6d a;
  for (int k = 0; k < 6; ++k) a[k] = gaussian(rng);
  return a.normalized();
}

DynamicsInput extremeProblem(std::mt19937_64& rng, const ChainSpec& spec, TaskKind kind, int stuck) {
  RandomProblemOptions options;
  options.max_constraint_rows = kind == TaskKind::Random ? 6 : 3;
  DynamicsInput in = randomProblem(rng, spec, options);
  const int n = spec.dof();
  for (int j = 0; j < n; ++j) {
    const double speed = logUniform(rng, 1e-3, 1e3);
    in.qd[j] = uniform01(rng) < 0.5 ? -speed : speed;
    const double torque = uniform01(rng) < 0.1 ? 0.0 : logUniform(rng, 1e-3, 1e4);
    in.tau[j] = uniform01(rng) < 0.5 ? -torque : torque;
  }
  // `stuck` joints exactly at rest, chosen at random.
  std::vector<int> order(static_cast<std::size_t>(n));
  for (int j = 0; j < n; ++j) order[static_cast<std::size_t>(j)] = j;
  for (int j = n - 1; j > 0; --j)
    std::swap(order[static_cast<std::size_t>(j)], order[static_cast<std::size_t>(uniformInt(rng, 0, j))]);
  for (int s = 0; s < stuck; ++s) in.qd[order[static_cast<std::size_t>(s)]] = 0.0;

  const std::string& tip = spec.links.back().name;
  ConstraintInput c;
  c.axes = uniform01(rng) < 0.5 ? Axes::Local : Axes::World;
  switch (kind) {
    case TaskKind::Random: return in;
    case TaskKind::NearSingular: {  // two rows 1e-9 apart
      c.link = tip;
      c.A.resize(6, 2);
      c.A.col(0) = unitColumn(rng);
      c.A.col(1) = (c.A.col(0) + 1e-9 * unitColumn(rng)).normalized();
      break;
    }
    case TaskKind::RepeatedRow: {
      c.link = tip;
      c.A.resize(6, 2);
      c.A.col(0) = unitColumn(rng);
      c.A.col(1) = c.A.col(0);
      break;
    }
    case TaskKind::OnBase: {  // nothing can move the base
      c.link = spec.links.front().name;
      c.A.resize(6, 1);
      c.A.col(0) = unitColumn(rng);
      break;
    }
    case TaskKind::OverConstrained: {  // more independent rows than joints
      c.link = tip;
      c.A = Matrix6Xd::Identity(6, 6);
      break;
    }
  }
  c.b = randomVector(rng, static_cast<int>(c.A.cols()), 3.0);
  in.constraints.push_back(c);
  return in;
}

bool finiteSolution(const Solution& s) {
  bool ok = s.qdd.allFinite() && s.nu.allFinite() && s.tau_constraint.allFinite() && s.tau_control.allFinite() &&
            std::isfinite(s.gauss);
  return ok;
}

struct Worst {
  double closure = 0, constraint = 0, tau_c = 0, dissipation = 0, feasibility = 0, agreement = 0;
  double closure_singular = 0;  // max(closure, tau_c) over singular tasks
  int draws = 0, solves = 0, singular = 0, degenerate = 0, regular_constrained = 0;
  int stuck_joints_max = 0, stuck_hist[9] = {};
  int active_iterations_max = 0, gradient_iterations_max = 0, gradient_not_converged = 0;
  int pattern_solves = 0, pattern_answers = 0;  // StickPatterns forced; answered without the active set
  int stick = 0, slip = 0;
  int constraint_failures = 0;         // regular tasks beyond kConstraintTolerance
  int singular_residual_failures = 0;  // closure or tau_c beyond tolerance (singular tasks only in the default run)
  int dissipation_violations = 0, disagreements = 0, active_not_converged = 0, feasibility_violations = 0;
};

// The residuals shared by both solvers. tau_friction is zero for the plain solve.
struct Residuals {
  double closure = 0, constraint = 0, tau_c = 0;
};

Residuals residuals(const Model& model, const Task& task, const DynamicsInput& in, const DenseResult& dense,
                    const Solution& s, const Eigen::VectorXd& tau_friction, Workspace& scratch) {
  Residuals r;
  REQUIRE(jointSpaceInertia(model, scratch, in.q));
  const Eigen::MatrixXd H = scratch.H;
  REQUIRE(inverseDynamics(model, scratch, in.q, in.qd, Eigen::VectorXd::Zero(in.q.size()), task));
  const Eigen::VectorXd C = scratch.tau;
  REQUIRE(inverseDynamics(model, scratch, in.q, in.qd, s.qdd, task));
  const Eigen::VectorXd id = scratch.tau;
  // (‖G‖∞‖ν‖∞ too: τ_control holds Gᵀν, whose rounding is ε‖G‖‖ν‖ even when
  // it cancels to a small torque, as on a damped singular task with large ν.)
  const double constraint_forces = task.constraintRows() > 0 ? inf(dense.G) * inf(s.nu) : 0.0;
  // (‖H‖∞‖q̇‖∞² too: the velocity-product terms of C are of that size and cancel
  // — a single joint spinning about its own axis has C = 0 from terms of 1e9 —
  // so C and q̈ carry their rounding even when ‖C‖ is tiny.)
  const double velocity_terms = inf(H) * inf(in.qd) * inf(in.qd);
  r.closure =
      ratio(inf(Eigen::VectorXd(id - s.tau_control - tau_friction)),
            inf(H) * inf(s.qdd) + inf(C) + velocity_terms + inf(s.tau_control) + inf(tau_friction) + constraint_forces);
  if (task.constraintRows() > 0) {
    // (‖G‖∞‖H⁻¹Gᵀν‖∞ too: q̈ is the free acceleration plus the constraint forces'
    // H⁻¹Gᵀν, which cancel to the small q̈ a light joint is held to, against
    // kinetic friction of up to 1e4 N·m, so G q̈ carries their rounding.)
    const Eigen::VectorXd held = H.ldlt().solve(Eigen::VectorXd(dense.G.transpose() * s.nu));
    r.constraint = ratio(inf(Eigen::VectorXd(dense.G * s.qdd - dense.gamma)),
                         inf(dense.G) * (inf(s.qdd) + inf(held)) + inf(dense.gamma));
    const Eigen::MatrixXd Gt = dense.G.transpose();
    r.tau_c = ratio(inf(Eigen::VectorXd(s.tau_constraint - Gt * s.nu)), inf(Gt) * inf(s.nu) + inf(s.tau_constraint));
  }
  return r;
}

// Asserts the residuals of one solve (plain or with friction) and records the
// worst: closure and τ_c always; the constraint residual of a regular task only
void checkResiduals(const Residuals& r, bool singular, Worst& worst) {
  const double closure_tolerance = singular ? kSingularClosureTolerance : kClosureTolerance;
  CHECK(r.closure <= closure_tolerance);
  CHECK(r.tau_c <= kTauConstraintTolerance);
  if (r.closure > closure_tolerance || r.tau_c > kTauConstraintTolerance) ++worst.singular_residual_failures;
  if (!singular) CHECK(r.constraint <= kConstraintTolerance);
  if (!singular && r.constraint > kConstraintTolerance) ++worst.constraint_failures;
  double& closure = singular ? worst.closure_singular : worst.closure;
  closure = std::max(closure, std::max(r.closure, r.tau_c));
  worst.tau_c = std::max(worst.tau_c, singular ? 0.0 : r.tau_c);
  if (!singular) worst.constraint = std::max(worst.constraint, r.constraint);
}

// One draw of a seed's sequence: chain index and stuck-set size.
struct Draw {
  int chain, stuck;
};

// The 150 chains of `seed`, every draw checked, or (`only` not empty) only
// those draws: the others are still drawn, so each keeps its numbers.
void runStress(unsigned long long seed, const std::vector<Draw>& only = {}) {
  std::printf("numerical stress: seed %llu%s\n", seed, only.empty() ? "" : " (selected draws)");
  std::mt19937_64 rng(seed);
  Worst worst;
  const TaskKind kinds[] = {TaskKind::Random,      TaskKind::Random, TaskKind::NearSingular,
                            TaskKind::RepeatedRow, TaskKind::OnBase, TaskKind::OverConstrained};
  const int chains = 150;
  for (int c = 0; c < chains; ++c) {
    const ChainSpec spec = extremeChain(rng, 7);
    if (!only.empty() && std::none_of(only.begin(), only.end(), [&](const Draw& d) { return d.chain == c; })) {
      for (int stuck = 0; stuck <= spec.dof(); ++stuck)  // drawn, not solved
        extremeProblem(rng, spec, kinds[uniformInt(rng, 0, 5)], stuck);
      continue;
    }
    const Model model = modelFromSpec(spec);
    const int n = model.dof();
    REQUIRE(n == spec.dof());
    for (int stuck = 0; stuck <= n; ++stuck) {
      const TaskKind kind = kinds[uniformInt(rng, 0, 5)];
      const DynamicsInput in = extremeProblem(rng, spec, kind, stuck);
      const Task task = taskFromInput(model, in);
      if (!only.empty() &&
          std::none_of(only.begin(), only.end(), [&](const Draw& d) { return d.chain == c && d.stuck == stuck; }))
        continue;
      const DenseResult dense = denseDynamics(spec, in);
      Workspace ws(model, task), scratch(model, task);
      ++worst.draws;
      INFO("chain " << c << " (" << n << " dof), " << stuck << " stuck, task " << kindName(kind) << ", "
                    << task.constraintRows() << " rows");

      // --- plain hybrid dynamics
      Status status = solveHybridDynamics(model, ws, in.q, in.qd, in.tau, task);
      ++worst.solves;
      INFO("status: " << status.message);
      if (status.code == StatusCode::Degenerate) {  // documented: a joint with no inertia to move
        ++worst.degenerate;
        continue;
      }
      REQUIRE(status.ok());
      REQUIRE(finiteSolution(ws.solution));
      const bool singular = ws.solution.balance.singular;
      const double condition = ws.solution.balance.condition;
      INFO("balance condition " << condition << ", rank " << ws.solution.balance.rank << ", damping "
                                << ws.solution.balance.damping << "\nnu " << ws.solution.nu.transpose() << "\nqdd "
                                << ws.solution.qdd.transpose() << "\ntau_control "
                                << ws.solution.tau_control.transpose());
      CHECK(!std::isnan(condition));  // ∞ when singular, never NaN
      if (kind == TaskKind::RepeatedRow || kind == TaskKind::OnBase || kind == TaskKind::NearSingular ||
          (kind == TaskKind::OverConstrained && n < 6))
        CHECK(singular);
      if (singular) {
        ++worst.singular;
        CHECK((ws.solution.balance.rank < ws.solution.balance.rows || ws.solution.balance.damping > 0.0));
      } else if (task.constraintRows() > 0) {
        ++worst.regular_constrained;
      }
      const Eigen::VectorXd no_friction = Eigen::VectorXd::Zero(n);
      checkResiduals(residuals(model, task, in, dense, ws.solution, no_friction, scratch), singular, worst);

      // --- static friction, both maximisers and the pattern search
      Eigen::VectorXd qdd_active;
      double scale_active = 0.0;  // the problem's acceleration scale, from the active set's K μ* (the search has no K)
      for (const FrictionMethod method :
           {FrictionMethod::ActiveSet, FrictionMethod::ProjectedGradient, FrictionMethod::StickPatterns}) {
        FrictionOptions options;
        options.method = method;
        options.joint_limits = false;  // limits: test_friction_limits; here q is anywhere
        const bool active = method == FrictionMethod::ActiveSet;
        INFO(toString(method));
        status = solveWithFriction(model, ws, in.q, in.qd, in.tau, task, options);
        ++worst.solves;
        INFO("status: " << status.message);
        REQUIRE(status.ok());
        REQUIRE(finiteSolution(ws.solution));
        const FrictionResult& fr = ws.friction;
        REQUIRE(fr.mu.allFinite());
        REQUIRE(fr.tau_friction.allFinite());
        REQUIRE(std::isfinite(fr.gauss_dual));
        REQUIRE(static_cast<int>(fr.stuck.size()) == stuck);
        CHECK(fr.iterations >= 0);
        CHECK(fr.iterations <= options.max_iterations);  // terminates within its cap
        if (active) {
          worst.active_iterations_max = std::max(worst.active_iterations_max, fr.iterations);
          CHECK(fr.converged);
          if (!fr.converged) ++worst.active_not_converged;
          worst.stuck_hist[stuck]++;
        } else if (method == FrictionMethod::ProjectedGradient) {
          worst.gradient_iterations_max = std::max(worst.gradient_iterations_max, fr.iterations);
          if (!fr.converged) ++worst.gradient_not_converged;
        } else {
          ++worst.pattern_solves;
          if (fr.method == FrictionMethod::StickPatterns) ++worst.pattern_answers;
        }
        checkResiduals(residuals(model, task, in, dense, ws.solution, fr.tau_friction, scratch), singular, worst);

        // Maximum dissipation on Θ₀, with q̈(0) = q̈* − (∂q̈/∂μ) μ*.
        const Eigen::VectorXd& qdd = ws.solution.qdd;
        const Eigen::VectorXd k_mu = fr.dqdd_dmu * fr.mu;
        const Eigen::VectorXd qdd0 = qdd - k_mu;
        double scale = 0.0;
        for (const int j : fr.stuck) scale = std::max({scale, std::abs(qdd0[j]), std::abs(k_mu[j])});
        double violation = 0.0, infeasible = 0.0, f_scale = 1.0;
        for (const int j : fr.stuck) f_scale = std::max(f_scale, model.joint(j).breakaway_friction);
        for (const int j : fr.stuck) {
          const double f = model.joint(j).breakaway_friction, mu = fr.mu[j], a = qdd[j];
          infeasible = std::max(infeasible, std::max(0.0, std::abs(mu) - f) / f_scale);
          if (f == 0.0) continue;  // μ_j = 0 and q̈_j free
          if (mu >= f * (1 - 1e-9))
            violation = std::max(violation, ratio(std::max(0.0, -a), scale));
          else if (mu <= -f * (1 - 1e-9))
            violation = std::max(violation, ratio(std::max(0.0, a), scale));
          else
            violation = std::max(violation, ratio(std::abs(a), scale));
          if (active) (std::abs(mu) < f * (1 - 1e-9) ? worst.stick : worst.slip)++;
        }
        std::string detail;
        for (const int j : fr.stuck) {
          char line[200];
          std::snprintf(line, sizeof line, "\n  joint %d: f %.6g mu %.17g qdd %.6g qdd(0) %.6g state %s", j,
                        model.joint(j).breakaway_friction, fr.mu[j], qdd[j], qdd0[j],
                        toString(fr.state[static_cast<std::size_t>(j)]));
          detail += line;
        }
        INFO("stuck joints (scale " << scale << ", iterations " << fr.iterations << ", kkt " << fr.kkt_residual
                                    << ", indeterminate " << fr.indeterminate << "):" << detail);
        CHECK(infeasible <= 1e-12);
        CHECK(infeasible <= 1e-6);  // loose, always: μ stays in the friction box
        if (infeasible > 1e-12) ++worst.feasibility_violations;
        worst.feasibility = std::max(worst.feasibility, infeasible);
        if (active || fr.converged) {
          const double dissipation_tolerance = singular ? kSingularDissipationTolerance : kDissipationTolerance;
          CHECK(violation <= dissipation_tolerance);
          if (violation > dissipation_tolerance) ++worst.dissipation_violations;
          worst.dissipation = std::max(worst.dissipation, violation);
        }
        if (active) {
          qdd_active = qdd;
          scale_active = scale;
        } else if (fr.converged) {
          const double d =
              ratio(inf(Eigen::VectorXd(qdd - qdd_active)), inf(qdd_active) + std::max(scale, scale_active));
          // The pattern search's q̈ comes from other sweeps (the sticking joints locked) than q̈(0) − K μ*: where
          // constraint forces cancel to the q̈ a row holds (seed 17, chain 4: 1e12 rad/s² on 1e-10 kg·m²), each
          // carries ε of them differently.
          const bool other_sweeps = fr.method == FrictionMethod::StickPatterns;
          const double agreement_tolerance =
              singular || other_sweeps ? kSingularAgreementTolerance : kAgreementTolerance;
          CHECK(d <= agreement_tolerance);
          if (d > agreement_tolerance) ++worst.disagreements;
          worst.agreement = std::max(worst.agreement, d);
        }
      }
    }
  }
  std::printf(
      "numerical stress: %d draws on %d chains (%d solves): %d singular tasks, %d regular constrained, %d degenerate\n"
      "  worst relative residuals, regular tasks: closure %.1e (tol %.0e), constraint %.1e (tol %.0e),"
      " tau_c vs G^T nu %.1e (tol %.0e); singular tasks: closure or tau_c %.1e\n"
      "  friction: max dissipation violation %.1e (tol %.0e, singular tasks %.0e), |mu| beyond f %.1e, active set vs the others %.1e (tol %.0e, singular tasks %.0e)\n"
      "  maximiser iterations: active set max %d, projected gradient max %d (%d not converged at the cap);"
      " stuck joints stick %d, slip %d; the pattern search answered %d of %d\n"
      "  draws per stuck-set size 0..7:",
      worst.draws, chains, worst.solves, worst.singular, worst.regular_constrained, worst.degenerate, worst.closure,
      kClosureTolerance, worst.constraint, kConstraintTolerance, worst.tau_c, kTauConstraintTolerance,
      worst.closure_singular, worst.dissipation, kDissipationTolerance, kSingularDissipationTolerance,
      worst.feasibility, worst.agreement, kAgreementTolerance, kSingularAgreementTolerance, worst.active_iterations_max,
      worst.gradient_iterations_max, worst.gradient_not_converged, worst.stick, worst.slip, worst.pattern_answers,
      worst.pattern_solves);
  for (int k = 0; k <= 7; ++k) std::printf(" %d", worst.stuck_hist[k]);
  std::printf(
      "\n  beyond tolerance: %d solves of singular tasks miss closure or tau_c = G^T nu (asserted);"
      " %d solves of regular tasks miss the constraint tolerance, %d friction solves violate maximum dissipation,"
      " %d |mu| > f, %d active-set runs not converged, %d maximiser disagreements\n",
      worst.singular_residual_failures, worst.constraint_failures, worst.dissipation_violations,
      worst.feasibility_violations, worst.active_not_converged, worst.disagreements);
  if (!only.empty()) {
    CHECK(worst.draws == static_cast<int>(only.size()));
    return;
  }
  CHECK(worst.regular_constrained > 50);  // the checks above did run on constrained tasks
  CHECK(worst.singular > 50);
  CHECK(worst.stick > 50);
  CHECK(worst.slip > 50);
}

}  // namespace

// ZWANG_STRESS_SEED draws another 150 chains (the default seed is CI's;
// test/CMakeLists.txt runs a few more seeds as tests of their own).
TEST_CASE("numerical stress: extreme chains, singular tasks, every stuck-set size, maximum dissipation on every draw") {
  const char* seed_text = std::getenv("ZWANG_STRESS_SEED");
  runStress(seed_text ? std::strtoull(seed_text, nullptr, 10) : 20240606ULL);
}

TEST_CASE("numerical stress: the draws of seeds 2 to 60 whose projected-gradient friction injected energy",
          "[friction]") {
  // Singular tasks (over-constrained, repeated rows, damped balances of
  // condition 1e6 .. ∞) give a K_ΘΘ that is positive semi-definite only
  // roughly: diagonal entries at rounding of their terms or below zero beside
  // real off-diagonal ones. The projected-gradient maximiser (docs/friction.md,
  // "The maximiser") took the trace of such a K as λ_max's bound: zero or
  // negative, so K counted as zero and every μ went to the vertex q̈_Θ(0)
  // points to, reported converged after 0 iterations (KKT residual up to
  // 6.3e3: μ_j = −f_j with q̈_j > 0). Where one variable's diagonal was
  // rounding, it went to that vertex and was left there and out of the
  // stopping test while the others' motion reversed its slope. Each draw
  // below failed "dissipation on every draw" so; both maximisers run on each.
  const struct {
    unsigned long long seed;
    std::vector<Draw> draws;
  } failed[] = {
      {2, {{40, 5}}},           {3, {{94, 5}}},   {5, {{131, 5}}},
      {6, {{84, 3}}},           {7, {{25, 4}}},   {9, {{44, 3}}},
      {11, {{27, 5}}},          {12, {{46, 4}}},  {15, {{24, 6}}},
      {16, {{41, 6}, {73, 6}}}, {24, {{65, 6}}},  {29, {{60, 5}}},
      {30, {{88, 4}}},          {33, {{1, 5}}},   {35, {{103, 5}, {111, 6}}},
      {36, {{59, 5}}},          {37, {{27, 5}}},  {41, {{127, 4}}},
      {42, {{48, 6}}},          {43, {{74, 5}}},  {45, {{79, 5}, {128, 6}}},
      {46, {{56, 5}}},          {52, {{54, 2}}},  {53, {{5, 2}, {5, 6}, {19, 5}, {119, 7}}},
      {55, {{1, 3}}},           {56, {{106, 5}}}, {57, {{45, 3}, {104, 6}}},
      {59, {{40, 2}, {46, 3}}}, {60, {{19, 5}}},
  };
  for (const auto& f : failed) {
    INFO("seed " << f.seed);
    runStress(f.seed, f.draws);
  }
}

TEST_CASE("numerical stress: the draws of seeds 34, 96 and 97 that reported a NaN condition or missed closure") {
  // 34/80 (4 rows) and 97/118 (1 row on the base) constrain a 1-dof chain
  // along directions its joint cannot move: every row was zeroed, every σ̃ = 0,
  // and the condition √(Σσ̃² Σσ̃⁻²) was 0·∞ = NaN. They and 96/3 (no rows) also
  // missed closure by 6e-5, 2.9e-3 and 4.5e-4: a joint spinning about its own
  // axis has C = 0 from velocity terms of up to 7e9 N·m, which left the
  // rounding of C (4.8e-7, 1.3e-23, 2.6e-26) over a denominator of ‖C‖ alone.
  runStress(34, {{80, 0}});
  runStress(96, {{3, 0}});
  runStress(97, {{118, 0}});
}

TEST_CASE("numerical stress: the draws of seeds 14 to 119 whose constraint residual counted no cancelled forces") {
  // Regular tasks (condition 1 .. 1e3) on light joints with kinetic friction:
  // the constraint forces H⁻¹Gᵀν (up to 1.9e12 rad/s² on 1e-10 kg·m² at
  // 119/78) cancel the free acceleration to the small q̈ the row holds, so
  // G q̈ − γ carries ε of them (1.2e-4 there, 9e-17 of ‖G‖‖H⁻¹Gᵀν‖) and missed
  // 1e-6 of ‖G‖‖q̈‖ + ‖γ‖ (1.6e-6 .. 2.4e-5) while closure held to 1e-9.
  const struct {
    unsigned long long seed;
    std::vector<Draw> draws;
  } failed[] = {
      {14, {{123, 1}}}, {16, {{41, 4}}}, {17, {{4, 1}}},   {20, {{139, 1}}}, {38, {{101, 0}}}, {52, {{54, 5}}},
      {60, {{85, 3}}},  {72, {{55, 2}}}, {90, {{140, 3}}}, {91, {{37, 5}}},  {119, {{78, 0}}},
  };
  for (const auto& f : failed) {
    INFO("seed " << f.seed);
    runStress(f.seed, f.draws);
  }
}

TEST_CASE("numerical stress: non-finite and wrongly sized inputs come back as a status, never as NaN") {
  const Model model = loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/panda.urdf");
  Task task(model);
  task.addConstraint("tool0", ConstraintMatrix::Identity(6, 6), Expressed::World);
  Workspace ws(model, task);
  const Eigen::VectorXd ok = Eigen::VectorXd::Constant(7, 0.1);
  for (const double bad : {std::nan(""), HUGE_VAL, -HUGE_VAL}) {
    for (int which = 0; which < 3; ++which) {
      Eigen::VectorXd v[3] = {ok, ok, ok};
      v[which][3] = bad;
      CHECK(solveHybridDynamics(model, ws, v[0], v[1], v[2], task).code == StatusCode::NonFinite);
      CHECK(solveWithFriction(model, ws, v[0], v[1], v[2], task).code == StatusCode::NonFinite);
    }
    task.targets()[2] = bad;
    CHECK(solveHybridDynamics(model, ws, ok, ok, ok, task).code == StatusCode::NonFinite);
    task.targets()[2] = 0.0;
  }
}

// ---------------------------------------------------------------------------
// Regression tests: bugs the stress test found, reduced to a few joints.

namespace {
// Two revolute joints about z, no gravity: a heavy 1 m link (1e4 kg) and a
// light 1 mm one (1e-6 kg) at its tip, no rotor inertia.
Model heavyLightArm(double breakaway) {
  ModelBuilder builder("heavy_light", "base");
  Joint j;
  j.axis = Vec3::UnitZ();
  j.name = "heavy";
  j.breakaway_friction = j.kinetic_friction = breakaway;
  builder.addJoint(j, "link1", RigidInertia::fromMassComInertia(1e4, Vec3(0.5, 0, 0), Mat3::Identity() * 1e3));
  j.name = "light";
  j.placement = Transform::translation(Vec3(1, 0, 0));
  j.breakaway_friction = j.kinetic_friction = 0.0;
  builder.addJoint(j, "link2", RigidInertia::fromMassComInertia(1e-6, Vec3(5e-4, 0, 0), Mat3::Identity() * 1e-13));
  return builder.build();
}
}  // namespace

TEST_CASE("a heavy stuck joint next to a light fast one sticks (friction scales from the stuck joints only)",
          "[friction]") {
  // Joint 'heavy' is stuck (q̇ = 0), pushed by 1 N·m, breakaway 10 N·m: it must
  // stick (q̈ = 0, μ ≈ 1). The light joint spins at 1e3 rad/s. The maximiser's
  // zero-curvature threshold was once 1e-10 · max_i 1/D_i over ALL bodies, set
  // by the light joint (1/D ~ 1e12), so the heavy joint's curvature K ~ 1e-4
  // counted as zero and μ went to a vertex of the box.
  const Model model = heavyLightArm(10.0);
  Task task(model);
  task.gravity.setZero();
  Workspace ws(model, task);
  const Eigen::Vector2d q(0.3, 0.2), qd(0.0, 1e3), tau(1.0, 0.0);
  for (const FrictionMethod method : {FrictionMethod::ActiveSet, FrictionMethod::ProjectedGradient}) {
    FrictionOptions options;
    options.method = method;
    REQUIRE(solveWithFriction(model, ws, q, qd, tau, task, options));
    INFO("method " << (method == FrictionMethod::ActiveSet ? "active set" : "projected gradient") << ": mu "
                   << ws.friction.mu.transpose() << ", qdd " << ws.solution.qdd.transpose() << ", state "
                   << toString(ws.friction.state[0]) << ", kkt " << ws.friction.kkt_residual);
    CHECK(std::abs(ws.friction.mu[0]) < 10.0);    // inside the friction cone
    CHECK(std::abs(ws.solution.qdd[0]) <= 1e-9);  // sticks
    CHECK(ws.friction.state[0] == JointState::Stick);
  }
}

TEST_CASE("a constraint row nothing can move gets nu = 0 (regression: it got 1e35 between e427cb7 and 9d1da32)") {
  // The draw test_stress reports as "chain 24 (5 dof), 3 stuck, task on the
  // base" (its URDF written by test/support/urdf_writer, its inputs below). Row
  // 0 constrains link1's linear y in link axes; link1's origin lies on joint1's
  // axis, so no joint can move it: its row of G is zero and 𝓛 is zero up to
  // rounding (not exactly 0). Row 1 is on the base. docs/solver.md: "a row
  // nothing can move gets ν = 0". Between e427cb7 and 9d1da32 zwang returned
  // ν₀ = 1.35e35, q̈ ~ 1e17 and τ_c = −1.15e18 on joint1 although Gᵀν = 0.
  const Model model = loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/../test/stress/immovable_row_chain.urdf");
  Task task(model);
  task.gravity << -6.7542213900690768, -3.0933240268091602, -6.4068666194247026;
  task.wrench(task.addWrench("link2", Expressed::Local)) << -2.7830377119036971, -1.9762287584513283,
      0.19643051172421935, -4.3443894054931844, -0.69816961574070979, -2.8001680374061837;
  task.wrench(task.addWrench("link1", Expressed::World)) << -6.8395312209931873, -8.1369225718812483,
      -6.4770524209221083, 4.8979155546621405, -4.853515883129667, 3.8477765560045132;
  ConstraintMatrix y = ConstraintMatrix::Zero(6, 1), base(6, 1);
  y(1, 0) = 1.0;
  base << 0.057994014338010901, 0.3189720879409384, 0.35023238927716299, -0.80677373957768017, 0.20095326881410563,
      -0.28454295246507477;
  task.addConstraint("link1", y, Expressed::Local);
  task.addConstraint("base", base, Expressed::Local);
  task.targets() << 2.2001108239339535, -2.7461494733922476;
  Eigen::VectorXd q(5), qd(5), tau(5);
  q << -1.8508391881749604, -2.2895991871129819, 1.7223035365442829, 1.7816306797331212, 2.2729511744188393;
  qd << 21.158291402917442, 0, 0, 0, 26.694499304429318;
  tau << -0.051337674531538716, 0.0049860000403736792, 0.051695840801024809, 0, -0.0024442861380955883;
  Workspace ws(model, task);
  REQUIRE(solveHybridDynamics(model, ws, q, qd, tau, task));
  const Solution s = ws.solution;
  REQUIRE(inverseDynamics(model, ws, q, qd, s.qdd, task));
  INFO("nu " << s.nu.transpose() << "\nqdd " << s.qdd.transpose() << "\ntau_c " << s.tau_constraint.transpose()
             << "\nRNEA(qdd) - tau_control " << (ws.tau - s.tau_control).transpose() << "\nrank " << s.balance.rank
             << ", condition " << s.balance.condition << ", damping " << s.balance.damping);
  CHECK(s.balance.singular);
  CHECK(s.nu.cwiseAbs().maxCoeff() <= 1e3);
  CHECK((ws.tau - s.tau_control).cwiseAbs().maxCoeff() <= 1e-9 * (1.0 + s.tau_control.cwiseAbs().maxCoeff()));
}

TEST_CASE("a task no joint can move reports an infinite condition, not NaN") {
  // Every row zeroed (docs/solver.md: a row nothing can move gets ν = 0), so
  // every σ̃ = 0: the condition was √(Σσ̃² Σσ̃⁻²) = √(0·∞) = NaN.
  const Model model = heavyLightArm(0.0);
  Task task(model);
  task.addConstraint("base", ConstraintMatrix::Identity(6, 2), Expressed::World);
  Workspace ws(model, task);
  const Eigen::Vector2d q(0.3, 0.2), qd(1.0, 2.0), tau(1.0, 0.5);
  REQUIRE(solveHybridDynamics(model, ws, q, qd, tau, task));
  const BalanceReport& b = ws.solution.balance;
  INFO("condition " << b.condition << ", rank " << b.rank);
  CHECK(b.rank == 0);
  CHECK(b.singular);
  CHECK(std::isinf(b.condition));
  CHECK(ws.solution.nu.cwiseAbs().maxCoeff() == 0.0);
}
