// Bad input at solve time: a Status that names the input, never an exception,
// a crash or a NaN. Bad input while building a task: a ModelError naming it.
#include <catch2/catch.hpp>
#include <limits>

#include "zwang/zwang.hpp"

using namespace zwang;
using Catch::Matchers::Contains;

namespace {

Model arm() { return loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/panda.urdf"); }
const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

}  // namespace

TEST_CASE("wrong sizes and non-finite joint vectors are named with their index") {
  const Model model = arm();
  Task task(model);
  Workspace ws(model, task);
  const Eigen::VectorXd ok = Eigen::VectorXd::Zero(7);
  Eigen::VectorXd bad = ok;

  Status s = solveHybridDynamics(model, ws, Eigen::VectorXd::Zero(3), ok, ok, task);
  CHECK(s.code == StatusCode::SizeMismatch);
  CHECK_THAT(s.message, Contains("q has 3 entries") && Contains("7 joints"));

  s = solveHybridDynamics(model, ws, ok, ok, Eigen::VectorXd::Zero(8), task);
  CHECK(s.code == StatusCode::SizeMismatch);
  CHECK_THAT(s.message, Contains("tau has 8 entries"));

  bad[2] = kNaN;
  s = solveHybridDynamics(model, ws, ok, bad, ok, task);
  CHECK(s.code == StatusCode::NonFinite);
  CHECK_THAT(s.message, Contains("qd[2]") && Contains("not finite"));

  bad[2] = 0.0;
  bad[6] = -kInf;
  s = solveHybridDynamics(model, ws, ok, ok, bad, task);
  CHECK(s.code == StatusCode::NonFinite);
  CHECK_THAT(s.message, Contains("tau[6]") && Contains("-inf"));

  s = inverseDynamics(model, ws, ok, ok, bad, task);
  CHECK_THAT(s.message, Contains("qdd[6]"));
  s = jointSpaceInertia(model, ws, Eigen::VectorXd::Zero(2));
  CHECK_THAT(s.message, Contains("q has 2 entries"));
  Eigen::MatrixXd J(6, 6);
  s = frameJacobian(model, ws, ok, 0, Expressed::World, J);
  CHECK_THAT(s.message, Contains("Jacobian output is 6x6") && Contains("6x7"));
}

TEST_CASE("non-finite gravity, targets and wrenches are named") {
  const Model model = arm();
  Task task(model);
  task.addConstraint("tool0", ConstraintMatrix::Identity(6, 2));
  const int w = task.addWrench("panda_link5");
  Workspace ws(model, task);
  const Eigen::VectorXd z = Eigen::VectorXd::Zero(7);

  task.gravity.z() = kNaN;
  CHECK_THAT(solveHybridDynamics(model, ws, z, z, z, task).message, Contains("gravity"));
  task.gravity.z() = -9.81;
  task.targets()[1] = kInf;
  CHECK_THAT(solveHybridDynamics(model, ws, z, z, z, task).message, Contains("constraint targets b"));
  task.targets()[1] = 0.0;
  task.wrench(w)[4] = kNaN;
  CHECK_THAT(solveHybridDynamics(model, ws, z, z, z, task).message, Contains("wrench 0") && Contains("panda_link5"));
  task.wrench(w)[4] = 0.0;
  CHECK(solveHybridDynamics(model, ws, z, z, z, task).ok());
  CHECK(ws.solution.qdd.allFinite());
}

TEST_CASE("a workspace with room for fewer rows makes room; one made for another model is refused") {
  const Model model = arm();
  Task task(model);
  task.addConstraint("tool0", ConstraintMatrix::Identity(6, 6));
  Workspace small(model, 3), sized(model, task);
  const Eigen::VectorXd z = Eigen::VectorXd::Zero(7), q = Eigen::VectorXd::LinSpaced(7, -0.5, 0.7);
  Status s = solveHybridDynamics(model, small, q, z, z, task);
  CHECK(s);
  CHECK(small.constraintCapacity() == 6);
  REQUIRE(solveHybridDynamics(model, sized, q, z, z, task));
  CHECK(small.solution.qdd == sized.solution.qdd);  // the same arithmetic in the same room
  CHECK(small.solution.nu == sized.solution.nu);

  const Model other = loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/one_dof_arm.urdf");
  Workspace other_ws(other, 6);
  s = solveHybridDynamics(model, other_ws, z, z, z, task);
  CHECK(s.code == StatusCode::ModelMismatch);
  CHECK_THAT(s.message, Contains("workspace was made for 1 joints"));
  Task other_task(other);
  Workspace ws(model, 6);
  s = solveHybridDynamics(model, ws, z, z, z, other_task);
  CHECK(s.code == StatusCode::ModelMismatch);
  CHECK_THAT(s.message, Contains("task was made for another model"));
}

TEST_CASE("building a task with an unknown frame or a bad matrix throws a ModelError naming it") {
  const Model model = arm();
  Task task(model);
  CHECK_THROWS_WITH(task.addConstraint("gripper", ConstraintMatrix::Identity(6, 1)), Contains("no frame 'gripper'"));
  CHECK_THROWS_WITH(task.addWrench("hand"), Contains("no frame 'hand'"));
  ConstraintMatrix bad = ConstraintMatrix::Identity(6, 2);
  bad(3, 1) = kNaN;
  CHECK_THROWS_WITH(task.addConstraint("tool0", bad), Contains("tool0") && Contains("not finite"));
  CHECK_THROWS_WITH(task.addConstraint("tool0", ConstraintMatrix(6, 0)), Contains("at least one column"));
  CHECK_THROWS_WITH(model.frameIndex("nope"), Contains("no frame 'nope'") && Contains("panda_link3"));
  CHECK_THROWS_WITH(model.jointIndex("nope"), Contains("no moving joint 'nope'") && Contains("panda_joint7"));
}

TEST_CASE("q outside the joint limits: solved as given, the solution says which joint") {
  const Model model = loadUrdfFile(ZWANG_MODELS_DIR "/panda.urdf");
  Task task(model);
  Workspace ws(model, task);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(7), zero = Eigen::VectorXd::Zero(7);
  REQUIRE(solveHybridDynamics(model, ws, q, zero, zero, task));
  CHECK(ws.solution.joints_outside_limits == 1);  // panda_joint4's range is [-3.0718, -0.0698]: 0 is outside
  CHECK(ws.solution.first_joint_outside_limits == 3);
  q[3] = -1.5;
  q[5] = 5.0;  // panda_joint6: [-0.0175, 3.7525]
  REQUIRE(solveWithFriction(model, ws, q, zero, zero, task));
  CHECK(ws.solution.joints_outside_limits == 1);
  CHECK(ws.solution.first_joint_outside_limits == 5);
  q[5] = 1.0;
  REQUIRE(solveHybridDynamics(model, ws, q, zero, zero, task));
  CHECK(ws.solution.joints_outside_limits == 0);
  CHECK(ws.solution.first_joint_outside_limits == -1);
}
