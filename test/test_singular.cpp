// Singular tasks: more independent constraints than the robot has joints, a
// stretched-out arm, wrist and elbow singularities, redundant rows and
// constraints on the fixed base. The results stay finite, the balance says
// it is singular, consistent tasks are met to rounding and inconsistent ones
// at the least-squares optimum — both compared with a dense pseudo-inverse
// solution computed from H, C and G alone (no code shared with the solver).
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <catch2/catch.hpp>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <limits>
#include <stdexcept>

#include "support/frame_values.hpp"
#include "support/random_chain.hpp"
#include "support/random_problem.hpp"

using namespace zwang;
using namespace zwang::testing;

namespace {

// ‖G q̈ − γ‖ for our q̈, and the least-squares optimum min_x ‖G x − γ‖.
std::pair<double, double> residuals(const DenseResult& ref, const Eigen::VectorXd& qdd) {
  const Eigen::VectorXd best =
      ref.G.jacobiSvd(Eigen::ComputeThinU | Eigen::ComputeThinV).setThreshold(1e-10).solve(ref.gamma);
  return {(ref.G * qdd - ref.gamma).norm(), (ref.G * best - ref.gamma).norm()};
}

// The dense minimum-norm least-squares solution of the balance: with
// 𝓛 = G H⁻¹ Gᵀ and r = γ − G H⁻¹(τ − C), ν = 𝓛⁺ r and q̈ = H⁻¹(τ − C + Gᵀ ν).
// 𝓛's range is G's column space, taken from G's SVD with the known rank (the
// rank of G, decided on G's singular values, not on 𝓛's squared ones), so
// the regular part is solved exactly and nothing acts across the null space.
struct PseudoInverse {
  Eigen::VectorXd qdd, nu;
  double residual = 0.0;  // ‖G q̈ − γ‖
  int rank = 0;
};

PseudoInverse densePseudoInverse(const DenseResult& ref, const DynamicsInput& in) {
  PseudoInverse out;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(ref.G, Eigen::ComputeFullU);
  const Eigen::VectorXd& sv = svd.singularValues();
  // G's entries are lengths and unit numbers of order one here; 1e-9 of the
  // largest separates the constructed rank loss (rounding, ~1e-16) from the
  // smallest regular singular value of these draws (≥ ~1e-4).
  for (Eigen::Index k = 0; k < sv.size(); ++k) out.rank += sv[k] > 1e-9 * sv[0] ? 1 : 0;
  const Eigen::MatrixXd Q = svd.matrixU().leftCols(out.rank);
  const Eigen::LLT<Eigen::MatrixXd> H(ref.H);
  const Eigen::VectorXd free = in.tau - ref.C;
  const Eigen::MatrixXd L = ref.G * H.solve(ref.G.transpose());
  const Eigen::VectorXd r = ref.gamma - ref.G * H.solve(free);
  const Eigen::MatrixXd Lq = Q.transpose() * L * Q;
  out.nu = Q * Lq.ldlt().solve(Q.transpose() * r);
  out.qdd = H.solve(free + ref.G.transpose() * out.nu);
  out.residual = (ref.G * out.qdd - ref.gamma).norm();
  return out;
}

double relativeDifference(const Eigen::VectorXd& ours, const Eigen::VectorXd& reference) {
  return (ours - reference).norm() / std::max(1.0, reference.norm());
}

bool allFinite(const Solution& s) {
  return s.qdd.allFinite() && s.nu.allFinite() && s.tau_constraint.allFinite() && s.tau_control.allFinite() &&
         std::isfinite(s.gauss);
}

ChainSpec planarArm() {
  ChainSpec spec;
  spec.name = "planar_arm";
  spec.links.resize(3);
  spec.links[0].name = "base";
  for (int k = 1; k <= 2; ++k) {
    LinkSpec& l = spec.links[static_cast<std::size_t>(k)];
    l.name = "link" + std::to_string(k);
    l.mass = 1.0;
    l.com = Eigen::Vector3d(0.5, 0, 0);
    l.inertia = Eigen::Vector3d(0.01, 0.1, 0.1).asDiagonal();
    JointSpec j;
    j.name = "joint" + std::to_string(k);
    j.xyz = k == 1 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(1, 0, 0);
    j.lower = -3;
    j.upper = 3;
    j.effort = 100;
    j.velocity = 10;
    spec.joints.push_back(j);
  }
  LinkSpec tip;
  tip.name = "tip";
  spec.links.push_back(tip);
  JointSpec fixed;
  fixed.name = "tip_joint";
  fixed.type = "fixed";
  fixed.xyz = Eigen::Vector3d(1, 0, 0);
  spec.joints.push_back(fixed);
  return spec;
}

}  // namespace

