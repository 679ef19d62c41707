// The constraint wrench on each constrained frame (constraintWrench, issue #27 item 2) against independent
// references, on random trees of every joint type (support/joint_types_problem) on a fixed, free or planar base:
//  * the wrench assembled in the test from the dense KKT reference's ν and the input's A columns (world axes at
//    the frame origin; a relative row on both frames, the reference's moment shifted to its own origin);
//  * τ_c = Σ_frames Jᵀ wrench with the dense reference's link Jacobians: all frame rows together are Gᵀν of the
//    reference, and less the contacts' share they are Solution::tau_constraint (which leaves contacts out);
//  * Newton–Euler for the whole robot on a floating base: the wrenches on the frames (contacts, absolute rows;
//    relative rows cancel) and gravity are the rate of the dense reference's momentum, after solveHybridDynamics
//    and after solveWithFriction (whose friction torques are internal);
//  * Local against World through framePose; the errors a user can meet.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "support/floating_reference.hpp"
#include "support/joint_types_problem.hpp"
#include "support/random_chain.hpp"
#include "support/random_problem.hpp"
#include "zwang/zwang.hpp"

using namespace zwang;
using namespace zwang::testing;

namespace {

// A wrench [f; n] at point p (world axes) as a spatial force at the world origin: [f; n + p × f].
Vector6d atWorldOrigin(const Vector6d& w, const Eigen::Vector3d& p) {
  Vector6d out;
  out << w.head<3>(), w.tail<3>() + p.cross(w.head<3>());
  return out;
}

// The reference wrenches, per link (world axes, at the link origin), from the dense reference's ν and the input's
// columns: each frame row +A ν on its link, −A ν on a relative row's reference (acting at the constrained link's
// origin). `contacts_only` keeps the contacts' rows alone. Joint rows (and mimic rows, after the input's) are no
// frame's: skipped.
std::vector<Vector6d> referenceWrenches(const ChainSpec& spec, const FloatingInput& in, const FloatingResult& dense,
                                        bool contacts_only) {
  std::vector<Vector6d> w(spec.links.size(), Vector6d::Zero());
  int row = 0;
  for (const ConstraintInput& c : in.constraints) {
    const auto m = static_cast<int>(c.b.size());
    if (c.joint >= 0 || c.base_dof >= 0 || (contacts_only && !c.contact)) {
      row += m;
      continue;
    }
    const auto a = static_cast<std::size_t>(spec.linkIndex(c.link));
    const std::size_t r = c.relative_to.empty() ? 0 : static_cast<std::size_t>(spec.linkIndex(c.relative_to));
    Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // World (and Reference on an absolute row: the world's)
    if (c.axes == Axes::Local) R = dense.poses[a].linear();
    if (c.axes == Axes::Reference && !c.relative_to.empty()) R = dense.poses[r].linear();
    const Vector6d local = c.A * dense.nu.segment(row, m);
    Vector6d force;
    force << R * local.head<3>(), R * local.tail<3>();
    w[a] += force;
    if (!c.relative_to.empty()) {
      const Eigen::Vector3d d = dense.poses[a].translation() - dense.poses[r].translation();
      w[r].head<3>() -= force.head<3>();
      w[r].tail<3>() -= force.tail<3>() + d.cross(force.head<3>());
    }
    row += m;
  }
  return w;
}

// Σ J_iᵀ w_i over the links, with the reference's spatial Jacobians (world origin) and the wrenches at the links'
// origins in world axes.
Eigen::VectorXd generalizedForce(const FloatingKinematics& K, const std::vector<Vector6d>& w) {
  Eigen::VectorXd tau = Eigen::VectorXd::Zero(K.J[0].cols());
  for (std::size_t i = 0; i < w.size(); ++i) tau += K.J[i].transpose() * atWorldOrigin(w[i], K.poses[i].translation());
  return tau;
}

// The library's wrench on every link's frame, world axes at the link origin.
std::vector<Vector6d> libraryWrenches(const ChainSpec& spec, const Model& model, const Workspace& ws, const Task& task,
                                      const Eigen::VectorXd& q) {
  std::vector<Vector6d> w(spec.links.size(), Vector6d::Zero());
  for (std::size_t i = 0; i < spec.links.size(); ++i) {
    Vec6 out;
    const Status s = constraintWrench(model, ws, task, q, model.frameIndex(spec.links[i].name), Expressed::World, out);
    INFO(s.message);
    REQUIRE(s);
    w[i] = out;
  }
  return w;
}

// max over the links of |x − y|, relative to max(1, the largest entry of y).
double largestError(const std::vector<Vector6d>& x, const std::vector<Vector6d>& y) {
  double diff = 0, size = 1;
  for (std::size_t i = 0; i < x.size(); ++i) {
    diff = std::max(diff, (x[i] - y[i]).cwiseAbs().maxCoeff());
    size = std::max(size, y[i].cwiseAbs().maxCoeff());
  }
  return diff / size;
}

// J_Bᵀ (Σ_i I_i a_i + v_i ×* I_i v_i − I_i [g; 0] − w_i): the base rows of the whole robot's Newton–Euler balance
// with the wrenches w on the links (world axes at their origins), the accelerations those of qdd. Zero when the
// wrenches and gravity are all the outside world exerts (τ on the base is 0, no applied wrenches).
Eigen::VectorXd baseImbalance(const ChainSpec& spec, const FloatingBase& base, const FloatingInput& in,
                              const Eigen::VectorXd& qdd, const std::vector<Vector6d>& w, double& size) {
  const FloatingKinematics K = floatingKinematics(spec, base, in.q, in.v);
  Vector6d sum = Vector6d::Zero();
  size = 1;
  for (std::size_t i = 0; i < w.size(); ++i) {
    Vector6d g;
    g << in.gravity, Eigen::Vector3d::Zero();
    const Vector6d inertial = K.inertia[i] * (K.J[i] * qdd + K.bias[i]) + forceCross(K.v[i]) * K.inertia[i] * K.v[i];
    const Vector6d outside = K.inertia[i] * g + atWorldOrigin(w[i], K.poses[i].translation());
    sum += inertial - outside;
    size = std::max({size, inertial.cwiseAbs().maxCoeff(), outside.cwiseAbs().maxCoeff()});
  }
  return K.J[0].leftCols(base.baseVelocitySize()).transpose() * sum;
}

}  // namespace

