// MuJoCo (Debian's libmujoco-dev, 2.2.2) as an independent oracle for the
// unconstrained dynamics of kinematic trees (issue #14, randomTree): mj_forward's qacc
// against solveHybridDynamics' q̈ with an empty task, mj_inverse's qfrc_inverse
// against inverseDynamics' τ. MuJoCo shares no code with zwang or with the
// other references; the model reaches it through our MJCF writer
// (test/support/mjcf_writer.cpp, which documents the mapping) and reaches zwang
// through modelFromSpec (a chain: the URDF writer and loader; a tree: the
// ModelBuilder). Conventions, checked here rather than assumed:
//  * MuJoCo's world is the root link's frame (links[0] is welded to the world at
//    the identity), so gravity and every axis are the same numbers on both sides;
//  * for hinge and slide joints qpos = q, qvel = q̇, qacc = q̈, and qfrc_applied,
//    qfrc_inverse are the joint torque or force, all positive about/along the
//    joint axis (MuJoCo's joint axis is the URDF axis, in the same body frame);
//  * MuJoCo numbers its dofs in the depth-first order of the MJCF body tree,
//    zwang in its own joint order: every vector is mapped joint by joint through
//    the joint's name (mj_name2id), never by position;
//  * MuJoCo's armature adds to the diagonal of the joint-space inertia exactly
//    as zwang's reflected rotor inertia d_j does.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <mujoco/mujoco.h>
#include <Eigen/Geometry>
#include <catch2/catch.hpp>

#include "support/mjcf_writer.hpp"
#include "support/mujoco_bridge.hpp"
#include "support/random_chain.hpp"
#include "support/random_problem.hpp"

using namespace zwang;
using namespace zwang::testing;

namespace {

// For zwang's joint i: MuJoCo's qpos and dof addresses of the joint of the same name.
struct JointMap {
  std::vector<int> qpos, dof;
};

JointMap mapJoints(const Model& model, const mjModel* m) {
  REQUIRE(m->nv == model.dof());
  REQUIRE(m->nq == model.dof());
  JointMap map;
  for (int i = 0; i < model.dof(); ++i) {
    const Joint& joint = model.joint(i);
    const int id = mj_name2id(m, mjOBJ_JOINT, joint.name.c_str());
    INFO("joint " << joint.name);
    REQUIRE(id >= 0);
    REQUIRE(m->jnt_type[id] == (joint.isRevolute() ? mjJNT_HINGE : mjJNT_SLIDE));
    map.qpos.push_back(m->jnt_qposadr[id]);
    map.dof.push_back(m->jnt_dofadr[id]);
  }
  return map;
}

// One state on one tree, both ways: forward (q̈ from τ) and inverse (τ from q̈).
struct Comparison {
  double forward = 0.0;  // relativeError(q̈ zwang, qacc MuJoCo)
  double inverse = 0.0;  // relativeError(τ zwang, qfrc_inverse MuJoCo)
};

struct State {
  Eigen::VectorXd q, qd, tau, qdd;
  Eigen::Vector3d gravity;
};

State randomState(std::mt19937_64& rng, int n) {
  State s;
  s.q = randomVector(rng, n, 3.0);
  s.qd = randomVector(rng, n, 2.0);
  s.tau = randomVector(rng, n, 10.0);
  s.qdd = randomVector(rng, n, 5.0);
  s.gravity = uniform01(rng) < 0.8 ? Eigen::Vector3d(9.81 * randomUnitVector(rng)) : Eigen::Vector3d::Zero();
  return s;
}

// zwang's model of `spec` against MuJoCo's model of `oracle_spec` (the same
// spec, or a deliberately perturbed one) in state s.
Comparison compare(const ChainSpec& spec, const ChainSpec& oracle_spec, const State& s) {
  const Model model = modelFromSpec(spec);
  Task task(model);  // no constraints, no wrenches
  task.gravity = s.gravity;
  Workspace ws(model, task);
  REQUIRE(solveHybridDynamics(model, ws, s.q, s.qd, s.tau, task));
  const Eigen::VectorXd qdd = ws.solution.qdd;
  REQUIRE(inverseDynamics(model, ws, s.q, s.qd, s.qdd, task));
  const Eigen::VectorXd tau = ws.tau;

  const Mujoco mj(toMjcf(oracle_spec, s.gravity));
  const JointMap map = mapJoints(model, mj.m());
  mjData* d = mj.d();
  scatter(s.q, map.qpos, d->qpos);
  scatter(s.qd, map.dof, d->qvel);
  scatter(s.tau, map.dof, d->qfrc_applied);  // no actuators: the joint torques are applied generalized forces
  mj_forward(mj.m(), d);
  Comparison c;
  c.forward = relativeError(qdd, gather(d->qacc, map.dof));
  scatter(s.qdd, map.dof, d->qacc);
  mj_inverse(mj.m(), d);  // the generalized force that produces qacc: M qacc + bias (constraint solver disabled)
  c.inverse = relativeError(tau, gather(d->qfrc_inverse, map.dof));
  return c;
}

// The rotation of a unit quaternion "w x y z" as MuJoCo stores it.
Eigen::Matrix3d rotation(const mjtNum* wxyz) {
  return Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]).normalized().toRotationMatrix();
}

