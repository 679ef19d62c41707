// Floating bases (issue #15) in the solver, against the dense floating-base
// reference (test/support/floating_reference.*, itself checked against
// MuJoCo's free joints in test_floating_reference): random free and planar
// trees with and without constraints; q̈ (the base's included), ν, τ_c and the
// base's classical acceleration; the closure H q̈ + C = τ + τ_c; physics
// (momentum, free fall); friction on a floating tree through the same sweeps.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdio>
#include <random>

#include "support/dense_reference.hpp"
#include "support/floating_reference.hpp"
#include "support/random_chain.hpp"
#include "support/random_problem.hpp"
#include "zwang/zwang.hpp"

using namespace zwang;
using namespace zwang::testing;

namespace {}  // namespace

TEST_CASE("floating trees: solveHybridDynamics against the dense floating-base reference", "[floating]") {
  std::mt19937_64 rng(20261124);
  RandomFloatingOptions options;
  options.max_constraint_rows = 12;
  options.max_constraint_frames = 4;
  options.relative_probability = 0.3;
  options.base_tau_probability = 0.2;
  int compared = 0, draws = 0, free = 0, planar = 0, constrained = 0, rows = 0, relative = 0;
  double e_qdd = 0, e_nu = 0, e_tau_c = 0, e_closure = 0, e_base_world = 0, e_gauss = 0;
  while (compared < 400 && draws < 3000) {
    ++draws;
    const FloatingProblem p = randomFloatingProblem(rng, options);
    const FloatingResult dense = floatingDynamics(p.spec, p.base, p.input);
    if (!wellPosed(dense)) continue;
    const Model model = floatingModelFromSpec(p.spec, p.base);
    const Task task = floatingTaskFromInput(model, p.input);
    Workspace ws(model, task);
    const Status s = solveHybridDynamics(model, ws, p.input.q, p.input.v, p.input.tau, task);
    INFO("draw " << draws << ": " << s.message);
    REQUIRE(s);
    ++compared;
    (p.base.kind == BaseKind::Free ? free : planar) += 1;
    const int m = task.constraintRows();
    if (m > 0) ++constrained;
    rows += m;
    for (const ConstraintInput& c : p.input.constraints)
      if (!c.relative_to.empty()) relative += static_cast<int>(c.A.cols());
    e_qdd = std::max(e_qdd, relativeError(ws.solution.qdd, dense.qdd));
    e_nu = std::max(e_nu, relativeError(ws.solution.nu, dense.nu.head(m)));
    e_tau_c = std::max(e_tau_c, relativeError(ws.solution.tau_constraint, dense.tau_c));
    e_base_world = std::max(e_base_world, relativeError(ws.solution.base_acceleration_world, dense.base_acc_world));
    // Closure: τ_control drives the unconstrained robot along q̈.
    const Eigen::VectorXd tau_id = floatingInverseDynamics(p.spec, p.base, p.input.q, p.input.v, ws.solution.qdd,
                                                           p.input.gravity, p.input.wrenches);
    e_closure = std::max(e_closure, relativeError(ws.solution.tau_control, tau_id));
    e_gauss = std::max(e_gauss, std::abs(ws.solution.gauss - dense.gauss) / std::max(1.0, std::abs(dense.gauss)));
  }
  std::printf(
      "floating trees vs the dense floating-base reference: %d compared (%d draws; %d free, %d planar), %d with "
      "rows (%d rows, %d relative)\n  max rel. error qdd %.2g, nu %.2g, tau_c %.2g, base classical acc %.2g, "
      "closure %.2g, Gauss %.2g\n",
      compared, draws, free, planar, constrained, rows, relative, e_qdd, e_nu, e_tau_c, e_base_world, e_closure,
      e_gauss);
  CHECK(compared >= 300);
  CHECK(free > 100);
  CHECK(planar > 100);
  CHECK(constrained > 100);
  CHECK(relative > 50);
  CHECK(e_qdd < 1e-9);
  CHECK(e_nu < 1e-9);
  CHECK(e_tau_c < 1e-9);
  CHECK(e_base_world < 1e-9);
  CHECK(e_closure < 1e-9);
  CHECK(e_gauss < 1e-9);
}

