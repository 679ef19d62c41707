// Warm start (FrictionOptions::warm_start, issue #28): the last solve's stick/slip pattern tried first, one pass of
// the sweeps with the sticking DOFs locked. Against the brute-force enumeration of every stick/slip pattern on the
// dense reference (support/friction_reference: no recursive algorithm), on random trees of every joint type with up
// to 5 stuck DOFs, 0–3 task rows (relative ones and contacts among them) and prescribed DOFs: the first call (the
// full solve, which keeps its pattern), the same call again (the pattern holds: the warm path answers) and the next
// cycle of a control loop (τ moved a little) must each give the reference's q̈*, g(μ*) and, where μ* is unique, μ*
// and τ_control. Also: a pattern is not tried for another task or a changed stuck set, and ∂q̈/∂μ is zero after a
// warm answer.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "support/floating_reference.hpp"
#include "support/friction_reference.hpp"
#include "support/joint_types_problem.hpp"
#include "support/random_chain.hpp"
#include "support/random_problem.hpp"
#include "zwang/zwang.hpp"

using namespace zwang;
using namespace zwang::testing;

namespace {

struct Errors {
  double qdd = 0, g = 0, mu = 0, tau_control = 0;
};

// One solve against the reference: q̈* and g(μ*) always, μ* and τ_control where μ* is unique. True when compared
// with μ* unique.
bool compareWithReference(const Workspace& ws, const FrictionReference& ref, const FrictionSetup& setup, Errors& e) {
  const FrictionResult& fr = ws.friction;
  const double eq = relativeError(ws.solution.qdd, ref.qdd);
  const double eg = std::abs(fr.gauss_dual - ref.gauss_dual) / std::max(1.0, std::abs(ref.gauss_dual));
  CHECK(eq < 1e-8);  // both sides solve the same motion; rounding of condition ≤ 1e6 systems
  CHECK(eg < 1e-8);
  e.qdd = std::max(e.qdd, eq);
  e.g = std::max(e.g, eg);
  const bool mu_unique = ref.mu_spread <= 1e-9 * (1.0 + setup.breakaway.maxCoeff()) && !ref.pinned;
  if (!mu_unique) return false;
  const double em = (fr.mu - ref.mu).cwiseAbs().maxCoeff() / (1.0 + setup.breakaway.maxCoeff());
  const double et = relativeError(ws.solution.tau_control, ref.tau_control);
  CHECK(em < 1e-8);
  CHECK(et < 1e-8);
  e.mu = std::max(e.mu, em);
  e.tau_control = std::max(e.tau_control, et);
  return true;
}

}  // namespace