// True when links[l] moves with some joint: a moving joint on its path to the root.
bool moves(const ChainSpec& spec, int l) {
  for (; l > 0; l = spec.parentLink(static_cast<std::size_t>(l) - 1))
    if (!spec.joints[static_cast<std::size_t>(l) - 1].isFixed()) return true;
  return false;
}

// A small hand-made tree whose depth-first (MuJoCo) dof order differs from the
// spec's joint order: base ─joint1→ link1 ─joint3→ link3, base ─joint2→ link2
// ─joint4 (fixed)→ link4 ─joint5→ link5. MJCF order joint1, joint3, joint2, joint5;
// spec order joint1, joint2, joint3, joint5.
ChainSpec handTree(std::mt19937_64& rng) {
  ChainSpec spec;
  spec.name = "hand_tree";
  for (int i = 0; i <= 5; ++i) {
    LinkSpec link;
    link.name = i == 0 ? "base" : "link" + std::to_string(i);
    link.mass = uniform(rng, 0.5, 2.0);
    link.com = randomVector(rng, 3, 0.2);
    link.inertial_rpy = randomVector(rng, 3, 3.0);
    link.inertia = randomInertia(rng, link.mass);
    spec.links.push_back(link);
  }
  const char* types[] = {"revolute", "prismatic", "continuous", "fixed", "revolute"};
  const int parents[] = {0, 0, 1, 2, 4};
  for (int k = 0; k < 5; ++k) {
    JointSpec joint;
    joint.name = "joint" + std::to_string(k + 1);
    joint.type = types[k];
    joint.parent = parents[k];
    joint.xyz = randomVector(rng, 3, 0.4);
    joint.rpy = randomVector(rng, 3, 3.0);
    joint.axis = randomUnitVector(rng);
    joint.rotor_inertia = uniform(rng, 1e-4, 1e-2);
    joint.gear_ratio = uniform(rng, 1.0, 5.0);
    spec.joints.push_back(joint);
  }
  spec.check();
  return spec;
}

