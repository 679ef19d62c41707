// Self-tests of the independent friction references (support/friction_reference):
// the brute-force pattern enumeration and the report's grid sampling agree with
// each other, with the closed forms of docs/theory.md, "The reference cases", and the brute
// force's μ* really maximises g over the box. No zwang friction code is used.
#include <catch2/catch.hpp>
#include <cstdio>

#include "support/friction_reference.hpp"
#include "support/random_chain.hpp"
#include "support/random_problem.hpp"

using namespace zwang::testing;

namespace {

// The report's 1-DOF arm (docs/theory.md, "The reference cases"), no gravity, stuck at q = 0.
DynamicsInput armInput() {
  DynamicsInput in;
  in.q = Eigen::VectorXd::Zero(1);
  in.qd = Eigen::VectorXd::Zero(1);
  in.tau = Eigen::VectorXd::Zero(1);
  in.gravity.setZero();
  return in;
}

DynamicsInput tipForce(double fy) {
  DynamicsInput in = armInput();
  WrenchInput w;
  w.link = "tool";
  w.wrench << 0.0, fy, 0.0, 0.0, 0.0, 0.0;
  in.wrenches.push_back(w);
  return in;
}

ConstraintInput angularZ(const std::string& link, double b) {
  ConstraintInput c;
  c.link = link;
  c.A = Matrix6Xd::Zero(6, 1);
  c.A(5, 0) = 1.0;
  c.b = Eigen::VectorXd::Constant(1, b);
  return c;
}

}  // namespace

TEST_CASE("friction references reproduce the report's 1-DOF evaluation") {
  const ChainSpec spec = oneDofArm();
  SECTION("-5 N sticks") {
    const DynamicsInput in = tipForce(-5.0);
    const FrictionSetup setup = frictionSetupFromSpec(spec, in.qd);
    const FrictionReference r = bruteForceFriction(spec, in, setup);
    REQUIRE(r.feasible);
    CHECK(r.pattern == "s");
    CHECK(r.mu(0) == Approx(-5.0).margin(1e-12));
    CHECK(r.qdd(0) == Approx(0.0).margin(1e-12));
    CHECK(r.valid_patterns == 1);
    const SampledFriction s = sampledFriction(spec, in, setup, 201);
    CHECK(s.mu(0) == Approx(-5.0).margin(1e-12));  // -5 is a grid point (spacing 0.1)
    CHECK(s.g == Approx(r.gauss_dual).margin(1e-12));
  }
  SECTION("-11 N slips") {
    const DynamicsInput in = tipForce(-11.0);
    const FrictionSetup setup = frictionSetupFromSpec(spec, in.qd);
    const FrictionReference r = bruteForceFriction(spec, in, setup);
    REQUIRE(r.feasible);
    CHECK(r.pattern == "-");
    CHECK(r.mu(0) == Approx(-10.0).margin(1e-12));
    CHECK(r.qdd(0) == Approx(-1.0 / 2.25).epsilon(1e-12));
    const SampledFriction s = sampledFriction(spec, in, setup, 201);
    CHECK(s.mu(0) == Approx(-10.0).margin(1e-12));
    CHECK(s.qdd(0) == Approx(-1.0 / 2.25).epsilon(1e-12));
  }
  SECTION("Fig. 5.5: fully constrained, a vertex") {
    DynamicsInput in = armInput();
    in.constraints.push_back(angularZ("link1", 5.0));
    const FrictionSetup setup = frictionSetupFromSpec(spec, in.qd);
    const FrictionReference r = bruteForceFriction(spec, in, setup);
    REQUIRE(r.feasible);
    CHECK(r.pattern == "+");
    CHECK(r.singular_patterns == 1);  // stick: the task already fixes q̈
    CHECK(r.mu(0) == Approx(10.0).margin(1e-12));
    CHECK(r.qdd(0) == Approx(5.0).epsilon(1e-12));
    CHECK(r.nu(0) == Approx(2.25 * 5.0 + 10.0).epsilon(1e-12));  // τ_c = ν for this row
    const SampledFriction s = sampledFriction(spec, in, setup, 21);
    CHECK(s.mu(0) == Approx(10.0).margin(1e-12));
  }
  SECTION("fully constrained holding still: indeterminate") {
    DynamicsInput in = armInput();
    in.constraints.push_back(angularZ("link1", 0.0));
    const FrictionSetup setup = frictionSetupFromSpec(spec, in.qd);
    const FrictionReference r = bruteForceFriction(spec, in, setup);
    REQUIRE(r.feasible);
    CHECK(r.valid_patterns == 2);  // slip+ and slip-, both with q̈ = 0
    CHECK(r.mu_spread == Approx(20.0));
    CHECK(r.qdd_spread == 0.0);
  }
}

