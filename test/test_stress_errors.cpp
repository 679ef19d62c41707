// Every error message of the library, produced once (docs/errors.md lists them
// with the test that produces each). Status messages of the solver entry
// points, ModelError messages of ModelBuilder, Model lookups and Task; the URDF
// loader's messages are produced by test_urdf (and the ones it does not reach,
// here). Each check asserts the code and the words of the message.
#include <cmath>
#include <functional>
#include <limits>
#include <string>

#include <catch2/catch.hpp>

#include "support/bad_inputs.hpp"
#include "zwang/zwang.hpp"

using namespace zwang;
using Catch::Contains;
using Catch::Equals;
using zwang::testing::oneDofArmModel;

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

Model panda() { return zwang::testing::pandaModel(); }

std::string modelError(const std::function<void()>& f) {
  try {
    f();
  } catch (const ModelError& e) {
    return e.what();
  }
  return "(no ModelError)";
}

RigidInertia box(double mass) {
  return RigidInertia::fromMassComInertia(mass, Vec3(0.1, 0, 0), Mat3::Identity() * 0.01);
}

Joint revolute(const std::string& name) {
  Joint j;
  j.name = name;
  return j;
}

}  // namespace

TEST_CASE("errors: solve statuses (sizes, non-finite inputs, workspace and task)", "[errors]") {
  const Model model = panda();
  const Model arm = oneDofArmModel();
  Task task(model);
  task.addConstraint("tool0", ConstraintMatrix::Identity(6, 6));
  const int w = task.addWrench("panda_link5");
  Workspace ws(model, task), small(model, 2), foreign(arm, 6);
  const Eigen::VectorXd x = Eigen::VectorXd::Zero(7), short3 = Eigen::VectorXd::Zero(3);
  Eigen::VectorXd bad = x;
  bad[2] = kNaN;

  Status s = solveHybridDynamics(model, ws, short3, x, x, task);
  CHECK(s.code == StatusCode::SizeMismatch);
  CHECK_THAT(s.message, Contains("q has 3 entries, the model has 7 joints"));
  s = solveHybridDynamics(model, ws, x, bad, x, task);
  CHECK(s.code == StatusCode::NonFinite);
  CHECK_THAT(s.message, Contains("qd[2] is nan (not finite)"));
  task.gravity[1] = kInf;
  s = solveHybridDynamics(model, ws, x, x, x, task);
  CHECK(s.code == StatusCode::NonFinite);
  CHECK_THAT(s.message, Contains("gravity holds a non-finite value (inf) at entry 1"));
  task.gravity[1] = 0.0;
  task.targets()[4] = kNaN;
  s = solveHybridDynamics(model, ws, x, x, x, task);
  CHECK_THAT(s.message, Contains("constraint targets b holds a non-finite value"));
  task.targets()[4] = 0.0;
  task.wrench(w)[0] = kNaN;
  s = solveHybridDynamics(model, ws, x, x, x, task);
  CHECK(s.code == StatusCode::NonFinite);
  CHECK_THAT(s.message, Contains("wrench 0 (on frame 'panda_link5') is not finite"));
  task.wrench(w)[0] = 0.0;
  s = solveHybridDynamics(model, small, x, x, x, task);  // makes room for the task's 6 rows
  CHECK(s);
  CHECK(small.constraintCapacity() == 6);
  s = solveHybridDynamics(model, foreign, x, x, x, task);
  CHECK(s.code == StatusCode::ModelMismatch);
  CHECK_THAT(s.message, Contains("workspace was made for 1 joints, the model has 7"));
  const Task arm_task(arm);
  s = solveHybridDynamics(model, ws, x, x, x, arm_task);
  CHECK(s.code == StatusCode::ModelMismatch);
  CHECK_THAT(s.message, Contains("task was made for another model (1 joints"));
}

