// Once the workspace exists, the hot-path calls make no heap allocation: the
// replaced malloc (counting_malloc.cpp) counts every allocation of the calls,
// on the Panda, trees, and floating bases (the humanoid, solo12, random trees).
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <string>
#include <type_traits>
#include <utility>

#include "counting_malloc.hpp"
#include "support/bad_inputs.hpp"
#include "support/random_chain.hpp"
#include "support/random_problem.hpp"
#include "support/simulation_models.hpp"
#include "zwang/zwang.hpp"

using namespace zwang;
using zwang::testing::allocationsDuring;

namespace {
Model panda() { return zwang::testing::pandaModel(); }
}  // namespace

TEST_CASE("the counter sees allocations at all (guards against a test that cannot fail)") {
  CHECK(allocationsDuring([] {
          Eigen::VectorXd x(100);
          x.setOnes();
        }) >= 1);
  // (operator new directly: a new-expression paired with delete may be elided.)
  CHECK(allocationsDuring([] {
          void* volatile p = ::operator new(16);
          ::operator delete(p);
        }) >= 1);
}

TEST_CASE("hybrid dynamics with constraints on two frames and a wrench allocates nothing") {
  const Model model = panda();
  Task task(model);
  task.addConstraint("tool0", ConstraintMatrix::Identity(6, 6), Expressed::World);
  ConstraintMatrix elbow = ConstraintMatrix::Zero(6, 1);
  elbow(2, 0) = 1.0;
  task.addConstraint("panda_link4", elbow, Expressed::World);
  const int w = task.addWrench("panda_link6", Expressed::World);
  task.wrench(w) << 1, 2, 3, 0.1, 0.2, 0.3;
  Workspace ws(model, task);
  const Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(7, -0.5, 0.7), qd = Eigen::VectorXd::Constant(7, 0.3),
                        tau = Eigen::VectorXd::Constant(7, 1.0);
  REQUIRE(solveHybridDynamics(model, ws, q, qd, tau, task));  // warm
  // No Catch2 assertion inside a counted region: the framework may allocate.
  bool all_ok = true;
  long count = allocationsDuring([&] {
    for (int k = 0; k < 10; ++k) {
      task.targets()[0] = 0.1 * k;
      task.wrench(w)[0] = k;
      all_ok = solveHybridDynamics(model, ws, q, qd, tau, task).ok() && all_ok;
    }
  });
  CHECK(all_ok);
  CHECK(count == 0);

  // An error status is reported without allocating, too.
  const Eigen::VectorXd short_q = Eigen::VectorXd::Zero(3);
  Status status;
  count = allocationsDuring([&] { status = solveHybridDynamics(model, ws, short_q, qd, tau, task); });
  CHECK_FALSE(status.ok());
  CHECK(count == 0);
}

TEST_CASE("a singular task (damped balance) allocates nothing") {
  const Model model = panda();
  Task task(model);
  task.addConstraint("tool0", ConstraintMatrix::Identity(6, 6), Expressed::Local);
  task.addConstraint("panda_link7", ConstraintMatrix::Identity(6, 6), Expressed::Local);
  Workspace ws(model, task);
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(7), qd = Eigen::VectorXd::Zero(7), tau = Eigen::VectorXd::Zero(7);
  REQUIRE(solveHybridDynamics(model, ws, q, qd, tau, task));
  CHECK(ws.solution.balance.singular);
  bool ok = false;
  CHECK(allocationsDuring([&] { ok = solveHybridDynamics(model, ws, q, qd, tau, task).ok(); }) == 0);
  CHECK(ok);
}

TEST_CASE("RNEA, CRBA, kinematics and Jacobians allocate nothing") {
  const Model model = panda();
  Task task(model);
  Workspace ws(model, task);
  const Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(7, -0.5, 0.7), qd = Eigen::VectorXd::Constant(7, 0.3);
  Eigen::MatrixXd J(6, 7);
  const int tool = model.frameIndex("tool0");
  Eigen::Isometry3d pose;
  Vec6 v_local, v_world;
  bool ok = false;
  double sink = 0.0;
  StatusCode stale = StatusCode::Ok;
  const long count = allocationsDuring([&] {
    ok = inverseDynamics(model, ws, q, qd, qd, task).ok();
    ok = jointSpaceInertia(model, ws, q).ok() && ok;
    ok = forwardKinematics(model, ws, q, qd).ok() && ok;
    ok = framePose(model, ws, q, tool, pose).ok() && ok;
    ok = frameVelocity(model, ws, q, qd, tool, Expressed::Local, v_local).ok() && ok;
    ok = frameVelocity(model, ws, q, qd, tool, Expressed::World, v_world).ok() && ok;
    sink = pose.translation().x() + v_local[0] + v_world[1];
    ok = frameJacobian(model, ws, q, tool, Expressed::World, J).ok() && ok;
    ok = forwardDynamics(model, ws, q, qd, qd).ok() && ok;
    ok = forwardDynamics(model, ws, q, qd, qd, task).ok() && ok;
    ok = inverseDynamics(model, ws, q, qd, qd).ok() && ok;
    ok = frameJacobian(model, ws, q, tool, Expressed::World, J).ok() && ok;  // the poses held at q: no sweep
    stale = framePose(model, ws, qd, tool, pose).code;                       // another q: NotComputed
  });
  CHECK(ok);
  CHECK(stale == StatusCode::NotComputed);
  CHECK(std::isfinite(sink));
  CHECK(count == 0);
}

TEST_CASE("the friction solve allocates nothing (all joints stuck, indeterminate, both maximisers)") {
  const Model model = panda();
  Task task(model);
  task.addConstraint("tool0", ConstraintMatrix::Identity(6, 6), Expressed::World);
  ConstraintMatrix elbow = ConstraintMatrix::Zero(6, 1);
  elbow(5, 0) = 1.0;
  task.addConstraint("panda_link1", elbow);
  Workspace ws(model, task);
  const Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(7, -0.5, 0.7), zero = Eigen::VectorXd::Zero(7);
  Eigen::VectorXd qd = zero;
  qd[3] = 0.4;  // one moving joint: kinetic friction
  FrictionOptions active, gradient;
  gradient.method = FrictionMethod::ProjectedGradient;
  REQUIRE(solveWithFriction(model, ws, q, zero, zero, task, active));  // warm
  bool ok = true;
  const long count = allocationsDuring([&] {
    ok = solveWithFriction(model, ws, q, zero, zero, task, active).ok() && ok;
    ok = solveWithFriction(model, ws, q, qd, zero, task, active).ok() && ok;
    ok = solveWithFriction(model, ws, q, zero, zero, task, gradient).ok() && ok;
  });
  CHECK(ok);
  CHECK(count == 0);
  CHECK(ws.friction.stuck.size() == 7);
}

// ---------------------------------------------------------------------------
// Every entry point (issue #6): the remaining success paths, every error
// return, and no exception out of any of them.

