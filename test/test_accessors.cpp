// Issue #24, items 2 and 4: storage a user can resize and results a workspace
// does not hold.
//  * Task::targets() and the workspace's results are resizable vectors: a
//    solve refuses any size but the task's or the model's (SizeMismatch), so it
//    never reads or writes past them (CI runs this binary under ASan too).
//  * framePose, frameVelocity and frameAcceleration read what the last call
//    that computes kinematics left (Workspace::kinematics): anything more, or
//    for another model, is NotComputed, never a stale or zero value.
#include <catch2/catch.hpp>
#include <cmath>
#include <functional>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "support/bad_inputs.hpp"
#include "zwang/zwang.hpp"

using namespace zwang;
using Catch::Matchers::Contains;

namespace {

Model panda() { return zwang::testing::pandaModel(); }

struct State {
  Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(7, -0.5, 0.7);
  Eigen::VectorXd qd = Eigen::VectorXd::LinSpaced(7, 0.3, -0.2);
  Eigen::VectorXd tau = Eigen::VectorXd::LinSpaced(7, 1.0, -1.0);
};

// The three queries on one frame at the state (q, qd); each error must leave its output as it was.
struct Queries {
  const Model& model;
  const Workspace& ws;
  int frame;
  Eigen::VectorXd q, qd;
  Eigen::Isometry3d pose;
  Vec6 velocity, acceleration;

  Queries(const Model& m, const Workspace& w, int f, const Eigen::VectorXd& q_, const Eigen::VectorXd& qd_)
      : model(m), ws(w), frame(f), q(q_), qd(qd_) {
    mark();
  }
  void mark() {
    pose = Eigen::Isometry3d::Identity();
    pose.translation() << 7, 7, 7;
    velocity = acceleration = Vec6::Constant(7.0);
  }
  Status poseStatus() { return framePose(model, ws, q, frame, pose); }
  Status velocityStatus() { return frameVelocity(model, ws, q, qd, frame, Expressed::World, velocity); }
  Status accelerationStatus() { return frameAcceleration(model, ws, q, qd, frame, Expressed::World, acceleration); }
  bool marked() const {
    return pose.translation() == Eigen::Vector3d(7, 7, 7) && velocity == Vec6::Constant(7.0) &&
           acceleration == Vec6::Constant(7.0);
  }
};

void checkNotComputed(const Status& s, const std::string& text) {
  CHECK(s.code == StatusCode::NotComputed);
  CHECK_THAT(s.message, Contains(text));
}

}  // namespace

TEST_CASE("resized targets: both solvers refuse them, naming the sizes", "[accessors]") {
  // Before the fix the solve took the row count from b itself, indexed b by the
  // rows the task was built with, read past a shortened b and returned Ok.
  const Model model = panda();
  const State x;
  Task task(model);
  REQUIRE(task.addConstraint("tool0", ConstraintMatrix::Identity(6, 6)) == 0);
  Workspace ws(model, task);
  task.targets() << 0.1, -0.2, 0.3, 0.0, 0.1, 0.0;
  REQUIRE(solveHybridDynamics(model, ws, x.q, x.qd, x.tau, task));
  const Eigen::VectorXd qdd = ws.solution.qdd;

  for (const Eigen::Index size : {Eigen::Index(3), Eigen::Index(0), Eigen::Index(9)}) {
    INFO("b resized to " << size);
    task.targets() = Eigen::VectorXd::Zero(size);
    CHECK(task.constraintRows() == 6);  // the task's rows, not b's size
    const std::string expected = "constraint targets b has " + std::to_string(size) +
                                 " entries, the task has 6 constraint rows (Task::targets() must keep its size)";
    Status s = solveHybridDynamics(model, ws, x.q, x.qd, x.tau, task);
    CHECK(s.code == StatusCode::SizeMismatch);
    CHECK(std::string(s.message) == expected);
    s = solveWithFriction(model, ws, x.q, x.qd, x.tau, task);
    CHECK(s.code == StatusCode::SizeMismatch);
    CHECK(std::string(s.message) == expected);
    // Adding a constraint would leave rows without a set point: refused, the task unchanged.
    const int columns = task.solverColumns();
    CHECK_THROWS_WITH(task.addJointConstraint(2), Contains("constraint targets b has " + std::to_string(size) +
                                                           " entries, the task has 6 constraint rows"));
    CHECK_THROWS_AS(task.addConstraint("panda_link4", ConstraintMatrix::Identity(6, 1)), ModelError);
    CHECK(task.constraintRows() == 6);
    CHECK(task.solverColumns() == columns);
  }

  // Restored to its size, the task solves as before.
  task.targets() = Eigen::VectorXd::Zero(6);
  task.targets() << 0.1, -0.2, 0.3, 0.0, 0.1, 0.0;
  REQUIRE(solveHybridDynamics(model, ws, x.q, x.qd, x.tau, task));
  CHECK(ws.solution.qdd == qdd);
  CHECK(task.addJointConstraint(2) == 6);
  CHECK(task.targets().size() == 7);
  CHECK(task.targets()[6] == 0.0);
}

