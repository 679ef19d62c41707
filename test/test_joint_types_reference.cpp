// Multi-DOF joints (issue #25) against the independent references, on random trees whose moving joints are
// revolute, continuous, prismatic, SPHERICAL (in the middle of the tree as well as at the leaves), planar and free
// (below the root), on a fixed, free or planar base:
//  * solveHybridDynamics against the dense KKT reference (support/floating_reference.*: world poses and Jacobian
//    columns per DOF, a spherical joint's columns the child's angular axes, J̇v in closed form; no recursive
//    algorithm): q̈, ν, τ_c, τ_control and Gauss's Z, with frame rows, relative rows and joint rows on
//    multi-DOF joints (one row per DOF);
//  * solveWithFriction against the brute-force enumeration of every stick/slip pattern
//    (support/friction_reference.*, bruteForceFloatingFriction): a box per DOF, each DOF of a multi-DOF joint its
//    own friction unknown with |μ_k| ≤ f of its joint.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <Eigen/SVD>

#include "support/floating_reference.hpp"
#include "support/friction_reference.hpp"
#include "support/joint_types_problem.hpp"
#include "support/random_chain.hpp"
#include "support/random_problem.hpp"
#include "zwang/zwang.hpp"

using namespace zwang;
using namespace zwang::testing;

namespace {

// True when some moving joint lies below links[link].
bool hasMovingDescendant(const ChainSpec& spec, int link) {
  for (std::size_t k = 0; k < spec.joints.size(); ++k) {
    if (spec.joints[k].isFixed()) continue;
    for (int l = spec.parentLink(k); l >= 0; l = l == 0 ? -1 : spec.parentLink(static_cast<std::size_t>(l) - 1))
      if (l == link) return true;
  }
  return false;
}

struct Census {
  int trees = 0, fixed = 0, free_base = 0, planar_base = 0, spherical = 0, spherical_inner = 0, planar = 0, free = 0,
      one_dof = 0;
  void count(const ChainSpec& spec, const FloatingBase& base) {
    ++trees;
    (base.kind == BaseKind::Fixed ? fixed : base.kind == BaseKind::Free ? free_base : planar_base) += 1;
    for (std::size_t k = 0; k < spec.joints.size(); ++k) {
      const JointSpec& joint = spec.joints[k];
      if (joint.isFixed()) continue;
      if (joint.isSpherical()) {
        ++spherical;
        spherical_inner += hasMovingDescendant(spec, static_cast<int>(k) + 1) ? 1 : 0;
      } else if (joint.isPlanar()) {
        ++planar;
      } else if (joint.isFree()) {
        ++free;
      } else {
        ++one_dof;
      }
    }
  }
};

// One joint row per DOF of a random moving joint (Task::addJointConstraint on a multi-DOF joint adds one per DOF):
// the reference's rows (a joint row per DOF index) and the joint's name, for the task.
struct JointRows {
  std::string joint;
  int first_dof = 0, dofs = 0;
  Eigen::VectorXd b;
};

JointRows randomJointRows(std::mt19937_64& rng, const ChainSpec& spec) {
  const std::vector<int> moving = spec.movingJoints();
  const int pick = uniformInt(rng, 0, static_cast<int>(moving.size()) - 1);
  JointRows rows;
  for (int j = 0; j < pick; ++j) rows.first_dof += spec.joints[static_cast<std::size_t>(moving[j])].nv();
  const JointSpec& joint = spec.joints[static_cast<std::size_t>(moving[static_cast<std::size_t>(pick)])];
  rows.joint = joint.name;
  rows.dofs = joint.nv();
  rows.b = randomVector(rng, rows.dofs, 2.0);
  return rows;
}

// The input's rows (frame and relative rows) as a Task, then the joint rows last, in both.
Task taskWithJointRows(const Model& model, FloatingInput& in, const std::vector<JointRows>& joint_rows) {
  Task task = floatingTaskFromInput(model, in);
  for (const JointRows& r : joint_rows) {
    const int first = task.addJointConstraint(r.joint);
    task.targets().segment(first, r.dofs) = r.b;
    for (int a = 0; a < r.dofs; ++a) {
      ConstraintInput c;
      c.joint = r.first_dof + a;
      c.A = Matrix6Xd::Zero(6, 1);
      c.b = Eigen::VectorXd::Constant(1, r.b(a));
      in.constraints.push_back(c);
    }
  }
  return task;
}

}  // namespace

