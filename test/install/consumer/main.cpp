// Uses the installed zwang: load the 1-DOF arm, push it, check q̈ = τ / I.
#include <cmath>
#include <cstdio>
#include <zwang/zwang.hpp>

static_assert(ZWANG_VERSION_AT_LEAST(0, 2, 0), "the installed version.hpp is read");

int main(int argc, char** argv) {
  if (argc < 2) return 2;
  const zwang::Model model = zwang::loadUrdfFile(argv[1]);
  zwang::Task task(model);
  task.gravity.setZero();
  zwang::Workspace ws(model, task);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(1), tau = Eigen::VectorXd::Constant(1, 4.5);
  const zwang::Status status = zwang::solveHybridDynamics(model, ws, zero, zero, tau, task);
  if (!status) {
    std::printf("solve failed: %s\n", status.message);
    return 1;
  }
  std::printf("qdd = %.12f (expected 2)\n", ws.solution.qdd[0]);
  if (std::abs(ws.solution.qdd[0] - 2.0) >= 1e-12) return 1;
  // The same by the unconstrained solve's name: gravity along the axis or not, τ / I again with zero gravity.
  if (!zwang::forwardDynamics(model, ws, zero, zero, tau, task)) return 1;
  return std::abs(ws.solution.qdd[0] - 2.0) < 1e-12 ? 0 : 1;
}
