// Proves the test references right WITHOUT the zwang solver: closed forms,
// mechanics identities checked by finite differences of forward kinematics
// alone, an independent URDF parser, and KDL (whose conventions are pinned
// down here, one by one, against the dense reference).
#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include <tinyxml.h>
#include <urdf_parser/urdf_parser.h>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <catch2/catch.hpp>
#include <kdl/chainhdsolver_vereshchagin.hpp>

#include "support/chain_spec.hpp"
#include "support/dense_reference.hpp"
#include "support/kdl_bridge.hpp"
#include "support/random_chain.hpp"
#include "support/urdf_writer.hpp"

using namespace zwang::testing;

namespace {

constexpr double kGravity = 9.81;

// ‖a − b‖ / max(‖b‖, 1): relative for the O(1)–O(100) values these tests
// produce, absolute near zero (where a relative error means nothing).
double relErr(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  REQUIRE(a.rows() == b.rows());
  REQUIRE(a.cols() == b.cols());
  return (a - b).norm() / std::max(b.norm(), 1.0);
}

// Rotation vector θ·u of R (world-frame angle-axis).
Eigen::Vector3d rotationVector(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}

// Draws a full random problem (no constraints) for `spec`.
DynamicsInput randomInput(std::mt19937_64& rng, const ChainSpec& spec) {
  const int n = spec.dof();
  DynamicsInput in;
  in.q = randomVector(rng, n, 2.0);
  in.qd = randomVector(rng, n, 1.5);
  in.tau = randomVector(rng, n, 10.0);
  in.gravity =
      uniform01(rng) < 0.7 ? Eigen::Vector3d(0.0, 0.0, -kGravity) : Eigen::Vector3d(kGravity * randomUnitVector(rng));
  const int wrenches = uniformInt(rng, 0, 3);
  for (int k = 0; k < wrenches; ++k) {
    const std::size_t link = static_cast<std::size_t>(uniformInt(rng, 0, static_cast<int>(spec.links.size()) - 1));
    in.wrenches.push_back(
        {spec.links[link].name, Vector6d(randomVector(rng, 6, 5.0)), uniform01(rng) < 0.5 ? Axes::Local : Axes::World});
  }
  return in;
}

// m random constraint columns: sometimes axis selections (unit forces and
// moments, as in KDL's examples), otherwise general directions.
ConstraintInput randomConstraint(std::mt19937_64& rng, const std::string& link, int m) {
  ConstraintInput c;
  c.link = link;
  c.A = Matrix6Xd::Zero(6, m);
  if (uniform01(rng) < 0.4) {
    std::vector<int> rows = {0, 1, 2, 3, 4, 5};
    for (int k = 0; k < m; ++k) {
      const int pick = uniformInt(rng, k, 5);
      std::swap(rows[static_cast<std::size_t>(k)], rows[static_cast<std::size_t>(pick)]);
      c.A(rows[static_cast<std::size_t>(k)], k) = 1.0;
    }
  } else {
    for (int k = 0; k < m; ++k) c.A.col(k) = randomVector(rng, 6, 1.0);
  }
  c.b = randomVector(rng, m, 3.0);
  c.axes = uniform01(rng) < 0.5 ? Axes::Local : Axes::World;
  return c;
}

// Chain options that KDL's Vereshchagin can take (no fixed joints).
RandomChainOptions noFixed() {
  RandomChainOptions options;
  options.fixed_joint_probability = 0.0;
  return options;
}

// The COM of every link in world coordinates and its world-axes rotational
// inertia, from the link poses alone.
Eigen::Vector3d comWorld(const ChainSpec& spec, const std::vector<Eigen::Isometry3d>& poses, std::size_t i) {
  return poses[i] * spec.links[i].com;
}
Eigen::Matrix3d inertiaWorld(const ChainSpec& spec, const std::vector<Eigen::Isometry3d>& poses, std::size_t i) {
  const Eigen::Matrix3d R = poses[i].linear() * rpyToMatrix(spec.links[i].inertial_rpy);
  return R * spec.links[i].inertia * R.transpose();
}

std::vector<Eigen::Isometry3d> poses(const ChainSpec& spec, const Eigen::VectorXd& q) {
  return denseKinematics(spec, q, Eigen::VectorXd::Zero(q.size())).poses;
}

}  // namespace

// --------------------------------------------------------------------------
// ChainSpec and the random generator
// --------------------------------------------------------------------------

TEST_CASE("ChainSpec: dof, moving joints, names, rpy", "[references]") {
  const ChainSpec arm = oneDofArm();
  CHECK(arm.dof() == 1);
  CHECK(arm.movingJoints() == std::vector<int>{0});
  CHECK(arm.linkIndex("tool") == 2);
  CHECK_THROWS_AS(arm.linkIndex("nope"), std::invalid_argument);

  // URDF rpy: fixed axes x, y, z, i.e. Rz(yaw)·Ry(pitch)·Rx(roll).
  const double r = 0.3, p = -1.1, y = 2.0;
  Eigen::Matrix3d Rx, Ry, Rz;
  Rx << 1, 0, 0, 0, std::cos(r), -std::sin(r), 0, std::sin(r), std::cos(r);
  Ry << std::cos(p), 0, std::sin(p), 0, 1, 0, -std::sin(p), 0, std::cos(p);
  Rz << std::cos(y), -std::sin(y), 0, std::sin(y), std::cos(y), 0, 0, 0, 1;
  CHECK((rpyToMatrix(Eigen::Vector3d(r, p, y)) - Rz * Ry * Rx).norm() < 1e-15);
}

