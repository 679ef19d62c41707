// Kinematic trees (issue #14) against independent references: the dense KKT
// formulation of support/dense_reference (which walks each link's parents,
// nothing shared with the sweeps), finite differences of the relative pose for
// the meaning of a relative constraint, and the brute-force enumeration of
// stick/slip patterns for friction. Every case prints what it measured.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdio>
#include <random>

#include "support/dense_reference.hpp"
#include "support/friction_check.hpp"
#include "support/friction_reference.hpp"
#include "support/random_chain.hpp"
#include "support/random_problem.hpp"
#include "zwang/zwang.hpp"

using namespace zwang;
using namespace zwang::testing;

namespace {

// The number of links with two or more children, and the most children of one link.
std::pair<int, int> branching(const ChainSpec& spec) {
  std::vector<int> children(spec.links.size(), 0);
  for (std::size_t k = 0; k < spec.joints.size(); ++k) ++children[static_cast<std::size_t>(spec.parentLink(k))];
  int branch_points = 0;
  for (int c : children) branch_points += c > 1 ? 1 : 0;
  return {branch_points, *std::max_element(children.begin(), children.end())};
}

// The dense rows G q̈ − γ for zwang's q̈, relative to the terms' size.
double closureError(const DenseResult& dense, const Eigen::VectorXd& qdd) {
  if (dense.G.rows() == 0) return 0.0;
  const Eigen::VectorXd r = dense.G * qdd - dense.gamma;
  const double size = 1.0 + (dense.G.cwiseAbs() * qdd.cwiseAbs()).maxCoeff() + dense.gamma.cwiseAbs().maxCoeff();
  return r.cwiseAbs().maxCoeff() / size;
}

}  // namespace

TEST_CASE("trees: q̈, ν and τ_c match the dense KKT reference (500 random trees, relative constraints)", "[trees]") {
  std::mt19937_64 rng(20261124);
  RandomTreeOptions tree;  // 2–30 moving joints, branching 1–4, fixed joints, rotors
  int accepted = 0, attempts = 0, relative_rows = 0, rows_total = 0, most_rows = 0, most_links = 0, branched = 0;
  int most_children = 0, largest = 0;
  double e_qdd = 0.0, e_nu = 0.0, e_tau_c = 0.0, e_closure = 0.0, e_gauss = 0.0;
  while (accepted < 500) {
    REQUIRE(++attempts < 5000);
    const ChainSpec spec = randomTree(rng, tree);
    RandomProblemOptions options;
    options.max_constraint_rows = std::min(12, spec.dof());  // more rows than joints can never be met
    options.max_constraint_frames = 4;
    options.relative_probability = 0.4;
    const DynamicsInput in = randomProblem(rng, spec, options);
    const DenseResult dense = denseDynamics(spec, in);
    if (!wellPosed(dense, in)) continue;
    const Model model = modelFromSpec(spec);
    const Task task = taskFromInput(model, in);
    Workspace ws(model, task);
    REQUIRE(solveHybridDynamics(model, ws, in.q, in.qd, in.tau, task));
    const Solution& s = ws.solution;
    INFO("tree " << accepted << ": " << spec.dof() << " joints, " << in.constraintRows() << " rows");
    const double eq = relativeError(s.qdd, dense.qdd), en = relativeError(s.nu, dense.nu);
    const double et = relativeError(s.tau_constraint, dense.tau_c), ec = closureError(dense, s.qdd);
    const double eg = std::abs(s.gauss - dense.gauss) / std::max(1.0, std::abs(dense.gauss));
    CHECK(eq < 1e-9);
    CHECK(en < 1e-9);
    CHECK(et < 1e-9);
    CHECK(ec < 1e-9);
    CHECK(eg < 1e-9);
    CHECK(s.balance.consistent);
    e_qdd = std::max(e_qdd, eq);
    e_nu = std::max(e_nu, en);
    e_tau_c = std::max(e_tau_c, et);
    e_closure = std::max(e_closure, ec);
    e_gauss = std::max(e_gauss, eg);
    ++accepted;
    rows_total += in.constraintRows();
    most_rows = std::max(most_rows, in.constraintRows());
    most_links = std::max(most_links, static_cast<int>(in.constraints.size()));
    for (const ConstraintInput& c : in.constraints)
      relative_rows += c.relative_to.empty() ? 0 : static_cast<int>(c.b.size());
    const auto [points, children] = branching(spec);
    branched += points > 0 ? 1 : 0;
    most_children = std::max(most_children, children);
    largest = std::max(largest, spec.dof());
  }
  std::printf(
      "trees vs dense KKT: %d trees (%d draws, the rest ill-conditioned), %d branched (up to %d children), up to %d "
      "joints; %d rows (%d relative), up to %d rows on %d links\n"
      "  max rel. error qdd %.2e, nu %.2e, tau_c %.2e, closure %.2e, Gauss %.2e\n",
      accepted, attempts, branched, most_children, largest, rows_total, relative_rows, most_rows, most_links, e_qdd,
      e_nu, e_tau_c, e_closure, e_gauss);
  CHECK(relative_rows > 300);  // the relative constraints are exercised
  CHECK(branched > 250);       // a quarter of the trees draw branching 1: chains
}