TEST_CASE("friction references: joint limits") {
  ChainSpec spec = oneDofArm();
  spec.joints[0].lower = -0.5;
  spec.joints[0].upper = 1.0;
  spec.joints[0].friction = 2.0;
  DynamicsInput in = armInput();
  in.gravity = Eigen::Vector3d(0.0, -9.81, 0.0);
  FrictionSetup setup = frictionSetupFromSpec(spec, in.qd);
  setup.limit_side = Eigen::VectorXi::Constant(1, -1);
  in.q(0) = -0.5;  // on the lower limit; gravity torque −0.5·9.81·cos(0.5) pulls into it
  const double G = -0.5 * 9.81 * std::cos(0.5);

  SECTION("resting on the limit") {
    const FrictionReference r = bruteForceFriction(spec, in, setup);
    REQUIRE(r.feasible);
    CHECK(r.pattern == "L");
    CHECK(r.qdd(0) == Approx(0.0).margin(1e-12));
    CHECK(r.mu(0) == Approx(G).epsilon(1e-12));  // τ − μ + G = 0 with τ = 0
  }
  SECTION("gravity reversed: slips away from the limit") {
    in.gravity = -in.gravity;
    const FrictionReference r = bruteForceFriction(spec, in, setup);
    REQUIRE(r.feasible);
    CHECK(r.pattern == "+");
    CHECK(r.qdd(0) == Approx((-G - 2.0) / 2.25).epsilon(1e-12));
  }
  SECTION("a task pushing into the limit is infeasible") {
    in.constraints.push_back(angularZ("link1", -1.0));
    const FrictionReference r = bruteForceFriction(spec, in, setup);
    CHECK_FALSE(r.feasible);
    CHECK(r.valid_patterns == 0);
  }
  SECTION("a task pulling away from the limit") {
    in.constraints.push_back(angularZ("link1", 1.0));
    const FrictionReference r = bruteForceFriction(spec, in, setup);
    REQUIRE(r.feasible);
    CHECK(r.pattern == "+");
    CHECK(r.mu(0) == Approx(2.0));
  }
}

TEST_CASE("brute force maximises g; the grid sampling agrees (random chains)") {
  std::mt19937_64 rng(5150);
  int accepted = 0, attempts = 0, sampled = 0, ill_posed = 0;
  double max_spread = 0.0, max_dual_err = 0.0, max_qdd_err = 0.0, max_excess = 0.0, max_grid_gap = 0.0;
  while (accepted < 120) {
    ++attempts;
    REQUIRE(attempts < 1000);
    const FrictionDraw d = randomFrictionDraw(rng, 2, 6, 1, 4, 6);
    const DenseResult dense = denseDynamics(d.spec, d.input);
    if (!wellPosed(dense, d.input.constraintRows())) {
      ++ill_posed;
      continue;
    }
    const FrictionReference r = bruteForceFriction(d.spec, d.input, d.setup);
    REQUIRE(r.feasible);  // a regular valid pattern always exists (see friction_reference.hpp)
    ++accepted;
    max_spread = std::max({max_spread, r.qdd_spread, r.gauss_spread});
    // g at μ* by an independent full dense solve.
    const FrictionDual at = denseFrictionDual(d.spec, d.input, d.setup, r.mu);
    max_dual_err = std::max(max_dual_err, std::abs(at.g - r.gauss_dual) / std::max(1.0, std::abs(r.gauss_dual)));
    max_qdd_err = std::max(max_qdd_err, relativeError(at.qdd, r.qdd));
    // No point of the box does better.
    for (int t = 0; t < 10; ++t) {
      Eigen::VectorXd mu = Eigen::VectorXd::Zero(d.spec.dof());
      for (int j : d.setup.stuck) mu(j) = uniform(rng, -1.0, 1.0) * d.setup.breakaway(j);
      const FrictionDual other = denseFrictionDual(d.spec, d.input, d.setup, mu);
      max_excess = std::max(max_excess, (other.g - r.gauss_dual) / std::max(1.0, std::abs(r.gauss_dual)));
    }
    // The report's grid: never above the maximum, and close to it.
    const int k = static_cast<int>(d.setup.stuck.size());
    if (k <= 2) {
      ++sampled;
      const SampledFriction s = sampledFriction(d.spec, d.input, d.setup, k == 1 ? 101 : 31);
      const double h = s.spacing.maxCoeff();
      Eigen::VectorXd grad(k);
      for (int i = 0; i < k; ++i) grad(i) = r.qdd(d.setup.stuck[static_cast<std::size_t>(i)]);
      const Eigen::MatrixXd K = denseConstrainedInverseInertia(d.spec, d.input);
      double kmax = 0.0;
      for (int j : d.setup.stuck) kmax = std::max(kmax, K(j, j));
      // g(μ*) − g(μ) ≤ |∇g(μ*)|₁ h + ½ λ_max k h² for the grid point nearest μ*.
      const double bound = grad.lpNorm<1>() * h + 0.5 * kmax * k * k * h * h;
      const double gap = r.gauss_dual - s.g;
      CHECK(gap >= -1e-9 * std::max(1.0, std::abs(r.gauss_dual)));
      CHECK(gap <= bound + 1e-9 * std::max(1.0, std::abs(r.gauss_dual)));
      max_grid_gap = std::max(max_grid_gap, bound > 0 ? gap / bound : 0.0);
    }
  }
  std::printf(
      "friction references: %d random problems (%d ill-posed draws skipped), %d sampled on a grid\n"
      "  spread among valid patterns %.1e, g vs dense solve %.1e, qdd vs dense solve %.1e,\n"
      "  max excess of g at random box points %.1e, grid gap / bound %.2f\n",
      accepted, ill_posed, sampled, max_spread, max_dual_err, max_qdd_err, max_excess, max_grid_gap);
  CHECK(max_spread < 1e-9);
  CHECK(max_dual_err < 1e-10);
  CHECK(max_qdd_err < 1e-10);
  CHECK(max_excess <= 1e-12);
  CHECK(sampled > 30);
}
