// Joint position limits as one-sided reactions combined with static friction
// (docs/friction.md, "Joint position limits"; issue 3 item 5), through solveWithFriction, against closed forms on
// a 1-DOF arm and the brute-force enumeration (support/friction_reference) on
// random chains with stuck joints resting exactly on a limit.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <string>

#include "support/friction_check.hpp"
#include "support/friction_reference.hpp"
#include "support/random_chain.hpp"
#include "support/random_problem.hpp"
#include "zwang/friction.hpp"

using namespace zwang;
using namespace zwang::testing;

namespace {

ConstraintMatrix angularZ() {
  ConstraintMatrix A = ConstraintMatrix::Zero(6, 1);
  A(5, 0) = 1.0;
  return A;
}

bool finiteOutputs(const Workspace& ws) {
  const FrictionResult& r = ws.friction;
  return ws.solution.qdd.allFinite() && ws.solution.tau_control.allFinite() && ws.solution.tau_constraint.allFinite() &&
         ws.solution.nu.allFinite() && r.mu.allFinite() && r.tau_friction.allFinite() && r.dqdd_dmu.allFinite() &&
         std::isfinite(r.gauss_dual) && std::isfinite(ws.solution.gauss);
}

// The report's arm (docs/theory.md, "The reference cases") with limits [−0.5, 1.0] and f = 2.
struct LimitedArm {
  ChainSpec spec;
  Model model;
  LimitedArm() : spec(make()), model(modelFromSpec(spec)) {}
  static ChainSpec make() {
    ChainSpec s = oneDofArm();
    s.joints[0].lower = -0.5;
    s.joints[0].upper = 1.0;
    s.joints[0].friction = 2.0;
    return s;
  }
};

struct Case {
  Status status;
  Workspace ws;
  std::string violation;
  double closure = 0.0;
};

Case solveArm(const LimitedArm& arm, const Task& task, double q0, double qd0, const FrictionOptions& options = {}) {
  const Eigen::VectorXd q = Eigen::VectorXd::Constant(1, q0), qd = Eigen::VectorXd::Constant(1, qd0);
  const Eigen::VectorXd tau = Eigen::VectorXd::Zero(1);
  Case c{Status{}, Workspace(arm.model, task), "", 0.0};
  c.status = solveWithFriction(arm.model, c.ws, q, qd, tau, task, options);
  if (c.status.ok()) {
    c.violation = checkMaximumDissipation(c.ws.friction, c.ws.solution, expectFriction(arm.model, q, qd, tau, options));
    c.closure = frictionClosureError(arm.model, task, q, qd, c.ws.friction, c.ws.solution);
  }
  return c;
}

#define REQUIRE_SOLVED(c)                           \
  do {                                              \
    INFO("status message: " << (c).status.message); \
    REQUIRE((c).status.ok());                       \
    INFO("maximum dissipation: " << (c).violation); \
    CHECK((c).violation.empty());                   \
    CHECK((c).closure < 1e-9);                      \
  } while (false)

}  // namespace

