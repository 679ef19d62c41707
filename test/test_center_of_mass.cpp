// Centre of mass and centroidal momentum (center_of_mass.hpp, issue #27 item 5) against independent references, on
// random trees whose joints are of every type (revolute, continuous, prismatic, spherical, planar, free) on a fixed,
// free or planar base:
//  * the dense reference's kinematics (support/floating_reference.*: world poses, spatial Jacobians at the world
//    origin and J̇q̇ per link, written joint by joint from the URDF semantics, no recursion shared with zwang): c =
//    Σ m_l c_l / M from the links' poses and the spec's inertias; J_com = Σ m_l (J_lin − [c_l]× J_ang) / M; ċ =
//    J_com q̇; c̈ from each link's spatial acceleration J q̈ + J̇ q̇ of the solve's q̈ (and of a random q̈ after
//    inverseDynamics), taken to its centre of mass; h = Σ I_l J_l q̇ moved from the world origin to c; for the whole
//    robot and for the subtree of every joint;
//  * J_com once more by central finite differences of c along each velocity coordinate (integrate), and c̈ by central
//    differences of ċ along the solver's motion;
//  * physics: a free-floating robot's centre of mass falls with exactly g whatever its joint torques, and without
//    gravity its centroidal momentum does not change: dh/dt by central differences along the solver's motion is 0.
// MuJoCo's subtree_com, subtree_linvel, subtree_angmom and the bodies' accelerations are compared in
// test_mujoco_joints.cpp.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "support/bad_inputs.hpp"
#include "support/floating_reference.hpp"
#include "support/joint_types_problem.hpp"
#include "support/random_chain.hpp"
#include "support/random_problem.hpp"
#include "zwang/zwang.hpp"

using namespace zwang;
using namespace zwang::testing;

namespace {

// Both sides are exact in double precision on up to ~60 DOFs (sums over the links of products of poses): round-off
// of a few 1e-15 relative to the sizes, grown by the tree's depth; 1e-10 leaves room and still sees any wrong term.
constexpr double kTolerance = 1e-10;

// The tree's random state (drawState) as a value, for the const inputs below.
FloatingInput randomState(std::mt19937_64& rng, const ChainSpec& spec, const FloatingBase& base) {
  FloatingInput in;
  drawState(rng, spec, base, in);
  return in;
}

Eigen::Matrix3d skew(const Eigen::Vector3d& a) {
  Eigen::Matrix3d S;
  S << 0, -a.z(), a.y(), a.z(), 0, -a.x(), -a.y(), a.x(), 0;
  return S;
}

// The links (index as spec.links) in the subtree below spec joint `joint` (its child link and what hangs from it), or
// every link that moves (`joint` = −1: all of them on a floating base, those below a moving joint on a fixed one).
std::vector<bool> linksOf(const ChainSpec& spec, const FloatingBase& base, int joint) {
  std::vector<bool> in(spec.links.size(), false);
  in[0] = joint < 0 && base.kind != BaseKind::Fixed;
  for (std::size_t k = 0; k < spec.joints.size(); ++k) {  // parents come before children (ChainSpec::check)
    const bool below = in[static_cast<std::size_t>(spec.parentLink(k))];
    in[k + 1] = static_cast<int>(k) == joint || below || (joint < 0 && !spec.joints[k].isFixed());
  }
  return in;
}

// The dense answers for one subtree, world axes.
struct DenseCom {
  double mass = 0.0;
  Eigen::Vector3d c = Eigen::Vector3d::Zero(), cd = Eigen::Vector3d::Zero(), cdd = Eigen::Vector3d::Zero();
  Eigen::MatrixXd J;
  Vector6d h = Vector6d::Zero();
};

DenseCom denseCom(const ChainSpec& spec, const FloatingKinematics& kin, const std::vector<bool>& links,
                  const Eigen::VectorXd& v, const Eigen::VectorXd& qdd) {
  DenseCom d;
  d.J = Eigen::MatrixXd::Zero(3, v.size());
  Eigen::Vector3d moment = Eigen::Vector3d::Zero(), mass_acceleration = Eigen::Vector3d::Zero();
  Vector6d h_origin = Vector6d::Zero();
  for (std::size_t l = 0; l < spec.links.size(); ++l) {
    if (!links[l]) continue;
    const double m = spec.links[l].mass;
    const Eigen::Vector3d c = kin.poses[l] * spec.links[l].com;
    const Eigen::MatrixXd& J = kin.J[l];
    d.mass += m;
    moment += m * c;
    d.J += m * (J.topRows(3) - skew(c) * J.bottomRows(3));
    // The classical acceleration of the point c of a body with spatial velocity V and acceleration A at the origin.
    const Vector6d A = J * qdd + kin.bias[l], V = kin.v[l];
    const Eigen::Vector3d w = V.tail<3>(), vc = V.head<3>() + w.cross(c);
    mass_acceleration += m * (A.head<3>() + Eigen::Vector3d(A.tail<3>()).cross(c) + w.cross(vc));
    h_origin += kin.inertia[l] * V;
  }
  d.c = moment / d.mass;
  d.J /= d.mass;
  d.cd = d.J * v;
  d.cdd = mass_acceleration / d.mass;
  d.h << h_origin.head<3>(), h_origin.tail<3>() - d.c.cross(h_origin.head<3>());
  return d;
}

// max |x − y| / max(1, max |y|).
double relative(const Eigen::MatrixXd& x, const Eigen::MatrixXd& y) {
  return (x - y).cwiseAbs().maxCoeff() / std::max(1.0, y.cwiseAbs().maxCoeff());
}

struct Worst {
  double c = 0, cd = 0, cdd = 0, cdd_inverse = 0, J = 0, h = 0, mass = 0;
};

}  // namespace