TEST_CASE("randomChain: deterministic, valid, within the documented ranges", "[references]") {
  for (std::uint64_t seed = 1; seed <= 50; ++seed) {
    std::mt19937_64 a(seed), b(seed);
    const ChainSpec spec = randomChain(a, {});
    CHECK(toUrdf(spec) == toUrdf(randomChain(b, {})));  // same seed, same chain
    CHECK(spec.dof() >= 1);
    CHECK(spec.dof() <= 12);
    for (std::size_t i = 1; i < spec.links.size(); ++i) {
      const LinkSpec& link = spec.links[i];
      CHECK(link.mass >= 0.2);
      CHECK(link.mass <= 5.0);
      CHECK((link.inertia - link.inertia.transpose()).norm() == 0.0);
      const Eigen::Vector3d principal = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(link.inertia).eigenvalues();
      CHECK(principal.minCoeff() > 0.0);
      CHECK(principal(0) + principal(1) >= principal(2));  // triangle inequality
    }
    for (const JointSpec& joint : spec.joints) {
      CHECK(std::abs(joint.axis.norm() - 1.0) < 1e-14);
      CHECK(joint.reflectedInertia() <= 0.5 + 1e-12);
      CHECK(joint.xyz.norm() >= 0.05 - 1e-12);
      CHECK(joint.xyz.norm() <= 0.5 + 1e-12);
    }
  }
  std::mt19937_64 a(1), b(2);
  CHECK(toUrdf(randomChain(a, {})) != toUrdf(randomChain(b, {})));

  // The generator's own raw draws are fixed by the standard's mt19937_64 alone.
  std::mt19937_64 r(42);
  const double u = uniform01(r);
  std::mt19937_64 r2(42);
  CHECK(u == static_cast<double>(r2() >> 11) * 0x1.0p-53);
}

// --------------------------------------------------------------------------
// URDF writer, read back by urdfdom (and TinyXML for the Drake tags)
// --------------------------------------------------------------------------

TEST_CASE("toUrdf: urdfdom reads back every field exactly", "[references][urdf]") {
  std::mt19937_64 rng(2024);
  for (int trial = 0; trial < 20; ++trial) {
    ChainSpec spec = randomChain(rng, {});
    spec.links[1].mass = 0.0;  // one massless link (written without <inertial>)
    spec.links[1].inertia.setZero();
    const std::string xml = toUrdf(spec);
    const urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(xml);
    REQUIRE(model);
    CHECK(model->getName() == spec.name);
    CHECK(model->getRoot()->name == spec.links[0].name);

    for (std::size_t i = 0; i < spec.links.size(); ++i) {
      const LinkSpec& link = spec.links[i];
      const urdf::LinkConstSharedPtr parsed = model->getLink(link.name);
      REQUIRE(parsed);
      if (link.mass == 0.0) {
        CHECK(!parsed->inertial);
        continue;
      }
      REQUIRE(parsed->inertial);
      CHECK(parsed->inertial->mass == link.mass);  // %.17g round-trips exactly
      CHECK(parsed->inertial->origin.position.x == link.com.x());
      CHECK(parsed->inertial->origin.position.y == link.com.y());
      CHECK(parsed->inertial->origin.position.z == link.com.z());
      CHECK(parsed->inertial->ixx == link.inertia(0, 0));
      CHECK(parsed->inertial->ixy == link.inertia(0, 1));
      CHECK(parsed->inertial->ixz == link.inertia(0, 2));
      CHECK(parsed->inertial->iyy == link.inertia(1, 1));
      CHECK(parsed->inertial->iyz == link.inertia(1, 2));
      CHECK(parsed->inertial->izz == link.inertia(2, 2));
      double qx, qy, qz, qw;
      parsed->inertial->origin.rotation.getQuaternion(qx, qy, qz, qw);
      CHECK((Eigen::Quaterniond(qw, qx, qy, qz).toRotationMatrix() - rpyToMatrix(link.inertial_rpy)).norm() < 1e-14);
    }

    for (std::size_t k = 0; k < spec.joints.size(); ++k) {
      const JointSpec& joint = spec.joints[k];
      const urdf::JointConstSharedPtr parsed = model->getJoint(joint.name);
      REQUIRE(parsed);
      CHECK(parsed->parent_link_name == spec.links[k].name);
      CHECK(parsed->child_link_name == spec.links[k + 1].name);
      const int expected_type = joint.type == "revolute"     ? urdf::Joint::REVOLUTE
                                : joint.type == "continuous" ? urdf::Joint::CONTINUOUS
                                : joint.type == "prismatic"  ? urdf::Joint::PRISMATIC
                                                             : urdf::Joint::FIXED;
      CHECK(parsed->type == expected_type);
      const urdf::Pose& origin = parsed->parent_to_joint_origin_transform;
      CHECK(origin.position.x == joint.xyz.x());
      CHECK(origin.position.y == joint.xyz.y());
      CHECK(origin.position.z == joint.xyz.z());
      double qx, qy, qz, qw;
      origin.rotation.getQuaternion(qx, qy, qz, qw);
      CHECK((Eigen::Quaterniond(qw, qx, qy, qz).toRotationMatrix() - rpyToMatrix(joint.rpy)).norm() < 1e-14);
      REQUIRE(parsed->dynamics);
      CHECK(parsed->dynamics->friction == joint.friction);
      CHECK(parsed->dynamics->damping == joint.damping);
      if (joint.isFixed()) continue;
      CHECK(parsed->axis.x == joint.axis.x());
      CHECK(parsed->axis.y == joint.axis.y());
      CHECK(parsed->axis.z == joint.axis.z());
      REQUIRE(parsed->limits);
      CHECK(parsed->limits->effort == joint.effort);
      CHECK(parsed->limits->velocity == joint.velocity);
      if (joint.type != "continuous") {
        CHECK(parsed->limits->lower == joint.lower);
        CHECK(parsed->limits->upper == joint.upper);
      }
    }

    // urdfdom ignores <transmission>; read the Drake actuator tags with TinyXML.
    TiXmlDocument doc;
    doc.Parse(xml.c_str());
    REQUIRE(!doc.Error());
    const TiXmlElement* robot = doc.FirstChildElement("robot");
    REQUIRE(robot);
    CHECK(std::string(robot->Attribute("xmlns:drake")) == "http://drake.mit.edu");
    int transmissions = 0;
    for (const TiXmlElement* t = robot->FirstChildElement("transmission"); t;
         t = t->NextSiblingElement("transmission")) {
      ++transmissions;
      const std::string joint_name = t->FirstChildElement("joint")->Attribute("name");
      const JointSpec& joint = *std::find_if(spec.joints.begin(), spec.joints.end(),
                                             [&](const JointSpec& j) { return j.name == joint_name; });
      const TiXmlElement* actuator = t->FirstChildElement("actuator");
      REQUIRE(actuator);
      double rotor = 0.0, ratio = 0.0;
      REQUIRE(actuator->FirstChildElement("drake:rotor_inertia")->QueryDoubleAttribute("value", &rotor) ==
              TIXML_SUCCESS);
      REQUIRE(actuator->FirstChildElement("drake:gear_ratio")->QueryDoubleAttribute("value", &ratio) == TIXML_SUCCESS);
      CHECK(rotor == joint.rotor_inertia);
      CHECK(ratio == joint.gear_ratio);
    }
    CHECK(transmissions ==
          static_cast<int>(std::count_if(spec.joints.begin(), spec.joints.end(),
                                         [](const JointSpec& j) { return !j.isFixed() && j.rotor_inertia > 0.0; })));
  }
}

