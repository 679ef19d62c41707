// URDF loading: the shipped models, the chain selection, rotor inertia from
// Drake's transmission tags, and one test per rejected input, checking that the
// message names the source, the link or joint, and the field.
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "zwang/urdf.hpp"

using Catch::Contains;
using zwang::JointType;
using zwang::loadUrdfFile;
using zwang::loadUrdfString;
using zwang::Mat3;
using zwang::Model;
using zwang::ModelError;
using zwang::UrdfOptions;
using zwang::Vec3;

namespace {

const std::string kModels = ZWANG_MODELS_DIR;
const double kPi = 3.14159265358979323846;

Mat3 rotX(double a) { return Eigen::AngleAxisd(a, Vec3::UnitX()).toRotationMatrix(); }
Mat3 rotY(double a) { return Eigen::AngleAxisd(a, Vec3::UnitY()).toRotationMatrix(); }
Mat3 rotZ(double a) { return Eigen::AngleAxisd(a, Vec3::UnitZ()).toRotationMatrix(); }

bool near(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double tol = 1e-12) {
  return (a - b).cwiseAbs().maxCoeff() <= tol;
}

std::string robot(const std::string& body) { return "<robot name=\"test_robot\">\n" + body + "\n</robot>\n"; }

const std::string kInertial = R"(<inertial><origin xyz="0.5 0 0" rpy="0 0 0"/><mass value="1"/>
    <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="2"/></inertial>)";
const std::string kJointBody = R"(<origin xyz="0 0 0" rpy="0 0 0"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="10" velocity="2"/><dynamics friction="1" damping="0.5"/>)";

// base --j1 (revolute)--> l1. The joint's inner XML and the link's inertial
// can be replaced; `extra` is appended inside <robot>.
std::string arm(const std::string& joint_body = kJointBody, const std::string& inertial = kInertial,
                const std::string& extra = "", const std::string& type = "revolute") {
  return robot(R"(<link name="base"/>
  <joint name="j1" type=")" +
               type + R"("><parent link="base"/><child link="l1"/>
    )" + joint_body +
               R"(
  </joint>
  <link name="l1">)" +
               inertial + R"(</link>
  )" + extra);
}

std::string inertialWith(const std::string& mass, const std::string& inertia, const std::string& origin = "") {
  return "<inertial>" + origin + "<mass value=\"" + mass + "\"/><inertia " + inertia + "/></inertial>";
}

// A tree: base -j1-> l1, l1 -j2a-> l2a -j3a-> l3a, l1 -j2b-> l2b,
// l1 -fixed-> sensor, and world -fixed-> base above the root.
const std::string kTree = robot(R"(
  <link name="world"/>
  <joint name="world_joint" type="fixed"><parent link="world"/><child link="base"/>
    <origin xyz="0 0 1" rpy="0 0 0"/></joint>
  <link name="base"/>
  <joint name="j1" type="continuous"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/></joint>
  <link name="l1"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="j2a" type="continuous"><parent link="l1"/><child link="l2a"/><origin xyz="1 0 0"/></joint>
  <link name="l2a"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="j3a" type="continuous"><parent link="l2a"/><child link="l3a"/><origin xyz="1 0 0"/></joint>
  <link name="l3a"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="j2b" type="continuous"><parent link="l1"/><child link="l2b"/><origin xyz="0 1 0"/></joint>
  <link name="l2b"><inertial><mass value="5"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="sensor_joint" type="fixed"><parent link="l1"/><child link="sensor"/><origin xyz="0 0 0.2"/></joint>
  <link name="sensor"><inertial><mass value="0.5"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial></link>
)");

std::string transmission(const std::string& name, const std::string& joint, const std::string& actuator_body) {
  return "<transmission name=\"" + name + "\"><type>transmission_interface/SimpleTransmission</type>" +
         "<joint name=\"" + joint + "\"><hardwareInterface>EffortJointInterface</hardwareInterface></joint>" +
         "<actuator name=\"" + name + "_motor\">" + actuator_body + "</actuator></transmission>";
}

UrdfOptions rootTip(const std::string& root, const std::string& tip) {
  UrdfOptions o;
  o.root = root;
  o.tip = tip;
  return o;
}

}  // namespace

// ---------------------------------------------------------------------------
// Shipped models