TEST_CASE("centre of mass: position, velocity, acceleration, Jacobian and momentum match the dense reference",
          "[com]") {
  std::mt19937_64 rng(2705);
  Worst worst;
  int trees = 0, subtrees = 0, floating = 0;
  for (int trial = 0; trial < 150; ++trial) {
    const ChainSpec spec = randomJointTypesTree(rng, 1, 20, 0.3);
    const FloatingBase base = randomBase(rng);
    const FloatingInput in = randomState(rng, spec, base);
    const Model model = floatingModelFromSpec(spec, base);
    Workspace ws(model);
    const Task task(model);
    REQUIRE(solveHybridDynamics(model, ws, in.q, in.v, in.tau, task));
    const Eigen::VectorXd qdd = ws.solution.qdd;
    const FloatingKinematics kin = floatingKinematics(spec, base, in.q, in.v);
    ++trees;
    floating += base.kind != BaseKind::Fixed ? 1 : 0;
    for (int k = -1; k < static_cast<int>(spec.joints.size()); ++k) {
      if (k >= 0 && spec.joints[static_cast<std::size_t>(k)].isFixed()) continue;
      const int joint = k < 0 ? kWholeRobot : model.jointIndex(spec.joints[static_cast<std::size_t>(k)].name);
      const DenseCom d = denseCom(spec, kin, linksOf(spec, base, k), in.v, qdd);
      INFO("trial " << trial << ", " << toString(base.kind) << " base, joint " << joint);
      double mass = 0.0;
      Vec3 c, cd, cdd;
      Vec6 h;
      Eigen::MatrixXd J(3, model.nv());
      REQUIRE(subtreeMass(model, joint, mass));
      REQUIRE(centerOfMass(model, ws, in.q, joint, c));
      REQUIRE(centerOfMassVelocity(model, ws, in.q, in.v, joint, cd));
      REQUIRE(centerOfMassAcceleration(model, ws, in.q, in.v, joint, cdd));
      REQUIRE(centroidalMomentum(model, ws, in.q, in.v, joint, h));
      REQUIRE(jacobianCenterOfMass(model, ws, in.q, joint, J));
      worst.mass = std::max(worst.mass, std::abs(mass - d.mass) / d.mass);
      worst.c = std::max(worst.c, relative(c, d.c));
      worst.cd = std::max(worst.cd, relative(cd, d.cd));
      worst.cdd = std::max(worst.cdd, relative(cdd, d.cdd));
      worst.J = std::max(worst.J, relative(J, d.J));
      worst.h = std::max(worst.h, relative(h, d.h));
      ++subtrees;
    }
    // After inverseDynamics the acceleration is that of its q̈, any q̈ (here random, gravity on).
    const Eigen::VectorXd qdd_any = randomVector(rng, model.nv(), 5.0);
    REQUIRE(inverseDynamics(model, ws, in.q, in.v, qdd_any, task));
    Vec3 cdd;
    REQUIRE(centerOfMassAcceleration(model, ws, in.q, in.v, kWholeRobot, cdd));
    const DenseCom d = denseCom(spec, kin, linksOf(spec, base, -1), in.v, qdd_any);
    worst.cdd_inverse = std::max(worst.cdd_inverse, relative(cdd, d.cdd));
  }
  std::printf(
      "centre of mass vs dense reference: %d trees (%d floating), %d subtrees; max rel. error: mass %.2e  c %.2e  "
      "c-dot %.2e  c-ddot %.2e (after inverseDynamics at a random q-ddot: %.2e)  J_com %.2e  h %.2e\n",
      trees, floating, subtrees, worst.mass, worst.c, worst.cd, worst.cdd, worst.cdd_inverse, worst.J, worst.h);
  CHECK(worst.cdd_inverse < kTolerance);
  CHECK(floating >= 60);
  CHECK(subtrees >= 1000);
  CHECK(worst.mass < kTolerance);
  CHECK(worst.c < kTolerance);
  CHECK(worst.cd < kTolerance);
  CHECK(worst.cdd < kTolerance);
  CHECK(worst.J < kTolerance);
  CHECK(worst.h < kTolerance);
}

