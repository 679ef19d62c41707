// URDF trees (issue #14): without a tip the loader takes the whole tree below
// the root, bodies depth first with each link's children in the order of
// their joints' names; root + tip still give the chain. A tree written by hand,
// the same tree built joint by joint with the ModelBuilder, random trees
// through the URDF writer, and Baxter (a real dual-arm tree with mimic
// grippers) from models/.
#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "support/chain_spec.hpp"
#include "support/random_chain.hpp"
#include "support/random_problem.hpp"
#include "support/urdf_writer.hpp"
#include "zwang/zwang.hpp"

#include "model/urdf_option_names.hpp"  // the front ends' names of the options

using Catch::Contains;
using namespace zwang;
using namespace zwang::testing;

namespace {

const std::string kModels = ZWANG_MODELS_DIR;

// world -waist-> torso; torso -fixed-> chest, torso -fixed-> sensor;
// chest -fixed-> left_mount -left_shoulder-> left_upper -left_elbow (prismatic)-> left_lower -fixed-> left_hand;
// chest -right_shoulder-> right_upper -right_elbow-> right_lower -fixed-> right_hand.
// The right arm comes first in the file; the loader orders children by joint
// name, so the left arm's joints come first.
const std::string kTwoArms = R"(<robot name="two_arms">
  <link name="world"/>
  <joint name="waist" type="revolute"><parent link="world"/><child link="torso"/>
    <origin xyz="0 0 0.5"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" effort="100" velocity="2"/><dynamics friction="2" damping="0.1"/></joint>
  <link name="torso"><inertial><origin xyz="0 0 0.2"/><mass value="10"/>
    <inertia ixx="0.5" ixy="0" ixz="0" iyy="0.5" iyz="0" izz="0.2"/></inertial></link>
  <joint name="sensor_joint" type="fixed"><parent link="torso"/><child link="sensor"/>
    <origin xyz="0.1 0 0.6" rpy="0 0.3 0"/></joint>
  <link name="sensor"><inertial><mass value="0.4"/>
    <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial></link>
  <joint name="chest_joint" type="fixed"><parent link="torso"/><child link="chest"/>
    <origin xyz="0 0 0.3" rpy="0 0 0.2"/></joint>
  <link name="chest"><inertial><origin xyz="0.05 0 0"/><mass value="3"/>
    <inertia ixx="0.05" ixy="0" ixz="0" iyy="0.04" iyz="0" izz="0.03"/></inertial></link>
  <joint name="right_shoulder" type="revolute"><parent link="chest"/><child link="right_upper"/>
    <origin xyz="0 -0.25 0.1" rpy="0.5 0 0"/><axis xyz="0 1 0"/>
    <limit lower="-2.5" upper="2.5" effort="50" velocity="3"/><dynamics friction="1" damping="0.05"/></joint>
  <link name="right_upper"><inertial><origin xyz="0 0 -0.15" rpy="0.1 0.2 0.3"/><mass value="2"/>
    <inertia ixx="0.02" ixy="0.001" ixz="0" iyy="0.02" iyz="0" izz="0.005"/></inertial></link>
  <joint name="right_elbow" type="revolute"><parent link="right_upper"/><child link="right_lower"/>
    <origin xyz="0 0 -0.3"/><axis xyz="1 0 0"/>
    <limit lower="-2.5" upper="2.5" effort="30" velocity="3"/><dynamics friction="0.5" damping="0.02"/></joint>
  <link name="right_lower"><inertial><origin xyz="0 0.01 -0.12"/><mass value="1.5"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.002"/></inertial></link>
  <joint name="right_hand_joint" type="fixed"><parent link="right_lower"/><child link="right_hand"/>
    <origin xyz="0 0 -0.25"/></joint>
  <link name="right_hand"/>
  <joint name="left_mount_joint" type="fixed"><parent link="chest"/><child link="left_mount"/>
    <origin xyz="0 0.25 0.1" rpy="-0.5 0 0"/></joint>
  <link name="left_mount"/>
  <joint name="left_shoulder" type="revolute"><parent link="left_mount"/><child link="left_upper"/>
    <axis xyz="0 1 0"/><limit lower="-2.5" upper="2.5" effort="50" velocity="3"/>
    <dynamics friction="1" damping="0.05"/></joint>
  <link name="left_upper"><inertial><origin xyz="0 0 -0.15"/><mass value="2"/>
    <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.005"/></inertial></link>
  <joint name="left_elbow" type="prismatic"><parent link="left_upper"/><child link="left_lower"/>
    <origin xyz="0 0 -0.3"/><axis xyz="0 0 -1"/>
    <limit lower="0" upper="0.2" effort="200" velocity="0.5"/><dynamics friction="3" damping="1"/></joint>
  <link name="left_lower"><inertial><origin xyz="0 0 -0.1"/><mass value="1.2"/>
    <inertia ixx="0.008" ixy="0" ixz="0" iyy="0.008" iyz="0" izz="0.001"/></inertial></link>
  <joint name="left_hand_joint" type="fixed"><parent link="left_lower"/><child link="left_hand"/>
    <origin xyz="0 0 -0.2"/></joint>
  <link name="left_hand"/>
</robot>)";