TEST_CASE("trees: RNEA, CRBA (zero blocks between branches), Jacobians and frame accelerations", "[trees]") {
  std::mt19937_64 rng(7);
  double e_tau = 0.0, e_H = 0.0, e_J = 0.0, e_acc = 0.0;
  int zero_blocks = 0;
  for (int t = 0; t < 150; ++t) {
    const ChainSpec spec = randomTree(rng);
    const DynamicsInput in = randomProblem(rng, spec);
    const Model model = modelFromSpec(spec);
    const Task task = taskFromInput(model, in);
    Workspace ws(model, task);
    const Eigen::VectorXd qdd = randomVector(rng, spec.dof(), 5.0);
    REQUIRE(inverseDynamics(model, ws, in.q, in.qd, qdd, task));
    e_tau =
        std::max(e_tau, relativeError(ws.tau, denseInverseDynamics(spec, in.q, in.qd, qdd, in.gravity, in.wrenches)));
    REQUIRE(jointSpaceInertia(model, ws, in.q));
    const DenseResult dense = denseDynamics(spec, in);
    e_H = std::max(e_H, (ws.H - dense.H).cwiseAbs().maxCoeff() / std::max(1.0, dense.H.cwiseAbs().maxCoeff()));
    for (int i = 0; i < model.dof(); ++i)  // joints on different branches: exactly zero
      for (int j = 0; j < model.dof(); ++j)
        if (!model.supports(i + 1, j + 1) && !model.supports(j + 1, i + 1)) {
          CHECK(ws.H(i, j) == 0.0);
          ++zero_blocks;
        }
    for (const LinkSpec& link : spec.links) {
      Eigen::MatrixXd J(6, model.dof());
      REQUIRE(frameJacobian(model, ws, in.q, model.frameIndex(link.name), Expressed::World, J));
      const Eigen::MatrixXd J_ref = linkJacobian(spec, in.q, link.name, Axes::World);
      e_J = std::max(e_J, J.size() ? (J - J_ref).cwiseAbs().maxCoeff() : 0.0);
    }
    REQUIRE(solveHybridDynamics(model, ws, in.q, in.qd, in.tau, task));
    for (const LinkSpec& link : spec.links) {
      Vec6 acc;
      REQUIRE(frameAcceleration(model, ws, in.q, in.qd, model.frameIndex(link.name), Expressed::World, acc));
      const Vector6d ref = linkAcceleration(spec, in.q, in.qd, ws.solution.qdd, link.name, Axes::World);
      e_acc = std::max(e_acc, (acc - ref).cwiseAbs().maxCoeff() / std::max(1.0, ref.cwiseAbs().maxCoeff()));
    }
  }
  std::printf(
      "trees, 150: max rel. error RNEA %.2e, CRBA %.2e (%d entries between branches, all exactly 0), "
      "Jacobian %.2e, frame acceleration %.2e\n",
      e_tau, e_H, zero_blocks, e_J, e_acc);
  CHECK(e_tau < 1e-10);
  CHECK(e_H < 1e-10);
  CHECK(e_J < 1e-10);
  CHECK(e_acc < 1e-9);
  CHECK(zero_blocks > 1000);
}