TEST_CASE("more independent constraint rows than joints: finite, singular, least-squares") {
  std::mt19937_64 rng(5);
  RandomChainOptions chain_options;
  chain_options.max_moving_joints = 4;
  int tested = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const ChainSpec spec = randomChain(rng, chain_options);
    RandomProblemOptions options;
    options.max_constraint_rows = 12;
    DynamicsInput in = randomProblem(rng, spec, options);
    if (in.constraintRows() <= spec.dof()) continue;
    ++tested;
    const DenseResult ref = denseDynamics(spec, in);
    const Model model = modelFromSpec(spec);
    const Task task = taskFromInput(model, in);
    Workspace ws(model, task);
    REQUIRE(solveHybridDynamics(model, ws, in.q, in.qd, in.tau, task));
    const Solution& s = ws.solution;
    CHECK(allFinite(s));
    CHECK(s.balance.singular);
    CHECK(s.balance.rank <= spec.dof());
    const auto [ours, best] = residuals(ref, s.qdd);
    INFO("residual ours " << ours << " least squares " << best);
    CHECK(ours <= best * (1.0 + 1e-9) + 1e-9);
    CHECK_FALSE(s.balance.consistent);  // random set points on more rows than joints: no q̈ meets them
    CHECK(s.balance.residual == Approx(ours).epsilon(1e-9));
  }
  CHECK(tested >= 20);
}

TEST_CASE("stretched-out arm: the along-arm tip acceleration is out of reach") {
  const ChainSpec spec = planarArm();
  const Model model = modelFromSpec(spec);
  DynamicsInput in;
  in.q = Eigen::Vector2d(0.3, 0.0);  // fully stretched
  in.qd = Eigen::Vector2d::Zero();
  in.tau = Eigen::Vector2d(1.0, -0.5);
  in.gravity.setZero();
  ConstraintInput c;
  c.link = "tip";
  c.A = Matrix6Xd::Zero(6, 2);
  c.A(0, 0) = 1.0;  // along the arm: unreachable at rest
  c.A(1, 1) = 1.0;  // across the arm
  c.b = Eigen::Vector2d(2.0, 0.7);
  in.constraints.push_back(c);
  const Task task = taskFromInput(model, in);
  Workspace ws(model, task);
  REQUIRE(solveHybridDynamics(model, ws, in.q, in.qd, in.tau, task));
  const Solution& s = ws.solution;
  CHECK(allFinite(s));
  CHECK(s.balance.singular);
  CHECK(s.balance.rank == 1);
  // Across the arm the demand is met; along it, the arm does what it can (nothing).
  const Vec6 a = accelerationOf(model, ws, model.frameIndex("tip"), Expressed::Local);
  CHECK(a[1] == Approx(0.7).epsilon(1e-6));
  CHECK(a[0] == Approx(0.0).margin(1e-9));
  const auto [ours, best] = residuals(denseDynamics(spec, in), s.qdd);
  CHECK(ours == Approx(best).epsilon(1e-6));
  CHECK(std::abs(s.nu[0]) < 1e-3);  // no force pushed along L's null space
}

TEST_CASE("a repeated constraint row: rank deficient but consistent, met exactly, ν shared") {
  const ChainSpec spec = planarArm();
  const Model model = modelFromSpec(spec);
  Task task(model);
  task.gravity.setZero();
  ConstraintMatrix A = ConstraintMatrix::Zero(6, 2);
  A(5, 0) = A(5, 1) = 1.0;  // the same angular row twice
  task.addConstraint("link2", A);
  task.targets() << 1.5, 1.5;
  Workspace ws(model, task);
  REQUIRE(solveHybridDynamics(model, ws, Eigen::Vector2d(0.2, 0.9), Eigen::Vector2d(0.1, -0.3), Eigen::Vector2d::Zero(),
                              task));
  CHECK(ws.solution.balance.singular);
  CHECK(ws.solution.balance.rank == 1);
  CHECK_FALSE(ws.solution.balance.nu_unique);
  CHECK(ws.solution.balance.consistent);
  CHECK(ws.solution.qdd.sum() == Approx(1.5).epsilon(1e-6));
  CHECK(ws.solution.nu[0] == Approx(ws.solution.nu[1]).epsilon(1e-9));
}