TEST_CASE("joint types: solveHybridDynamics against the dense reference on trees with spherical joints",
          "[joint_types]") {
  std::mt19937_64 rng(stressSeedOr(2025112601ULL));
  Census census;
  int compared = 0, draws = 0, constrained = 0, rows = 0, joint_row_sets = 0, multi_dof_joint_rows = 0;
  double e_qdd = 0, e_nu = 0, e_tau_c = 0, e_tau_control = 0, e_gauss = 0;
  while (compared < 300) {
    REQUIRE(++draws < 3000);
    auto [spec, base, in, model] = drawLoadedTree(rng, 2, 16, 0.35, rowOptions(8, 0.3));
    std::vector<JointRows> joint_rows;
    if (uniform01(rng) < 0.3) joint_rows.push_back(randomJointRows(rng, spec));
    const Task task = taskWithJointRows(model, in, joint_rows);
    const FloatingResult dense = floatingDynamics(spec, base, in);
    if (!wellPosed(dense)) continue;
    Workspace ws(model, task);
    const Status s = solveHybridDynamics(model, ws, in.q, in.v, in.tau, task);
    INFO("draw " << draws << " (" << toString(base.kind) << " base, " << model.nv() << " DOFs): " << s.message);
    REQUIRE(s);
    ++compared;
    census.count(spec, base);
    const int m = task.constraintRows();
    constrained += m > 0 ? 1 : 0;
    rows += m;
    joint_row_sets += joint_rows.empty() ? 0 : 1;
    multi_dof_joint_rows += !joint_rows.empty() && joint_rows[0].dofs > 1 ? 1 : 0;
    e_qdd = std::max(e_qdd, relativeError(ws.solution.qdd, dense.qdd));
    e_nu = std::max(e_nu, relativeError(ws.solution.nu, dense.nu));
    e_tau_c = std::max(e_tau_c, relativeError(ws.solution.tau_constraint, dense.tau_c));
    e_tau_control = std::max(e_tau_control, relativeError(ws.solution.tau_control, dense.tau_control));
    e_gauss = std::max(e_gauss, std::abs(ws.solution.gauss - dense.gauss) / std::max(1.0, std::abs(dense.gauss)));
  }
  std::printf(
      "joint types vs the dense reference: %d compared (%d draws; %d fixed, %d free, %d planar bases), %d with rows "
      "(%d rows; %d with joint rows, %d of them on multi-DOF joints)\n  joints: %d spherical (%d with moving joints "
      "below), %d planar, %d free, %d one-DOF\n  max rel. error qdd %.2g, nu %.2g, tau_c %.2g, tau_control %.2g, "
      "Gauss %.2g\n",
      compared, draws, census.fixed, census.free_base, census.planar_base, constrained, rows, joint_row_sets,
      multi_dof_joint_rows, census.spherical, census.spherical_inner, census.planar, census.free, census.one_dof, e_qdd,
      e_nu, e_tau_c, e_tau_control, e_gauss);
  CHECK(census.spherical_inner > 100);  // spherical joints in the middle of the tree, not only at leaves
  CHECK(census.planar > 50);
  CHECK(census.free > 20);
  CHECK(constrained > 150);
  CHECK(multi_dof_joint_rows > 20);
  // Both sides solve the same KKT system exactly, kept draws conditioned below 1e6: round-off only.
  CHECK(e_qdd < 1e-9);
  CHECK(e_nu < 1e-9);
  CHECK(e_tau_c < 1e-9);
  CHECK(e_tau_control < 1e-9);
  CHECK(e_gauss < 1e-9);
}

