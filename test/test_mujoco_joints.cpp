// The solver, RNEA and CRBA on trees of EVERY joint type against MuJoCo (Debian's libmujoco-dev 2.2.2) directly
// (issue #25): random trees mixing hinge (revolute, continuous), slide (prismatic) and ball (spherical) joints, ball
// joints anywhere (in the middle of the tree as well as at the leaves), on a free root (a free-flyer base) or a fixed
// base, some fixed bases with free joints of their own on the root link (free bodies built with
// ModelBuilder::addJoint rather than setBase). Random masses, inertias, placements and axes (randomTree), rotor
// inertia (MuJoCo's armature, on each DOF of a joint) on some joints of every type, random q (random unit
// quaternions for ball and free joints), q̇, τ, gravity and up to one wrench:
//  * solveHybridDynamics with an empty task: q̈ against mj_forward's qacc;
//  * inverseDynamics (RNEA) at a random q̈, against mj_inverse's qfrc_inverse, and solveHybridDynamics with every
//    DOF prescribed at that q̈ (issue #27: τ_control is then inverse dynamics) against the same;
//  * jointSpaceInertia (CRBA), against mj_fullM;
//  * every link's velocity and acceleration (frameVelocity, frameAcceleration) against mj_objectVelocity and
//    mj_objectAcceleration, which tells a wrong q̈ apart from wrong kinematics;
//  * the centre of mass, its velocity and acceleration and the centroidal momentum of every moving joint's subtree
//    (and of the whole robot on a free root; center_of_mass.hpp) against subtree_com, mj_subtreeVel's subtree_linvel
//    and subtree_angmom, and the bodies' accelerations at their centres of mass;
// each to 1e-9 relative to max(1, |MuJoCo's value|).
//
// The MJCF and the bridge are test_mujoco_floating's (support/mjcf_writer.hpp, support/mujoco_bridge.hpp): armature =
// the reflected rotor inertia, no damping, stiffness, friction loss, limits, contacts or constraint solver; joints
// mapped by name; MuJoCo's free joints only on top-level bodies (so a free spec joint hangs from the root link of a
// fixed base, at the identity: the root link is the world's frame). No task rows and no mimic joints: MuJoCo's
// equality constraints are soft (test_mujoco_floating's header).
//
// The velocity conventions, zwang's and MuJoCo's (quaternions w x y z in both, qpos = our q entry for entry):
//  * hinge, slide: qvel, qacc, qfrc are our q̇, q̈, τ;
//  * ball (our Spherical): q = the child's orientation in the joint frame; v = ω in the CHILD frame in both
//    (MuJoCo's ball qvel is the body-frame angular velocity); τ = the moment in the child frame in both;
//  * free (our Free root joint and free spec joints): zwang's v = [v; ω], the child origin's velocity and the angular
//    velocity, BOTH in the child frame; MuJoCo's qvel = [ṗ, the origin's velocity in WORLD axes; ω in the BODY
//    frame]. With R = ⁰R_child and T = blockdiag(R, 1₃) on each free joint's six entries, the identity elsewhere:
//      qvel = T v,  qacc = T v̇ + Ṫ v (Ṫ v = [R (ω × v_lin); 0]),  v̇ = T⁻¹ (qacc − Ṫ v),
//      qfrc = T⁻ᵀ τ,  τ = Tᵀ qfrc_inverse,  H = Tᵀ M_mj T
//    (the same power τᵀv and kinetic energy on both sides; support/mujoco_bridge.hpp derives it);
//  * armature on a free joint: both add it to the diagonal of the inertia matrix in their own coordinates, which for
//    the translations differ: MuJoCo's acts on ṗ in world axes (a force a p̈ = a R (v̇_lin + ω × v_lin)), zwang's
//    rotor inertia d on its child-frame v_lin (a force d v̇_lin, as Pinocchio's armature on a free-flyer). The same
//    H, but MuJoCo's dynamics carry the extra a ω × v_lin on those entries (in our coordinates): the test adds it to
//    τ before handing τ to mj_forward and takes it out of mj_inverse's answer (armatureCorrection). Rotations (ball
//    joints, a free joint's ω) have the same coordinates on both sides: no correction.
//
// So that the comparison can fail, the test case "the MuJoCo comparison fails on a wrong velocity convention" makes
// three plausible convention mistakes (a ball's ω read in the joint frame instead of the child's; a free spec joint's
// linear qvel read in body axes; MuJoCo's armature on a free joint taken as ours) and requires each to be seen far
// above 1e-9; two more check the conventions on MuJoCo alone, without zwang (a free spec joint on the world is
// MuJoCo's free base, in our coordinates; at rest, a ball joint is three hinges about the child's axes).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <mujoco/mujoco.h>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <catch2/catch.hpp>

#include "support/floating_reference.hpp"
#include "support/joint_types_problem.hpp"
#include "support/mjcf_writer.hpp"
#include "support/mujoco_bridge.hpp"
#include "support/random_chain.hpp"
#include "support/random_problem.hpp"
#include "zwang/zwang.hpp"

using namespace zwang;
using namespace zwang::testing;