TEST_CASE("errors: RNEA, CRBA, kinematics and Jacobian statuses", "[errors]") {
  const Model model = panda();
  const Model arm = oneDofArmModel();
  const Task task(model), arm_task(arm);
  Workspace ws(model, task), foreign(arm, arm_task);
  const Eigen::VectorXd x = Eigen::VectorXd::Zero(7);
  Status s = inverseDynamics(model, ws, x, x, x, arm_task);
  CHECK(s.code == StatusCode::ModelMismatch);
  CHECK_THAT(s.message, Contains("workspace or task was made for another model"));
  s = jointSpaceInertia(model, foreign, x);
  CHECK(s.code == StatusCode::ModelMismatch);
  CHECK_THAT(s.message, Contains("workspace was made for 1 joints, the model has 7"));
  s = forwardKinematics(model, foreign, x);
  CHECK(s.code == StatusCode::ModelMismatch);
  CHECK_THAT(s.message, Contains("workspace was made for 1 joints, the model has 7"));
  Eigen::MatrixXd J(6, 5);
  s = frameJacobian(model, ws, x, 1, Expressed::World, J);
  CHECK(s.code == StatusCode::SizeMismatch);
  CHECK_THAT(s.message, Contains("Jacobian output is 6x5, expected 6x7"));

  // A frame index out of range, and a workspace made for another model: the
  // kinematics accessors (issue #6) and frameJacobian say the same.
  REQUIRE(forwardKinematics(model, ws, x, x));
  Eigen::Isometry3d pose;
  Vec6 out;
  J.resize(6, 7);
  const int frames = static_cast<int>(model.frames().size());
  const std::function<Status(const Workspace&, int)> accessors[] = {
      [&](const Workspace& w, int f) { return framePose(model, w, x, f, pose); },
      [&](const Workspace& w, int f) { return frameVelocity(model, w, x, x, f, Expressed::Local, out); },
      [&](const Workspace& w, int f) { return frameAcceleration(model, w, x, x, f, Expressed::World, out); }};
  for (const auto& accessor : accessors) {
    s = accessor(ws, frames);
    CHECK(s.code == StatusCode::ModelMismatch);
    CHECK_THAT(s.message, Contains("frame index 10 is not a frame of this model (it has 10 frames)"));
    s = accessor(ws, -1);
    CHECK(s.code == StatusCode::ModelMismatch);
    CHECK_THAT(s.message, Contains("frame index -1 is not a frame of this model (it has 10 frames)"));
    s = accessor(foreign, 1);
    CHECK(s.code == StatusCode::ModelMismatch);
    CHECK_THAT(s.message, Contains("workspace was made for 1 joints, the model has 7"));
  }
  s = frameJacobian(model, ws, x, -1, Expressed::Local, J);
  CHECK(s.code == StatusCode::ModelMismatch);
  CHECK_THAT(s.message, Contains("frame index -1 is not a frame of this model (it has 10 frames)"));
}

TEST_CASE("errors: friction options and the infeasible task", "[errors]") {
  const Model model = panda();
  const Task task(model);
  Workspace ws(model, task);
  const Eigen::VectorXd x = Eigen::VectorXd::Zero(7);
  for (const zwang::testing::BadFrictionOption& bad : zwang::testing::badFrictionOptions()) {
    const Status s = solveWithFriction(model, ws, x, x, x, task, bad.options);
    CHECK(s.code == StatusCode::BadOption);
    CHECK_THAT(s.message, Contains(bad.message));
  }

  // The report's arm on its upper limit, asked to accelerate into it.
  zwang::testing::IntoUpperLimit into;
  const Status s = solveWithFriction(into.arm, into.ws, into.q, into.zero, into.zero, into.task);
  CHECK(s.code == StatusCode::Infeasible);
  CHECK_THAT(s.message, Contains(into.message));
  CHECK(into.ws.solution.qdd.allFinite());
}

TEST_CASE("errors: Degenerate, a joint with no inertia to move", "[errors]") {
  // A massless body whose only load is a second joint about the same axis
  // through the same point: the second joint absorbs every rotation of the
  // first, so the first has D = 0 (no rotor inertia on either).
  ModelBuilder builder("degenerate", "base");
  builder.addJoint(revolute("first"), "link1", RigidInertia{});
  builder.addJoint(revolute("second"), "link2",
                   RigidInertia::fromMassComInertia(1.0, Vec3::Zero(), Mat3::Identity() * 0.01));
  const Model model = builder.build();
  const Task task(model);
  Workspace ws(model, task);
  const Eigen::VectorXd x = Eigen::VectorXd::Zero(2);
  const Status s = solveHybridDynamics(model, ws, x, x, x, task);
  CHECK(s.code == StatusCode::Degenerate);
  CHECK_THAT(s.message, Contains("joint 'first' has no inertia to move here (D = "));
}

