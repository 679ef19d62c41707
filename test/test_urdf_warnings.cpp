// Doubtful but usable URDF data loads with a warning; non-physical data fails
// naming the real cause; strict mode refuses what would be warned about.
// Each case writes its own URDF (a one- or two-joint arm) so the figures at
// stake are in the test.
#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <string>

#include "support/dense_reference.hpp"
#include "support/random_problem.hpp"
#include "support/urdf_writer.hpp"
#include "zwang/zwang.hpp"

using Catch::Contains;
using namespace zwang;
using namespace zwang::testing;

namespace {

// base --j1 (revolute about z)--> l1 with this <inertial> body; `extra` inside <robot>.
std::string arm(const std::string& mass, const std::string& inertia, const std::string& com = "0.5 0 0",
                const std::string& extra = "",
                const std::string& limit = R"(lower="-2" upper="2" effort="10" velocity="3")") {
  return R"(<robot name="arm"><link name="base"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit )" +
         limit + R"(/></joint>
  <link name="l1"><inertial><origin xyz=")" +
         com + R"("/><mass value=")" + mass + R"("/>
    <inertia )" +
         inertia + R"(/></inertial></link>)" + extra + "</robot>";
}

std::string diagonal(const std::string& ixx, const std::string& iyy, const std::string& izz) {
  return "ixx=\"" + ixx + "\" ixy=\"0\" ixz=\"0\" iyy=\"" + iyy + "\" iyz=\"0\" izz=\"" + izz + "\"";
}

UrdfOptions strict() {
  UrdfOptions o;
  o.strict = true;
  return o;
}

// The warning codes of a model, in order.
std::vector<WarningCode> codes(const Model& m) {
  std::vector<WarningCode> out;
  for (const ModelWarning& w : m.warnings()) out.push_back(w.code);
  return out;
}

using Codes = std::vector<WarningCode>;

}  // namespace

TEST_CASE("semi-definite inertias load: point mass, thin rod, tiny inertia far from the origin", "[urdf][warnings]") {
  SECTION("all-zero inertia with mass: a point mass, warned") {
    const Model m = loadUrdfString(arm("2", diagonal("0", "0", "0")));
    REQUIRE(codes(m) == Codes{WarningCode::PointMass});
    CHECK_THAT(m.warnings()[0].message, Contains("<string>: link 'l1': a point mass") && Contains("mass 2 kg"));
    CHECK(m.inertia(1).Ibar(2, 2) == Approx(2 * 0.25));  // m·|c|² about the joint
    REQUIRE_THROWS_WITH(loadUrdfString(arm("2", diagonal("0", "0", "0")), strict()),
                        Contains("<string>: refused in strict mode (1 warning): link 'l1': a point mass"));
  }
  SECTION("a thin rod (one zero moment) is a real body: no warning") {
    const Model m = loadUrdfString(arm("1", diagonal("0", "0.08", "0.08")));
    CHECK(m.warnings().empty());
    CHECK_NOTHROW(loadUrdfString(arm("1", diagonal("0", "0.08", "0.08")), strict()));
  }
  SECTION("2 kg, COM at 0.32 m, I = diag(1e-18, 2e-18, 2.5e-18): the origin form loses I to rounding") {
    // m·|c|² = 0.2 kg·m²; its rounding (~1e-17) dwarfs I, so the builder's
    // re-check sees moments of either sign at 1e-17: a point mass.
    const Model m = loadUrdfString(arm("2", diagonal("1e-18", "2e-18", "2.5e-18"), "0.32 0 0"));
    CHECK(codes(m) == Codes{WarningCode::PointMass});
    CHECK(m.inertia(1).mass == 2.0);
    // Through ModelBuilder directly, the same.
    Joint j;
    j.name = "j1";
    const RigidInertia I =
        RigidInertia::fromMassComInertia(2.0, Vec3(0.32, 0, 0), Vec3(1e-18, 2e-18, 2.5e-18).asDiagonal());
    const Model built = ModelBuilder("m", "base").addJoint(j, "l1", I).build();
    CHECK(codes(built) == Codes{WarningCode::PointMass});
  }
  SECTION("a rounding-level negative moment is zero") {
    const Model m = loadUrdfString(arm("1", diagonal("-1e-17", "0.08", "0.08")));
    CHECK(m.warnings().empty());
  }
}