TEST_CASE("floating trees: physics without a reference model", "[floating]") {
  std::mt19937_64 rng(7);
  RandomFloatingOptions options;
  options.free_probability = 1.0;
  options.max_constraint_rows = 0;
  options.max_wrenches = 0;
  double e_momentum = 0.0, e_fall = 0.0;
  for (int draw = 0; draw < 100; ++draw) {
    FloatingProblem p = randomFloatingProblem(rng, options);
    p.input.tau.head(6).setZero();
    const Model model = floatingModelFromSpec(p.spec, p.base);
    Task task(model);
    Workspace ws(model, task);
    // No gravity, no wrench, no constraint, no torque: the spatial momentum
    // stays constant; its rate from our q̈, by a central difference of the
    // reference's momentum along the motion.
    task.gravity.setZero();
    Eigen::VectorXd tau = Eigen::VectorXd::Zero(model.nv());
    REQUIRE(solveHybridDynamics(model, ws, p.input.q, p.input.v, tau, task));
    const double h = 1e-6;
    const Eigen::VectorXd qdd = ws.solution.qdd;
    const auto momentumAt = [&](double t) {
      const Eigen::VectorXd q = integrateConfiguration(p.base, p.input.q, p.input.v + 0.5 * t * qdd, t);
      return floatingMomentum(p.spec, p.base, q, p.input.v + t * qdd);
    };
    const Vector6d rate = (momentumAt(h) - momentumAt(-h)) / (2 * h);
    const Vector6d h0 = floatingMomentum(p.spec, p.base, p.input.q, p.input.v);
    e_momentum = std::max(e_momentum, rate.norm() / std::max(1.0, h0.norm()));
    // At rest under gravity with no torque: every body falls at g.
    task.gravity = Vec3(0.3, -1.0, -9.81);
    const Eigen::VectorXd zero_v = Eigen::VectorXd::Zero(model.nv());
    REQUIRE(solveHybridDynamics(model, ws, p.input.q, zero_v, tau, task));
    for (int f = 0; f < static_cast<int>(model.frames().size()); ++f) {
      Vec6 a;
      REQUIRE(frameAcceleration(model, ws, p.input.q, zero_v, f, Expressed::World, a));
      e_fall = std::max(e_fall, (a.head<3>() - task.gravity).norm() / 9.81 + a.tail<3>().norm());
    }
  }
  std::printf(
      "floating physics: momentum rate (free, no gravity) %.2g (central differences, h = 1e-6), free fall "
      "at g: every frame %.2g\n",
      e_momentum, e_fall);
  CHECK(e_momentum < 1e-6);  // the differences' own error, O(h²)·|q⃛| and rounding/h
  CHECK(e_fall < 1e-12);
}