namespace {

// The bound. Both sides are exact algorithms in double precision on up to ~60 DOFs; their round-off,
// amplified by the inertia matrix's condition (light distal links next to armatures up to 0.5 kg·m²), is about 1e-12.
constexpr double kTolerance = 1e-9;
// A convention mistake must disagree by 1000 times the tolerance, so that none can pass unseen.
constexpr double kMistakeFloor = 1e3 * kTolerance;

// How our velocity coordinates are turned into MuJoCo's (Correct), or a plausible mistake.
enum class Conversion {
  Correct,
  BallRatesInJointFrame,  // a ball's qvel taken as ω in the joint (parent) frame: T block = the joint's rotation
  FreeJointLinearInBody,  // a free spec joint's linear qvel taken as body axes (T = 1 on it)
  FreeArmatureAsOurs,     // MuJoCo's armature on a free joint's translations taken as zwang's (no correction)
};

// The joint types of a draw, in the order of the summary.
struct Census {
  int trees = 0, free_roots = 0, fixed_bases = 0, with_free_joints = 0, hinge = 0, slide = 0, ball = 0, ball_inner = 0,
      ball_armature = 0, free = 0, most_dofs = 0;
};

// True when some moving joint lies below links[link] (ancestors through spec.parentLink).
bool hasMovingDescendant(const ChainSpec& spec, int link) {
  for (std::size_t k = 0; k < spec.joints.size(); ++k) {
    if (spec.joints[k].isFixed()) continue;
    for (int l = spec.parentLink(k); l >= 0; l = l == 0 ? -1 : spec.parentLink(static_cast<std::size_t>(l) - 1))
      if (l == link) return true;
  }
  return false;
}

struct JointsProblem {
  ChainSpec spec;
  FloatingBase base;
  FloatingInput input;
  Eigen::VectorXd qdd_inverse;
};

// A random tree (randomTree: 1–30 moving joints, fixed joints anywhere) whose moving joints become ball joints with
// probability 0.35 (half of those without rotor inertia); on a free root when `free_root`, else on a fixed base
// whose root-link joints become free joints (at the identity) with probability `free_joint_probability`. Then the
// state: hinge angles in ±π, slides in ±0.5 m, random unit quaternions, base and free positions in ±2 m, every
// velocity entry in ±2, τ in ±5 on the joints (and in ±5 on a free root in half the draws), gravity (a random
// direction in half the draws, none in a tenth), a wrench on a random link in half the draws, q̈ in ±5 for the RNEA.
JointsProblem randomJointsProblem(std::mt19937_64& rng, bool free_root, double free_joint_probability) {
  RandomTreeOptions options;
  options.min_moving_joints = 1;
  options.max_moving_joints = 30;
  JointsProblem p;
  p.spec = randomTree(rng, options);
  p.spec.name = "joints_tree";
  for (std::size_t k = 0; k < p.spec.joints.size(); ++k) {
    JointSpec& joint = p.spec.joints[k];
    if (joint.isFixed()) continue;
    if (!free_root && p.spec.parentLink(k) == 0 && uniform01(rng) < free_joint_probability) {
      joint.type = "free";
      joint.xyz.setZero();
      joint.rpy.setZero();
    } else if (uniform01(rng) < 0.35) {
      joint.type = "spherical";
      if (uniform01(rng) < 0.5) joint.rotor_inertia = 0.0;
    } else {
      continue;
    }
    joint.lower = joint.upper = 0.0;
  }
  p.spec.check();
  p.base.kind = free_root ? BaseKind::Free : BaseKind::Fixed;

  FloatingInput& in = p.input;
  in.q.resize(p.base.nq(p.spec));
  Eigen::Index qi = 0;
  if (free_root) {
    in.q.head<3>() = randomVector(rng, 3, 2.0);
    in.q.segment<4>(3) = randomQuaternion(rng);
    qi = 7;
  }
  for (const int k : p.spec.movingJoints()) {
    const JointSpec& joint = p.spec.joints[static_cast<std::size_t>(k)];
    if (joint.isFree()) {
      in.q.segment<3>(qi) = randomVector(rng, 3, 2.0);
      in.q.segment<4>(qi + 3) = randomQuaternion(rng);
    } else if (joint.isSpherical()) {
      in.q.segment<4>(qi) = randomQuaternion(rng);
    } else {
      in.q(qi) = joint.isPrismatic() ? uniform(rng, -0.5, 0.5) : uniform(rng, -3.14159, 3.14159);
    }
    qi += joint.nq();
  }
  const int nv = p.base.nv(p.spec), base_velocity_size = p.base.baseVelocitySize();
  in.v = randomVector(rng, nv, 2.0);
  in.tau = randomVector(rng, nv, 5.0);
  if (base_velocity_size > 0 && uniform01(rng) < 0.5) in.tau.head(base_velocity_size).setZero();
  const double g = uniform01(rng);
  in.gravity = g < 0.1   ? Eigen::Vector3d::Zero()
               : g < 0.5 ? Eigen::Vector3d(0.0, 0.0, -9.81)
                         : Eigen::Vector3d(9.81 * randomUnitVector(rng));
  if (uniform01(rng) < 0.5) {
    WrenchInput w;
    w.link = p.spec.links[static_cast<std::size_t>(uniformInt(rng, 0, static_cast<int>(p.spec.links.size()) - 1))].name;
    w.axes = uniform01(rng) < 0.5 ? Axes::Local : Axes::World;
    w.wrench = randomVector(rng, 6, 5.0);
    in.wrenches.push_back(w);
  }
  p.qdd_inverse = randomVector(rng, nv, 5.0);
  return p;
}

void count(const JointsProblem& p, Census& c) {
  ++c.trees;
  c.free_roots += p.base.kind == BaseKind::Free ? 1 : 0;
  c.fixed_bases += p.base.kind == BaseKind::Fixed ? 1 : 0;
  bool has_free = false;
  for (std::size_t k = 0; k < p.spec.joints.size(); ++k) {
    const JointSpec& joint = p.spec.joints[k];
    if (joint.isFixed()) continue;
    if (joint.isFree()) {
      ++c.free;
      has_free = true;
    } else if (joint.isSpherical()) {
      ++c.ball;
      c.ball_inner += hasMovingDescendant(p.spec, static_cast<int>(k) + 1) ? 1 : 0;
      c.ball_armature += joint.reflectedInertia() > 0.0 ? 1 : 0;
    } else if (joint.isPrismatic()) {
      ++c.slide;
    } else {
      ++c.hinge;
    }
  }
  c.with_free_joints += has_free ? 1 : 0;
  c.most_dofs = std::max(c.most_dofs, p.base.nv(p.spec));
}

// u_mujoco = T v and u̇_mujoco = T v̇ + Ṫ v.
struct VelocityChange {
  Eigen::MatrixXd T;
  Eigen::VectorXd Tdot_v;
};

VelocityChange velocityChange(const JointsProblem& p, Conversion conversion) {
  const FloatingInput& in = p.input;
  VelocityChange change{mujocoVelocityMap(p.spec, p.base, in.q), mujocoVelocityMapRate(p.spec, p.base, in.q, in.v)};
  if (conversion == Conversion::Correct) return change;
  Eigen::Index qi = p.base.baseConfigurationSize(), vi = p.base.baseVelocitySize();
  for (const int k : p.spec.movingJoints()) {
    const JointSpec& joint = p.spec.joints[static_cast<std::size_t>(k)];
    if (conversion == Conversion::BallRatesInJointFrame && joint.isSpherical()) {
      // ω_joint = R ω_child, and d/dt (R ω) = R ω̇ (Ṙ ω = R (ω × ω) = 0): no rate term.
      const Eigen::Quaterniond quat(in.q(qi), in.q(qi + 1), in.q(qi + 2), in.q(qi + 3));
      change.T.block<3, 3>(vi, vi) = quat.toRotationMatrix();
    }
    if (conversion == Conversion::FreeJointLinearInBody && joint.isFree()) {
      change.T.block<3, 3>(vi, vi).setIdentity();
      change.Tdot_v.segment<3>(vi).setZero();
    }
    qi += joint.nq();
    vi += joint.nv();
  }
  return change;
}

// The quantities compared, in our coordinates.
struct Answers {
  Eigen::VectorXd qdd;  // forward dynamics: v̇ (the root's, then every joint's entries)
  // Every link's (index as spec.links) classical velocity [ṗ; ω] and acceleration [p̈; ω̇] at its origin, world
  // axes, in the forward motion.
  std::vector<Vector6d> link_velocity, link_acceleration;
  Eigen::VectorXd tau;             // inverse dynamics at qdd_inverse
  Eigen::VectorXd tau_prescribed;  // the same by the hybrid solve with every DOF prescribed (MuJoCo: = tau)
  Eigen::MatrixXd H;               // joint-space inertia
};

Answers solveWithZwang(const JointsProblem& p) {
  const Model model = floatingModelFromSpec(p.spec, p.base);
  REQUIRE(model.nq() == p.base.nq(p.spec));
  REQUIRE(model.nv() == p.base.nv(p.spec));
  const Task task = floatingTaskFromInput(model, p.input);
  REQUIRE(task.constraintRows() == 0);
  Workspace ws(model, task);
  Answers a;
  const Status solved = solveHybridDynamics(model, ws, p.input.q, p.input.v, p.input.tau, task);
  INFO(solved.message);
  REQUIRE(solved);
  a.qdd = ws.solution.qdd;
  for (const LinkSpec& link : p.spec.links) {
    const int frame = model.frameIndex(link.name);
    Vec6 velocity, acceleration;
    REQUIRE(frameVelocity(model, ws, p.input.q, p.input.v, frame, Expressed::World, velocity));
    REQUIRE(frameAcceleration(model, ws, p.input.q, p.input.v, frame, Expressed::World, acceleration));
    a.link_velocity.push_back(velocity);
    a.link_acceleration.push_back(acceleration);
  }
  REQUIRE(inverseDynamics(model, ws, p.input.q, p.input.v, p.qdd_inverse, task));
  a.tau = ws.tau;
  Task prescribed = task;
  for (int v = 0; v < model.nv(); ++v) prescribed.setDofMode(v, DofMode::Prescribed);
  prescribed.prescribedAccelerations() = p.qdd_inverse;
  REQUIRE(solveHybridDynamics(model, ws, p.input.q, p.input.v, p.input.tau, prescribed));
  a.tau_prescribed = ws.solution.tau_control;
  REQUIRE(jointSpaceInertia(model, ws, p.input.q));
  a.H = ws.H;
  return a;
}

// MuJoCo's link velocities and accelerations after mj_forward (as test_mujoco_floating: angular part first in
// MuJoCo's; its cacc starts from −g at the world, so g is added back).
void mujocoLinkMotions(const ChainSpec& spec, const Eigen::Vector3d& gravity, const mjModel* m, mjData* d, Answers& a) {
  mj_rnePostConstraint(m, d);  // cacc: mj_forward leaves it to the sensors that need it
  for (const LinkSpec& link : spec.links) {
    const int body = mj_name2id(m, mjOBJ_BODY, link.name.c_str());
    REQUIRE(body >= 1);
    mjtNum velocity[6], acceleration[6];
    mj_objectVelocity(m, d, mjOBJ_XBODY, body, velocity, 0);
    mj_objectAcceleration(m, d, mjOBJ_XBODY, body, acceleration, 0);
    Vector6d v, acc;
    v << velocity[3], velocity[4], velocity[5], velocity[0], velocity[1], velocity[2];
    acc << Eigen::Vector3d(acceleration[3], acceleration[4], acceleration[5]) + gravity, acceleration[0],
        acceleration[1], acceleration[2];
    a.link_velocity.push_back(v);
    a.link_acceleration.push_back(acc);
  }
}

// The MJCF as MuJoCo compiled it: only the smooth dynamics, no equality constraint, and on every dof no damping,
// stiffness or friction loss and the armature zwang has (0 on a free root, the reflected rotor inertia on every DOF
// of a joint), each joint of the type the spec says with as many DOFs.
void checkMujocoConventions(const JointsProblem& p, const mjModel* m, const MujocoCoordinates& map) {
  const int smooth_only = mjDSBL_CONTACT | mjDSBL_CONSTRAINT | mjDSBL_EQUALITY | mjDSBL_PASSIVE;
  CHECK((m->opt.disableflags & smooth_only) == smooth_only);
  CHECK(m->neq == 0);
  std::vector<double> armature(static_cast<std::size_t>(p.base.baseVelocitySize()), 0.0);
  for (const int k : p.spec.movingJoints()) {
    const JointSpec& joint = p.spec.joints[static_cast<std::size_t>(k)];
    armature.insert(armature.end(), static_cast<std::size_t>(joint.nv()), joint.reflectedInertia());
  }
  REQUIRE(armature.size() == map.dof.size());
  for (std::size_t k = 0; k < map.dof.size(); ++k) {
    const int dof = map.dof[k];
    CHECK(m->dof_armature[dof] == Approx(armature[k]).epsilon(1e-15).margin(0.0));  // the written %.17g, read back
    CHECK(m->dof_damping[dof] == 0.0);
    CHECK(m->dof_frictionloss[dof] == 0.0);
    CHECK(m->jnt_stiffness[m->dof_jntid[dof]] == 0.0);
  }
}

// M (MuJoCo's dense mass matrix) in our coordinate order.
Eigen::MatrixXd mujocoMassMatrix(const mjModel* m, const mjData* d, const std::vector<int>& dof) {
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> full(m->nv, m->nv);
  mj_fullM(m, full.data(), d->qM);
  const auto n = static_cast<Eigen::Index>(dof.size());
  Eigen::MatrixXd M(n, n);
  for (Eigen::Index r = 0; r < n; ++r)
    for (Eigen::Index c = 0; c < n; ++c)
      M(r, c) = full(dof[static_cast<std::size_t>(r)], dof[static_cast<std::size_t>(c)]);
  return M;
}

// The generalized force MuJoCo's armature adds to zwang's on each free spec joint's translations (file comment):
// a ω × v_lin on those entries (our coordinates), 0 elsewhere.
Eigen::VectorXd armatureCorrection(const ChainSpec& spec, const FloatingBase& base, const Eigen::VectorXd& v) {
  Eigen::VectorXd correction = Eigen::VectorXd::Zero(v.size());
  Eigen::Index vi = base.baseVelocitySize();
  for (const int k : spec.movingJoints()) {
    const JointSpec& joint = spec.joints[static_cast<std::size_t>(k)];
    if (joint.isFree())
      correction.segment<3>(vi) =
          joint.reflectedInertia() * Eigen::Vector3d(v.segment<3>(vi + 3)).cross(Eigen::Vector3d(v.segment<3>(vi)));
    vi += joint.nv();
  }
  return correction;
}

// The same quantities from MuJoCo for (spec, base), in our coordinates by `change`.
Answers solveWithMujoco(const ChainSpec& spec, const FloatingBase& base, const JointsProblem& p,
                        const VelocityChange& change, bool check_conventions = true, bool correct_armature = true) {
  const FloatingInput& in = p.input;
  const Mujoco mj(toMjcf(spec, in.gravity, base));
  const mjModel* m = mj.m();
  mjData* d = mj.d();
  const MujocoCoordinates map = mapCoordinates(spec, base, m);
  if (check_conventions) checkMujocoConventions(p, m, map);
  Answers a;

  // Forward: the state, τ (with the armature correction) as the generalized force T⁻ᵀ τ, the wrench at its body's
  // COM.
  const Eigen::VectorXd armature =
      correct_armature ? armatureCorrection(spec, base, in.v) : Eigen::VectorXd::Zero(in.v.size());
  scatter(in.q, map.qpos, d->qpos);
  scatter(change.T * in.v, map.dof, d->qvel);
  scatter(change.T.transpose().lu().solve(in.tau + armature), map.dof, d->qfrc_applied);
  mj_kinematics(m, d);
  const std::vector<Eigen::Isometry3d> poses = mujocoLinkPoses(spec, m, d);
  addWrenchesToXfrc(spec, poses, in.wrenches, m, d);
  mj_forward(m, d);
  a.qdd = change.T.lu().solve(gather(d->qacc, map.dof) - change.Tdot_v);
  mujocoLinkMotions(spec, in.gravity, m, d, a);
  a.H = change.T.transpose() * mujocoMassMatrix(m, d, map.dof) * change.T;

  // Inverse: no applied forces (mj_inverse leaves them out of qfrc_inverse); the wrench's own generalized forces are
  // taken out instead, since zwang's RNEA subtracts them.
  std::fill(d->qfrc_applied, d->qfrc_applied + m->nv, 0.0);
  std::fill(d->xfrc_applied, d->xfrc_applied + 6 * m->nbody, 0.0);
  scatter(change.T * p.qdd_inverse + change.Tdot_v, map.dof, d->qacc);
  mj_inverse(m, d);
  const std::vector<mjtNum> qfrc_wrenches = wrenchGeneralizedForces(spec, poses, in.wrenches, m, d);
  a.tau = change.T.transpose() * (gather(d->qfrc_inverse, map.dof) - gather(qfrc_wrenches.data(), map.dof)) - armature;
  a.tau_prescribed = a.tau;
  return a;
}

Answers solveWithMujoco(const JointsProblem& p, Conversion conversion = Conversion::Correct) {
  return solveWithMujoco(p.spec, p.base, p, velocityChange(p, conversion), true,
                         conversion != Conversion::FreeArmatureAsOurs);
}

// max |x − y| / max(1, max |y|) over all entries of a matrix.
double matrixRelativeError(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y) {
  if (x.rows() != y.rows() || x.cols() != y.cols()) return std::numeric_limits<double>::infinity();
  if (x.size() == 0) return 0.0;
  return (x - y).cwiseAbs().maxCoeff() / std::max(1.0, y.cwiseAbs().maxCoeff());
}

// The largest relativeError of one link's 6-vector against the other's, over the links.
double linkError(const std::vector<Vector6d>& ours, const std::vector<Vector6d>& theirs) {
  REQUIRE(ours.size() == theirs.size());
  double e = 0.0;
  for (std::size_t i = 0; i < ours.size(); ++i) e = std::max(e, relativeError(ours[i], theirs[i]));
  return e;
}

struct Errors {
  double qdd = 0.0, link_velocity = 0.0, link_acceleration = 0.0, tau = 0.0, tau_prescribed = 0.0, H = 0.0;
  double largest() const { return std::max({qdd, link_velocity, link_acceleration, tau, tau_prescribed, H}); }
  void max(const Errors& o) {
    qdd = std::max(qdd, o.qdd);
    link_velocity = std::max(link_velocity, o.link_velocity);
    link_acceleration = std::max(link_acceleration, o.link_acceleration);
    tau = std::max(tau, o.tau);
    tau_prescribed = std::max(tau_prescribed, o.tau_prescribed);
    H = std::max(H, o.H);
  }
};

Errors compare(const Answers& ours, const Answers& theirs) {
  Errors e;
  e.qdd = relativeError(ours.qdd, theirs.qdd);
  e.link_velocity = linkError(ours.link_velocity, theirs.link_velocity);
  e.link_acceleration = linkError(ours.link_acceleration, theirs.link_acceleration);
  e.tau = relativeError(ours.tau, theirs.tau);
  e.tau_prescribed = relativeError(ours.tau_prescribed, theirs.tau_prescribed);
  e.H = matrixRelativeError(ours.H, theirs.H);
  return e;
}

// The kind of tree of draw `trial`: a free root in 2 of 5, a fixed base with free joints on the root link in 1 of 5,
// a fixed base otherwise.
JointsProblem drawTrial(std::mt19937_64& rng, int trial) {
  const int kind = trial % 5;
  return randomJointsProblem(rng, kind < 2, kind == 2 ? 0.6 : 0.0);
}

}  // namespace