TEST_CASE("a constraint on the fixed base changes nothing and is reported singular") {
  const ChainSpec spec = planarArm();
  const Model model = modelFromSpec(spec);
  Task task(model);
  task.addConstraint("base", ConstraintMatrix::Identity(6, 3));
  task.targets() << 1, 2, 3;
  Task free_task(model);
  Workspace ws(model, task);
  const Eigen::Vector2d q(0.4, -0.2), qd(1, 2), tau(3, -1);
  REQUIRE(solveHybridDynamics(model, ws, q, qd, tau, free_task));
  const Eigen::VectorXd free_qdd = ws.solution.qdd;
  REQUIRE(solveHybridDynamics(model, ws, q, qd, tau, task));
  CHECK(ws.solution.balance.singular);
  CHECK(ws.solution.balance.rank == 0);
  CHECK(ws.solution.nu.norm() == 0.0);
  CHECK((ws.solution.qdd - free_qdd).norm() < 1e-12);
}

// A standing humanoid (models/simple_humanoid.urdf, free base, 29 joints, nv =
// 35): both ankles on the ground in 6-D (12 contact rows) and every joint held
// by its motor (29 joint rows), the problem of docs/evaluation.md, section 4.
// The joint rows fix every joint; either foot alone then fixes the base, so
// the rank is nv = 35 of 41 rows, and the 6 rows beyond it are the ground's
// split between the feet: an internal force between them moves nothing. At
// rest with every target 0, q̈ = 0 meets every row: ν is not unique but the
// task is met — statically indeterminate, not a failure. Asking the left ankle
// alone for an acceleration keeps the rows and the rank, but with every joint
// held the robot is one rigid body at rest, and the right ankle's zero then
// fixes the left one's: no motion meets both, the lost rank leaves rows unmet.
TEST_CASE(
    "a standing humanoid: the weight split between the feet is indeterminate but met; a rank loss that "
    "leaves rows unmet is not") {
  UrdfOptions options;
  options.base = BaseType::Free;
  const Model model = loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/simple_humanoid.urdf", options);
  REQUIRE(model.dof() == 29);
  REQUIRE(model.nv() == 35);
  Task task(model);
  for (const char* foot : {"l_ankle", "r_ankle"})
    task.addContact(foot, ConstraintMatrix::Identity(6, 6), Expressed::World);
  for (int j = 0; j < model.dof(); ++j) task.addJointConstraint(j);
  Workspace ws(model, task);
  Eigen::VectorXd q(model.nq());
  REQUIRE(neutralConfiguration(model, q));
  const Eigen::VectorXd qd = Eigen::VectorXd::Zero(model.nv()), tau = Eigen::VectorXd::Zero(model.nv());
  for (const double left : {0.0, 0.5}) {
    INFO("left ankle's first row asked for " << left);
    task.targets().setZero();
    task.targets()[0] = left;
    REQUIRE(solveHybridDynamics(model, ws, q, qd, tau, task));
    const BalanceReport& report = ws.solution.balance;
    CHECK(report.rows == 41);
    CHECK(report.rank == 35);
    CHECK(report.singular);
    CHECK_FALSE(report.nu_unique);
    if (left == 0.0) {
      CHECK(report.consistent);
      CHECK(ws.solution.qdd.cwiseAbs().maxCoeff() < 1e-9);
    } else {
      CHECK_FALSE(report.consistent);
      CHECK(report.residual > 1e-3);  // far above rounding: a row is not met
    }
  }
}