Mat3 rpy(double r, double p, double y) {
  return (Eigen::AngleAxisd(y, Vec3::UnitZ()) * Eigen::AngleAxisd(p, Vec3::UnitY()) *
          Eigen::AngleAxisd(r, Vec3::UnitX()))
      .toRotationMatrix();
}

Transform pose(const Vec3& xyz, const Mat3& R = Mat3::Identity()) { return Transform::fromPose(R, xyz); }

RigidInertia inertia(double mass, const Vec3& com, const Mat3& I, const Mat3& R = Mat3::Identity()) {
  return RigidInertia::fromMassComInertia(mass, com, R * I * R.transpose());
}

Joint joint(const std::string& name, JointType type, const Vec3& axis, const Transform& placement, double lower,
            double upper, double effort, double velocity, double friction, double damping) {
  Joint j;
  j.name = name;
  j.type = type;
  j.axis = axis;
  j.placement = placement;
  j.lower = lower;
  j.upper = upper;
  j.effort_limit = effort;
  j.velocity_limit = velocity;
  j.breakaway_friction = j.kinetic_friction = friction;
  j.viscous_friction = damping;
  return j;
}

// kTwoArms built joint by joint with the ModelBuilder: what the URDF says, by hand.
Model twoArmsByHand() {
  const Mat3 I_torso = Eigen::Vector3d(0.5, 0.5, 0.2).asDiagonal();
  const Mat3 I_sensor = Eigen::Vector3d(0.001, 0.001, 0.001).asDiagonal();
  const Mat3 I_chest = Eigen::Vector3d(0.05, 0.04, 0.03).asDiagonal();
  Mat3 I_right_upper;
  I_right_upper << 0.02, 0.001, 0, 0.001, 0.02, 0, 0, 0, 0.005;
  const Mat3 I_right_lower = Eigen::Vector3d(0.01, 0.01, 0.002).asDiagonal();
  const Mat3 I_left_upper = Eigen::Vector3d(0.02, 0.02, 0.005).asDiagonal();
  const Mat3 I_left_lower = Eigen::Vector3d(0.008, 0.008, 0.001).asDiagonal();
  ModelBuilder b("two_arms", "world");
  b.addJoint(joint("waist", JointType::Revolute, Vec3::UnitZ(), pose(Vec3(0, 0, 0.5)), -2, 2, 100, 2, 2, 0.1), "torso",
             inertia(10, Vec3(0, 0, 0.2), I_torso), "world");
  b.addFixedFrame("sensor", "torso", pose(Vec3(0.1, 0, 0.6), rpy(0, 0.3, 0)), inertia(0.4, Vec3::Zero(), I_sensor));
  b.addFixedFrame("chest", "torso", pose(Vec3(0, 0, 0.3), rpy(0, 0, 0.2)), inertia(3, Vec3(0.05, 0, 0), I_chest));
  b.addFixedFrame("left_mount", "chest", pose(Vec3(0, 0.25, 0.1), rpy(-0.5, 0, 0)), RigidInertia{});
  b.addJoint(joint("left_shoulder", JointType::Revolute, Vec3::UnitY(), Transform{}, -2.5, 2.5, 50, 3, 1, 0.05),
             "left_upper", inertia(2, Vec3(0, 0, -0.15), I_left_upper), "left_mount");
  b.addJoint(joint("left_elbow", JointType::Prismatic, -Vec3::UnitZ(), pose(Vec3(0, 0, -0.3)), 0, 0.2, 200, 0.5, 3, 1),
             "left_lower", inertia(1.2, Vec3(0, 0, -0.1), I_left_lower), "left_upper");
  b.addFixedFrame("left_hand", "left_lower", pose(Vec3(0, 0, -0.2)), RigidInertia{});
  b.addJoint(joint("right_shoulder", JointType::Revolute, Vec3::UnitY(), pose(Vec3(0, -0.25, 0.1), rpy(0.5, 0, 0)),
                   -2.5, 2.5, 50, 3, 1, 0.05),
             "right_upper", inertia(2, Vec3(0, 0, -0.15), I_right_upper, rpy(0.1, 0.2, 0.3)), "chest");
  b.addJoint(
      joint("right_elbow", JointType::Revolute, Vec3::UnitX(), pose(Vec3(0, 0, -0.3)), -2.5, 2.5, 30, 3, 0.5, 0.02),
      "right_lower", inertia(1.5, Vec3(0, 0.01, -0.12), I_right_lower), "right_upper");
  b.addFixedFrame("right_hand", "right_lower", pose(Vec3(0, 0, -0.25)), RigidInertia{});
  return b.build();
}

double maxDifference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return a.size() == 0 ? 0.0 : (a - b).cwiseAbs().maxCoeff();
}

double transformDifference(const Transform& a, const Transform& b) {
  return std::max(maxDifference(a.E, b.E), maxDifference(a.r, b.r));
}