TEST_CASE("joint types: solver, RNEA and CRBA match MuJoCo on 320 trees of hinge, slide, ball and free joints",
          "[joints][mujoco]") {
  REQUIRE(mj_version() == mjVERSION_HEADER);  // the library is the one the header describes
  std::mt19937_64 rng(stressSeedOr(2525));    // ZWANG_STRESS_SEED: other trees
  Census census;
  Errors worst;
  int failures = 0;
  for (int trial = 0; trial < 320; ++trial) {
    const JointsProblem p = drawTrial(rng, trial);
    count(p, census);
    INFO("trial " << trial << ": " << toString(p.base.kind) << " base, " << p.spec.movingJoints().size()
                  << " moving joints, nv " << p.base.nv(p.spec));
    const Errors e = compare(solveWithZwang(p), solveWithMujoco(p));
    worst.max(e);
    INFO("rel. errors: qdd " << e.qdd << ", tau " << e.tau << ", tau all prescribed " << e.tau_prescribed << ", H "
                             << e.H << ", link velocity " << e.link_velocity << ", link acceleration "
                             << e.link_acceleration);
    CHECK(e.largest() < kTolerance);
    if (!(e.largest() < kTolerance) && ++failures == 1)  // the first failing tree in full, to reproduce it
      std::printf("first failing tree (trial %d):\n%s", trial, toMjcf(p.spec, p.input.gravity, p.base).c_str());
  }
  std::printf(
      "MuJoCo %s vs zwang on joint types: %d trees (%d on a free root, %d fixed bases, %d of them with free joints), "
      "joints: %d hinge, %d slide, %d ball (%d not at a leaf, %d with armature), %d free; up to %d DOFs; max rel. "
      "error: q̈ (solveHybridDynamics vs mj_forward) %.2e  tau (inverseDynamics vs mj_inverse) %.2e  tau (every DOF "
      "prescribed vs mj_inverse) %.2e  H "
      "(jointSpaceInertia vs mj_fullM) %.2e  link velocity %.2e  link acceleration %.2e\n",
      mj_versionString(), census.trees, census.free_roots, census.fixed_bases, census.with_free_joints, census.hinge,
      census.slide, census.ball, census.ball_inner, census.ball_armature, census.free, census.most_dofs, worst.qdd,
      worst.tau, worst.tau_prescribed, worst.H, worst.link_velocity, worst.link_acceleration);
  CHECK(census.trees >= 300);
  CHECK(census.free_roots >= 100);
  CHECK(census.fixed_bases >= 100);
  CHECK(census.with_free_joints >= 30);
  CHECK(census.ball_inner >= 100);
  CHECK(census.ball_armature >= 100);
  CHECK(census.slide >= 100);
  CHECK(worst.qdd < kTolerance);
  CHECK(worst.tau < kTolerance);
  CHECK(worst.tau_prescribed < kTolerance);
  CHECK(worst.H < kTolerance);
  CHECK(worst.link_velocity < kTolerance);
  CHECK(worst.link_acceleration < kTolerance);
}