TEST_CASE("one_dof_arm.urdf is the report's chapter 6 arm", "[urdf]") {
  const Model m = loadUrdfFile(kModels + "/one_dof_arm.urdf");
  REQUIRE(m.name() == "one_dof_arm");
  REQUIRE(m.dof() == 1);
  const zwang::Joint& j = m.joint(0);
  CHECK(j.name == "joint1");
  CHECK(j.type == JointType::Revolute);
  CHECK(near(j.axis, Vec3::UnitZ()));
  CHECK(near(j.placement.E, Mat3::Identity()));
  CHECK(near(j.placement.r, Vec3::Zero()));
  CHECK(j.breakaway_friction == 10.0);
  CHECK(j.kinetic_friction == 10.0);
  CHECK(j.viscous_friction == 0.0);
  CHECK(j.rotor_inertia == 0.0);

  const zwang::RigidInertia& I = m.inertia(1);
  CHECK(I.mass == Approx(1.0));
  CHECK(near(I.com(), Vec3(0.5, 0, 0)));
  CHECK(I.inertiaAboutCom()(2, 2) == Approx(2.0));
  CHECK(I.Ibar(2, 2) == Approx(2.25));  // about the joint: 2 + 1·0.5²

  REQUIRE(m.frames().size() == 3);
  CHECK(m.frame(m.bodyFrame(0)).name == "base");
  CHECK(m.frame(m.bodyFrame(1)).name == "link1");
  const zwang::Frame& tip = m.frame(m.frameIndex("tip"));
  CHECK(tip.body == 1);
  CHECK(near(tip.placement.r, Vec3(1, 0, 0)));
  CHECK(near(tip.placement.E, Mat3::Identity()));
}

TEST_CASE("panda.urdf carries the figures of panda_arm.urdf", "[urdf]") {
  const Model m = loadUrdfFile(kModels + "/panda.urdf");
  REQUIRE(m.name() == "panda");
  REQUIRE(m.dof() == 7);
  for (int j = 0; j < 7; ++j) {
    CHECK(m.joint(j).name == "panda_joint" + std::to_string(j + 1));
    CHECK(m.joint(j).type == JointType::Revolute);
    CHECK(near(m.joint(j).axis, Vec3::UnitZ()));
    CHECK(m.frame(m.bodyFrame(j + 1)).name == "panda_link" + std::to_string(j + 1));
  }
  CHECK(m.frame(m.bodyFrame(0)).name == "panda_link0");

  const double masses[] = {4.970684, 0.646926, 3.228604, 3.587895, 1.225946, 1.666555, 7.35522e-01};
  for (int b = 1; b <= 7; ++b) CHECK(m.inertia(b).mass == Approx(masses[b - 1]));
  CHECK(near(m.inertia(1).com(), Vec3(3.875e-03, 2.081e-03, -0.1750)));
  Mat3 I1;
  I1 << 7.0337e-01, -1.3900e-04, 6.7720e-03, -1.3900e-04, 7.0661e-01, 1.9169e-02, 6.7720e-03, 1.9169e-02, 9.1170e-03;
  CHECK(near(m.inertia(1).inertiaAboutCom(), I1, 1e-12));

  const zwang::Joint& j1 = m.joint(0);
  CHECK(j1.lower == -2.8973);
  CHECK(j1.upper == 2.8973);
  CHECK(j1.effort_limit == 87.0);
  CHECK(j1.velocity_limit == 2.1750);
  CHECK(j1.breakaway_friction == 5.0);
  CHECK(j1.kinetic_friction == 5.0);
  CHECK(j1.viscous_friction == 10.0);
  CHECK(near(j1.placement.r, Vec3(0, 0, 0.333)));
  CHECK(m.joint(3).lower == -3.0718);
  CHECK(m.joint(3).upper == -0.0698);
  CHECK(m.joint(4).effort_limit == 12.0);
  CHECK(m.joint(6).breakaway_friction == 0.5);
  CHECK(m.joint(6).viscous_friction == 1.0);
  // panda_joint2: rpy (-π/2, 0, 0) → ʲX_parent has E = Rx(-π/2)ᵀ.
  CHECK(near(m.joint(1).placement.E, rotX(-1.57079632679).transpose()));
  CHECK(near(m.joint(2).placement.r, Vec3(0, -0.316, 0)));

  // Flange and tool frames: both welded to body 7, massless.
  REQUIRE(m.frames().size() == 10);
  const zwang::Frame& flange = m.frame(m.frameIndex("panda_link8"));
  CHECK(flange.body == 7);
  CHECK(near(flange.placement.r, Vec3(0, 0, 0.107)));
  const zwang::Frame& tool = m.frame(m.frameIndex("tool0"));
  CHECK(tool.body == 7);
  CHECK(near(tool.placement.r, Vec3(0, 0, 0.107 + 0.1034)));
  CHECK(near(tool.placement.E, Mat3::Identity()));
  CHECK(m.inertia(7).mass == Approx(7.35522e-01));  // nothing merged
}

