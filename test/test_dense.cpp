// The solver and the classic algorithms against the dense reference
// (test/support/dense_reference: world-frame Jacobians, H = Σ JᵀIJ, KKT solve),
// on random chains with mixed joint types, fixed joints, rotor inertias,
// wrenches and constraints on up to three frames.
#include <catch2/catch.hpp>
#include <cstdio>

#include "support/frame_values.hpp"
#include "support/random_chain.hpp"
#include "support/random_problem.hpp"

using namespace zwang;
using namespace zwang::testing;

namespace {

struct MaxError {
  double value = 0.0;
  void add(double e) { value = std::max(value, e); }
};

}  // namespace

TEST_CASE("hybrid dynamics matches the dense KKT solution on 500+ random chains") {
  std::mt19937_64 rng(20261122);
  MaxError qdd_err, nu_err, tauc_err, gauss_err, acc_err, closure_err;
  int accepted = 0, attempts = 0, constrained = 0, multi_frame = 0;
  while (accepted < 520) {
    ++attempts;
    REQUIRE(attempts < 2000);
    const ChainSpec spec = randomChain(rng);
    const DynamicsInput in = randomProblem(rng, spec);
    const DenseResult ref = denseDynamics(spec, in);
    if (!wellPosed(ref, in)) continue;
    ++accepted;
    if (in.constraintRows() > 0) ++constrained;
    if (in.constraints.size() > 1) ++multi_frame;

    const Model model = modelFromSpec(spec);
    const Task task = taskFromInput(model, in);
    Workspace ws(model, task);
    const Status status = solveHybridDynamics(model, ws, in.q, in.qd, in.tau, task);
    INFO("chain " << accepted << ": " << spec.dof() << " dof, " << in.constraintRows() << " rows; " << status.message);
    REQUIRE(status.ok());
    const Solution& s = ws.solution;
    CHECK_FALSE(s.balance.singular);
    qdd_err.add(relativeError(s.qdd, ref.qdd));
    nu_err.add(relativeError(s.nu, ref.nu));
    tauc_err.add(relativeError(s.tau_constraint, ref.tau_c));
    gauss_err.add(std::abs(s.gauss - ref.gauss) / std::max(1.0, std::abs(ref.gauss)));
    for (std::size_t l = 0; l < spec.links.size(); ++l) {
      const int frame = model.frameIndex(spec.links[l].name);
      acc_err.add(relativeError(accelerationOf(model, ws, frame, Expressed::Local), ref.acc_local[l]));
      acc_err.add(relativeError(accelerationOf(model, ws, frame, Expressed::World), ref.acc_world[l]));
    }

    // Closure (docs/solver.md, "Constraint torques: why not eq. 4.4"): the
    // unconstrained arm driven by τ_ctrl and the same wrenches accelerates with exactly q̈.
    DynamicsInput free_input = in;
    free_input.constraints.clear();
    const Task free_task = taskFromInput(model, free_input);
    const Eigen::VectorXd qdd = s.qdd, tau_control = s.tau_control;
    REQUIRE(solveHybridDynamics(model, ws, in.q, in.qd, tau_control, free_task));
    closure_err.add(relativeError(ws.solution.qdd, qdd));
  }
  std::printf(
      "dense reference, %d chains (%d constrained, %d on 2-3 frames, %d draws skipped as ill-conditioned):\n"
      "  max rel. error  qdd %.2e  nu %.2e  tau_c %.2e  Z %.2e  frame acc %.2e  closure %.2e\n",
      accepted, constrained, multi_frame, attempts - accepted, qdd_err.value, nu_err.value, tauc_err.value,
      gauss_err.value, acc_err.value, closure_err.value);
  CHECK(constrained > 300);
  CHECK(multi_frame > 100);
  CHECK(qdd_err.value < 1e-9);
  CHECK(nu_err.value < 1e-9);
  CHECK(tauc_err.value < 1e-9);
  CHECK(gauss_err.value < 1e-9);
  CHECK(acc_err.value < 1e-9);
  CHECK(closure_err.value < 1e-9);
}

