// The solver, RNEA and CRBA on FLOATING bases against MuJoCo (Debian's
// libmujoco-dev 2.2.2) directly, with no dense reference in between
// (test_floating checks the solver against the dense floating-base reference
// and test_floating_reference that reference against MuJoCo; this test closes
// the triangle). On random free-flyer and planar trees and chains (0–30
// moving joints, random base and joint velocities, joint torques, a base
// generalized force in half the draws, gravity, wrenches on links and on the
// base link):
//  * solveHybridDynamics with an empty task: q̈ (the base's v̇ and the joints'
//    q̈) and Solution::base_acceleration_world, against mj_forward's qacc;
//  * inverseDynamics (RNEA) at a random q̈, against mj_inverse's qfrc_inverse;
//  * jointSpaceInertia (CRBA), against mj_fullM;
// each to 1e-9 relative to max(1, |MuJoCo's value|) (issue #15).
//
// No task rows: MuJoCo's equality constraints are soft (a spring-damper
// solved by its constraint solver, which the MJCF disables), nothing like our
// exact rows; the dense reference covers rows (test_floating). For the same
// reason no mimic joints: the test refuses a model with any.
//
// The MJCF (support/mjcf_writer.hpp, as test_mujoco): each joint's armature is
// its reflected rotor inertia (MuJoCo adds it to the diagonal of M exactly as
// zwang adds d_j), no damping, stiffness, friction loss or limits, contacts,
// the constraint solver and passive forces disabled. The root link floats on a
// <freejoint/> or on slide x, slide y, hinge z at the plane pose. Joints are
// mapped by name. Every compiled model is checked for these settings
// (checkMujocoConventions).
//
// The conversion (derived in support/mujoco_bridge.hpp, whose helpers do it).
// Free base, R = ⁰R_base, ω the angular velocity in base axes, T =
// blockdiag(R, 1₃, 1 (joints)):
//   qvel          = T v            = [R v_lin; ω; q̇]        (MuJoCo: ṗ in world axes, ω in body axes)
//   v̇ from qacc   = T⁻¹(qacc − Ṫv) = [Rᵀ p̈ − ω × v_lin; ω̇; q̈] (v_lin = Rᵀṗ: the rate of base-axes coordinates)
//   qacc (RNEA)   = T v̇ + Ṫv       = [R (v̇_lin + ω × v_lin); ω̇; q̈]
//   qfrc_applied  = T⁻ᵀ τ          = [R τ_lin; τ_ang; τ_joints]
//   τ from qfrc   = Tᵀ qfrc_inverse (minus the wrenches' generalized forces: mj_inverse leaves applied forces out)
//   H             = Tᵀ M_mj T
//   [p̈; ω̇] world  = [qacc_lin; R qacc_ang]  (straight from qacc, no use of our v̇)
// Planar base: qvel, qacc, qfrc are ours (rates in the plane's axes, whatever the yaw); the base's classical
// acceleration is [R_P (ẍ, ÿ, 0); ψ̈ R_P e_z], R_P the plane's axes.
//
// So that the comparison can fail, the last test case makes three plausible conversion mistakes (MuJoCo's linear
// qvel read as base axes; the −ω × v_lin term dropped; planar rates read in the base's yawed axes) and requires each
// to be seen far above 1e-9.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <mujoco/mujoco.h>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <catch2/catch.hpp>

#include "support/floating_reference.hpp"
#include "support/mjcf_writer.hpp"
#include "support/mujoco_bridge.hpp"
#include "support/random_chain.hpp"
#include "support/random_problem.hpp"
#include "zwang/zwang.hpp"

using namespace zwang;
using namespace zwang::testing;

