// The MJCF loader (zwang/mjcf.hpp, issue #30) against independent references:
//  * MuJoCo itself: random MJCF trees written here (hinge, slide, ball and free joints; joint anchors off the body
//    origin, joint references, several joints in one body, welded bodies, a free base or free bodies on a fixed
//    world) are loaded by loadMjcfString and compiled by MuJoCo; zwang's forward dynamics (solveHybridDynamics, no
//    friction) must give mj_forward's qacc and its inverse dynamics (RNEA) mj_inverse's qfrc_inverse, to 1e-9;
//  * the URDF loader: the same random tree written as URDF (support/urdf_writer) and as MJCF (support/mjcf_writer
//    with the joints' data) must load into the same model (placements, axes, inertias, limits, friction, rotor
//    inertia) and give the same solutions, plain and with friction;
//  * the Menagerie models in models/mjcf (MuJoCo 2.2.2 compiles all five): each loads, with MuJoCo's DOF count
//    and total mass and the warnings that name what is not mapped;
//  * bad inputs: every refusal names the source and the reason, and MuJoCo's message when MuJoCo refuses.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <mujoco/mujoco.h>
#include <urdf_parser/urdf_parser.h>
#include <Eigen/Geometry>
#include <catch2/catch.hpp>

#include "support/mjcf_writer.hpp"
#include "support/mujoco_bridge.hpp"
#include "support/random_chain.hpp"
#include "support/random_problem.hpp"
#include "support/urdf_writer.hpp"
#include "zwang/mjcf.hpp"
#include "zwang/zwang.hpp"

using namespace zwang;
using namespace zwang::testing;

namespace {

// Both sides are exact recursive algorithms in double precision on up to ~40 DOFs; their round-off, amplified by
// the inertia matrix's condition (light bodies next to armatures), stays far below this bound of the issue.
constexpr double kMujocoTolerance = 1e-9;
// The same robot through two loaders: the same arithmetic but for the rotations (URDF rpy, MJCF quaternions, read
// back from %.17g) and the inertias (URDF's tensor, MJCF's principal axes): a few ulps in the data, which the
// solutions carry times the balance's condition (compareSolutions).
constexpr double kLoaderTolerance = 1e-12;

std::string num(double x) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", x);
  return buffer;
}
std::string vec(const Eigen::Vector3d& v) { return num(v.x()) + " " + num(v.y()) + " " + num(v.z()); }
std::string quat(const Eigen::Quaterniond& q) {
  return num(q.w()) + " " + num(q.x()) + " " + num(q.y()) + " " + num(q.z());
}
Eigen::Quaterniond randomQuat(std::mt19937_64& rng) {
  for (;;) {
    const Eigen::Quaterniond q(gaussian(rng), gaussian(rng), gaussian(rng), gaussian(rng));
    if (q.norm() > 1e-6) return q.normalized();
  }
}

// ---------------------------------------------------------------------------
// Random MJCF trees, written here (the mapping under test is the loader's, so this writer mirrors MuJoCo's XML
// reference and nothing of zwang's).

struct RandomJoint {
  std::string name;
  int type = mjJNT_HINGE;
};

struct RandomMjcf {
  std::string xml;
  std::vector<RandomJoint> joints;  // in MuJoCo's order (the XML's)
  bool free_base = false;
  Eigen::Vector3d gravity;
};

struct TreeWriter {
  std::mt19937_64& rng;
  std::ostringstream out;
  RandomMjcf result;
  int bodies = 0, joints = 0, max_bodies = 0;

  void joint(const std::string& indent, int type) {
    const std::string name = "j" + std::to_string(joints++);
    result.joints.push_back({name, type});
    if (type == mjJNT_FREE) {  // no armature: MuJoCo's acts on world-axes ṗ, zwang's on child-frame v (mjcf.hpp)
      out << indent << "<joint name=\"" << name << "\" type=\"free\"/>\n";
      return;
    }
    const char* kind = type == mjJNT_HINGE ? "hinge" : type == mjJNT_SLIDE ? "slide" : "ball";
    out << indent << "<joint name=\"" << name << "\" type=\"" << kind << "\"";
    if (uniform01(rng) < 0.6) out << " pos=\"" << vec(randomVector(rng, 3, 0.2)) << "\"";  // an anchor off the origin
    if (type != mjJNT_BALL) out << " axis=\"" << vec(randomUnitVector(rng)) << "\"";
    if (type != mjJNT_BALL && uniform01(rng) < 0.5) out << " ref=\"" << num(uniform(rng, -1.0, 1.0)) << "\"";
    out << " armature=\"" << num(uniform01(rng) < 0.5 ? uniform(rng, 0.0, 0.3) : 0.0) << "\"/>\n";
  }

  void inertial(const std::string& indent) {
    const double mass = uniform(rng, 0.2, 5.0);
    // Principal moments from second moments s: I1 = s_y + s_z etc., so the triangle inequality holds strictly.
    const Eigen::Vector3d s =
        mass * Eigen::Vector3d(uniform(rng, 0.002, 0.05), uniform(rng, 0.002, 0.05), uniform(rng, 0.002, 0.05));
    const Eigen::Vector3d moments(s.y() + s.z(), s.x() + s.z(), s.x() + s.y());
    out << indent << "<inertial pos=\"" << vec(randomVector(rng, 3, 0.1)) << "\" quat=\"" << quat(randomQuat(rng))
        << "\" mass=\"" << num(mass) << "\" diaginertia=\"" << vec(moments) << "\"/>\n";
  }