TEST_CASE("placeholder inertia and triangle-inequality violations are warned, strict refuses", "[urdf][warnings]") {
  SECTION("the 1e-6 placeholder on a 2 kg link: denser than osmium") {
    const std::string xml = arm("2", diagonal("1e-6", "1e-6", "1e-6"));
    const Model m = loadUrdfString(xml);
    REQUIRE(codes(m) == Codes{WarningCode::PlaceholderInertia});
    CHECK_THAT(m.warnings()[0].message, Contains("link 'l1': inertia too small for the mass") && Contains("osmium"));
    REQUIRE_THROWS_WITH(loadUrdfString(xml, strict()), Contains("strict mode") && Contains("link 'l1'"));
    // The same moments on a 1 g link are plausible (a 1 cm part).
    CHECK(loadUrdfString(arm("0.001", diagonal("1e-6", "1e-6", "1e-6"))).warnings().empty());
  }
  SECTION("violations from 1e-9 to 10 kg·m² are warned; rounding-level ones are not") {
    for (const char* izz : {"2.000000001", "2.001", "2.5", "12"}) {
      INFO("izz = " << izz);
      const Model m = loadUrdfString(arm("1", diagonal("1", "1", izz)));
      REQUIRE(codes(m) == Codes{WarningCode::TriangleInequality});
      CHECK_THAT(m.warnings()[0].message, Contains("link 'l1': inertia violates the triangle inequality, 1 + 1 < "));
      REQUIRE_THROWS_WITH(loadUrdfString(arm("1", diagonal("1", "1", izz)), strict()), Contains("triangle inequality"));
    }
    CHECK(loadUrdfString(arm("1", diagonal("1", "1", "2.0000000000000004"))).warnings().empty());  // 1 ulp
  }
}

TEST_CASE("non-physical inertias and masses fail naming the cause", "[urdf][errors]") {
  REQUIRE_THROWS_WITH(loadUrdfString(arm("1", diagonal("1", "1", "-0.001"))),
                      Contains("<string>: link 'l1': inertia is not positive semi-definite: principal moment -0.001 "
                               "kg·m² is negative"));
  REQUIRE_THROWS_WITH(loadUrdfString(arm("1e300", diagonal("1", "1", "1"))),
                      Contains("<string>: link 'l1': <inertial> <mass> value 1e+300 kg is above 1e+12 kg") &&
                          !Contains("positive"));
  REQUIRE_THROWS_WITH(loadUrdfString(arm("1", diagonal("1e300", "1e300", "1e300"))),
                      Contains("link 'l1': inertia entry 1e+300 kg·m² is above 1e+12 kg·m²") && !Contains("positive"));
}

TEST_CASE("links welded to the fixed base are not judged, whichever link is the root", "[urdf][warnings]") {
  // world (negative mass, negative inertia) -fixed-> base -j1-> l1.
  const std::string xml = R"(<robot name="r">
    <link name="world"><inertial><mass value="-3"/><inertia ixx="-1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
    <joint name="w" type="fixed"><parent link="world"/><child link="base"/></joint>
    <link name="base"><inertial><mass value="1"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="5"/></inertial></link>
    <joint name="j1" type="continuous"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/></joint>
    <link name="l1"><inertial><origin xyz="0.5 0 0"/><mass value="1"/>
      <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link></robot>)";
  for (const char* root : {"", "world", "base"}) {
    INFO("root '" << root << "'");
    UrdfOptions o = strict();
    o.root = root;
    const Model m = loadUrdfString(xml, o);
    CHECK(m.warnings().empty());
    CHECK(m.dof() == 1);
    CHECK(m.inertia(1).mass == 1.0);
  }
  // The same flaw on a moving body fails, naming it.
  const std::string moving = R"(<robot name="r"><link name="base"/>
    <joint name="j1" type="continuous"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/></joint>
    <link name="l1"><inertial><origin xyz="0.5 0 0"/><mass value="1"/>
      <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
    <joint name="w" type="fixed"><parent link="l1"/><child link="bad"/></joint>
    <link name="bad"><inertial><mass value="1"/><inertia ixx="-1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link></robot>)";
  REQUIRE_THROWS_WITH(loadUrdfString(moving), Contains("link 'bad': inertia is not positive semi-definite"));
}

TEST_CASE("placeholder limits are no limits, with a warning", "[urdf][warnings]") {
  const std::string xml =
      arm("1", diagonal("0.1", "0.1", "0.1"), "0.5 0 0", "", R"(lower="0" upper="0" effort="0" velocity="0")");
  const Model m = loadUrdfString(xml);
  REQUIRE(codes(m) == Codes{WarningCode::PlaceholderLimits});
  CHECK_THAT(m.warnings()[0].message, Contains("<string>: joint 'j1': placeholder <limit lower=\"0\" upper=\"0\""));
  CHECK(m.joint(0).lower == -std::numeric_limits<double>::infinity());
  CHECK(m.joint(0).upper == std::numeric_limits<double>::infinity());
  CHECK(m.joint(0).effort_limit == std::numeric_limits<double>::infinity());
  REQUIRE_THROWS_WITH(loadUrdfString(xml, strict()), Contains("placeholder <limit"));
  // Equal bounds with an effort are a real (locked) joint: kept.
  const Model locked = loadUrdfString(
      arm("1", diagonal("0.1", "0.1", "0.1"), "0.5 0 0", "", R"(lower="0.3" upper="0.3" effort="5" velocity="0")"));
  CHECK(locked.warnings().empty());
  CHECK(locked.joint(0).lower == 0.3);
}