// What MuJoCo compiled from toMjcf(spec) against the spec itself, field by
// field; returns the largest relative inertia difference. Bodies and joints
// are found by name; body 0 is MuJoCo's world.
double checkCompiledModel(const ChainSpec& spec, const mjModel* m) {
  REQUIRE(m->nbody == static_cast<int>(spec.links.size()) + 1);
  REQUIRE(m->nv == spec.dof());
  REQUIRE(m->njnt == spec.dof());
  double inertia_err = 0.0;
  auto body = [&](const std::string& name) {
    const int id = mj_name2id(m, mjOBJ_BODY, name.c_str());
    INFO("body " << name);
    REQUIRE(id >= 1);
    return id;
  };
  REQUIRE(m->body_parentid[body(spec.links[0].name)] == 0);  // the root link is welded to the world
  for (std::size_t i = 0; i < spec.links.size(); ++i) {
    const LinkSpec& link = spec.links[i];
    const int b = body(link.name);
    INFO("link " << link.name);
    CHECK(m->body_mass[b] == Approx(link.mass).epsilon(1e-15).margin(0.0));  // a copy of the written %.17g
    if (link.mass == 0.0) continue;
    // The inertial frame MuJoCo made (COM at body_ipos, principal axes body_iquat, moments body_inertia) against
    // the spec's inertia about the COM turned into the link frame: R I Rᵀ, R = R(inertial_rpy).
    const Eigen::Vector3d ipos(m->body_ipos[3 * b], m->body_ipos[3 * b + 1], m->body_ipos[3 * b + 2]);
    const Eigen::Vector3d moments(m->body_inertia[3 * b], m->body_inertia[3 * b + 1], m->body_inertia[3 * b + 2]);
    const Eigen::Matrix3d Ri = rotation(m->body_iquat + 4 * b);
    const Eigen::Matrix3d Rs = rpyToMatrix(link.inertial_rpy);
    const Eigen::Matrix3d expected = Rs * link.inertia * Rs.transpose();
    inertia_err = std::max(inertia_err, (Ri * moments.asDiagonal() * Ri.transpose() - expected).cwiseAbs().maxCoeff() /
                                            expected.cwiseAbs().maxCoeff());
    // The COM is copied; 1e-15: a few ulps of the sub-metre offsets.
    CHECK((ipos - link.com).cwiseAbs().maxCoeff() < 1e-15);
  }
  for (std::size_t k = 0; k < spec.joints.size(); ++k) {
    const JointSpec& joint = spec.joints[k];
    const int child = body(spec.links[k + 1].name);
    INFO("joint " << joint.name);
    CHECK(m->body_parentid[child] == body(spec.links[static_cast<std::size_t>(spec.parentLink(k))].name));
    // The joint origin: position copied (1e-15: ulps of the sub-metre offsets), orientation the same rotation (a
    // quaternion's sign is free; 1e-14: the rpy → quaternion → matrix round trip on unit-size numbers).
    const Eigen::Vector3d pos(m->body_pos[3 * child], m->body_pos[3 * child + 1], m->body_pos[3 * child + 2]);
    CHECK((pos - joint.xyz).cwiseAbs().maxCoeff() < 1e-15);
    CHECK((rotation(m->body_quat + 4 * child) - rpyToMatrix(joint.rpy)).cwiseAbs().maxCoeff() < 1e-14);
    const int id = mj_name2id(m, mjOBJ_JOINT, joint.name.c_str());
    if (joint.isFixed()) {
      CHECK(id == -1);
      CHECK(m->body_jntnum[child] == 0);
      continue;
    }
    REQUIRE(id >= 0);
    CHECK(m->jnt_bodyid[id] == child);
    CHECK(m->jnt_type[id] == (joint.isPrismatic() ? mjJNT_SLIDE : mjJNT_HINGE));
    CHECK(m->jnt_limited[id] == 0);
    const Eigen::Vector3d axis(m->jnt_axis[3 * id], m->jnt_axis[3 * id + 1], m->jnt_axis[3 * id + 2]);
    CHECK((axis - joint.axis).cwiseAbs().maxCoeff() < 1e-15);  // a unit axis, normalised again: ulps
    const Eigen::Vector3d anchor(m->jnt_pos[3 * id], m->jnt_pos[3 * id + 1], m->jnt_pos[3 * id + 2]);
    CHECK(anchor.isZero(0.0));
    const int dof = m->jnt_dofadr[id];
    CHECK(m->dof_armature[dof] == Approx(joint.reflectedInertia()).epsilon(1e-15).margin(0.0));
    CHECK(m->dof_damping[dof] == 0.0);
    CHECK(m->dof_frictionloss[dof] == 0.0);
  }
  return inertia_err;
}

}  // namespace