// --------------------------------------------------------------------------
// Dense reference: closed forms (docs/theory.md, "The reference cases", and textbook cases)
// --------------------------------------------------------------------------

TEST_CASE("dense reference: the 1-DOF arm of the report", "[references][closed-form]") {
  const ChainSpec arm = oneDofArm();
  DynamicsInput in;
  in.q = Eigen::VectorXd::Zero(1);
  in.qd = Eigen::VectorXd::Constant(1, 0.7);  // no effect on q̈ for a single revolute joint
  in.tau = Eigen::VectorXd::Constant(1, 1.0);
  in.gravity.setZero();

  SECTION("inertia about the joint is 2.25 kg·m², q̈ = τ / I") {
    const DenseResult r = denseDynamics(arm, in);
    CHECK(r.H(0, 0) == Approx(2.25).epsilon(1e-14));
    CHECK(r.qdd(0) == Approx(1.0 / 2.25).epsilon(1e-14));
    // Z = ½ I q̈² − τ q̈ at the minimum = −τ² / (2 I).
    CHECK(r.gauss == Approx(-1.0 / (2.0 * 2.25)).epsilon(1e-13));
  }
  SECTION("a −11 N force along −y at the tip: q̈ = −11 / 2.25") {
    in.tau(0) = 0.0;
    in.q(0) = 0.4;  // rotated: the force is given in the tool's own axes
    in.wrenches.push_back({"tool", (Vector6d() << 0, -11, 0, 0, 0, 0).finished(), Axes::Local});
    CHECK(denseDynamics(arm, in).qdd(0) == Approx(-11.0 / 2.25).epsilon(1e-14));
    // The same force in world axes at q = 0.
    in.q(0) = 0.0;
    in.wrenches[0].axes = Axes::World;
    CHECK(denseDynamics(arm, in).qdd(0) == Approx(-11.0 / 2.25).epsilon(1e-14));
  }
  SECTION("Fig. 5.5 task: angular acceleration 5 rad/s² enforced; ν = τ_c = 2.25·5") {
    in.tau(0) = 0.0;
    ConstraintInput c;
    c.link = "link1";
    c.A = Matrix6Xd::Zero(6, 1);
    c.A(5, 0) = 1.0;  // unit moment about z: constrains ω̇_z
    c.b = Eigen::VectorXd::Constant(1, 5.0);
    in.constraints.push_back(c);
    const DenseResult r = denseDynamics(arm, in);
    CHECK(r.qdd(0) == Approx(5.0).epsilon(1e-14));
    CHECK(r.nu(0) == Approx(2.25 * 5.0).epsilon(1e-14));
    CHECK(r.tau_c(0) == Approx(2.25 * 5.0).epsilon(1e-14));
    CHECK(r.acc_world[1](5) == Approx(5.0).epsilon(1e-14));
  }
  SECTION("a constraint on the CLASSICAL tip acceleration includes the centripetal term") {
    // At q = 0 the tip (1, 0, 0) accelerates by p̈ = (−q̇², q̈, 0). Constrain
    // dᵀ p̈ = b along d = (cos φ, sin φ, 0):  q̈ = (b + q̇² cos φ) / sin φ.
    const double phi = 0.6, b = 1.5, w = in.qd(0);
    ConstraintInput c;
    c.link = "tool";
    c.A = Matrix6Xd::Zero(6, 1);
    c.A.col(0).head<3>() = Eigen::Vector3d(std::cos(phi), std::sin(phi), 0.0);
    c.b = Eigen::VectorXd::Constant(1, b);
    c.axes = Axes::World;
    in.constraints.push_back(c);
    const DenseResult r = denseDynamics(arm, in);
    CHECK(r.qdd(0) == Approx((b + w * w * std::cos(phi)) / std::sin(phi)).epsilon(1e-14));
    CHECK(r.acc_world[2](0) == Approx(-w * w).epsilon(1e-14));
    // ν: the unit force d at 1 m gives a torque sin φ about z; H q̈ = τ + sin φ·ν.
    CHECK(r.nu(0) == Approx((2.25 * r.qdd(0) - in.tau(0)) / std::sin(phi)).epsilon(1e-13));
  }
}