TEST_CASE("the URDF has no moving joint", "[urdf][errors]") {
  const std::string xml = R"(<robot name="r"><link name="a"/><joint name="w" type="fixed"><parent link="a"/>
    <child link="b"/></joint><link name="b"/></robot>)";
  REQUIRE_THROWS_WITH(loadUrdfString(xml), Contains("<string>: the URDF has no moving joint (all 1 joints are fixed)"));
}

namespace {

// base -j1-> l1 -j2-> hand -finger (prismatic)-> finger -tip_joint (fixed)-> pad.
ChainSpec armWithFinger() {
  ChainSpec spec;
  spec.name = "gripper_arm";
  auto link = [](const char* name, double mass, const Vec3& com, const Vec3& moments) {
    LinkSpec l;
    l.name = name;
    l.mass = mass;
    l.com = com;
    l.inertia = moments.asDiagonal();
    return l;
  };
  auto joint = [](const char* name, const char* type, const Vec3& xyz, const Vec3& axis) {
    JointSpec j;
    j.name = name;
    j.type = type;
    j.xyz = xyz;
    j.axis = axis;
    j.lower = -2;
    j.upper = 2;
    j.effort = 50;
    j.velocity = 2;
    return j;
  };
  spec.links = {link("base", 0, Vec3::Zero(), Vec3::Zero()), link("l1", 2, Vec3(0, 0, 0.2), Vec3(0.02, 0.02, 0.01)),
                link("hand", 0.7, Vec3(0.05, 0, 0.02), Vec3(0.002, 0.003, 0.003)),
                link("finger", 0.3, Vec3(0.0, 0.02, 0.03), Vec3(0.0004, 0.0003, 0.0002)),
                link("pad", 0.1, Vec3(0.01, 0, 0), Vec3(0.0001, 0.0001, 0.0001))};
  spec.joints = {joint("j1", "revolute", Vec3(0, 0, 0.1), Vec3(0, 1, 0)),
                 joint("j2", "revolute", Vec3(0, 0, 0.4), Vec3(1, 0, 0)),
                 joint("finger_joint", "prismatic", Vec3(0.1, 0, 0.05), Vec3(0, 1, 0)),
                 joint("pad_joint", "fixed", Vec3(0, 0.05, 0.05), Vec3(0, 0, 1))};
  return spec;
}

}  // namespace

TEST_CASE("mass beyond the tip: warned, or attached as a payload matching the dense reference", "[urdf][warnings]") {
  const ChainSpec spec = armWithFinger();
  const std::string xml = toUrdf(spec);
  UrdfOptions to_hand;
  to_hand.tip = "hand";

  const Model ignored = loadUrdfString(xml, to_hand);
  REQUIRE(codes(ignored) == Codes{WarningCode::MassBeyondTip});
  CHECK_THAT(ignored.warnings()[0].message,
             Contains("<string>: 2 links ('finger', 'pad', 0.4 kg in all) behind moving joint 'finger_joint' "
                      "beyond the tip 'hand'") &&
                 Contains("UrdfOptions::attach_beyond_tip"));
  UrdfOptions strict_to_hand = to_hand;
  strict_to_hand.strict = true;
  REQUIRE_THROWS_WITH(loadUrdfString(xml, strict_to_hand), Contains("strict mode") && Contains("beyond the tip"));

  UrdfOptions attach = to_hand;
  attach.attach_beyond_tip = true;
  const Model payload = loadUrdfString(xml, attach);
  REQUIRE(payload.dof() == 2);
  REQUIRE(codes(payload) == Codes{WarningCode::PayloadAttached});
  CHECK(payload.inertia(2).mass == Approx(0.7 + 0.3 + 0.1));
  CHECK(payload.hasFrame("pad"));
  UrdfOptions strict_attach = attach;
  strict_attach.strict = true;  // the payload note reports the user's own choice: not refused
  CHECK(loadUrdfString(xml, strict_attach).dof() == 2);

  // Holding torques (q̇ = q̈ = 0) and full inverse dynamics: the dense
  // reference of the whole 3-dof chain with the finger at 0, first two entries.
  std::mt19937_64 rng(1616);
  std::uniform_real_distribution<double> draw(-1.5, 1.5);
  const Task task(payload);
  Workspace ws(payload, task);
  double worst = 0.0, worst_ignored = 0.0;
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector2d q(draw(rng), draw(rng));
    const Eigen::Vector2d qd = trial < 10 ? Eigen::Vector2d::Zero() : Eigen::Vector2d(draw(rng), draw(rng));
    const Eigen::Vector2d qdd = trial < 10 ? Eigen::Vector2d::Zero() : Eigen::Vector2d(draw(rng), draw(rng));
    const Eigen::Vector3d q3(q[0], q[1], 0.0), qd3(qd[0], qd[1], 0.0), qdd3(qdd[0], qdd[1], 0.0);
    const Eigen::VectorXd dense = denseInverseDynamics(spec, q3, qd3, qdd3, task.gravity).head(2);
    REQUIRE(inverseDynamics(payload, ws, q, qd, qdd, task));
    worst = std::max(worst, relativeError(ws.tau, dense));
    const Task ignored_task(ignored);
    Workspace ignored_ws(ignored, ignored_task);
    REQUIRE(inverseDynamics(ignored, ignored_ws, q, qd, qdd, ignored_task));
    worst_ignored = std::max(worst_ignored, relativeError(ignored_ws.tau, dense));
  }
  CHECK(worst < 1e-12);
  CHECK(worst_ignored > 1e-2);  // the hand's fingers weigh: ignoring them is visibly wrong
}