TEST_CASE("the friction solve allocates nothing when the maximisers form a hyperplane (7 joints, 6 rows)") {
  // K_ΣΣ of rank one: the least-effort choice takes the dual, scalar path
  // (leastDistanceOnHyperplane), which once copied its scratch (two
  // allocations per call, found by callgrind).
  const Model model = panda();
  Task task(model);
  task.addConstraint("tool0", ConstraintMatrix::Identity(6, 6), Expressed::World);
  Workspace ws(model, task);
  const Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(7, -0.5, 0.7), zero = Eigen::VectorXd::Zero(7);
  REQUIRE(solveWithFriction(model, ws, q, zero, zero, task));  // warm
  REQUIRE(ws.friction.indeterminate);                          // the choice among maximisers ran
  bool ok = false;
  CHECK(allocationsDuring([&] { ok = solveWithFriction(model, ws, q, zero, zero, task).ok(); }) == 0);
  CHECK(ok);
}

TEST_CASE("the solver entry points are declared noexcept") {
  const Model model = panda();
  Task task(model);
  Workspace ws(model, task);
  const Eigen::VectorXd x = Eigen::VectorXd::Zero(7);
  // (Through Ref arguments: converting a VectorXd to a Ref is not itself noexcept.)
  const Eigen::Ref<const Eigen::VectorXd> r(x);
  const FrictionOptions options;
  static_assert(noexcept(solveHybridDynamics(model, ws, r, r, r, task)));
  static_assert(noexcept(solveWithFriction(model, ws, r, r, r, task, options)));
  static_assert(noexcept(inverseDynamics(model, ws, r, r, r, task)));
  static_assert(noexcept(inverseDynamics(model, ws, r, r, r)));
  static_assert(noexcept(forwardDynamics(model, ws, r, r, r, task)));
  static_assert(noexcept(forwardDynamics(model, ws, r, r, r)));
  static_assert(noexcept(jointSpaceInertia(model, ws, r)));
  CHECK(solveHybridDynamics(model, ws, r, r, r, task).ok());  // (and they run)
}

TEST_CASE("the kinematics entry points are declared noexcept") {
  const Model model = panda();
  Workspace ws(model, 0);
  const Eigen::VectorXd x = Eigen::VectorXd::Zero(7);
  const Eigen::Ref<const Eigen::VectorXd> r(x);
  Eigen::Isometry3d pose;
  Vec6 out;
  // (qd given: the default argument builds a Ref, which is not noexcept itself.)
  static_assert(noexcept(forwardKinematics(model, ws, r, r)));
  static_assert(noexcept(framePose(model, ws, r, 0, pose)));
  static_assert(noexcept(frameVelocity(model, ws, r, r, 0, Expressed::Local, out)));
  static_assert(noexcept(frameAcceleration(model, ws, r, r, 0, Expressed::World, out)));
  // frameJacobian takes its output Ref by value, and copying a Ref is not
  // noexcept: assert the declaration itself (noexcept is part of the type).
  static_assert(
      std::is_same_v<decltype(frameJacobian), Status(const Model&, Workspace&, const Eigen::Ref<const Eigen::VectorXd>&,
                                                     int, Expressed, Eigen::Ref<Eigen::MatrixXd>) noexcept>);
  CHECK(forwardKinematics(model, ws, r, r).ok());  // (and they run)
  CHECK(framePose(model, ws, r, 0, pose).ok());
  CHECK(pose.isApprox(Eigen::Isometry3d::Identity()));  // frame 0 is the base
}

TEST_CASE("friction at a joint limit, with overrides, a margin and an infeasible task allocates nothing") {
  const Model model = panda();
  Task task(model);
  Workspace ws(model, task);
  Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(7, -0.5, 0.7);
  q[3] = model.joint(3).lower;  // on its lower limit
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(7);
  FrictionOptions options;
  options.breakaway = Eigen::VectorXd::Constant(7, 0.5);
  options.margin = 0.5;
  REQUIRE(solveWithFriction(model, ws, q, zero, zero, task, options));  // warm
  bool ok = false;
  CHECK(allocationsDuring([&] { ok = solveWithFriction(model, ws, q, zero, zero, task, options).ok(); }) == 0);
  CHECK(ok);

  // The report's arm on its upper limit, asked to accelerate into it: Infeasible.
  zwang::testing::IntoUpperLimit into;
  Status status;
  solveWithFriction(into.arm, into.ws, into.q, into.zero, into.zero, into.task);  // warm
  CHECK(allocationsDuring(
            [&] { status = solveWithFriction(into.arm, into.ws, into.q, into.zero, into.zero, into.task); }) == 0);
  CHECK(status.code == StatusCode::Infeasible);
}

TEST_CASE("frame accelerations and kinematics without velocities allocate nothing") {
  const Model model = panda();
  Task task(model);
  Workspace ws(model, task);
  const Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(7, -0.5, 0.7), qd = Eigen::VectorXd::Constant(7, 0.3);
  REQUIRE(solveHybridDynamics(model, ws, q, qd, qd, task));
  const int tool = model.frameIndex("tool0");
  Vec6 a_world, a_local;
  Eigen::Isometry3d pose;
  bool ok = false;
  double sink = 0.0;
  const long count = allocationsDuring([&] {
    ok = frameAcceleration(model, ws, q, qd, tool, Expressed::World, a_world).ok();
    ok = frameAcceleration(model, ws, q, qd, tool, Expressed::Local, a_local).ok() && ok;
    ok = forwardKinematics(model, ws, q).ok() && ok;
    ok = framePose(model, ws, q, tool, pose).ok() && ok;
    sink = a_world[2] + a_local[0] + pose.translation().z();
  });
  CHECK(ok);
  CHECK(std::isfinite(sink));
  CHECK(count == 0);
}

TEST_CASE("constraint wrenches allocate nothing, also on a relative constraint's reference and a contact") {
  const Model model = panda();
  Task task(model);
  task.addConstraint("tool0", ConstraintMatrix::Identity(6, 3), Expressed::World);
  task.addRelativeConstraint("panda_link4", "panda_link2", ConstraintMatrix::Identity(6, 2));
  task.addContact("panda_link6", ConstraintMatrix::Identity(6, 1));
  Workspace ws(model, task);
  const Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(7, -0.5, 0.7), qd = Eigen::VectorXd::Constant(7, 0.3);
  const Eigen::Ref<const Eigen::VectorXd> r(q);  // (building a Ref from q is not noexcept itself)
  static_assert(noexcept(constraintWrench(model, ws, task, r, 0, Expressed::World, std::declval<Vec6&>())));
  REQUIRE(solveHybridDynamics(model, ws, q, qd, qd, task));
  Vec6 w;
  bool ok = true;
  double sink = 0.0;
  StatusCode error = StatusCode::Ok;
  const int frames[] = {model.frameIndex("tool0"), model.frameIndex("panda_link4"), model.frameIndex("panda_link2"),
                        model.frameIndex("panda_link6"), model.frameIndex("panda_link1")};
  const long count = allocationsDuring([&] {
    for (const int frame : frames)
      for (const Expressed e : {Expressed::World, Expressed::Local}) {
        ok = constraintWrench(model, ws, task, q, frame, e, w).ok() && ok;
        sink += w.sum();
      }
    error = constraintWrench(model, ws, task, qd, 1, Expressed::World, w).code;  // NotComputed: poses at another q
  });
  CHECK(ok);
  CHECK(std::isfinite(sink));
  CHECK(error == StatusCode::NotComputed);
  CHECK(count == 0);
}