TEST_CASE("warm start: the last pattern gives the brute-force answer, in a loop of nearby states",
          "[warm_start][friction]") {
  std::mt19937_64 rng(stressSeedOr(2026112810ULL));
  int compared = 0, draws = 0, warm_same = 0, warm_next = 0, unique = 0, prescribed_draws = 0;
  Errors first, same, next;
  while (compared < 250) {
    REQUIRE(++draws < 5000);
    const ChainSpec spec = randomJointTypesTree(rng, 2, 5, 0.4);
    const int n = spec.dof();
    if (n > 11) continue;  // the enumeration is 3^stuck
    const FloatingBase base = randomBase(rng);
    RandomProblemOptions options = rowOptions(std::min(3, n), 0.2);
    options.max_constraint_frames = 2;
    FloatingInput in = loadedInput(rng, spec, base, options);
    makeContact(rng, base, in);
    const int base_velocity_size = base.baseVelocitySize();
    const Model model = floatingModelFromSpec(spec, base);
    Task task = floatingTaskFromInput(model, in);
    FrictionSetup setup = sizedFrictionSetup(n);
    moveEveryDof(rng, base_velocity_size, n, in);
    for (int k = 0; k < n; ++k) {
      setup.breakaway(k) = uniform(rng, 0.0, 15.0);
      setup.kinetic(k) = uniform(rng, 0.0, setup.breakaway(k));
      setup.viscous(k) = uniform(rng, 0.0, 1.0);
      if (static_cast<int>(setup.stuck.size()) < 5 && uniform01(rng) < 0.5) {
        in.v(base_velocity_size + k) = 0.0;
        setup.stuck.push_back(k);
      }
    }
    if (setup.stuck.empty()) continue;
    // The first moving DOF prescribed in a third of the draws (a row q̈ = y in the reference; no friction unknown).
    bool has_prescribed = false;
    if (model.mimicJoints().empty() && uniform01(rng) < 0.3)
      for (int k = 0; k < n && !has_prescribed; ++k)
        if (in.v(base_velocity_size + k) != 0.0) {
          const double y = uniform(rng, -2.0, 2.0);
          task.setDofMode(base_velocity_size + k, DofMode::Prescribed);
          task.prescribedAccelerations()[base_velocity_size + k] = y;
          ConstraintInput c;
          c.joint = k;
          c.A = Matrix6Xd::Zero(6, 1);
          c.b = Eigen::VectorXd::Constant(1, y);
          in.constraints.push_back(c);
          has_prescribed = true;
        }
    FrictionOptions fo;
    fo.joint_limits = false;  // multi-DOF joints have none; the one-DOF ones are drawn inside theirs
    fo.breakaway = setup.breakaway;
    fo.kinetic = setup.kinetic;
    fo.viscous = setup.viscous;
    fo.warm_start = true;

    const FloatingResult dense = floatingDynamics(spec, base, in);
    if (!wellPosed(dense)) continue;
    const FrictionReference ref = bruteForceFloatingFriction(spec, base, in, setup);
    if (!ref.feasible || ref.qdd_spread > 1e-9) continue;  // the reference itself cannot tell q̈* apart
    // The next cycle: τ moved by up to 1 % of the friction box on each DOF (the pattern mostly stays).
    FloatingInput moved = in;
    for (int k = 0; k < n; ++k)
      moved.tau(base_velocity_size + k) += 0.01 * uniform(rng, -1.0, 1.0) * setup.breakaway(k);
    const FloatingResult dense_moved = floatingDynamics(spec, base, moved);
    if (!wellPosed(dense_moved)) continue;
    const FrictionReference ref_moved = bruteForceFloatingFriction(spec, base, moved, setup);
    if (!ref_moved.feasible || ref_moved.qdd_spread > 1e-9) continue;

    Workspace ws(model, task);
    INFO("draw " << draws << " (" << toString(base.kind) << " base, " << n << " DOFs, " << setup.stuck.size()
                 << " stuck, " << task.constraintRows() << " rows)");
    REQUIRE(solveWithFriction(model, ws, in.q, in.v, in.tau, task, fo));
    CHECK_FALSE(ws.friction.warm_started);  // nothing kept yet: the full solve
    ++compared;
    prescribed_draws += has_prescribed ? 1 : 0;
    unique += compareWithReference(ws, ref, setup, first) ? 1 : 0;
    REQUIRE(solveWithFriction(model, ws, in.q, in.v, in.tau, task, fo));
    if (ws.friction.warm_started) {
      ++warm_same;
      CHECK(ws.friction.dqdd_dmu.isZero(0.0));  // not computed: zeroed
    }
    compareWithReference(ws, ref, setup, same);
    REQUIRE(solveWithFriction(model, ws, moved.q, moved.v, moved.tau, task, fo));
    warm_next += ws.friction.warm_started ? 1 : 0;
    compareWithReference(ws, ref_moved, setup, next);
  }
  std::printf(
      "warm start vs brute force: %d problems (%d draws, %d with a prescribed DOF), mu* unique in %d\n"
      "  the same call again answered warm in %d, the next cycle (tau moved) in %d\n"
      "  max rel. error qdd %.2e / %.2e / %.2e, g %.2e / %.2e / %.2e, mu %.2e / %.2e / %.2e, tau_control %.2e / "
      "%.2e / %.2e (first / again / next)\n",
      compared, draws, prescribed_draws, unique, warm_same, warm_next, first.qdd, same.qdd, next.qdd, first.g, same.g,
      next.g, first.mu, same.mu, next.mu, first.tau_control, same.tau_control, next.tau_control);
  CHECK(warm_same > compared / 2);  // the determinate ones: most of the draws
  CHECK(warm_next > compared / 3);
  CHECK(prescribed_draws > 20);
}