  // A body and its subtree; `free_joint`: a free joint (a free base or a free body on the world); `fill`: children
  // until the tree has max_bodies (a free base, so that the world has one child).
  void body(const std::string& indent, bool top, bool free_joint, bool fill = false) {
    const std::string name = "b" + std::to_string(bodies++);
    out << indent << "<body name=\"" << name << "\"";
    if (!free_joint)
      out << " pos=\"" << vec(randomVector(rng, 3, 0.5)) << "\" quat=\"" << quat(randomQuat(rng)) << "\"";
    out << ">\n";
    const std::string inner = indent + "  ";
    if (free_joint) {
      joint(inner, mjJNT_FREE);
    } else {
      const double welded = top ? 0.0 : 0.12;
      const int count = uniform01(rng) < welded ? 0 : uniformInt(rng, 1, uniform01(rng) < 0.6 ? 1 : 3);
      // MuJoCo refuses a ball joint followed by another rotation in the same body: a ball is a body's last joint,
      // and the joints before it slides (a hinge next to a ball would give the body four rotations: singular).
      const bool ball = uniform01(rng) < 0.25;
      for (int k = 0; k < count; ++k) {
        const bool slide = ball || uniform01(rng) < 1.0 / 3.0;
        joint(inner, ball && k + 1 == count ? mjJNT_BALL : slide ? mjJNT_SLIDE : mjJNT_HINGE);
      }
    }
    inertial(inner);
    if (uniform01(rng) < 0.3)
      out << inner << "<site name=\"s" << name << "\" pos=\"" << vec(randomVector(rng, 3, 0.2)) << "\"/>\n";
    const int children = bodies < max_bodies ? uniformInt(rng, 0, 2) : 0;
    for (int c = 0; c < children && bodies < max_bodies; ++c) body(inner, false, false);
    while (fill && bodies < max_bodies) body(inner, false, false);
    out << indent << "</body>\n";
  }
};

RandomMjcf randomMjcf(std::mt19937_64& rng) {
  TreeWriter w{rng, {}, {}, 0, 0, uniformInt(rng, 1, 14)};
  const double g = uniform01(rng);
  w.result.gravity = g < 0.1   ? Eigen::Vector3d::Zero()
                     : g < 0.5 ? Eigen::Vector3d(0.0, 0.0, -9.81)
                               : Eigen::Vector3d(9.81 * randomUnitVector(rng));
  w.out << "<mujoco model=\"random_tree\">\n"
        << "  <compiler angle=\"radian\" inertiafromgeom=\"false\" balanceinertia=\"false\" boundmass=\"0\" "
           "boundinertia=\"0\"/>\n"
        << "  <option gravity=\"" << vec(w.result.gravity) << "\">\n"
        << "    <flag contact=\"disable\" constraint=\"disable\" passive=\"disable\"/>\n"
        << "  </option>\n  <worldbody>\n";
  if (uniform01(rng) < 0.3) {
    w.body("    ", true, true, true);  // a free base: the world's only child
    w.result.free_base = true;
  } else {
    const int tops = uniformInt(rng, 1, 3);
    int written = 0;
    bool first_free = false;
    for (int t = 0; t < tops && (t == 0 || w.bodies < w.max_bodies); ++t, ++written) {
      const bool free = uniform01(rng) < 0.25;
      first_free = t == 0 ? free : first_free;
      w.body("    ", true, free);
    }
    w.result.free_base = written == 1 && first_free;  // the loader's rule: the world's only child, on a free joint
  }
  w.out << "  </worldbody>\n</mujoco>\n";
  w.result.xml = w.out.str();
  return std::move(w.result);
}

// zwang's coordinates at MuJoCo's addresses: per entry of q its qpos address, per entry of v its dof address; and
// per free joint (the base's or a body's on the world) its first v entry and q entry (for T, mujoco_bridge.hpp).
struct Addresses {
  std::vector<int> qpos, dof;
  std::vector<std::pair<int, int>> free;  // (v index, q index)
};

Addresses addresses(const Model& model, const mjModel* m, const RandomMjcf& r) {
  Addresses a;
  for (std::size_t j = 0; j < model.allJoints().size(); ++j) {
    const Joint& joint = model.allJoints()[j];
    // The floating base's root joint is MuJoCo's first joint (the base body's free joint).
    const std::string name = model.hasFloatingBase() && j == 0 ? r.joints.front().name : joint.name;
    const int id = mj_name2id(m, mjOBJ_JOINT, name.c_str());
    REQUIRE(id >= 0);
    for (int k = 0; k < joint.nq(); ++k) a.qpos.push_back(m->jnt_qposadr[id] + k);
    for (int k = 0; k < joint.nv(); ++k) a.dof.push_back(m->jnt_dofadr[id] + k);
    if (joint.type == JointType::Free) a.free.emplace_back(joint.v_index, joint.q_index);
  }
  return a;
}

// u = T v, u̇ = T v̇ + Ṫ v: R = ⁰R_body on each free joint's linear entries (its body hangs from the world).
Eigen::MatrixXd velocityMap(const Addresses& a, const Eigen::VectorXd& q, Eigen::Index nv) {
  Eigen::MatrixXd T = Eigen::MatrixXd::Identity(nv, nv);
  for (const auto& [v, qi] : a.free)
    T.block<3, 3>(v, v) = Eigen::Quaterniond(q(qi + 3), q(qi + 4), q(qi + 5), q(qi + 6)).toRotationMatrix();
  return T;
}
Eigen::VectorXd velocityMapRate(const Addresses& a, const Eigen::MatrixXd& T, const Eigen::VectorXd& v) {
  Eigen::VectorXd rate = Eigen::VectorXd::Zero(v.size());
  for (const auto& [i, qi] : a.free) {
    (void)qi;
    rate.segment<3>(i) =
        T.block<3, 3>(i, i) * Eigen::Vector3d(v.segment<3>(i + 3)).cross(Eigen::Vector3d(v.segment<3>(i)));
  }
  return rate;
}

double scaledError(const Eigen::VectorXd& x, const Eigen::VectorXd& reference) {
  return (x - reference).lpNorm<Eigen::Infinity>() / std::max(1.0, reference.lpNorm<Eigen::Infinity>());
}