double inertiaDifference(const RigidInertia& a, const RigidInertia& b) {
  return std::max({std::abs(a.mass - b.mass), maxDifference(a.h, b.h), maxDifference(a.Ibar, b.Ibar)});
}

std::vector<std::string> jointNames(const Model& m) {
  std::vector<std::string> names;
  for (const Joint& j : m.joints()) names.push_back(j.name);
  return names;
}

std::vector<WarningCode> codes(const Model& m) {
  std::vector<WarningCode> out;
  for (const ModelWarning& w : m.warnings()) out.push_back(w.code);
  return out;
}

UrdfOptions rootTip(const std::string& root, const std::string& tip) {
  UrdfOptions o;
  o.root = root;
  o.tip = tip;
  return o;
}

UrdfOptions lockMimic() {
  UrdfOptions o;
  o.mimic = MimicJoints::Lock;
  return o;
}

}  // namespace

TEST_CASE("a hand-written tree loads whole: parents, subtrees, joint order by name, frames", "[urdf][trees]") {
  const Model m = loadUrdfString(kTwoArms);
  REQUIRE(m.dof() == 5);
  CHECK_FALSE(m.isChain());
  CHECK(jointNames(m) ==
        std::vector<std::string>{"waist", "left_shoulder", "left_elbow", "right_shoulder", "right_elbow"});
  // Bodies: 0 world, 1 torso, 2 left_upper, 3 left_lower, 4 right_upper, 5 right_lower.
  const std::vector<int> parents{-1, 0, 1, 2, 1, 4}, ends{6, 6, 4, 4, 6, 6};
  for (int b = 0; b < m.bodyCount(); ++b) {
    INFO("body " << b);
    CHECK(m.parent(b) == parents[static_cast<std::size_t>(b)]);
    CHECK(m.subtreeEnd(b) == ends[static_cast<std::size_t>(b)]);
  }
  CHECK(m.parentBodyOfJoint(3) == 1);  // right_shoulder hangs from the torso's body
  CHECK(m.supports(1, 5));
  CHECK_FALSE(m.supports(2, 4));
  const std::vector<std::pair<std::string, int>> frames{
      {"world", 0},      {"torso", 1},     {"sensor", 1},      {"chest", 1},       {"left_mount", 1}, {"left_upper", 2},
      {"left_lower", 3}, {"left_hand", 3}, {"right_upper", 4}, {"right_lower", 5}, {"right_hand", 5}};
  CHECK(m.frames().size() == frames.size());
  for (const auto& [name, body] : frames) {
    INFO(name);
    REQUIRE(m.hasFrame(name));
    CHECK(m.frame(m.frameIndex(name)).body == body);
  }
  CHECK(m.frame(m.bodyFrame(0)).name == "world");
  CHECK(m.frame(m.bodyFrame(4)).name == "right_upper");
  CHECK(m.joint(2).type == JointType::Prismatic);
  CHECK(m.joint(2).breakaway_friction == 3.0);
  CHECK(m.warnings().empty());  // nothing off a chain in a whole tree
}

TEST_CASE("a loaded tree is the tree built by hand: model data and dynamics", "[urdf][trees]") {
  const Model loaded = loadUrdfString(kTwoArms), hand = twoArmsByHand();
  REQUIRE(loaded.dof() == hand.dof());
  REQUIRE(jointNames(loaded) == jointNames(hand));
  double d_model = 0.0;
  for (int b = 0; b < hand.bodyCount(); ++b) {
    CHECK(loaded.parent(b) == hand.parent(b));
    CHECK(loaded.subtreeEnd(b) == hand.subtreeEnd(b));
    d_model = std::max(d_model, inertiaDifference(loaded.inertia(b), hand.inertia(b)));
  }
  for (int j = 0; j < hand.dof(); ++j) {
    d_model = std::max(d_model, transformDifference(loaded.joint(j).placement, hand.joint(j).placement));
    d_model = std::max(d_model, maxDifference(loaded.joint(j).axis, hand.joint(j).axis));
    CHECK(loaded.joint(j).lower == hand.joint(j).lower);
    CHECK(loaded.joint(j).upper == hand.joint(j).upper);
    CHECK(loaded.joint(j).viscous_friction == hand.joint(j).viscous_friction);
  }
  for (const Frame& f : hand.frames()) {
    const Frame& g = loaded.frame(loaded.frameIndex(f.name));
    CHECK(g.body == f.body);
    d_model = std::max(d_model, transformDifference(g.placement, f.placement));
  }
  CHECK(d_model < 1e-14);

  // Forward dynamics with the hands held together (relative, 6 rows) and a wrench on the sensor.
  const auto solve = [](const Model& m, Eigen::VectorXd& qdd, Eigen::VectorXd& nu, Eigen::VectorXd& tau_c) {
    Task task(m);
    task.addRelativeConstraint("left_hand", "right_hand", ConstraintMatrix::Identity(6, 6));
    task.wrench(task.addWrench("sensor", Expressed::World)) << 3, -1, 2, 0.1, 0.2, -0.3;
    Workspace ws(m, task);
    Eigen::VectorXd q(5), qd(5), tau(5);
    q << 0.3, -0.4, 0.05, 0.7, -1.1;
    qd << 0.2, -0.1, 0.03, 0.4, 0.5;
    tau << 1, -2, 5, 0.5, -0.3;
    REQUIRE(solveHybridDynamics(m, ws, q, qd, tau, task));
    qdd = ws.solution.qdd;
    nu = ws.solution.nu;
    tau_c = ws.solution.tau_constraint;
  };
  Eigen::VectorXd qdd_l, nu_l, tc_l, qdd_h, nu_h, tc_h;
  solve(loaded, qdd_l, nu_l, tc_l);
  solve(hand, qdd_h, nu_h, tc_h);
  const double e_qdd = relativeError(qdd_l, qdd_h), e_nu = relativeError(nu_l, nu_h), e_tc = relativeError(tc_l, tc_h);
  std::printf(
      "two-arm tree, loaded vs built by hand: model data %.2g, qdd %.2g, nu %.2g, tau_c %.2g (bit-identical: %s)\n",
      d_model, e_qdd, e_nu, e_tc, qdd_l == qdd_h && nu_l == nu_h ? "yes" : "no");
  CHECK(e_qdd < 1e-12);
  CHECK(e_nu < 1e-12);
  CHECK(e_tc < 1e-12);
}