TEST_CASE("errors: ModelBuilder and model lookups", "[errors]") {
  const Model model = panda();
  CHECK_THAT(modelError([&] { model.jointIndex("elbow"); }),
             Contains("model 'panda' has no moving joint 'elbow' (joints: ") && Contains("panda_joint1"));
  CHECK_THAT(modelError([&] { model.frameIndex("hand"); }),
             Contains("model 'panda' has no frame 'hand' (frames: ") && Contains("tool0"));

  const auto addJoint = [](const Joint& j, const RigidInertia& inertia) {
    return modelError([&] { ModelBuilder("m", "base").addJoint(j, "link1", inertia); });
  };
  Joint j = revolute("j1");
  CHECK_THAT(addJoint(j, RigidInertia::fromMassComInertia(kNaN, Vec3::Zero(), Mat3::Identity())),
             Contains("link 'link1': mass is not finite"));
  CHECK_THAT(addJoint(j, RigidInertia::fromMassComInertia(1.0, Vec3(kInf, 0, 0), Mat3::Identity())),
             Contains("centre of mass is not finite"));
  CHECK_THAT(addJoint(j, RigidInertia::fromMassComInertia(1.0, Vec3::Zero(), Mat3::Identity() * kNaN)),
             Contains("inertia is not finite"));
  CHECK_THAT(addJoint(j, RigidInertia::fromMassComInertia(-1.0, Vec3::Zero(), Mat3::Identity())),
             Contains("mass -1.000000 is negative"));
  Mat3 skew = Mat3::Identity();
  skew(0, 1) = 0.5;
  CHECK_THAT(addJoint(j, RigidInertia::fromMassComInertia(1.0, Vec3::Zero(), skew)),
             Contains("inertia is not symmetric"));
  CHECK_THAT(addJoint(j, RigidInertia::fromMassComInertia(1.0, Vec3::Zero(), Vec3(1, 1, -0.5).asDiagonal())),
             Contains("link 'link1': inertia is not positive semi-definite: principal moment -0.5 kg·m² is negative"));
  CHECK_THAT(addJoint(j, RigidInertia::fromMassComInertia(2e300, Vec3::Zero(), Mat3::Identity())),
             Contains("link 'link1': mass 2e+300 kg is above 1e+12 kg"));
  CHECK_THAT(addJoint(j, RigidInertia::fromMassComInertia(1.0, Vec3::Zero(), Mat3::Identity() * 1e13)),
             Contains("link 'link1': inertia entry 1e+13 kg·m² is above 1e+12 kg·m²"));

  CHECK_THAT(addJoint(revolute(""), box(1.0)), Contains("a moving joint needs a name"));
  CHECK_THAT(modelError([] {
               ModelBuilder b("m", "base");
               b.addJoint(revolute("j1"), "link1", box(1.0)).addJoint(revolute("j1"), "link2", box(1.0));
             }),
             Contains("joint 'j1': a joint of that name exists already"));
  CHECK_THAT(modelError([] { ModelBuilder("m", "base").addJoint(revolute("j1"), "base", box(1.0)); }),
             Contains("joint 'j1': frame 'base' exists already"));
  // A tree is built depth first: a branch off the base is fine, but going back
  // into a completed branch (link1 after link2 has started another) is not.
  CHECK(modelError([] {
          ModelBuilder b("m", "base");
          b.addJoint(revolute("j1"), "link1", box(1.0)).addJoint(revolute("j2"), "link2", box(1.0), "base");
          (void)b.build();
        }) == "(no ModelError)");
  CHECK_THAT(modelError([] {
               ModelBuilder b("m", "base");
               b.addJoint(revolute("j1"), "link1", box(1.0)).addJoint(revolute("j2"), "link2", box(1.0), "base");
               b.addJoint(revolute("j3"), "link3", box(1.0), "link1");
             }),
             Contains("joint 'j3': parent frame 'link1' is on a branch that is already complete (add joints depth "
                      "first: the parent must be the last body added or one of its ancestors)"));
  j = revolute("j1");
  j.axis = Vec3::Zero();
  CHECK_THAT(addJoint(j, box(1.0)), Contains("joint 'j1': axis must be a finite non-zero vector"));
  j = revolute("j1");
  j.placement = Transform::translation(Vec3(kNaN, 0, 0));
  CHECK_THAT(addJoint(j, box(1.0)), Contains("joint 'j1': origin is not finite"));
  j = revolute("j1");
  j.viscous_friction = kInf;
  CHECK_THAT(addJoint(j, box(1.0)), Contains("joint 'j1': viscous friction is not finite"));
  j = revolute("j1");
  j.rotor_inertia = -0.5;
  CHECK_THAT(addJoint(j, box(1.0)), Contains("joint 'j1': rotor inertia -0.500000 is negative"));
  j = revolute("j1");
  j.lower = kNaN;
  CHECK_THAT(addJoint(j, box(1.0)), Contains("joint 'j1': limit is NaN"));
  j = revolute("j1");
  j.lower = 1.0;
  j.upper = -1.0;
  CHECK_THAT(addJoint(j, box(1.0)), Contains("joint 'j1': lower limit exceeds upper limit"));
  j = revolute("j1");
  j.effort_limit = -1.0;
  CHECK_THAT(addJoint(j, box(1.0)), Contains("joint 'j1': effort limit must be non-negative"));
  j = revolute("j1");
  j.velocity_limit = -1.0;
  CHECK_THAT(addJoint(j, box(1.0)), Contains("joint 'j1': velocity limit must be non-negative"));

  CHECK_THAT(modelError([] { ModelBuilder("m", "base").addFixedFrame("base", "base", Transform{}); }),
             Contains("link 'base': a frame of that name exists already"));
  CHECK_THAT(modelError([] {
               ModelBuilder("m", "base").addFixedFrame("tool", "base", Transform::translation(Vec3(0, kInf, 0)));
             }),
             Contains("link 'tool': origin of its fixed joint is not finite"));
  CHECK_THAT(modelError([&] { ModelBuilder(model).setRotorInertia("panda_joint1", -1.0); }),
             Contains("joint 'panda_joint1': rotor inertia must be finite and non-negative"));
  CHECK_THAT(modelError([&] { ModelBuilder(model).setFriction("panda_joint2", 1.0, kNaN, 0.0); }),
             Contains("joint 'panda_joint2': breakaway, kinetic and viscous friction must be finite and non-negative"));
  CHECK_THAT(modelError([] { ModelBuilder("m", "base").addJoint(revolute("j1"), "link1", RigidInertia{}).build(); }),
             Contains("link 'link1': zero mass on a moving body with nothing beyond it (joint 'j1'"));
}

