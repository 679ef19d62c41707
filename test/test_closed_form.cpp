// The solver against closed-form mechanics: the report's 1-DOF arm (docs/theory.md,
// "The reference cases"), a pendulum and a prismatic joint under gravity.
#include <catch2/catch.hpp>
#include <cmath>

#include "support/frame_values.hpp"
#include "zwang/zwang.hpp"

using namespace zwang;
using zwang::testing::accelerationOf;

namespace {

// The report's chapter 6 arm: revolute about z, 1 m link along x, 1 kg with
// its COM at 0.5 m, I_zz = 2 kg·m² at the COM (2.25 about the joint).
Model oneDofArm(double rotor_inertia = 0.0) {
  Joint j;
  j.name = "joint1";
  j.axis = Vec3::UnitZ();
  j.rotor_inertia = rotor_inertia;
  j.breakaway_friction = 10.0;
  const RigidInertia link = RigidInertia::fromMassComInertia(1.0, Vec3(0.5, 0, 0), Vec3(1.0, 1.0, 2.0).asDiagonal());
  return ModelBuilder("one_dof_arm", "base")
      .addJoint(j, "link1", link)
      .addFixedFrame("tip", "link1", Transform::translation(Vec3(1, 0, 0)))
      .build();
}

Eigen::VectorXd vec(std::initializer_list<double> v) {
  Eigen::VectorXd x(static_cast<Eigen::Index>(v.size()));
  Eigen::Index k = 0;
  for (double e : v) x[k++] = e;
  return x;
}

ConstraintMatrix unit(int row) {
  ConstraintMatrix A = ConstraintMatrix::Zero(6, 1);
  A(row, 0) = 1.0;
  return A;
}

}  // namespace

TEST_CASE("1-DOF arm: q̈ = τ / I about the joint, with and without rotor inertia") {
  for (double d : {0.0, 0.75}) {
    const Model model = oneDofArm(d);
    Task task(model);
    task.gravity.setZero();
    Workspace ws(model, task);
    REQUIRE(solveHybridDynamics(model, ws, vec({0.3}), vec({0.0}), vec({3.0}), task));
    CHECK(ws.solution.qdd[0] == Approx(3.0 / (2.25 + d)).epsilon(1e-14));
    CHECK(ws.solution.tau_control[0] == Approx(3.0));
    CHECK(ws.solution.tau_constraint[0] == Approx(0.0).margin(1e-14));
    // Z at the minimum of ½ I q̈² − τ q̈ is −τ²/(2I).
    CHECK(ws.solution.gauss == Approx(-9.0 / (2.0 * (2.25 + d))).epsilon(1e-13));
  }
}

TEST_CASE("1-DOF arm: a tip force of −5 N along y is a −5 N·m torque") {
  const Model model = oneDofArm();
  Task task(model);
  task.gravity.setZero();
  const int w = task.addWrench("tip", Expressed::Local);
  task.wrench(w) << 0, -5, 0, 0, 0, 0;
  Workspace ws(model, task);
  // At q = π/2 the link points along world y; in world axes the same force is along +x.
  REQUIRE(solveHybridDynamics(model, ws, vec({0.0}), vec({0.0}), vec({0.0}), task));
  CHECK(ws.solution.qdd[0] == Approx(-5.0 / 2.25).epsilon(1e-14));
  Task world(model);
  world.gravity.setZero();
  world.wrench(world.addWrench("tip", Expressed::World)) << 5, 0, 0, 0, 0, 0;
  REQUIRE(solveHybridDynamics(model, ws, vec({M_PI / 2}), vec({0.0}), vec({0.0}), world));
  CHECK(ws.solution.qdd[0] == Approx(-5.0 / 2.25).epsilon(1e-13));
}

TEST_CASE("1-DOF arm fully constrained (the report's Fig. 5.5 task): τ_c = I·5 − τ") {
  const Model model = oneDofArm();
  Task task(model);
  task.gravity.setZero();
  task.addConstraint("link1", unit(5));  // angular acceleration about z
  task.targets()[0] = 5.0;
  Workspace ws(model, task);
  REQUIRE(solveHybridDynamics(model, ws, vec({1.0}), vec({2.0}), vec({1.0}), task));
  CHECK(ws.solution.qdd[0] == Approx(5.0).epsilon(1e-14));
  CHECK(ws.solution.nu[0] == Approx(2.25 * 5.0 - 1.0).epsilon(1e-14));
  CHECK(ws.solution.tau_constraint[0] == Approx(2.25 * 5.0 - 1.0).epsilon(1e-14));
  CHECK(ws.solution.tau_control[0] == Approx(2.25 * 5.0).epsilon(1e-14));
  CHECK_FALSE(ws.solution.balance.singular);
  CHECK(ws.solution.balance.rank == 1);
}