TEST_CASE("root alone: the subtree below it; root and tip: the chain, as before", "[urdf][trees]") {
  SECTION("a subtree root with links welded above it") {
    const Model m = loadUrdfString(kTwoArms, rootTip("chest", ""));
    REQUIRE(m.dof() == 4);
    CHECK(jointNames(m) == std::vector<std::string>{"left_shoulder", "left_elbow", "right_shoulder", "right_elbow"});
    CHECK(m.frame(m.bodyFrame(0)).name == "chest");
    CHECK(m.parent(3) == 0);  // right_shoulder hangs from the base (chest)
    CHECK(m.frame(m.frameIndex("torso")).body == 0);
    CHECK(m.frame(m.frameIndex("sensor")).body == 0);
    CHECK_FALSE(m.hasFrame("world"));  // behind the moving waist
    CHECK(m.warnings().empty());
    // The base's mass (torso, sensor, chest) is not in the dynamics; the arms
    // are the same as in the whole tree with the waist at rest.
    const Model whole = loadUrdfString(kTwoArms);
    for (int b = 1; b < m.bodyCount(); ++b) CHECK(inertiaDifference(m.inertia(b), whole.inertia(b + 1)) < 1e-15);
  }
  SECTION("a subtree that is a chain loads as the chain to its leaf") {
    const Model m = loadUrdfString(kTwoArms, rootTip("left_mount", ""));
    CHECK(m.isChain());
    CHECK(jointNames(m) == std::vector<std::string>{"left_shoulder", "left_elbow"});
    const Model chain = loadUrdfString(kTwoArms, rootTip("left_mount", "left_hand"));
    REQUIRE(m.frames().size() == chain.frames().size());
    for (std::size_t k = 0; k < m.frames().size(); ++k) CHECK(m.frames()[k].name == chain.frames()[k].name);
  }
  SECTION("root and tip: the chain; the other arm rides on the waist, off the chain, with a warning") {
    const Model m = loadUrdfString(kTwoArms, rootTip("", "left_hand"));
    CHECK(m.isChain());
    CHECK(jointNames(m) == std::vector<std::string>{"waist", "left_shoulder", "left_elbow"});
    CHECK(codes(m) == std::vector<WarningCode>{WarningCode::MassOffChain});
    CHECK_THAT(m.warnings()[0].message, Contains("'right_upper', 'right_lower', 'right_hand', 3.5 kg in all"));
  }
  SECTION("an unknown subtree root is named, with the links") {
    REQUIRE_THROWS_WITH(loadUrdfString(kTwoArms, rootTip("shoulders", "")),
                        Contains("<string>: root link 'shoulders' not found (links: ") && Contains("'chest'") &&
                            Contains("'left_hand'"));
  }
  SECTION("a rotor inertia for a joint outside the subtree") {
    UrdfOptions o = rootTip("chest", "");
    o.rotor_inertia["waist"] = 0.1;
    REQUIRE_THROWS_WITH(loadUrdfString(kTwoArms, o),
                        Contains("UrdfOptions::rotor_inertia names joint 'waist', which is not a moving joint of the "
                                 "tree below 'chest' (its joints: 'left_shoulder', 'left_elbow', 'right_shoulder', "
                                 "'right_elbow')"));
  }
}