// A random state in zwang's coordinates: unit quaternions for ball and free joints.
Eigen::VectorXd randomConfigurationOf(std::mt19937_64& rng, const Model& model) {
  Eigen::VectorXd q(model.nq());
  for (const Joint& joint : model.allJoints()) {
    if (joint.type == JointType::Free) {
      q.segment<3>(joint.q_index) = randomVector(rng, 3, 2.0);
      const Eigen::Quaterniond r = randomQuat(rng);
      q.segment<4>(joint.q_index + 3) << r.w(), r.x(), r.y(), r.z();
    } else if (joint.type == JointType::Spherical) {
      const Eigen::Quaterniond r = randomQuat(rng);
      q.segment<4>(joint.q_index) << r.w(), r.x(), r.y(), r.z();
    } else {
      q(joint.q_index) = joint.type == JointType::Prismatic ? uniform(rng, -0.5, 0.5) : uniform(rng, -3.0, 3.0);
    }
  }
  return q;
}

}  // namespace

TEST_CASE("MJCF: forward and inverse dynamics of loaded random trees agree with MuJoCo", "[mjcf]") {
  std::mt19937_64 rng(stressSeedOr(30001));
  int trees = 0, free_bases = 0, free_bodies = 0, anchors_or_refs = 0, multi = 0, balls = 0;
  double worst_forward = 0.0, worst_inverse = 0.0;
  for (int draw = 0; draw < 200; ++draw) {
    const RandomMjcf r = randomMjcf(rng);
    INFO("draw " << draw << "\n" << r.xml);
    const MjcfModel loaded = readMjcfString(r.xml);
    const Model& model = loaded.model;
    const Mujoco mj(r.xml);
    const mjModel* m = mj.m();
    mjData* d = mj.d();
    REQUIRE(model.nq() == m->nq);
    REQUIRE(model.nv() == m->nv);
    REQUIRE(model.hasFloatingBase() == r.free_base);
    CHECK((loaded.gravity - r.gravity).norm() == 0.0);
    const Addresses a = addresses(model, m, r);

    const Eigen::VectorXd q = randomConfigurationOf(rng, model);
    const Eigen::VectorXd v = randomVector(rng, model.nv(), 2.0), tau = randomVector(rng, model.nv(), 5.0);
    const Eigen::MatrixXd T = velocityMap(a, q, model.nv());
    const Eigen::VectorXd Tdot_v = velocityMapRate(a, T, v);
    scatter(q, a.qpos, d->qpos);
    scatter(T * v, a.dof, d->qvel);
    scatter(T.transpose().inverse() * tau, a.dof, d->qfrc_applied);  // the same power: f = T⁻ᵀ τ
    mj_forward(m, d);
    const Eigen::VectorXd qdd_mujoco = T.inverse() * (gather(d->qacc, a.dof) - Tdot_v);

    Task task(model);
    task.gravity = loaded.gravity;
    Workspace ws(model, task);
    const Status solved = solveHybridDynamics(model, ws, q, v, tau, task);
    INFO(solved.message);
    REQUIRE(solved);
    const double forward = scaledError(ws.solution.qdd, qdd_mujoco);
    CHECK(forward < kMujocoTolerance);

    const Eigen::VectorXd qdd = randomVector(rng, model.nv(), 5.0);
    scatter(T * qdd + Tdot_v, a.dof, d->qacc);
    mj_inverse(m, d);
    const Eigen::VectorXd tau_mujoco = T.transpose() * gather(d->qfrc_inverse, a.dof);
    REQUIRE(inverseDynamics(model, ws, q, v, qdd, task));
    const double inverse = scaledError(ws.tau, tau_mujoco);
    CHECK(inverse < kMujocoTolerance);

    worst_forward = std::max(worst_forward, forward);
    worst_inverse = std::max(worst_inverse, inverse);
    ++trees;
    free_bases += r.free_base ? 1 : 0;
    for (int j = 0; j < m->njnt; ++j) {
      free_bodies += m->jnt_type[j] == mjJNT_FREE && !r.free_base ? 1 : 0;
      balls += m->jnt_type[j] == mjJNT_BALL ? 1 : 0;
      anchors_or_refs +=
          m->jnt_type[j] != mjJNT_FREE && (Eigen::Map<const Eigen::Vector3d>(m->jnt_pos + 3 * j).norm() > 0.0 ||
                                           m->qpos0[m->jnt_qposadr[j]] != 0.0)
              ? 1
              : 0;
    }
    for (int b = 1; b < m->nbody; ++b) multi += m->body_jntnum[b] > 1 ? 1 : 0;
  }
  std::printf(
      "MJCF vs MuJoCo: %d trees (%d free bases, %d free bodies, %d ball joints, %d joints off the origin "
      "or with a ref, %d bodies with several joints); worst q̈ %.2e, worst τ %.2e\n",
      trees, free_bases, free_bodies, balls, anchors_or_refs, multi, worst_forward, worst_inverse);
  CHECK(free_bases > 20);
  CHECK(free_bodies >= 10);
  CHECK(multi > 50);
}

