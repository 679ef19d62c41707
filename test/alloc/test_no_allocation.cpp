// Once the workspace exists, the hot-path calls make no heap allocation.
#include <catch2/catch.hpp>

#include "counting_malloc.hpp"
#include "zwang/zwang.hpp"

using namespace zwang;
using zwang::testing::allocationsDuring;

namespace {
Model panda() { return loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/panda.urdf"); }
}  // namespace

TEST_CASE("the counter sees allocations at all (guards against a test that cannot fail)") {
  CHECK(allocationsDuring([] { Eigen::VectorXd x(100); x.setOnes(); }) >= 1);
  // (operator new directly: a new-expression paired with delete may be elided.)
  CHECK(allocationsDuring([] { void* volatile p = ::operator new(16); ::operator delete(p); }) >= 1);
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
  REQUIRE(solveHybridDynamics(model, task, q, qd, tau, ws));  // warm
  // No Catch2 assertion inside a counted region: the framework may allocate.
  bool all_ok = true;
  long count = allocationsDuring([&] {
    for (int k = 0; k < 10; ++k) {
      task.targets()[0] = 0.1 * k;
      task.wrench(w)[0] = k;
      all_ok = solveHybridDynamics(model, task, q, qd, tau, ws).ok() && all_ok;
    }
  });
  CHECK(all_ok);
  CHECK(count == 0);

  // An error status is reported without allocating, too.
  const Eigen::VectorXd short_q = Eigen::VectorXd::Zero(3);
  Status status;
  count = allocationsDuring([&] { status = solveHybridDynamics(model, task, short_q, qd, tau, ws); });
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
  REQUIRE(solveHybridDynamics(model, task, q, qd, tau, ws));
  CHECK(ws.solution.coupling.singular);
  bool ok = false;
  CHECK(allocationsDuring([&] { ok = solveHybridDynamics(model, task, q, qd, tau, ws).ok(); }) == 0);
  CHECK(ok);
}

TEST_CASE("RNEA, CRBA, kinematics and Jacobians allocate nothing") {
  const Model model = panda();
  Task task(model);
  Workspace ws(model, task);
  const Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(7, -0.5, 0.7), qd = Eigen::VectorXd::Constant(7, 0.3);
  Eigen::MatrixXd J(6, 7);
  const int tool = model.frameIndex("tool0");
  bool ok = false;
  double sink = 0.0;
  const long count = allocationsDuring([&] {
    ok = inverseDynamics(model, task, q, qd, qd, ws).ok();
    ok = jointSpaceInertia(model, q, ws).ok() && ok;
    ok = forwardKinematics(model, ws, q, qd).ok() && ok;
    sink = framePose(model, ws, tool).translation().x() + frameVelocity(model, ws, tool)[0];
    ok = frameJacobian(model, ws, q, tool, Expressed::World, J).ok() && ok;
  });
  CHECK(ok);
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
  REQUIRE(solveWithFriction(model, task, q, zero, zero, ws, active));  // warm
  bool ok = true;
  const long count = allocationsDuring([&] {
    ok = solveWithFriction(model, task, q, zero, zero, ws, active).ok() && ok;
    ok = solveWithFriction(model, task, q, qd, zero, ws, active).ok() && ok;
    ok = solveWithFriction(model, task, q, zero, zero, ws, gradient).ok() && ok;
  });
  CHECK(ok);
  CHECK(count == 0);
  CHECK(ws.friction.stuck.size() == 7);
}