TEST_CASE("the Panda loads as before: the chain to its unique leaf", "[urdf][trees]") {
  const Model plain = loadUrdfFile(kModels + "/panda.urdf");
  const Model chain = loadUrdfFile(kModels + "/panda.urdf", rootTip("panda_link0", "tool0"));
  CHECK(plain.isChain());
  REQUIRE(plain.dof() == 7);
  REQUIRE(jointNames(plain) == jointNames(chain));
  REQUIRE(plain.frames().size() == chain.frames().size());
  for (std::size_t k = 0; k < plain.frames().size(); ++k) {
    CHECK(plain.frames()[k].name == chain.frames()[k].name);
    CHECK(plain.frames()[k].body == chain.frames()[k].body);
    CHECK(transformDifference(plain.frames()[k].placement, chain.frames()[k].placement) == 0.0);
  }
  for (int b = 0; b < plain.bodyCount(); ++b) CHECK(inertiaDifference(plain.inertia(b), chain.inertia(b)) == 0.0);
  CHECK(plain.warnings().size() == chain.warnings().size());
}

TEST_CASE("random trees through the URDF writer and loader match the ModelBuilder's", "[urdf][trees]") {
  std::mt19937_64 rng(14142);
  double e_tau = 0.0, e_qdd = 0.0;
  int trees = 0, reordered = 0;
  for (int k = 0; k < 200; ++k) {
    const ChainSpec spec = randomTree(rng);
    const Model built = modelFromSpecByBuilder(spec), loaded = loadUrdfString(toUrdf(spec));
    REQUIRE(loaded.dof() == built.dof());
    trees += loaded.isChain() ? 0 : 1;
    // The loader orders each link's children by joint name ("joint10" < "joint2"):
    // the same joints, maybe in another order. perm[j]: the built index of loaded joint j.
    const int n = built.dof();
    std::vector<int> perm(static_cast<std::size_t>(n));
    for (int j = 0; j < n; ++j) perm[static_cast<std::size_t>(j)] = built.jointIndex(loaded.joint(j).name);
    reordered += std::is_sorted(perm.begin(), perm.end()) ? 0 : 1;
    for (int j = 0; j < n; ++j) {  // the same parent joint (−1: the base) on both sides
      const int p_loaded = loaded.parentBodyOfJoint(j) - 1;
      const int p_built = built.parentBodyOfJoint(perm[static_cast<std::size_t>(j)]) - 1;
      CHECK((p_loaded < 0 ? -1 : perm[static_cast<std::size_t>(p_loaded)]) == p_built);
    }
    Eigen::VectorXd q = Eigen::VectorXd::Random(n), qd = Eigen::VectorXd::Random(n), tau = Eigen::VectorXd::Random(n);
    Eigen::VectorXd q_b(n), qd_b(n), tau_b(n);
    for (int j = 0; j < n; ++j) {
      const int b = perm[static_cast<std::size_t>(j)];
      q_b[b] = q[j];
      qd_b[b] = qd[j];
      tau_b[b] = tau[j];
    }
    Task task_l(loaded), task_b(built);
    Workspace ws_l(loaded, task_l), ws_b(built, task_b);
    REQUIRE(solveHybridDynamics(loaded, ws_l, q, qd, tau, task_l));
    REQUIRE(solveHybridDynamics(built, ws_b, q_b, qd_b, tau_b, task_b));
    Eigen::VectorXd qdd_b(n);
    for (int j = 0; j < n; ++j) qdd_b[j] = ws_b.solution.qdd[perm[static_cast<std::size_t>(j)]];
    e_qdd = std::max(e_qdd, relativeError(ws_l.solution.qdd, qdd_b));
    REQUIRE(inverseDynamics(loaded, ws_l, q, qd, ws_l.solution.qdd, task_l));
    e_tau = std::max(e_tau, relativeError(ws_l.tau, tau));
  }
  std::printf(
      "200 random trees (%d branching, %d with joints reordered by name) loaded from URDF vs built: "
      "qdd %.2g, RNEA closure %.2g\n",
      trees, reordered, e_qdd, e_tau);
  CHECK(trees > 100);
  CHECK(reordered > 0);
  CHECK(e_qdd < 1e-10);
  CHECK(e_tau < 1e-10);
}