TEST_CASE("dense reference: pendulum and vertical slider under gravity", "[references][closed-form]") {
  SECTION("pendulum: q̈ = −m g l_c sin q / (I_O + d)") {
    const double m = 2.0, lc = 0.7, Iyy = 0.05, d = 0.12;
    ChainSpec spec;
    spec.links.resize(2);
    spec.links[0].name = "base";
    spec.links[1].name = "bob";
    spec.links[1].mass = m;
    spec.links[1].com = Eigen::Vector3d(0.0, 0.0, -lc);  // hangs straight down at q = 0
    spec.links[1].inertia = Eigen::Vector3d(0.05, Iyy, 0.01).asDiagonal();
    spec.joints.resize(1);
    spec.joints[0].name = "hinge";
    spec.joints[0].type = "continuous";
    spec.joints[0].xyz = Eigen::Vector3d(0.1, -0.2, 1.0);
    spec.joints[0].axis = Eigen::Vector3d::UnitY();  // horizontal axis
    spec.joints[0].rotor_inertia = d / 9.0;
    spec.joints[0].gear_ratio = 3.0;
    for (const double q : {0.0, 0.3, -1.2, 2.5}) {
      DynamicsInput in;
      in.q = Eigen::VectorXd::Constant(1, q);
      in.qd = Eigen::VectorXd::Constant(1, -0.8);
      in.tau = Eigen::VectorXd::Zero(1);
      const DenseResult r = denseDynamics(spec, in);
      const double I_O = Iyy + m * lc * lc + d;
      CHECK(r.qdd(0) == Approx(-m * kGravity * lc * std::sin(q) / I_O).margin(1e-14).epsilon(1e-13));
    }
  }
  SECTION("slider: q̈ = (τ + m gᵀu) / (m + d); held still by ν = m g − τ") {
    const double m = 3.0, tau = 4.0;
    ChainSpec spec;
    spec.links.resize(2);
    spec.links[0].name = "base";
    spec.links[1].name = "carriage";
    spec.links[1].mass = m;
    spec.links[1].com = Eigen::Vector3d(0.1, 0.2, 0.3);
    spec.links[1].inertia = Eigen::Vector3d(0.02, 0.03, 0.04).asDiagonal();
    spec.joints.resize(1);
    spec.joints[0].name = "slide";
    spec.joints[0].type = "prismatic";
    spec.joints[0].axis = Eigen::Vector3d::UnitZ();
    DynamicsInput in;
    in.q = Eigen::VectorXd::Constant(1, 0.25);
    in.qd = Eigen::VectorXd::Constant(1, 0.5);
    in.tau = Eigen::VectorXd::Constant(1, tau);
    CHECK(denseDynamics(spec, in).qdd(0) == Approx(tau / m - kGravity).epsilon(1e-14));

    // Tilted joint frame and rotor inertia: u = R(rpy)·axis.
    spec.joints[0].rpy = Eigen::Vector3d(0.4, -0.3, 1.0);
    spec.joints[0].rotor_inertia = 0.01;
    spec.joints[0].gear_ratio = 5.0;
    const Eigen::Vector3d u = rpyToMatrix(spec.joints[0].rpy) * spec.joints[0].axis;
    CHECK(denseDynamics(spec, in).qdd(0) == Approx((tau + m * in.gravity.dot(u)) / (m + 0.25)).epsilon(1e-14));

    // Vertical again, held by a vertical unit force at the carriage: p̈_z = 0.
    spec.joints[0].rpy.setZero();
    ConstraintInput c;
    c.link = "carriage";
    c.A = Matrix6Xd::Zero(6, 1);
    c.A(2, 0) = 1.0;
    c.b = Eigen::VectorXd::Zero(1);
    in.constraints.push_back(c);
    const DenseResult r = denseDynamics(spec, in);
    CHECK(std::abs(r.qdd(0)) < 1e-14);
    CHECK(r.nu(0) == Approx(m * kGravity - tau).epsilon(1e-14));
  }
}

// --------------------------------------------------------------------------
// Dense reference: identities on random chains, checked against finite
// differences of the forward kinematics (which is itself checked against KDL)
// --------------------------------------------------------------------------

TEST_CASE("dense reference: forward kinematics agrees with KDL's", "[references][kdl]") {
  std::mt19937_64 rng(3);
  double worst = 0.0;
  for (int trial = 0; trial < 100; ++trial) {
    const ChainSpec spec = randomChain(rng, {});
    const Eigen::VectorXd q = randomVector(rng, spec.dof(), 3.0);
    const auto dense = poses(spec, q);
    const auto kdl = kdlLinkPoses(spec, q);
    REQUIRE(dense.size() == kdl.size());
    for (std::size_t i = 0; i < dense.size(); ++i)
      worst = std::max(worst, (dense[i].matrix() - kdl[i].matrix()).norm());
  }
  INFO("max pose difference " << worst);
  CHECK(worst < 1e-13);
}

TEST_CASE("dense reference: KKT solution, symmetry, constraint rows, Gauss", "[references]") {
  std::mt19937_64 rng(5);
  for (int trial = 0; trial < 100; ++trial) {
    const ChainSpec spec = randomChain(rng, {});
    const int n = spec.dof();
    DynamicsInput in = randomInput(rng, spec);
    const int groups = uniformInt(rng, 0, 2);
    for (int k = 0; k < groups; ++k) {
      const std::size_t link = static_cast<std::size_t>(uniformInt(rng, 1, static_cast<int>(spec.links.size()) - 1));
      in.constraints.push_back(randomConstraint(rng, spec.links[link].name, uniformInt(rng, 1, 3)));
    }
    const DenseResult r = denseDynamics(spec, in);
    if (!r.wellConditioned()) continue;
    const int m = in.constraintRows();
    CAPTURE(trial, n, m);

    // H symmetric positive definite.
    CHECK((r.H - r.H.transpose()).norm() == 0.0);
    CHECK(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(r.H).eigenvalues().minCoeff() > 0.0);

    // H q̈ + C = τ + Σ Jᵀ A ν, with Jᵀ A ν rebuilt from the classical link
    // Jacobians and the world-axes columns (not from G).
    Eigen::VectorXd tau_c = Eigen::VectorXd::Zero(n);
    int row = 0;
    for (const ConstraintInput& c : in.constraints) {
      const int link = spec.linkIndex(c.link);
      const Eigen::Matrix3d R = c.axes == Axes::Local
                                    ? Eigen::Matrix3d(r.poses[static_cast<std::size_t>(link)].linear())
                                    : Eigen::Matrix3d::Identity();
      Matrix6Xd A_world(6, c.A.cols());
      A_world << R * c.A.topRows<3>(), R * c.A.bottomRows<3>();
      tau_c += linkJacobian(spec, in.q, c.link, Axes::World).transpose() * A_world * r.nu.segment(row, c.A.cols());
      // The rows hold on the classical acceleration, in the constraint's own axes.
      const Vector6d acc = linkAcceleration(spec, in.q, in.qd, r.qdd, c.link, c.axes);
      CHECK(relErr(c.A.transpose() * acc, c.b) < 1e-10);
      CHECK(relErr(acc, c.axes == Axes::Local ? r.acc_local[static_cast<std::size_t>(link)]
                                              : r.acc_world[static_cast<std::size_t>(link)]) < 1e-12);
      row += static_cast<int>(c.A.cols());
    }
    CHECK(relErr(tau_c, r.tau_c) < 1e-10);
    CHECK(relErr(r.H * r.qdd + r.C, in.tau + tau_c) < 1e-10);
    CHECK(relErr(denseInverseDynamics(spec, in.q, in.qd, r.qdd, in.gravity, in.wrenches), in.tau + r.tau_c) < 1e-10);

    // Gauss's principle: q̈ minimises Z on {G q̈ = γ}; along any null-space
    // step δ the increase is exactly ½ δᵀ H δ (the linear term vanishes).
    const Eigen::MatrixXd N = m > 0 ? Eigen::MatrixXd(Eigen::FullPivLU<Eigen::MatrixXd>(r.G).kernel())
                                    : Eigen::MatrixXd(Eigen::MatrixXd::Identity(n, n));
    if (N.cols() > 0 && N.norm() > 0.0) {
      const Eigen::VectorXd delta = N * randomVector(rng, static_cast<int>(N.cols()), 0.5);
      const double increase = gaussFunction(spec, in, r.qdd + delta) - r.gauss;
      CHECK(increase == Approx(0.5 * delta.dot(r.H * delta)).epsilon(1e-7).margin(1e-9));
    }
  }
}

