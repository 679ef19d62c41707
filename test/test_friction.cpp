// Static friction (docs/friction.md; issue 3) through the public API solveWithFriction,
// against independent references (support/friction_reference: dense KKT brute
// force over all stick/slip patterns and the report's grid sampling) and the
// closed forms of docs/theory.md, "The reference cases". Every friction solve is checked with
// checkMaximumDissipation (support/friction_check) and the closure property.
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>

#include "support/friction_check.hpp"
#include "support/friction_reference.hpp"
#include "support/random_chain.hpp"
#include "support/random_problem.hpp"
#include "zwang/friction.hpp"

using namespace zwang;
using namespace zwang::testing;

namespace {

// One friction solve, checked: status as expected, maximum dissipation, closure.
struct Solved {
  Status status;
  FrictionResult friction;
  Solution solution;
  std::string violation;
  double closure = 0.0;
};

Solved solveChecked(const Model& model, const Task& task, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                    const Eigen::VectorXd& tau, const FrictionOptions& options = {},
                    const DissipationTolerances& tolerances = {}) {
  Workspace ws(model, task);
  Solved s;
  s.status = solveWithFriction(model, ws, q, qd, tau, task, options);
  s.friction = ws.friction;
  s.solution = ws.solution;
  if (s.status.ok()) {
    s.violation =
        checkMaximumDissipation(ws.friction, ws.solution, expectFriction(model, q, qd, tau, options), tolerances);
    s.closure = frictionClosureError(model, task, q, qd, ws.friction, ws.solution);
  }
  return s;
}

#define REQUIRE_SOLVED(s)                           \
  do {                                              \
    INFO("status message: " << (s).status.message); \
    REQUIRE((s).status.ok());                       \
    INFO("maximum dissipation: " << (s).violation); \
    CHECK((s).violation.empty());                   \
    CHECK((s).closure < 1e-9);                      \
  } while (false)

Model oneDofArmModel() { return loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/one_dof_arm.urdf"); }

ConstraintMatrix angularZ() {
  ConstraintMatrix A = ConstraintMatrix::Zero(6, 1);
  A(5, 0) = 1.0;
  return A;
}

double median(std::vector<int> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

// Per-solve friction overrides drawn at random in about a third of the draws
// (the reference setup is updated to match).
FrictionOptions randomOverrides(std::mt19937_64& rng, FrictionSetup& setup, int n) {
  FrictionOptions o;
  if (uniform01(rng) < 0.35) {
    o.breakaway = randomVector(rng, n, 1.0).cwiseAbs() * 8.0;
    o.kinetic = randomVector(rng, n, 1.0).cwiseAbs() * 4.0;
    o.viscous = randomVector(rng, n, 1.0).cwiseAbs();
    setup.breakaway = o.breakaway;
    setup.kinetic = o.kinetic;
    setup.viscous = o.viscous;
  }
  return o;
}

}  // namespace

TEST_CASE("the report's 1-DOF evaluation, exactly (the reference cases)") {
  const Model model = oneDofArmModel();
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(1), qd = Eigen::VectorXd::Zero(1), tau = Eigen::VectorXd::Zero(1);
  for (FrictionMethod method :
       {FrictionMethod::ActiveSet, FrictionMethod::ProjectedGradient, FrictionMethod::StickPatterns}) {
    INFO("method: " << toString(method));
    FrictionOptions options;
    options.method = method;
    Task task(model);
    task.gravity.setZero();
    const int w = task.addWrench("tip", Expressed::Local);

    SECTION("-5 N at the tip: stick") {
      task.wrench(w) << 0.0, -5.0, 0.0, 0.0, 0.0, 0.0;
      const Solved s = solveChecked(model, task, q, qd, tau, options);
      REQUIRE_SOLVED(s);
      CHECK(s.friction.stuck == std::vector<int>{0});
      CHECK(s.friction.state[0] == JointState::Stick);
      CHECK(s.friction.mu(0) == Approx(-5.0).epsilon(1e-12));
      CHECK(s.friction.tau_friction(0) == Approx(5.0).epsilon(1e-12));
      CHECK(s.solution.qdd(0) == Approx(0.0).margin(1e-12));
      CHECK(s.solution.tau_control(0) == Approx(0.0).margin(1e-12));
      CHECK(s.friction.gauss_dual == Approx(0.0).margin(1e-12));
      CHECK_FALSE(s.friction.indeterminate);
    }
    SECTION("-11 N at the tip: slip") {
      task.wrench(w) << 0.0, -11.0, 0.0, 0.0, 0.0, 0.0;
      const Solved s = solveChecked(model, task, q, qd, tau, options);
      REQUIRE_SOLVED(s);
      CHECK(s.friction.state[0] == JointState::SlipNegative);
      CHECK(s.friction.mu(0) == Approx(-10.0).epsilon(1e-12));
      CHECK(s.solution.qdd(0) == Approx(-1.0 / 2.25).epsilon(1e-12));
      CHECK(s.solution.tau_control(0) == Approx(0.0).margin(1e-12));
      // g(μ*) = −½ (net torque)² / I = −1 / 4.5.
      CHECK(s.friction.gauss_dual == Approx(-1.0 / 4.5).epsilon(1e-12));
      CHECK_FALSE(s.friction.indeterminate);
    }
    SECTION("Fig. 5.5: fully constrained, the vertex opposing the motion") {
      const int row = task.addConstraint("link1", angularZ(), Expressed::Local);
      task.targets()(row) = 5.0;
      const Solved s = solveChecked(model, task, q, qd, tau, options);
      REQUIRE_SOLVED(s);
      CHECK(s.friction.state[0] == JointState::SlipPositive);
      CHECK(s.friction.mu(0) == Approx(10.0).epsilon(1e-12));
      CHECK(s.solution.qdd(0) == Approx(5.0).epsilon(1e-12));
      CHECK(s.solution.tau_control(0) == Approx(2.25 * 5.0 + 10.0).epsilon(1e-12));
      CHECK_FALSE(s.friction.indeterminate);
    }
  }
}

TEST_CASE("friction matches the brute-force enumeration of stick/slip patterns (300+ random chains)") {
  // The automatic choice (the active set for most of these small stuck sets) and the pattern search forced.
  const FrictionMethod method = GENERATE(FrictionMethod::Automatic, FrictionMethod::StickPatterns);
  INFO("method " << toString(method));
  std::mt19937_64 rng(314159);
  int accepted = 0, attempts = 0, ill_posed = 0, overridden = 0, mu_compared = 0;
  int states[5] = {0, 0, 0, 0, 0};
  int by_k[6] = {0, 0, 0, 0, 0, 0};
  double qdd_err = 0.0, g_err = 0.0, mu_err = 0.0, kkt_max = 0.0, closure_max = 0.0;
  std::vector<int> iterations;
  while (accepted < 320) {
    ++attempts;
    REQUIRE(attempts < 3000);
    FrictionDraw d = randomFrictionDraw(rng, 2, 7, 1, 5, 6);
    const DenseResult dense = denseDynamics(d.spec, d.input);
    if (!wellPosed(dense, d.input.constraintRows())) {
      ++ill_posed;
      continue;
    }
    const Model model = modelFromSpec(d.spec);
    const Task task = taskFromInput(model, d.input);
    FrictionOptions options = randomOverrides(rng, d.setup, d.spec.dof());
    options.method = method;
    if (options.breakaway.size() > 0) ++overridden;
    const FrictionReference ref = bruteForceFriction(d.spec, d.input, d.setup);
    REQUIRE(ref.feasible);
    REQUIRE(ref.qdd_spread < 1e-9);
    ++accepted;
    ++by_k[d.setup.stuck.size()];

    const Solved s = solveChecked(model, task, d.input.q, d.input.qd, d.input.tau, options);
    INFO("draw " << accepted << ": " << d.spec.dof() << " dof, " << d.input.constraintRows() << " rows, "
                 << d.setup.stuck.size() << " stuck, reference pattern " << ref.pattern);
    REQUIRE_SOLVED(s);
    for (JointState st : s.friction.state) ++states[static_cast<int>(st)];
    const double e_qdd = relativeError(s.solution.qdd, ref.qdd);
    const double e_g = std::abs(s.friction.gauss_dual - ref.gauss_dual) / std::max(1.0, std::abs(ref.gauss_dual));
    CHECK(e_qdd < 1e-8);
    CHECK(e_g < 1e-8);
    qdd_err = std::max(qdd_err, e_qdd);
    g_err = std::max(g_err, e_g);
    // μ* is unique here (one valid pattern, or all valid patterns agree on μ).
    if (ref.mu_spread == 0.0 && !s.friction.indeterminate) {
      ++mu_compared;
      const double e_mu = relativeError(s.friction.mu, ref.mu);
      CHECK(e_mu < 1e-6);
      mu_err = std::max(mu_err, e_mu);
    }
    CHECK_FALSE(s.friction.limit_impact);
    iterations.push_back(s.friction.iterations);
    kkt_max = std::max(kkt_max, s.friction.kkt_residual);
    closure_max = std::max(closure_max, s.closure);
  }
  std::printf(
      "friction vs brute force, %d random chains (%d ill-posed draws skipped, %d with per-solve overrides;"
      " k = 1..5 stuck: %d %d %d %d %d):\n"
      "  max rel. error qdd %.2e, g(mu*) %.2e, mu %.2e (%d with unique mu*), closure %.2e\n"
      "  joint states: moving %d, stick %d, slip+ %d, slip- %d, at-limit %d\n"
      "  maximiser iterations median %.1f, max %d; max KKT residual %.2e\n",
      accepted, ill_posed, overridden, by_k[1], by_k[2], by_k[3], by_k[4], by_k[5], qdd_err, g_err, mu_err, mu_compared,
      closure_max, states[0], states[1], states[2], states[3], states[4], median(iterations),
      *std::max_element(iterations.begin(), iterations.end()), kkt_max);
  CHECK(states[1] > 50);  // both sticking and slipping joints are exercised
  CHECK(states[2] + states[3] > 50);
}

TEST_CASE("the report's sampling method agrees within the grid resolution (k = 1, 2)") {
  std::mt19937_64 rng(271828);
  for (int k = 1; k <= 2; ++k) {
    int accepted = 0, attempts = 0, mu_checked = 0;
    double worst_gap = 0.0, worst_mu = 0.0;
    while (accepted < (k == 1 ? 40 : 20)) {
      ++attempts;
      REQUIRE(attempts < 500);
      const FrictionDraw d = randomFrictionDraw(rng, 2, 6, k, k, 6);
      const DenseResult dense = denseDynamics(d.spec, d.input);
      if (!wellPosed(dense, d.input.constraintRows())) continue;
      ++accepted;
      const Model model = modelFromSpec(d.spec);
      const Task task = taskFromInput(model, d.input);
      const Solved s = solveChecked(model, task, d.input.q, d.input.qd, d.input.tau);
      REQUIRE_SOLVED(s);
      const int points = k == 1 ? 201 : 41;
      const SampledFriction grid = sampledFriction(d.spec, d.input, d.setup, points);
      const double h = grid.spacing.maxCoeff();
      const double g = s.friction.gauss_dual, scale = std::max(1.0, std::abs(g));

      // Curvature −K_ΘΘ and slope q̈_Θ* of g, from the dense reference.
      const Eigen::MatrixXd K = denseConstrainedInverseInertia(d.spec, d.input);
      Eigen::MatrixXd Ktt(k, k);
      Eigen::VectorXd slope(k), mu_z(k), mu_g(k);
      for (int a = 0; a < k; ++a) {
        const int ja = d.setup.stuck[static_cast<std::size_t>(a)];
        slope(a) = s.solution.qdd(ja);
        mu_z(a) = s.friction.mu(ja);
        mu_g(a) = grid.mu(ja);
        for (int b = 0; b < k; ++b) Ktt(a, b) = K(ja, d.setup.stuck[static_cast<std::size_t>(b)]);
      }
      const Eigen::VectorXd ev = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Ktt).eigenvalues();
      // No sample beats the maximum, and the grid point nearest μ* is within
      // |∇g|₁ h + ½ λ_max k h² of it.
      const double gap = g - grid.g;
      const double bound = slope.lpNorm<1>() * h + 0.5 * ev(k - 1) * k * h * h;
      INFO("k " << k << ", h " << h << ", g " << g << ", grid g " << grid.g << ", bound " << bound);
      CHECK(gap >= -1e-9 * scale);
      CHECK(gap <= bound + 1e-9 * scale);
      worst_gap = std::max(worst_gap, bound > 0.0 ? gap / bound : 0.0);
      // μ: g(μ*) − g(μ) ≥ ½ λ_min |μ − μ*|² for μ in the box, so the grid
      // maximiser lies within sqrt(2 gap / λ_min) (k = 1 and interior: h/2).
      if (ev(0) > 1e-6 * std::max(1e-12, ev(k - 1))) {
        ++mu_checked;
        const double radius =
            std::sqrt(2.0 * std::max(gap, 0.0) / ev(0)) + 1e-7 * std::max(1.0, mu_z.cwiseAbs().maxCoeff());
        const double dist = (mu_g - mu_z).norm();
        CHECK(dist <= radius);
        if (k == 1) CHECK(dist <= 0.5 * h * (1.0 + 1e-6) + 1e-9);
        worst_mu = std::max(worst_mu, h > 0.0 ? dist / h : 0.0);
      }
    }
    std::printf(
        "grid sampling, k = %d: %d problems (%d draws skipped), gap/bound max %.2f, |mu_grid - mu*|/h max %.2f"
        " (%d compared)\n",
        k, accepted, attempts - accepted, worst_gap, worst_mu, mu_checked);
  }
}

TEST_CASE("dqdd/dmu from the sweeps matches finite differences; K_ThTh is symmetric PSD") {
  std::mt19937_64 rng(1618);
  int accepted = 0, attempts = 0;
  double fd_err = 0.0, dense_err = 0.0, asym = 0.0, min_eig = 0.0;
  while (accepted < 100) {
    ++attempts;
    REQUIRE(attempts < 1000);
    const FrictionDraw d = randomFrictionDraw(rng, 2, 7, 1, 5, 6);
    const DenseResult dense = denseDynamics(d.spec, d.input);
    if (!wellPosed(dense, d.input.constraintRows())) continue;
    ++accepted;
    const Model model = modelFromSpec(d.spec);
    const Task task = taskFromInput(model, d.input);
    FrictionOptions options;
    options.method = FrictionMethod::ActiveSet;  // ∂q̈/∂μ is the K-based methods'
    const Solved s = solveChecked(model, task, d.input.q, d.input.qd, d.input.tau, options);
    REQUIRE_SOLVED(s);
    const Eigen::MatrixXd& D = s.friction.dqdd_dmu;
    const Eigen::MatrixXd Kd = denseConstrainedInverseInertia(d.spec, d.input);
    const double scale = std::max(1.0, D.cwiseAbs().maxCoeff());
    Workspace ws(model, task);
    const int k = static_cast<int>(d.setup.stuck.size());
    Eigen::MatrixXd Ktt(k, k);
    for (int a = 0; a < k; ++a) {
      const int j = d.setup.stuck[static_cast<std::size_t>(a)];
      // Central difference of the friction-free solver in the torque −μ_j e_j.
      const double h = 0.5;
      Eigen::VectorXd tp = d.input.tau, tm = d.input.tau;
      tp(j) -= h;  // μ_j = +h
      tm(j) += h;  // μ_j = −h
      REQUIRE(solveHybridDynamics(model, ws, d.input.q, d.input.qd, tp, task));
      const Eigen::VectorXd qp = ws.solution.qdd;
      REQUIRE(solveHybridDynamics(model, ws, d.input.q, d.input.qd, tm, task));
      const Eigen::VectorXd fd = (qp - ws.solution.qdd) / (2.0 * h);
      const double e = (D.col(j) - fd).cwiseAbs().maxCoeff() / scale;
      CHECK(e < 1e-6);
      fd_err = std::max(fd_err, e);
      dense_err = std::max(dense_err, (D.col(j) + Kd.col(j)).cwiseAbs().maxCoeff() / scale);
      for (int b = 0; b < k; ++b) Ktt(b, a) = -D(d.setup.stuck[static_cast<std::size_t>(b)], j);
    }
    const double as = (Ktt - Ktt.transpose()).cwiseAbs().maxCoeff() / scale;
    CHECK(as < 1e-9);
    asym = std::max(asym, as);
    const double lo =
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(0.5 * (Ktt + Ktt.transpose())).eigenvalues()(0) / scale;
    CHECK(lo > -1e-9);
    min_eig = std::min(min_eig, lo);
  }
  std::printf(
      "dqdd/dmu on %d random problems (%d skipped): max rel. error vs central differences %.1e, vs dense K %.1e;"
      " K_ThTh asymmetry %.1e, smallest eigenvalue %.1e\n",
      accepted, attempts - accepted, fd_err, dense_err, asym, min_eig);
  CHECK(dense_err < 1e-8);
}

TEST_CASE("active-set and projected-gradient maximisers give the same motion") {
  std::mt19937_64 rng(314159);  // the brute-force set's seed: the same draws
  int accepted = 0, attempts = 0;
  double qdd_diff = 0.0, g_diff = 0.0;
  std::vector<int> it_as, it_pg;
  while (accepted < 200) {
    ++attempts;
    REQUIRE(attempts < 2000);
    FrictionDraw d = randomFrictionDraw(rng, 2, 7, 1, 5, 6);
    const DenseResult dense = denseDynamics(d.spec, d.input);
    if (!wellPosed(dense, d.input.constraintRows())) continue;
    ++accepted;
    const Model model = modelFromSpec(d.spec);
    const Task task = taskFromInput(model, d.input);
    FrictionOptions options = randomOverrides(rng, d.setup, d.spec.dof());
    options.method = FrictionMethod::ActiveSet;
    const Solved a = solveChecked(model, task, d.input.q, d.input.qd, d.input.tau, options);
    REQUIRE_SOLVED(a);
    options.method = FrictionMethod::ProjectedGradient;
    const Solved p = solveChecked(model, task, d.input.q, d.input.qd, d.input.tau, options);
    INFO("draw " << accepted << ": " << d.spec.dof() << " dof, " << d.setup.stuck.size() << " stuck");
    REQUIRE_SOLVED(p);
    const double e = relativeError(p.solution.qdd, a.solution.qdd);
    CHECK(e < 1e-8);
    qdd_diff = std::max(qdd_diff, e);
    g_diff = std::max(g_diff, std::abs(p.friction.gauss_dual - a.friction.gauss_dual) /
                                  std::max(1.0, std::abs(a.friction.gauss_dual)));
    it_as.push_back(a.friction.iterations);
    it_pg.push_back(p.friction.iterations);
  }
  std::printf(
      "active set vs projected gradient on %d problems: max rel. difference qdd %.1e, g %.1e;"
      " iterations median/max: active set %.1f/%d, projected gradient %.1f/%d\n",
      accepted, qdd_diff, g_diff, median(it_as), *std::max_element(it_as.begin(), it_as.end()), median(it_pg),
      *std::max_element(it_pg.begin(), it_pg.end()));
  CHECK(g_diff < 1e-8);
}

TEST_CASE("indeterminate hold-still on the Panda: friction carries load, effort drops") {
  // The automatic choice (the active set: 7 stuck joints) and the pattern search forced, which makes the
  // least-effort choice itself, on the margin box here (docs/friction.md, "The pattern search").
  const FrictionMethod method = GENERATE(FrictionMethod::Automatic, FrictionMethod::StickPatterns);
  INFO("method " << toString(method));
  int searched = 0;
  const Model model = loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/panda.urdf");
  REQUIRE(model.dof() == 7);
  Task task(model);                                                                 // default gravity
  task.addConstraint("tool0", ConstraintMatrix::Identity(6, 6), Expressed::Local);  // tool0 held still
  task.addConstraint("panda_link1", angularZ(), Expressed::Local);                  // and the elbow's self-motion
  const double pi = 3.14159265358979323846;
  const std::vector<std::vector<double>> poses = {
      {0.0, -pi / 4, 0.0, -3 * pi / 4, 0.0, pi / 2, pi / 4},
      {0.5, 0.3, -0.4, -1.8, 0.6, 1.9, -0.3},
      {-1.0, 0.8, 0.9, -1.2, -1.5, 2.5, 1.0},
      {0.2, -1.2, 0.3, -2.5, 0.4, 0.9, 0.0},
  };
  const Eigen::VectorXd f = [&] {
    Eigen::VectorXd v(7);
    for (int j = 0; j < 7; ++j) v(j) = model.joint(j).breakaway_friction;
    return v;
  }();
  for (const auto& pose : poses) {
    const Eigen::VectorXd q = Eigen::Map<const Eigen::VectorXd>(pose.data(), 7);
    const Eigen::VectorXd qd = Eigen::VectorXd::Zero(7), tau = Eigen::VectorXd::Zero(7);
    Workspace free_ws(model, task);
    REQUIRE(solveHybridDynamics(model, free_ws, q, qd, tau, task));
    REQUIRE(free_ws.solution.balance.rank == 7);  // every joint's acceleration is fixed
    REQUIRE_FALSE(free_ws.solution.balance.singular);
    const Eigen::VectorXd G = free_ws.solution.tau_control;  // gravity torques, held by the motors
    for (double margin : {1.0, 0.5, 0.0}) {
      INFO("pose " << q.transpose() << ", margin " << margin);
      FrictionOptions options;
      options.margin = margin;
      options.method = method;
      const Solved s = solveChecked(model, task, q, qd, tau, options);
      REQUIRE_SOLVED(s);
      CHECK(s.friction.indeterminate);
      searched += s.friction.method == FrictionMethod::StickPatterns ? 1 : 0;
      CHECK(s.solution.qdd.cwiseAbs().maxCoeff() < 1e-9);
      // Closed form: τ_ctrl = G + μ with |μ_j| ≤ margin f_j, minimal ‖τ_ctrl‖.
      for (int j = 0; j < 7; ++j) {
        const double expected = std::max(0.0, std::abs(G(j)) - margin * f(j));
        CHECK(std::abs(s.solution.tau_control(j)) == Approx(expected).margin(1e-8));
        if (expected > 1e-6) CHECK(s.solution.tau_control(j) * G(j) > 0.0);
      }
      if (margin > 0.0)
        CHECK(s.solution.tau_control.norm() < G.norm() - 1e-3);
      else
        CHECK(s.solution.tau_control.norm() == Approx(G.norm()).epsilon(1e-9));
      std::printf("panda hold-still, margin %.1f: |tau_ctrl| %.3f N·m without friction, %.3f with (%s)\n", margin,
                  G.norm(), s.solution.tau_control.norm(), toString(s.friction.method));
    }
  }
  if (method == FrictionMethod::StickPatterns) CHECK(searched >= 8);  // of 12: the search's own choice
}

TEST_CASE("1-DOF arm held still under gravity: |tau| = max(0, |G| - margin f)") {
  const Model model = oneDofArmModel();  // f = 10 N·m, 1 kg, COM at 0.5 m
  const Eigen::VectorXd qd = Eigen::VectorXd::Zero(1), tau = Eigen::VectorXd::Zero(1);
  for (double q0 : {0.0, 0.7, 2.5}) {
    for (double g : {9.81, 30.0, -30.0}) {
      Task task(model);
      task.gravity = Eigen::Vector3d(0.0, -g, 0.0);
      task.addConstraint("link1", angularZ(), Expressed::Local);  // q̈ = 0
      const Eigen::VectorXd q = Eigen::VectorXd::Constant(1, q0);
      const double G = 0.5 * g * std::cos(q0);  // the torque that holds the link
      for (double margin : {1.0, 0.5, 0.0}) {
        INFO("q " << q0 << ", gravity " << g << ", G " << G << ", margin " << margin);
        FrictionOptions options;
        options.margin = margin;
        const Solved s = solveChecked(model, task, q, qd, tau, options);
        REQUIRE_SOLVED(s);
        CHECK(s.friction.indeterminate);
        CHECK(s.solution.qdd(0) == Approx(0.0).margin(1e-12));
        CHECK(std::abs(s.solution.tau_control(0)) == Approx(std::max(0.0, std::abs(G) - margin * 10.0)).margin(1e-9));
        CHECK(s.friction.mu(0) == Approx(-std::copysign(std::min(std::abs(G), margin * 10.0), G)).margin(1e-9));
      }
    }
  }
}

TEST_CASE("bad friction options are refused with BadOption") {
  const Model model = oneDofArmModel();
  Task task(model);
  Workspace ws(model, task);
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(1), qd = Eigen::VectorXd::Zero(1), tau = Eigen::VectorXd::Zero(1);
  auto refused = [&](const FrictionOptions& o, const char* word) {
    const Status st = solveWithFriction(model, ws, q, qd, tau, task, o);
    INFO("message: " << st.message);
    CHECK(st.code == StatusCode::BadOption);
    CHECK(std::strlen(st.message) > 10);
    if (word) CHECK(std::string(st.message).find(word) != std::string::npos);
  };
  FrictionOptions o;
  o.breakaway = Eigen::VectorXd::Ones(2);
  refused(o, "breakaway");
  o = {};
  o.kinetic = Eigen::VectorXd::Ones(3);
  refused(o, "kinetic");
  o = {};
  o.viscous = Eigen::VectorXd::Ones(2);
  refused(o, "viscous");
  o = {};
  o.breakaway = Eigen::VectorXd::Constant(1, -1.0);
  refused(o, "breakaway");
  o = {};
  o.kinetic = Eigen::VectorXd::Constant(1, -0.5);
  refused(o, "kinetic");
  o = {};
  o.viscous = Eigen::VectorXd::Constant(1, std::numeric_limits<double>::quiet_NaN());
  refused(o, "viscous");
  o = {};
  o.velocity_tolerance = -1e-6;
  refused(o, "velocity_tolerance");
  o = {};
  o.margin = -0.1;
  refused(o, "margin");
  o = {};
  o.margin = 1.5;
  refused(o, "margin");
  o = {};
  o.max_iterations = 0;
  refused(o, "max_iterations");
  // A good solve afterwards still works.
  const Solved s = solveChecked(model, task, q, qd, tau);
  REQUIRE_SOLVED(s);
}