TEST_CASE("mimic joints in a tree: modelled (the default), locked or refused", "[urdf][trees][errors]") {
  // base -j1-> l1 -fixed-> palm; palm -f1-> finger1, palm -f2 (mimics f1)-> finger2: a tree.
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
    <limit lower="0" upper="0.04" effort="10" velocity="1"/><mimic joint="f1" multiplier="0.5" offset="0.01"/></joint>
  <link name="finger2"><inertial><mass value="0.2"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial></link>
</robot>)";
  const Model modelled = loadUrdfString(gripper);
  CHECK(jointNames(modelled) == std::vector<std::string>{"j1", "f1", "f2"});
  CHECK(modelled.mimicJoints() == std::vector<int>{2});
  CHECK(modelled.joint(2).mimic.leader == 1);
  CHECK(modelled.joint(2).mimic.multiplier == 0.5);
  CHECK(modelled.joint(2).mimic.offset == 0.01);
  CHECK(!modelled.joint(1).mimic.active());
  CHECK(modelled.warnings().empty());
  {  // the same gripper built by hand, mimic law and all: the same motion
    ModelBuilder b("gripper", "base");
    for (int j = 0; j < modelled.dof(); ++j) {
      const Joint& joint = modelled.joint(j);
      const int parent = modelled.parentBodyOfJoint(j);
      b.addJoint(joint, modelled.frame(modelled.bodyFrame(j + 1)).name, modelled.inertia(j + 1),
                 modelled.frame(modelled.bodyFrame(parent)).name);
    }
    b.setMimic("f2", "f1", 0.5, 0.01);
    const Model built = b.build();
    Task task_l(modelled), task_b(built);
    Workspace ws_l(modelled, task_l), ws_b(built, task_b);
    Eigen::VectorXd q(3), qd(3), tau(3);
    q << 0.4, 0.02, 0.0;
    qd << -0.3, 0.1, 0.0;
    tau << 0.5, 2.0, -1.0;
    modelled.followLeaders(q, qd);
    CHECK(q[2] == 0.5 * 0.02 + 0.01);
    CHECK(qd[2] == 0.5 * 0.1);
    REQUIRE(solveHybridDynamics(modelled, ws_l, q, qd, tau, task_l));
    REQUIRE(solveHybridDynamics(built, ws_b, q, qd, tau, task_b));
    CHECK(relativeError(ws_l.solution.qdd, ws_b.solution.qdd) < 1e-14);
    CHECK(std::abs(ws_l.solution.qdd[2] - 0.5 * ws_l.solution.qdd[1]) < 1e-12 * (1 + std::abs(ws_l.solution.qdd[1])));
    CHECK(ws_l.solution.tau_control[2] == 0.0);  // the leader's motor carries it
    Eigen::VectorXd q_off = q;
    q_off[2] = 0.0;  // not where f1 puts it
    const Status s = solveHybridDynamics(modelled, ws_l, q_off, qd, tau, task_l);
    CHECK(s.code == StatusCode::MimicMismatch);
    CHECK_THAT(std::string(s.message), Contains("joint 'f2' mimics 'f1'"));
  }

  UrdfOptions refuse;
  refuse.mimic = MimicJoints::Refuse;
  REQUIRE_THROWS_WITH(
      loadUrdfString(gripper, refuse),
      Contains("<string>: joint 'f2' mimics joint 'f1' (q = 0.5·q_f1 + 0.01): refused (UrdfOptions::mimic = "
               "MimicJoints::Refuse)") &&
          Contains("set UrdfOptions::mimic = MimicJoints::Lock to weld it at q = 0.01 (its position when 'f1' is at "
                   "rest)"));

  const Model locked = loadUrdfString(gripper, lockMimic());
  CHECK(jointNames(locked) == std::vector<std::string>{"j1", "f1"});
  CHECK(locked.isChain());
  CHECK(locked.frame(locked.frameIndex("finger2")).body == 1);
  CHECK(locked.frame(locked.frameIndex("finger2")).placement.originOfTarget().isApprox(Vec3(0.3, -0.01, 0)));
  REQUIRE(codes(locked) == std::vector<WarningCode>{WarningCode::MimicLocked});
  CHECK_THAT(locked.warnings()[0].message,
             Contains("joint 'f2' mimics joint 'f1' (q = 0.5·q_f1 + 0.01): locked at q = 0.01"));
  UrdfOptions strict = lockMimic();
  strict.strict = true;
  CHECK(loadUrdfString(gripper, strict).dof() == 2);  // a note: strict lets it pass

  UrdfOptions at = lockMimic();
  at.locked_positions["f2"] = 0.03;
  const Model m_at = loadUrdfString(gripper, at);
  CHECK(m_at.frame(m_at.frameIndex("finger2")).placement.originOfTarget().isApprox(Vec3(0.3, -0.03, 0)));
  at.locked_positions = {{"f1", 0.02}};  // f1 is a joint of the model, not locked
  REQUIRE_THROWS_WITH(loadUrdfString(gripper, at),
                      Contains("locked position for joint 'f1' (0.02): not a finite position of a locked mimic joint "
                               "(those joints: 'f2')"));

  // On an explicit chain through the mimic joint: its leader is off the chain,
  // so the coupling cannot be kept: refused, or locked.
  REQUIRE_THROWS_WITH(loadUrdfString(gripper, rootTip("", "finger2")),
                      Contains("joint 'f2' (q = 0.5·q_f1 + 0.01) mimics joint 'f1', which is not in the chain from "
                               "'base' to 'finger2': load a tree or chain that holds both, or set UrdfOptions::mimic "
                               "= MimicJoints::Lock"));
  UrdfOptions refuse_chain = rootTip("", "finger2");
  refuse_chain.mimic = MimicJoints::Refuse;
  REQUIRE_THROWS_WITH(loadUrdfString(gripper, refuse_chain),
                      Contains("joint 'f2' on the chain mimics joint 'f1'") &&
                          Contains("choose a UrdfOptions::tip before it (e.g. 'palm')"));
  // The subtree below the palm holds both fingers: modelled.
  UrdfOptions palm;
  palm.root = "palm";
  const Model hand = loadUrdfString(gripper, palm);
  CHECK(jointNames(hand) == std::vector<std::string>{"f1", "f2"});
  CHECK(hand.joint(1).mimic.leader == 0);
  UrdfOptions chain = rootTip("", "finger2");
  chain.mimic = MimicJoints::Lock;
  const Model c = loadUrdfString(gripper, chain);
  CHECK(jointNames(c) == std::vector<std::string>{"j1"});
  // finger1 hangs from the tip body through the moving f1: beyond the tip.
  CHECK(codes(c) == std::vector<WarningCode>{WarningCode::MimicLocked, WarningCode::MassBeyondTip});
}