TEST_CASE("dense reference: Jacobians and J̇q̇ against finite differences", "[references][fd]") {
  std::mt19937_64 rng(7);
  const double h = 1e-5;
  for (int trial = 0; trial < 40; ++trial) {
    const ChainSpec spec = randomChain(rng, {});
    const int n = spec.dof();
    const Eigen::VectorXd q = randomVector(rng, n, 2.0), qd = randomVector(rng, n, 1.5),
                          qdd = randomVector(rng, n, 3.0);
    const DenseKinematics kin = denseKinematics(spec, q, qd);
    const DenseKinematics plus = denseKinematics(spec, q + h * qd, qd), minus = denseKinematics(spec, q - h * qd, qd);
    for (std::size_t i = 0; i < spec.links.size(); ++i) {
      const std::string& link = spec.links[i].name;
      CAPTURE(trial, link);
      // Spatial bias J̇ q̇ = d/dt (J(q + t q̇) q̇).
      const Vector6d bias_fd = (plus.J[i] * qd - minus.J[i] * qd) / (2.0 * h);
      CHECK(relErr(kin.bias[i], bias_fd) < 1e-8);

      // Classical Jacobian: [ṗ; ω] from the pose alone (ω from Ṙ = ω× R).
      const Vector6d twist = linkJacobian(spec, q, link, Axes::World) * qd;
      Vector6d twist_fd;
      twist_fd << (plus.poses[i].translation() - minus.poses[i].translation()) / (2.0 * h),
          rotationVector(plus.poses[i].linear() * minus.poses[i].linear().transpose()) / (2.0 * h);
      CHECK(relErr(twist, twist_fd) < 1e-8);
      const Eigen::Matrix3d Rt = kin.poses[i].linear().transpose();
      Vector6d twist_local;
      twist_local << Rt * twist.head<3>(), Rt * twist.tail<3>();
      CHECK(relErr(linkJacobian(spec, q, link, Axes::Local) * qd, twist_local) < 1e-13);

      // Classical acceleration = d/dt of [ṗ; ω] along q(t) = q + t q̇ + ½ t² q̈.
      auto q_at = [&](double t) { return Eigen::VectorXd(q + t * qd + 0.5 * t * t * qdd); };
      auto qd_at = [&](double t) { return Eigen::VectorXd(qd + t * qdd); };
      const Vector6d acc = linkAcceleration(spec, q, qd, qdd, link, Axes::World);
      const Vector6d acc_fd = (linkJacobian(spec, q_at(h), link, Axes::World) * qd_at(h) -
                               linkJacobian(spec, q_at(-h), link, Axes::World) * qd_at(-h)) /
                              (2.0 * h);
      CHECK(relErr(acc, acc_fd) < 1e-8);
      // …and p̈ as the second difference of the position itself.
      const double h2 = 1e-4;
      const Eigen::Vector3d p_fd = (poses(spec, q_at(h2))[i].translation() - 2.0 * kin.poses[i].translation() +
                                    poses(spec, q_at(-h2))[i].translation()) /
                                   (h2 * h2);
      CHECK(relErr(acc.head<3>(), p_fd) < 1e-5);
    }
  }
}

