// Floating bases from URDF (issue #15): UrdfOptions::base on files without a
// root joint (models/solo12.urdf, models/simple_humanoid.urdf), a floating or
// planar root joint in the file ("world → base_link"), the root link's own
// inertia in body 0, a floating joint below the root (a free joint, issue
// #25), and the errors: a base option on a file that floats already, a planar
// root joint's axis that is not the joint frame's z.
#include <Eigen/Geometry>
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "zwang/zwang.hpp"

#include "model/split_mix64.hpp"        // the generator randomConfiguration draws from
#include "model/urdf_option_names.hpp"  // the front ends' names of the options

using namespace zwang;
using Catch::Matchers::Contains;
using zwang::internal::splitMix64;

namespace {

const std::string kModels = ZWANG_MODELS_DIR;

std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

UrdfOptions withBase(BaseType base) {
  UrdfOptions o;
  o.base = base;
  return o;
}

// The URDF text with `xml` inserted right after the <robot …> tag.
std::string insertAfterRobot(const std::string& urdf, const std::string& xml) {
  const std::size_t at = urdf.find('>', urdf.find("<robot"));
  REQUIRE(at != std::string::npos);
  return urdf.substr(0, at + 1) + "\n" + xml + urdf.substr(at + 1);
}

// A root joint from link "world" to `child`.
std::string rootJoint(const std::string& type, const std::string& child, const std::string& origin = "",
                      const std::string& axis = "") {
  return "<link name=\"world\"/><joint name=\"root_joint\" type=\"" + type +
         "\"><parent link=\"world\"/><child link=\"" + child + "\"/>" + origin + axis + "</joint>";
}

double totalMass(const Model& m) {
  double mass = 0.0;
  for (int b = 0; b < m.bodyCount(); ++b) mass += m.inertia(b).mass;
  return mass;
}

// A random state: configuration from randomConfiguration, velocities and torques uniform in [−1, 1].
struct State {
  Eigen::VectorXd q, v, tau;
};
State randomState(const Model& m, std::uint64_t seed) {
  State s;
  s.q.resize(m.nq());
  REQUIRE(randomConfiguration(m, seed, s.q));
  s.v.resize(m.nv());
  s.tau.resize(m.nv());
  for (Eigen::Index k = 0; k < m.nv(); ++k) {
    s.v[k] = 2.0 * static_cast<double>(splitMix64(seed) >> 11) * 0x1.0p-53 - 1.0;
    s.tau[k] = 2.0 * static_cast<double>(splitMix64(seed) >> 11) * 0x1.0p-53 - 1.0;
  }
  return s;
}

Eigen::VectorXd qdd(const Model& m, const State& s, const Vec3& gravity = Vec3(0, 0, -9.81)) {
  Task task(m);
  task.gravity = gravity;
  Workspace ws(m, task);
  const Status status = solveHybridDynamics(m, ws, s.q, s.v, s.tau, task);
  INFO(status.message);
  REQUIRE(status);
  return ws.solution.qdd;
}

}  // namespace