TEST_CASE("mimic joints: nothing left to move, or no finite position to lock at", "[urdf][trees][errors]") {
  // base -m1-> a and base -m2-> b, each mimicking the other: a tree of mimic joints only.
  const std::string mimics = R"(<robot name="mimics"><link name="base"/>
  <joint name="m1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/><mimic joint="m2" multiplier="1e300"/></joint>
  <link name="a"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="m2" type="revolute"><parent link="base"/><child link="b"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/><mimic joint="m1"/></joint>
  <link name="b"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
</robot>)";
  REQUIRE_THROWS_WITH(loadUrdfString(mimics), Contains("<string>: mimic joints 'm1' → 'm2' → 'm1' form a cycle"));
  REQUIRE_THROWS_WITH(loadUrdfString(mimics, lockMimic()),
                      Contains("the tree below root link 'base' has no moving joint (its mimic joints are locked)"));
  std::string missing = mimics;
  missing.replace(missing.find("<mimic joint=\"m1\"/>"), std::string("<mimic joint=\"m1\"/>").size(),
                  "<mimic joint=\"nope\"/>");
  REQUIRE_THROWS_WITH(loadUrdfString(missing),
                      Catch::Equals("<string>: joint 'm2' (q = 1·q_nope + 0) mimics joint 'nope', which the URDF "
                                    "does not have: set UrdfOptions::mimic = MimicJoints::Lock to weld it at q = 0 "
                                    "(its position when 'nope' is at rest)"));
  // The names the CLI and Python give the lock option (their loader, found by argument-dependent lookup).
  zwang::internal::NamedUrdfOptions cli;
  cli.names.lock_mimic = "--lock-mimic";
  REQUIRE_THROWS_WITH(loadUrdfString(missing, cli), Contains("which the URDF does not have: set --lock-mimic to weld"));
  cli.names.lock_mimic = "lock_mimic=True";
  REQUIRE_THROWS_WITH(loadUrdfString(missing, cli), Contains("which the URDF does not have: set lock_mimic=True to "));
  std::string lone = missing;  // m1 independent: what the message suggests loads
  lone.erase(lone.find("<mimic joint=\"m2\" multiplier=\"1e300\"/>"),
             std::string("<mimic joint=\"m2\" multiplier=\"1e300\"/>").size());
  REQUIRE_THROWS_WITH(loadUrdfString(lone), Contains("mimics joint 'nope', which the URDF does not have: set"));
  CHECK(loadUrdfString(lone, lockMimic()).dof() == 1);
  std::string fixed_leader = mimics;  // a leader that does not move
  fixed_leader.replace(fixed_leader.find("<mimic joint=\"m1\"/>"), std::string("<mimic joint=\"m1\"/>").size(),
                       "<mimic joint=\"w\" offset=\"0.2\"/>");
  fixed_leader.insert(fixed_leader.find("</robot>"),
                      R"(<joint name="w" type="fixed"><parent link="base"/><child link="c"/></joint><link name="c"/>)");
  REQUIRE_THROWS_WITH(loadUrdfString(fixed_leader),
                      Catch::Equals("<string>: joint 'm2' (q = 1·q_w + 0.2) mimics joint 'w', which is not a moving "
                                    "joint (a fixed, floating or planar joint): set UrdfOptions::mimic = "
                                    "MimicJoints::Lock to weld it at q = 0.2 (its position when 'w' is at rest)"));
  UrdfOptions chain = lockMimic();
  chain.tip = "b";
  REQUIRE_THROWS_WITH(loadUrdfString(mimics, chain),
                      Contains("the chain from root link 'base' to tip link 'b' has no moving joint (its mimic joints "
                               "are locked)"));
  UrdfOptions huge = lockMimic();
  huge.locked_positions["m2"] = 1e300;
  REQUIRE_THROWS_WITH(loadUrdfString(mimics, huge),
                      Contains("joint 'm1' (q = 1e+300·q_m2 + 0): the position to lock it at is not finite"));
}