TEST_CASE("joint types: a free joint on the world is MuJoCo's free base, in our coordinates", "[joints][mujoco]") {
  // MuJoCo alone, so that the conversion of free spec joints is checked without zwang: the same tree once on a free
  // base (links[0] on MuJoCo's freejoint) and once with a massless world link and a free spec joint to links[0]
  // (written at the top level, the other joints shifted by one link). The two are the same MuJoCo model but for an
  // extra massless body, and must give the same numbers in our coordinates (to round-off, should MuJoCo order its
  // operations differently: 1e-12).
  std::mt19937_64 rng(77);
  double worst = 0.0;
  for (int trial = 0; trial < 30; ++trial) {
    const JointsProblem p = randomJointsProblem(rng, true, 0.0);
    ChainSpec world = p.spec;
    LinkSpec world_link;
    world_link.name = "world_link";
    JointSpec free;
    free.name = "free_root";
    free.type = "free";
    free.parent = 0;
    world.links.insert(world.links.begin(), world_link);
    for (std::size_t k = 0; k < world.joints.size(); ++k) world.joints[k].parent = p.spec.parentLink(k) + 1;
    world.joints.insert(world.joints.begin(), free);
    world.check();
    const FloatingBase fixed{BaseKind::Fixed, Eigen::Isometry3d::Identity()};
    JointsProblem q = p;
    q.spec = world;
    q.base = fixed;
    const Answers on_base = solveWithMujoco(p);
    const Answers on_joint = solveWithMujoco(world, fixed, q, velocityChange(q, Conversion::Correct), false);
    Answers trimmed = on_joint;  // the world link's motion (zero) dropped
    trimmed.link_velocity.erase(trimmed.link_velocity.begin());
    trimmed.link_acceleration.erase(trimmed.link_acceleration.begin());
    worst = std::max(worst, compare(trimmed, on_base).largest());
  }
  std::printf(
      "MuJoCo free joint on the world vs its free base, in our coordinates: 30 trees, max rel. difference "
      "%.2e\n",
      worst);
  CHECK(worst < 1e-12);
}