TEST_CASE("centre of mass: the Jacobian is the derivative of the position along each velocity coordinate", "[com]") {
  // Central differences c(q ⊕ ε e_k) − c(q ⊕ −ε e_k) over 2ε, with zwang's integrate (exact for a constant velocity):
  // truncation ε² |c'''| ~ 1e-10 and rounding 1e-16/ε ~ 1e-11 at ε = 1e-5, so 1e-8 relative.
  std::mt19937_64 rng(2706);
  double worst = 0.0;
  for (int trial = 0; trial < 40; ++trial) {
    const ChainSpec spec = randomJointTypesTree(rng, 1, 20, 0.3);
    const FloatingBase base = randomBase(rng);
    const FloatingInput in = randomState(rng, spec, base);
    const Model model = floatingModelFromSpec(spec, base);
    Workspace ws(model);
    Eigen::MatrixXd J(3, model.nv()), J_fd(3, model.nv());
    REQUIRE(jacobianCenterOfMass(model, ws, in.q, kWholeRobot, J));
    const double eps = 1e-5;
    for (int k = 0; k < model.nv(); ++k) {
      Eigen::VectorXd step = Eigen::VectorXd::Zero(model.nv()), q_plus(model.nq()), q_minus(model.nq());
      step[k] = 1.0;
      REQUIRE(integrate(model, in.q, step, eps, q_plus));
      REQUIRE(integrate(model, in.q, step, -eps, q_minus));
      Vec3 c_plus, c_minus;
      REQUIRE(forwardKinematics(model, ws, q_plus));
      REQUIRE(centerOfMass(model, ws, q_plus, kWholeRobot, c_plus));
      REQUIRE(forwardKinematics(model, ws, q_minus));
      REQUIRE(centerOfMass(model, ws, q_minus, kWholeRobot, c_minus));
      J_fd.col(k) = (c_plus - c_minus) / (2 * eps);
    }
    worst = std::max(worst, relative(J, J_fd));
  }
  std::printf("centre-of-mass Jacobian vs central differences: 40 trees, max rel. error %.2e\n", worst);
  CHECK(worst < 1e-8);
}