TEST_CASE("toMjcf: MuJoCo compiles the spec's bodies, joints, inertias and tree", "[mujoco][references]") {
  std::mt19937_64 rng(1414);
  double inertia_err = 0.0;
  for (int trial = 0; trial < 50; ++trial) {
    const ChainSpec spec = trial % 2 == 0 ? randomTree(rng) : randomChain(rng);
    const Mujoco mj(toMjcf(spec, Eigen::Vector3d(0.0, 0.0, -9.81)));
    inertia_err = std::max(inertia_err, checkCompiledModel(spec, mj.m()));
    // randomTree's trees are depth first: MuJoCo's dofs come in the spec's joint order.
    std::vector<int> dof_joints;
    for (int dof = 0; dof < mj.m()->nv; ++dof)
      dof_joints.push_back(spec.linkIndex(mj_id2name(mj.m(), mjOBJ_BODY, mj.m()->dof_bodyid[dof])) - 1);
    CHECK(dof_joints == spec.movingJoints());
  }

  // A tree that is not depth first (link3's parent link1 is not on link2's path to the base): the bodies still
  // nest by parent link, but MuJoCo's dof order (depth first) is not the spec's joint order, which is why
  // test_mujoco maps every vector by joint name.
  const ChainSpec tree = handTree(rng);
  const Mujoco mj(toMjcf(tree, Eigen::Vector3d(0.0, 0.0, -9.81)));
  inertia_err = std::max(inertia_err, checkCompiledModel(tree, mj.m()));
  std::vector<std::string> dof_order;
  for (int dof = 0; dof < mj.m()->nv; ++dof)
    dof_order.push_back(mj_id2name(mj.m(), mjOBJ_JOINT, mj.m()->dof_jntid[dof]));
  CHECK(dof_order == std::vector<std::string>{"joint1", "joint3", "joint2", "joint5"});

  // The same chain with parent = −1 and with parent = k spelled out writes the same document.
  std::mt19937_64 chain_rng(7);
  ChainSpec chain = randomChain(chain_rng);
  const std::string implicit = toMjcf(chain, Eigen::Vector3d(0.0, 0.0, -9.81));
  for (std::size_t k = 0; k < chain.joints.size(); ++k) chain.joints[k].parent = static_cast<int>(k);
  CHECK(toMjcf(chain, Eigen::Vector3d(0.0, 0.0, -9.81)) == implicit);

  // A moving link without mass: refused, naming it.
  ChainSpec massless = tree;
  massless.links[5].mass = 0.0;
  massless.links[5].inertia.setZero();
  CHECK_THROWS_WITH(toMjcf(massless, Eigen::Vector3d::Zero()), Catch::Contains("link5"));

  std::printf(
      "MuJoCo %s compiles 25 random trees, 25 chains and a 5-joint tree as written; largest relative difference of "
      "its link inertias from the spec's %.2e\n",
      mj_versionString(), inertia_err);
  // The writer diagonalises (Eigen, round-off ~1e-16) and MuJoCo only normalises the quaternion: a correct writer
  // lands within ~1e-15. 1e-12 leaves room for that round-off and still fails the 1.4e-6 of MuJoCo 2.2.2's own
  // diagonalisation of fullinertia (mjcf_writer.cpp) or any wrong axis or order.
  CHECK(inertia_err < 1e-12);
}