namespace {

// MuJoCo's state, forward and inverse dynamics at v = 0 in OUR dof order (`dof`: MuJoCo's dof address per entry).
struct AtRest {
  Eigen::VectorXd qacc, qfrc_inverse;
  Eigen::MatrixXd M;
};

AtRest mujocoAtRest(const std::string& xml, const std::vector<std::pair<std::string, int>>& qpos_names,
                    const Eigen::VectorXd& qpos, const std::vector<std::pair<std::string, int>>& dof_names,
                    const Eigen::VectorXd& tau, const Eigen::VectorXd& qdd) {
  const Mujoco mj(xml);
  const mjModel* m = mj.m();
  mjData* d = mj.d();
  // (joint name, entry within the joint) → MuJoCo's address.
  auto addresses = [m](const std::vector<std::pair<std::string, int>>& names, const int* adr) {
    std::vector<int> out;
    for (const auto& [name, entry] : names) {
      const int id = mj_name2id(m, mjOBJ_JOINT, name.c_str());
      REQUIRE(id >= 0);
      out.push_back(adr[id] + entry);
    }
    return out;
  };
  const std::vector<int> qadr = addresses(qpos_names, m->jnt_qposadr), vadr = addresses(dof_names, m->jnt_dofadr);
  REQUIRE(m->nv == static_cast<int>(vadr.size()));
  scatter(qpos, qadr, d->qpos);
  scatter(tau, vadr, d->qfrc_applied);
  mj_forward(m, d);
  AtRest r;
  r.qacc = gather(d->qacc, vadr);
  r.M = mujocoMassMatrix(m, d, vadr);
  std::fill(d->qfrc_applied, d->qfrc_applied + m->nv, 0.0);
  scatter(qdd, vadr, d->qacc);
  mj_inverse(m, d);
  r.qfrc_inverse = gather(d->qfrc_inverse, vadr);
  return r;
}

}  // namespace