TEST_CASE("RNEA, CRBA, Jacobians and poses match the dense reference") {
  std::mt19937_64 rng(77);
  MaxError rnea_err, crba_err, jac_err, pose_err;
  for (int trial = 0; trial < 200; ++trial) {
    RandomInverseDynamics c(rng);
    const ChainSpec& spec = c.spec;
    const DynamicsInput& in = c.in;
    const Model& model = c.model;
    Workspace& ws = c.ws;
    const Eigen::VectorXd& qdd = c.qdd;
    REQUIRE(c.solve());
    rnea_err.add(relativeError(ws.tau, denseInverseDynamics(spec, in.q, in.qd, qdd, in.gravity, in.wrenches)));

    const DenseKinematics kin = denseKinematics(spec, in.q, in.qd);
    const DenseResult ref = denseDynamics(spec, in);
    REQUIRE(jointSpaceInertia(model, ws, in.q));
    crba_err.add((ws.H - ref.H).cwiseAbs().maxCoeff() / std::max(1.0, ref.H.cwiseAbs().maxCoeff()));

    Eigen::MatrixXd J(6, spec.dof());
    for (std::size_t l = 0; l < spec.links.size(); ++l) {
      const int frame = model.frameIndex(spec.links[l].name);
      for (Axes axes : {Axes::Local, Axes::World}) {
        REQUIRE(frameJacobian(model, ws, in.q, frame, axes == Axes::Local ? Expressed::Local : Expressed::World, J));
        const Eigen::MatrixXd Jref = linkJacobian(spec, in.q, spec.links[l].name, axes);
        jac_err.add((J - Jref).cwiseAbs().maxCoeff());
      }
      const Eigen::Isometry3d T = poseOf(model, ws, frame);
      pose_err.add((T.matrix() - kin.poses[l].matrix()).cwiseAbs().maxCoeff());
    }
  }
  std::printf(
      "dense reference, 200 chains: max rel. error RNEA %.2e  CRBA %.2e; max abs. error Jacobian %.2e  pose %.2e\n",
      rnea_err.value, crba_err.value, jac_err.value, pose_err.value);
  CHECK(rnea_err.value < 1e-10);
  CHECK(crba_err.value < 1e-10);
  CHECK(jac_err.value < 1e-10);
  CHECK(pose_err.value < 1e-10);
}

TEST_CASE("constraint columns of any length: a column scaled by c scales its row and divides its nu by c") {
  // docs/conventions.md, "Constraints": the columns need not be unit. Column
  // c·a with set point c·b is the same constraint as a with b: the same q̈ and
  // τ_c, and ν along c·a is ν/c. Checked on random chains against the
  // unscaled solve and against the dense KKT solution of the unscaled task.
  std::mt19937_64 rng(20261126);
  std::uniform_real_distribution<double> log_scale(-3.0, 3.0);  // c from 1e-3 to 1e3
  MaxError qdd_err, tauc_err, nu_err;
  int accepted = 0, attempts = 0;
  while (accepted < 200) {
    ++attempts;
    REQUIRE(attempts < 2000);
    const ChainSpec spec = randomChain(rng);
    const DynamicsInput in = randomProblem(rng, spec);
    if (in.constraintRows() == 0) continue;
    const DenseResult ref = denseDynamics(spec, in);
    if (!wellPosed(ref, in)) continue;
    ++accepted;
    DynamicsInput scaled = in;
    Eigen::VectorXd c(in.constraintRows());
    int row = 0;
    for (ConstraintInput& k : scaled.constraints)
      for (Eigen::Index j = 0; j < k.A.cols(); ++j, ++row) {
        c[row] = std::pow(10.0, log_scale(rng));
        k.A.col(j) *= c[row];
        k.b[j] *= c[row];
      }
    const Model model = modelFromSpec(spec);
    const Task task = taskFromInput(model, scaled);
    Workspace ws(model, task);
    REQUIRE(solveHybridDynamics(model, ws, in.q, in.qd, in.tau, task));
    const Solution& s = ws.solution;
    qdd_err.add(relativeError(s.qdd, ref.qdd));
    tauc_err.add(relativeError(s.tau_constraint, ref.tau_c));
    nu_err.add(relativeError(s.nu.head(row).cwiseProduct(c), ref.nu.head(row)));
  }
  std::printf("columns scaled by 1e-3..1e3, %d chains: max rel. error qdd %.2e, tau_c %.2e, c*nu %.2e\n", accepted,
              qdd_err.value, tauc_err.value, nu_err.value);
  CHECK(qdd_err.value < 1e-9);
  CHECK(tauc_err.value < 1e-9);
  CHECK(nu_err.value < 1e-9);
}