namespace {

// The bound. Both sides are exact algorithms in double precision (MuJoCo's recursive ones and its
// factorisation of M; zwang's sweeps) on up to ~30 bodies; their round-off, amplified by the inertia matrix's
// condition (light distal links next to armatures up to 0.5 kg·m²), is about 1e-12 (the printout).
constexpr double kTolerance = 1e-9;
// A conversion mistake must disagree by 1000 times the tolerance, so that none can pass unseen.
constexpr double kMistakeFloor = 1e3 * kTolerance;

// How our velocity coordinates are turned into MuJoCo's (Correct), or a plausible mistake.
enum class Conversion {
  Correct,
  FreeLinearInBaseAxes,   // the free joint's linear qvel taken as base axes (T = 1)
  FreeWithoutTransport,   // T right, but v̇_lin = Rᵀ p̈ (the −ω × v_lin of the rotating axes dropped)
  PlanarRatesInBaseAxes,  // planar ẋ, ẏ read in the base's yawed axes instead of the plane's
};

// u_mujoco = T v and u̇_mujoco = T v̇ + Ṫ v.
struct VelocityChange {
  Eigen::MatrixXd T;
  Eigen::VectorXd Tdot_v;
};

VelocityChange velocityChange(const FloatingProblem& p, Conversion conversion) {
  const FloatingInput& in = p.input;
  VelocityChange change{mujocoVelocityMap(p.spec, p.base, in.q), mujocoVelocityMapRate(p.spec, p.base, in.q, in.v)};
  if (conversion == Conversion::FreeLinearInBaseAxes) {
    change.T.setIdentity();
    change.Tdot_v.setZero();
  } else if (conversion == Conversion::FreeWithoutTransport) {
    change.Tdot_v.setZero();
  } else if (conversion == Conversion::PlanarRatesInBaseAxes) {
    change.T.topLeftCorner<2, 2>() = Eigen::Rotation2Dd(in.q(2)).toRotationMatrix();
  }
  return change;
}

// The quantities compared, in our coordinates, from zwang (solveWithZwang) or from MuJoCo (solveWithMujoco).
struct Answers {
  Eigen::VectorXd qdd;                     // forward dynamics: v̇ of the base, then the joints' q̈
  Vector6d base_world = Vector6d::Zero();  // the base origin's classical [p̈; ω̇], world axes
  // Every link's (index as spec.links) classical velocity [ṗ; ω] and true acceleration [p̈; ω̇] at its origin,
  // world axes, in the forward motion.
  std::vector<Vector6d> link_velocity, link_acceleration;
  Eigen::VectorXd tau;  // inverse dynamics at qdd_inverse
  Eigen::MatrixXd H;    // joint-space inertia
};

// zwang's link velocities and accelerations after a solve (frameVelocity, frameAcceleration of each link's frame).
void zwangLinkMotions(const ChainSpec& spec, const Model& model, const Workspace& ws, const FloatingInput& input,
                      Answers& a) {
  for (const LinkSpec& link : spec.links) {
    const int frame = model.frameIndex(link.name);
    Vec6 velocity, acceleration;
    REQUIRE(frameVelocity(model, ws, input.q, input.v, frame, Expressed::World, velocity));
    REQUIRE(frameAcceleration(model, ws, input.q, input.v, frame, Expressed::World, acceleration));
    a.link_velocity.push_back(velocity);
    a.link_acceleration.push_back(acceleration);
  }
}

Answers solveWithZwang(const FloatingProblem& p, const Eigen::VectorXd& qdd_inverse) {
  const Model model = floatingModelFromSpec(p.spec, p.base);
  REQUIRE(model.mimicJoints().empty());
  const Task task = floatingTaskFromInput(model, p.input);
  REQUIRE(task.constraintRows() == 0);
  Workspace ws(model, task);
  Answers a;
  const Status solved = solveHybridDynamics(model, ws, p.input.q, p.input.v, p.input.tau, task);
  INFO(solved.message);
  REQUIRE(solved);
  a.qdd = ws.solution.qdd;
  a.base_world = ws.solution.base_acceleration_world;
  zwangLinkMotions(p.spec, model, ws, p.input, a);
  REQUIRE(inverseDynamics(model, ws, p.input.q, p.input.v, qdd_inverse, task));
  a.tau = ws.tau;
  REQUIRE(jointSpaceInertia(model, ws, p.input.q));
  a.H = ws.H;
  return a;
}

// The base's classical acceleration straight from MuJoCo's qacc (our order), without our v̇ (file comment).
Vector6d classicalBaseAcceleration(const FloatingBase& base, const Eigen::VectorXd& q, const Eigen::VectorXd& qacc) {
  Vector6d acc;
  if (base.kind == BaseKind::Free) {
    acc << qacc.head<3>(), basePose(base, q).linear() * qacc.segment<3>(3);
  } else {
    const Eigen::Matrix3d RP = base.plane.linear();
    acc << qacc(0) * RP.col(0) + qacc(1) * RP.col(1), qacc(2) * RP.col(2);
  }
  return acc;
}

// MuJoCo's link velocities and accelerations after mj_forward: mj_objectVelocity and mj_objectAcceleration of each
// body frame (mjOBJ_XBODY) in world axes, which give [ω; ṗ] and [ω̇; p̈ − g] (angular part first; the accelerations
// are MuJoCo's cacc, whose sweep starts from −g at the world, as zwang's from [−g; 0] inside: g is added back).
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

// What the file comment says of the MJCF, as MuJoCo compiled it: only the smooth dynamics (no contacts, constraint
// solver, equality constraints or passive forces), no equality constraint at all (no mimic joints), and on every dof
// no damping, stiffness or friction loss and the armature zwang has (0 on the base, d_j = the reflected rotor
// inertia on joint j: both add it to the diagonal of the inertia matrix).
void checkMujocoConventions(const ChainSpec& spec, const FloatingBase& base, const mjModel* m,
                            const MujocoCoordinates& map) {
  const int smooth_only = mjDSBL_CONTACT | mjDSBL_CONSTRAINT | mjDSBL_EQUALITY | mjDSBL_PASSIVE;
  CHECK((m->opt.disableflags & smooth_only) == smooth_only);
  CHECK(m->neq == 0);
  const auto base_velocity_size = static_cast<std::size_t>(base.baseVelocitySize());
  const std::vector<int> moving = spec.movingJoints();
  for (std::size_t k = 0; k < map.dof.size(); ++k) {
    const int dof = map.dof[k];
    const double armature =
        k < base_velocity_size
            ? 0.0
            : spec.joints[static_cast<std::size_t>(moving[k - base_velocity_size])].reflectedInertia();
    CHECK(m->dof_armature[dof] == Approx(armature).epsilon(1e-15).margin(0.0));  // the written %.17g, read back
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

// The same quantities from MuJoCo, turned into our coordinates with `conversion`.
Answers solveWithMujoco(const FloatingProblem& p, const Eigen::VectorXd& qdd_inverse, Conversion conversion) {
  const FloatingInput& in = p.input;
  const Mujoco mj(toMjcf(p.spec, in.gravity, p.base));
  const mjModel* m = mj.m();
  mjData* d = mj.d();
  const MujocoCoordinates map = mapCoordinates(p.spec, p.base, m);
  checkMujocoConventions(p.spec, p.base, m, map);
  const VelocityChange change = velocityChange(p, conversion);
  Answers a;

  // Forward: the state, τ as the generalized force T⁻ᵀ τ, each wrench at its body's COM (poses from MuJoCo's own
  // kinematics of this qpos).
  scatter(in.q, map.qpos, d->qpos);
  scatter(change.T * in.v, map.dof, d->qvel);
  scatter(change.T.transpose().lu().solve(in.tau), map.dof, d->qfrc_applied);
  mj_kinematics(m, d);
  const std::vector<Eigen::Isometry3d> poses = mujocoLinkPoses(p.spec, m, d);
  addWrenchesToXfrc(p.spec, poses, in.wrenches, m, d);
  mj_forward(m, d);
  const Eigen::VectorXd qacc = gather(d->qacc, map.dof);
  a.qdd = change.T.lu().solve(qacc - change.Tdot_v);
  a.base_world = classicalBaseAcceleration(p.base, in.q, qacc);
  mujocoLinkMotions(p.spec, in.gravity, m, d, a);
  a.H = change.T.transpose() * mujocoMassMatrix(m, d, map.dof) * change.T;

  // Inverse: no applied forces (mj_inverse leaves them out of qfrc_inverse); the wrenches' own generalized forces
  // are taken out instead, since zwang's RNEA subtracts them.
  std::fill(d->qfrc_applied, d->qfrc_applied + m->nv, 0.0);
  std::fill(d->xfrc_applied, d->xfrc_applied + 6 * m->nbody, 0.0);
  scatter(change.T * qdd_inverse + change.Tdot_v, map.dof, d->qacc);
  mj_inverse(m, d);
  const std::vector<mjtNum> qfrc_wrenches = wrenchGeneralizedForces(p.spec, poses, in.wrenches, m, d);
  a.tau = change.T.transpose() * (gather(d->qfrc_inverse, map.dof) - gather(qfrc_wrenches.data(), map.dof));
  return a;
}

// max |x − y| / max(1, max |y|) over all entries of a matrix.
double matrixRelativeError(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y) {
  if (x.rows() != y.rows() || x.cols() != y.cols()) return std::numeric_limits<double>::infinity();
  if (x.size() == 0) return 0.0;
  return (x - y).cwiseAbs().maxCoeff() / std::max(1.0, y.cwiseAbs().maxCoeff());
}

// zwang against MuJoCo, each quantity relative to MuJoCo's magnitude (the base's v̇ and the joints' q̈ apart; each
// link's velocity and acceleration apart).
struct Errors {
  double base_qdd = 0.0, joint_qdd = 0.0, base_world = 0.0, link_velocity = 0.0, link_acceleration = 0.0, tau = 0.0,
         H = 0.0;
  double largest() const {
    return std::max({base_qdd, joint_qdd, base_world, link_velocity, link_acceleration, tau, H});
  }
  void max(const Errors& o) {
    base_qdd = std::max(base_qdd, o.base_qdd);
    joint_qdd = std::max(joint_qdd, o.joint_qdd);
    base_world = std::max(base_world, o.base_world);
    link_velocity = std::max(link_velocity, o.link_velocity);
    link_acceleration = std::max(link_acceleration, o.link_acceleration);
    tau = std::max(tau, o.tau);
    H = std::max(H, o.H);
  }
};

// The largest relativeError of one link's 6-vector against MuJoCo's, over the links.
double linkError(const std::vector<Vector6d>& ours, const std::vector<Vector6d>& theirs) {
  REQUIRE(ours.size() == theirs.size());
  double e = 0.0;
  for (std::size_t i = 0; i < ours.size(); ++i) e = std::max(e, relativeError(ours[i], theirs[i]));
  return e;
}

Errors compareWithMujoco(const FloatingProblem& p, const Eigen::VectorXd& qdd_inverse,
                         Conversion conversion = Conversion::Correct) {
  const Answers ours = solveWithZwang(p, qdd_inverse);
  const Answers theirs = solveWithMujoco(p, qdd_inverse, conversion);
  const int base_velocity_size = p.base.baseVelocitySize(), n = p.spec.dof();
  Errors e;
  e.base_qdd = relativeError(ours.qdd.head(base_velocity_size), theirs.qdd.head(base_velocity_size));
  e.joint_qdd = relativeError(ours.qdd.tail(n), theirs.qdd.tail(n));
  e.base_world = relativeError(ours.base_world, theirs.base_world);
  e.link_velocity = linkError(ours.link_velocity, theirs.link_velocity);
  e.link_acceleration = linkError(ours.link_acceleration, theirs.link_acceleration);
  e.tau = relativeError(ours.tau, theirs.tau);
  e.H = matrixRelativeError(ours.H, theirs.H);
  return e;
}

// Random floating problems of the kind asked for: no rows, up to two wrenches (on the base link too), a base force in
// half the draws; free or planar as `kind` says (tilted planes in 70 % of the planar draws); trees of 0–30 moving
// joints or chains of 1–12.
FloatingProblem randomFloatingRobot(std::mt19937_64& rng, BaseKind kind, bool no_joints) {
  RandomFloatingOptions options;
  options.free_probability = kind == BaseKind::Free ? 1.0 : 0.0;
  options.max_constraint_rows = 0;
  options.max_wrenches = 2;
  options.base_tau_probability = 0.5;
  options.tree.min_moving_joints = 0;
  if (no_joints) {  // a single floating body: the base link alone
    options.chain_probability = 0.0;
    options.tree.max_moving_joints = 0;
  }
  FloatingProblem p = randomFloatingProblem(rng, options);
  REQUIRE(p.base.kind == kind);
  return p;
}

}  // namespace

TEST_CASE("floating bases: solver, RNEA and CRBA match MuJoCo on 220 free-flyer and 110 planar robots",
          "[floating][mujoco]") {
  REQUIRE(mj_version() == mjVERSION_HEADER);  // the library is the one the header describes
  std::mt19937_64 rng(15015);
  Errors worst[2];
  int count[2] = {0, 0}, min_joints = 1000, max_joints = 0, joints = 0, chains = 0, single_bodies = 0, with_gravity = 0,
      with_wrenches = 0, base_wrenches = 0, base_forces = 0, tilted_planes = 0;
  for (int trial = 0; trial < 330; ++trial) {
    // Two free draws for each planar one; every 30th a single body (no joints at all).
    const BaseKind kind = trial % 3 == 2 ? BaseKind::Planar : BaseKind::Free;
    const bool no_joints = trial % 30 == 0 || trial % 30 == 2;
    const FloatingProblem p = randomFloatingRobot(rng, kind, no_joints);
    const Eigen::VectorXd qdd_inverse = randomVector(rng, p.base.nv(p.spec), 5.0);
    INFO("trial " << trial << ": " << toString(kind) << " base, " << p.spec.dof() << " joints");
    const Errors e = compareWithMujoco(p, qdd_inverse);
    const int b = kind == BaseKind::Free ? 0 : 1;
    worst[b].max(e);
    ++count[b];
    min_joints = std::min(min_joints, p.spec.dof());
    max_joints = std::max(max_joints, p.spec.dof());
    joints += p.spec.dof();
    chains += p.spec.isChain() && p.spec.dof() > 0 ? 1 : 0;
    single_bodies += p.spec.links.size() == 1 ? 1 : 0;
    with_gravity += p.input.gravity.isZero(0.0) ? 0 : 1;
    with_wrenches += p.input.wrenches.empty() ? 0 : 1;
    for (const WrenchInput& w : p.input.wrenches) base_wrenches += w.link == p.spec.links[0].name ? 1 : 0;
    base_forces += p.input.tau.head(p.base.baseVelocitySize()).isZero(0.0) ? 0 : 1;
    tilted_planes += kind == BaseKind::Planar && !p.base.plane.matrix().isIdentity(0.0) ? 1 : 0;
  }
  std::printf(
      "MuJoCo %s vs zwang on floating bases: %d free + %d planar (%d tilted planes), %d serial chains, %d single "
      "bodies, %d–%d joints (%d in all), %d under gravity, %d with wrenches (%d on the base link), %d with a base "
      "force\n",
      mj_versionString(), count[0], count[1], tilted_planes, chains, single_bodies, min_joints, max_joints, joints,
      with_gravity, with_wrenches, base_wrenches, base_forces);
  const char* names[] = {"free", "planar"};
  for (int b = 0; b < 2; ++b)
    std::printf(
        "  %-6s max rel. error: base v̇ (solveHybridDynamics vs mj_forward) %.2e  joint q̈ %.2e  base classical "
        "[p̈; ω̇] world %.2e  every link's velocity %.2e and acceleration %.2e (frameVelocity, frameAcceleration vs "
        "mj_objectVelocity, mj_objectAcceleration)  tau (inverseDynamics vs mj_inverse) %.2e  H (jointSpaceInertia "
        "vs mj_fullM) %.2e\n",
        names[b], worst[b].base_qdd, worst[b].joint_qdd, worst[b].base_world, worst[b].link_velocity,
        worst[b].link_acceleration, worst[b].tau, worst[b].H);
  CHECK(count[0] >= 200);
  CHECK(count[1] >= 100);
  CHECK(min_joints == 0);
  CHECK(max_joints >= 25);
  CHECK(tilted_planes >= 50);
  CHECK(base_wrenches >= 20);
  for (int b = 0; b < 2; ++b) {
    CHECK(worst[b].base_qdd < kTolerance);
    CHECK(worst[b].joint_qdd < kTolerance);
    CHECK(worst[b].base_world < kTolerance);
    CHECK(worst[b].link_velocity < kTolerance);
    CHECK(worst[b].link_acceleration < kTolerance);
    CHECK(worst[b].tau < kTolerance);
    CHECK(worst[b].H < kTolerance);
  }
}

TEST_CASE("floating bases: the MuJoCo comparison fails on a wrong velocity conversion", "[floating][mujoco]") {
  // Each mistake on 20 random robots of its kind of base: the least disagreement over all of them must stay far
  // above the tolerance, while the right conversion on the same robots stays within it.
  std::mt19937_64 rng(4711);
  const Conversion mistakes[] = {Conversion::FreeLinearInBaseAxes, Conversion::FreeWithoutTransport,
                                 Conversion::PlanarRatesInBaseAxes};
  const char* names[] = {"free joint's linear qvel read in base axes", "free joint's -w x v_lin dropped",
                         "planar rates read in the base's yawed axes"};
  for (int k = 0; k < 3; ++k) {
    const BaseKind kind = mistakes[k] == Conversion::PlanarRatesInBaseAxes ? BaseKind::Planar : BaseKind::Free;
    double least = 1e300, correct = 0.0;
    for (int trial = 0; trial < 20; ++trial) {
      const FloatingProblem p = randomFloatingRobot(rng, kind, false);
      const Eigen::VectorXd qdd_inverse = randomVector(rng, p.base.nv(p.spec), 5.0);
      least = std::min(least, compareWithMujoco(p, qdd_inverse, mistakes[k]).largest());
      correct = std::max(correct, compareWithMujoco(p, qdd_inverse).largest());
    }
    std::printf(
        "floating MuJoCo comparison with a wrong conversion (%s): 20 robots, smallest disagreement %.2e "
        "(the right conversion on the same robots: largest %.2e)\n",
        names[k], least, correct);
    CHECK(least > kMistakeFloor);
    CHECK(correct < kTolerance);
  }
}