TEST_CASE("joint types: MuJoCo's ball velocity is the angular velocity in the child frame", "[joints][mujoco]") {
  // MuJoCo alone, so that the ball convention the header states is checked without zwang: each ball joint at its
  // quaternion Q against three hinges about the child's x, y, z at angle 0 in one body (MuJoCo composes a body's
  // joints in order) placed at the joint placement times Q. At rest (v = 0, no velocity products) the two are the
  // same mechanism in the same coordinates exactly when the ball's qvel is ω in the child frame: the same M, qacc
  // under τ and gravity, and qfrc_inverse for a q̈, to round-off (1e-11: both sides are MuJoCo's double-precision
  // sweeps on the same numbers, the placements composed in another order, qacc's round-off amplified by M's
  // condition). Read in the joint frame, M would be rotated by Q on each ball's block.
  std::mt19937_64 rng(78);
  double worst = 0.0;
  int balls = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const JointsProblem p = randomJointsProblem(rng, trial % 2 == 0, 0.0);
    ChainSpec hinges = p.spec;
    std::vector<std::pair<std::string, int>> q_ball, v_ball, q_hinge, v_hinge;
    Eigen::VectorXd qpos_hinge(p.base.nv(p.spec) + (p.base.kind == BaseKind::Free ? 1 : 0));
    Eigen::Index qi = 0, hi = 0;
    if (p.base.kind == BaseKind::Free) {
      for (int i = 0; i < 7; ++i) q_ball.emplace_back(kMjcfFreeJoint, i);
      for (int i = 0; i < 6; ++i) v_ball.emplace_back(kMjcfFreeJoint, i);
      q_hinge = q_ball;
      v_hinge = v_ball;
      qpos_hinge.head<7>() = p.input.q.head<7>();
      qi = hi = 7;
    }
    const char* suffix[] = {"", "_y", "_z"};
    for (const int k : p.spec.movingJoints()) {
      JointSpec& joint = hinges.joints[static_cast<std::size_t>(k)];
      const int nq = joint.nq();  // before the ball becomes a hinge
      for (int i = 0; i < nq; ++i) q_ball.emplace_back(joint.name, i);
      for (int i = 0; i < joint.nv(); ++i) v_ball.emplace_back(joint.name, i);
      if (joint.isSpherical()) {
        ++balls;
        const Eigen::Quaterniond Q(p.input.q(qi), p.input.q(qi + 1), p.input.q(qi + 2), p.input.q(qi + 3));
        const Eigen::Matrix3d R = rpyToMatrix(joint.rpy) * Q.toRotationMatrix();
        const Eigen::Vector3d ypr = R.eulerAngles(2, 1, 0);  // R = Rz(yaw)·Ry(pitch)·Rx(roll)
        joint.rpy = Eigen::Vector3d(ypr(2), ypr(1), ypr(0));
        joint.type = "revolute";
        joint.axis = Eigen::Vector3d::UnitX();  // the other two hinges are written into the same body below
        for (int i = 0; i < 3; ++i) {
          q_hinge.emplace_back(joint.name + suffix[i], 0);
          v_hinge.emplace_back(joint.name + suffix[i], 0);
          qpos_hinge(hi++) = 0.0;
        }
      } else {
        q_hinge.emplace_back(joint.name, 0);
        v_hinge.emplace_back(joint.name, 0);
        qpos_hinge(hi++) = p.input.q(qi);
      }
      qi += nq;
    }
    std::string xml = toMjcf(hinges, p.input.gravity, p.base);
    for (const int k : p.spec.movingJoints()) {
      const JointSpec& joint = p.spec.joints[static_cast<std::size_t>(k)];
      if (!joint.isSpherical()) continue;
      const std::string name = "<joint name=\"" + joint.name + "\" type=\"hinge\"";
      const std::size_t begin = xml.find(name), end = xml.find('\n', begin);
      REQUIRE(begin != std::string::npos);
      std::string x_line = xml.substr(begin, end - begin), y_line = x_line, z_line = x_line;
      y_line.replace(y_line.find(joint.name + "\""), joint.name.size() + 1, joint.name + "_y\"");
      z_line.replace(z_line.find(joint.name + "\""), joint.name.size() + 1, joint.name + "_z\"");
      y_line.replace(y_line.find("axis=\"1 0 0\""), 12, "axis=\"0 1 0\"");
      z_line.replace(z_line.find("axis=\"1 0 0\""), 12, "axis=\"0 0 1\"");
      const std::string indent = xml.substr(xml.rfind('\n', begin) + 1, begin - xml.rfind('\n', begin) - 1);
      xml.insert(end, "\n" + indent + y_line + "\n" + indent + z_line);
    }
    const AtRest ball =
        mujocoAtRest(toMjcf(p.spec, p.input.gravity, p.base), q_ball, p.input.q, v_ball, p.input.tau, p.qdd_inverse);
    const AtRest hinge = mujocoAtRest(xml, q_hinge, qpos_hinge, v_hinge, p.input.tau, p.qdd_inverse);
    worst = std::max({worst, relativeError(ball.qacc, hinge.qacc), relativeError(ball.qfrc_inverse, hinge.qfrc_inverse),
                      matrixRelativeError(ball.M, hinge.M)});
  }
  std::printf(
      "MuJoCo ball joints vs three hinges about the child's axes, at rest: 30 trees, %d ball joints, max rel. "
      "difference %.2e\n",
      balls, worst);
  CHECK(balls >= 50);
  CHECK(worst < 1e-11);
}