TEST_CASE("joint types: friction (a box per DOF) matches the brute-force enumeration on trees with spherical joints",
          "[joint_types][friction]") {
  // The automatic choice (the active set for most of these small stuck sets) and the pattern search forced.
  const FrictionMethod method = GENERATE(FrictionMethod::Automatic, FrictionMethod::StickPatterns);
  INFO("method " << toString(method));
  std::mt19937_64 rng(stressSeedOr(2025112602ULL));
  Census census;
  int compared = 0, draws = 0, unique = 0, constrained = 0, spherical_stuck = 0, own_friction = 0;
  int states[3] = {0, 0, 0};
  double e_qdd = 0, e_g = 0, e_mu = 0, e_tau_control = 0, e_bound = 0, e_kinetic = 0;
  while (compared < 300) {
    REQUIRE(++draws < 4000);
    const ChainSpec spec = randomJointTypesTree(rng, 1, 4, 0.5);
    const int n = spec.dof();
    if (n > 10) continue;  // the enumeration is 3^stuck; the state draw below sticks at most 6
    const FloatingBase base = randomBase(rng);
    RandomProblemOptions options;
    options.max_constraint_rows = std::min(4, n);
    options.max_constraint_frames = 2;
    options.relative_probability = 0.2;
    FloatingInput in = loadedInput(rng, spec, base, options);
    const int base_velocity_size = base.baseVelocitySize();

    // Every DOF moving at 0.1–2, then 1..min(6, n) DOFs stuck exactly; a spherical joint often all three at once.
    FrictionSetup setup = sizedFrictionSetup(n);
    moveEveryDof(rng, base_velocity_size, n, in);
    std::vector<bool> stuck(static_cast<std::size_t>(n), false);
    const bool own = uniform01(rng) < 0.5;  // the model's friction (per joint, on each DOF), else overrides per DOF
    own_friction += own ? 1 : 0;
    int dof = 0, count = 0;
    for (const int j : spec.movingJoints()) {
      const JointSpec& joint = spec.joints[static_cast<std::size_t>(j)];
      const bool whole = joint.nv() > 1 && uniform01(rng) < 0.5;
      for (int a = 0; a < joint.nv(); ++a, ++dof) {
        if (own) {
          setup.breakaway(dof) = setup.kinetic(dof) = joint.friction;
          setup.viscous(dof) = joint.damping;
        } else {
          setup.breakaway(dof) = uniform(rng, 0.0, 20.0);
          setup.kinetic(dof) = uniform(rng, 0.0, setup.breakaway(dof));
          setup.viscous(dof) = uniform(rng, 0.0, 1.0);
        }
        if (count < 6 && (whole || uniform01(rng) < 0.3)) {
          stuck[static_cast<std::size_t>(dof)] = true;
          ++count;
        }
      }
    }
    if (count == 0) {
      stuck[static_cast<std::size_t>(uniformInt(rng, 0, n - 1))] = true;
      count = 1;
    }
    for (int k = 0; k < n; ++k)
      if (stuck[static_cast<std::size_t>(k)]) {
        setup.stuck.push_back(k);
        in.v(base_velocity_size + k) = 0.0;
      }

    const FloatingResult dense = floatingDynamics(spec, base, in);
    if (!wellPosed(dense)) continue;
    const FrictionReference ref = bruteForceFloatingFriction(spec, base, in, setup);
    REQUIRE(ref.feasible);                // no limits: some pattern is always valid
    if (ref.qdd_spread > 1e-9) continue;  // the reference itself cannot tell q̈* apart

    const Model model = floatingModelFromSpec(spec, base);
    REQUIRE(model.dof() == n);
    const Task task = floatingTaskFromInput(model, in);
    FrictionOptions fo;
    fo.method = method;
    fo.joint_limits = false;  // multi-DOF joints have none; the one-DOF ones are drawn inside theirs
    if (!own) {
      fo.breakaway = setup.breakaway;
      fo.kinetic = setup.kinetic;
      fo.viscous = setup.viscous;
    }
    Workspace ws(model, task);
    const Status s = solveWithFriction(model, ws, in.q, in.v, in.tau, task, fo);
    INFO("draw " << draws << " (" << toString(base.kind) << " base, " << n << " DOFs, " << count
                 << " stuck): reference pattern " << ref.pattern << " of " << ref.valid_patterns
                 << " valid; status: " << s.message);
    REQUIRE(s);
    ++compared;
    census.count(spec, base);
    constrained += task.constraintRows() > 0 ? 1 : 0;
    {
      int d = 0;
      for (const int j : spec.movingJoints()) {
        const JointSpec& joint = spec.joints[static_cast<std::size_t>(j)];
        for (int a = 0; a < joint.nv(); ++a, ++d)
          if (joint.isSpherical() && stuck[static_cast<std::size_t>(d)]) ++spherical_stuck;
      }
    }
    const FrictionResult& fr = ws.friction;
    REQUIRE(fr.stuck == setup.stuck);
    const double eq = relativeError(ws.solution.qdd, ref.qdd);
    const double eg = std::abs(fr.gauss_dual - ref.gauss_dual) / std::max(1.0, std::abs(ref.gauss_dual));
    CHECK(eq < 1e-8);  // both sides solve the same motion; rounding of condition ≤ 1e6 systems
    CHECK(eg < 1e-8);
    e_qdd = std::max(e_qdd, eq);
    e_g = std::max(e_g, eg);
    // Each stuck DOF within its own box.
    for (const int k : setup.stuck)
      e_bound = std::max(e_bound, std::max(0.0, std::abs(fr.mu(k)) - setup.breakaway(k)) / (1.0 + setup.breakaway(k)));
    // Each moving DOF's kinetic friction, −f_c,k sign(v_k) − b_k v_k: the same two products.
    for (int k = 0; k < n; ++k)
      if (!stuck[static_cast<std::size_t>(k)])
        e_kinetic = std::max(e_kinetic, std::abs(fr.tau_friction(k) - ref.tau_kinetic(k)) /
                                            std::max(1.0, std::abs(ref.tau_kinetic(k))));
    const bool mu_unique = ref.mu_spread <= 1e-9 * (1.0 + setup.breakaway.maxCoeff()) && !ref.pinned;
    if (!mu_unique) continue;
    ++unique;
    const double em = (fr.mu - ref.mu).cwiseAbs().maxCoeff() / (1.0 + setup.breakaway.maxCoeff());
    const double et = relativeError(ws.solution.tau_control, ref.tau_control);
    CHECK(em < 1e-8);
    CHECK(et < 1e-8);
    e_mu = std::max(e_mu, em);
    e_tau_control = std::max(e_tau_control, et);
    // The state of each stuck DOF where the reference's is clear of a boundary (as test_floating_friction): the
    // solver calls |q̈_k| ≤ 1e-9·(1 + max|q̈_Θ(0)|) sticking, the reference's q̈ is good to ~1e-12 of its scale and
    // μ* to ~1e-9 of f.
    const double acc_scale = 1.0 + ref.qdd.cwiseAbs().maxCoeff();
    for (const int k : setup.stuck) {
      const double qdd = ref.qdd(base_velocity_size + k), f = setup.breakaway(k);
      int expected = -1;  // 0 stick, 1 slip+, 2 slip−, −1 within rounding of a boundary: not judged
      if (qdd > 1e-6 * acc_scale)
        expected = 1;
      else if (qdd < -1e-6 * acc_scale)
        expected = 2;
      else if (std::abs(qdd) <= 1e-11 * acc_scale && std::abs(ref.mu(k)) < f - 1e-7 * (1.0 + f))
        expected = 0;
      if (expected < 0) continue;
      const JointState want = expected == 0   ? JointState::Stick
                              : expected == 1 ? JointState::SlipPositive
                                              : JointState::SlipNegative;
      INFO("DOF " << k << ": zwang " << toString(fr.state[static_cast<std::size_t>(k)]) << ", reference "
                  << toString(want));
      CHECK(fr.state[static_cast<std::size_t>(k)] == want);
      ++states[expected];
    }
  }
  std::printf(
      "joint types, friction vs brute force: %d compared (%d draws; %d fixed, %d free, %d planar bases; %d with the "
      "model's own friction, %d with rows)\n  joints: %d spherical (%d inner), %d planar, %d free, %d one-DOF; %d "
      "stuck spherical DOFs\n  max rel. error qdd %.2e, g(mu*) %.2e, kinetic friction %.2e, |mu| beyond its box %.2e\n  mu* unique in %d: mu "
      "%.2e, tau_control %.2e; states stick %d, slip+ %d, slip- %d\n",
      compared, draws, census.fixed, census.free_base, census.planar_base, own_friction, constrained, census.spherical,
      census.spherical_inner, census.planar, census.free, census.one_dof, spherical_stuck, e_qdd, e_g, e_kinetic,
      e_bound, unique, e_mu, e_tau_control, states[0], states[1], states[2]);
  CHECK(spherical_stuck > 200);
  CHECK(census.spherical_inner > 30);
  CHECK(unique > 150);
  CHECK(states[0] > 50);
  CHECK(states[1] + states[2] > 50);
  CHECK(e_kinetic < 1e-12);  // the same two products per DOF
  CHECK(e_bound < 1e-9);     // the maximiser projects onto the box: only round-off beyond it
}

