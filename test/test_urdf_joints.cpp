// URDF `floating` and `planar` joints anywhere in the tree (issue #25): they
// load as Free and Planar joints (a floating or planar root joint still makes
// the base: test_urdf_floating). Their layout in q and v, the planar joint's
// plane (normal to the URDF <axis>), friction per DOF, ignored limits, and
// solves checked against independent references: the subtree below a free
// joint moves as the same bodies floating alone, a body on a planar joint
// accelerates as Newton's and Euler's laws restricted to the plane say.
#include <Eigen/Geometry>
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>

#include "zwang/zwang.hpp"

using namespace zwang;
using Catch::Matchers::Contains;

namespace {

// A link with mass 1.3 kg and a full inertia tensor; `com` its centre of mass.
std::string link(const std::string& name, const std::string& com = "0.05 -0.02 0.1") {
  return "<link name=\"" + name + "\"><inertial><origin xyz=\"" + com +
         "\"/><mass value=\"1.3\"/><inertia ixx=\"0.04\" ixy=\"0.003\" ixz=\"-0.002\" iyy=\"0.05\" iyz=\"0.004\" "
         "izz=\"0.03\"/></inertial></link>";
}

std::string joint(const std::string& name, const std::string& type, const std::string& parent, const std::string& child,
                  const std::string& extra = "") {
  return "<joint name=\"" + name + "\" type=\"" + type + "\"><parent link=\"" + parent + "\"/><child link=\"" + child +
         "\"/>" + extra + "</joint>";
}

const std::string kLimit = R"(<limit lower="-3" upper="3" effort="100" velocity="10"/>)";

// base ─j1 (revolute)→ l1 ─float (floating)→ ball ─j2 (revolute)→ l2, and base ─j3 (prismatic)→ l3.
std::string midTreeFloating() {
  return "<robot name=\"mid\">" + link("base") +
         joint("j1", "revolute", "base", "l1", R"(<origin xyz="0 0 0.5"/><axis xyz="0 1 0"/>)" + kLimit) + link("l1") +
         joint("float", "floating", "l1", "ball", R"(<origin xyz="0.3 0 0" rpy="0.1 0.2 0.3"/>)") + link("ball") +
         joint("j2", "revolute", "ball", "l2", R"(<origin xyz="0 0 0.2"/><axis xyz="1 0 0"/>)" + kLimit) + link("l2") +
         joint("j3", "prismatic", "base", "l3", R"(<axis xyz="0 0 1"/>)" + kLimit) + link("l3") + "</robot>";
}

// base ─slide (planar, normal `axis`)→ puck, the puck's centre of mass at its origin; a stand welded to
// the base, so that the planar joint is not the root link's only joint (which would make it the base).
std::string planarPuck(const std::string& axis, const std::string& extra = "") {
  return "<robot name=\"puck\">" + link("base") + joint("weld", "fixed", "base", "stand") + "<link name=\"stand\"/>" +
         joint("slide", "planar", "base", "puck",
               R"(<origin xyz="0.1 0.2 0.3" rpy="0.3 -0.2 0.5"/><axis xyz=")" + axis + "\"/>" + extra) +
         link("puck", "0 0 0") + "</robot>";
}

// The pose of joint j's child link in its parent link's frame at the joint's coordinates q_j.
Eigen::Isometry3d childPose(const Model& m, int j, const double* q_j) {
  const Joint& joint = m.joint(j);
  const Frame& child = m.frame(m.bodyFrame(joint.body()));
  const Transform X = child.placement * joint.transform(q_j);  // ᶜX_parent body (the parent link's frame here)
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = X.rotationOfTarget();
  pose.translation() = X.originOfTarget();
  return pose;
}

}  // namespace