// ---------------------------------------------------------------------------
// Geometry, inertia, joint fields

TEST_CASE("URDF rpy is fixed-axis roll, pitch, yaw for joints and inertials", "[urdf]") {
  const double r = 0.1, p = 0.2, y = 0.3;
  const Mat3 R = rotZ(y) * rotY(p) * rotX(r);
  const std::string joint = R"(<origin xyz="0.1 0.2 0.3" rpy="0.1 0.2 0.3"/><axis xyz="0 0 2"/>
      <limit lower="-1" upper="1" effort="10" velocity="2"/>)";
  // Principal moments (1, 2, 2.5) in a COM frame turned by 90° about z: in the
  // link frame the x and y moments swap.
  const std::string inertial = inertialWith("2", R"(ixx="1" ixy="0" ixz="0" iyy="2" iyz="0" izz="2.5")",
                                            R"(<origin xyz="0 0 0.5" rpy="0 0 1.5707963267948966"/>)");
  const Model m = loadUrdfString(arm(joint, inertial));
  CHECK(near(m.joint(0).placement.E, R.transpose(), 1e-14));
  CHECK(near(m.joint(0).placement.r, Vec3(0.1, 0.2, 0.3)));
  CHECK(near(m.joint(0).axis, Vec3::UnitZ()));  // normalised
  Mat3 expected = Vec3(2, 1, 2.5).asDiagonal();
  CHECK(near(m.inertia(1).inertiaAboutCom(), expected, 1e-12));
  CHECK(near(m.inertia(1).com(), Vec3(0, 0, 0.5)));
}

TEST_CASE("a fixed child's inertia is merged into its body", "[urdf]") {
  // l1: 2 kg at (0.1, 0, 0), I = diag(0.1, 0.2, 0.3).
  // l2 welded at (0.5, 0, 0) turned 90° about z: 1 kg at (0.2, 0, 0) of l2,
  // i.e. (0.5, 0.2, 0) of l1, I = diag(0.01, 0.02, 0.025) in l2's axes,
  // diag(0.02, 0.01, 0.025) in l1's.
  const std::string inertial1 =
      inertialWith("2", R"(ixx="0.1" ixy="0" ixz="0" iyy="0.2" iyz="0" izz="0.3")", R"(<origin xyz="0.1 0 0"/>)");
  const std::string extra =
      R"(
    <joint name="weld" type="fixed"><parent link="l1"/><child link="l2"/>
      <origin xyz="0.5 0 0" rpy="0 0 1.5707963267948966"/></joint>
    <link name="l2">)" +
      inertialWith("1", R"(ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.025")", R"(<origin xyz="0.2 0 0"/>)") +
      "</link>";
  const Model m = loadUrdfString(arm(kJointBody, inertial1, extra));
  REQUIRE(m.dof() == 1);
  const zwang::RigidInertia& I = m.inertia(1);
  CHECK(I.mass == Approx(3.0));
  CHECK(near(I.com(), Vec3(0.7 / 3.0, 0.2 / 3.0, 0.0)));
  // About l1's origin, by hand: Σ I_com + m (|c|² 1 − c cᵀ).
  CHECK(I.Ibar(0, 0) == Approx(0.1 + 0.02 + 1 * 0.04));
  CHECK(I.Ibar(1, 1) == Approx(0.2 + 2 * 0.01 + 0.01 + 1 * 0.25));
  CHECK(I.Ibar(2, 2) == Approx(0.3 + 2 * 0.01 + 0.025 + 1 * (0.25 + 0.04)));
  CHECK(I.Ibar(0, 1) == Approx(-1 * 0.5 * 0.2));
  CHECK(std::abs(I.Ibar(0, 2)) < 1e-15);

  const zwang::Frame& l2 = m.frame(m.frameIndex("l2"));
  CHECK(l2.body == 1);
  CHECK(near(l2.placement.r, Vec3(0.5, 0, 0)));
  CHECK(near(l2.placement.E, rotZ(kPi / 2).transpose(), 1e-14));
}