TEST_CASE("a task with more rows than the workspace had: the first solve makes room, the next allocate nothing") {
  const Model model = panda();
  Task task(model);
  task.addConstraint("tool0", ConstraintMatrix::Identity(6, 6), Expressed::World);
  task.addConstraint("panda_link4", ConstraintMatrix::Identity(6, 2));
  Workspace ws(model, 3), reserved(model, 3);
  const Eigen::VectorXd q = Eigen::VectorXd::Constant(7, 0.1);
  bool ok = solveHybridDynamics(model, ws, q, q, q, task).ok();  // grows: 8 rows
  REQUIRE(ws.constraintCapacity() == 8);
  REQUIRE(reserved.reserve(model, 8));
  long count = allocationsDuring([&] {
    for (int k = 0; k < 3; ++k) {
      ok = solveHybridDynamics(model, ws, q, q, q, task).ok() && ok;
      ok = solveWithFriction(model, ws, q, q, q, task).ok() && ok;
    }
  });
  CHECK(ok);
  CHECK(count == 0);
  // A workspace that made room before the loop (Workspace::reserve) allocates nothing at its first solve, but for ν
  // (sized to the task's rows by the first solve of a task).
  reserved.solution.nu.setZero(task.constraintRows());
  count = allocationsDuring([&] { ok = solveHybridDynamics(model, reserved, q, q, q, task).ok() && ok; });
  CHECK(ok);
  CHECK(count == 0);
  // The counter sees the growth itself: a fresh small workspace allocates in its first solve of this task.
  Workspace small(model, 3);
  count = allocationsDuring([&] { ok = solveHybridDynamics(model, small, q, q, q, task).ok() && ok; });
  CHECK(count > 0);
  CHECK(small.constraintCapacity() == 8);
}

TEST_CASE("the friction solve's warm start allocates nothing (the full solve, then the pattern held)") {
  const Model model = panda();
  Task task(model);
  task.addConstraint("tool0", ConstraintMatrix::Identity(6, 2), Expressed::World);
  Workspace ws(model, task);
  const Eigen::VectorXd q = Eigen::VectorXd::Constant(7, 0.3);
  Eigen::VectorXd qd(7), tau = Eigen::VectorXd::Constant(7, 0.5);
  qd << 0.2, 0.3, -0.1, 0.4, 0.0, 0.0, 0.0;  // 3 stuck joints and 2 rows: μ* unique, the pattern kept
  FrictionOptions options;
  options.breakaway = Eigen::VectorXd::Constant(7, 50.0);
  options.warm_start = true;
  bool ok = true;
  int warm = 0;
  const long count = allocationsDuring([&] {
    for (int k = 0; k < 4; ++k) {
      tau[2] += 0.01;  // the next cycle
      ok = solveWithFriction(model, ws, q, qd, tau, task, options).ok() && ok;
      warm += ws.friction.warm_started ? 1 : 0;
    }
  });
  CHECK(ok);
  CHECK(warm == 3);  // all but the first
  CHECK(count == 0);
}

TEST_CASE("the pattern search allocates nothing: pivots, a changed stuck set, another task, the active set after it") {
  const Model model = panda();
  const Task task(model), other(model);
  Task held(model);
  held.addConstraint("tool0", ConstraintMatrix::Identity(6, 6), Expressed::World);  // 13 conditions: not searched
  Workspace ws(model, task), ws_held(model, held);
  const Eigen::VectorXd q = Eigen::VectorXd::Constant(7, 0.3), rest = Eigen::VectorXd::Zero(7);
  Eigen::VectorXd one_moving = rest, tau = Eigen::VectorXd::LinSpaced(7, -4.0, 5.0);
  one_moving[2] = 0.4;
  FrictionOptions options;
  options.method = FrictionMethod::StickPatterns;
  options.breakaway = Eigen::VectorXd::LinSpaced(7, 0.5, 3.0);  // some stick, some slip: passes with pivots
  options.warm_start = true;
  REQUIRE(solveWithFriction(model, ws, q, rest, tau, task, options));
  FrictionOptions from_sticking = options;
  from_sticking.warm_start = false;
  REQUIRE(solveWithFriction(model, ws_held, q, rest, tau, held, from_sticking));
  bool ok = true;
  int searched = 0, pivots = 0;
  const long count = allocationsDuring([&] {
    for (int k = 0; k < 3; ++k) {
      ok = solveWithFriction(model, ws, q, k == 1 ? one_moving : rest, tau, task, options).ok() && ok;
      searched += ws.friction.method == FrictionMethod::StickPatterns ? 1 : 0;
      pivots = std::max(pivots, ws.friction.iterations);
      ok = solveWithFriction(model, ws, q, rest, tau, other, options).ok() && ok;  // the kept pattern: not its
      ok = solveWithFriction(model, ws_held, q, rest, tau, held, from_sticking).ok() && ok;  // the active set answers
      searched += ws_held.friction.method == FrictionMethod::StickPatterns ? 1 : 0;
      tau[1] += 0.3;
    }
  });
  CHECK(ok);
  CHECK(searched == 3);
  CHECK(pivots > 1);
  CHECK(count == 0);
}