TEST_CASE("joint types: the MuJoCo comparison fails on a wrong velocity convention", "[joints][mujoco]") {
  // Each mistake on 20 random trees that have the joints it concerns: the least disagreement over them must stay far
  // above the tolerance, while the right conversion on the same trees stays within it.
  std::mt19937_64 rng(4712);
  const Conversion mistakes[] = {Conversion::BallRatesInJointFrame, Conversion::FreeJointLinearInBody,
                                 Conversion::FreeArmatureAsOurs};
  const char* names[] = {"ball omega read in the joint frame", "free joint's linear qvel read in body axes",
                         "MuJoCo's armature on a free joint's translations taken as ours"};
  for (int k = 0; k < 3; ++k) {
    double least = 1e300, correct = 0.0;
    for (int trial = 0; trial < 20;) {
      const JointsProblem p = randomJointsProblem(rng, k == 0 && trial % 2 == 0, k == 0 ? 0.0 : 1.0);
      bool concerned = false;
      for (const JointSpec& joint : p.spec.joints)
        concerned |= k == 0 ? joint.isSpherical() : joint.isFree() && (k == 1 || joint.reflectedInertia() > 0.0);
      if (!concerned) continue;
      ++trial;
      const Answers ours = solveWithZwang(p);
      least = std::min(least, compare(ours, solveWithMujoco(p, mistakes[k])).largest());
      correct = std::max(correct, compare(ours, solveWithMujoco(p)).largest());
    }
    std::printf(
        "joint-type MuJoCo comparison with a wrong convention (%s): 20 trees, smallest disagreement %.2e (the right "
        "conversion on the same trees: largest %.2e)\n",
        names[k], least, correct);
    CHECK(least > kMistakeFloor);
    CHECK(correct < kTolerance);
  }
}