TEST_CASE("warm start: from the kept pattern of the same task, across a change of the stuck set; not another task's",
          "[warm_start][friction]") {
  const Model model = loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/panda.urdf");
  const Task task(model), other(model);
  Workspace ws(model, task), reference(model, task);
  const Eigen::VectorXd q = Eigen::VectorXd::Constant(model.nq(), 0.3), rest = Eigen::VectorXd::Zero(model.nv());
  const Eigen::VectorXd tau = Eigen::VectorXd::Constant(model.nv(), 0.5);
  FrictionOptions fo;
  fo.breakaway = Eigen::VectorXd::Constant(model.dof(), 100.0);  // every joint holds
  fo.warm_start = true;
  REQUIRE(solveWithFriction(model, ws, q, rest, tau, task, fo));
  CHECK_FALSE(ws.friction.warm_started);  // nothing kept yet, and 7 stuck DOFs are too few to search from sticking
  CHECK(ws.friction.method == FrictionMethod::ActiveSet);
  CHECK_FALSE(ws.friction.dqdd_dmu.isZero(0.0));  // the K-based solve computes it
  REQUIRE(solveWithFriction(model, ws, q, rest, tau, task, fo));
  CHECK(ws.friction.warm_started);
  CHECK(ws.friction.method == FrictionMethod::StickPatterns);
  CHECK(ws.friction.iterations == 1);  // the kept pattern holds: one pass
  CHECK(ws.solution.qdd.isZero(0.0));  // every joint locked: exactly at rest
  CHECK(ws.friction.dqdd_dmu.isZero(0.0));
  REQUIRE(solveWithFriction(model, ws, q, rest, tau, other, fo));
  CHECK_FALSE(ws.friction.warm_started);  // another task object
  // Another stuck set, the same task: the kept pattern mapped onto it (joint 3 moving, the others sticking).
  Eigen::VectorXd one_moving = rest;
  one_moving[3] = 0.5;
  REQUIRE(solveWithFriction(model, ws, q, one_moving, tau, other, fo));
  CHECK(ws.friction.warm_started);
  FrictionOptions active_set = fo;
  active_set.method = FrictionMethod::ActiveSet;
  active_set.warm_start = false;
  REQUIRE(solveWithFriction(model, reference, q, one_moving, tau, other, active_set));
  CHECK(reference.friction.method == FrictionMethod::ActiveSet);
  CHECK_FALSE(reference.friction.dqdd_dmu.isZero(0.0));                   // the K-based solve computes it
  CHECK(relativeError(ws.solution.qdd, reference.solution.qdd) < 1e-12);  // rounding of one solve
  CHECK((ws.friction.mu - reference.friction.mu).cwiseAbs().maxCoeff() < 1e-10);
  fo.warm_start = false;
  REQUIRE(solveWithFriction(model, ws, q, one_moving, tau, other, fo));
  CHECK_FALSE(ws.friction.warm_started);
}

TEST_CASE("warm start: when μ* is not unique the full solve chooses, every time", "[warm_start][friction]") {
  // The Panda holding its flange still (6 rows) with every joint stuck: 13 conditions on 7 joints, so friction and
  // the task's forces trade (statically indeterminate); the least-effort choice is the full solve's.
  const Model model = loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/panda.urdf");
  Task task(model);
  task.addConstraint("panda_link8", ConstraintMatrix::Identity(6, 6), Expressed::World);
  Workspace warm(model, task), cold(model, task);
  const Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(model.nq(), -0.4, 0.6), rest = Eigen::VectorXd::Zero(model.nv());
  const Eigen::VectorXd tau = Eigen::VectorXd::LinSpaced(model.nv(), -3.0, 4.0);
  FrictionOptions fo;
  fo.breakaway = Eigen::VectorXd::Constant(model.dof(), 2.0);
  REQUIRE(solveWithFriction(model, cold, q, rest, tau, task, fo));
  REQUIRE(cold.friction.indeterminate);
  fo.warm_start = true;
  for (int call = 0; call < 3; ++call) {
    REQUIRE(solveWithFriction(model, warm, q, rest, tau, task, fo));
    CHECK_FALSE(warm.friction.warm_started);
    CHECK(warm.solution.qdd == cold.solution.qdd);  // the same path, the same arithmetic
    CHECK(warm.friction.mu == cold.friction.mu);
    CHECK(warm.solution.tau_control == cold.solution.tau_control);
  }
}