TEST_CASE("point-mass and thin-rod chains agree with the dense reference", "[urdf][warnings]") {
  ChainSpec spec = armWithFinger();
  spec.links.pop_back();
  spec.joints.pop_back();
  spec.links[1].inertia = Vec3(0.0, 0.03, 0.03).asDiagonal();  // a thin rod along x
  spec.links[2].inertia.setZero();                             // a point mass (COM off every axis)
  spec.links[3].inertia.setZero();
  const Model model = modelFromSpec(spec);
  REQUIRE(model.dof() == 3);
  CHECK(codes(model) == (Codes{WarningCode::PointMass, WarningCode::PointMass}));
  std::mt19937_64 rng(160);
  double worst = 0.0;
  int compared = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const DynamicsInput in = randomProblem(rng, spec);
    const DenseResult ref = denseDynamics(spec, in);
    if (!wellPosed(ref, in)) continue;
    ++compared;
    const Task task = taskFromInput(model, in);
    Workspace ws(model, task);
    REQUIRE(solveHybridDynamics(model, ws, in.q, in.qd, in.tau, task));
    worst = std::max({worst, relativeError(ws.solution.qdd, ref.qdd), relativeError(ws.solution.nu, ref.nu)});
  }
  INFO(compared << " of 200 draws well posed, worst relative error " << worst);
  CHECK(compared >= 50);  // the comparison is not vacuous (a 3-dof chain cannot meet many of up to 6 random rows)
  CHECK(worst < 1e-9);
}

TEST_CASE("urdfdom's warnings become model warnings, once each", "[urdf][warnings]") {
  const std::string visual = R"(<link name="l2"><visual><geometry><box size="0.1 0.1 0.1"/></geometry>
      <material name="no_such_material"/></visual></link>
    <joint name="w" type="fixed"><parent link="l1"/><child link="l2"/></joint>)";
  const Model m = loadUrdfString(arm("1", diagonal("0.1", "0.1", "0.1"), "0.5 0 0", visual));
  REQUIRE(codes(m) == Codes{WarningCode::Urdfdom});
  CHECK_THAT(m.warnings()[0].message, Contains("<string>: urdfdom: ") && Contains("no_such_material"));
  REQUIRE_THROWS_WITH(loadUrdfString(arm("1", diagonal("0.1", "0.1", "0.1"), "0.5 0 0", visual), strict()),
                      Contains("strict mode") && Contains("no_such_material"));
}

TEST_CASE("a payload joint locked at a given position", "[urdf][warnings]") {
  const ChainSpec spec = armWithFinger();
  UrdfOptions o;
  o.tip = "hand";
  o.attach_beyond_tip = true;
  o.locked_positions["finger_joint"] = 0.04;
  const Model m = loadUrdfString(toUrdf(spec), o);
  const Task task(m);
  Workspace ws(m, task);
  const Eigen::Vector2d q(0.3, -0.7);
  REQUIRE(inverseDynamics(m, ws, q, Eigen::Vector2d::Zero(), Eigen::Vector2d::Zero(), task));
  const Eigen::VectorXd dense = denseInverseDynamics(spec, Eigen::Vector3d(0.3, -0.7, 0.04), Eigen::Vector3d::Zero(),
                                                     Eigen::Vector3d::Zero(), task.gravity)
                                    .head(2);
  CHECK(relativeError(ws.tau, dense) < 1e-12);
  o.locked_positions = {{"j2", 0.1}};
  REQUIRE_THROWS_WITH(loadUrdfString(toUrdf(spec), o),
                      Contains("locked position for joint 'j2' (0.1): not a finite position of a moving joint beyond "
                               "the tip (those joints: 'finger_joint')"));
}