TEST_CASE("a floating joint mid-tree is a free joint: layout in q and v", "[urdf][joints]") {
  const Model m = loadUrdfString(midTreeFloating());
  CHECK(m.baseType() == BaseType::Fixed);
  REQUIRE(m.joints().size() == 4);
  const Joint& f = m.joint(m.jointIndex("float"));
  CHECK(f.type == JointType::Free);
  // Depth first, children in the order of their joints' names: j1, float, j2, then j3.
  CHECK(m.joint(0).name == "j1");
  CHECK(m.joint(1).name == "float");
  CHECK(m.joint(2).name == "j2");
  CHECK(m.joint(3).name == "j3");
  CHECK(f.nq() == 7);
  CHECK(f.nv() == 6);
  CHECK(f.q_index == 1);
  CHECK(f.v_index == 1);
  CHECK(m.joint(2).q_index == 8);
  CHECK(m.joint(2).v_index == 7);
  CHECK(m.joint(3).q_index == 9);
  CHECK(m.joint(3).v_index == 8);
  CHECK(m.nq() == 10);
  CHECK(m.nv() == 9);
  CHECK(m.dof() == 9);
  CHECK(m.dofs()[1].name == "float.vx");
  CHECK(m.dofs()[6].name == "float.wz");
  CHECK(m.dofs()[7].name == "j2");
  // The ball hangs from l1's body, j2 from the ball's.
  CHECK(m.frame(m.frameIndex("ball")).body == f.body());
  CHECK(m.parentBodyOfJoint(2) == f.body());
  CHECK(m.parentBodyOfJoint(1) == m.joint(0).body());
  // The joint frame is the URDF <origin>: q = [0 0 0, 1 0 0 0] puts the ball where the URDF draws it.
  const double rest[7] = {0, 0, 0, 1, 0, 0, 0};
  const Eigen::Isometry3d pose = childPose(m, 1, rest);
  const Mat3 R = (Eigen::AngleAxisd(0.3, Vec3::UnitZ()) * Eigen::AngleAxisd(0.2, Vec3::UnitY()) *
                  Eigen::AngleAxisd(0.1, Vec3::UnitX()))
                     .toRotationMatrix();
  CHECK((pose.translation() - Vec3(0.3, 0, 0)).norm() < 1e-15);
  CHECK((pose.linear() - R).norm() < 1e-15);  // rounding of the rpy → matrix conversion
}

TEST_CASE("a planar joint mid-tree moves in the plane normal to its URDF axis", "[urdf][joints]") {
  // URDF: the child moves in the plane perpendicular to <axis> and turns about it.
  for (const char* axis_text : {"0 0 1", "1 0 0", "0 0 -1", "0 1 1", "-0.3 0.5 0.8"}) {
    INFO(axis_text);
    const Model m = loadUrdfString(planarPuck(axis_text));
    REQUIRE(m.joints().size() == 1);
    const Joint& p = m.joint(0);
    CHECK(p.type == JointType::Planar);
    CHECK(p.nq() == 3);
    CHECK(p.nv() == 3);
    CHECK(p.q_index == 0);
    CHECK(p.v_index == 0);
    CHECK(m.dofs()[2].name == "slide.yaw");
    std::istringstream in(axis_text);
    Vec3 a;
    in >> a.x() >> a.y() >> a.z();
    a.normalize();
    const double zero[3] = {0, 0, 0};
    const Eigen::Isometry3d origin = childPose(m, 0, zero);  // the URDF's joint frame
    const Mat3 R = (Eigen::AngleAxisd(0.5, Vec3::UnitZ()) * Eigen::AngleAxisd(-0.2, Vec3::UnitY()) *
                    Eigen::AngleAxisd(0.3, Vec3::UnitX()))
                       .toRotationMatrix();
    CHECK((origin.translation() - Vec3(0.1, 0.2, 0.3)).norm() < 1e-15);
    CHECK((origin.linear() - R).norm() < 1e-14);
    // Yaw alone turns the link about the axis (in the joint frame) and keeps its origin.
    const double yaw[3] = {0, 0, 0.7};
    const Eigen::Isometry3d turned = origin.inverse() * childPose(m, 0, yaw);
    CHECK(turned.translation().norm() < 1e-14);
    CHECK((turned.linear() - Eigen::AngleAxisd(0.7, a).toRotationMatrix()).norm() < 1e-14);
    // x and y move it in the plane: orthonormal directions normal to the axis, right-handed with it.
    const double x[3] = {1, 0, 0}, y[3] = {0, 1, 0};
    const Vec3 u = (origin.inverse() * childPose(m, 0, x)).translation();
    const Vec3 w = (origin.inverse() * childPose(m, 0, y)).translation();
    CHECK(std::abs(u.norm() - 1) < 1e-14);
    CHECK(std::abs(w.norm() - 1) < 1e-14);
    CHECK(std::abs(u.dot(a)) < 1e-14);
    CHECK(std::abs(w.dot(a)) < 1e-14);
    CHECK((u.cross(w) - a).norm() < 1e-14);
    // The shortest rotation taking z onto the axis turns the plane's axes (urdf.hpp): for a normal along x, x is −z.
    if (std::string(axis_text) == "1 0 0") CHECK((u - Vec3(0, 0, -1)).norm() < 1e-15);
    if (std::string(axis_text) == "0 0 -1") CHECK((u - Vec3(1, 0, 0)).norm() < 1e-15);
    if (std::string(axis_text) == "0 0 1") CHECK(m.frame(m.frameIndex("puck")).placement.E.isIdentity(0.0));
  }
}