TEST_CASE("floating trees: friction through the same sweeps, checked by the dense reference", "[floating][friction]") {
  // The motion at μ* must be the dense floating-base motion under τ plus the
  // friction torques zwang reports, and μ* must satisfy maximum dissipation
  // joint by joint: stick ⇒ q̈_j = 0 and |μ_j| ≤ f_j; slip± ⇒ μ_j = ±f_j with
  // q̈_j of that sign.
  std::mt19937_64 rng(424242);
  RandomFloatingOptions options;
  options.max_constraint_rows = 6;
  options.relative_probability = 0.3;
  int compared = 0, draws = 0, stuck_total = 0, constrained = 0;
  int states[4] = {0, 0, 0, 0};
  double e_motion = 0.0, e_stick = 0.0, e_bound = 0.0, kkt = 0.0;
  while (compared < 200 && draws < 2000) {
    ++draws;
    FloatingProblem p = randomFloatingProblem(rng, options);
    if (p.spec.dof() == 0) continue;
    const int base_velocity_size = p.base.baseVelocitySize();
    // 1–5 joints stuck exactly; breakaway friction 0–20 on every joint.
    std::vector<int> order(static_cast<std::size_t>(p.spec.dof()));
    for (std::size_t j = 0; j < order.size(); ++j) order[j] = static_cast<int>(j);
    std::shuffle(order.begin(), order.end(), rng);
    const int k = std::min<int>(static_cast<int>(order.size()), 1 + static_cast<int>(rng() % 5));
    for (int a = 0; a < k; ++a) p.input.v[base_velocity_size + order[static_cast<std::size_t>(a)]] = 0.0;
    const FloatingResult check = floatingDynamics(p.spec, p.base, p.input);
    if (!wellPosed(check)) continue;
    const Model plain = floatingModelFromSpec(p.spec, p.base);
    FrictionOptions fo;
    fo.breakaway.resize(plain.dof());
    fo.kinetic.resize(plain.dof());
    fo.viscous.setZero(plain.dof());
    for (int j = 0; j < plain.dof(); ++j)
      fo.breakaway[j] = fo.kinetic[j] = 20.0 * std::uniform_real_distribution<>(0, 1)(rng);
    fo.joint_limits = false;
    const Task task = floatingTaskFromInput(plain, p.input);
    Workspace ws(plain, task);
    const Status s = solveWithFriction(plain, ws, p.input.q, p.input.v, p.input.tau, task, fo);
    INFO("draw " << draws << ": " << s.message);
    REQUIRE(s);
    ++compared;
    if (task.constraintRows() > 0) ++constrained;
    const FrictionResult& fr = ws.friction;
    stuck_total += static_cast<int>(fr.stuck.size());
    FloatingInput with_friction = p.input;
    with_friction.tau.tail(plain.dof()) += fr.tau_friction;
    const FloatingResult dense = floatingDynamics(p.spec, p.base, with_friction);
    e_motion = std::max(e_motion, relativeError(ws.solution.qdd, dense.qdd));
    const double acc_scale = 1.0 + ws.solution.qdd.cwiseAbs().maxCoeff();
    for (const int j : fr.stuck) {
      const double qdd = ws.solution.qdd[base_velocity_size + j], mu = fr.mu[j], f = fo.breakaway[j];
      const JointState st = fr.state[static_cast<std::size_t>(j)];
      states[st == JointState::Stick          ? 0
             : st == JointState::SlipPositive ? 1
             : st == JointState::SlipNegative ? 2
                                              : 3]++;
      if (st == JointState::Stick) e_stick = std::max(e_stick, std::abs(qdd) / acc_scale);
      e_bound = std::max(e_bound, std::max(0.0, std::abs(mu) - f) / (1.0 + f));
      if (st == JointState::SlipPositive) e_bound = std::max(e_bound, std::abs(mu - f) / (1.0 + f));
      if (st == JointState::SlipNegative) e_bound = std::max(e_bound, std::abs(mu + f) / (1.0 + f));
    }
    kkt = std::max(kkt, fr.kkt_residual / acc_scale);
  }
  std::printf(
      "floating trees with friction: %d compared (%d draws, %d with rows), %d stuck joints (stick %d, slip+ %d, "
      "slip- %d, other %d)\n  motion vs dense at mu* %.2g, stick |qdd| %.2g, |mu| beyond its bound %.2g, "
      "maximiser KKT %.2g\n",
      compared, draws, constrained, stuck_total, states[0], states[1], states[2], states[3], e_motion, e_stick, e_bound,
      kkt);
  CHECK(compared >= 150);
  CHECK(states[0] > 50);
  CHECK(states[1] + states[2] > 50);
  CHECK(e_motion < 1e-9);
  CHECK(e_stick < 1e-9);
  CHECK(e_bound < 1e-9);
  CHECK(kkt < 1e-9);
}