TEST_CASE("relative constraints: the acceleration seen from the reference frame (finite differences)", "[trees]") {
  // Hold link a to link r on another branch with all six rows and random set
  // points; zwang's q̈ then makes the motion q(t) = q + q̇ t + ½ q̈ t², along
  // which R_r(t)ᵀ (p_a − p_r) and R_r(t)ᵀ (ω_a − ω_r) are differentiated
  // numerically and turned back to world axes at t = 0.
  std::mt19937_64 rng(99);
  RandomTreeOptions tree;
  tree.min_moving_joints = 14;
  tree.max_moving_joints = 20;
  tree.min_branching = 2;
  int accepted = 0, attempts = 0;
  double worst = 0.0;
  while (accepted < 40) {
    REQUIRE(++attempts < 2000);
    const ChainSpec spec = randomTree(rng, tree);
    DynamicsInput in = randomProblem(rng, spec, RandomProblemOptions{0, 1, 0, false, 0.8, 0.0});
    ConstraintInput c;
    c.link = spec.links[static_cast<std::size_t>(uniformInt(rng, 1, static_cast<int>(spec.links.size()) - 1))].name;
    c.relative_to =
        spec.links[static_cast<std::size_t>(uniformInt(rng, 1, static_cast<int>(spec.links.size()) - 1))].name;
    if (c.link == c.relative_to) continue;
    c.A = Matrix6Xd::Identity(6, 6);
    c.b = randomVector(rng, 6, 2.0);
    c.axes = Axes::World;
    in.constraints.push_back(c);
    const DenseResult dense = denseDynamics(spec, in);
    if (!wellPosed(dense, in)) continue;
    const Model model = modelFromSpec(spec);
    const Task task = taskFromInput(model, in);
    Workspace ws(model, task);
    REQUIRE(solveHybridDynamics(model, ws, in.q, in.qd, in.tau, task));
    const Eigen::VectorXd& qdd = ws.solution.qdd;
    const auto a = static_cast<std::size_t>(spec.linkIndex(c.link)),
               r = static_cast<std::size_t>(spec.linkIndex(c.relative_to));
    auto relative = [&](double t, Eigen::Vector3d& p_rel, Eigen::Vector3d& w_rel) {
      const DenseKinematics kin = denseKinematics(spec, in.q + in.qd * t + 0.5 * qdd * t * t, in.qd + qdd * t);
      const Eigen::Matrix3d Rr = kin.poses[r].linear();
      p_rel = Rr.transpose() * (kin.poses[a].translation() - kin.poses[r].translation());
      w_rel = Rr.transpose() * (kin.v[a].tail<3>() - kin.v[r].tail<3>());
      return Rr;
    };
    // Central differences with Richardson extrapolation, D = (4 D(h/2) − D(h)) / 3,
    // at h = 2e-4: truncation O(h⁴) (~1e-8 for the fastest draws, |q̈| ~ 1e2)
    // and rounding ~ε/h² ≈ 1e-8, both well below the check's 1e-6.
    auto difference = [&](double h) {
      Eigen::Vector3d p0, pp, pm, w0, wp, wm;
      const Eigen::Matrix3d R0 = relative(0.0, p0, w0);
      relative(h, pp, wp);
      relative(-h, pm, wm);
      Vector6d out;
      out << R0 * (pp - 2.0 * p0 + pm) / (h * h), R0 * (wp - wm) / (2.0 * h);
      return out;
    };
    const Vector6d fd = (4.0 * difference(1e-4) - difference(2e-4)) / 3.0;
    const double e = (fd - c.b).cwiseAbs().maxCoeff() / (1.0 + c.b.cwiseAbs().maxCoeff());
    INFO("link " << c.link << " relative to " << c.relative_to);
    CHECK(e < 1e-6);
    worst = std::max(worst, e);
    ++accepted;
  }
  std::printf(
      "relative constraints: %d trees, finite-difference p̈_rel, ω̇_rel vs set points: max rel. error %.2e "
      "(truncation and rounding ~1e-8)\n",
      accepted, worst);
}

