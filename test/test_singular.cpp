// Singular tasks: more independent constraints than the robot has joints, a
// stretched-out arm, redundant rows and constraints on the fixed base. The
// results stay finite, the coupling matrix says it is singular, and the
// constraints hold in the least-squares sense (compared with the dense
// reference's G q̈ = γ).
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <catch2/catch.hpp>

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
    REQUIRE(solveHybridDynamics(model, task, in.q, in.qd, in.tau, ws));
    const Solution& s = ws.solution;
    CHECK(allFinite(s));
    CHECK(s.coupling.singular);
    CHECK(s.coupling.rank <= spec.dof());
    CHECK((s.coupling.damping > 0.0 || s.coupling.rank == 0));  // rank 0: nothing to damp
    const auto [ours, best] = residuals(ref, s.qdd);
    INFO("residual ours " << ours << " least squares " << best);
    CHECK(ours <= best * (1.0 + 1e-6) + 1e-6);
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
  REQUIRE(solveHybridDynamics(model, task, in.q, in.qd, in.tau, ws));
  const Solution& s = ws.solution;
  CHECK(allFinite(s));
  CHECK(s.coupling.singular);
  CHECK(s.coupling.rank == 1);
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
  REQUIRE(solveHybridDynamics(model, task, Eigen::Vector2d(0.2, 0.9), Eigen::Vector2d(0.1, -0.3),
                              Eigen::Vector2d::Zero(), ws));
  CHECK(ws.solution.coupling.singular);
  CHECK(ws.solution.coupling.rank == 1);
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
  REQUIRE(solveHybridDynamics(model, free_task, q, qd, tau, ws));
  const Eigen::VectorXd free_qdd = ws.solution.qdd;
  REQUIRE(solveHybridDynamics(model, task, q, qd, tau, ws));
  CHECK(ws.solution.coupling.singular);
  CHECK(ws.solution.coupling.rank == 0);
  CHECK(ws.solution.nu.norm() == 0.0);
  CHECK((ws.solution.qdd - free_qdd).norm() < 1e-12);
}

TEST_CASE("coupling diagnostics: Frobenius condition number of 𝓛 against the dense G H⁻¹ Gᵀ") {
  // 𝓛 is the dense G H⁻¹ Gᵀ up to a permutation of rows (solver order), so
  // κ_F = ‖𝓛‖_F ‖𝓛⁻¹‖_F must match whichever way the solver factored it.
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
    const Eigen::MatrixXd Ls = 0.5 * (Ld + Ld.transpose());
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Ls);
    const double lmin = eig.eigenvalues().minCoeff(), lmax = eig.eigenvalues().maxCoeff();
    if (!(lmin > 1e-7 * lmax)) continue;  // the dense reference itself loses digits beyond that
    ++tested;
    const double kappa_f = Ls.norm() * Ls.inverse().norm();
    const Model model = modelFromSpec(spec);
    const Task task = taskFromInput(model, in);
    Workspace ws(model, task);
    REQUIRE(solveHybridDynamics(model, task, in.q, in.qd, in.tau, ws));
    const CouplingDiagnostics& d = ws.solution.coupling;
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