namespace {

// Joint j of `other` that has the name of `joint`.
const Joint& sameJoint(const Model& other, const Joint& joint) { return other.joint(other.jointIndex(joint.name)); }

// Body b of `from` in `to` (one-DOF joints: the body of the joint of the same name; 0 stays 0).
int sameBody(const Model& from, const Model& to, int b) {
  if (b == 0) return 0;
  return sameJoint(to, from.joint(from.dofs()[static_cast<std::size_t>(b - 1)].joint)).body();
}

double relative(double x, double y) { return std::abs(x - y) / std::max(1.0, std::abs(y)); }

void checkSameModel(const Model& urdf, const Model& mjcf) {
  REQUIRE(urdf.nv() == mjcf.nv());
  REQUIRE(urdf.joints().size() == mjcf.joints().size());
  for (const Joint& ju : urdf.joints()) {
    INFO("joint " << ju.name);
    const Joint& jm = sameJoint(mjcf, ju);
    CHECK(ju.type == jm.type);
    CHECK((ju.axis - jm.axis).norm() < kLoaderTolerance);
    CHECK((ju.placement.E - jm.placement.E).norm() < kLoaderTolerance);
    CHECK((ju.placement.r - jm.placement.r).norm() < kLoaderTolerance);
    CHECK((ju.lower == jm.lower || relative(ju.lower, jm.lower) < kLoaderTolerance));
    CHECK((ju.upper == jm.upper || relative(ju.upper, jm.upper) < kLoaderTolerance));
    CHECK(relative(ju.breakaway_friction, jm.breakaway_friction) < kLoaderTolerance);
    CHECK(relative(ju.kinetic_friction, jm.kinetic_friction) < kLoaderTolerance);
    CHECK(relative(ju.viscous_friction, jm.viscous_friction) < kLoaderTolerance);
    CHECK(relative(ju.rotor_inertia, jm.rotor_inertia) < kLoaderTolerance);
    const RigidInertia& Iu = urdf.inertia(ju.body());
    const RigidInertia& Im = mjcf.inertia(jm.body());
    CHECK(relative(Iu.mass, Im.mass) < kLoaderTolerance);
    CHECK((Iu.h - Im.h).norm() < kLoaderTolerance);
    CHECK((Iu.Ibar - Im.Ibar).norm() < kLoaderTolerance * std::max(1.0, Iu.Ibar.norm()));
    CHECK(urdf.parentBodyOfJoint(urdf.jointIndex(ju.name)) ==
          sameBody(mjcf, urdf, mjcf.parentBodyOfJoint(mjcf.jointIndex(jm.name))));
  }
  for (const Frame& fu : urdf.frames()) {  // every URDF link is an MJCF body of its name
    INFO("frame " << fu.name);
    REQUIRE(mjcf.hasFrame(fu.name));
    const Frame& fm = mjcf.frame(mjcf.frameIndex(fu.name));
    CHECK(sameBody(urdf, mjcf, fu.body) == fm.body);
    CHECK((fu.placement.E - fm.placement.E).norm() < kLoaderTolerance);
    CHECK((fu.placement.r - fm.placement.r).norm() < kLoaderTolerance);
  }
}

// x (in `from`'s joint order) in `to`'s order, joint by name (one-DOF joints).
Eigen::VectorXd reorder(const Model& from, const Model& to, const Eigen::VectorXd& x) {
  Eigen::VectorXd y(x.size());
  for (const Joint& j : from.joints()) y(sameJoint(to, j).v_index) = x(j.v_index);
  return y;
}

struct Solved {
  Eigen::VectorXd qdd, qdd_friction;
  double condition = 1.0;  // the plain solve's balance (BalanceReport::condition)
};

// A plain solve with one random constraint and a friction solve of the same task.
Solved solveBoth(const Model& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd, const Eigen::VectorXd& tau,
                 const Eigen::Vector3d& gravity, const std::string& frame, const ConstraintMatrix& A,
                 const Eigen::VectorXd& b) {
  Task task(model);
  task.gravity = gravity;
  task.addConstraint(frame, A);
  task.targets() = b;
  Workspace ws(model, task);
  Solved s;
  const Status plain = solveHybridDynamics(model, ws, q, qd, tau, task);
  INFO(plain.message);
  REQUIRE(plain);
  s.qdd = ws.solution.qdd;
  s.condition = ws.solution.balance.condition;
  const Status friction = solveWithFriction(model, ws, q, qd, tau, task);
  INFO(friction.message);
  REQUIRE(friction);
  s.qdd_friction = ws.solution.qdd;
  return s;
}

}  // namespace

namespace {

// A plain problem on `urdf` (one random constraint on `frame`, half the joints at rest) solved on both models; the
// worst scaled difference of q̈, plain and with friction.
std::pair<double, double> compareSolutions(std::mt19937_64& rng, const Model& urdf, const Model& mjcf,
                                           const std::string& frame, const Eigen::Vector3d& gravity) {
  Eigen::VectorXd q(urdf.nq()), qd = randomVector(rng, urdf.nv(), 1.0);
  for (const Joint& j : urdf.joints()) {
    const double lo = std::max(j.lower, -3.0), hi = std::min(j.upper, 3.0);
    q(j.q_index) = uniform(rng, lo, hi);
    if (uniform01(rng) < 0.5) qd(j.v_index) = 0.0;  // at rest: static friction decides
  }
  const Eigen::VectorXd tau = randomVector(rng, urdf.nv(), 5.0);
  const int rows = uniformInt(rng, 1, 3);
  ConstraintMatrix A(6, rows);
  for (int c = 0; c < rows; ++c) A.col(c) = randomVector(rng, 6, 1.0).normalized();
  const Eigen::VectorXd b = randomVector(rng, rows, 2.0);
  const Solved su = solveBoth(urdf, q, qd, tau, gravity, frame, A, b);
  const Solved sm =
      solveBoth(mjcf, reorder(urdf, mjcf, q), reorder(urdf, mjcf, qd), reorder(urdf, mjcf, tau), gravity, frame, A, b);
  // The two models' data differ by a few ulps; the balance amplifies such differences by up to its condition
  // number (a task near singular), so the errors are compared per unit of it (a singular balance, infinite
  // condition, projects instead: compared as they are).
  const double per = std::isfinite(su.condition) ? std::max(1.0, su.condition) : 1.0;
  return {scaledError(reorder(mjcf, urdf, sm.qdd), su.qdd) / per,
          scaledError(reorder(mjcf, urdf, sm.qdd_friction), su.qdd_friction) / per};
}

// A URDF chain read by urdfdom alone (not zwang's loader) into a ChainSpec, for mjcf_writer.
LinkSpec linkSpec(const urdf::Link& link) {
  LinkSpec spec;
  spec.name = link.name;
  if (!link.inertial) return spec;
  const urdf::Inertial& in = *link.inertial;
  spec.mass = in.mass;
  spec.com = Eigen::Vector3d(in.origin.position.x, in.origin.position.y, in.origin.position.z);
  in.origin.rotation.getRPY(spec.inertial_rpy.x(), spec.inertial_rpy.y(), spec.inertial_rpy.z());
  spec.inertia << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
  return spec;
}

ChainSpec chainFromUrdf(const std::string& path) {
  const urdf::ModelInterfaceSharedPtr model = urdf::parseURDFFile(path);
  REQUIRE(model);
  ChainSpec spec;
  spec.name = model->getName();
  urdf::LinkConstSharedPtr link = model->getRoot();
  spec.links.push_back(linkSpec(*link));
  while (!link->child_joints.empty()) {
    REQUIRE(link->child_joints.size() == 1);  // a chain
    const urdf::Joint& uj = *link->child_joints[0];
    JointSpec j;
    j.name = uj.name;
    j.type = uj.type == urdf::Joint::REVOLUTE     ? "revolute"
             : uj.type == urdf::Joint::CONTINUOUS ? "continuous"
             : uj.type == urdf::Joint::PRISMATIC  ? "prismatic"
                                                  : "fixed";
    const urdf::Pose& o = uj.parent_to_joint_origin_transform;
    j.xyz = Eigen::Vector3d(o.position.x, o.position.y, o.position.z);
    o.rotation.getRPY(j.rpy.x(), j.rpy.y(), j.rpy.z());
    j.axis = Eigen::Vector3d(uj.axis.x, uj.axis.y, uj.axis.z);
    if (uj.limits) {
      j.lower = uj.limits->lower;
      j.upper = uj.limits->upper;
    }
    if (uj.dynamics) {
      j.friction = uj.dynamics->friction;
      j.damping = uj.dynamics->damping;
    }
    spec.joints.push_back(j);
    link = model->getLink(uj.child_link_name);
    spec.links.push_back(linkSpec(*link));
  }
  return spec;
}

}  // namespace