TEST_CASE("multi-DOF URDF joints: friction per DOF, limits ignored with a warning, no locking at a number",
          "[urdf][joints]") {
  const Model m = loadUrdfString(planarPuck("0 0 1", R"(<dynamics friction="0.4" damping="0.2"/>)"));
  for (const Dof& d : m.dofs()) {
    CHECK(d.breakaway_friction == 0.4);
    CHECK(d.kinetic_friction == 0.4);
    CHECK(d.viscous_friction == 0.2);
  }
  CHECK(m.warnings().empty());

  const Model limited = loadUrdfString(planarPuck("0 0 1", kLimit));
  REQUIRE(limited.warnings().size() == 1);
  CHECK(limited.warnings()[0].code == WarningCode::IgnoredLimits);
  CHECK(std::string(toString(WarningCode::IgnoredLimits)) == "ignored_limits");
  CHECK(limited.warnings()[0].message ==
        "<string>: joint 'slide': <limit> on a planar joint ignored (lower -3, upper 3, effort 100, velocity 10): "
        "zwang's multi-DOF joints have no position, effort or velocity limits");
  CHECK(std::isinf(limited.joint(0).effort_limit));
  CHECK(std::isinf(limited.dofs()[0].upper));
  UrdfOptions strict;
  strict.strict = true;
  REQUIRE_THROWS_WITH(loadUrdfString(planarPuck("0 0 1", kLimit), strict),
                      Contains("refused in strict mode") && Contains("<limit> on a planar joint ignored"));

  // A floating joint beyond the tip is welded at its origin; a number cannot place it.
  UrdfOptions beyond;
  beyond.tip = "l1";
  beyond.attach_beyond_tip = true;
  CHECK(loadUrdfString(midTreeFloating(), beyond).dof() == 1);
  beyond.locked_positions["float"] = 0.5;
  REQUIRE_THROWS_WITH(loadUrdfString(midTreeFloating(), beyond),
                      Contains("joint 'float': a floating joint cannot be locked at q = 0.5 (one number cannot place "
                               "it); it is locked at its origin: give it no locked position"));
  // A zero axis is still refused, now saying it is the plane's normal.
  REQUIRE_THROWS_WITH(loadUrdfString(planarPuck("0 0 0")),
                      Contains("joint 'slide': <axis> xyz \"0 0 0\" is zero (it must give the joint's direction, here "
                               "the normal of the plane)"));
}