TEST_CASE("world is the root link's frame: a root turned +90 deg about x needs gravity (0, -9.81, 0)",
          "[urdf][conventions]") {
  // docs/conventions.md, "Gravity": the same arm loaded from the upright
  // `world` and from the turned `mount` holds with the same torques when
  // gravity is given in the root's axes.
  const std::string xml = R"(<robot name="tilted"><link name="world"/>
    <joint name="mount_joint" type="fixed"><parent link="world"/><child link="mount"/>
      <origin xyz="0 0 0.3" rpy="1.5707963267948966 0 0"/></joint>
    <link name="mount"/>
    <joint name="j1" type="revolute"><parent link="mount"/><child link="l1"/><axis xyz="1 0 0"/>
      <limit lower="-3" upper="3" effort="50" velocity="2"/></joint>
    <link name="l1"><inertial><origin xyz="0.1 0.2 0.05"/><mass value="1.5"/>
      <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.03"/></inertial></link>
    <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0 0.4 0"/><axis xyz="0 0 1"/>
      <limit lower="-3" upper="3" effort="50" velocity="2"/></joint>
    <link name="l2"><inertial><origin xyz="0.2 0 0"/><mass value="0.8"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link></robot>)";
  UrdfOptions from_mount;
  from_mount.root = "mount";
  const Model upright = loadUrdfString(xml), turned = loadUrdfString(xml, from_mount);
  Task upright_task(upright), turned_task(turned);
  turned_task.gravity = Vec3(0.0, -9.81, 0.0);
  Workspace upright_ws(upright, upright_task), turned_ws(turned, turned_task);
  const Eigen::Vector2d q(0.4, -0.9), zero = Eigen::Vector2d::Zero();
  REQUIRE(inverseDynamics(upright, upright_ws, q, zero, zero, upright_task));
  REQUIRE(inverseDynamics(turned, turned_ws, q, zero, zero, turned_task));
  CHECK(relativeError(turned_ws.tau, upright_ws.tau) < 1e-12);
  CHECK(upright_ws.tau.cwiseAbs().maxCoeff() > 1.0);  // gravity does load the joints
  // The default gravity on the turned root is wrong, visibly.
  turned_task.gravity = Task(turned).gravity;
  REQUIRE(inverseDynamics(turned, turned_ws, q, zero, zero, turned_task));
  CHECK(relativeError(turned_ws.tau, upright_ws.tau) > 0.1);
}

TEST_CASE("a mimic joint on the chain is refused; mass on a moving side branch is warned", "[urdf][errors]") {
  // base -j1-> l1 -fixed-> palm, palm -f1-> finger1 (leader), palm -f2-> finger2 (mimics f1)
  const std::string gripper = R"(<robot name="gripper"><link name="base"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" effort="10" velocity="3"/></joint>
  <link name="l1"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="palm_joint" type="fixed"><parent link="l1"/><child link="palm"/><origin xyz="0.3 0 0"/></joint>
  <link name="palm"/>
  <joint name="f1" type="prismatic"><parent link="palm"/><child link="finger1"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.04" effort="10" velocity="1"/></joint>
  <link name="finger1"><inertial><mass value="0.1"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial></link>
  <joint name="f2" type="prismatic"><parent link="palm"/><child link="finger2"/><axis xyz="0 -1 0"/>
    <limit lower="0" upper="0.04" effort="10" velocity="1"/><mimic joint="f1" multiplier="1" offset="0"/></joint>
  <link name="finger2"><inertial><mass value="0.2"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial></link>
</robot>)";
  UrdfOptions to_finger2;
  to_finger2.tip = "finger2";
  REQUIRE_THROWS_WITH(loadUrdfString(gripper, to_finger2),
                      Contains("joint 'f2' (q = 1·q_f1 + 0) mimics joint 'f1', which is not in the chain from 'base' "
                               "to 'finger2'"));
  to_finger2.mimic = MimicJoints::Refuse;
  REQUIRE_THROWS_WITH(loadUrdfString(gripper, to_finger2),
                      Contains("joint 'f2' on the chain mimics joint 'f1' (q = 1·q_f1 + 0)") &&
                          Contains("choose a UrdfOptions::tip before it (e.g. 'palm')"));
  UrdfOptions to_finger1;
  to_finger1.tip = "finger1";
  const Model m = loadUrdfString(gripper, to_finger1);  // the leader's chain: finger2 rides on l1, off the chain
  REQUIRE(codes(m) == Codes{WarningCode::MassOffChain});
  CHECK_THAT(m.warnings()[0].message, Contains("'finger2', 0.2 kg in all) behind moving joint 'f2' off the chain"));
  CHECK_THROWS_WITH(loadUrdfString(
                        gripper,
                        [&] {
    UrdfOptions o = to_finger1;
    o.strict = true;
    return o;
                        }()),
                    Contains("off the chain"));
  UrdfOptions to_palm;
  to_palm.tip = "palm";  // both fingers beyond the tip: that warning, not this one
  CHECK(codes(loadUrdfString(gripper, to_palm)) == Codes{WarningCode::MassBeyondTip});
}