namespace {

// The centre of mass of one subtree, its velocity and acceleration, and the centroidal momentum [M ċ; L_c], world
// axes.
struct SubtreeMotion {
  Eigen::Vector3d c, cd, cdd;
  Vector6d h;
};

// The subtrees compared: the one below each moving spec joint (its child link, spec.links[k + 1]), and the whole
// robot (links[0]'s subtree) on a free root.
std::vector<int> subtreeRootLinks(const JointsProblem& p) {
  std::vector<int> links;
  if (p.base.kind == BaseKind::Free) links.push_back(0);
  for (const int k : p.spec.movingJoints()) links.push_back(k + 1);
  return links;
}

std::vector<SubtreeMotion> subtreesWithZwang(const JointsProblem& p) {
  const Model model = floatingModelFromSpec(p.spec, p.base);
  const Task task = floatingTaskFromInput(model, p.input);
  Workspace ws(model, task);
  const FloatingInput& in = p.input;
  REQUIRE(solveHybridDynamics(model, ws, in.q, in.v, in.tau, task));
  std::vector<SubtreeMotion> out;
  for (const int link : subtreeRootLinks(p)) {
    const int joint =
        link == 0 ? kWholeRobot : model.jointIndex(p.spec.joints[static_cast<std::size_t>(link - 1)].name);
    SubtreeMotion s;
    Vec3 c, cd, cdd;
    Vec6 h;
    REQUIRE(centerOfMass(model, ws, in.q, joint, c));
    REQUIRE(centerOfMassVelocity(model, ws, in.q, in.v, joint, cd));
    REQUIRE(centerOfMassAcceleration(model, ws, in.q, in.v, joint, cdd));
    REQUIRE(centroidalMomentum(model, ws, in.q, in.v, joint, h));
    s.c = c;
    s.cd = cd;
    s.cdd = cdd;
    s.h = h;
    out.push_back(s);
  }
  return out;
}

// MuJoCo's after mj_forward on the same state and forces (solveWithMujoco's forward part): subtree_com, and from
// mj_subtreeVel subtree_linvel (ċ) and subtree_angmom (L_c), M ċ from body_subtreemass; c̈ as Σ m_b p̈_b / M over the
// subtree's bodies, p̈_b the classical acceleration of body b's centre of mass (mj_objectAcceleration of mjOBJ_BODY,
// its inertial frame at xipos, with g added back as in mujocoLinkMotions).
std::vector<SubtreeMotion> subtreesWithMujoco(const JointsProblem& p) {
  const FloatingInput& in = p.input;
  const Mujoco mj(toMjcf(p.spec, in.gravity, p.base));
  const mjModel* m = mj.m();
  mjData* d = mj.d();
  const MujocoCoordinates map = mapCoordinates(p.spec, p.base, m);
  const VelocityChange change = velocityChange(p, Conversion::Correct);
  scatter(in.q, map.qpos, d->qpos);
  scatter(change.T * in.v, map.dof, d->qvel);
  scatter(change.T.transpose().lu().solve(in.tau + armatureCorrection(p.spec, p.base, in.v)), map.dof, d->qfrc_applied);
  mj_kinematics(m, d);
  addWrenchesToXfrc(p.spec, mujocoLinkPoses(p.spec, m, d), in.wrenches, m, d);
  mj_forward(m, d);
  mj_subtreeVel(m, d);
  mj_rnePostConstraint(m, d);
  std::vector<SubtreeMotion> out;
  for (const int link : subtreeRootLinks(p)) {
    const int root = mj_name2id(m, mjOBJ_BODY, p.spec.links[static_cast<std::size_t>(link)].name.c_str());
    REQUIRE(root >= 1);
    const double mass = m->body_subtreemass[root];
    SubtreeMotion s;
    s.c = Eigen::Map<const Eigen::Vector3d>(d->subtree_com + 3 * root);
    s.cd = Eigen::Map<const Eigen::Vector3d>(d->subtree_linvel + 3 * root);
    s.h << mass * s.cd, Eigen::Map<const Eigen::Vector3d>(d->subtree_angmom + 3 * root);
    Eigen::Vector3d mass_acceleration = Eigen::Vector3d::Zero();
    for (int b = 1; b < m->nbody; ++b) {
      bool inside = false;
      for (int a = b; a > 0 && !inside; a = m->body_parentid[a]) inside = a == root;
      if (!inside) continue;
      mjtNum acceleration[6];
      mj_objectAcceleration(m, d, mjOBJ_BODY, b, acceleration, 0);
      mass_acceleration +=
          m->body_mass[b] * (Eigen::Vector3d(acceleration[3], acceleration[4], acceleration[5]) + in.gravity);
    }
    s.cdd = mass_acceleration / mass;
    out.push_back(s);
  }
  return out;
}

}  // namespace

TEST_CASE(
    "joint types: centre of mass and centroidal momentum match MuJoCo's subtree_com, subtree_linvel and "
    "subtree_angmom",
    "[joints][mujoco][com]") {
  // The trees, states and forces of the first test case (drawTrial), fewer of them; every moving joint's subtree and
  // the whole robot on a free root; the same tolerance (both exact sums over the bodies; c̈ from the forward dynamics
  // of each side, whose q̈ agree to it).
  std::mt19937_64 rng(2727);
  double worst[4] = {0, 0, 0, 0};
  int subtrees = 0, wholes = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const JointsProblem p = drawTrial(rng, trial);
    const std::vector<SubtreeMotion> ours = subtreesWithZwang(p), theirs = subtreesWithMujoco(p);
    REQUIRE(ours.size() == theirs.size());
    wholes += p.base.kind == BaseKind::Free ? 1 : 0;
    for (std::size_t k = 0; k < ours.size(); ++k, ++subtrees) {
      worst[0] = std::max(worst[0], relativeError(ours[k].c, theirs[k].c));
      worst[1] = std::max(worst[1], relativeError(ours[k].cd, theirs[k].cd));
      worst[2] = std::max(worst[2], relativeError(ours[k].cdd, theirs[k].cdd));
      worst[3] = std::max(worst[3], relativeError(ours[k].h, theirs[k].h));
    }
  }
  std::printf(
      "MuJoCo %s vs zwang, centre of mass: 100 trees, %d subtrees (%d whole robots on a free root); max rel. error: c "
      "(subtree_com) %.2e  c-dot (subtree_linvel) %.2e  c-ddot (bodies' accelerations) %.2e  h ([M subtree_linvel; "
      "subtree_angmom]) %.2e\n",
      mj_versionString(), subtrees, wholes, worst[0], worst[1], worst[2], worst[3]);
  CHECK(subtrees >= 500);
  CHECK(worst[0] < kTolerance);
  CHECK(worst[1] < kTolerance);
  CHECK(worst[2] < kTolerance);
  CHECK(worst[3] < kTolerance);
}