// The unit-torque columns of a multi-DOF joint carry the constraint rows of its DOF bodies in block form; a joint row
// on one of its DOFs sits on that DOF's own body, so the joint's bodies see different rows. Stuck DOFs below and on
// such joints, against the brute force (q̈ and g(μ*), which are unique).
TEST_CASE("joint types: friction with joint rows on multi-DOF joints matches the brute-force enumeration",
          "[joint_types][friction]") {
  // The automatic choice (the active set for most of these small stuck sets) and the pattern search forced.
  const FrictionMethod method = GENERATE(FrictionMethod::Automatic, FrictionMethod::StickPatterns);
  INFO("method " << toString(method));
  std::mt19937_64 rng(stressSeedOr(2025112701ULL));
  int compared = 0, draws = 0, stuck_in_row_joint = 0;
  double e_qdd = 0, e_g = 0;
  while (compared < 150) {
    REQUIRE(++draws < 4000);
    const ChainSpec spec = randomJointTypesTree(rng, 1, 4, 0.6);
    const int n = spec.dof();
    if (n > 10) continue;  // the enumeration is 3^stuck
    const JointRows joint_rows = randomJointRows(rng, spec);
    if (joint_rows.dofs == 1) continue;
    const FloatingBase base = randomBase(rng);
    RandomProblemOptions options;
    options.max_constraint_rows = std::min(3, n);
    options.max_constraint_frames = 1;
    FloatingInput in = loadedInput(rng, spec, base, options);
    const int base_velocity_size = base.baseVelocitySize();
    FrictionSetup setup = sizedFrictionSetup(n);
    moveEveryDof(rng, base_velocity_size, n, in);
    for (int k = 0; k < n; ++k) {
      setup.breakaway(k) = uniform(rng, 0.0, 20.0);
      setup.kinetic(k) = uniform(rng, 0.0, setup.breakaway(k));
      setup.viscous(k) = uniform(rng, 0.0, 1.0);
      if (setup.stuck.size() < 6 && uniform01(rng) < 0.5) setup.stuck.push_back(k);
    }
    if (setup.stuck.empty()) setup.stuck.push_back(uniformInt(rng, 0, n - 1));
    for (const int k : setup.stuck) {
      in.v(base_velocity_size + k) = 0.0;
      stuck_in_row_joint += k >= joint_rows.first_dof && k < joint_rows.first_dof + joint_rows.dofs ? 1 : 0;
    }
    const Model model = floatingModelFromSpec(spec, base);
    const Task task = taskWithJointRows(model, in, {joint_rows});
    const FloatingResult dense = floatingDynamics(spec, base, in);
    if (!wellPosed(dense)) continue;
    const FrictionReference ref = bruteForceFloatingFriction(spec, base, in, setup);
    if (!ref.feasible || ref.qdd_spread > 1e-9) continue;  // a pinned DOF can leave every pattern or several valid
    FrictionOptions fo;
    fo.method = method;
    fo.joint_limits = false;
    fo.breakaway = setup.breakaway;
    fo.kinetic = setup.kinetic;
    fo.viscous = setup.viscous;
    Workspace ws(model, task);
    const Status s = solveWithFriction(model, ws, in.q, in.v, in.tau, task, fo);
    INFO("draw " << draws << " (" << toString(base.kind) << " base, " << n << " DOFs, joint rows on '"
                 << joint_rows.joint << "'): reference pattern " << ref.pattern << "; status: " << s.message);
    REQUIRE(s);
    ++compared;
    const double eq = relativeError(ws.solution.qdd, ref.qdd);
    const double eg = std::abs(ws.friction.gauss_dual - ref.gauss_dual) / std::max(1.0, std::abs(ref.gauss_dual));
    CHECK(eq < 1e-8);  // as the case above: the same motion, rounding of condition ≤ 1e6 systems
    CHECK(eg < 1e-8);
    e_qdd = std::max(e_qdd, eq);
    e_g = std::max(e_g, eg);
  }
  std::printf(
      "joint types, friction with joint rows on multi-DOF joints: %d compared (%d draws), %d stuck DOFs on the "
      "row's joint; max rel. error qdd %.2e, g(mu*) %.2e\n",
      compared, draws, stuck_in_row_joint, e_qdd, e_g);
  CHECK(stuck_in_row_joint > 30);
}