TEST_CASE("joint types, default axis and limits", "[urdf]") {
  SECTION("continuous: no position limits, effort and velocity kept") {
    const Model m = loadUrdfString(arm(R"(<limit effort="3" velocity="4"/>)", kInertial, "", "continuous"));
    CHECK(m.joint(0).type == JointType::Continuous);
    CHECK(m.joint(0).lower == -std::numeric_limits<double>::infinity());
    CHECK(m.joint(0).upper == std::numeric_limits<double>::infinity());
    CHECK(m.joint(0).effort_limit == 3.0);
    CHECK(m.joint(0).velocity_limit == 4.0);
    CHECK(near(m.joint(0).axis, Vec3::UnitX()));  // URDF default axis
    CHECK(m.joint(0).breakaway_friction == 0.0);
  }
  SECTION("continuous without <limit>") {
    const Model m = loadUrdfString(arm("", kInertial, "", "continuous"));
    CHECK(m.joint(0).effort_limit == std::numeric_limits<double>::infinity());
  }
  SECTION("prismatic") {
    const Model m = loadUrdfString(arm(R"(<axis xyz="0 1 0"/><limit lower="0" upper="0.3" effort="100" velocity="1"/>)",
                                       kInertial, "", "prismatic"));
    CHECK(m.joint(0).type == JointType::Prismatic);
    CHECK(near(m.joint(0).axis, Vec3::UnitY()));
    CHECK(m.joint(0).upper == 0.3);
  }
}

// ---------------------------------------------------------------------------
// Rotor inertia

TEST_CASE("rotor inertia from Drake's transmission tags, and the override", "[urdf]") {
  const std::string two_links = robot(R"(
    <link name="base"/>
    <joint name="j1" type="continuous"><parent link="base"/><child link="l1"/></joint>
    <link name="l1">)" + kInertial + R"(</link>
    <joint name="j2" type="continuous"><parent link="l1"/><child link="l2"/></joint>
    <link name="l2">)" + kInertial + R"(</link>)" +
                                      transmission("t1", "j1",
                                                   R"(<mechanicalReduction>3</mechanicalReduction>
        <drake:rotor_inertia value="0.5"/><drake:gear_ratio value="3"/>)") +
                                      transmission("t2", "j2", R"(<drake:rotor_inertia value="0.25"/>)"));
  SECTION("from the URDF: rotor_inertia · gear_ratio²") {
    const Model m = loadUrdfString(two_links);
    CHECK(m.joint(0).rotor_inertia == Approx(4.5));
    CHECK(m.joint(1).rotor_inertia == Approx(0.25));  // gear ratio defaults to 1
  }
  SECTION("UrdfOptions::rotor_inertia overrides") {
    UrdfOptions o;
    o.rotor_inertia["j1"] = 0.125;
    const Model m = loadUrdfString(two_links, o);
    CHECK(m.joint(0).rotor_inertia == 0.125);
    CHECK(m.joint(1).rotor_inertia == Approx(0.25));
  }
  SECTION("an override can give a joint without a transmission its rotor inertia") {
    UrdfOptions o;
    o.rotor_inertia["joint1"] = 0.01;
    const Model m = loadUrdfFile(kModels + "/one_dof_arm.urdf", o);
    CHECK(m.joint(0).rotor_inertia == 0.01);
  }
  SECTION("an override naming an unknown joint is an error") {
    UrdfOptions o;
    o.rotor_inertia["j9"] = 0.1;
    REQUIRE_THROWS_WITH(loadUrdfString(two_links, o), Contains("<string>") && Contains("rotor_inertia") &&
                                                          Contains("'j9'") && Contains("not a moving joint") &&
                                                          Contains("'j1', 'j2'") &&
                                                          Contains("the URDF has no joint of that name"));
  }
  SECTION("an override naming a joint off the chain is an error") {
    UrdfOptions o = rootTip("", "l1");
    o.rotor_inertia["j2"] = 0.1;
    REQUIRE_THROWS_WITH(loadUrdfString(two_links, o), Contains("'j2'") && Contains("not a moving joint of the chain") &&
                                                          !Contains("no joint of that name"));
  }
  SECTION("a negative override is an error") {
    UrdfOptions o;
    o.rotor_inertia["j1"] = -1;
    REQUIRE_THROWS_WITH(loadUrdfString(two_links, o), Contains("rotor_inertia") && Contains("'j1'") && Contains("-1"));
  }
}

// ---------------------------------------------------------------------------
// Chain selection