TEST_CASE("balance report: Frobenius condition number of the equilibrated 𝓛 against the dense G H⁻¹ Gᵀ") {
  // 𝓛 is the dense G H⁻¹ Gᵀ up to a permutation of rows (solver order), and
  // so is 𝓛̃ = E 𝓛 E (E = diag(1/√𝓛_ii)) with the same permutation, so
  // κ̃_F = ‖𝓛̃‖_F ‖𝓛̃⁻¹‖_F must match whichever way the solver factored it.
  std::mt19937_64 rng(17);
  RandomChainOptions chain_options;
  chain_options.max_moving_joints = 8;
  int tested = 0;
  double worst = 0.0;
  for (int trial = 0; trial < 200; ++trial) {
    const ChainSpec spec = randomChain(rng, chain_options);
    RandomProblemOptions options;
    options.max_constraint_rows = 6;
    DynamicsInput in = randomProblem(rng, spec, options);
    const int m = in.constraintRows();
    if (m == 0 || m > spec.dof()) continue;
    const DenseResult ref = denseDynamics(spec, in);
    const Eigen::MatrixXd Ld = ref.G * ref.H.fullPivLu().solve(ref.G.transpose());
    const Eigen::MatrixXd Lsym = 0.5 * (Ld + Ld.transpose());
    const Eigen::VectorXd raw = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Lsym).eigenvalues();
    // The dense reference itself loses digits beyond a raw ratio of 1e7 (a
    // row nothing moves has 𝓛_ii at rounding level, which equilibration would
    // blow up to 1: such draws are the singular tests' business).
    if (!(raw.minCoeff() > 1e-7 * raw.maxCoeff())) continue;
    const Eigen::VectorXd e = Lsym.diagonal().cwiseSqrt().cwiseInverse();
    const Eigen::MatrixXd Ls = e.asDiagonal() * Lsym * e.asDiagonal();
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Ls);
    const double lmin = eig.eigenvalues().minCoeff(), lmax = eig.eigenvalues().maxCoeff();
    ++tested;
    const double kappa_f = Ls.norm() * Ls.inverse().norm();
    const Model model = modelFromSpec(spec);
    const Task task = taskFromInput(model, in);
    Workspace ws(model, task);
    REQUIRE(solveHybridDynamics(model, ws, in.q, in.qd, in.tau, task));
    const BalanceReport& d = ws.solution.balance;
    CHECK_FALSE(d.singular);
    CHECK(d.rank == m);
    CHECK(d.damping == 0.0);
    CHECK(d.condition >= lmax / lmin * (1.0 - 1e-6));
    CHECK(d.condition <= m * lmax / lmin * (1.0 + 1e-6));
    worst = std::max(worst, std::abs(d.condition - kappa_f) / kappa_f);
  }
  INFO("tested " << tested << ", worst relative difference " << worst);
  CHECK(tested >= 60);
  CHECK(worst < 1e-5);
}