TEST_CASE("every error return of every entry point allocates nothing and throws nothing") {
  const Model model = panda(), other = zwang::testing::oneDofArmModel();
  Task task(model);
  task.addConstraint("tool0", ConstraintMatrix::Identity(6, 6), Expressed::World);
  task.addConstraint("panda_link4", ConstraintMatrix::Identity(6, 1));
  Workspace ws(model, task), foreign(other, 6), fresh(model, 0);
  const Task foreign_task(other);
  Task resized = task;
  resized.targets().resize(3);  // b no longer the task's 7 rows
  const Eigen::VectorXd ok7 = Eigen::VectorXd::Constant(7, 0.1), short3 = Eigen::VectorXd::Zero(3);
  Eigen::VectorXd nan7 = ok7;
  nan7[4] = std::nan("");
  // Every refused friction option (the table test_stress_errors checks the messages of).
  const std::vector<zwang::testing::BadFrictionOption> bad_options = zwang::testing::badFrictionOptions();
  std::vector<StatusCode> option_codes(bad_options.size(), StatusCode::Ok);
  Eigen::MatrixXd J(6, 7), J_wrong(6, 3);
  const int frames = static_cast<int>(model.frames().size());
  Eigen::Isometry3d pose;
  Vec6 out;

  // Each call returns the expected code; collected first, checked after the counted region.
  StatusCode codes[32];
  int n = 0;
  const long count = allocationsDuring([&] {
    codes[n++] = solveHybridDynamics(model, ws, short3, ok7, ok7, task).code;       // SizeMismatch
    codes[n++] = solveHybridDynamics(model, ws, ok7, nan7, ok7, task).code;         // NonFinite
    codes[n++] = solveHybridDynamics(model, foreign, ok7, ok7, ok7, task).code;     // ModelMismatch (workspace)
    codes[n++] = solveHybridDynamics(model, ws, ok7, ok7, ok7, foreign_task).code;  // ModelMismatch (task)
    codes[n++] = solveWithFriction(model, ws, ok7, ok7, nan7, task).code;           // NonFinite
    for (std::size_t k = 0; k < bad_options.size(); ++k)                            // BadOption, each
      option_codes[k] = solveWithFriction(model, ws, ok7, ok7, ok7, task, bad_options[k].options).code;
    codes[n++] = inverseDynamics(model, ws, ok7, short3, ok7, task).code;                 // SizeMismatch
    codes[n++] = inverseDynamics(model, foreign, ok7, ok7, ok7, task).code;               // ModelMismatch
    codes[n++] = jointSpaceInertia(model, ws, nan7).code;                                 // NonFinite
    codes[n++] = jointSpaceInertia(model, foreign, ok7).code;                             // ModelMismatch
    codes[n++] = forwardKinematics(model, ws, short3).code;                               // SizeMismatch
    codes[n++] = forwardKinematics(model, ws, ok7, nan7).code;                            // NonFinite
    codes[n++] = forwardKinematics(model, foreign, ok7).code;                             // ModelMismatch
    codes[n++] = frameJacobian(model, ws, ok7, 1, Expressed::World, J_wrong).code;        // SizeMismatch
    codes[n++] = frameJacobian(model, ws, nan7, 1, Expressed::World, J).code;             // NonFinite
    codes[n++] = frameJacobian(model, ws, ok7, frames, Expressed::World, J).code;         // ModelMismatch (frame)
    codes[n++] = framePose(model, ws, ok7, -1, pose).code;                                // ModelMismatch (frame)
    codes[n++] = framePose(model, ws, ok7, frames, pose).code;                            // ModelMismatch (frame)
    codes[n++] = framePose(model, foreign, ok7, 1, pose).code;                            // ModelMismatch (workspace)
    codes[n++] = frameVelocity(model, ws, ok7, ok7, -1, Expressed::Local, out).code;      // ModelMismatch (frame)
    codes[n++] = frameVelocity(model, ws, ok7, ok7, frames, Expressed::World, out).code;  // ModelMismatch (frame)
    codes[n++] = frameVelocity(model, foreign, ok7, ok7, 1, Expressed::Local, out).code;  // ModelMismatch (workspace)
    codes[n++] = frameAcceleration(model, ws, ok7, ok7, -1, Expressed::World, out).code;  // ModelMismatch (frame)
    codes[n++] = frameAcceleration(model, ws, ok7, ok7, frames, Expressed::Local, out).code;  // ModelMismatch (frame)
    codes[n++] =
        frameAcceleration(model, foreign, ok7, ok7, 1, Expressed::World, out).code;         // ModelMismatch (workspace)
    codes[n++] = solveHybridDynamics(model, ws, ok7, ok7, ok7, resized).code;               // SizeMismatch (targets)
    codes[n++] = framePose(model, fresh, ok7, 1, pose).code;                                // NotComputed
    codes[n++] = frameVelocity(model, fresh, ok7, ok7, 1, Expressed::Local, out).code;      // NotComputed
    codes[n++] = frameAcceleration(model, fresh, ok7, ok7, 1, Expressed::World, out).code;  // NotComputed
  });
  CHECK(count == 0);
  const StatusCode expected[] = {
      StatusCode::SizeMismatch,  StatusCode::NonFinite,     StatusCode::ModelMismatch, StatusCode::ModelMismatch,
      StatusCode::NonFinite,     StatusCode::SizeMismatch,  StatusCode::ModelMismatch, StatusCode::NonFinite,
      StatusCode::ModelMismatch, StatusCode::SizeMismatch,  StatusCode::NonFinite,     StatusCode::ModelMismatch,
      StatusCode::SizeMismatch,  StatusCode::NonFinite,     StatusCode::ModelMismatch, StatusCode::ModelMismatch,
      StatusCode::ModelMismatch, StatusCode::ModelMismatch, StatusCode::ModelMismatch, StatusCode::ModelMismatch,
      StatusCode::ModelMismatch, StatusCode::ModelMismatch, StatusCode::ModelMismatch, StatusCode::ModelMismatch,
      StatusCode::SizeMismatch,  StatusCode::NotComputed,   StatusCode::NotComputed,   StatusCode::NotComputed};
  REQUIRE(n == static_cast<int>(sizeof expected / sizeof expected[0]));
  for (int k = 0; k < n; ++k) {
    INFO("call " << k);
    CHECK(codes[k] == expected[k]);
  }
  REQUIRE(bad_options.size() >= 10);
  for (std::size_t k = 0; k < bad_options.size(); ++k) {
    INFO("friction option: " << bad_options[k].message);
    CHECK(option_codes[k] == StatusCode::BadOption);
  }
  // Every entry point is declared noexcept (the static_asserts above): one
  // that threw would have terminated this test binary.
}

TEST_CASE("a frame index out of range: every kinematics accessor returns a Status, allocates and throws nothing") {
  // (frameJacobian threw std::out_of_range from Model::frame() until 6daad16;
  // framePose, frameVelocity and frameAcceleration until issue #6 made them
  // return a Status.)
  const Model model = panda();
  Task task(model);
  Workspace ws(model, task);
  Eigen::MatrixXd J(6, 7);
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(7);
  REQUIRE(solveHybridDynamics(model, ws, q, q, q, task));
  const int frames = static_cast<int>(model.frames().size());
  REQUIRE(frames == 10);
  // Outputs hold a marker: an error leaves them unchanged.
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() << 7, 7, 7;
  const Vec6 marker = Vec6::Constant(7.0);
  Vec6 v = marker, a = marker;
  Status results[8];
  const long count = allocationsDuring([&] {
    int k = 0;
    for (const int bad : {-1, frames}) {
      results[k++] = frameJacobian(model, ws, q, bad, Expressed::World, J);
      results[k++] = framePose(model, ws, q, bad, pose);
      results[k++] = frameVelocity(model, ws, q, q, bad, Expressed::Local, v);
      results[k++] = frameAcceleration(model, ws, q, q, bad, Expressed::World, a);
    }
  });
  CHECK(count == 0);
  const char* expected[] = {"frame index -1 is not a frame of this model (it has 10 frames)",
                            "frame index 10 is not a frame of this model (it has 10 frames)"};
  for (int k = 0; k < 8; ++k) {
    INFO("call " << k);
    CHECK(results[k].code == StatusCode::ModelMismatch);
    CHECK(std::string(results[k].message) == expected[k / 4]);
  }
  CHECK(pose.translation() == Eigen::Vector3d(7, 7, 7));
  CHECK(v == marker);
  CHECK(a == marker);
}