TEST_CASE("MJCF: the Panda as URDF and as MJCF loads into the same model and the same solutions", "[mjcf]") {
  // models/panda.urdf read by urdfdom and written as MJCF with its limits, friction and damping.
  const std::string path = std::string(ZWANG_MODELS_DIR) + "/panda.urdf";
  const Eigen::Vector3d gravity(0.0, 0.0, -9.81);
  const std::string mjcf_text =
      toMjcf(chainFromUrdf(path), gravity, FloatingBase{BaseKind::Fixed, Eigen::Isometry3d::Identity()}, {true});
  const Model urdf = loadUrdfFile(path);
  const Model mjcf = loadMjcfString(mjcf_text);
  REQUIRE(urdf.joints().size() == 7);
  CHECK(urdf.joint(3).breakaway_friction > 0.0);  // the data compared is there
  checkSameModel(urdf, mjcf);
  std::mt19937_64 rng(stressSeedOr(30004));
  double worst_plain = 0.0, worst_friction = 0.0;
  for (int draw = 0; draw < 50; ++draw) {
    const auto [plain, friction] = compareSolutions(rng, urdf, mjcf, draw % 2 ? "tool0" : "panda_link4", gravity);
    CHECK(plain < kLoaderTolerance);
    CHECK(friction < kLoaderTolerance);
    worst_plain = std::max(worst_plain, plain);
    worst_friction = std::max(worst_friction, friction);
  }
  std::printf("Panda, MJCF vs URDF: 50 problems; worst q̈ per unit of condition %.2e plain, %.2e with friction\n",
              worst_plain, worst_friction);
}

TEST_CASE("MJCF: a random tree as URDF and as MJCF loads into the same model and the same solutions", "[mjcf]") {
  std::mt19937_64 rng(stressSeedOr(30002));
  double worst_plain = 0.0, worst_friction = 0.0;
  int joints = 0;
  for (int draw = 0; draw < 100; ++draw) {
    RandomTreeOptions options;
    options.min_moving_joints = 1;
    options.max_moving_joints = 20;
    const ChainSpec spec = randomTree(rng, options);
    const Eigen::Vector3d gravity(0.0, 0.0, -9.81);
    const std::string mjcf_text =
        toMjcf(spec, gravity, FloatingBase{BaseKind::Fixed, Eigen::Isometry3d::Identity()}, MjcfWriteOptions{true});
    INFO("draw " << draw << "\n" << mjcf_text);
    const Model urdf = loadUrdfString(toUrdf(spec));
    const MjcfModel mjcf = readMjcfString(mjcf_text);
    CHECK(mjcf.gravity == gravity);
    checkSameModel(urdf, mjcf.model);
    joints += static_cast<int>(urdf.joints().size());

    const std::string frame =
        spec.links[static_cast<std::size_t>(uniformInt(rng, 1, static_cast<int>(spec.links.size()) - 1))].name;
    const auto [plain, friction] = compareSolutions(rng, urdf, mjcf.model, frame, gravity);
    CHECK(plain < kLoaderTolerance);
    CHECK(friction < kLoaderTolerance);
    worst_plain = std::max(worst_plain, plain);
    worst_friction = std::max(worst_friction, friction);
  }
  std::printf(
      "MJCF vs URDF: 100 random trees, %d joints; worst q̈ per unit of condition %.2e plain, %.2e with "
      "friction\n",
      joints, worst_plain, worst_friction);
}

namespace {

const std::string kMenagerie = std::string(ZWANG_MODELS_DIR) + "/mjcf/";

bool hasWarning(const Model& model, WarningCode code, const std::string& text) {
  return std::any_of(model.warnings().begin(), model.warnings().end(), [&](const ModelWarning& w) {
    return w.code == code && w.message.find(text) != std::string::npos;
  });
}

double totalMass(const Model& model) {
  double mass = 0.0;
  for (int b = 0; b < model.bodyCount(); ++b) mass += model.inertia(b).mass;
  return mass;
}

// zwang's coordinates at MuJoCo's addresses, joints by name (a floating base's root joint: the base body's free joint).
Addresses addressesByName(const Model& model, const mjModel* m) {
  Addresses a;
  for (std::size_t j = 0; j < model.allJoints().size(); ++j) {
    const Joint& joint = model.allJoints()[j];
    int id = mj_name2id(m, mjOBJ_JOINT, joint.name.c_str());
    if (model.hasFloatingBase() && j == 0) {
      const std::string base = model.frame(model.bodyFrame(model.baseBody())).name;
      id = m->body_jntadr[mj_name2id(m, mjOBJ_BODY, base.c_str())];
    }
    REQUIRE(id >= 0);
    for (int k = 0; k < joint.nq(); ++k) a.qpos.push_back(m->jnt_qposadr[id] + k);
    for (int k = 0; k < joint.nv(); ++k) a.dof.push_back(m->jnt_dofadr[id] + k);
    if (joint.type == JointType::Free) a.free.emplace_back(joint.v_index, joint.q_index);
  }
  return a;
}

}  // namespace