// The humanoid standing on both feet (contacts only) with every joint stuck: locked, the robot is one rigid body on
// 12 contact rows, so the ground's split between the feet and with it μ is free along 6 directions. The pattern
// search takes the smallest μ there (docs/friction.md, "The pattern search"); it must be the full solve's choice,
// cold and warm, with the same report. The full solve's choice is checked against brute force on small floating
// trees (test_floating_friction, "smallest mu where every row is a contact"); 29 stuck joints are beyond brute force.
TEST_CASE("feet on the ground with every joint stuck: the pattern search's smallest μ is the full solve's",
          "[warm_start][friction][floating]") {
  UrdfOptions options;
  options.base = BaseType::Free;
  const Model model = loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/simple_humanoid.urdf", options);
  REQUIRE(model.dof() == 29);
  Task task(model);
  for (const char* foot : {"l_ankle", "r_ankle"})
    task.addContact(foot, ConstraintMatrix::Identity(6, 6), Expressed::World);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(model.nq());
  q[3] = 1.0;  // upright; knees bent as the bench's humanoid (hip pitch + knee + ankle pitch = 0: soles level)
  for (const char* side : {"RLEG_", "LLEG_"})
    for (const auto& [joint, value] : {std::pair{"HIP_P", -0.3}, std::pair{"KNEE", 0.25}, std::pair{"ANKLE_P", 0.05}})
      q[7 + model.jointIndex(std::string(side) + joint)] = value;
  const Eigen::VectorXd rest = Eigen::VectorXd::Zero(model.nv());
  Workspace cold(model, task), full(model, task), warm(model, task);
  std::mt19937_64 rng(2811);
  int searched = 0, indeterminate = 0, slipping = 0, all_sticking = 0;
  double e_qdd = 0.0, e_mu = 0.0, e_nu = 0.0, e_tau = 0.0;
  Eigen::VectorXd tau = Eigen::VectorXd::Zero(model.nv());
  for (int draw = 0; draw < 60; ++draw) {
    INFO("draw " << draw);
    FrictionOptions fo;  // mostly friction that holds every joint (gravity asks up to some 300 N·m); every fourth
    // draw weak enough for some joints to slip
    fo.breakaway = randomVector(rng, model.dof(), 1.0).cwiseAbs() * (draw % 4 == 3 ? 20.0 : 300.0);
    fo.breakaway.array() += draw % 4 == 3 ? 2.0 : 300.0;
    if (draw % 10 == 0) tau.tail(model.dof()) = randomVector(rng, model.dof(), 10.0);
    tau.tail(model.dof()) += randomVector(rng, model.dof(), 0.5);  // the next cycle: τ moved a little
    FrictionOptions reference = fo;
    reference.method = FrictionMethod::ActiveSet;
    REQUIRE(solveWithFriction(model, full, q, rest, tau, task, reference));
    REQUIRE(solveWithFriction(model, cold, q, rest, tau, task, fo));
    fo.warm_start = true;
    REQUIRE(solveWithFriction(model, warm, q, rest, tau, task, fo));
    searched += cold.friction.method == FrictionMethod::StickPatterns ? 1 : 0;
    searched += warm.friction.method == FrictionMethod::StickPatterns ? 1 : 0;
    indeterminate += full.friction.indeterminate ? 1 : 0;
    const auto slips = std::count_if(full.friction.state.begin(), full.friction.state.end(), [](JointState s) {
      return s == JointState::SlipPositive || s == JointState::SlipNegative;
    });
    slipping += slips > 0 ? 1 : 0;
    all_sticking += slips == 0 ? 1 : 0;
    for (const Workspace* ws : {&cold, &warm}) {
      INFO((ws == &cold ? "cold" : "warm") << ", answered by " << toString(ws->friction.method));
      const double eq = (ws->solution.qdd - full.solution.qdd).cwiseAbs().maxCoeff() /
                        (1.0 + full.solution.qdd.cwiseAbs().maxCoeff());
      const double em = relativeError(ws->friction.mu, full.friction.mu);
      const double en = relativeError(ws->solution.nu, full.solution.nu);
      const double et = relativeError(ws->solution.tau_control, full.solution.tau_control);
      CHECK(eq < 1e-9);  // the sweeps' rounding of the same motion
      CHECK(em < 1e-7);  // two least-norm problems on quantities good to ~1e-12, as test_floating_friction's
      CHECK(en < 1e-7);
      CHECK(et < 1e-7);
      CHECK(ws->friction.indeterminate == full.friction.indeterminate);
      CHECK(ws->friction.state == full.friction.state);
      CHECK(ws->solution.balance.rank == full.solution.balance.rank);
      CHECK(ws->solution.balance.nu_unique == full.solution.balance.nu_unique);
      CHECK(ws->solution.balance.singular == full.solution.balance.singular);
      CHECK(ws->solution.balance.consistent == full.solution.balance.consistent);
      e_qdd = std::max(e_qdd, eq);
      e_mu = std::max(e_mu, em);
      e_nu = std::max(e_nu, en);
      e_tau = std::max(e_tau, et);
    }
  }
  std::printf(
      "humanoid on both feet, every joint stuck: 60 draws (%d indeterminate, %d with a slipping joint, %d with none), %d "
      "of 120 "
      "cold and warm solves answered by the pattern search; against the active set: qdd %.2e, mu %.2e, nu %.2e, "
      "tau_control %.2e\n",
      indeterminate, slipping, all_sticking, searched, e_qdd, e_mu, e_nu, e_tau);
  CHECK(indeterminate > 30);
  CHECK(slipping > 5);
  CHECK(all_sticking > 30);
  CHECK(searched > 60);
}