TEST_CASE("solo12 and the humanoid load with each base type", "[urdf][floating]") {
  const struct {
    const char* file;
    int dof;
    double base_link_mass;  // the root link's own <inertial> (body 0 also carries the links welded to it)
  } robots[] = {{"solo12.urdf", 12, 1.16115091}, {"simple_humanoid.urdf", 29, 0.0}};
  for (const auto& robot : robots) {
    const std::string path = kModels + "/" + robot.file;
    const Model fixed = loadUrdfFile(path);
    const Model free = loadUrdfFile(path, withBase(BaseType::Free));
    const Model planar = loadUrdfFile(path, withBase(BaseType::Planar));
    INFO(robot.file);
    CHECK(fixed.baseType() == BaseType::Fixed);
    CHECK(free.baseType() == BaseType::Free);
    CHECK(planar.baseType() == BaseType::Planar);
    for (const Model* m : {&fixed, &free, &planar}) {
      CHECK(m->dof() == robot.dof);
      CHECK(m->frames().size() == fixed.frames().size());
      CHECK(m->inertia(m->baseBody()).mass >= robot.base_link_mass);
      CHECK(totalMass(*m) == Approx(totalMass(fixed)).epsilon(1e-15));
    }
    CHECK(fixed.nq() == robot.dof);
    CHECK(fixed.nv() == robot.dof);
    CHECK(free.nq() == robot.dof + 7);
    CHECK(free.nv() == robot.dof + 6);
    CHECK(planar.nq() == robot.dof + 3);
    CHECK(planar.nv() == robot.dof + 3);
    CHECK(planar.basePlacement().E.isIdentity(0.0));
    CHECK(planar.basePlacement().r.isZero(0.0));
    std::printf("%s: %d joints; nq/nv fixed %d/%d, free %d/%d, planar %d/%d; base mass %.9g kg of %.9g kg\n",
                robot.file, fixed.dof(), fixed.nq(), fixed.nv(), free.nq(), free.nv(), planar.nq(), planar.nv(),
                free.inertia(free.baseBody()).mass, totalMass(free));
  }
  // solo12's base_link has its own inertial, and nothing is welded to it: the base body is exactly that link.
  const Model solo = loadUrdfFile(kModels + "/solo12.urdf", withBase(BaseType::Free));
  CHECK(solo.inertia(solo.baseBody()).mass == 1.16115091);
  CHECK(solo.inertia(solo.baseBody())
            .inertiaAboutCom()
            .diagonal()
            .isApprox(Vec3(0.00578574, 0.01938108, 0.02476124), 1e-14));
  // The humanoid's base_link is massless; BODY (27 kg) is welded to it.
  const Model humanoid = loadUrdfFile(kModels + "/simple_humanoid.urdf", withBase(BaseType::Free));
  CHECK(humanoid.inertia(humanoid.baseBody()).mass == 27.0);
  CHECK(humanoid.frame(humanoid.frameIndex("BODY")).body == humanoid.baseBody());
}

TEST_CASE("the root link's own inertia is body 0's, fixed base too", "[urdf][floating]") {
  const std::string solo = readText(kModels + "/solo12.urdf");
  const Model fixed = loadUrdfString(solo);
  CHECK(fixed.inertia(0).mass == 1.16115091);  // counted (the "base mass"), not in the dynamics
  // A chain off the floating base: the other legs ride on the base, so their mass is warned about.
  UrdfOptions o = withBase(BaseType::Free);
  o.tip = "FL_FOOT";
  const Model leg = loadUrdfString(solo, o);
  CHECK(leg.dof() == 3);
  bool off_chain = false;
  for (const ModelWarning& w : leg.warnings()) off_chain = off_chain || w.code == WarningCode::MassOffChain;
  CHECK(off_chain);
  o.base = BaseType::Fixed;
  const Model fixed_leg = loadUrdfString(solo, o);
  for (const ModelWarning& w : fixed_leg.warnings()) CHECK(w.code != WarningCode::MassOffChain);
}