TEST_CASE("a 1-DOF arm on its limits under gravity") {
  const LimitedArm arm;
  Task task(arm.model);
  // Gravity −y: torque −0.5·g·cos q about z (the link pulled towards negative q).
  task.gravity = Eigen::Vector3d(0.0, -9.81, 0.0);
  const double G_lower = -0.5 * 9.81 * std::cos(-0.5);  // −4.30 N·m at the lower limit
  const double G_upper = -0.5 * 9.81 * std::cos(1.0);   // −2.65 N·m at the upper limit

  SECTION("resting on the lower limit, gravity pulling into it, f < |G|: stays, AtLimit") {
    const Case c = solveArm(arm, task, -0.5, 0.0);
    REQUIRE_SOLVED(c);
    CHECK(c.ws.friction.state[0] == JointState::AtLimit);
    CHECK(c.ws.solution.qdd(0) == Approx(0.0).margin(1e-12));
    CHECK(c.ws.friction.mu(0) == Approx(G_lower).epsilon(1e-10));  // holds all of it, beyond −f
    CHECK(c.ws.friction.tau_friction(0) == Approx(-G_lower).epsilon(1e-10));
    CHECK_FALSE(c.ws.friction.limit_impact);
  }
  SECTION("the same with limits off: it slips down") {
    FrictionOptions options;
    options.joint_limits = false;
    const Case c = solveArm(arm, task, -0.5, 0.0, options);
    REQUIRE_SOLVED(c);
    CHECK(c.ws.friction.state[0] == JointState::SlipNegative);
    CHECK(c.ws.solution.qdd(0) == Approx((G_lower + 2.0) / 2.25).epsilon(1e-10));
  }
  SECTION("on the lower limit, gravity pulling away, |G| > f: slips away") {
    task.gravity = -task.gravity;
    const Case c = solveArm(arm, task, -0.5, 0.0);
    REQUIRE_SOLVED(c);
    CHECK(c.ws.friction.state[0] == JointState::SlipPositive);
    CHECK(c.ws.friction.mu(0) == Approx(2.0));
    CHECK(c.ws.solution.qdd(0) == Approx((-G_lower - 2.0) / 2.25).epsilon(1e-10));
  }
  SECTION("on the lower limit, gravity pulling away, |G| < f: sticks by friction") {
    task.gravity = Eigen::Vector3d(0.0, 2.0, 0.0);
    const Case c = solveArm(arm, task, -0.5, 0.0);
    REQUIRE_SOLVED(c);
    CHECK(c.ws.friction.state[0] == JointState::Stick);
    CHECK(c.ws.friction.mu(0) == Approx(0.5 * 2.0 * std::cos(0.5)).epsilon(1e-10));
    CHECK(c.ws.solution.qdd(0) == Approx(0.0).margin(1e-12));
  }
  SECTION("on the lower limit, gravity into it but |G| < f: friction holds, Stick") {
    task.gravity = Eigen::Vector3d(0.0, -2.0, 0.0);
    const Case c = solveArm(arm, task, -0.5, 0.0);
    REQUIRE_SOLVED(c);
    CHECK(c.ws.friction.state[0] == JointState::Stick);
    CHECK(c.ws.friction.mu(0) == Approx(-0.5 * 2.0 * std::cos(0.5)).epsilon(1e-10));
  }
  SECTION("on the upper limit, gravity pulling away: slips down") {
    const Case c = solveArm(arm, task, 1.0, 0.0);
    REQUIRE_SOLVED(c);
    CHECK(c.ws.friction.state[0] == JointState::SlipNegative);
    CHECK(c.ws.solution.qdd(0) == Approx((G_upper + 2.0) / 2.25).epsilon(1e-10));
  }
  SECTION("on the upper limit, gravity pushing into it: AtLimit, μ beyond +f") {
    task.gravity = -task.gravity;
    const Case c = solveArm(arm, task, 1.0, 0.0);
    REQUIRE_SOLVED(c);
    CHECK(c.ws.friction.state[0] == JointState::AtLimit);
    CHECK(c.ws.friction.mu(0) == Approx(-G_upper).epsilon(1e-10));
    CHECK(c.ws.solution.qdd(0) == Approx(0.0).margin(1e-12));
  }
  SECTION("a task pulling away from the lower limit: friction opposes it") {
    const int row = task.addConstraint("link1", angularZ(), Expressed::Local);
    task.targets()(row) = 1.0;
    const Case c = solveArm(arm, task, -0.5, 0.0);
    REQUIRE_SOLVED(c);
    CHECK(c.ws.friction.state[0] == JointState::SlipPositive);
    CHECK(c.ws.friction.mu(0) == Approx(2.0));
    CHECK(c.ws.solution.qdd(0) == Approx(1.0).epsilon(1e-12));
    CHECK(c.ws.solution.tau_control(0) == Approx(2.25 * 1.0 + 2.0 - G_lower).epsilon(1e-10));
  }
  SECTION("a task driving into the lower limit is infeasible, with finite outputs") {
    const int row = task.addConstraint("link1", angularZ(), Expressed::Local);
    task.targets()(row) = -1.0;
    const Case c = solveArm(arm, task, -0.5, 0.0);
    INFO("message: " << c.status.message);
    CHECK(c.status.code == StatusCode::Infeasible);
    CHECK(std::string(c.status.message).size() > 10);
    CHECK(finiteOutputs(c.ws));
    // The brute force agrees: no stick/slip pattern satisfies the conditions.
    DynamicsInput in;
    in.q = Eigen::VectorXd::Constant(1, -0.5);
    in.qd = in.tau = Eigen::VectorXd::Zero(1);
    in.gravity = task.gravity;
    ConstraintInput con;
    con.link = "link1";
    con.A = angularZ();
    con.b = Eigen::VectorXd::Constant(1, -1.0);
    in.constraints.push_back(con);
    FrictionSetup setup = frictionSetupFromSpec(arm.spec, in.qd);
    setup.limit_side = Eigen::VectorXi::Constant(1, -1);
    CHECK_FALSE(bruteForceFriction(arm.spec, in, setup).feasible);
  }
  SECTION("a task holding still on the limit is fine") {
    task.addConstraint("link1", angularZ(), Expressed::Local);  // q̈ = 0
    const Case c = solveArm(arm, task, -0.5, 0.0);
    REQUIRE_SOLVED(c);
    CHECK(c.ws.solution.qdd(0) == Approx(0.0).margin(1e-12));
  }
  SECTION("moving into the lower limit: an impact, reported") {
    const Case c = solveArm(arm, task, -0.5, -0.3);
    INFO("message: " << c.status.message);
    CHECK(c.ws.friction.limit_impact);
    CHECK(c.ws.friction.impact_joint == 0);
    CHECK(finiteOutputs(c.ws));
  }
  SECTION("moving away from the lower limit: no impact, kinetic friction") {
    const Case c = solveArm(arm, task, -0.5, 0.3);
    REQUIRE_SOLVED(c);
    CHECK_FALSE(c.ws.friction.limit_impact);
    CHECK(c.ws.friction.state[0] == JointState::Moving);
    CHECK(c.ws.friction.tau_friction(0) == Approx(-2.0).epsilon(1e-12));  // f_c = f, no damping
  }
  SECTION("moving into the upper limit: an impact") {
    const Case c = solveArm(arm, task, 1.0, 0.3);
    CHECK(c.ws.friction.limit_impact);
    CHECK(c.ws.friction.impact_joint == 0);
    CHECK(finiteOutputs(c.ws));
  }
}