TEST_CASE("Baxter: each arm loads with the warnings its data calls for and solves; a mimic finger is refused",
          "[urdf][warnings]") {
  const std::string file = std::string(ZWANG_MODELS_DIR) + "/baxter.urdf";
  for (const std::string side : {"left", "right"}) {
    INFO(side << " arm");
    UrdfOptions options;
    options.tip = side + "_gripper";
    const Model model = loadUrdfFile(file, options);
    REQUIRE(model.dof() == 7);
    // The gripper base's inertia (0.3 kg, moments 2e-8) is a placeholder, the
    // gripper frame a point mass, the fingers (0.06 kg) lie beyond the tip;
    // the other arm and the head hang off the fixed base: not warned.
    CHECK(codes(model) == Codes{WarningCode::PlaceholderInertia, WarningCode::PointMass, WarningCode::MassBeyondTip});
    // Holding the gripper still with 6 world rows at a bent pose: the task
    // is met (the 7th joint's self-motion stays free) and τ_control
    // reproduces q̈ through inverse dynamics (closure).
    Task task(model);
    task.addConstraint(options.tip, ConstraintMatrix::Identity(6, 6), Expressed::World);
    Workspace ws(model, task);
    Eigen::VectorXd q(7), zero = Eigen::VectorXd::Zero(7);
    q << 0.3, -0.5, 0.2, 1.2, -0.3, 0.8, 0.1;
    REQUIRE(solveHybridDynamics(model, ws, q, zero, zero, task));
    CHECK(ws.solution.balance.consistent);
    const int gripper = model.frameIndex(options.tip);
    Vec6 a;
    REQUIRE(frameAcceleration(model, ws, q, zero, gripper, Expressed::World, a));
    CHECK(a.norm() < 1e-10);
    Task free_task(model);
    Workspace id(model, free_task);
    REQUIRE(inverseDynamics(model, id, q, zero, ws.solution.qdd, free_task));
    CHECK((id.tau - ws.solution.tau_control).norm() < 1e-9 * (1.0 + id.tau.norm()));
    REQUIRE(solveWithFriction(model, ws, q, zero, zero, task));  // every joint stuck
    CHECK(ws.solution.balance.consistent);
    REQUIRE(frameAcceleration(model, ws, q, zero, gripper, Expressed::World, a));
    CHECK(a.norm() < 1e-10);
  }
  UrdfOptions through_mimic;
  through_mimic.tip = "r_gripper_r_finger_tip";
  CHECK_THROWS_WITH(loadUrdfFile(file, through_mimic),
                    Contains("joint 'r_gripper_r_finger_joint' (q = -1·q_r_gripper_l_finger_joint + 0) mimics joint "
                             "'r_gripper_l_finger_joint', which is not in the chain from 'base' to "
                             "'r_gripper_r_finger_tip'"));
}