TEST_CASE("a floating root joint in the file equals the base option", "[urdf][floating]") {
  for (const char* file : {"solo12.urdf", "simple_humanoid.urdf"}) {
    INFO(file);
    const std::string urdf = readText(kModels + "/" + file);
    const Model option = loadUrdfString(urdf, withBase(BaseType::Free));
    // The joint's origin is folded into the base pose: it changes nothing in the model.
    for (const std::string& origin :
         {std::string(), std::string(R"(<origin xyz="0.1 -0.2 0.3" rpy="0.4 0.5 0.6"/>)")}) {
      const Model root = loadUrdfString(insertAfterRobot(urdf, rootJoint("floating", "base_link", origin)));
      CHECK(root.baseType() == BaseType::Free);
      CHECK(root.nq() == option.nq());
      CHECK(root.frames().size() == option.frames().size());  // "world" is the world, not a frame
      CHECK_FALSE(root.hasFrame("world"));
      CHECK(root.frame(0).name == "base_link");
      double worst = 0.0;
      for (std::uint64_t seed = 1; seed <= 20; ++seed) {
        const State s = randomState(option, seed);
        const Eigen::VectorXd a = qdd(option, s), b = qdd(root, s);
        worst = std::max(worst, (a - b).cwiseAbs().maxCoeff());
      }
      std::printf("%s: floating root joint%s vs base option, 20 random states: max |qdd difference| %.3g\n", file,
                  origin.empty() ? "" : " (with an origin)", worst);
      CHECK(worst == 0.0);  // the same model, built the same way
    }
    // The same for a planar root joint in the world's x-y plane.
    const Model planar_option = loadUrdfString(urdf, withBase(BaseType::Planar));
    const Model planar_root =
        loadUrdfString(insertAfterRobot(urdf, rootJoint("planar", "base_link", "", R"(<axis xyz="0 0 1"/>)")));
    CHECK(planar_root.baseType() == BaseType::Planar);
    const State s = randomState(planar_option, 7);
    CHECK((qdd(planar_option, s) - qdd(planar_root, s)).cwiseAbs().maxCoeff() == 0.0);
  }
}

TEST_CASE("the model may start at the floating joint's child link, or below it", "[urdf][floating]") {
  const std::string urdf = insertAfterRobot(readText(kModels + "/solo12.urdf"), rootJoint("floating", "base_link"));
  UrdfOptions o;
  o.root = "world";
  CHECK(loadUrdfString(urdf, o).baseType() == BaseType::Free);
  o.root = "base_link";
  CHECK(loadUrdfString(urdf, o).baseType() == BaseType::Free);
  o.root = "FL_UPPER_LEG";  // below the joint: a fixed base there, or one asked for
  CHECK(loadUrdfString(urdf, o).baseType() == BaseType::Fixed);
  o.base = BaseType::Planar;
  CHECK(loadUrdfString(urdf, o).baseType() == BaseType::Planar);
  // A floating root joint to a single rigid body: no joint at all.
  const std::string box = R"(<robot name="box"><link name="world"/>
    <joint name="free" type="floating"><parent link="world"/><child link="box"/></joint>
    <link name="box"><inertial><mass value="2"/><inertia ixx="1" ixy="0" ixz="0" iyy="2" iyz="0" izz="3"/></inertial></link></robot>)";
  const Model body = loadUrdfString(box);
  CHECK(body.dof() == 0);
  CHECK(body.nq() == 7);
  CHECK(body.nv() == 6);
  CHECK(body.inertia(body.baseBody()).mass == 2.0);
  // The same body without the joint, given a base by the option.
  const std::string bare = R"(<robot name="box"><link name="box"><inertial><mass value="2"/>
    <inertia ixx="1" ixy="0" ixz="0" iyy="2" iyz="0" izz="3"/></inertial></link></robot>)";
  CHECK(loadUrdfString(bare, withBase(BaseType::Free)).nv() == 6);
  REQUIRE_THROWS_WITH(loadUrdfString(bare), Contains("no moving joint"));
}