TEST_CASE("MJCF: the five Menagerie models load, with MuJoCo's DOFs, mass and forward dynamics", "[mjcf]") {
  struct Case {
    const char* file;
    int nv;
    double mass;  // models/mjcf/README.md: the sum of the <inertial> masses, to its six decimals
    bool floating;
    const char* unmapped;  // a word of an Unmapped warning the model must have
  };
  const Case cases[] = {
      {"franka_emika_panda__panda.xml", 9, 17.451901, false, "tendons 'split'"},
      {"anybotics_anymal_c__anymal_c.xml", 18, 44.965180, true, "actuators"},
      {"unitree_g1__g1.xml", 43, 32.238921, true, "actuators"},
      {"shadow_hand__right_hand.xml", 24, 3.794000, false, "tendons"},
      {"agility_cassie__cassie.xml", 32, 33.312000, true, "equality constraints"},
  };
  std::mt19937_64 rng(stressSeedOr(30003));
  for (const Case& c : cases) {
    INFO(c.file);
    const MjcfModel loaded = readMjcfFile(kMenagerie + c.file);
    const Model& model = loaded.model;
    CHECK(model.nv() == c.nv);
    CHECK(model.hasFloatingBase() == c.floating);
    CHECK(std::abs(totalMass(model) - c.mass) < 1e-6);  // the README's rounding
    CHECK(hasWarning(model, WarningCode::Unmapped, c.unmapped));
    CHECK_THROWS_WITH(loadMjcfFile(kMenagerie + c.file, MjcfOptions{true}),
                      Catch::Contains(c.file) && Catch::Contains("refused in strict mode"));

    // Forward dynamics without friction against MuJoCo's smooth dynamics: no constraints, no passive forces and no
    // actuation (a position actuator's bias pulls towards ctrl = 0 even without a control).
    mjModel* m = mj_loadXML((kMenagerie + c.file).c_str(), nullptr, nullptr, 0);
    REQUIRE(m != nullptr);
    m->opt.disableflags |= mjDSBL_CONSTRAINT | mjDSBL_CONTACT | mjDSBL_PASSIVE | mjDSBL_EQUALITY | mjDSBL_ACTUATION;
    mjData* d = mj_makeData(m);
    const Addresses a = addressesByName(model, m);
    Eigen::VectorXd q = randomConfigurationOf(rng, model);
    Eigen::VectorXd v = randomVector(rng, model.nv(), 1.0);
    model.followLeaders(q, v);  // the Panda's fingers: the mimic law MuJoCo's equality states
    const Eigen::VectorXd tau = randomVector(rng, model.nv(), 5.0);
    const Eigen::MatrixXd T = velocityMap(a, q, model.nv());
    scatter(q, a.qpos, d->qpos);
    scatter(T * v, a.dof, d->qvel);
    scatter(T.transpose().inverse() * tau, a.dof, d->qfrc_applied);
    mj_forward(m, d);
    const Eigen::VectorXd qdd_mujoco = T.inverse() * (gather(d->qacc, a.dof) - velocityMapRate(a, T, v));
    mj_deleteData(d);
    mj_deleteModel(m);
    if (!model.mimicJoints().empty()) continue;  // zwang holds the mimic law, MuJoCo's equality is disabled here
    Task task(model);
    task.gravity = loaded.gravity;
    Workspace ws(model, task);
    REQUIRE(solveHybridDynamics(model, ws, q, v, tau, task));
    CHECK(scaledError(ws.solution.qdd, qdd_mujoco) < kMujocoTolerance);
  }
}

TEST_CASE("MJCF: mapping details (mimic, limits, friction, sites, intermediate frames)", "[mjcf]") {
  const MjcfModel panda = readMjcfFile(kMenagerie + "franka_emika_panda__panda.xml");
  const Model& m = panda.model;
  REQUIRE(m.mimicJoints().size() == 1);  // <equality joint finger_joint1 finger_joint2 polycoef="0 1 0 0 0">
  const Joint& finger = m.joint(m.mimicJoints()[0]);
  CHECK(finger.name == "finger_joint1");  // joint1 = c0 + c1·joint2: joint1 follows
  CHECK(m.joint(finger.mimic.leader).name == "finger_joint2");
  CHECK(finger.mimic.multiplier == 1.0);
  CHECK(finger.mimic.offset == 0.0);
  const Joint& joint1 = m.joint(m.jointIndex("joint1"));
  CHECK(joint1.lower == -2.8973);
  CHECK(joint1.upper == 2.8973);
  CHECK(joint1.rotor_inertia == 0.1);
  CHECK(joint1.viscous_friction == 1.0);
  CHECK(joint1.breakaway_friction == 0.0);
  CHECK(panda.gravity == Vec3(0.0, 0.0, -9.81));
  const Model anymal = loadMjcfFile(kMenagerie + "anybotics_anymal_c__anymal_c.xml");
  const Joint& haa = anymal.joint(0);
  CHECK(haa.breakaway_friction == 0.1);
  CHECK(haa.kinetic_friction == 0.1);

  // Two hinges in one body, each off the body origin: an intermediate frame, and MuJoCo's pose of the body.
  const std::string xml = R"(<mujoco model="two_hinges"><compiler angle="radian"/><worldbody>
    <body name="link" pos="0.1 0.2 0.3" quat="0.9 0.1 0.3 0.2">
      <joint name="a" type="hinge" axis="0 0 1" pos="0.1 0 0" ref="0.3" range="-1 1" limited="true"/>
      <joint name="b" type="hinge" axis="1 0 0" pos="0 0.2 0"/>
      <inertial pos="0 0 0.1" mass="1" diaginertia="0.1 0.1 0.1"/>
      <site name="tip" pos="0 0 0.5"/>
    </body></worldbody></mujoco>)";
  const Model two = loadMjcfString(xml);
  CHECK(two.hasFrame("link:a"));
  CHECK(two.hasFrame("tip"));
  CHECK(two.joint(0).type == JointType::Revolute);
  CHECK(two.joint(0).lower == -1.0);  // q is qpos, ref or not: the range as written
  CHECK(two.joint(1).type == JointType::Continuous);
  const Mujoco mj(xml);
  Eigen::VectorXd q(2);
  q << 0.7, -0.4;
  scatter(q, {0, 1}, mj.d()->qpos);
  mj_kinematics(mj.m(), mj.d());
  Workspace ws(two);
  REQUIRE(forwardKinematics(two, ws, q));
  for (const char* name : {"link", "tip"}) {
    INFO(name);
    Eigen::Isometry3d pose;
    REQUIRE(framePose(two, ws, q, two.frameIndex(name), pose));
    const bool site = std::string(name) == "tip";
    const int id = mj_name2id(mj.m(), site ? mjOBJ_SITE : mjOBJ_BODY, name);
    const mjtNum* p = site ? mj.d()->site_xpos + 3 * id : mj.d()->xpos + 3 * id;
    const mjtNum* R = site ? mj.d()->site_xmat + 9 * id : mj.d()->xmat + 9 * id;
    CHECK((pose.translation() - Eigen::Vector3d(p[0], p[1], p[2])).norm() < 1e-14);  // a few roundings of 1 m
    CHECK((pose.linear() - Eigen::Matrix<double, 3, 3, Eigen::RowMajor>(R)).norm() < 1e-14);
  }
}