TEST_CASE("a copied task is independent of its original, and so is a moved-from one", "[accessors]") {
  // The task's solver layout sits behind a pointer (Task::Layout): a copy
  // must own its own, and a move (a copy) must leave the source a whole task.
  const Model model = panda();
  const State x;
  const auto hold_tool = [&model]() {
    Task task(model);
    task.addConstraint("tool0", ConstraintMatrix::Identity(6, 3), Expressed::World);
    task.targets() << 0.2, -0.1, 0.3;
    task.wrench(task.addWrench("panda_link5")) << 1.0, 0.0, -2.0, 0.0, 0.1, 0.0;
    return task;
  };
  const auto solved = [&](const Task& task) {
    Workspace ws(model, task);
    REQUIRE(solveHybridDynamics(model, ws, x.q, x.qd, x.tau, task));
    return Eigen::VectorXd(ws.solution.qdd);
  };
  const Eigen::VectorXd expected = solved(hold_tool());

  Task original = hold_tool();
  const Task copy = original;  // NOLINT(performance-unnecessary-copy-initialization): the copy is the test
  original.addRelativeConstraint("panda_link3", "tool0", ConstraintMatrix::Identity(6, 2));
  original.addJointConstraint(1);
  CHECK(copy.constraintRows() == 3);
  CHECK(copy.solverColumns() == 3);
  CHECK(solved(copy) == expected);
  const Eigen::VectorXd changed = solved(original);
  CHECK(changed != expected);

  Task assigned(model);
  assigned.addJointConstraint(4);
  assigned = original;  // over a layout of another shape
  CHECK(assigned.solverColumns() == original.solverColumns());
  CHECK(solved(assigned) == changed);

  Task source = hold_tool();
  const Task moved = std::move(source);
  CHECK(solved(moved) == expected);
  CHECK(solved(source) == expected);  // NOLINT(bugprone-use-after-move): a move copies
}

TEST_CASE("resized workspace results: the solves refuse them, naming the result", "[accessors]") {
  // Before the fix a solve wrote q̈, τ_c, τ_control and the friction results
  // through whatever size these public vectors had.
  const Model model = panda();
  const State x;
  const Task task(model);
  Workspace ws(model, task);
  const auto expect = [&](bool friction, const std::string& message) {
    const Status s = friction ? solveWithFriction(model, ws, x.q, x.qd, x.tau, task)
                              : solveHybridDynamics(model, ws, x.q, x.qd, x.tau, task);
    CHECK(s.code == StatusCode::SizeMismatch);
    CHECK(std::string(s.message) == message);
  };
  const std::string keep = " (a workspace's results must keep their sizes)";

  ws.solution.qdd.resize(3);
  expect(false, "workspace result solution.qdd has 3 entries, expected nv = 7" + keep);
  expect(true, "workspace result solution.qdd has 3 entries, expected nv = 7" + keep);
  ws.solution.qdd.setZero(7);
  ws.solution.tau_constraint.resize(0);
  expect(false, "workspace result solution.tau_constraint has 0 entries, expected nv = 7" + keep);
  ws.solution.tau_constraint.setZero(7);
  ws.solution.tau_control.resize(8);
  expect(false, "workspace result solution.tau_control has 8 entries, expected nv = 7" + keep);
  ws.solution.tau_control.setZero(7);
  REQUIRE(solveHybridDynamics(model, ws, x.q, x.qd, x.tau, task));

  ws.friction.mu.resize(2);
  expect(true, "workspace result friction.mu has 2 entries, expected 7" + keep);
  ws.friction.mu.setZero(7);
  ws.friction.tau_friction.resize(1);
  expect(true, "workspace result friction.tau_friction has 1 entries, expected 7" + keep);
  ws.friction.tau_friction.setZero(7);
  ws.friction.state.resize(3);
  expect(true, "workspace result friction.state has 3 entries, expected 7" + keep);
  ws.friction.state.assign(7, JointState::Moving);
  ws.friction.dqdd_dmu.resize(7, 3);
  expect(true, "workspace result friction.dqdd_dmu has 3 columns, expected 7" + keep);
  ws.friction.dqdd_dmu.resize(2, 7);
  expect(true, "workspace result friction.dqdd_dmu has 2 rows, expected 7" + keep);
  ws.friction.dqdd_dmu.setZero(7, 7);
  std::vector<int>().swap(ws.friction.stuck);  // room for no joint: the solve would allocate
  expect(true, "workspace result friction.stuck has room for 0 joints, expected 7" + keep);
  ws.friction.stuck.reserve(7);
  CHECK(solveWithFriction(model, ws, x.q, x.qd, x.tau, task));

  // H with the model's rows but too few columns: the CRBA would write past it.
  ws.H.resize(7, 3);
  const Status s = jointSpaceInertia(model, ws, x.q);
  CHECK(s.code == StatusCode::SizeMismatch);
  CHECK(std::string(s.message) == "workspace result H is 7x3, expected 7x7" + keep);
  ws.H.setZero(7, 7);
  CHECK(jointSpaceInertia(model, ws, x.q));
  ws.tau.resize(2);
  const Status t = inverseDynamics(model, ws, x.q, x.qd, x.qd, task);
  CHECK(t.code == StatusCode::SizeMismatch);
  CHECK(std::string(t.message) == "workspace result tau has 2 entries, expected nv = 7" + keep);
  ws.tau.setZero(7);
  CHECK(inverseDynamics(model, ws, x.q, x.qd, x.qd, task));
}