TEST_CASE("a planar root joint: the joint frame is the plane", "[urdf][floating]") {
  // A box with its centre of mass at its origin on a plane tilted by 0.3 rad
  // about x, 0.5 m up: at rest it slides down the plane at g's component in
  // the plane, without turning.
  const double tilt = 0.3;
  const std::string box = R"(<robot name="sled"><link name="world"/>
    <joint name="slide" type="planar"><parent link="world"/><child link="sled"/>
      <origin xyz="0 0 0.5" rpy="0.3 0 0"/><axis xyz="0 0 1"/></joint>
    <link name="sled"><inertial><mass value="2"/><inertia ixx="1" ixy="0" ixz="0" iyy="2" iyz="0" izz="3"/></inertial></link></robot>)";
  const Model m = loadUrdfString(box);
  REQUIRE(m.baseType() == BaseType::Planar);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(tilt, Vec3::UnitX()).toRotationMatrix();  // plane axes in the world
  CHECK(m.basePlacement().rotationOfTarget().isApprox(R, 1e-15));
  CHECK(m.basePlacement().originOfTarget().isApprox(Vec3(0, 0, 0.5), 1e-15));
  const Vec3 g(0, 0, -9.81), n = R.col(2);
  State s{Eigen::Vector3d(0.2, -0.1, 0.7), Eigen::VectorXd::Zero(3), Eigen::VectorXd::Zero(3)};
  Task task(m);
  Workspace ws(m, task);
  REQUIRE(solveHybridDynamics(m, ws, s.q, s.v, s.tau, task));
  const Vec3 expected = g - g.dot(n) * n;
  const double e_world = (ws.solution.base_acceleration_world.head<3>() - expected).norm() +
                         ws.solution.base_acceleration_world.tail<3>().norm();
  const double e_plane =
      (ws.solution.qdd - Eigen::Vector3d((R.transpose() * expected).x(), (R.transpose() * expected).y(), 0.0)).norm();
  std::printf(
      "planar root joint (plane tilted 0.3 rad): base acceleration vs g projected on the plane %.2g (world), "
      "%.2g (plane coordinates)\n",
      e_world, e_plane);
  CHECK(e_world < 1e-14);
  CHECK(e_plane < 1e-14);
}

TEST_CASE("a free robot at rest under gravity falls at g", "[urdf][floating]") {
  for (const char* file : {"solo12.urdf", "simple_humanoid.urdf"}) {
    const Model m = loadUrdfFile(kModels + "/" + file, withBase(BaseType::Free));
    Task task(m);
    task.gravity = Vec3(0.3, -1.0, -9.81);
    Workspace ws(m, task);
    double worst = 0.0, worst_qdd = 0.0;
    for (std::uint64_t seed = 1; seed <= 20; ++seed) {
      State s = randomState(m, seed);
      s.v.setZero();
      s.tau.setZero();
      REQUIRE(solveHybridDynamics(m, ws, s.q, s.v, s.tau, task));
      worst_qdd = std::max(worst_qdd, ws.solution.qdd.tail(m.dof()).cwiseAbs().maxCoeff());
      for (int f = 0; f < static_cast<int>(m.frames().size()); ++f) {
        Vec6 a;
        REQUIRE(frameAcceleration(m, ws, s.q, s.v, f, Expressed::World, a));
        worst = std::max(worst, (a.head<3>() - task.gravity).norm() / task.gravity.norm() + a.tail<3>().norm());
      }
    }
    std::printf("%s, free base at rest, 20 random configurations: every frame falls at g to %.2g, joint |qdd| %.2g\n",
                file, worst, worst_qdd);
    CHECK(worst < 1e-11);
    CHECK(worst_qdd < 1e-11);
  }
}