namespace {

// Six rows holding `link` (linear and angular, world or local axes, the blocks
// turned at random) with set points either met by some q̈ (consistent: the
// link's acceleration for a random q̈₀) or drawn at random (inconsistent when
// the robot has fewer than six degrees of freedom there).
ConstraintInput sixRows(std::mt19937_64& rng, const ChainSpec& spec, const DynamicsInput& in, const std::string& link,
                        bool consistent) {
  ConstraintInput c;
  c.link = link;
  c.axes = uniform01(rng) < 0.5 ? Axes::Local : Axes::World;
  c.A = Matrix6Xd::Zero(6, 6);
  const bool turned = uniform01(rng) < 0.5;
  c.A.topLeftCorner<3, 3>() = turned ? randomRotation(rng) : Eigen::Matrix3d::Identity();
  c.A.bottomRightCorner<3, 3>() = turned ? randomRotation(rng) : Eigen::Matrix3d::Identity();
  if (consistent) {
    const Eigen::VectorXd qdd0 = randomVector(rng, spec.dof(), 3.0);
    c.b = c.A.transpose() * linkAcceleration(spec, in.q, in.qd, qdd0, link, c.axes);
  } else {
    c.b = randomVector(rng, 6, 3.0);
  }
  return c;
}

struct Agreement {
  int tested = 0, consistent = 0, inconsistent = 0;
  double qdd = 0.0, nu = 0.0, residual = 0.0, met = 0.0;
};

// One solve against the dense pseudo-inverse: q̈ and ν to `tolerance`
// relative, the reported residual equal to the dense one, and the
// consistency flag right.
void checkAgainstPseudoInverse(const ChainSpec& spec, const DynamicsInput& in, bool consistent, double tolerance,
                               Agreement& worst) {
  const DenseResult ref = denseDynamics(spec, in);
  const PseudoInverse best = densePseudoInverse(ref, in);
  const Model model = modelFromSpec(spec);
  const Task task = taskFromInput(model, in);
  Workspace ws(model, task);
  REQUIRE(solveHybridDynamics(model, ws, in.q, in.qd, in.tau, task));
  const Solution& s = ws.solution;
  REQUIRE(allFinite(s));
  const double scale = ref.gamma.norm() + ref.G.norm() * best.qdd.norm() + 1.0;  // what G q̈ − γ is computed from
  const double d_qdd = relativeDifference(s.qdd, best.qdd), d_nu = relativeDifference(s.nu, best.nu);
  const double d_residual = std::abs(s.balance.residual - best.residual) / scale;
  INFO("q̈ " << d_qdd << ", ν " << d_nu << ", residual ours " << s.balance.residual << " dense " << best.residual
            << ", rank ours " << s.balance.rank << " dense " << best.rank << ", condition " << s.balance.condition);
  CHECK(d_qdd <= tolerance);
  CHECK(d_nu <= tolerance);
  CHECK(d_residual <= tolerance);
  CHECK(s.balance.rank == best.rank);
  CHECK(s.balance.singular == (best.rank < in.constraintRows()));
  if (consistent) {
    CHECK(s.balance.consistent);
    CHECK(s.balance.residual <= tolerance * scale);
    worst.met = std::max(worst.met, s.balance.residual / scale);
    ++worst.consistent;
  } else if (best.residual > 1e-6 * scale) {  // a random b can happen to be (nearly) reachable
    CHECK_FALSE(s.balance.consistent);
    ++worst.inconsistent;
  }
  ++worst.tested;
  worst.qdd = std::max(worst.qdd, d_qdd);
  worst.nu = std::max(worst.nu, d_nu);
  worst.residual = std::max(worst.residual, d_residual);
}

// A 6R arm (z, y, y | z, y, z wrist) whose singular postures are known: the
// wrist with q5 = 0 (axes 4 and 6 collinear), the elbow with q3 = 0 (the arm
// stretched). With `seven`, a shoulder roll joins after joint 2, so the
// shoulder (q2 = 0: axes 1 and 3 collinear) adds a second rank loss.
ChainSpec sixJointArm(std::mt19937_64& rng, bool seven) {
  ChainSpec spec;
  spec.name = seven ? "seven_joint_arm" : "six_joint_arm";
  std::vector<std::pair<Eigen::Vector3d, double>> axes_offsets = {
      {Eigen::Vector3d::UnitZ(), 0.3},  {Eigen::Vector3d::UnitY(), 0.0}, {Eigen::Vector3d::UnitY(), 0.4},
      {Eigen::Vector3d::UnitZ(), 0.35}, {Eigen::Vector3d::UnitY(), 0.1}, {Eigen::Vector3d::UnitZ(), 0.1}};
  if (seven) axes_offsets.insert(axes_offsets.begin() + 2, {Eigen::Vector3d::UnitZ(), 0.2});
  spec.links.push_back(LinkSpec{"base", 0.0, {}, {}, Eigen::Matrix3d::Zero()});
  for (std::size_t k = 0; k < axes_offsets.size(); ++k) {
    LinkSpec link;
    link.name = "link" + std::to_string(k + 1);
    link.mass = uniform(rng, 0.3, 4.0);
    link.com = Eigen::Vector3d(uniform(rng, -0.02, 0.02), uniform(rng, -0.02, 0.02), uniform(rng, 0.0, 0.15));
    link.inertia = randomInertia(rng, link.mass);
    spec.links.push_back(link);
    JointSpec joint;
    joint.name = "joint" + std::to_string(k + 1);
    joint.type = "continuous";
    joint.axis = axes_offsets[k].first;
    joint.xyz = Eigen::Vector3d(0, 0, axes_offsets[k].second);
    joint.rotor_inertia = uniform(rng, 0.0, 0.05);
    spec.joints.push_back(joint);
  }
  spec.links.push_back(LinkSpec{"tool", 0.0, {}, {}, Eigen::Matrix3d::Zero()});
  JointSpec tool;
  tool.name = "tool_joint";
  tool.type = "fixed";
  tool.xyz = Eigen::Vector3d(0.02, 0.0, 0.12);
  spec.joints.push_back(tool);
  return spec;
}

}  // namespace