TEST_CASE("dense reference: H and C from Lagrange's equations by finite differences", "[references][fd]") {
  // Independent of J, J̇ and the spatial inertias: kinetic energy from COM
  // velocities and angular velocities (finite differences of the poses),
  // potential energy from COM heights, generalised forces of wrenches by
  // virtual work — and C = Ḣ q̇ − ½ ∂(q̇ᵀ H q̇)/∂q + ∂V/∂q − Q_ext.
  std::mt19937_64 rng(9);
  const double h = 1e-5;
  for (int trial = 0; trial < 25; ++trial) {
    const ChainSpec spec = randomChain(rng, {});
    const int n = spec.dof();
    DynamicsInput in = randomInput(rng, spec);
    CAPTURE(trial, n);
    auto solve = [&](const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::Vector3d& g,
                     const std::vector<WrenchInput>& wrenches) {
      DynamicsInput x = in;
      x.q = q;
      x.qd = qd;
      x.gravity = g;
      x.wrenches = wrenches;
      return denseDynamics(spec, x);
    };
    const DenseResult r = solve(in.q, in.qd, Eigen::Vector3d::Zero(), {});

    // ½ q̇ᵀ H q̇ = Σ ½ m |ċ|² + ½ ωᵀ I_c ω + ½ Σ d q̇².
    for (int k = 0; k < 3; ++k) {
      const Eigen::VectorXd v = randomVector(rng, n, 1.0);
      const auto plus = poses(spec, in.q + h * v), minus = poses(spec, in.q - h * v), here = poses(spec, in.q);
      double T = 0.0;
      for (std::size_t i = 0; i < spec.links.size(); ++i) {
        const Eigen::Vector3d cdot = (comWorld(spec, plus, i) - comWorld(spec, minus, i)) / (2.0 * h);
        const Eigen::Vector3d w = rotationVector(plus[i].linear() * minus[i].linear().transpose()) / (2.0 * h);
        T += 0.5 * spec.links[i].mass * cdot.squaredNorm() + 0.5 * w.dot(inertiaWorld(spec, here, i) * w);
      }
      for (int j = 0; j < n; ++j) T += 0.5 * denseKinematics(spec, in.q, in.qd).reflected(j) * v(j) * v(j);
      CHECK(0.5 * v.dot(r.H * v) == Approx(T).epsilon(1e-8));
    }

    // Velocity terms: C(q, q̇; g = 0, no wrench) = Ḣ q̇ − ½ ∂(q̇ᵀ H q̇)/∂q.
    Eigen::VectorXd C_fd = (solve(in.q + h * in.qd, in.qd, Eigen::Vector3d::Zero(), {}).H -
                            solve(in.q - h * in.qd, in.qd, Eigen::Vector3d::Zero(), {}).H) /
                           (2.0 * h) * in.qd;
    // Gravity: ∂V/∂q with V = −Σ m gᵀ c.  Wrenches: Q_k = Σ fᵀ ∂p/∂q_k + nᵀ θ_k.
    Eigen::VectorXd G_fd(n), Q_fd = Eigen::VectorXd::Zero(n);
    for (int k = 0; k < n; ++k) {
      const Eigen::VectorXd e = Eigen::VectorXd::Unit(n, k);
      const double kinetic_plus = in.qd.dot(solve(in.q + h * e, in.qd, Eigen::Vector3d::Zero(), {}).H * in.qd);
      const double kinetic_minus = in.qd.dot(solve(in.q - h * e, in.qd, Eigen::Vector3d::Zero(), {}).H * in.qd);
      C_fd(k) -= 0.5 * (kinetic_plus - kinetic_minus) / (2.0 * h);
      const auto plus = poses(spec, in.q + h * e), minus = poses(spec, in.q - h * e), here = poses(spec, in.q);
      double V_plus = 0.0, V_minus = 0.0;
      for (std::size_t i = 0; i < spec.links.size(); ++i) {
        V_plus -= spec.links[i].mass * in.gravity.dot(comWorld(spec, plus, i));
        V_minus -= spec.links[i].mass * in.gravity.dot(comWorld(spec, minus, i));
      }
      G_fd(k) = (V_plus - V_minus) / (2.0 * h);
      for (const WrenchInput& w : in.wrenches) {
        const auto i = static_cast<std::size_t>(spec.linkIndex(w.link));
        const Eigen::Matrix3d R =
            w.axes == Axes::Local ? Eigen::Matrix3d(here[i].linear()) : Eigen::Matrix3d::Identity();
        const Eigen::Vector3d dp = (plus[i].translation() - minus[i].translation()) / (2.0 * h);
        const Eigen::Vector3d dtheta = rotationVector(plus[i].linear() * minus[i].linear().transpose()) / (2.0 * h);
        Q_fd(k) += (R * w.wrench.head<3>()).dot(dp) + (R * w.wrench.tail<3>()).dot(dtheta);
      }
    }
    const Eigen::VectorXd C_vel = r.C;
    const Eigen::VectorXd C_grav = solve(in.q, Eigen::VectorXd::Zero(n), in.gravity, {}).C;
    const Eigen::VectorXd C_ext = solve(in.q, Eigen::VectorXd::Zero(n), Eigen::Vector3d::Zero(), in.wrenches).C;
    const Eigen::VectorXd C_all = solve(in.q, in.qd, in.gravity, in.wrenches).C;
    CHECK(relErr(C_vel, C_fd) < 1e-7);
    CHECK(relErr(C_grav, G_fd) < 1e-8);
    CHECK(relErr(C_ext, -Q_fd) < 1e-8);
    CHECK(relErr(C_all, C_vel + C_grav + C_ext) < 1e-12);
  }
}

TEST_CASE("dense reference: invariant under moving the whole chain in the world", "[references]") {
  // Place the chain elsewhere (a rigid transform T in front of the first joint),
  // turn gravity and the world-axes inputs with it: q̈, ν, Z, H, C are unchanged.
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 50; ++trial) {
    const ChainSpec spec = randomChain(rng, {});
    DynamicsInput in = randomInput(rng, spec);
    const std::size_t link = static_cast<std::size_t>(uniformInt(rng, 1, static_cast<int>(spec.links.size()) - 1));
    in.constraints.push_back(randomConstraint(rng, spec.links[link].name, uniformInt(rng, 1, 3)));
    const DenseResult r = denseDynamics(spec, in);
    if (!r.wellConditioned()) continue;

    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = randomRotation(rng);
    T.translation() = randomVector(rng, 3, 2.0);
    ChainSpec moved = spec;
    Eigen::Isometry3d first = Eigen::Isometry3d::Identity();
    first.translation() = spec.joints[0].xyz;
    first.linear() = rpyToMatrix(spec.joints[0].rpy);
    first = T * first;
    moved.joints[0].xyz = first.translation();
    moved.joints[0].rpy = first.linear().eulerAngles(2, 1, 0).reverse();  // (roll, pitch, yaw)
    REQUIRE((rpyToMatrix(moved.joints[0].rpy) - first.linear()).norm() < 1e-13);
    DynamicsInput in_moved = in;
    in_moved.gravity = T.linear() * in.gravity;
    // (The base link itself stays put, but J_base = 0: its wrenches do nothing.)
    for (WrenchInput& w : in_moved.wrenches)
      if (w.axes == Axes::World) w.wrench << T.linear() * w.wrench.head<3>(), T.linear() * w.wrench.tail<3>();
    for (ConstraintInput& c : in_moved.constraints)
      if (c.axes == Axes::World) c.A << T.linear() * c.A.topRows<3>(), T.linear() * c.A.bottomRows<3>();
    const DenseResult a = denseDynamics(spec, in), b = denseDynamics(moved, in_moved);
    CAPTURE(trial);
    CHECK(relErr(b.H, a.H) < 1e-12);
    CHECK(relErr(b.C, a.C) < 1e-11);
    CHECK(relErr(b.qdd, a.qdd) < 1e-9);
    CHECK(relErr(b.nu, a.nu) < 1e-9);
    // Z is frame-invariant (the base link adds nothing: its a and v are 0).
    CHECK(b.gauss == Approx(a.gauss).epsilon(1e-9).margin(1e-9));
  }
}

// --------------------------------------------------------------------------
// KDL against the dense reference, and KDL's conventions
// --------------------------------------------------------------------------