TEST_CASE("kinematics queries: what the workspace does not hold is NotComputed", "[accessors]") {
  const Model model = panda();
  const State x;
  const Eigen::VectorXd q2 = x.q.reverse();
  const Task task(model);
  Workspace ws(model, task);
  const int tool = model.frameIndex("tool0");
  Queries query(model, ws, tool, x.q, x.qd);
  CHECK(ws.kinematics.stage == KinematicsStage::None);

  // A fresh workspace: nothing (before the fix: Ok, the identity pose, zeros).
  checkNotComputed(query.poseStatus(),
                   "framePose: the workspace holds no kinematics (none computed yet, or the last call failed); call "
                   "forwardKinematics or a solve first");
  checkNotComputed(query.velocityStatus(), "frameVelocity: the workspace holds no kinematics");
  checkNotComputed(query.accelerationStatus(),
                   "frameAcceleration: the workspace holds no kinematics (none computed yet, or the last call "
                   "failed); call solveHybridDynamics, solveWithFriction or inverseDynamics first");
  CHECK(query.marked());

  // Poses only: forwardKinematics without qd.
  REQUIRE(forwardKinematics(model, ws, x.q));
  CHECK(ws.kinematics.stage == KinematicsStage::Poses);
  CHECK(query.poseStatus());
  checkNotComputed(query.velocityStatus(),
                   "frameVelocity: the workspace holds poses only (the last call computed no velocities); call "
                   "forwardKinematics with qd, or a solve first");
  checkNotComputed(query.accelerationStatus(), "frameAcceleration: the workspace holds poses only");
  const Eigen::Isometry3d pose_q = query.pose;

  // Poses and velocities: forwardKinematics with qd (before the fix:
  // frameAcceleration Ok with zeros).
  query.mark();
  REQUIRE(forwardKinematics(model, ws, x.q, x.qd));
  CHECK(query.poseStatus());
  CHECK(query.velocityStatus());
  checkNotComputed(query.accelerationStatus(),
                   "frameAcceleration: the workspace holds poses and velocities only (the last call computed no "
                   "accelerations); call solveHybridDynamics, solveWithFriction or inverseDynamics first");
  const Vec6 velocity_q = query.velocity;

  // A solve holds all three, for its state.
  REQUIRE(solveHybridDynamics(model, ws, x.q, x.qd, x.tau, task));
  CHECK(ws.kinematics.stage == KinematicsStage::Accelerations);
  CHECK(query.poseStatus());
  CHECK(query.pose.isApprox(pose_q, 1e-14));
  CHECK(query.velocityStatus());
  CHECK(query.velocity.isApprox(velocity_q, 1e-14));
  CHECK(query.accelerationStatus());
  const Vec6 acceleration_solve = query.acceleration;
  // The same accelerations from RNEA at the solve's q̈ (an independent sweep).
  const Eigen::VectorXd qdd = ws.solution.qdd;
  REQUIRE(inverseDynamics(model, ws, x.q, x.qd, qdd, task));
  CHECK(query.accelerationStatus());
  CHECK((query.acceleration - acceleration_solve).norm() <= 1e-9 * (1.0 + acceleration_solve.norm()));

  // Another q overwrites the poses: the accelerations and velocities of the
  // earlier state are gone (before the fix: returned as if current).
  REQUIRE(solveHybridDynamics(model, ws, x.q, x.qd, x.tau, task));
  query.mark();
  REQUIRE(forwardKinematics(model, ws, q2));
  // The queries compare the state: at x.q the poses held (q2's) are stale.
  checkNotComputed(query.poseStatus(),
                   "framePose: the workspace holds kinematics at another q (q[0] = 0.7 held, -0.5 given); call "
                   "forwardKinematics(model, ws, q) first");
  CHECK(query.marked());
  query.q = q2;
  CHECK(query.poseStatus());
  checkNotComputed(query.velocityStatus(), "frameVelocity: the workspace holds poses only");
  checkNotComputed(query.accelerationStatus(), "frameAcceleration: the workspace holds poses only");
  Workspace fresh(model, 0);
  Eigen::Isometry3d pose_q2;
  REQUIRE(forwardKinematics(model, fresh, q2));
  REQUIRE(framePose(model, fresh, q2, tool, pose_q2));
  CHECK(query.pose.isApprox(pose_q2, 1e-14));

  // frameJacobian and jointSpaceInertia compute poses only (their velocities are at rest).
  Eigen::MatrixXd J(6, 7);
  for (int call = 0; call < 2; ++call) {
    INFO((call == 0 ? "frameJacobian" : "jointSpaceInertia"));
    REQUIRE(solveHybridDynamics(model, ws, x.q, x.qd, x.tau, task));
    REQUIRE((call == 0 ? frameJacobian(model, ws, q2, tool, Expressed::World, J) : jointSpaceInertia(model, ws, q2)));
    CHECK(ws.kinematics.stage == KinematicsStage::Poses);
    query.mark();
    CHECK(query.poseStatus());
    CHECK(query.pose.isApprox(pose_q2, 1e-14));
    checkNotComputed(query.velocityStatus(), "frameVelocity: the workspace holds poses only");
    checkNotComputed(query.accelerationStatus(), "frameAcceleration: the workspace holds poses only");
  }

  // A solve at (x.q, x.qd): a query at another q̇ is stale; frameJacobian at
  // the solve's q reads its poses and keeps its accelerations.
  REQUIRE(solveHybridDynamics(model, ws, x.q, x.qd, x.tau, task));
  query.q = x.q;
  query.qd = x.tau;
  query.mark();
  checkNotComputed(query.velocityStatus(),
                   "frameVelocity: the workspace holds kinematics at another qd (qd[0] = 0.3 held, 1 given); call "
                   "forwardKinematics(model, ws, q, qd) first");
  checkNotComputed(query.accelerationStatus(),
                   "frameAcceleration: the workspace holds kinematics at another qd (qd[0] = 0.3 held, 1 given); call "
                   "solveHybridDynamics, solveWithFriction or inverseDynamics first");
  CHECK(query.marked());
  query.qd = x.qd;
  REQUIRE(frameJacobian(model, ws, x.q, tool, Expressed::World, J));
  CHECK(ws.kinematics.stage == KinematicsStage::Accelerations);
  CHECK(query.accelerationStatus());

  // A call that fails its input checks computed nothing.
  Eigen::VectorXd nan7 = x.q;
  nan7[3] = std::numeric_limits<double>::quiet_NaN();
  const std::function<Status()> failing[] = {[&] { return forwardKinematics(model, ws, nan7); },
                                             [&] { return forwardKinematics(model, ws, x.q, nan7); },
                                             [&] { return frameJacobian(model, ws, nan7, tool, Expressed::World, J); },
                                             [&] { return jointSpaceInertia(model, ws, nan7); },
                                             [&] { return inverseDynamics(model, ws, x.q, nan7, x.qd, task); },
                                             [&] { return solveHybridDynamics(model, ws, x.q, x.qd, nan7, task); },
                                             [&] { return solveWithFriction(model, ws, nan7, x.qd, x.tau, task); }};
  for (std::size_t k = 0; k < std::size(failing); ++k) {
    INFO("failing call " << k);
    REQUIRE(solveHybridDynamics(model, ws, x.q, x.qd, x.tau, task));
    CHECK(failing[k]().code == StatusCode::NonFinite);
    CHECK(ws.kinematics.stage == KinematicsStage::None);
    query.mark();
    checkNotComputed(query.poseStatus(), "framePose: the workspace holds no kinematics");
    CHECK(query.marked());
  }

  // Another Model object with the same joints: its frames are not these results'.
  REQUIRE(solveHybridDynamics(model, ws, x.q, x.qd, x.tau, task));
  const Model copy = model;
  Queries other(copy, ws, tool, x.q, x.qd);
  checkNotComputed(
      other.poseStatus(),
      "framePose: the workspace's kinematics were computed for another Model object; call forwardKinematics "
      "or a solve with this model first");
  checkNotComputed(other.accelerationStatus(), "frameAcceleration: the workspace's kinematics were computed for");
  CHECK(other.marked());
  REQUIRE(forwardKinematics(copy, ws, x.q));
  CHECK(other.poseStatus());
  checkNotComputed(query.poseStatus(), "framePose: the workspace's kinematics were computed for another Model");
}