TEST_CASE("solve: the subtree below a mid-tree free joint moves as the same bodies floating alone",
          "[urdf][joints][solve]") {
  // Without torque on the free joint, nothing but gravity acts on {ball, l2} from outside: their motion
  // is that of a second model, the same two links with a free base, started in the same state.
  const Model a = loadUrdfString(midTreeFloating());
  UrdfOptions alone;
  alone.root = "ball";
  alone.base = BaseType::Free;
  const Model b = loadUrdfString(midTreeFloating(), alone);
  REQUIRE(b.nv() == 7);
  Eigen::VectorXd q(a.nq()), qd(a.nv()), tau(a.nv());
  const Eigen::Quaterniond quat = Eigen::Quaterniond(0.9, -0.2, 0.3, 0.25).normalized();
  q << 0.7, 0.1, -0.2, 0.3, quat.w(), quat.x(), quat.y(), quat.z(), -0.4, 0.05;
  qd << 0.8, 0.3, -0.5, 0.2, 1.1, -0.7, 0.4, -1.3, 0.6;
  tau << 3.0, 0, 0, 0, 0, 0, 0, 0.5, -2.0;
  const Task task_a(a);
  Workspace ws_a(a, task_a);
  REQUIRE(solveHybridDynamics(a, ws_a, q, qd, tau, task_a));

  // The ball's pose and velocity ([v; ω] in its own axes, the free base's coordinates) from model a.
  const int ball_a = a.frameIndex("ball");
  Eigen::Isometry3d pose;
  Vec6 v_ball;
  REQUIRE(framePose(a, ws_a, q, ball_a, pose));
  REQUIRE(frameVelocity(a, ws_a, q, qd, ball_a, Expressed::Local, v_ball));
  const Eigen::Quaterniond orientation(pose.linear());
  Eigen::VectorXd qb(b.nq()), qdb(b.nv()), taub(b.nv());
  qb << pose.translation(), orientation.w(), orientation.x(), orientation.y(), orientation.z(), q[8];
  qdb << v_ball, qd[7];
  taub << Vec6::Zero(), tau[7];
  const Task task_b(b);
  Workspace ws_b(b, task_b);
  REQUIRE(solveHybridDynamics(b, ws_b, qb, qdb, taub, task_b));

  CHECK(std::abs(ws_a.solution.qdd[7] - ws_b.solution.qdd[6]) < 1e-10);
  double worst = 0.0;
  for (const char* frame : {"ball", "l2"}) {
    INFO(frame);
    Vec6 acc_a, acc_b;
    REQUIRE(frameAcceleration(a, ws_a, q, qd, a.frameIndex(frame), Expressed::World, acc_a));
    REQUIRE(frameAcceleration(b, ws_b, qb, qdb, b.frameIndex(frame), Expressed::World, acc_b));
    CHECK((acc_a - acc_b).norm() < 1e-10);  // two sweeps over different trees: rounding only
    worst = std::max(worst, (acc_a - acc_b).norm());
  }
  std::printf("free joint mid-tree vs the subtree floating alone: |dqdd_j2| %.2g, frame accelerations %.2g\n",
              std::abs(ws_a.solution.qdd[7] - ws_b.solution.qdd[6]), worst);
}