TEST_CASE("six rows on a 1–5 joint chain: consistent tasks met exactly, inconsistent at the least-squares optimum") {
  // Holding a tool with six rows on an arm with fewer than six joints: 𝓛 has
  // exact rank loss. At rest with b = 0, or moving with b from some q̈₀, the
  // task is consistent and must be met to rounding; random b is met in the
  // least-squares sense. Regular directions must not be damped, however
  // small 𝓛's raw eigenvalues are next to its largest (metres vs radians).
  std::mt19937_64 rng(2024);
  RandomChainOptions chain_options;
  chain_options.max_moving_joints = 5;
  Agreement worst;
  for (int trial = 0; trial < 320; ++trial) {
    const ChainSpec spec = randomChain(rng, chain_options);
    const int n = spec.dof();
    DynamicsInput in;
    in.q = randomVector(rng, n, 2.5);
    const bool moving = trial % 2 == 1;
    in.qd = moving ? randomVector(rng, n, 1.5) : Eigen::VectorXd::Zero(n);
    in.tau = randomVector(rng, n, 3.0);
    const bool consistent = trial % 4 < 3;
    in.constraints.push_back(sixRows(rng, spec, in, spec.links.back().name, consistent));
    INFO("trial " << trial << ", " << n << " joints, " << (moving ? "moving" : "at rest") << ", "
                  << (consistent ? "consistent" : "random b"));
    checkAgainstPseudoInverse(spec, in, consistent, consistent ? 1e-10 : 1e-9, worst);
  }
  WARN("1-5 joint chains, 6 rows: " << worst.tested << " solves (" << worst.consistent << " consistent, "
                                    << worst.inconsistent << " inconsistent); worst relative difference q̈ " << worst.qdd
                                    << ", ν " << worst.nu << ", residual " << worst.residual
                                    << "; consistent tasks met to " << worst.met);
  CHECK(worst.tested == 320);
  CHECK(worst.consistent == 240);
  CHECK(worst.inconsistent >= 60);
}

TEST_CASE("6- and 7-joint arms at wrist, elbow and shoulder singularities: met exactly or in the least-squares sense") {
  std::mt19937_64 rng(77);
  Agreement worst;
  for (int trial = 0; trial < 160; ++trial) {
    const bool seven = trial % 2 == 1;
    const ChainSpec spec = sixJointArm(rng, seven);
    const int n = spec.dof();
    DynamicsInput in;
    in.q = randomVector(rng, n, 2.5);
    for (int j = 0; j < n; ++j)  // away from the other singular postures (0, ±π), so only the chosen ones are
      in.q[j] = (in.q[j] < 0 ? -1.0 : 1.0) * uniform(rng, 0.3, 2.8);
    const int wrist = seven ? 5 : 4, elbow = seven ? 3 : 2, shoulder = 1;  // indices into q
    switch (trial % 4 / 2 + (seven ? 2 : 0)) {
      case 0: in.q[wrist] = 0.0; break;                        // 6R wrist
      case 1: in.q[elbow] = 0.0; break;                        // 6R elbow
      case 2: in.q[wrist] = 0.0, in.q[shoulder] = 0.0; break;  // 7R wrist and shoulder
      default: in.q[wrist] = 0.0, in.q[elbow + 1] = 0.0, in.q[shoulder] = 0.0; break;
    }
    const bool moving = trial % 3 != 0;
    in.qd = moving ? randomVector(rng, n, 1.5) : Eigen::VectorXd::Zero(n);
    in.tau = randomVector(rng, n, 3.0);
    const bool consistent = trial % 5 != 0;
    in.constraints.push_back(sixRows(rng, spec, in, "tool", consistent));
    INFO("trial " << trial << ", " << n << " joints, q " << in.q.transpose());
    REQUIRE(densePseudoInverse(denseDynamics(spec, in), in).rank < 6);  // the posture is singular
    checkAgainstPseudoInverse(spec, in, consistent, consistent ? 1e-10 : 1e-9, worst);
  }
  WARN("6-7 joint arms at singular postures: " << worst.tested << " solves; worst relative difference q̈ " << worst.qdd
                                               << ", ν " << worst.nu << ", residual " << worst.residual
                                               << "; consistent tasks met to " << worst.met);
  CHECK(worst.tested == 160);
}