TEST_CASE("kinematics queries after each solve: friction, infeasible, degenerate", "[accessors]") {
  const Model model = panda();
  const State x;
  const Task task(model);
  Workspace ws(model, task);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(7);
  Queries query(model, ws, model.frameIndex("tool0"), x.q, zero);

  // The friction solve's accelerations are those of q̈* (all joints stuck: the
  // sweep's q̈(0) moves, q̈* of a held arm may not), as RNEA at q̈* gives them.
  REQUIRE(solveWithFriction(model, ws, x.q, zero, zero, task));
  CHECK(ws.kinematics.stage == KinematicsStage::Accelerations);
  REQUIRE(query.accelerationStatus());
  const Vec6 a_friction = query.acceleration;
  const Eigen::VectorXd qdd = ws.solution.qdd;
  REQUIRE(inverseDynamics(model, ws, x.q, zero, qdd, task));
  REQUIRE(query.accelerationStatus());
  CHECK((query.acceleration - a_friction).norm() <= 1e-9 * (1.0 + a_friction.norm()));

  // Infeasible: the outputs are finite and the accelerations are theirs.
  zwang::testing::IntoUpperLimit into;
  REQUIRE(solveWithFriction(into.arm, into.ws, into.q, into.zero, into.zero, into.task).code == StatusCode::Infeasible);
  Queries limit(into.arm, into.ws, into.arm.frameIndex(into.arm.frames().back().name), into.q, into.zero);
  CHECK(limit.accelerationStatus());
  CHECK(limit.acceleration.allFinite());

  // Degenerate: the sweeps stopped after the poses and velocities.
  ModelBuilder builder("degenerate", "base");
  Joint first, second;
  first.name = "first";
  second.name = "second";
  builder.addJoint(first, "link1", RigidInertia{});
  builder.addJoint(second, "link2", RigidInertia::fromMassComInertia(1.0, Vec3::Zero(), Mat3::Identity() * 0.01));
  const Model degenerate = builder.build();
  const Task degenerate_task(degenerate);
  Workspace degenerate_ws(degenerate, degenerate_task);
  const Eigen::VectorXd x2 = Eigen::VectorXd::Constant(2, 0.1);
  Queries stopped(degenerate, degenerate_ws, degenerate.frameIndex("link2"), x2, x2);
  for (const bool friction : {false, true}) {
    INFO((friction ? "solveWithFriction" : "solveHybridDynamics"));
    const Status s = friction ? solveWithFriction(degenerate, degenerate_ws, x2, x2, x2, degenerate_task)
                              : solveHybridDynamics(degenerate, degenerate_ws, x2, x2, x2, degenerate_task);
    REQUIRE(s.code == StatusCode::Degenerate);
    CHECK(stopped.poseStatus());
    CHECK(stopped.velocityStatus());
    checkNotComputed(stopped.accelerationStatus(), "frameAcceleration: the workspace holds poses and velocities only");
  }
}

TEST_CASE("kinematics queries on a floating base: poses only without the base's velocity", "[accessors]") {
  const Model model = ModelBuilder(panda()).setBase(BaseType::Free).build();
  Workspace ws(model, 0);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(model.nq());
  q[3] = 1.0;  // the identity quaternion (w first)
  const Eigen::VectorXd v = Eigen::VectorXd::Constant(model.nv(), 0.2);
  Queries query(model, ws, model.frameIndex("tool0"), q, v);
  REQUIRE(forwardKinematics(model, ws, q));
  CHECK(query.poseStatus());
  checkNotComputed(query.velocityStatus(), "frameVelocity: the workspace holds poses only");
  REQUIRE(forwardKinematics(model, ws, q, v));
  CHECK(query.velocityStatus());
  checkNotComputed(query.accelerationStatus(), "frameAcceleration: the workspace holds poses and velocities only");
}