TEST_CASE("root and tip selection", "[urdf]") {
  SECTION("the tip may be omitted when the tree does not branch into moving joints") {
    const Model m = loadUrdfFile(kModels + "/panda.urdf");
    CHECK(m.dof() == 7);
    CHECK(m.hasFrame("tool0"));
  }
  SECTION("no tip in a branching tree: the whole tree (test_urdf_trees has more)") {
    const Model m = loadUrdfString(kTree);
    REQUIRE(m.dof() == 4);
    CHECK(m.joint(0).name == "j1");
    CHECK(m.joint(1).name == "j2a");
    CHECK(m.joint(2).name == "j3a");
    CHECK(m.joint(3).name == "j2b");
    CHECK(m.parentBodyOfJoint(3) == 1);
    CHECK(m.inertia(1).mass == Approx(1.5));  // l1 + welded sensor
    CHECK(m.frame(m.frameIndex("world")).body == 0);
    CHECK(m.warnings().empty());
  }
  SECTION("explicit tip in a branching tree; off-chain moving branches are not in the model") {
    const Model m = loadUrdfString(kTree, rootTip("", "l3a"));
    REQUIRE(m.dof() == 3);
    CHECK(m.joint(0).name == "j1");
    CHECK(m.joint(1).name == "j2a");
    CHECK(m.joint(2).name == "j3a");
    CHECK(m.frame(m.bodyFrame(0)).name == "world");  // the URDF root
    CHECK_FALSE(m.hasFrame("l2b"));
    CHECK(m.inertia(1).mass == Approx(1.5));  // l1 + welded sensor, not l2b
    const zwang::Frame& sensor = m.frame(m.frameIndex("sensor"));
    CHECK(sensor.body == 1);
    CHECK(near(sensor.placement.r, Vec3(0, 0, 0.2)));
    CHECK(m.frame(m.frameIndex("base")).body == 0);
    CHECK(near(m.joint(0).placement.r, Vec3(0, 0, 1)));  // rebased on world through the weld
  }
  SECTION("mid-tree root: its fixed parent becomes a frame too") {
    const Model m = loadUrdfString(kTree, rootTip("base", "l2b"));
    REQUIRE(m.dof() == 2);
    CHECK(m.joint(1).name == "j2b");
    CHECK(m.frame(m.bodyFrame(0)).name == "base");
    const zwang::Frame& world = m.frame(m.frameIndex("world"));
    CHECK(world.body == 0);
    CHECK(near(world.placement.r, Vec3(0, 0, -1)));  // world's origin, seen from base
    CHECK_FALSE(m.hasFrame("l2a"));
  }
  SECTION("mid-chain root with the tip omitted") {
    const Model m = loadUrdfString(kTree, rootTip("l2a", ""));
    REQUIRE(m.dof() == 1);
    CHECK(m.joint(0).name == "j3a");
    CHECK(m.frame(m.bodyFrame(0)).name == "l2a");
    CHECK(m.frames().size() == 2);
  }
  SECTION("the tip may be a welded link") {
    const Model m = loadUrdfString(kTree, rootTip("", "sensor"));
    REQUIRE(m.dof() == 1);
    CHECK(m.frame(m.frameIndex("sensor")).body == 1);
  }
  SECTION("panda from link3 to link6") {
    const Model m = loadUrdfFile(kModels + "/panda.urdf", rootTip("panda_link3", "panda_link6"));
    REQUIRE(m.dof() == 3);
    CHECK(m.joint(0).name == "panda_joint4");
    CHECK(m.joint(2).name == "panda_joint6");
    CHECK(m.frame(m.bodyFrame(0)).name == "panda_link3");
    CHECK_FALSE(m.hasFrame("panda_link7"));
    CHECK_FALSE(m.hasFrame("panda_link8"));
    CHECK_FALSE(m.hasFrame("panda_link2"));
    CHECK(m.frames().size() == 4);
  }
  SECTION("panda to the flange") {
    const Model m = loadUrdfFile(kModels + "/panda.urdf", rootTip("", "panda_link8"));
    CHECK(m.dof() == 7);
    CHECK(m.hasFrame("tool0"));  // welded below the tip
  }
}

// ---------------------------------------------------------------------------
// Errors: every message names the source, the link or joint and the field.

TEST_CASE("error: missing or unreadable file", "[urdf][errors]") {
  REQUIRE_THROWS_AS(loadUrdfFile("/nonexistent/dir/robot.urdf"), ModelError);
  REQUIRE_THROWS_WITH(loadUrdfFile("/nonexistent/dir/robot.urdf"),
                      Contains("/nonexistent/dir/robot.urdf") && Contains("cannot open") && Contains("No such file"));
  REQUIRE_THROWS_WITH(loadUrdfFile(kModels), Contains(kModels) && Contains("directory"));
}

TEST_CASE("error: malformed XML gives the line", "[urdf][errors]") {
  const std::string xml = "<robot name=\"r\">\n  <link name=\"a\">\n  <link name=\"b\"/>\n</robot>\n";
  REQUIRE_THROWS_WITH(loadUrdfString(xml),
                      Contains("<string>") && Contains("malformed XML") && Contains("line 4") && Contains("end tag"));
  REQUIRE_THROWS_WITH(loadUrdfString(""), Contains("<string>") && Contains("malformed XML"));
  REQUIRE_THROWS_WITH(loadUrdfString("<model/>"), Contains("<string>") && Contains("<robot>") && Contains("<model>"));

  // The same through a file: the message names the file.
  const std::string path = (std::filesystem::temp_directory_path() / "zwang_test_urdf_malformed.urdf").string();
  std::ofstream(path) << xml;
  REQUIRE_THROWS_WITH(loadUrdfFile(path), Contains(path + ": malformed XML at line 4"));
  std::remove(path.c_str());
}