TEST_CASE("solve: a body on a planar joint follows Newton and Euler in its plane", "[urdf][joints][solve]") {
  // Centre of mass at the joint's child origin: ẍ, ÿ = (F + m g)·(plane axis) / m and ψ̈ = n / (aᵀ I a),
  // whatever the velocities (gyroscopic torques are normal to the axis and the joint takes them).
  for (const char* axis_text : {"0 0 1", "1 0 0", "0 1 1"}) {
    INFO(axis_text);
    const Model m = loadUrdfString(planarPuck(axis_text));
    const Task task(m);
    Workspace ws(m, task);
    const Eigen::Vector3d q(0.2, -0.1, 0.6), qd(0.3, -0.4, 2.0), tau(1.5, -0.7, 0.25);
    REQUIRE(solveHybridDynamics(m, ws, q, qd, tau, task));
    // The plane's axes and normal in the world (the base is fixed: its frame is the world's).
    const double x[3] = {1, 0, 0}, y[3] = {0, 1, 0}, zero[3] = {0, 0, 0};
    const Eigen::Isometry3d origin = childPose(m, 0, zero);
    const Vec3 u = childPose(m, 0, x).translation() - origin.translation();
    const Vec3 w = childPose(m, 0, y).translation() - origin.translation();
    const Vec3 n = u.cross(w);
    Mat3 I;
    I << 0.04, 0.003, -0.002, 0.003, 0.05, 0.004, -0.002, 0.004, 0.03;  // in the puck's frame
    const Mat3 R = childPose(m, 0, q.data()).linear();                  // the puck's axes in the world
    const double mass = 1.3, I_n = n.dot(R * I * R.transpose() * n);
    const Vec3 g = task.gravity;
    CHECK(std::abs(ws.solution.qdd[0] - (tau[0] / mass + g.dot(u))) < 1e-12);
    CHECK(std::abs(ws.solution.qdd[1] - (tau[1] / mass + g.dot(w))) < 1e-12);
    CHECK(std::abs(ws.solution.qdd[2] - tau[2] / I_n) < 1e-12);
    std::printf("planar joint, axis %s: qdd against Newton-Euler in the plane %.2g %.2g %.2g\n", axis_text,
                ws.solution.qdd[0] - (tau[0] / mass + g.dot(u)), ws.solution.qdd[1] - (tau[1] / mass + g.dot(w)),
                ws.solution.qdd[2] - tau[2] / I_n);
  }
}

namespace {
// world ─slide (planar, normal `axis`)→ base ─j1 (revolute)→ l1, a tool welded to the base. The planar
// joint is the world link's only joint, so it makes a planar base; `anchored` welds a post to the world as
// well, which keeps the world a fixed base and makes the planar joint one below it (the mid-tree case).
std::string planarRoot(const std::string& axis, bool anchored) {
  return "<robot name=\"sled\"><link name=\"world\"/>" +
         (anchored ? joint("anchor", "fixed", "world", "post") + "<link name=\"post\"/>" : std::string()) +
         joint("slide", "planar", "world", "base",
               R"(<origin xyz="0.1 -0.2 0.3" rpy="0.3 -0.2 0.5"/><axis xyz=")" + axis + "\"/>") +
         link("base") + joint("weld", "fixed", "base", "tool", R"(<origin xyz="0.2 0.1 0" rpy="0.1 0 0.4"/>)") +
         link("tool", "0.01 0 0.02") +
         joint("j1", "revolute", "base", "l1", R"(<origin xyz="0 0.3 0.1"/><axis xyz="1 0 0"/>)" + kLimit) +
         link("l1") + "</robot>";
}
}  // namespace