TEST_CASE("urdfdom errors about visuals only load with a warning naming the link; dynamics errors are refused",
          "[urdf][warnings][errors]") {
  using Catch::Equals;
  // l1 as in arm(), with `appearance` inside the link; `top` before the links.
  const auto withLink = [](const std::string& appearance, const std::string& top = "") {
    std::string xml = arm("1", diagonal("0.1", "0.1", "0.1"));
    xml.insert(xml.find("</inertial>") + std::string("</inertial>").size(), appearance);
    xml.insert(xml.find("<link name=\"base\"/>"), top);
    return xml;
  };
  const Model plain = loadUrdfString(arm("1", diagonal("0.1", "0.1", "0.1")));
  const auto sameDynamics = [&plain](const Model& m) {
    REQUIRE(m.dof() == 1);
    CHECK(m.inertia(1).mass == plain.inertia(1).mass);
    CHECK(m.inertia(1).h == plain.inertia(1).h);
    CHECK(m.inertia(1).Ibar == plain.inertia(1).Ibar);
    CHECK(m.joint(0).upper == plain.joint(0).upper);
  };
  const std::string box = R"(<geometry><box size="0.1 0.1 0.1"/></geometry>)";

  SECTION("a visual material without a name (Unitree H1-2)") {
    const std::string xml = withLink("<visual>" + box + R"(<material><color rgba="1 0 0 1"/></material></visual>)");
    const Model m = loadUrdfString(xml);
    sameDynamics(m);
    REQUIRE(codes(m) == Codes{WarningCode::Urdfdom});
    CHECK_THAT(m.warnings()[0].message,
               Equals("<string>: link 'l1': urdfdom cannot read its <visual> or <collision> elements (Visual material "
                      "must contain a name attribute; Could not parse visual element for Link [l1]); they do not "
                      "enter the dynamics: loaded without them"));
    REQUIRE_THROWS_WITH(loadUrdfString(xml, strict()),
                        Equals("<string>: refused in strict mode (1 warning): link 'l1': urdfdom cannot read its "
                               "<visual> or <collision> elements (Visual material must contain a name attribute; "
                               "Could not parse visual element for Link [l1]); they do not enter the dynamics: loaded "
                               "without them"));
  }
  SECTION("a visual without geometry (Drake's Atlas), a collision with a bad box") {
    const Model m = loadUrdfString(withLink(R"(<visual><origin xyz="0 0 0.1"/></visual>)"));
    sameDynamics(m);
    REQUIRE(codes(m) == Codes{WarningCode::Urdfdom});
    CHECK_THAT(m.warnings()[0].message,
               Equals("<string>: link 'l1': urdfdom cannot read its <visual> or <collision> elements (Could not parse "
                      "visual element for Link [l1]); they do not enter the dynamics: loaded without them"));
    const Model c = loadUrdfString(withLink(R"(<collision><geometry><box size="1 1"/></geometry></collision>)"));
    sameDynamics(c);
    REQUIRE(codes(c) == Codes{WarningCode::Urdfdom});
    CHECK_THAT(c.warnings()[0].message,
               Equals("<string>: link 'l1': urdfdom cannot read its <visual> or <collision> elements (Parser found 2 "
                      "elements but 3 expected while parsing vector [1 1]; Could not parse collision element for "
                      "Link [l1]); they do not enter the dynamics: loaded without them"));
  }
  SECTION("a top-level material without a colour") {
    const Model m = loadUrdfString(withLink("", R"(<material name="blue"/>)"));
    sameDynamics(m);
    REQUIRE(codes(m) == Codes{WarningCode::Urdfdom});
    CHECK_THAT(m.warnings()[0].message,
               Equals("<string>: <material> 'blue': urdfdom cannot read it (Material [blue] color has no rgba; "
                      "Material [blue] not defined in file); materials do not enter the dynamics: loaded without it"));
  }
  SECTION("with an error beyond the visuals, urdfdom's reasons for that error fail the load") {
    std::string xml = withLink("<visual>" + box + R"(<material><color rgba="1 0 0 1"/></material></visual>)");
    xml.replace(xml.find("<limit "), xml.find("/>", xml.find("<limit ")) + 2 - xml.find("<limit "), "");
    REQUIRE_THROWS_WITH(loadUrdfString(xml), Equals("<string>: urdfdom rejected the URDF: Joint [j1] is of type "
                                                    "REVOLUTE but it does not specify limits; joint xml is not "
                                                    "initialized correctly"));
  }
  SECTION("an <inertial> urdfdom would zero is refused, naming the link") {
    const std::string tail =
        ": urdfdom would silently read all six moments as zero (give ixx, ixy, ixz, iyy, iyz and "
        "izz, 0 where the moment is zero)";
    REQUIRE_THROWS_WITH(loadUrdfString(arm("1", R"(ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0")")),
                        Equals("<string>: link 'l1': <inertial> <inertia> has no izz attribute" + tail));
    REQUIRE_THROWS_WITH(loadUrdfString(arm("1", R"(ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1")")),
                        Equals("<string>: link 'l1': <inertial> <inertia> has no ixx attribute" + tail));
    std::string no_inertia = arm("1", diagonal("0.1", "0.1", "0.1"));
    no_inertia.erase(no_inertia.find("<inertia "),
                     no_inertia.find("/>", no_inertia.find("<inertia ")) + 2 - no_inertia.find("<inertia "));
    REQUIRE_THROWS_WITH(loadUrdfString(no_inertia),
                        Equals("<string>: link 'l1': <inertial> has no <inertia> element: urdfdom would silently read "
                               "all six moments as zero (write <inertia ixx=\"…\" ixy=\"…\" ixz=\"…\" iyy=\"…\" "
                               "iyz=\"…\" izz=\"…\"/>)"));
    std::string no_mass = arm("1", diagonal("0.1", "0.1", "0.1"));
    no_mass.erase(no_mass.find("<mass value=\"1\"/>"), std::string("<mass value=\"1\"/>").size());
    REQUIRE_THROWS_WITH(loadUrdfString(no_mass),
                        Equals("<string>: link 'l1': <inertial> has no <mass> element: urdfdom would silently read "
                               "the link's mass and inertia as zero (write <mass value=\"…\"/>)"));
    std::string no_value = arm("1", diagonal("0.1", "0.1", "0.1"));
    no_value.replace(no_value.find("<mass value=\"1\"/>"), std::string("<mass value=\"1\"/>").size(), "<mass/>");
    REQUIRE_THROWS_WITH(loadUrdfString(no_value),
                        Equals("<string>: link 'l1': <inertial> has no value attribute in its <mass>: urdfdom would "
                               "silently read the link's mass and inertia as zero (write <mass value=\"…\"/>)"));
  }
}

TEST_CASE("negative effort and velocity limits (-1: unlimited) are no limits, with a warning", "[urdf][warnings]") {
  using Catch::Equals;
  constexpr double inf = std::numeric_limits<double>::infinity();
  const std::string both =
      arm("1", diagonal("0.1", "0.1", "0.1"), "0.5 0 0", "", R"(lower="-2" upper="2" effort="-1" velocity="-1")");
  const Model m = loadUrdfString(both);
  REQUIRE(codes(m) == Codes{WarningCode::PlaceholderLimits});
  CHECK_THAT(m.warnings()[0].message,
             Equals("<string>: joint 'j1': <limit> effort -1 and velocity -1 are negative: read as no effort and no "
                    "velocity limit (how some files write \"unlimited\")"));
  CHECK(m.joint(0).effort_limit == inf);
  CHECK(m.joint(0).velocity_limit == inf);
  CHECK(m.joint(0).lower == -2.0);  // the position limits are real ones: kept
  CHECK(m.joint(0).upper == 2.0);
  REQUIRE_THROWS_WITH(loadUrdfString(both, strict()), Contains("strict mode") && Contains("effort -1 and velocity -1"));

  const Model effort = loadUrdfString(
      arm("1", diagonal("0.1", "0.1", "0.1"), "0.5 0 0", "", R"(lower="-2" upper="2" effort="-10" velocity="3")"));
  REQUIRE(codes(effort) == Codes{WarningCode::PlaceholderLimits});
  CHECK_THAT(effort.warnings()[0].message,
             Equals("<string>: joint 'j1': <limit> effort -10 is negative: read as no effort limit (how some files "
                    "write \"unlimited\")"));
  CHECK(effort.joint(0).effort_limit == inf);
  CHECK(effort.joint(0).velocity_limit == 3.0);

  const Model velocity = loadUrdfString(
      arm("1", diagonal("0.1", "0.1", "0.1"), "0.5 0 0", "", R"(lower="-2" upper="2" effort="10" velocity="-2")"));
  CHECK_THAT(velocity.warnings()[0].message,
             Equals("<string>: joint 'j1': <limit> velocity -2 is negative: read as no velocity limit (how some files "
                    "write \"unlimited\")"));
  CHECK(velocity.joint(0).effort_limit == 10.0);
  CHECK(velocity.joint(0).velocity_limit == inf);
}

TEST_CASE("a file with no <inertial> at all says so once", "[urdf][errors]") {
  using Catch::Equals;
  // A kinematics-only two-joint arm, as vendors ship for visualisation.
  const std::string xml = R"(<robot name="kin"><link name="base"/>
    <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
      <limit lower="-2" upper="2" effort="10" velocity="3"/></joint>
    <link name="l1"><visual><geometry><box size="0.1 0.1 0.1"/></geometry></visual></link>
    <joint name="j2" type="revolute"><parent link="l1"/><child link="l2"/><origin xyz="0.5 0 0"/><axis xyz="0 0 1"/>
      <limit lower="-2" upper="2" effort="10" velocity="3"/></joint>
    <link name="l2"/></robot>)";
  const std::string message =
      "<string>: the URDF has no <inertial> element on any link: it describes the kinematics only (no masses, no "
      "inertias), and dynamics need them; use a description of the robot with its inertial data";
  REQUIRE_THROWS_WITH(loadUrdfString(xml), Equals(message));
  UrdfOptions chain;
  chain.tip = "l1";
  REQUIRE_THROWS_WITH(loadUrdfString(xml, chain), Equals(message));
  UrdfOptions free;
  free.base = BaseType::Free;
  REQUIRE_THROWS_WITH(loadUrdfString(xml, free), Equals(message));
  // Rotor inertias alone give each joint of a fixed base something to move: it loads.
  UrdfOptions rotors;
  rotors.rotor_inertia = {{"j1", 0.1}, {"j2", 0.1}};
  CHECK(loadUrdfString(xml, rotors).dof() == 2);
  // One link with inertial data: the massless leaf is named as before.
  std::string one = xml;
  one.replace(
      one.find("<link name=\"l1\">"), std::string("<link name=\"l1\">").size(),
      R"(<link name="l1"><inertial><mass value="1"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>)");
  REQUIRE_THROWS_WITH(loadUrdfString(one), Contains("link 'l2': zero mass on a moving body"));
}