TEST_CASE("limits on random chains match the brute force with one-sided bounds") {
  // The automatic choice (the active set for most of these small stuck sets) and the pattern search forced.
  const FrictionMethod method = GENERATE(FrictionMethod::Automatic, FrictionMethod::StickPatterns);
  INFO("method " << toString(method));
  std::mt19937_64 rng(8128);
  int accepted = 0, attempts = 0, infeasible = 0, at_limit_states = 0, on_limit = 0;
  double qdd_err = 0.0, g_err = 0.0;
  while (accepted < 150) {
    ++attempts;
    REQUIRE(attempts < 2000);
    FrictionDraw d = randomFrictionDraw(rng, 2, 6, 1, 4, 6);
    // Put about half of the stuck joints that have limits exactly on one.
    const std::vector<int> moving = d.spec.movingJoints();
    d.setup.limit_side = Eigen::VectorXi::Zero(d.spec.dof());
    for (int j : d.setup.stuck) {
      const JointSpec& joint = d.spec.joints[static_cast<std::size_t>(moving[static_cast<std::size_t>(j)])];
      if (joint.type == "continuous" || uniform01(rng) < 0.4) continue;
      const bool lower = uniform01(rng) < 0.5;
      d.input.q(j) = lower ? joint.lower : joint.upper;
      d.setup.limit_side(j) = lower ? -1 : 1;
    }
    if (d.setup.limit_side.cwiseAbs().sum() == 0) continue;
    const DenseResult dense = denseDynamics(d.spec, d.input);
    if (!wellPosed(dense, d.input.constraintRows())) continue;
    ++accepted;
    on_limit += d.setup.limit_side.cwiseAbs().sum();
    const FrictionReference ref = bruteForceFriction(d.spec, d.input, d.setup);
    const Model model = modelFromSpec(d.spec);
    const Task task = taskFromInput(model, d.input);
    Workspace ws(model, task);
    FrictionOptions options;
    options.method = method;
    const Status status = solveWithFriction(model, ws, d.input.q, d.input.qd, d.input.tau, task, options);
    INFO("draw " << accepted << ": " << d.spec.dof() << " dof, " << d.input.constraintRows() << " rows, "
                 << d.setup.stuck.size() << " stuck, reference pattern " << ref.pattern << "; " << status.message);
    CHECK_FALSE(ws.friction.limit_impact);
    if (!ref.feasible) {
      ++infeasible;
      // (When the solver claims success anyway, say what is wrong with it.)
      INFO("maximum dissipation of the returned result: "
           << (status.ok() ? checkMaximumDissipation(ws.friction, ws.solution,
                                                     expectFriction(model, d.input.q, d.input.qd, d.input.tau))
                           : std::string("-"))
           << "; iterations " << ws.friction.iterations << ", kkt residual " << ws.friction.kkt_residual);
      CHECK(status.code == StatusCode::Infeasible);
      CHECK(finiteOutputs(ws));
      continue;
    }
    REQUIRE(status.ok());
    const std::string why =
        checkMaximumDissipation(ws.friction, ws.solution, expectFriction(model, d.input.q, d.input.qd, d.input.tau));
    INFO("maximum dissipation: " << why);
    CHECK(why.empty());
    CHECK(frictionClosureError(model, task, d.input.q, d.input.qd, ws.friction, ws.solution) < 1e-9);
    REQUIRE(ref.qdd_spread < 1e-9);
    const double e_qdd = relativeError(ws.solution.qdd, ref.qdd);
    const double e_g = std::abs(ws.friction.gauss_dual - ref.gauss_dual) / std::max(1.0, std::abs(ref.gauss_dual));
    CHECK(e_qdd < 1e-8);
    CHECK(e_g < 1e-8);
    qdd_err = std::max(qdd_err, e_qdd);
    g_err = std::max(g_err, e_g);
    for (JointState s : ws.friction.state) at_limit_states += s == JointState::AtLimit;
  }
  std::printf(
      "limits vs brute force, %d random chains (%d draws skipped; %d stuck joints on a limit, %d AtLimit, "
      "%d infeasible): max rel. error qdd %.2e, g %.2e\n",
      accepted, attempts - accepted, on_limit, at_limit_states, infeasible, qdd_err, g_err);
  CHECK(at_limit_states > 10);
}