TEST_CASE("centre of mass: the acceleration is the derivative of the velocity along the solver's motion", "[com]") {
  // Central differences of ċ over the states (q ⊕ (±ε v + ε²/2 v̇), v ± ε v̇), the solve's v̇ = q̈: the difference
  // quotient is c̈ + O(ε²) (the same reasoning as the free-flight case below), far below 1e-6 of max(1, |c̈|) at ε =
  // 1e-5, for every subtree's and the whole robot's c̈, gravity and joint torques on.
  std::mt19937_64 rng(2708);
  double worst = 0.0;
  int subtrees = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const ChainSpec spec = randomJointTypesTree(rng, 1, 20, 0.3);
    const FloatingBase base = randomBase(rng);
    const FloatingInput in = randomState(rng, spec, base);
    const Model model = floatingModelFromSpec(spec, base);
    Workspace ws(model);
    const Task task(model);
    REQUIRE(solveHybridDynamics(model, ws, in.q, in.v, in.tau, task));
    const Eigen::VectorXd vdot = ws.solution.qdd;
    for (int joint = kWholeRobot; joint < static_cast<int>(model.joints().size()); ++joint, ++subtrees) {
      double mass = 0.0;
      REQUIRE(subtreeMass(model, joint, mass));
      if (mass <= 0.0) continue;
      Vec3 cdd;
      REQUIRE(solveHybridDynamics(model, ws, in.q, in.v, in.tau, task));
      REQUIRE(centerOfMassAcceleration(model, ws, in.q, in.v, joint, cdd));
      const double eps = 1e-5;
      Vec3 cd_at[2];
      for (int side = 0; side < 2; ++side) {
        const double s = side == 0 ? eps : -eps;
        Eigen::VectorXd q(model.nq());
        const Eigen::VectorXd v = in.v + s * vdot;
        REQUIRE(integrate(model, in.q, in.v * s + vdot * (0.5 * s * s), 1.0, q));
        REQUIRE(forwardKinematics(model, ws, q, v));
        REQUIRE(centerOfMassVelocity(model, ws, q, v, joint, cd_at[side]));
      }
      const Vec3 difference = (cd_at[0] - cd_at[1]) / (2 * eps);
      worst = std::max(worst, (difference - cdd).cwiseAbs().maxCoeff() / std::max(1.0, cdd.cwiseAbs().maxCoeff()));
    }
  }
  std::printf("centre-of-mass acceleration vs central differences of its velocity: %d subtrees, max rel. error %.2e\n",
              subtrees, worst);
  CHECK(worst < 1e-6);
}