TEST_CASE("error: structural errors reported by urdfdom", "[urdf][errors]") {
  REQUIRE_THROWS_WITH(loadUrdfString(arm(R"(<axis xyz="0 0 1"/>)")),
                      Contains("<string>") && Contains("urdfdom rejected") && Contains("j1") && Contains("limits"));
  REQUIRE_THROWS_WITH(loadUrdfString(arm(kJointBody, kInertial, "", "hinge")),
                      Contains("urdfdom rejected") && Contains("j1") && Contains("hinge"));
}

TEST_CASE("error: unknown root or tip, tip not below root", "[urdf][errors]") {
  REQUIRE_THROWS_WITH(loadUrdfString(kTree, rootTip("nope", "")),
                      Contains("<string>") && Contains("root link 'nope' not found") && Contains("'l3a'"));
  REQUIRE_THROWS_WITH(loadUrdfString(kTree, rootTip("", "nope")),
                      Contains("<string>") && Contains("tip link 'nope' not found") && Contains("'l2b'"));
  REQUIRE_THROWS_WITH(loadUrdfString(kTree, rootTip("l2a", "l2b")),
                      Contains("<string>") && Contains("tip link 'l2b' is not below root link 'l2a'") &&
                          Contains("'l1'"));
  REQUIRE_THROWS_WITH(loadUrdfFile(kModels + "/panda.urdf", rootTip("panda_link5", "panda_link2")),
                      Contains("panda.urdf") &&
                          Contains("tip link 'panda_link2' is not below root link 'panda_link5'"));
  REQUIRE_THROWS_WITH(loadUrdfString(kTree, rootTip("l1", "sensor")),
                      Contains("<string>") && Contains("'l1'") && Contains("'sensor'") && Contains("no moving joint"));
}

TEST_CASE("floating and planar joints on the chain are free and planar joints", "[urdf][errors]") {
  // Below the root they are joints of the model (issue #25; at the root they are the base: test_urdf_floating).
  const auto below = [](const std::string& type) {
    return arm(kJointBody, kInertial,
               "<joint name=\"j2\" type=\"" + type +
                   R"("><parent link="l1"/><child link="l2"/><axis xyz="0 0 1"/></joint><link name="l2">)" + kInertial +
                   "</link>");
  };
  const Model floating = loadUrdfString(below("floating"));
  REQUIRE(floating.joints().size() == 2);
  CHECK(floating.joint(1).type == JointType::Free);
  CHECK(floating.nv() == 7);
  const Model planar = loadUrdfString(below("planar"));
  REQUIRE(planar.joints().size() == 2);
  CHECK(planar.joint(1).type == JointType::Planar);
  CHECK(planar.nq() == 4);
  // Off the chain it is fine (it is not part of the model).
  const std::string extra = R"(<joint name="free" type="floating"><parent link="base"/><child link="ball"/></joint>
      <link name="ball">)" + kInertial +
                            "</link>";
  UrdfOptions o = rootTip("", "l1");
  CHECK(loadUrdfString(arm(kJointBody, kInertial, extra), o).dof() == 1);
}

TEST_CASE("error: bad masses and inertias", "[urdf][errors]") {
  const std::string unit = R"(ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1")";
  REQUIRE_THROWS_WITH(loadUrdfString(arm(kJointBody, inertialWith("-1", unit))),
                      Contains("<string>") && Contains("link 'l1'") && Contains("<mass>") && Contains("-1") &&
                          Contains("negative"));
  REQUIRE_THROWS_WITH(
      loadUrdfString(arm(kJointBody, inertialWith("0", R"(ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0")"))),
      Contains("<string>") && Contains("link 'l1'") && Contains("zero mass") && Contains("j1"));
  REQUIRE_THROWS_WITH(loadUrdfString(arm(kJointBody, "")),
                      Contains("the URDF has no <inertial> element on any link"));  // test_urdf_warnings has more
  REQUIRE_THROWS_WITH(
      loadUrdfString(arm(kJointBody, inertialWith("1", R"(ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="-1")"))),
      Contains("<string>") && Contains("link 'l1'") && Contains("inertia") && Contains("not positive semi-definite") &&
          Contains("-1 kg·m² is negative"));
  REQUIRE_THROWS_WITH(
      loadUrdfString(arm(kJointBody, inertialWith("1", R"(ixx="1" ixy="2" ixz="0" iyy="1" iyz="0" izz="1")"))),
      Contains("link 'l1'") && Contains("not positive semi-definite"));
  // A welded link on a moving body is checked too.
  const std::string welded = R"(<joint name="w" type="fixed"><parent link="l1"/><child link="l2"/></joint>
      <link name="l2">)" + inertialWith("-2", unit) +
                             "</link>";
  REQUIRE_THROWS_WITH(loadUrdfString(arm(kJointBody, kInertial, welded)),
                      Contains("link 'l2'") && Contains("<mass>") && Contains("negative"));
  // A massless last body is fine when a welded link beyond it carries the mass.
  const std::string carrier = R"(<joint name="w" type="fixed"><parent link="l1"/><child link="l2"/></joint>
      <link name="l2">)" + kInertial +
                              "</link>";
  CHECK(loadUrdfString(arm(kJointBody, "", carrier)).inertia(1).mass == Approx(1.0));
}