TEST_CASE("KDL RNE agrees with the dense inverse dynamics", "[references][kdl]") {
  std::mt19937_64 rng(13);
  double worst = 0.0;
  for (int trial = 0; trial < 200; ++trial) {
    const ChainSpec spec = randomChain(rng, {});  // fixed joints included: RNE handles them
    const DynamicsInput in = randomInput(rng, spec);
    const Eigen::VectorXd qdd = randomVector(rng, spec.dof(), 3.0);
    const Eigen::VectorXd dense = denseInverseDynamics(spec, in.q, in.qd, qdd, in.gravity, in.wrenches);
    const Eigen::VectorXd kdl = kdlInverseDynamics(spec, in.q, in.qd, qdd, in.gravity, in.wrenches);
    worst = std::max(worst, relErr(kdl, dense));
  }
  INFO("max relative difference " << worst);
  CHECK(worst < 1e-11);
}

TEST_CASE("KDL Vereshchagin agrees with the dense KKT solution", "[references][kdl]") {
  std::mt19937_64 rng(17);
  int compared = 0, skipped = 0;
  double worst_qdd = 0.0, worst_nu = 0.0, worst_acc = 0.0, worst_tau_c = 0.0, worst_naive = 1e300;
  for (int trial = 0; trial < 320; ++trial) {
    const ChainSpec spec = randomChain(rng, noFixed());
    const int n = spec.dof();
    DynamicsInput in = randomInput(rng, spec);
    const int m = uniformInt(rng, 0, std::min(6, n + 1));  // n + 1: some over-constrained draws, skipped
    if (m > 0) in.constraints.push_back(randomConstraint(rng, spec.links.back().name, m));
    const DenseResult dense = denseDynamics(spec, in);
    if (!dense.wellConditioned() || dense.constraint_rank < m) {
      ++skipped;
      continue;
    }
    const KdlHybridResult kdl = kdlHybridDynamics(spec, in);
    REQUIRE(kdl.error == 0);
    ++compared;
    worst_qdd = std::max(worst_qdd, relErr(kdl.qdd, dense.qdd));
    worst_nu = std::max(worst_nu, m > 0 ? relErr(kdl.nu, dense.nu) : 0.0);
    worst_tau_c = std::max(worst_tau_c, relErr(kdl.tau_c, dense.tau_c));
    for (std::size_t i = 0; i < spec.links.size(); ++i)
      worst_acc = std::max(worst_acc, relErr(kdl.acc_world[i], dense.acc_world[i]));

    // The beta conversion matters: handing KDL the classical set points
    // directly (β = b) gives a different motion.
    // (Only where the conversion changes β noticeably: rows without a force
    // part, l = 0, need none.)
    if (m > 0 && (kdl.beta - in.constraints[0].b).norm() > 1e-2) {
      const KDL::Chain chain = toKdlChain(spec);
      const KDL::Vector minus_g(-in.gravity.x(), -in.gravity.y(), -in.gravity.z());
      KDL::ChainHdSolver_Vereshchagin solver(chain, KDL::Twist(minus_g, KDL::Vector::Zero()),
                                             static_cast<unsigned int>(m));
      KDL::JntArray q(n), qd(n), qdd(n), tau(n), ct(n), beta(static_cast<unsigned int>(m));
      q.data = in.q;
      qd.data = in.qd;
      tau.data = in.tau;
      beta.data = in.constraints[0].b;
      KDL::Jacobian alpha(static_cast<unsigned int>(m));
      alpha.data = kdl.alpha;
      KDL::Wrenches f_ext;
      for (const Vector6d& f : kdl.f_ext)
        f_ext.emplace_back(KDL::Vector(f(0), f(1), f(2)), KDL::Vector(f(3), f(4), f(5)));
      solver.CartToJnt(q, qd, qdd, alpha, beta, f_ext, tau, ct);
      worst_naive = std::min(worst_naive, relErr(qdd.data, dense.qdd));
    }
  }
  INFO("compared " << compared << ", skipped " << skipped << "; max rel. error q̈ " << worst_qdd << ", ν " << worst_nu
                   << ", τ_c " << worst_tau_c << ", link accelerations " << worst_acc
                   << "; naive β = b: smallest error " << worst_naive);
  CHECK(compared >= 200);
  CHECK(worst_qdd < 1e-9);
  CHECK(worst_nu < 1e-9);
  CHECK(worst_tau_c < 1e-9);
  CHECK(worst_acc < 1e-9);
  CHECK(worst_naive > 1e-6);
}

TEST_CASE("KDL conventions: the sign of ν and what constraint_torques are", "[references][kdl]") {
  std::mt19937_64 rng(19);
  int compared = 0;
  int kdl_replay_fails = 0;  // draws where τ + KDL's constraint_torques does NOT replay q̈
  double worst_sign = 0.0, best_wrong_sign = 1e300, worst_last = 0.0, worst_articulated = 0.0, worst_replay = 0.0;
  for (int trial = 0; trial < 120; ++trial) {
    RandomChainOptions options = noFixed();
    options.min_moving_joints = 2;
    const ChainSpec spec = randomChain(rng, options);
    const int n = spec.dof();
    DynamicsInput in = randomInput(rng, spec);
    const int m = uniformInt(rng, 1, std::min(6, n));
    in.constraints.push_back(randomConstraint(rng, spec.links.back().name, m));
    const DenseResult dense = denseDynamics(spec, in);
    if (!dense.wellConditioned() || dense.constraint_rank < m) continue;
    const KdlHybridResult kdl = kdlHybridDynamics(spec, in);
    ++compared;

    // ν_KDL = −ν: KDL applies the wrench −α ν_KDL to the tip.
    worst_sign = std::max(worst_sign, relErr(-kdl.nu_kdl, dense.nu));
    best_wrong_sign = std::min(best_wrong_sign, relErr(kdl.nu_kdl, dense.nu));

    // KDL's constraint_torques: with W = A ν (our sign) at the tip and J the
    // tip Jacobian, entry j is the joint-j torque when the distal joints
    // f = j+1..n are free and unactuated:  J_jᵀW − H_jf H_ff⁻¹ J_fᵀ W.
    // Only the last entry is the physical torque (J ᵀ W)_n.
    const Eigen::VectorXd physical = dense.tau_c;
    worst_last = std::max(worst_last, std::abs(kdl.constraint_torques_kdl(n - 1) - physical(n - 1)) /
                                          std::max(1.0, physical.norm()));
    Eigen::VectorXd articulated(n);
    for (int j = 0; j < n; ++j) {
      const int f = n - 1 - j;
      articulated(j) = physical(j);
      if (f > 0)
        articulated(j) -=
            dense.H.row(j).segment(j + 1, f).dot(dense.H.block(j + 1, j + 1, f, f).ldlt().solve(physical.tail(f)));
    }
    worst_articulated = std::max(worst_articulated, relErr(kdl.constraint_torques_kdl, articulated));

    // Closure (docs/solver.md, "Constraint torques: why not eq. 4.4"): the
    // unconstrained arm driven by τ + τ_c replays q̈;
    // driven by τ + KDL's constraint_torques it does not (except in special
    // draws where the tip wrench loads no distal joint, J_fᵀ W = 0).
    DynamicsInput free = in;
    free.constraints.clear();
    free.tau = in.tau + kdl.tau_c;
    worst_replay = std::max(worst_replay, relErr(kdlHybridDynamics(spec, free).qdd, kdl.qdd));
    free.tau = in.tau + kdl.constraint_torques_kdl;
    if (relErr(kdlHybridDynamics(spec, free).qdd, kdl.qdd) > 1e-6) ++kdl_replay_fails;
  }
  INFO("compared " << compared << "; ν = −ν_KDL to " << worst_sign << " (with +: " << best_wrong_sign
                   << "); last constraint torque " << worst_last << "; articulated formula " << worst_articulated
                   << "; replay with τ_c " << worst_replay << "; KDL's constraint_torques fail to replay in "
                   << kdl_replay_fails << " draws");
  CHECK(compared >= 60);
  CHECK(worst_sign < 1e-9);
  CHECK(best_wrong_sign > 1e-3);
  CHECK(worst_last < 1e-10);
  CHECK(worst_articulated < 1e-9);
  CHECK(worst_replay < 1e-9);
  CHECK(kdl_replay_fails >= compared * 9 / 10);
}