TEST_CASE(
    "joint types: forwardDynamics against the dense reference and inverseDynamics on trees with spherical "
    "joints",
    "[joint_types]") {
  std::mt19937_64 rng(stressSeedOr(2026112701ULL));
  Census census;
  int compared = 0, draws = 0, with_wrenches = 0;
  double e_qdd = 0, e_default = 0, e_round_trip = 0;
  while (compared < 200) {
    REQUIRE(++draws < 2000);
    auto [spec, base, in, model] = drawLoadedTree(rng, 2, 16, 0.35, rowOptions(0, 0.0));
    in.constraints.clear();
    const Task task = floatingTaskFromInput(model, in);
    REQUIRE(task.constraintRows() == 0);
    const FloatingResult dense = floatingDynamics(spec, base, in);
    if (!wellPosed(dense)) continue;
    Workspace ws(model, task);
    const Status s = forwardDynamics(model, ws, in.q, in.v, in.tau, task);
    INFO("draw " << draws << " (" << toString(base.kind) << " base, " << model.nv() << " DOFs): " << s.message);
    REQUIRE(s);
    ++compared;
    census.count(spec, base);
    with_wrenches += in.wrenches.empty() ? 0 : 1;
    e_qdd = std::max(e_qdd, relativeError(ws.solution.qdd, dense.qdd));
    // The accelerations held are this motion's, at this state.
    Vec6 acceleration;
    CHECK(frameAcceleration(model, ws, in.q, in.v, model.frameIndex(spec.links.back().name), Expressed::World,
                            acceleration));
    // RNEA at that q̈ gives τ back: forward and inverse dynamics are each other's inverse.
    const Eigen::VectorXd qdd = ws.solution.qdd;
    REQUIRE(inverseDynamics(model, ws, in.q, in.v, qdd, task));
    e_round_trip = std::max(e_round_trip, relativeError(ws.tau, in.tau));
    // Without a task: Task's default gravity and no wrenches.
    FloatingInput plain = in;
    plain.gravity = Eigen::Vector3d(0.0, 0.0, -9.81);
    plain.wrenches.clear();
    const FloatingResult dense_plain = floatingDynamics(spec, base, plain);
    REQUIRE(forwardDynamics(model, ws, in.q, in.v, in.tau));
    e_default = std::max(e_default, relativeError(ws.solution.qdd, dense_plain.qdd));
  }
  std::printf(
      "forwardDynamics vs the dense reference: %d compared (%d draws, %d with wrenches; %d spherical joints, %d "
      "planar, %d free)\n  max rel. error qdd %.2g, default task %.2g, inverseDynamics round trip %.2g\n",
      compared, draws, with_wrenches, census.spherical, census.planar, census.free, e_qdd, e_default, e_round_trip);
  CHECK(census.spherical_inner > 50);
  CHECK(with_wrenches > 50);
  // The same systems solved exactly by both, draws conditioned below 1e6: round-off only.
  CHECK(e_qdd < 1e-9);
  CHECK(e_default < 1e-9);
  CHECK(e_round_trip < 1e-9);
}

TEST_CASE("forwardDynamics refuses a task with constraint rows, naming solveHybridDynamics", "[joint_types]") {
  const ChainSpec spec = [] {
    std::mt19937_64 rng(7);
    return randomJointTypesTree(rng, 3, 6, 0.35);
  }();
  const Model model = floatingModelFromSpec(spec, FloatingBase{});
  Task task(model);
  task.addConstraint(static_cast<int>(model.frames().size()) - 1, ConstraintMatrix::Identity(6, 3));
  Workspace ws(model, task);
  Eigen::VectorXd q(model.nq());
  REQUIRE(neutralConfiguration(model, q));
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(model.nv());
  REQUIRE(solveHybridDynamics(model, ws, q, zero, zero, task));
  const Status s = forwardDynamics(model, ws, q, zero, zero, task);
  CHECK(s.code == StatusCode::BadOption);
  CHECK(std::string(s.message) ==
        "forwardDynamics: the task has 3 constraint rows; forwardDynamics is the unconstrained solve (gravity and "
        "wrenches only): use solveHybridDynamics to meet them");
  CHECK(ws.kinematics.stage == KinematicsStage::None);  // as any call that fails its input checks
}