TEST_CASE("trees: friction matches the brute-force enumeration of stick/slip patterns (200+ trees)", "[trees]") {
  std::mt19937_64 rng(271828);
  int accepted = 0, attempts = 0, with_rows = 0, with_relative = 0, states[5] = {0, 0, 0, 0, 0};
  double e_qdd = 0.0, e_g = 0.0, e_closure = 0.0;
  std::string failure;
  while (accepted < 220) {
    REQUIRE(++attempts < 4000);
    const FrictionDraw d = randomTreeFrictionDraw(rng, 2, 8, 5, 4, 0.4);
    const DenseResult dense = denseDynamics(d.spec, d.input);
    if (!wellPosed(dense, d.input.constraintRows())) continue;
    const FrictionReference ref = bruteForceFriction(d.spec, d.input, d.setup);
    if (!ref.feasible || ref.qdd_spread > 1e-9) continue;  // the reference itself is ambiguous here
    const Model model = modelFromSpec(d.spec);
    const Task task = taskFromInput(model, d.input);
    Workspace ws(model, task);
    REQUIRE(solveWithFriction(model, ws, d.input.q, d.input.qd, d.input.tau, task));
    INFO("tree " << accepted << ": " << d.spec.dof() << " joints, " << d.input.constraintRows() << " rows, pattern "
                 << ref.pattern);
    const double eq = relativeError(ws.solution.qdd, ref.qdd);
    const double eg = std::abs(ws.friction.gauss_dual - ref.gauss_dual) / std::max(1.0, std::abs(ref.gauss_dual));
    CHECK(eq < 1e-8);
    CHECK(eg < 1e-8);
    failure =
        checkMaximumDissipation(ws.friction, ws.solution, expectFriction(model, d.input.q, d.input.qd, d.input.tau));
    CHECK(failure.empty());
    const double ec = frictionClosureError(model, task, d.input.q, d.input.qd, ws.friction, ws.solution);
    CHECK(ec < 1e-8);
    e_qdd = std::max(e_qdd, eq);
    e_g = std::max(e_g, eg);
    e_closure = std::max(e_closure, ec);
    for (JointState st : ws.friction.state) ++states[static_cast<int>(st)];
    with_rows += d.input.constraintRows() > 0 ? 1 : 0;
    for (const ConstraintInput& c : d.input.constraints)
      if (!c.relative_to.empty()) {
        ++with_relative;
        break;
      }
    ++accepted;
  }
  std::printf(
      "trees, friction vs brute force: %d trees (%d with constraints, %d relative): max rel. error qdd %.2e, "
      "g(mu*) %.2e, closure %.2e; states moving %d, stick %d, slip+ %d, slip- %d\n",
      accepted, with_rows, with_relative, e_qdd, e_g, e_closure, states[0], states[1], states[2], states[3]);
  CHECK(states[1] > 50);
  CHECK(states[2] + states[3] > 50);
  CHECK(with_relative > 30);
}

TEST_CASE("trees: bad relative constraints are refused with the reason", "[trees]") {
  std::mt19937_64 rng(3);
  const ChainSpec spec = randomTree(rng);
  const Model model = modelFromSpec(spec);
  Task task(model);
  const ConstraintMatrix A = ConstraintMatrix::Identity(6, 3);
  const std::string link = spec.links[1].name;
  auto message = [&](auto&& f) -> std::string {
    try {
      f();
    } catch (const ModelError& e) {
      return e.what();
    }
    return "(no ModelError)";
  };
  CHECK(message([&] { task.addRelativeConstraint(link, link, A); }) ==
        "task: a relative constraint on frame '" + link + "' needs another frame to refer to, not itself");
  const std::string unknown = "task: the model has no frame 'no_such_link' (frames: '" + model.frames()[0].name + "', ";
  CHECK(message([&] { task.addRelativeConstraint(link, "no_such_link", A); }).rfind(unknown, 0) == 0);
  CHECK(message([&] { task.addRelativeConstraint("no_such_link", link, A); }).rfind(unknown, 0) == 0);
  CHECK(message([&] { task.addRelativeConstraint(1, 99999, A); }) == "task: reference frame index 99999 out of range");
  CHECK(task.constraintRows() == 0);  // nothing half-added
  // And a good one works, relative to the base as well as to another link.
  CHECK(task.addRelativeConstraint(link, spec.links[0].name, A) == 0);
  CHECK(task.solverColumns() == 6);
}