TEST_CASE("floating joints off the root; errors: a base on a floating file, a planar axis", "[urdf][floating]") {
  const std::string solo = readText(kModels + "/solo12.urdf");
  // A floating joint below the root.
  std::string below = solo;
  const std::string knee = R"(<joint name="FL_KFE" type="revolute">)";
  REQUIRE(below.find(knee) != std::string::npos);
  below.replace(below.find(knee), knee.size(), R"(<joint name="FL_KFE" type="floating">)");
  // … is a free joint of the model (issue #25: test_urdf_joints).
  const Model free_knee = loadUrdfString(below, withBase(BaseType::Free));
  CHECK(free_knee.joint(free_knee.jointIndex("FL_KFE")).type == JointType::Free);
  CHECK(free_knee.nv() == 6 + 11 + 6);
  // A root link with a floating joint and another joint: not a root joint, a free joint below the fixed root.
  const std::string two = insertAfterRobot(
      solo,
      rootJoint("floating", "base_link") +
          R"(<joint name="table_joint" type="fixed"><parent link="world"/><child link="table"/></joint><link name="table"/>)");
  const Model table = loadUrdfString(two);
  CHECK(table.baseType() == BaseType::Fixed);
  CHECK(table.joint(0).name == "root_joint");
  CHECK(table.joint(0).type == JointType::Free);
  // A base option on a file that floats already.
  const std::string floating = insertAfterRobot(solo, rootJoint("floating", "base_link"));
  REQUIRE_THROWS_WITH(loadUrdfString(floating, withBase(BaseType::Free)),
                      Contains("<string>: the URDF already has a floating root joint 'root_joint' (from 'world' to "
                               "'base_link'), a free base; drop UrdfOptions::base"));
  REQUIRE_THROWS_WITH(loadUrdfString(floating, withBase(BaseType::Planar)),
                      Contains("already has a floating root joint 'root_joint'"));
  // … unless the caller accepts the file's own base of the same type.
  // With a front end's names for the options (their loader, found by argument-dependent lookup).
  zwang::internal::NamedUrdfOptions match{withBase(BaseType::Free), {}};
  match.base_may_match_file = true;
  CHECK(loadUrdfString(floating, match).baseType() == BaseType::Free);
  match.base = BaseType::Planar;
  match.names.base = "\"base\"";
  REQUIRE_THROWS_WITH(loadUrdfString(floating, match),
                      Contains("the URDF has a floating root joint 'root_joint' (from 'world' to 'base_link'), a "
                               "free base, not the planar base that \"base\" asks for"));
  // Any planar axis is the plane's normal, as below the root (test_urdf_joints: "a planar ROOT joint whose
  // axis is not z"); a missing <axis> is the URDF default, 1 0 0; a zero one is refused.
  for (const char* axis : {"1 0 0", "0 0 -1", "0 1 1", "0 0 2"}) {
    INFO(axis);
    CHECK(loadUrdfString(
              insertAfterRobot(solo, rootJoint("planar", "base_link", "", std::string("<axis xyz=\"") + axis + "\"/>")))
              .baseType() == BaseType::Planar);
  }
  CHECK(loadUrdfString(insertAfterRobot(solo, rootJoint("planar", "base_link"))).baseType() == BaseType::Planar);
  REQUIRE_THROWS_WITH(
      loadUrdfString(insertAfterRobot(solo, rootJoint("planar", "base_link", "", R"(<axis xyz="0 0 0"/>)"))),
      Contains("planar root joint 'root_joint': <axis> xyz \"0 0 0\" is zero (it must give the normal of the plane)"));
  // Friction on the base joint would be dropped: refused.
  REQUIRE_THROWS_WITH(
      loadUrdfString(insertAfterRobot(solo, rootJoint("floating", "base_link", R"(<dynamics damping="0.5"/>)"))),
      Contains("root joint 'root_joint'") && Contains("a floating base has no friction"));
}

TEST_CASE("a floating base's links are judged like moving ones", "[urdf][floating]") {
  // A point mass welded to the base: unjudged on a fixed base, a warning (an error in strict mode) when it floats.
  const std::string urdf = R"(<robot name="r"><link name="base"><inertial><mass value="1"/>
      <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
    <joint name="w" type="fixed"><parent link="base"/><child link="bad"/></joint>
    <link name="bad"><inertial><mass value="-1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
    <joint name="j1" type="continuous"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/></joint>
    <link name="l1"><inertial><origin xyz="0.5 0 0"/><mass value="1"/>
      <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link></robot>)";
  CHECK(loadUrdfString(urdf).dof() == 1);
  REQUIRE_THROWS_WITH(loadUrdfString(urdf, withBase(BaseType::Free)),
                      Contains("link 'bad'") && Contains("<mass>") && Contains("negative"));
}