TEST_CASE("error: negative friction and damping, inverted limits", "[urdf][errors]") {
  const auto body = [](const std::string& limit, const std::string& dynamics) {
    return R"(<axis xyz="0 0 1"/><limit )" + limit + R"(/><dynamics )" + dynamics + "/>";
  };
  const std::string lim = R"(lower="-1" upper="1" effort="10" velocity="2")";
  REQUIRE_THROWS_WITH(loadUrdfString(arm(body(lim, R"(friction="-1" damping="0")"))),
                      Contains("<string>: joint 'j1': <dynamics> friction -1 is negative"));
  REQUIRE_THROWS_WITH(loadUrdfString(arm(body(lim, R"(friction="1" damping="-0.5")"))),
                      Contains("<string>") && Contains("joint 'j1'") &&
                          Contains("<dynamics> damping -0.5 is negative"));
  REQUIRE_THROWS_WITH(loadUrdfString(arm(body(R"(lower="2" upper="1" effort="10" velocity="2")", "friction=\"0\""))),
                      Contains("<string>") && Contains("joint 'j1'") && Contains("<limit> lower 2") &&
                          Contains("upper 1"));
  // Negative effort and velocity limits are "no limit" (test_urdf_warnings).
}

TEST_CASE("error: zero axis", "[urdf][errors]") {
  REQUIRE_THROWS_WITH(
      loadUrdfString(arm(R"(<axis xyz="0 0 0"/><limit lower="-1" upper="1" effort="1" velocity="1"/>)")),
      Contains("<string>") && Contains("joint 'j1'") && Contains("<axis>") && Contains("zero"));
}

TEST_CASE("error: NaN, Inf and non-numbers anywhere", "[urdf][errors]") {
  const std::string lim = R"(<limit lower="-1" upper="1" effort="1" velocity="1"/>)";
  const auto joint = [&](const std::string& inner) { return loadUrdfString(arm(inner + lim)); };
  const auto link = [&](const std::string& inertial) { return loadUrdfString(arm(kJointBody, inertial)); };
  const std::string unit = R"(ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1")";

  REQUIRE_THROWS_WITH(joint(R"(<origin xyz="nan 0 0"/>)"),
                      Contains("<string>: joint 'j1': <origin> xyz") && Contains("nan 0 0") && Contains("not finite"));
  REQUIRE_THROWS_WITH(joint(R"(<origin rpy="0 inf 0"/>)"),
                      Contains("joint 'j1'") && Contains("<origin> rpy") && Contains("not finite"));
  REQUIRE_THROWS_WITH(joint(R"(<origin xyz="1e999 0 0"/>)"),
                      Contains("joint 'j1'") && Contains("<origin> xyz") && Contains("not finite"));
  REQUIRE_THROWS_WITH(joint(R"(<axis xyz="0 0 -Inf"/>)"),
                      Contains("joint 'j1'") && Contains("<axis> xyz") && Contains("not finite"));
  REQUIRE_THROWS_WITH(joint(R"(<axis xyz="0 one 0"/>)"),
                      Contains("joint 'j1'") && Contains("<axis> xyz") && Contains("'one' is not a number"));
  REQUIRE_THROWS_WITH(joint(R"(<axis xyz="0 1"/>)"),
                      Contains("joint 'j1'") && Contains("<axis> xyz") && Contains("must hold 3 numbers"));
  REQUIRE_THROWS_WITH(loadUrdfString(arm(R"(<limit lower="nan" upper="1" effort="1" velocity="1"/>)")),
                      Contains("joint 'j1'") && Contains("<limit> lower") && Contains("not finite"));
  REQUIRE_THROWS_WITH(loadUrdfString(arm(R"(<limit lower="-1" upper="1" effort="inf" velocity="1"/>)")),
                      Contains("joint 'j1'") && Contains("<limit> effort") && Contains("not finite"));
  REQUIRE_THROWS_WITH(joint(R"(<dynamics friction="NaN" damping="0"/>)"),
                      Contains("joint 'j1'") && Contains("<dynamics> friction") && Contains("not finite"));
  REQUIRE_THROWS_WITH(joint(R"(<dynamics friction="1" damping="lots"/>)"),
                      Contains("joint 'j1'") && Contains("<dynamics> damping") && Contains("not a number"));

  REQUIRE_THROWS_WITH(link(inertialWith("nan", unit)),
                      Contains("<string>: link 'l1': <inertial> <mass> value") && Contains("not finite"));
  REQUIRE_THROWS_WITH(link(inertialWith("1", R"(ixx="1" ixy="0" ixz="0" iyy="inf" iyz="0" izz="1")")),
                      Contains("link 'l1'") && Contains("<inertia> iyy") && Contains("not finite"));
  REQUIRE_THROWS_WITH(link(inertialWith("1", unit, R"(<origin xyz="0 0 nan"/>)")),
                      Contains("link 'l1'") && Contains("<inertial> <origin> xyz") && Contains("not finite"));
  REQUIRE_THROWS_WITH(link(inertialWith("heavy", unit)),
                      Contains("link 'l1'") && Contains("<mass> value") && Contains("'heavy' is not a number"));

  // Anywhere: also on a link that would not be part of the model.
  const std::string off = R"(<joint name="jx" type="continuous"><parent link="base"/><child link="lx"/></joint>
      <link name="lx">)" + inertialWith("nan", unit) +
                          "</link>";
  REQUIRE_THROWS_WITH(loadUrdfString(arm(kJointBody, kInertial, off), rootTip("", "l1")),
                      Contains("link 'lx'") && Contains("not finite"));
}