TEST_CASE("constraint wrench: the dense reference's A nu per frame, and tau_c = sum J^T wrench",
          "[constraint_wrench]") {
  std::mt19937_64 rng(stressSeedOr(2026112821ULL));
  int compared = 0, draws = 0, relative = 0, contacts = 0, floating = 0;
  double e_wrench = 0, e_local = 0, e_g_nu = 0, e_tau_c = 0;
  while (compared < 250) {
    REQUIRE(++draws < 3000);
    auto [spec, base, in, model] = drawLoadedTree(rng, 2, 12, 0.3, rowOptions(6, 0.4));
    const bool has_contact = makeContact(rng, base, in);
    const Task task = floatingTaskFromInput(model, in);
    if (task.constraintRows() == 0) continue;
    const FloatingResult dense = floatingDynamics(spec, base, in);
    if (!wellPosed(dense)) continue;
    Workspace ws(model, task);
    REQUIRE(solveHybridDynamics(model, ws, in.q, in.v, in.tau, task));
    ++compared;
    floating += base.kind != BaseKind::Fixed ? 1 : 0;
    contacts += has_contact ? 1 : 0;
    relative += std::any_of(in.constraints.begin(), in.constraints.end(),
                            [](const ConstraintInput& c) { return !c.relative_to.empty(); })
                    ? 1
                    : 0;
    const std::vector<Vector6d> ours = libraryWrenches(spec, model, ws, task, in.q);
    e_wrench = std::max(e_wrench, largestError(ours, referenceWrenches(spec, in, dense, false)));
    for (std::size_t i = 0; i < ours.size(); ++i) {  // Local: the world's components turned into the frame's axes
      const int frame = model.frameIndex(spec.links[i].name);
      Vec6 local;
      Eigen::Isometry3d pose;
      REQUIRE(constraintWrench(model, ws, task, in.q, frame, Expressed::Local, local));
      REQUIRE(framePose(model, ws, in.q, frame, pose));
      Vector6d turned;
      turned << pose.linear().transpose() * ours[i].head<3>(), pose.linear().transpose() * ours[i].tail<3>();
      e_local =
          std::max(e_local, (local - turned).cwiseAbs().maxCoeff() / std::max(1.0, ours[i].cwiseAbs().maxCoeff()));
    }
    const FloatingKinematics K = floatingKinematics(spec, base, in.q, in.v);
    const Eigen::VectorXd all_rows = generalizedForce(K, ours);
    const int user_rows = dense.user_rows;
    e_g_nu =
        std::max(e_g_nu, relativeError(all_rows, dense.G.topRows(user_rows).transpose() * dense.nu.head(user_rows)));
    // τ_c: the motors' share (contacts out) and the mimic couplings, which are no frame's.
    const Eigen::VectorXd mimic = dense.G.bottomRows(dense.mimic_rows).transpose() * dense.nu.tail(dense.mimic_rows);
    const Eigen::VectorXd contact_part = generalizedForce(K, referenceWrenches(spec, in, dense, true));
    e_tau_c = std::max(e_tau_c, relativeError(all_rows - contact_part + mimic, ws.solution.tau_constraint));
  }
  std::printf(
      "constraint wrench vs the dense reference: %d compared (%d draws), %d floating, %d with relative rows, %d with "
      "a contact\n  max rel. error wrench (world) %.2g, local vs framePose %.2g, sum J^T w vs G^T nu %.2g, "
      "tau_constraint %.2g\n",
      compared, draws, floating, relative, contacts, e_wrench, e_local, e_g_nu, e_tau_c);
  CHECK(relative > 50);
  CHECK(contacts > 20);
  // Both sides come from the same KKT system solved exactly, kept draws conditioned below 1e6: round-off only.
  CHECK(e_wrench < 1e-9);
  CHECK(e_g_nu < 1e-9);
  CHECK(e_tau_c < 1e-9);
  CHECK(e_local < 1e-14);  // one rotation of the same numbers: a few ulps
}