TEST_CASE("a tree with constraints on two branches and a relative constraint allocates nothing (plain and friction)") {
  std::mt19937_64 rng(5);
  zwang::testing::RandomTreeOptions options;
  options.min_moving_joints = options.max_moving_joints = 12;
  options.min_branching = 3;
  const zwang::testing::ChainSpec spec = zwang::testing::randomTree(rng, options);
  const Model model = zwang::testing::modelFromSpec(spec);
  REQUIRE_FALSE(model.isChain());
  Task task(model);
  const int last = static_cast<int>(model.frames().size()) - 1;
  task.addConstraint(last, ConstraintMatrix::Identity(6, 3), Expressed::World);
  task.addRelativeConstraint(model.bodyFrame(3), model.bodyFrame(model.bodyCount() - 1),
                             ConstraintMatrix::Identity(6, 2));
  Workspace ws(model, task);
  Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(12, -0.5, 0.7), qd = Eigen::VectorXd::Constant(12, 0.3),
                  tau = Eigen::VectorXd::Constant(12, 1.0);
  for (int j = 0; j < 12; j += 3) qd[j] = 0.0;                // some joints stuck
  REQUIRE(solveHybridDynamics(model, ws, q, qd, tau, task));  // warm
  REQUIRE(solveWithFriction(model, ws, q, qd, tau, task));
  bool all_ok = true;
  const long count = allocationsDuring([&] {
    for (int k = 0; k < 10; ++k) {
      task.targets()[0] = 0.1 * k;
      all_ok = solveHybridDynamics(model, ws, q, qd, tau, task).ok() && all_ok;
      all_ok = solveWithFriction(model, ws, q, qd, tau, task).ok() && all_ok;
      all_ok = inverseDynamics(model, ws, q, qd, tau, task).ok() && all_ok;
    }
  });
  CHECK(all_ok);
  CHECK(count == 0);
}

// ---------------------------------------------------------------------------
// Floating bases (issue #15): the same promise with a free or planar base —
// the base's step in every sweep, contacts, joint rows, the friction
// maximiser with the base's rows in ∂q̈/∂μ, the least-effort choice and the
// errors only a floating base has. Real robots (the humanoid on two feet,
// solo12 on four) loaded with the base option, and random trees.

namespace {

// A floating problem ready to solve: the model, a task with contacts and
// joint rows, a state (some joints stuck) and the friction options.
struct FloatingCase {
  Model model;
  Task task;
  Eigen::VectorXd q, v, tau;
  FrictionOptions options;
  explicit FloatingCase(Model m) : model(std::move(m)), task(model) {}
};

// The state every case starts from: the base at the origin (free: turned a
// little, moving), the joints at q_j = 0.1·sin(j) moving at 0.3, except every
// third joint stuck.
void baseState(FloatingCase& c) {
  const Model& m = c.model;
  c.q = Eigen::VectorXd::Zero(m.nq());
  c.v = Eigen::VectorXd::Zero(m.nv());
  c.tau = Eigen::VectorXd::Zero(m.nv());
  const int base_configuration_size = m.baseConfigurationSize(), base_velocity_size = m.baseVelocitySize();
  if (m.baseType() == BaseType::Free) {
    const Eigen::Quaterniond turn(Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()));
    c.q.segment<4>(3) << turn.w(), turn.x(), turn.y(), turn.z();
  }
  for (int k = 0; k < base_velocity_size; ++k) c.v[k] = 0.1 * (k + 1);
  for (int j = 0; j < m.dof(); ++j) {
    c.q[base_configuration_size + j] = std::clamp(0.1 * std::sin(j), m.joint(j).lower, m.joint(j).upper);
    c.v[base_velocity_size + j] = j % 3 == 0 ? 0.0 : 0.3;
    c.tau[base_velocity_size + j] = std::cos(j);
  }
}