namespace {

struct SweepSample {
  double s = 0.0;  // q5, the wrist angle
  Eigen::VectorXd nu;
  double residual = 0.0, damping = 0.0;
  bool consistent = true;
};

// The 6R arm moving through its wrist singularity (q5 = s for s in
// [−span, span], `points` samples), the tool held still (six world rows,
// b = 0) while the joints move: near s = 0 the velocity terms ask for a tool
// acceleration the arm cannot cancel.
std::vector<SweepSample> wristSweep(int points, double span, const BalanceOptions& options) {
  std::mt19937_64 rng(4242);
  const ChainSpec spec = sixJointArm(rng, false);
  const Model model = modelFromSpec(spec);
  Task task(model);
  task.balance = options;
  task.addConstraint("tool", ConstraintMatrix::Identity(6, 6), Expressed::World);
  Workspace ws(model, task);
  Eigen::VectorXd q(6), qd(6), tau(6);
  q << 0.4, -0.7, 1.1, 0.6, 0.0, -0.5;
  qd << 0.3, -0.2, 0.4, 0.5, -0.6, 0.2;
  tau << 1.0, -2.0, 0.5, 0.2, -0.1, 0.05;
  std::vector<SweepSample> samples;
  for (int i = 0; i < points; ++i) {
    SweepSample sample;
    sample.s = -span + 2.0 * span * i / (points - 1);
    q[4] = sample.s;
    const Status status = solveHybridDynamics(model, ws, q, qd, tau, task);
    if (!status) throw std::runtime_error(status.message);
    sample.nu = ws.solution.nu;
    sample.residual = ws.solution.balance.residual;
    sample.damping = ws.solution.balance.damping;
    sample.consistent = ws.solution.balance.consistent;
    samples.push_back(sample);
  }
  return samples;
}

double largestStep(const std::vector<SweepSample>& samples) {
  double step = 0.0;
  for (std::size_t i = 1; i < samples.size(); ++i) step = std::max(step, (samples[i].nu - samples[i - 1].nu).norm());
  return step;
}

double largestNu(const std::vector<SweepSample>& samples) {
  double largest = 0.0;
  for (const SweepSample& s : samples) largest = std::max(largest, s.nu.norm());
  return largest;
}

}  // namespace

TEST_CASE("through a wrist singularity: ν bounded and continuous, the residual reported", "[sweep]") {
  const double span = 4e-3;  // σ̃_min ~ q5²: the ramp (σ̃ < 1e-6) spans |q5| ≲ 1e-3
  const std::vector<SweepSample> coarse = wristSweep(801, span, BalanceOptions{});
  const std::vector<SweepSample> fine = wristSweep(1601, span, BalanceOptions{});
  // Continuity by finite differences: a Lipschitz path's largest step halves
  // with the step; a jump would not shrink.
  const double step_coarse = largestStep(coarse), step_fine = largestStep(fine);
  INFO("largest |Δν|: step h " << step_coarse << ", step h/2 " << step_fine << "; largest |ν| " << largestNu(fine));
  CHECK(step_fine <= 0.6 * step_coarse);
  // Bounded: without the ramp (threshold just above the rank tolerance, the
  // plain pseudo-inverse) ν grows like 1/q5² as the wrist aligns.
  BalanceOptions undamped;
  undamped.singular_threshold = 2.0 * undamped.rank_tolerance;
  const double plain = largestNu(wristSweep(801, span, undamped));
  INFO("largest |ν| undamped " << plain);
  CHECK(largestNu(coarse) * 100.0 < plain);
  // Honest reporting: met away from the singularity, not met (and said so)
  // at it; the residual is continuous too.
  CHECK(fine.front().consistent);
  CHECK(fine.back().consistent);
  CHECK(fine.front().residual < 1e-10);
  const SweepSample& middle = fine[fine.size() / 2];
  CHECK(middle.s == 0.0);
  CHECK_FALSE(middle.consistent);
  CHECK(middle.residual > 1e-3);
  const auto residual_step = [](const std::vector<SweepSample>& samples) {
    double step = 0.0;
    for (std::size_t i = 1; i < samples.size(); ++i)
      step = std::max(step, std::abs(samples[i].residual - samples[i - 1].residual));
    return step;
  };
  CHECK(residual_step(fine) <= 0.6 * residual_step(coarse));
  // The figure of docs/solver.md: ZWANG_SINGULAR_CSV=<file> writes the path.
  if (const char* path = std::getenv("ZWANG_SINGULAR_CSV")) {
    std::ofstream csv(path);
    csv << "# q5 [rad], |nu| default [N, N·m], |nu| undamped, residual |A^T Xdd - b| default [m/s², rad/s²], "
           "residual undamped, damping (0..1)\n";
    const std::vector<SweepSample> plain_fine = wristSweep(1601, span, undamped);
    for (std::size_t i = 0; i < fine.size(); ++i)
      csv << fine[i].s << ' ' << fine[i].nu.norm() << ' ' << plain_fine[i].nu.norm() << ' ' << fine[i].residual << ' '
          << plain_fine[i].residual << ' ' << fine[i].damping << '\n';
  }
}