TEST_CASE("constraint wrench: Newton-Euler on a floating base, after solveHybridDynamics and solveWithFriction",
          "[constraint_wrench]") {
  std::mt19937_64 rng(stressSeedOr(2026112822ULL));
  int compared = 0, draws = 0, stuck = 0;
  double e_plain = 0, e_friction = 0;
  while (compared < 200) {
    REQUIRE(++draws < 3000);
    const ChainSpec spec = randomJointTypesTree(rng, 2, 10, 0.3);
    const FloatingBase base = randomBase(rng);
    if (base.kind == BaseKind::Fixed) continue;
    RandomProblemOptions options;
    options.relative_probability = 0.3;
    FloatingInput in = loadedInput(rng, spec, base, options);
    makeContact(rng, base, in);
    in.wrenches.clear();              // the balance below has the constraints and gravity as the only outside forces
    in.v.tail(spec.dof()).setZero();  // joints at rest: friction holds some of them
    const Model model = floatingModelFromSpec(spec, base);
    const Task task = floatingTaskFromInput(model, in);
    if (!wellPosed(floatingDynamics(spec, base, in))) continue;
    Workspace ws(model, task);
    REQUIRE(solveHybridDynamics(model, ws, in.q, in.v, in.tau, task));
    double size = 1;
    Eigen::VectorXd miss =
        baseImbalance(spec, base, in, ws.solution.qdd, libraryWrenches(spec, model, ws, task, in.q), size);
    e_plain = std::max(e_plain, miss.cwiseAbs().maxCoeff() / size);
    const Status s = solveWithFriction(model, ws, in.q, in.v, in.tau, task);
    INFO(s.message);
    REQUIRE(s);
    stuck += static_cast<int>(ws.friction.stuck.size());
    miss = baseImbalance(spec, base, in, ws.solution.qdd, libraryWrenches(spec, model, ws, task, in.q), size);
    e_friction = std::max(e_friction, miss.cwiseAbs().maxCoeff() / size);
    ++compared;
  }
  std::printf(
      "constraint wrench, Newton-Euler of the floating robot: %d compared (%d draws), %d stuck joints under "
      "friction\n  max rel. imbalance after solveHybridDynamics %.2g, after solveWithFriction %.2g\n",
      compared, draws, stuck, e_plain, e_friction);
  CHECK(stuck > 100);
  // Sums of products of the dense reference's kinematics with the solved q̈ and wrenches, well-posed draws:
  // round-off of the solve, amplified at most by the conditioning (below 1e6).
  CHECK(e_plain < 1e-9);
  CHECK(e_friction < 1e-9);
}