namespace {

// What the trajectories below went through, and how far the warm answers were from the cold ones.
struct TrajectoryTally {
  int steps = 0, solved = 0, infeasible = 0, indeterminate = 0, with_stuck = 0, warm = 0, by_patterns = 0;
  int stuck_set_changes = 0, pattern_changes = 0, limit_stops = 0, stale = 0;
  double qdd = 0, mu = 0, tau_control = 0;
};

// The next state of a crude 1 kHz-like loop (semi-implicit Euler): a DOF whose velocity crosses zero stops there
// (it is stuck at the next solve), a one-DOF joint that passes a limit stops on it.
void stepState(const Model& model, const Eigen::VectorXd& qdd, double h, Eigen::VectorXd& q, Eigen::VectorXd& v,
               TrajectoryTally& t) {
  const Eigen::VectorXd v_before = v;
  v += h * qdd;
  for (int k = model.baseVelocitySize(); k < model.nv(); ++k)
    if (v_before[k] * v[k] < 0.0) v[k] = 0.0;
  REQUIRE(integrate(model, q, v, h, q));
  for (int k = model.baseVelocitySize(); k < model.nv(); ++k) {
    const Dof& dof = model.dofs()[static_cast<std::size_t>(k)];
    const int at = model.joint(dof.joint).q_index;
    if (model.joint(dof.joint).nv() != 1 || !(q[at] < dof.lower || q[at] > dof.upper)) continue;
    q[at] = std::clamp(q[at], dof.lower, dof.upper);
    v[k] = 0.0;
    ++t.limit_stops;
  }
}

}  // namespace

