// docs/getting-started.md: the Panda holds its tool still under gravity.
#include <cmath>
#include <cstdio>
#include <zwang/zwang.hpp>

int main(int argc, char** argv) {
  const zwang::Model model = zwang::loadUrdfFile(argc > 1 ? argv[1] : "models/panda.urdf");
  zwang::Task task(model);  // gravity (0, 0, -9.81) by default
  task.addConstraint("tool0", zwang::ConstraintMatrix::Identity(6, 6), zwang::Expressed::World);
  task.targets().setZero();  // tool0's true acceleration: zero in all six directions
  zwang::Workspace ws(model, task);  // all scratch memory, allocated once

  Eigen::VectorXd q(7), qd = Eigen::VectorXd::Zero(7), tau = Eigen::VectorXd::Zero(7);
  q << 0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785;  // the "ready" pose, at rest

  zwang::Status status = zwang::solveHybridDynamics(model, ws, q, qd, tau, task);  // no friction
  if (!status) return std::fprintf(stderr, "%s\n", status.message), 1;
  const Eigen::VectorXd plain = ws.solution.tau_control, plain_qdd = ws.solution.qdd;  // τ_control = τ + τ_c

  status = zwang::solveWithFriction(model, ws, q, qd, tau, task);  // static friction used
  if (!status) return std::fprintf(stderr, "%s\n", status.message), 1;
  auto clean = [](double x) { return std::abs(x) < 1e-9 ? 0.0 : x; };  // rounding noise shown as 0
  std::printf("joint         plain: qdd   tau_control | with friction: qdd   tau_control       mu  state\n");
  for (int j = 0; j < model.dof(); ++j)
    std::printf("%-13s %10.4f %13.4f | %19.4f %13.4f %8.4f  %s\n", model.joint(j).name.c_str(), clean(plain_qdd[j]),
                clean(plain[j]), clean(ws.solution.qdd[j]), clean(ws.solution.tau_control[j]), clean(ws.friction.mu[j]),
                zwang::toString(ws.friction.state[j]));
  std::printf("|tau|^2: %.1f plain, %.1f with friction; rank %d, singular %s, indeterminate %s\n",
              plain.squaredNorm(), ws.solution.tau_control.squaredNorm(), ws.solution.balance.rank,
              ws.solution.balance.singular ? "yes" : "no", ws.friction.indeterminate ? "yes" : "no");
}