TEST_CASE("contacts on the humanoid loaded bolted down warn, naming the floating base (Task::warnings)",
          "[urdf][floating]") {
  // The humanoid's URDF has no root joint: loaded as it is, its base (BODY,
  // 27 kg, welded to base_link) is bolted to the world, which then holds the
  // robot up in place of its feet. Standing on both feet (two contacts, every
  // joint held by its motor), the ground carries the whole weight only with a
  // free base (Newton: Σ f_z = m g at rest).
  const auto standing = [](const Model& m, std::vector<std::string> contacts) {
    Task task(m);
    for (const std::string& foot : contacts) task.addContact(foot, ConstraintMatrix::Identity(6, 6), Expressed::World);
    for (int j = 0; j < m.dof(); ++j) task.addJointConstraint(j);
    return task;
  };
  const Model bolted = loadUrdfFile(kModels + "/simple_humanoid.urdf");
  const Model free = loadUrdfFile(kModels + "/simple_humanoid.urdf", withBase(BaseType::Free));
  REQUIRE_FALSE(bolted.hasFloatingBase());
  REQUIRE(bolted.inertia(0).mass == 27.0);

  const Task on_feet = standing(bolted, {"l_ankle", "r_ankle"});
  REQUIRE(on_feet.warnings().size() == 1);  // once per task, not per contact
  const ModelWarning& w = on_feet.warnings()[0];
  CHECK(w.code == WarningCode::FixedBaseContact);
  CHECK(std::string(toString(w.code)) == "fixed_base_contact");
  CHECK_THAT(w.message, Contains("contact on frame 'l_ankle' of a fixed-base model whose base carries 27 kg "
                                 "(link 'base_link' and the links welded to it)"));
  for (const char* fix : {"UrdfOptions::base = BaseType::Free", "ModelBuilder::setBase",
                          "CLI \"base\": {\"type\": \"free\"}", "Python base=\"free\""})
    CHECK_THAT(w.message, Contains(fix));
  CHECK(standing(free, {"l_ankle", "r_ankle"}).warnings().empty());
  CHECK(standing(bolted, {}).warnings().empty());  // joint rows alone: an arm holding a pose
  Task reached(bolted);                            // a hand's constraint that is not a contact
  reached.addConstraint("l_wrist", ConstraintMatrix::Identity(6, 3));
  CHECK(reached.warnings().empty());
  // An arm whose base link carries no mass may touch a table without a warning.
  const Model panda = loadUrdfFile(kModels + "/panda.urdf");
  REQUIRE(panda.inertia(0).mass == 0.0);
  Task table(panda);
  table.addContact("panda_link8", ConstraintMatrix::Identity(6, 3), Expressed::World);
  CHECK(table.warnings().empty());

  // What the warning is about: the ground's vertical force on the two feet.
  const auto groundForce = [&](const Model& m) {
    Eigen::VectorXd q = Eigen::VectorXd::Zero(m.nq());
    if (m.hasFloatingBase()) q.head<7>() << 0, 0, 1, 1, 0, 0, 0;
    const int base = m.baseConfigurationSize();
    for (const auto& [joint, value] : std::vector<std::pair<std::string, double>>{{"LLEG_HIP_P", -0.12},
                                                                                  {"RLEG_HIP_P", -0.12},
                                                                                  {"LLEG_KNEE", 0.06},
                                                                                  {"RLEG_KNEE", 0.06},
                                                                                  {"LLEG_ANKLE_P", 0.06},
                                                                                  {"RLEG_ANKLE_P", 0.06}})
      q[base + m.jointIndex(joint)] = value;
    const Task task = standing(m, {"l_ankle", "r_ankle"});
    Workspace ws(m, task);
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(m.nv());
    const Status s = solveHybridDynamics(m, ws, q, zero, zero, task);
    INFO(s.message);
    REQUIRE(s);
    return ws.solution.nu[2] + ws.solution.nu[8];  // f_z of each foot (world axes, linear rows first)
  };
  const double weight = totalMass(free) * 9.81;
  const double bolted_force = groundForce(bolted), free_force = groundForce(free);
  std::printf(
      "humanoid on both feet, the ground's vertical force: bolted down %.3g N, free base %.6g N (weight %.6g N)\n",
      bolted_force, free_force, weight);
  CHECK(std::abs(free_force - weight) < 1e-9 * weight);
  CHECK(std::abs(bolted_force) < 0.01 * weight);  // the world holds it: the silent wrong answer warned about
}