TEST_CASE("error: bad Drake rotor inertia or gear ratio", "[urdf][errors]") {
  const auto with = [&](const std::string& tr) { return loadUrdfString(arm(kJointBody, kInertial, tr)); };
  REQUIRE_THROWS_WITH(with(transmission("t1", "j1", R"(<drake:rotor_inertia value="-0.5"/>)")),
                      Contains("<string>") && Contains("transmission 't1'") && Contains("<drake:rotor_inertia>") &&
                          Contains("-0.5 is negative"));
  REQUIRE_THROWS_WITH(with(transmission("t1", "j1", R"(<drake:rotor_inertia value="big"/>)")),
                      Contains("transmission 't1'") && Contains("<drake:rotor_inertia>") && Contains("not a number"));
  REQUIRE_THROWS_WITH(with(transmission("t1", "j1", R"(<drake:rotor_inertia value="nan"/>)")),
                      Contains("transmission 't1'") && Contains("<drake:rotor_inertia>") && Contains("not finite"));
  REQUIRE_THROWS_WITH(with(transmission("t1", "j1", R"(<drake:rotor_inertia/>)")),
                      Contains("transmission 't1'") && Contains("no value"));
  REQUIRE_THROWS_WITH(
      with(transmission("t1", "j1", R"(<drake:rotor_inertia value="1"/><drake:gear_ratio value="-3"/>)")),
      Contains("transmission 't1'") && Contains("<drake:gear_ratio>") && Contains("-3 is negative"));
  REQUIRE_THROWS_WITH(
      with(transmission("t1", "j1", R"(<drake:rotor_inertia value="1"/><drake:gear_ratio value="x3"/>)")),
      Contains("<drake:gear_ratio>") && Contains("not a number"));
  REQUIRE_THROWS_WITH(with(transmission("t1", "j7", R"(<drake:rotor_inertia value="1"/>)")),
                      Contains("transmission 't1'") && Contains("'j7'") && Contains("not a joint"));
}

TEST_CASE("a text ending inside a multi-byte UTF-8 name is refused, never read past its end", "[urdf]") {
  // TinyXML steps over the final NUL when the last byte is a UTF-8 lead byte
  // (found by fuzz_urdf); the ASan build of this test reads out of bounds if
  // the loader passes the text without room after it.
  const std::string text = "<?xml version=\"1.0\"?>\n<robot name=\"r\">\n  <joint name=\"j\xdd\xd7";
  for (std::size_t cut = text.size() - 3; cut <= text.size(); ++cut) {
    const std::string truncated = text.substr(0, cut);
    CHECK_THROWS_AS(zwang::loadUrdfString(truncated), zwang::ModelError);
  }
}