TEST_CASE("MJCF: a joint equality is a mimic joint that satisfies MuJoCo's equality", "[mjcf]") {
  // q_a − ref_a = c0 + c1 (q_c − ref_c) in MuJoCo's terms, with refs on both joints: zwang's law must put MuJoCo's
  // equality residual (efc_pos of its row) at zero wherever the leader is.
  const std::string xml = R"(<mujoco><compiler angle="radian"/><worldbody>
      <body name="B"><joint name="a" axis="0 0 1" ref="0.4"/><inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/></body>
      <body name="C"><joint name="c" type="slide" axis="1 0 0" ref="-0.3"/>
        <inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/></body></worldbody>
      <equality><joint joint1="a" joint2="c" polycoef="0.1 2 0 0 0"/></equality></mujoco>)";
  const Model model = loadMjcfString(xml);
  REQUIRE(model.mimicJoints().size() == 1);
  const Mujoco mj(xml);
  for (const double leader : {-1.0, 0.0, 0.7}) {
    Eigen::VectorXd q(2), v = Eigen::VectorXd::Zero(2);
    q << 0.0, leader;
    model.followLeaders(q, v);
    scatter(q, {0, 1}, mj.d()->qpos);
    mj_forward(mj.m(), mj.d());
    REQUIRE(mj.d()->nefc >= 1);
    int row = -1;
    for (int r = 0; r < mj.d()->nefc; ++r)
      if (mj.d()->efc_type[r] == mjCNSTR_EQUALITY) row = r;
    REQUIRE(row >= 0);
    CHECK(std::abs(mj.d()->efc_pos[row]) < 1e-15);  // a few roundings of numbers below 2
  }
}

TEST_CASE("MJCF: bad inputs are refused with the source and the reason", "[mjcf]") {
  CHECK_THROWS_WITH(loadMjcfFile("/no/such/file.xml"), Catch::StartsWith("/no/such/file.xml: cannot open the file"));
  CHECK_THROWS_WITH(loadMjcfFile(ZWANG_MODELS_DIR), Catch::Contains("it is a directory"));
  // MuJoCo's own message, with the line: a syntax error, an unknown element, an unknown attribute value.
  CHECK_THROWS_WITH(loadMjcfString("<mujoco><worldbody>"),
                    Catch::StartsWith("<string>: MuJoCo refuses the model: ") && Catch::Contains("XML parse error"));
  try {  // MuJoCo's message spans lines; zwang's is one
    loadMjcfString("<mujoco><worldbody><body><joint/></body></worldbody></mujoco>");
    FAIL("a massless moving body loaded");
  } catch (const ModelError& e) {
    CHECK(std::string(e.what()).find('\n') == std::string::npos);
    CHECK_THAT(e.what(), Catch::Contains("mass and inertia of moving bodies must be larger than mjMINVAL"));
  }
  CHECK_THROWS_WITH(loadMjcfString("<mujoco><worldbody><bogus/></worldbody></mujoco>"),
                    Catch::Contains("MuJoCo refuses the model") && Catch::Contains("bogus"));
  CHECK_THROWS_WITH(loadMjcfString("<mujoco><worldbody><body><joint type=\"spiral\"/><geom size=\"1\"/></body>"
                                   "</worldbody></mujoco>"),
                    Catch::Contains("MuJoCo refuses the model") && Catch::Contains("spiral"));
  CHECK_THROWS_WITH(loadMjcfFile(std::string(ZWANG_MODELS_DIR) + "/panda.urdf"),
                    Catch::EndsWith("panda.urdf: the root element is <robot>, not <mujoco>: not an MJCF file (a "
                                    "URDF: loadUrdfFile)"));
  // Nothing moves.
  CHECK_THROWS_WITH(loadMjcfString("<mujoco><worldbody><body><geom size=\"1\"/></body></worldbody></mujoco>"),
                    Catch::Equals("<string>: the model has no joint: nothing moves"));
  // Not mapped, said: an actuator and a tendon; strict refuses them.
  const std::string actuated = R"(<mujoco><worldbody><body><joint name="h" axis="0 0 1"/>
      <inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/></body></worldbody>
      <tendon><fixed name="t"><joint joint="h" coef="1"/></fixed></tendon>
      <actuator><motor name="m" joint="h" gear="2"/></actuator></mujoco>)";
  const Model model = loadMjcfString(actuated);
  CHECK(hasWarning(model, WarningCode::Unmapped, "<string>: tendons 't' are not mapped"));
  CHECK(hasWarning(model, WarningCode::Unmapped, "actuators 'm' are not mapped"));
  CHECK_THROWS_WITH(loadMjcfString(actuated, MjcfOptions{true}),
                    Catch::StartsWith("<string>: refused in strict mode (2 warnings): tendons 't'"));
}