TEST_CASE("Baxter: the whole dual-arm tree with its mimic fingers modelled, or locked", "[urdf][trees]") {
  const std::string file = kModels + "/baxter.urdf";
  // The file's 19 moving joints, depth first from 'base' with children by joint
  // name: head_pan, the left arm, its gripper's two fingers, the right arm and
  // its fingers. The two r_finger joints mimic the l_finger joints.
  const Model full = loadUrdfFile(file);
  REQUIRE(full.dof() == 19);
  REQUIRE(full.mimicJoints().size() == 2);
  for (const int j : full.mimicJoints()) {
    const Joint& joint = full.joint(j);
    CHECK(joint.name.find("_gripper_r_finger_joint") != std::string::npos);
    CHECK(full.joint(joint.mimic.leader).name == joint.name.substr(0, 2) + "gripper_l_finger_joint");
    CHECK(joint.mimic.multiplier == -1.0);
  }
  {  // both grippers close while the arms hold still against gravity: the
     // fingers move as one, and only the leaders' motors work.
    Task task(full);
    Workspace ws(full, task);
    Eigen::VectorXd q = Eigen::VectorXd::Zero(19), qd = q, tau = q;
    for (const int j : full.mimicJoints()) {
      const int l = full.joint(j).mimic.leader;
      q[l] = 0.01;
      qd[l] = -0.02;
      tau[l] = 5.0;
      tau[j] = 1.0;
    }
    full.followLeaders(q, qd);
    REQUIRE(solveHybridDynamics(full, ws, q, qd, tau, task));
    for (const int j : full.mimicJoints()) {
      const int l = full.joint(j).mimic.leader;
      CHECK(std::abs(ws.solution.qdd[j] + ws.solution.qdd[l]) < 1e-10 * (1 + std::abs(ws.solution.qdd[l])));
      CHECK(ws.solution.tau_control[j] == 0.0);
      CHECK(std::abs(ws.solution.tau_control[l] - (5.0 - 1.0)) < 1e-12);  // τ_l + a·τ_m, a = −1
    }
    CHECK(ws.solution.balance.residual < 1e-9);
  }
  const Model m = loadUrdfFile(file, lockMimic());
  const std::vector<std::string> expected{"head_pan",
                                          "left_s0",
                                          "left_s1",
                                          "left_e0",
                                          "left_e1",
                                          "left_w0",
                                          "left_w1",
                                          "left_w2",
                                          "l_gripper_l_finger_joint",
                                          "right_s0",
                                          "right_s1",
                                          "right_e0",
                                          "right_e1",
                                          "right_w0",
                                          "right_w1",
                                          "right_w2",
                                          "r_gripper_l_finger_joint"};
  REQUIRE(jointNames(m) == expected);  // 19 − 2 locked mimic joints
  CHECK(m.frame(m.bodyFrame(0)).name == "base");
  CHECK(m.parentBodyOfJoint(0) == 0);                                // head_pan on the torso, welded to the base
  CHECK(m.parentBodyOfJoint(1) == 0);                                // left_s0
  CHECK(m.parentBodyOfJoint(9) == 0);                                // right_s0
  CHECK(m.parentBodyOfJoint(8) == 8);                                // the left finger on left_w2's body
  CHECK(m.subtreeEnd(2) == 10);                                      // the left arm: bodies 2–9
  CHECK(m.frame(m.frameIndex("l_gripper_r_finger_tip")).body == 8);  // welded with its locked joint
  const std::vector<WarningCode> c = codes(m);
  CHECK(std::count(c.begin(), c.end(), WarningCode::MimicLocked) == 2);
  CHECK(std::count(c.begin(), c.end(), WarningCode::MassBeyondTip) == 0);
  CHECK(std::count(c.begin(), c.end(), WarningCode::MassOffChain) == 0);

  // Each arm of the tree is the arm's chain with the gripper attached (the
  // fingers welded at 0): inverse dynamics agree with the finger at rest.
  UrdfOptions left = rootTip("", "left_gripper");
  left.attach_beyond_tip = true;
  const Model arm = loadUrdfFile(file, left);
  REQUIRE(arm.dof() == 7);
  Task task_tree(m), task_arm(arm);
  Workspace ws_tree(m, task_tree), ws_arm(arm, task_arm);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(17), qd = q, qdd = q;
  Eigen::VectorXd q_arm(7), qd_arm(7), qdd_arm(7);
  q_arm << 0.3, -0.5, 0.2, 1.2, -0.3, 0.8, 0.1;
  qd_arm << 0.1, 0.2, -0.3, 0.1, 0.05, -0.2, 0.3;
  qdd_arm << 1, -0.5, 0.3, 0.2, -1, 0.4, 0.7;
  q.segment(1, 7) = q_arm;
  qd.segment(1, 7) = qd_arm;
  qdd.segment(1, 7) = qdd_arm;
  q(9) = -0.4;  // the right arm moves too; it does not load the left one (the torso is welded to the base)
  qd(10) = 0.5;
  REQUIRE(inverseDynamics(m, ws_tree, q, qd, qdd, task_tree));
  REQUIRE(inverseDynamics(arm, ws_arm, q_arm, qd_arm, qdd_arm, task_arm));
  const double e = relativeError(ws_tree.tau.segment(1, 7), ws_arm.tau);
  std::printf(
      "Baxter tree: %d moving joints (2 mimic locked); left arm's RNEA vs its chain with the gripper attached: %.2g\n",
      m.dof(), e);
  CHECK(e < 1e-12);
}