TEST_CASE("floating trees: standing on contacts, every joint held by its motor (joint rows)", "[floating]") {
  // Two links are feet (addContact, 6 world rows each: the ground's wrench);
  // every joint is held by a joint row q̈_j = 0 (addJointConstraint: its
  // motor). At rest the robot must stand still, τ_control must have nothing
  // on the base, and — the independent check — the motors' τ_control with
  // the contacts alone (the dense floating reference, no joint rows) must
  // hold it still with the same ground wrenches.
  std::mt19937_64 rng(99);
  RandomFloatingOptions options;
  options.free_probability = 1.0;
  options.max_constraint_rows = 0;
  options.max_wrenches = 0;
  int compared = 0, draws = 0;
  double e_still = 0.0, e_base = 0.0, e_ground = 0.0, e_nu = 0.0;
  while (compared < 100 && draws < 1000) {
    ++draws;
    FloatingProblem p = randomFloatingProblem(rng, options);
    if (p.spec.dof() < 4) continue;
    const Model model = floatingModelFromSpec(p.spec, p.base);
    // Feet: the last link and one other link off the base.
    const std::string foot_a = p.spec.links.back().name;
    const std::string foot_b = p.spec.links[1 + rng() % (p.spec.links.size() - 2)].name;
    FloatingInput contacts = p.input;
    contacts.v.setZero();
    contacts.tau.setZero();
    contacts.constraints.clear();
    for (const std::string& foot : {foot_a, foot_b}) {
      ConstraintInput c;
      c.link = foot;
      c.A = Matrix6Xd::Identity(6, 6);
      c.b = Eigen::VectorXd::Zero(6);
      c.axes = Axes::World;
      contacts.constraints.push_back(c);
    }
    const FloatingResult feet_only = floatingDynamics(p.spec, p.base, contacts);
    if (!feet_only.wellConditioned(1e6) || feet_only.constraint_rank < 12) continue;
    Task task(model);
    task.gravity = p.input.gravity;
    task.addContact(foot_a, ConstraintMatrix::Identity(6, 6), Expressed::World);
    task.addContact(foot_b, ConstraintMatrix::Identity(6, 6), Expressed::World);
    for (int j = 0; j < model.dof(); ++j) task.addJointConstraint(j);
    Workspace ws(model, task);
    const Status s = solveHybridDynamics(model, ws, contacts.q, contacts.v, contacts.tau, task);
    INFO("draw " << draws << ": " << s.message);
    REQUIRE(s);
    ++compared;
    e_still = std::max(e_still, ws.solution.qdd.cwiseAbs().maxCoeff());
    e_base = std::max(e_base, ws.solution.tau_control.head(6).cwiseAbs().maxCoeff() /
                                  std::max(1.0, ws.solution.tau_control.cwiseAbs().maxCoeff()));
    FloatingInput driven = contacts;
    driven.tau = ws.solution.tau_control;
    const FloatingResult check = floatingDynamics(p.spec, p.base, driven);
    e_ground = std::max(e_ground, check.qdd.cwiseAbs().maxCoeff());
    e_nu = std::max(e_nu, relativeError(ws.solution.nu.head(12), check.nu.head(12)));
  }
  std::printf(
      "floating trees standing on two feet (contacts) with every joint held by its motor: %d compared (%d "
      "draws)\n  |qdd| %.2g, base entries of tau_control %.2g, the motors' tau_control with the contacts alone "
      "(dense): |qdd| %.2g, ground wrenches %.2g\n",
      compared, draws, e_still, e_base, e_ground, e_nu);
  CHECK(compared >= 50);
  CHECK(e_still < 1e-9);
  CHECK(e_base < 1e-9);
  CHECK(e_ground < 1e-9);
  CHECK(e_nu < 1e-9);
}