TEST_CASE("centre of mass: in free flight it falls with g and the centroidal momentum is conserved", "[com]") {
  // A free-floating robot (free base, no contact, any joint torques: they are internal forces) has c̈ = g exactly;
  // without gravity its centroidal momentum h is constant, so dh/dt = 0 along the solver's motion. dh/dt is taken by
  // central differences over ±ε along the motion: the state (q ⊕ (±ε v + ε²/2 v̇), v ± ε v̇) is the true one to
  // O(ε³) in q and O(ε²) in v with the same ε² term on both sides, so the difference quotient is dh/dt + O(ε²). At
  // ε = 1e-5 the truncation ε²|d³h/dt³|/6 of these fast random motions (light links accelerating at hundreds of
  // m/s²) and the rounding 1e-16 |h|/ε (|h| up to a few hundred) stay far below 1e-6 of max(1, |h|), while a term
  // missing from h would leave a rate of order 1.
  std::mt19937_64 rng(2707);
  double worst_fall = 0.0, worst_rate = 0.0, largest_h = 0.0;
  for (int trial = 0; trial < 60; ++trial) {
    const ChainSpec spec = randomJointTypesTree(rng, 1, 20, 0.3);
    const FloatingBase base{BaseKind::Free, Eigen::Isometry3d::Identity()};
    const FloatingInput in = randomState(rng, spec, base);
    const Model model = floatingModelFromSpec(spec, base);
    Workspace ws(model);
    Task task(model);
    task.gravity = 9.81 * randomUnitVector(rng);
    REQUIRE(solveHybridDynamics(model, ws, in.q, in.v, in.tau, task));
    Vec3 cdd;
    REQUIRE(centerOfMassAcceleration(model, ws, in.q, in.v, kWholeRobot, cdd));
    worst_fall = std::max(worst_fall, (cdd - task.gravity).norm() / 9.81);

    task.gravity.setZero();
    REQUIRE(solveHybridDynamics(model, ws, in.q, in.v, in.tau, task));
    const Eigen::VectorXd vdot = ws.solution.qdd;
    const double eps = 1e-5;
    Vec6 h_at[2];
    for (int side = 0; side < 2; ++side) {
      const double s = side == 0 ? eps : -eps;
      Eigen::VectorXd q(model.nq());
      const Eigen::VectorXd v = in.v + s * vdot;
      REQUIRE(integrate(model, in.q, in.v * s + vdot * (0.5 * s * s), 1.0, q));
      REQUIRE(forwardKinematics(model, ws, q, v));
      REQUIRE(centroidalMomentum(model, ws, q, v, kWholeRobot, h_at[side]));
      largest_h = std::max(largest_h, h_at[side].cwiseAbs().maxCoeff());
    }
    const Vec6 rate = (h_at[0] - h_at[1]) / (2 * eps);
    worst_rate = std::max(worst_rate, rate.cwiseAbs().maxCoeff() / std::max(1.0, h_at[0].cwiseAbs().maxCoeff()));
  }
  std::printf(
      "free flight: 60 floating trees; max |c-ddot − g|/|g| %.2e; max |dh/dt| / max(1, |h|) %.2e (|h| up to %.1f)\n",
      worst_fall, worst_rate, largest_h);
  CHECK(worst_fall < kTolerance);
  CHECK(worst_rate < 1e-6);
}

TEST_CASE("centre of mass: bad inputs come back as a Status", "[com]") {
  const Model model = pandaModel();
  Workspace ws(model);
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(7), qd = Eigen::VectorXd::Zero(7);
  Vec3 c = Vec3::Constant(42.0);
  Status s = centerOfMass(model, ws, q, kWholeRobot, c);
  CHECK(s.code == StatusCode::NotComputed);
  CHECK(c == Vec3::Constant(42.0));  // left unchanged on an error
  REQUIRE(forwardKinematics(model, ws, q));
  CHECK(centerOfMass(model, ws, q, kWholeRobot, c));
  s = centerOfMass(model, ws, q, 7, c);
  CHECK(s.code == StatusCode::ModelMismatch);
  CHECK(std::string(s.message).find("joint index 7") != std::string::npos);
  s = centerOfMassVelocity(model, ws, q, qd, kWholeRobot, c);
  CHECK(s.code == StatusCode::NotComputed);
  Eigen::MatrixXd J(3, 6);
  s = jacobianCenterOfMass(model, ws, q, kWholeRobot, J);
  CHECK(s.code == StatusCode::SizeMismatch);
  double mass = 0.0;
  REQUIRE(subtreeMass(model, kWholeRobot, mass));
  CHECK(mass > 0.0);

  // A disc that only spins (rotational inertia, no mass) has no centre of mass.
  Joint spin;
  spin.name = "spin";
  const Model disc = ModelBuilder().addJoint(spin, "disc", RigidInertia{0.0, Vec3::Zero(), Mat3::Identity()}).build();
  Workspace ws_disc(disc);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(1);
  REQUIRE(forwardKinematics(disc, ws_disc, zero, zero));
  s = centerOfMass(disc, ws_disc, zero, kWholeRobot, c);
  CHECK(s.code == StatusCode::BadConfiguration);
  CHECK(std::string(s.message) == "the robot has no moving mass: its centre of mass is undefined");
  s = centerOfMass(disc, ws_disc, zero, 0, c);
  CHECK(std::string(s.message) == "the subtree of joint 'spin' has no mass: its centre of mass is undefined");
  Vec6 h;
  CHECK(centroidalMomentum(disc, ws_disc, zero, zero, kWholeRobot, h).code == StatusCode::BadConfiguration);
}