TEST_CASE("KDL Vereshchagin and fixed segments", "[references][kdl]") {
  std::mt19937_64 rng(23);
  RandomChainOptions options = noFixed();
  options.min_moving_joints = 3;
  options.max_moving_joints = 3;
  ChainSpec spec = randomChain(rng, options);
  JointSpec fixed;
  fixed.name = "fixed_joint";
  fixed.type = "fixed";
  fixed.xyz = Eigen::Vector3d(0.1, 0.2, 0.3);
  fixed.rpy = Eigen::Vector3d(0.3, 0.2, 0.1);
  LinkSpec extra = spec.links[1];
  extra.name = "fixed_link";
  spec.joints.insert(spec.joints.begin() + 2, fixed);
  spec.links.insert(spec.links.begin() + 3, extra);
  DynamicsInput in = randomInput(rng, spec);

  // The bridge refuses such chains…
  CHECK_THROWS_AS(kdlHybridDynamics(spec, in), std::invalid_argument);

  // …because KDL cannot do them: a fixed segment between moving ones has
  // D = Sᵀ P S = 0 and the sweeps divide by it. (A fixed segment first or
  // last indexes the joint arrays out of range: Debian's KDL aborts on an
  // Eigen assertion, so those cases are not run here.)
  const KDL::Chain chain = toKdlChain(spec);
  KDL::ChainHdSolver_Vereshchagin solver(chain, KDL::Twist(KDL::Vector(0, 0, kGravity), KDL::Vector::Zero()), 0);
  const unsigned int n = static_cast<unsigned int>(spec.dof());
  KDL::JntArray q(n), qd(n), qdd(n), tau(n), ct(n), beta(0);
  q.data = in.q;
  qd.data = in.qd;
  tau.data = in.tau;
  KDL::Jacobian alpha(0);
  KDL::Wrenches f_ext(chain.getNrOfSegments(), KDL::Wrench::Zero());
  solver.CartToJnt(q, qd, qdd, alpha, beta, f_ext, tau, ct);
  CHECK(!qdd.data.allFinite());

  // Merging the fixed joint gives an equivalent chain that KDL does solve.
  const ChainSpec merged = mergeFixedJoints(spec);
  CHECK(merged.dof() == spec.dof());
  CHECK(!hasFixedJoints(merged));
  in.wrenches.clear();  // wrenches on the merged-away link have no counterpart
  const DenseResult dense = denseDynamics(spec, in);
  CHECK(relErr(kdlHybridDynamics(merged, in).qdd, dense.qdd) < 1e-9);
}

TEST_CASE("mergeFixedJoints keeps the dynamics (dense and KDL)", "[references][kdl]") {
  std::mt19937_64 rng(29);
  int compared = 0;
  double worst_dense = 0.0, worst_kdl = 0.0;
  for (int trial = 0; trial < 100; ++trial) {
    RandomChainOptions options;
    options.fixed_joint_probability = 0.5;
    ChainSpec spec = randomChain(rng, options);
    while (spec.joints.back().isFixed()) {  // the tip must survive the merge
      spec.joints.pop_back();
      spec.links.pop_back();
    }
    const ChainSpec merged = mergeFixedJoints(spec);
    REQUIRE(merged.dof() == spec.dof());
    DynamicsInput in = randomInput(rng, spec);
    in.wrenches.clear();
    for (const LinkSpec& link : merged.links)  // wrenches on surviving links only
      if (uniform01(rng) < 0.3)
        in.wrenches.push_back(
            {link.name, Vector6d(randomVector(rng, 6, 5.0)), uniform01(rng) < 0.5 ? Axes::Local : Axes::World});
    const int m = uniformInt(rng, 0, std::min(6, spec.dof()));
    if (m > 0) in.constraints.push_back(randomConstraint(rng, spec.links.back().name, m));
    const DenseResult a = denseDynamics(spec, in);
    if (!a.wellConditioned() || a.constraint_rank < m) continue;
    ++compared;
    const DenseResult b = denseDynamics(merged, in);
    worst_dense = std::max({worst_dense, relErr(b.qdd, a.qdd), relErr(b.H, a.H), m > 0 ? relErr(b.nu, a.nu) : 0.0});
    const KdlHybridResult k = kdlHybridDynamics(merged, in);
    worst_kdl = std::max({worst_kdl, relErr(k.qdd, a.qdd), m > 0 ? relErr(k.nu, a.nu) : 0.0});
  }
  INFO("compared " << compared << "; merged dense " << worst_dense << ", KDL on merged " << worst_kdl);
  CHECK(compared >= 50);
  CHECK(worst_dense < 1e-9);
  CHECK(worst_kdl < 1e-9);
}