TEST_CASE("friction on a singular task: a held tip with stuck joints on a 5-joint arm stays held") {
  std::mt19937_64 rng(909);
  RandomChainOptions chain_options;
  chain_options.min_moving_joints = chain_options.max_moving_joints = 5;
  int tested = 0;
  double worst_tip = 0.0, worst_qdd = 0.0;
  for (int trial = 0; trial < 40; ++trial) {
    const ChainSpec spec = randomChain(rng, chain_options);
    const Model model = modelFromSpec(spec);
    Task task(model);
    const int tip = static_cast<int>(model.frames().size()) - 1;
    task.addConstraint(tip, ConstraintMatrix::Identity(6, 6), Expressed::World);
    Workspace ws(model, task);
    const Eigen::VectorXd q = randomVector(rng, 5, 2.5), qd = Eigen::VectorXd::Zero(5);
    const Eigen::VectorXd tau = randomVector(rng, 5, 2.0);
    REQUIRE(solveWithFriction(model, ws, q, qd, tau, task));
    REQUIRE(ws.friction.stuck.size() == 5u);
    // At rest the task (b = 0) is consistent: q̈ = 0 meets it, and the
    // joints, all stuck, have friction to spare for whatever the held tip
    // leaves free.
    const Vec6 a = accelerationOf(model, ws, tip, Expressed::World);
    INFO("trial " << trial << ", tip acceleration " << a.transpose() << ", q̈ " << ws.solution.qdd.transpose());
    CHECK(ws.solution.balance.singular);
    CHECK(ws.solution.balance.rank <= 5);
    CHECK(ws.solution.balance.consistent);
    CHECK(a.norm() < 1e-10);
    CHECK(ws.solution.qdd.norm() < 1e-10);
    worst_tip = std::max(worst_tip, a.norm());
    worst_qdd = std::max(worst_qdd, ws.solution.qdd.norm());
    ++tested;
  }
  WARN("held tip with friction, 5-joint arms: " << tested << " solves, tip acceleration at most " << worst_tip
                                                << ", |q̈| at most " << worst_qdd);
}

TEST_CASE("balance options out of range: clear errors") {
  const ChainSpec spec = planarArm();
  const Model model = modelFromSpec(spec);
  Task task(model);
  task.addConstraint("tip", ConstraintMatrix::Identity(6, 2));
  Workspace ws(model, task);
  const Eigen::Vector2d q(0.3, 0.4), qd(0.0, 0.0), tau(0.0, 0.0);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<std::pair<std::function<void(BalanceOptions&)>, std::string>> cases = {
      {[](BalanceOptions& o) { o.singular_threshold = 0.0; }, "singular_threshold 0 must be in (0, 1)"},
      {[](BalanceOptions& o) { o.singular_threshold = 1.0; }, "singular_threshold 1 must be in (0, 1)"},
      {[nan](BalanceOptions& o) { o.singular_threshold = nan; }, "singular_threshold nan must be in (0, 1)"},
      {[](BalanceOptions& o) { o.rank_tolerance = -1e-12; }, "rank_tolerance -1e-12 must be in [0, singular_threshold"},
      {[](BalanceOptions& o) { o.rank_tolerance = 1e-6; },
       "rank_tolerance 1e-06 must be in [0, singular_threshold = 1e-06)"},
      {[](BalanceOptions& o) { o.residual_tolerance = 0.0; }, "residual_tolerance 0 must be finite and positive"},
      {[](BalanceOptions& o) { o.residual_tolerance = std::numeric_limits<double>::infinity(); },
       "residual_tolerance inf must be finite and positive"},
  };
  for (const auto& [set, message] : cases) {
    task.balance = BalanceOptions{};
    set(task.balance);
    const Status plain = solveHybridDynamics(model, ws, q, qd, tau, task);
    INFO(plain.message);
    CHECK(plain.code == StatusCode::BadOption);
    CHECK(std::string(plain.message).find(message) != std::string::npos);
    const Status friction = solveWithFriction(model, ws, q, qd, tau, task);
    CHECK(friction.code == StatusCode::BadOption);
  }
}