TEST_CASE("constraint wrench: closed forms and errors", "[constraint_wrench]") {
  // The report's 1-DOF arm: revolute about z, 1 kg at 0.5 m along x, I_zz = 2 at the COM (2.25 about the joint).
  // A moment row about z on its link (Local): the wrench is [0, 0, 0, 0, 0, ν].
  Joint joint;
  joint.name = "joint1";
  joint.axis = Vec3::UnitZ();
  const Model model =
      ModelBuilder("one_dof_arm", "base")
          .addJoint(joint, "link1",
                    RigidInertia::fromMassComInertia(1.0, Vec3(0.5, 0, 0), Vec3(1.0, 1.0, 2.0).asDiagonal()))
          .build();
  Task task(model);
  ConstraintMatrix A = ConstraintMatrix::Zero(6, 1);
  A(5, 0) = 1.0;
  task.addConstraint("link1", A);
  task.targets()[0] = 1.5;
  const Eigen::VectorXd q = Eigen::VectorXd::Constant(1, 0.3), qd = Eigen::VectorXd::Zero(1),
                        tau = Eigen::VectorXd::Constant(1, 0.7);
  Workspace ws(model, task);
  Vec6 w;
  const int frame = model.frameIndex("link1");
  CHECK(constraintWrench(model, ws, task, q, frame, Expressed::World, w).code == StatusCode::NotComputed);
  REQUIRE(solveHybridDynamics(model, ws, q, qd, tau, task));
  REQUIRE(constraintWrench(model, ws, task, q, frame, Expressed::Local, w));
  Vec6 expected = Vec6::Zero();
  expected[5] = ws.solution.nu[0];
  CHECK((w - expected).cwiseAbs().maxCoeff() < 1e-14);  // turned to the world and back: rounding of the rotation
  REQUIRE(constraintWrench(model, ws, task, q, frame, Expressed::World, w));
  CHECK((w - expected).cwiseAbs().maxCoeff() < 1e-14);  // the frame turned about z: z stays (rounding of cos, sin)
  // I q̈ = τ + ν about the joint, I = 2.25: ν = 2.25 · 1.5 − 0.7 (gravity, along −z, has no moment about z).
  CHECK(std::abs(ws.solution.nu[0] - (2.25 * 1.5 - 0.7)) < 1e-12);  // rounding of the sweeps' few products
  // A frame the task does not constrain: zero.
  REQUIRE(constraintWrench(model, ws, task, q, model.frameIndex("base"), Expressed::World, w));
  CHECK(w == Vec6::Zero());
  // Errors.
  CHECK(constraintWrench(model, ws, task, q, 99, Expressed::World, w).code == StatusCode::ModelMismatch);
  const Eigen::VectorXd other_q = Eigen::VectorXd::Constant(1, 0.4);
  CHECK(constraintWrench(model, ws, task, other_q, frame, Expressed::World, w).code == StatusCode::NotComputed);
  Task bigger(model);
  bigger.addConstraint("link1", ConstraintMatrix::Identity(6, 2));
  const Status s = constraintWrench(model, ws, bigger, q, frame, Expressed::World, w);
  CHECK(s.code == StatusCode::NotComputed);
  CHECK(std::string(s.message).find("solution.nu has 1 entries, the task has 2") != std::string::npos);
}