TEST_CASE("forward and inverse dynamics match MuJoCo on 220 random trees and 60 chains", "[mujoco]") {
  REQUIRE(mj_version() == mjVERSION_HEADER);  // the library is the one the header describes
  std::mt19937_64 rng(20140);
  Comparison worst;
  int trees = 0, chains = 0, dofs = 0, with_gravity = 0;
  for (int trial = 0; trial < 280; ++trial) {
    // Trees go to zwang through the ModelBuilder, chains through the URDF writer and loader (modelFromSpec).
    const bool tree = trial < 220;
    const ChainSpec spec = tree ? randomTree(rng) : randomChain(rng);
    const State s = randomState(rng, spec.dof());
    const Comparison c = compare(spec, spec, s);
    worst.forward = std::max(worst.forward, c.forward);
    worst.inverse = std::max(worst.inverse, c.inverse);
    ++(tree ? trees : chains);
    dofs += spec.dof();
    if (!s.gravity.isZero()) ++with_gravity;
  }
  std::printf(
      "MuJoCo %s, %d trees and %d chains (%d joints, %d under gravity): max rel. error qdd (mj_forward) %.2e  "
      "tau (mj_inverse) %.2e\n",
      mj_versionString(), trees, chains, dofs, with_gravity, worst.forward, worst.inverse);
  // Both sides are exact recursive algorithms in double precision on a few dozen bodies; the round-off, amplified by
  // the joint-space inertia's condition (light distal links next to 0.5 kg·m² armatures), stays well below 1e-9.
  CHECK(worst.forward < 1e-9);
  CHECK(worst.inverse < 1e-9);
}

TEST_CASE("the MuJoCo comparison fails on a wrong model: armature, inertial frame, joint origin", "[mujoco]") {
  // Three plausible writer mistakes, made on the spec handed to MuJoCo (zwang keeps the right one): each must
  // show up far above the 1e-9 of the comparison, in every tree it changes.
  // Two moving joints at least (randomTree's default) and gravity always on: with one joint and no gravity a
  // turned joint origin would turn the whole arm rigidly and change nothing.
  std::mt19937_64 rng(5150);
  const char* names[] = {"armature + 0.1 on the first joint", "inertial rpy dropped", "joint origin rpy negated"};
  double least[3] = {1e300, 1e300, 1e300};
  int applied[3] = {0, 0, 0};
  for (int trial = 0; trial < 20; ++trial) {
    const ChainSpec spec = randomTree(rng);
    State s = randomState(rng, spec.dof());
    s.gravity = 9.81 * randomUnitVector(rng);
    for (int mistake = 0; mistake < 3; ++mistake) {
      ChainSpec wrong = spec;
      bool changed = false;
      if (mistake == 0) {
        JointSpec& first = wrong.joints[static_cast<std::size_t>(wrong.movingJoints().front())];
        first.rotor_inertia += 0.1 / (first.gear_ratio * first.gear_ratio);
        changed = true;
      }
      for (std::size_t i = 1; mistake == 1 && i < wrong.links.size(); ++i) {
        changed = changed || (moves(wrong, static_cast<int>(i)) && !wrong.links[i].inertial_rpy.isZero(0.0));
        wrong.links[i].inertial_rpy.setZero();
      }
      for (std::size_t k = 0; mistake == 2 && k < wrong.joints.size(); ++k) {
        changed = changed || !wrong.joints[k].rpy.isZero(0.0);
        wrong.joints[k].rpy = -wrong.joints[k].rpy;
      }
      if (!changed) continue;
      ++applied[mistake];
      const Comparison c = compare(spec, wrong, s);
      least[mistake] = std::min(least[mistake], std::max(c.forward, c.inverse));
    }
  }
  for (int mistake = 0; mistake < 3; ++mistake) {
    std::printf("MuJoCo with a wrong model (%s): %d trees, smallest disagreement %.2e\n", names[mistake],
                applied[mistake], least[mistake]);
    CHECK(applied[mistake] >= 10);
    // 1e-6: a thousand times the comparison's tolerance, so a mistake of this kind cannot pass unseen.
    CHECK(least[mistake] > 1e-6);
  }
}