// The humanoid standing on both ankles (6 world rows each), each arm's
// elbow held by its motor (a joint row on a stuck joint: μ* is not unique
// there), friction from per-solve overrides (its URDF has none).
FloatingCase humanoidOnTwoFeet(BaseType base) {
  UrdfOptions options;
  options.base = base;
  FloatingCase c(loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/simple_humanoid.urdf", options));
  c.task.addContact("l_ankle", ConstraintMatrix::Identity(6, 6), Expressed::World);
  c.task.addContact("r_ankle", ConstraintMatrix::Identity(6, 6), Expressed::World);
  c.task.addJointConstraint("LARM_ELBOW");
  c.task.addJointConstraint("RARM_ELBOW");
  baseState(c);
  c.v[c.model.baseVelocitySize() + c.model.jointIndex("LARM_ELBOW")] = 0.0;
  c.v[c.model.baseVelocitySize() + c.model.jointIndex("RARM_ELBOW")] = 0.0;
  c.options.breakaway = Eigen::VectorXd::Constant(c.model.dof(), 5.0);
  return c;
}

// solo12 on its four feet (3 world rows each: point contacts), its own friction.
FloatingCase soloOnFourFeet(BaseType base) {
  UrdfOptions options;
  options.base = base;
  FloatingCase c(loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/solo12.urdf", options));
  for (const char* foot : {"FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"})
    c.task.addContact(foot, ConstraintMatrix::Identity(6, 3), Expressed::World);
  baseState(c);
  return c;
}

// A random 10-joint tree with a frame row on a branch, a relative row, a
// joint row, a contact and a wrench.
FloatingCase randomFloatingTree(BaseType base, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  zwang::testing::RandomTreeOptions tree;
  tree.min_moving_joints = tree.max_moving_joints = 10;
  const zwang::testing::ChainSpec spec = zwang::testing::randomTree(rng, tree);
  zwang::testing::FloatingBase kind;
  kind.kind = base == BaseType::Free ? zwang::testing::BaseKind::Free : zwang::testing::BaseKind::Planar;
  FloatingCase c(zwang::testing::floatingModelFromSpec(spec, kind));
  const int last = c.model.bodyFrame(c.model.bodyCount() - 1);
  c.task.addConstraint(c.model.bodyFrame(4), ConstraintMatrix::Identity(6, 2), Expressed::World);
  c.task.addRelativeConstraint(last, c.model.bodyFrame(2), ConstraintMatrix::Identity(6, 1));
  c.task.addJointConstraint(5);
  c.task.addContact(c.model.bodyFrame(7), ConstraintMatrix::Identity(6, 3), Expressed::World);
  c.task.wrench(c.task.addWrench(last, Expressed::World)) << 1, 2, 3, 0.1, 0.2, 0.3;
  baseState(c);
  return c;
}

// Everything a control cycle calls on a floating model, counted after a
// warm-up: the plain solve, friction by both maximisers, RNEA, CRBA, a
// Jacobian; every status kept for the caller to check.
struct FloatingCounts {
  long allocations = 0;
  bool ok = true;
  std::string first_error;
  bool indeterminate = false;
  int stuck = 0;
};

FloatingCounts countFloatingSolves(FloatingCase& c) {
  Workspace ws(c.model, c.task);
  FrictionOptions gradient = c.options;
  gradient.method = FrictionMethod::ProjectedGradient;
  Eigen::MatrixXd J(6, c.model.nv());
  const int frame = c.model.bodyFrame(c.model.bodyCount() - 1);
  Status statuses[6];
  const auto cycle = [&] {
    statuses[0] = solveHybridDynamics(c.model, ws, c.q, c.v, c.tau, c.task);
    statuses[1] = solveWithFriction(c.model, ws, c.q, c.v, c.tau, c.task, gradient);
    statuses[2] = inverseDynamics(c.model, ws, c.q, c.v, c.tau, c.task);
    statuses[3] = jointSpaceInertia(c.model, ws, c.q);
    statuses[4] = frameJacobian(c.model, ws, c.q, frame, Expressed::World, J);
    statuses[5] = solveWithFriction(c.model, ws, c.q, c.v, c.tau, c.task, c.options);  // last: its result is read
  };
  cycle();  // warm
  FloatingCounts out;
  out.allocations = allocationsDuring(cycle);
  for (const Status& s : statuses)
    if (!s.ok() && out.ok) {
      out.ok = false;
      out.first_error = s.message;
    }
  out.indeterminate = ws.friction.indeterminate;
  out.stuck = static_cast<int>(ws.friction.stuck.size());
  return out;
}

}  // namespace

TEST_CASE("floating bases: humanoid, solo12 and random trees allocate nothing (plain, friction, RNEA, CRBA)",
          "[floating]") {
  for (const BaseType base : {BaseType::Free, BaseType::Planar}) {
    FloatingCase cases[] = {humanoidOnTwoFeet(base), soloOnFourFeet(base), randomFloatingTree(base, 5),
                            randomFloatingTree(base, 6)};
    const char* names[] = {"humanoid on two feet", "solo12 on four feet", "random tree (seed 5)",
                           "random tree (seed 6)"};
    for (std::size_t k = 0; k < 4; ++k) {
      INFO(toString(base) << " base, " << names[k]);
      const FloatingCounts counts = countFloatingSolves(cases[k]);
      INFO("first error: " << counts.first_error);
      CHECK(counts.ok);
      CHECK(counts.allocations == 0);
      CHECK(counts.stuck > 0);
      if (k == 0) CHECK(counts.indeterminate);  // the held elbows: the least-effort choice ran
    }
  }
}

// Every joint stuck on two feet (contacts only): the pattern search's smallest μ along the locked balance's null
// directions (pivoted Cholesky, the contacts' torques per direction), cold and from the kept pattern.
TEST_CASE("floating bases: the humanoid on two feet with every joint stuck, the pattern search, allocates nothing",
          "[floating]") {
  UrdfOptions options;
  options.base = BaseType::Free;
  const Model model = loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/simple_humanoid.urdf", options);
  Task task(model);
  task.addContact("l_ankle", ConstraintMatrix::Identity(6, 6), Expressed::World);
  task.addContact("r_ankle", ConstraintMatrix::Identity(6, 6), Expressed::World);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(model.nq());
  q[3] = 1.0;
  const Eigen::VectorXd rest = Eigen::VectorXd::Zero(model.nv()), tau = Eigen::VectorXd::Zero(model.nv());
  FrictionOptions cold, warm;
  cold.breakaway = Eigen::VectorXd::Constant(model.dof(), 500.0);  // holds every joint
  warm = cold;
  warm.warm_start = true;
  Workspace ws(model, task);
  Status status[2];
  const auto both = [&] {
    status[0] = solveWithFriction(model, ws, q, rest, tau, task, cold);
    status[1] = solveWithFriction(model, ws, q, rest, tau, task, warm);
  };
  both();  // the workspace's first task
  CHECK(allocationsDuring(both) == 0);
  CHECK(status[0].ok());
  CHECK(status[1].ok());
  CHECK(ws.friction.method == FrictionMethod::StickPatterns);
  CHECK(ws.friction.warm_started);
  CHECK(ws.friction.indeterminate);
  CHECK(ws.solution.balance.nu_unique);
}

// An arm holding its flange (6 world rows, motor rows) with every joint stuck and friction that can carry all of
// gravity: the pattern search's least-effort choice (EffortChange::Own) and its check of the free balance.
TEST_CASE("the Panda holding its flange with every joint stuck, the pattern search's least effort, allocates nothing",
          "[friction]") {
  const Model model = loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/panda.urdf");
  Task task(model);
  task.addConstraint("panda_link8", ConstraintMatrix::Identity(6, 6), Expressed::World);
  const Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(model.nq(), -0.4, 0.6), rest = Eigen::VectorXd::Zero(model.nv());
  const Eigen::VectorXd tau = Eigen::VectorXd::Zero(model.nv());
  FrictionOptions cold, warm;
  cold.breakaway = Eigen::VectorXd::Constant(model.dof(), 1e3);  // far above what gravity asks: μ = −G inside
  cold.method = FrictionMethod::StickPatterns;  // 7 stuck DOFs: the automatic choice would run the active set
  warm = cold;
  warm.warm_start = true;
  Workspace ws(model, task);
  Status status[2];
  const auto both = [&] {
    status[0] = solveWithFriction(model, ws, q, rest, tau, task, cold);
    status[1] = solveWithFriction(model, ws, q, rest, tau, task, warm);
  };
  both();  // the workspace's first task
  CHECK(allocationsDuring(both) == 0);
  CHECK(status[0].ok());
  CHECK(status[1].ok());
  CHECK(ws.friction.method == FrictionMethod::StickPatterns);
  CHECK(ws.friction.warm_started);
  CHECK(ws.friction.indeterminate);
  CHECK(ws.solution.tau_control.cwiseAbs().maxCoeff() < 1e-9);  // friction carries all of it: no motor effort
}

TEST_CASE("floating bases: a stuck joint on a limit, an infeasible task and the base's errors allocate nothing",
          "[floating]") {
  FloatingCase c = humanoidOnTwoFeet(BaseType::Free);
  const int base_configuration_size = c.model.baseConfigurationSize(), base_velocity_size = c.model.baseVelocitySize();
  const int knee = c.model.jointIndex("LLEG_KNEE");
  c.q[base_configuration_size + knee] = c.model.joint(knee).lower;  // stuck on its lower limit
  c.v[base_velocity_size + knee] = 0.0;
  Workspace ws(c.model, c.task);
  REQUIRE(solveWithFriction(c.model, ws, c.q, c.v, c.tau, c.task, c.options));  // warm
  bool ok = false;
  CHECK(allocationsDuring([&] { ok = solveWithFriction(c.model, ws, c.q, c.v, c.tau, c.task, c.options).ok(); }) == 0);
  CHECK(ok);

  // The knee held on its limit and asked to accelerate into it: Infeasible.
  Task into(c.model);
  into.addJointConstraint(knee);
  into.targets()[0] = -1.0;
  Workspace ws_into(c.model, into);
  Status status = solveWithFriction(c.model, ws_into, c.q, c.v, c.tau, into, c.options);  // warm
  CHECK(allocationsDuring([&] { status = solveWithFriction(c.model, ws_into, c.q, c.v, c.tau, into, c.options); }) ==
        0);
  CHECK(status.code == StatusCode::Infeasible);

  // A quaternion off unit length, a q of the fixed base's length, a workspace
  // made for the fixed base.
  Eigen::VectorXd off_unit = c.q;
  off_unit.segment<4>(3) *= 1.01;
  const Eigen::VectorXd joints_only = c.q.tail(c.model.dof());
  const Model fixed = loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/simple_humanoid.urdf");
  Workspace ws_fixed(fixed, c.task.constraintRows());
  StatusCode codes[4];
  const long count = allocationsDuring([&] {
    codes[0] = solveHybridDynamics(c.model, ws, off_unit, c.v, c.tau, c.task).code;
    codes[1] = solveWithFriction(c.model, ws, off_unit, c.v, c.tau, c.task, c.options).code;
    codes[2] = solveHybridDynamics(c.model, ws, joints_only, c.v, c.tau, c.task).code;
    codes[3] = solveHybridDynamics(c.model, ws_fixed, c.q, c.v, c.tau, c.task).code;
  });
  CHECK(count == 0);
  CHECK(codes[0] == StatusCode::BadConfiguration);
  CHECK(codes[1] == StatusCode::BadConfiguration);
  CHECK(codes[2] == StatusCode::SizeMismatch);
  CHECK(codes[3] == StatusCode::ModelMismatch);
}

// The humanoid standing still on both feet with a joint row on every joint
// (zwang energy's standing scenario): the feet's share of the load moves with
// friction, so the least-effort step works on the true τ_control (its
// sensitivities by constraintTorques, a Cholesky factor, the least-distance
// passes: EffortChange::Shared in src/friction/friction_maximisers.cpp).
TEST_CASE("floating bases: the standing humanoid, contacts sharing the load with friction, allocates nothing",
          "[floating]") {
  FloatingCase c = humanoidOnTwoFeet(BaseType::Free);
  for (int j = 0; j < c.model.dof(); ++j)
    if (j != c.model.jointIndex("LARM_ELBOW") && j != c.model.jointIndex("RARM_ELBOW")) c.task.addJointConstraint(j);
  c.v.setZero();  // at rest: every joint stuck
  c.tau.setZero();
  Workspace ws(c.model, c.task);
  FrictionOptions half = c.options;
  half.margin = 0.5;
  Status statuses[2];
  const auto solves = [&] {
    statuses[0] = solveWithFriction(c.model, ws, c.q, c.v, c.tau, c.task, half);
    statuses[1] = solveWithFriction(c.model, ws, c.q, c.v, c.tau, c.task, c.options);
  };
  solves();  // warm
  CHECK(allocationsDuring(solves) == 0);
  CHECK(statuses[0]);
  CHECK(statuses[1]);
  CHECK(ws.friction.stuck.size() == static_cast<std::size_t>(c.model.dof()));
  CHECK(ws.friction.indeterminate);
  // The feet took a share: what the joints feel, τ_control − μ, is not the
  // plain solve's τ_control (the standing scenario measures up to 1.9 N·m).
  const int n = c.model.dof();
  const Eigen::VectorXd felt = ws.solution.tau_control.tail(n) - ws.friction.mu;
  REQUIRE(solveHybridDynamics(c.model, ws, c.q, c.v, c.tau, c.task));
  CHECK((felt - ws.solution.tau_control.tail(n)).cwiseAbs().maxCoeff() > 1e-3);
}

// ---------------------------------------------------------------------------
// Multi-DOF joints (issue #25): a random 10-joint tree whose second and fourth moving joints are spherical (balls
// inside the tree), the sixth planar and the seventh free, on a fixed, free or planar base; a frame row, a relative
// row, joint rows on a ball (one per DOF), a contact and a wrench; every third DOF stuck.

namespace {

FloatingCase sphericalTree(zwang::testing::BaseKind kind, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  zwang::testing::RandomTreeOptions tree;
  tree.min_moving_joints = tree.max_moving_joints = 10;
  zwang::testing::ChainSpec spec = zwang::testing::randomTree(rng, tree);
  int moving = 0;
  for (zwang::testing::JointSpec& joint : spec.joints) {
    if (joint.isFixed()) continue;
    const char* type = moving == 1 || moving == 3 ? "spherical" : moving == 5 ? "planar" : moving == 6 ? "free" : "";
    ++moving;
    if (*type == '\0') continue;
    joint.type = type;
    joint.lower = joint.upper = 0.0;
  }
  zwang::testing::FloatingBase base;
  base.kind = kind;
  FloatingCase c(zwang::testing::floatingModelFromSpec(spec, base));
  const Model& m = c.model;
  const int last = m.bodyFrame(m.bodyCount() - 1);
  int ball = -1;
  for (std::size_t j = 0; j < m.joints().size() && ball < 0; ++j)
    if (m.joints()[j].type == JointType::Spherical) ball = static_cast<int>(j);
  c.task.addConstraint(m.bodyFrame(6), ConstraintMatrix::Identity(6, 2), Expressed::World);
  c.task.addRelativeConstraint(last, m.bodyFrame(3), ConstraintMatrix::Identity(6, 1));
  c.task.addJointConstraint(ball);
  c.task.addContact(m.bodyFrame(9), ConstraintMatrix::Identity(6, 3), Expressed::World);
  c.task.wrench(c.task.addWrench(last, Expressed::World)) << 1, 2, 3, 0.1, 0.2, 0.3;
  // The state: the base as baseState's; balls and free joints turned 0.3 rad, one-DOF joints at 0.1·sin(j)
  // inside their limits; every third DOF stuck, the rest moving at 0.3.
  c.q = Eigen::VectorXd::Zero(m.nq());
  c.v = Eigen::VectorXd::Zero(m.nv());
  c.tau = Eigen::VectorXd::Zero(m.nv());
  const Eigen::Quaterniond turn(Eigen::AngleAxisd(0.3, Vec3(1, 2, 3).normalized()));
  const int base_velocity_size = m.baseVelocitySize();
  for (const Joint& joint : m.allJoints()) {
    const int q = joint.q_index;
    if (joint.type == JointType::Spherical) c.q.segment<4>(q) << turn.w(), turn.x(), turn.y(), turn.z();
    if (joint.type == JointType::Free) c.q.segment<4>(q + 3) << turn.w(), turn.x(), turn.y(), turn.z();
    if (joint.nv() == 1) c.q[q] = std::clamp(0.1 * std::sin(joint.v_index), joint.lower, joint.upper);
  }
  for (int k = 0; k < base_velocity_size; ++k) c.v[k] = 0.1 * (k + 1);
  for (int k = 0; k < m.dof(); ++k) {
    c.v[base_velocity_size + k] = k % 3 == 0 ? 0.0 : 0.3;
    c.tau[base_velocity_size + k] = std::cos(k);
  }
  return c;
}

}  // namespace

TEST_CASE("trees with spherical, planar and free joints allocate nothing (plain, friction, RNEA, CRBA)",
          "[joint_types]") {
  using zwang::testing::BaseKind;
  for (const BaseKind kind : {BaseKind::Fixed, BaseKind::Free, BaseKind::Planar})
    for (const std::uint64_t seed : {5u, 6u}) {
      FloatingCase c = sphericalTree(kind, seed);
      INFO(zwang::testing::toString(kind) << " base, seed " << seed);
      REQUIRE(c.model.dof() == 21);  // 6 one-DOF joints, two balls, a planar and a free joint
      const FloatingCounts counts = countFloatingSolves(c);
      INFO("first error: " << counts.first_error);
      CHECK(counts.ok);
      CHECK(counts.allocations == 0);
      CHECK(counts.stuck > 0);
    }
}

TEST_CASE("prescribed and locked joints allocate nothing: modes changed between solves, plain and friction",
          "[prescribed]") {
  const Model model = panda();
  Task task(model);
  task.addConstraint("tool0", ConstraintMatrix::Identity(6, 6).leftCols(3), Expressed::World);
  Workspace ws(model, task);
  const Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(7, -0.5, 0.7), tau = Eigen::VectorXd::Constant(7, 1.0);
  Eigen::VectorXd qd = Eigen::VectorXd::Constant(7, 0.3);
  qd[2] = qd[4] = 0.0;  // two joints at rest: one stuck, one prescribed below
  FrictionOptions friction;
  task.lock(1);
  REQUIRE(solveHybridDynamics(model, ws, q, qd, tau, task));  // warm
  REQUIRE(solveWithFriction(model, ws, q, qd, tau, task, friction));
  bool all_ok = true;
  const long count = allocationsDuring([&] {
    for (int k = 0; k < 10; ++k) {
      task.prescribe(4);
      task.prescribedAccelerations()[4] = 0.1 * k;
      task.setDofMode(6, k % 2 ? DofMode::Prescribed : DofMode::Torque);
      all_ok = solveHybridDynamics(model, ws, q, qd, tau, task).ok() && all_ok;
      all_ok = solveWithFriction(model, ws, q, qd, tau, task, friction).ok() && all_ok;
      task.release(4);
      all_ok = solveWithFriction(model, ws, q, qd, tau, task, friction).ok() && all_ok;
    }
  });
  CHECK(all_ok);
  CHECK(count == 0);
}

TEST_CASE("the centre-of-mass and centroidal-momentum calls allocate nothing and are noexcept", "[com]") {
  using zwang::testing::BaseKind;
  for (const BaseKind kind : {BaseKind::Fixed, BaseKind::Free, BaseKind::Planar}) {
    FloatingCase c = sphericalTree(kind, 5u);
    INFO(zwang::testing::toString(kind) << " base");
    const Model& m = c.model;
    Workspace ws(m, c.task);
    Eigen::MatrixXd J(3, m.nv()), J_wrong(3, 1);
    Vec3 position, velocity, acceleration;
    Vec6 momentum;
    double mass = 0.0;
    Status statuses[10];
    const auto cycle = [&] {
      statuses[0] = solveHybridDynamics(m, ws, c.q, c.v, c.tau, c.task);
      for (const int joint : {kWholeRobot, 2}) {
        statuses[1] = subtreeMass(m, joint, mass);
        statuses[2] = centerOfMass(m, ws, c.q, joint, position);
        statuses[3] = centerOfMassVelocity(m, ws, c.q, c.v, joint, velocity);
        statuses[4] = centerOfMassAcceleration(m, ws, c.q, c.v, joint, acceleration);
        statuses[5] = centroidalMomentum(m, ws, c.q, c.v, joint, momentum);
        statuses[6] = jacobianCenterOfMass(m, ws, c.q, joint, J);
      }
      // Error returns: a joint index out of range, a Jacobian of the wrong size, a query for another q̇ (τ).
      statuses[7] = centerOfMass(m, ws, c.q, 1000, position);
      statuses[8] = jacobianCenterOfMass(m, ws, c.q, kWholeRobot, J_wrong);
      statuses[9] = centerOfMassAcceleration(m, ws, c.q, c.tau, 0, velocity);
    };
    cycle();  // warm
    const long allocations = allocationsDuring(cycle);
    for (int k = 0; k <= 6; ++k) {
      INFO("call " << k << ": " << statuses[k].message);
      CHECK(statuses[k].ok());
    }
    CHECK(statuses[7].code == StatusCode::ModelMismatch);
    CHECK(statuses[8].code == StatusCode::SizeMismatch);
    CHECK(statuses[9].code == StatusCode::NotComputed);
    CHECK(allocations == 0);
    CHECK(mass > 0.0);
  }
  const Model model = panda();
  Workspace ws(model, 0);
  const Eigen::VectorXd x = Eigen::VectorXd::Zero(7);
  const Eigen::Ref<const Eigen::VectorXd> r(x);
  Vec3 out3;
  Vec6 out6;
  double mass = 0.0;
  static_assert(noexcept(subtreeMass(model, kWholeRobot, mass)));
  static_assert(noexcept(centerOfMass(model, ws, r, kWholeRobot, out3)));
  static_assert(noexcept(centerOfMassVelocity(model, ws, r, r, kWholeRobot, out3)));
  static_assert(noexcept(centerOfMassAcceleration(model, ws, r, r, kWholeRobot, out3)));
  static_assert(noexcept(centroidalMomentum(model, ws, r, r, kWholeRobot, out6)));
  static_assert(std::is_same_v<decltype(jacobianCenterOfMass),
                               Status(const Model&, Workspace&, const Eigen::Ref<const Eigen::VectorXd>&, int,
                                      Eigen::Ref<Eigen::MatrixXd>) noexcept>);
}

TEST_CASE("a simulation's step loop allocates nothing: both integrators, breakaways, stops and a limit reached") {
  const Model model = panda();
  Task task(model);
  Workspace ws(model, task);
  const Eigen::VectorXd q0 = Eigen::VectorXd::Constant(7, 0.3);
  REQUIRE(inverseDynamics(model, ws, q0, Eigen::VectorXd::Zero(7), Eigen::VectorXd::Zero(7), task));
  const Eigen::VectorXd gravity = ws.tau;
  for (const Integrator integrator : {Integrator::SemiImplicitEuler, Integrator::RungeKutta4}) {
    SimulationOptions options;
    options.integrator = integrator;
    options.friction.breakaway = Eigen::VectorXd::Constant(7, 2.0);
    options.friction.kinetic = Eigen::VectorXd::Constant(7, 1.5);
    Simulation sim(model, task, options);
    REQUIRE(sim.reset(q0, Eigen::VectorXd::Zero(7)));
    // Gravity compensated at q0 and a swing of 3 N·m: joints break away, stop and stick again.
    const TorqueSchedule tau = [&gravity](double t, Eigen::Ref<Eigen::VectorXd> out) {
      for (Eigen::Index j = 0; j < 7; ++j) out[j] = gravity[j] + 3.0 * std::sin(2.0 * M_PI * (1.0 + 0.3 * j) * t);
    };
    const Eigen::VectorXd held = gravity + Eigen::VectorXd::Constant(7, 2.5);  // a push within the boxes, held
    bool ok = true;
    const long count = allocationsDuring([&] {
      for (int k = 0; k < 1500; ++k) ok = (k < 200 ? sim.step(held) : sim.stepWith(tau)).ok() && ok;
    });
    CHECK(ok);
    CHECK(sim.events().size() >= 10);
    CHECK(count == 0);
  }
}

TEST_CASE("a simulation's step loop allocates nothing when a joint stops at its limit") {
  const Model model = zwang::testing::limitPendulum();
  Task task(model);
  for (const Integrator integrator : {Integrator::SemiImplicitEuler, Integrator::RungeKutta4}) {
    SimulationOptions options;
    options.integrator = integrator;
    Simulation sim(model, task, options);
    REQUIRE(sim.reset(Eigen::VectorXd::Constant(1, 0.2), Eigen::VectorXd::Constant(1, 3.0)));
    const Eigen::VectorXd tau = Eigen::VectorXd::Zero(1);
    bool ok = true;
    const long count = allocationsDuring([&] {
      for (int k = 0; k < 400; ++k) ok = sim.step(tau).ok() && ok;
    });
    CHECK(ok);
    CHECK(std::count_if(sim.events().begin(), sim.events().end(),
                        [](const SimulationEvent& e) { return e.kind == EventKind::Limit; }) >= 1);
    CHECK(count == 0);
  }
}