TEST_CASE(
    "warm start along trajectories: the cold solve's answer at every step, through pattern changes, limit "
    "stops and a stale workspace",
    "[warm_start][friction]") {
  std::mt19937_64 rng(stressSeedOr(2026112811ULL));
  TrajectoryTally t;
  constexpr int kTrajectories = 40, kSteps = 150;
  constexpr double h = 2e-3;  // s: 0.3 s per trajectory, long enough for joints to break away and stop again
  for (int trajectory = 0; trajectory < kTrajectories; ++trajectory) {
    auto [spec, base, in, model] = drawLoadedTree(rng, 3, 8, 0.3, rowOptions(2, 0.2));
    const Task task = floatingTaskFromInput(model, in), other(model);
    const int n = model.dof(), base_velocity_size = model.baseVelocitySize();
    FrictionOptions warm_options;
    warm_options.breakaway.resize(n);
    for (int k = 0; k < n; ++k) warm_options.breakaway[k] = uniform(rng, 0.0, 8.0);
    warm_options.kinetic = 0.6 * warm_options.breakaway;
    warm_options.viscous = Eigen::VectorXd::Constant(n, 0.1);
    warm_options.warm_start = true;
    FrictionOptions cold_options = warm_options;
    cold_options.warm_start = false;
    cold_options.method = FrictionMethod::ActiveSet;
    // τ swings by 1.5 boxes about the drawn load at 2–6 Hz: the joints stick, break away and stop again.
    const Eigen::VectorXd tau0 = in.tau;
    Eigen::VectorXd amplitude = Eigen::VectorXd::Zero(model.nv()), omega = amplitude, phase = amplitude;
    for (int k = 0; k < n; ++k) {
      amplitude[base_velocity_size + k] = 1.5 * warm_options.breakaway[k] + 0.5;
      omega[base_velocity_size + k] = 2.0 * M_PI * uniform(rng, 2.0, 6.0);
      phase[base_velocity_size + k] = uniform(rng, 0.0, 2.0 * M_PI);
    }
    Eigen::VectorXd q = in.q, v = in.v, tau = tau0;
    v.tail(n).setZero();  // at rest: every joint DOF stuck
    Workspace warm(model, task), cold(model, task);
    std::vector<JointState> last_state;
    std::vector<int> last_stuck;
    for (int step = 0; step < kSteps; ++step) {
      const double time = step * h;
      tau = tau0 + amplitude.cwiseProduct((omega * time + phase).array().sin().matrix());
      if (step % 50 == 25) {  // the workspace is used for another task in between: its pattern is not this task's
        const Status so = solveWithFriction(model, warm, q, v, tau, other, warm_options);
        CHECK((so.ok() || so.code == StatusCode::Infeasible));
        ++t.stale;
      }
      INFO("trajectory " << trajectory << " (" << toString(base.kind) << " base, " << n << " DOFs, "
                         << task.constraintRows() << " rows), step " << step);
      const Status sw = solveWithFriction(model, warm, q, v, tau, task, warm_options);
      const Status sc = solveWithFriction(model, cold, q, v, tau, task, cold_options);
      INFO("warm: " << sw.message << "; cold: " << sc.message);
      ++t.steps;
      REQUIRE(sw.code == sc.code);
      if (!sc) {
        t.infeasible += sc.code == StatusCode::Infeasible ? 1 : 0;
        break;  // a stop the task pushes into: this trajectory ends
      }
      ++t.solved;
      const FrictionResult& fw = warm.friction;
      const FrictionResult& fc = cold.friction;
      t.with_stuck += fw.stuck.empty() ? 0 : 1;
      t.warm += fw.warm_started ? 1 : 0;
      t.by_patterns += fw.method == FrictionMethod::StickPatterns ? 1 : 0;
      const double eq = relativeError(warm.solution.qdd, cold.solution.qdd);
      CHECK(eq < 1e-9);  // rounding of two solves of the same problem, condition ≤ 1e6
      t.qdd = std::max(t.qdd, eq);
      if (fc.indeterminate) {
        ++t.indeterminate;
      } else {
        const double em = (fw.mu - fc.mu).cwiseAbs().maxCoeff() / (1.0 + warm_options.breakaway.maxCoeff());
        const double et = relativeError(warm.solution.tau_control, cold.solution.tau_control);
        CHECK(em < 1e-9);
        CHECK(et < 1e-9);
        t.mu = std::max(t.mu, em);
        t.tau_control = std::max(t.tau_control, et);
      }
      if (step > 0) {
        t.stuck_set_changes += fw.stuck != last_stuck ? 1 : 0;
        t.pattern_changes += fw.stuck == last_stuck && fw.state != last_state ? 1 : 0;
      }
      last_stuck = fw.stuck;
      last_state = fw.state;
      stepState(model, warm.solution.qdd, h, q, v, t);
    }
  }
  std::printf(
      "warm start along %d trajectories: %d steps (%d solved, %d Infeasible ends, %d indeterminate, %d with a stuck "
      "DOF), answered by the pattern search %d, of them warm %d; stuck set changed %d times, the pattern on the same "
      "set %d times, %d limit stops, %d stale workspaces\n"
      "  max difference to the cold active set: qdd %.2e, mu %.2e, tau_control %.2e\n",
      kTrajectories, t.steps, t.solved, t.infeasible, t.indeterminate, t.with_stuck, t.by_patterns, t.warm,
      t.stuck_set_changes, t.pattern_changes, t.limit_stops, t.stale, t.qdd, t.mu, t.tau_control);
  CHECK(t.warm > t.with_stuck * 3 / 4);  // a control loop is mostly answered from the last pattern
  CHECK(t.stuck_set_changes > 50);
  CHECK(t.pattern_changes > 20);
  CHECK(t.limit_stops > 5);
}