TEST_CASE("1-DOF arm: constraints and accelerations are classical (ω×v included)") {
  const Model model = oneDofArm();
  Task task(model);
  task.gravity.setZero();
  task.addConstraint("tip", unit(1));  // tip's linear acceleration along its local y
  task.targets()[0] = 2.0;             // = α · 1 m
  Workspace ws(model, task);
  const double omega = 3.0;
  REQUIRE(solveHybridDynamics(model, ws, vec({0.4}), vec({omega}), vec({0.0}), task));
  CHECK(ws.solution.qdd[0] == Approx(2.0).epsilon(1e-14));
  // The tip moves on a unit circle: centripetal −ω² along local x, α along y.
  const Vec6 a_tip = accelerationOf(model, ws, model.frameIndex("tip"), Expressed::Local);
  CHECK(a_tip[0] == Approx(-omega * omega).epsilon(1e-13));
  CHECK(a_tip[1] == Approx(2.0).epsilon(1e-13));
  CHECK(a_tip[5] == Approx(2.0).epsilon(1e-13));
  // The body frame sits on the axis: no linear acceleration.
  CHECK(accelerationOf(model, ws, model.bodyFrame(1), Expressed::Local).head<3>().norm() < 1e-13);
  // In world axes, at q = 0.4 the local x axis is (cos, sin, 0).
  const Vec6 a_world = accelerationOf(model, ws, model.frameIndex("tip"), Expressed::World);
  const double c = std::cos(0.4), s = std::sin(0.4);
  CHECK(a_world[0] == Approx(-omega * omega * c - 2.0 * s).epsilon(1e-13));
  CHECK(a_world[1] == Approx(-omega * omega * s + 2.0 * c).epsilon(1e-13));
}

TEST_CASE("pendulum under gravity: q̈ = m g l cos q / I_O") {
  const double m = 2.0, l = 0.7, g = 9.81;
  Joint j;
  j.name = "hinge";
  j.axis = Vec3::UnitY();
  const Mat3 Ic = Vec3(0.01, 0.02, 0.015).asDiagonal();
  const Model model = ModelBuilder("pendulum", "world")
                          .addJoint(j, "bob", RigidInertia::fromMassComInertia(m, Vec3(l, 0, 0), Ic))
                          .build();
  Task task(model);
  Workspace ws(model, 1);
  const double I_O = 0.02 + m * l * l;
  for (double q : {0.0, 0.5, -1.2, 2.0}) {
    REQUIRE(solveHybridDynamics(model, ws, vec({q}), vec({0.0}), vec({0.0}), task));
    CHECK(ws.solution.qdd[0] == Approx(m * g * l * std::cos(q) / I_O).epsilon(1e-13));
    // RNEA at that q̈ returns zero torque; at rest the holding torque is −m g l cos q.
    REQUIRE(inverseDynamics(model, ws, vec({q}), vec({0.0}), vec({0.0}), task));
    CHECK(ws.tau[0] == Approx(-m * g * l * std::cos(q)).epsilon(1e-13));
    REQUIRE(jointSpaceInertia(model, ws, vec({q})));
    CHECK(ws.H(0, 0) == Approx(I_O).epsilon(1e-14));
  }
  // Holding the bob still (angular acceleration zero) takes ν = −m g l cos q.
  Task hold(model);
  hold.addConstraint("bob", unit(4));
  REQUIRE(solveHybridDynamics(model, ws, vec({0.5}), vec({0.0}), vec({0.0}), hold));
  CHECK(ws.solution.qdd[0] == Approx(0.0).margin(1e-13));
  CHECK(ws.solution.tau_control[0] == Approx(-m * g * l * std::cos(0.5)).epsilon(1e-13));
}

TEST_CASE("prismatic joint under gravity: q̈ = (τ − m g)/(m + d), held with ν = m g") {
  const double m = 3.0, d = 0.5, g = 9.81;
  Joint j;
  j.name = "lift";
  j.type = JointType::Prismatic;
  j.axis = Vec3::UnitZ();
  j.rotor_inertia = d;
  const Model model =
      ModelBuilder("lift", "world")
          .addJoint(j, "carriage", RigidInertia::fromMassComInertia(m, Vec3(0.1, 0.2, 0.3), Mat3::Identity() * 0.1))
          .build();
  Task task(model);
  Workspace ws(model, 6);
  REQUIRE(solveHybridDynamics(model, ws, vec({0.2}), vec({1.0}), vec({40.0}), task));
  CHECK(ws.solution.qdd[0] == Approx((40.0 - m * g) / (m + d)).epsilon(1e-14));

  Task hold(model);
  hold.addConstraint("carriage", unit(2), Expressed::World);
  REQUIRE(solveHybridDynamics(model, ws, vec({0.2}), vec({0.0}), vec({0.0}), hold));
  CHECK(ws.solution.qdd[0] == Approx(0.0).margin(1e-13));
  CHECK(ws.solution.nu[0] == Approx(m * g).epsilon(1e-14));
  CHECK(ws.solution.tau_control[0] == Approx(m * g).epsilon(1e-14));
}