TEST_CASE("a planar ROOT joint whose axis is not z is the planar joint below a fixed world", "[urdf][joints][solve]") {
  // The same plane either way (the joint frame turned so its z is the axis, the base link keeping the URDF's
  // orientation): every frame's pose and acceleration, q̈, RNEA and H agree; at q = 0 the base link sits where
  // the URDF's <origin> puts it, and x, y move it normal to the axis.
  double worst = 0.0;
  for (const char* axis_text : {"0 0 1", "1 0 0", "0 0 -1", "0 1 1", "-0.3 0.5 0.8"}) {
    INFO(axis_text);
    const Model a = loadUrdfString(planarRoot(axis_text, false));
    const Model b = loadUrdfString(planarRoot(axis_text, true));
    REQUIRE(a.baseType() == BaseType::Planar);
    REQUIRE(b.baseType() == BaseType::Fixed);
    REQUIRE(a.nq() == 4);
    REQUIRE(b.nq() == 4);
    REQUIRE(b.joint(0).type == JointType::Planar);
    std::istringstream in(axis_text);
    Vec3 normal;
    in >> normal.x() >> normal.y() >> normal.z();
    const Mat3 R_origin = (Eigen::AngleAxisd(0.5, Vec3::UnitZ()) * Eigen::AngleAxisd(-0.2, Vec3::UnitY()) *
                           Eigen::AngleAxisd(0.3, Vec3::UnitX()))
                              .toRotationMatrix();
    const Vec3 normal_world = R_origin * normal.normalized();  // the axis is in the joint frame
    const Task task_a(a), task_b(b);
    Workspace ws_a(a, task_a), ws_b(b, task_b);
    Eigen::Isometry3d pose;
    // At q = 0 the base link is at the URDF's <origin>; x and y move it normal to the axis.
    const Eigen::Vector4d q0 = Eigen::Vector4d::Zero();
    REQUIRE(forwardKinematics(a, ws_a, q0));
    REQUIRE(framePose(a, ws_a, q0, a.frameIndex("base"), pose));
    CHECK((pose.translation() - Vec3(0.1, -0.2, 0.3)).norm() < 1e-15);
    CHECK((pose.linear() - R_origin).norm() < 1e-14);
    for (int k = 0; k < 2; ++k) {
      Eigen::Vector4d q = q0;
      q[k] = 1.0;
      REQUIRE(forwardKinematics(a, ws_a, q));
      Eigen::Isometry3d moved;
      REQUIRE(framePose(a, ws_a, q, a.frameIndex("base"), moved));
      const Vec3 step = moved.translation() - pose.translation();
      CHECK(std::abs(step.norm() - 1.0) < 1e-14);
      CHECK(std::abs(step.dot(normal_world)) < 1e-14);
      CHECK((moved.linear() - pose.linear()).norm() < 1e-14);
    }
    std::uint64_t seed = 7;
    for (int draw = 0; draw < 20; ++draw) {
      Eigen::VectorXd q(4), qd = Eigen::VectorXd::Random(4), tau = 5.0 * Eigen::VectorXd::Random(4),
                            qdd = Eigen::VectorXd::Random(4);
      REQUIRE(randomConfiguration(a, seed, q));
      REQUIRE(solveHybridDynamics(a, ws_a, q, qd, tau, task_a));
      REQUIRE(solveHybridDynamics(b, ws_b, q, qd, tau, task_b));
      worst = std::max(worst, (ws_a.solution.qdd - ws_b.solution.qdd).cwiseAbs().maxCoeff());
      for (const char* frame : {"base", "tool", "l1"}) {
        INFO(frame);
        Eigen::Isometry3d pa, pb;
        Vec6 acc_a, acc_b;
        REQUIRE(framePose(a, ws_a, q, a.frameIndex(frame), pa));
        REQUIRE(framePose(b, ws_b, q, b.frameIndex(frame), pb));
        REQUIRE(frameAcceleration(a, ws_a, q, qd, a.frameIndex(frame), Expressed::World, acc_a));
        REQUIRE(frameAcceleration(b, ws_b, q, qd, b.frameIndex(frame), Expressed::World, acc_b));
        CHECK((pa.matrix() - pb.matrix()).cwiseAbs().maxCoeff() < 1e-14);
        worst = std::max(worst, (acc_a - acc_b).cwiseAbs().maxCoeff());
      }
      REQUIRE(inverseDynamics(a, ws_a, q, qd, qdd, task_a));
      REQUIRE(inverseDynamics(b, ws_b, q, qd, qdd, task_b));
      worst = std::max(worst, (ws_a.tau - ws_b.tau).cwiseAbs().maxCoeff());
      REQUIRE(jointSpaceInertia(a, ws_a, q));
      REQUIRE(jointSpaceInertia(b, ws_b, q));
      worst = std::max(worst, (ws_a.H - ws_b.H).cwiseAbs().maxCoeff());
    }
  }
  std::printf("planar root joint vs the same joint below a fixed world: worst difference %.2g\n", worst);
  CHECK(worst < 1e-11);  // two sweeps over the same bodies in other orders: rounding of terms up to ~10
}