TEST_CASE("errors: Task construction", "[errors]") {
  const Model model = panda();
  Task task(model);
  std::string frames;  // every candidate, in the model's order
  for (const Frame& f : model.frames()) frames += (frames.empty() ? "'" : ", '") + f.name + "'";
  const std::string unknown = "task: the model has no frame 'hand' (frames: " + frames + ")";
  CHECK(frames.find("'panda_link0', 'panda_link1'") != std::string::npos);
  CHECK_THAT(modelError([&] { task.addConstraint("hand", ConstraintMatrix::Identity(6, 1)); }), Equals(unknown));
  CHECK_THAT(modelError([&] { task.addContact("hand", ConstraintMatrix::Identity(6, 1)); }), Equals(unknown));
  CHECK_THAT(modelError([&] { task.addWrench("hand"); }), Equals(unknown));
  CHECK_THAT(modelError([&] { task.addConstraint(99, ConstraintMatrix::Identity(6, 1)); }),
             Contains("task: frame index 99 out of range"));
  CHECK_THAT(modelError([&] { task.addConstraint("tool0", ConstraintMatrix(6, 0)); }),
             Contains("task: a constraint needs at least one column"));
  ConstraintMatrix bad = ConstraintMatrix::Identity(6, 1);
  bad(3, 0) = kNaN;
  CHECK_THAT(modelError([&] { task.addConstraint("tool0", bad); }),
             Contains("task: constraint matrix on frame 'tool0' is not finite"));
  CHECK_THAT(modelError([&] { task.addWrench(-1); }), Contains("task: frame index -1 out of range"));
}