// Numbers MuJoCo 2.2.2 compiles as written but zwang cannot read (fuzz_mjcf's inputs): a ModelError naming the object.
TEST_CASE("MJCF: degenerate quaternions and a non-finite gravity are refused with the object", "[mjcf]") {
  const std::string inertial = R"(<inertial pos="0 0 0" mass="1" diaginertia="1 1 1"/>)";
  const auto body = [&](const std::string& attributes, const std::string& inside) {
    return "<mujoco><worldbody><body name=\"b\" " + attributes + "><joint name=\"j\"/>" + inside +
           "</body></worldbody></mujoco>";
  };
  CHECK_THROWS_WITH(loadMjcfString(body("quat=\"0 0 0 0\"", inertial)),
                    Catch::Equals("<string>: body 'b': its orientation: the quaternion (0, 0, 0, 0) is zero or not "
                                  "finite"));
  CHECK_THROWS_WITH(loadMjcfString(body("quat=\"1e-200 1e-200 0 0\"", inertial)),
                    Catch::StartsWith("<string>: body 'b': its orientation: the quaternion (1e-200, 1e-200, 0, 0)"));
  CHECK_THROWS_WITH(loadMjcfString(body("quat=\"nan 0 0 0\"", inertial)),
                    Catch::StartsWith("<string>: body 'b': its orientation: the quaternion (nan,"));
  CHECK_THROWS_WITH(loadMjcfString(body("", R"(<inertial pos="0 0 0" quat="0 0 0 0" mass="1" diaginertia="1 1 1"/>)")),
                    Catch::StartsWith("<string>: body 'b': its inertia's orientation: the quaternion (0, 0, 0, 0)"));
  CHECK_THROWS_WITH(loadMjcfString(body("", inertial + R"(<site name="s" quat="0 0 0 0"/>)")),
                    Catch::StartsWith("<string>: site 's': its orientation: the quaternion (0, 0, 0, 0)"));
  CHECK_THROWS_WITH(loadMjcfString("<mujoco><option gravity=\"nan 0 inf\"/><worldbody><body><joint/>" + inertial +
                                   "</body></worldbody></mujoco>"),
                    Catch::Equals("<string>: <option gravity> (nan, 0, inf) is not finite"));
  // Disabled, the gravity is not read: zero.
  CHECK(readMjcfString("<mujoco><option gravity=\"nan 0 0\"><flag gravity=\"disable\"/></option><worldbody><body>"
                       "<joint/>" +
                       inertial + "</body></worldbody></mujoco>")
            .gravity == Vec3::Zero());
  // A NaN axis: the model builder's refusal, naming the joint.
  CHECK_THROWS_WITH(loadMjcfString("<mujoco><worldbody><body><joint name=\"j\" axis=\"nan 0 1\"/>" + inertial +
                                   "</body></worldbody></mujoco>"),
                    Catch::Contains("joint 'j'") && Catch::Contains("axis"));
}

// A floating base without joints (fuzz_mjcf: solveWithFriction offset a null pointer, the empty ∂q̈/∂μ's data()).
TEST_CASE("MJCF: a free body alone loads and falls, with friction too", "[mjcf]") {
  const MjcfModel loaded = readMjcfString(R"(<mujoco><worldbody><body name="b"><joint type="free"/>
      <inertial pos="-1 -1 -1" mass="0.01" fullinertia="1 1 1 -0.1 -0.1 -0.1"/></body></worldbody></mujoco>)");
  const Model& model = loaded.model;
  REQUIRE(model.dof() == 0);
  REQUIRE(model.nv() == 6);
  Task task(model);
  task.gravity = loaded.gravity;
  Workspace ws(model, task);
  Eigen::VectorXd q(model.nq());
  REQUIRE(neutralConfiguration(model, q).ok());
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(model.nv());
  REQUIRE(solveHybridDynamics(model, ws, q, zero, zero, task).ok());
  CHECK(ws.solution.qdd.norm() == Approx(9.81));  // at rest, every point falls with g: no rotation
  REQUIRE(solveWithFriction(model, ws, q, zero, zero, task).ok());
  CHECK(ws.solution.qdd.norm() == Approx(9.81));
}

// A finite but absurd coefficient (fuzz_mjcf: damping 8e307 made solveWithFriction's b·q̇ overflow and return Ok with
// q̈ = −inf): the builder refuses rotor inertia and friction above validate::kMaxJointCoefficient, naming the joint.
TEST_CASE("MJCF: a joint's damping, frictionloss or armature above 1e12 is refused", "[mjcf]") {
  for (const char* attribute : {"damping", "frictionloss", "armature"}) {
    const std::string xml = std::string("<mujoco><worldbody><body name=\"b1\"><joint name=\"j0\" type=\"slide\" ") +
                            attribute +
                            "=\"8.1771766090407624e+307\"/><inertial pos=\"1 1 1\" mass=\"10\" diaginertia=\"1 1 1\"/>"
                            "</body></worldbody></mujoco>";
    CHECK_THROWS_WITH(loadMjcfString(xml),
                      Catch::StartsWith("<string>: joint 'j0': ") &&
                          Catch::Contains("8.17718e+307 is above 1e+12, the largest zwang accepts"));
  }
  const std::string fine = R"(<mujoco><worldbody><body name="b1"><joint name="j0" type="slide" damping="1e12"/>
      <inertial pos="1 1 1" mass="10" diaginertia="1 1 1"/></body></worldbody></mujoco>)";
  CHECK(loadMjcfString(fine).joint(0).viscous_friction == 1e12);
}