namespace {
// A two-joint URDF with `transmissions` appended inside <robot>.
std::string urdfWith(const std::string& transmissions) {
  return R"(<?xml version="1.0"?>
<robot name="r" xmlns:drake="http://drake.mit.edu">
  <link name="base"/>
  <link name="l1"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <link name="l2"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
  <joint name="j1" type="continuous"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/></joint>
  <joint name="j2" type="continuous"><parent link="l1"/><child link="l2"/><origin xyz="1 0 0"/><axis xyz="0 0 1"/></joint>
)" + transmissions +
         "\n</robot>\n";
}

std::string transmission(const std::string& name, const std::string& joints, const std::string& actuators) {
  return "<transmission name=\"" + name + "\">" + joints + actuators + "</transmission>";
}

std::string urdfError(const std::string& xml) {
  return modelError([&] { loadUrdfString(xml); });
}
}  // namespace

TEST_CASE("errors: URDF <transmission> rotor inertias (the messages test_urdf does not reach)", "[errors]") {
  const std::string j1 = "<joint name=\"j1\"/>", j2 = "<joint name=\"j2\"/>";
  const auto actuator = [](const std::string& name, const std::string& tags) {
    return "<actuator name=\"" + name + "\">" + tags + "</actuator>";
  };
  REQUIRE(loadUrdfString(urdfWith(transmission("t", j1, actuator("m", "<drake:rotor_inertia value=\"0.5\"/>"))))
              .joint(0)
              .rotor_inertia == 0.5);  // the template itself loads
  CHECK_THAT(urdfError(urdfWith(transmission("t", j1, actuator("m", "<drake:rotor_inertia/>")))),
             Contains("<string>: transmission 't': <actuator> 'm'") &&
                 Contains("<drake:rotor_inertia> has no value attribute"));
  CHECK_THAT(urdfError(urdfWith(transmission("t", j1, actuator("m", "<drake:rotor_inertia value=\"heavy\"/>")))),
             Contains("<drake:rotor_inertia> value \"heavy\" is not a number"));
  CHECK_THAT(urdfError(urdfWith(transmission("t", j1, actuator("m", "<drake:gear_ratio value=\"1 2\"/>")))),
             Contains("<drake:gear_ratio> value \"1 2\" is not a number"));
  CHECK_THAT(urdfError(urdfWith(transmission("t", j1, actuator("m", "<drake:rotor_inertia value=\"inf\"/>")))),
             Contains("<drake:rotor_inertia> value \"inf\" is not finite"));
  CHECK_THAT(urdfError(urdfWith(transmission("t", j1, actuator("m", "<drake:rotor_inertia value=\"-2\"/>")))),
             Contains("<drake:rotor_inertia> value -2 is negative"));
  CHECK_THAT(urdfError(urdfWith(transmission("t", j1,
                                             actuator("m1", "<drake:rotor_inertia value=\"1\"/>") +
                                                 actuator("m2", "<drake:rotor_inertia value=\"1\"/>")))),
             Contains("transmission 't': more than one <actuator> has a <drake:rotor_inertia>"));
  CHECK_THAT(urdfError(urdfWith(transmission("t", j1 + j2, actuator("m", "<drake:rotor_inertia value=\"1\"/>")))),
             Contains("transmission 't': a <drake:rotor_inertia> needs exactly one <joint name=") &&
                 Contains("found 2"));
  CHECK_THAT(urdfError(urdfWith(
                 transmission("t", "<joint name=\"j7\"/>", actuator("m", "<drake:rotor_inertia value=\"1\"/>")))),
             Contains("transmission 't': <joint> 'j7' is not a joint of the URDF"));
  CHECK_THAT(urdfError(urdfWith(transmission("t", j1, actuator("m", "<drake:rotor_inertia value=\"1\"/>")) +
                                transmission("u", j1, actuator("n", "<drake:rotor_inertia value=\"2\"/>")))),
             Contains("transmission 'u': joint 'j1' already has a rotor inertia from another transmission"));
}
