// The main demo: the Franka Panda at rest under gravity, asked to hold its
// tool still (all six tool accelerations zero). Prints the motion the Gauss
// principle picks (the tool stays, the redundant elbow may move), the
// constraint wrench ν at the tool, and the motor torques.
//
//   zwang_demo [model.urdf [tool_frame]]
#include <cstdio>
#include <string>

#include "zwang/zwang.hpp"

namespace {

void printVector(const char* label, const Eigen::VectorXd& x) {
  std::printf("  %-28s", label);
  for (Eigen::Index k = 0; k < x.size(); ++k) std::printf(" %9.4f", x[k]);
  std::printf("\n");
}

}  // namespace

int main(int argc, char** argv) {
  const std::string path = argc > 1 ? argv[1] : std::string(ZWANG_MODELS_DIR) + "/panda.urdf";
  const std::string tool = argc > 2 ? argv[2] : "tool0";
  try {
    const zwang::Model model = zwang::loadUrdfFile(path);
    const int n = model.dof();

    // The task: keep the tool's classical acceleration (world axes) at zero.
    zwang::Task task(model);
    task.addConstraint(tool, zwang::ConstraintMatrix::Identity(6, 6), zwang::Expressed::World);
    zwang::Workspace ws(model, task);

    // A typical "ready" pose of the Panda (joint 4 bent, joint 6 up), at rest.
    Eigen::VectorXd q = Eigen::VectorXd::Zero(n);
    if (n == 7) q << 0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785;
    const Eigen::VectorXd qd = Eigen::VectorXd::Zero(n), tau = Eigen::VectorXd::Zero(n);

    const zwang::Status status = zwang::solveHybridDynamics(model, ws, q, qd, tau, task);
    if (!status) {
      std::fprintf(stderr, "zwang_demo: %s\n", status.message);
      return 1;
    }
    const zwang::Solution& s = ws.solution;
    const int tool_frame = model.frameIndex(tool);
    Eigen::Isometry3d pose;
    zwang::Vec6 a_tool;
    zwang::Status read = zwang::framePose(model, ws, q, tool_frame, pose);
    if (read) read = zwang::frameAcceleration(model, ws, q, qd, tool_frame, zwang::Expressed::World, a_tool);
    if (!read) {
      std::fprintf(stderr, "zwang_demo: %s\n", read.message);
      return 1;
    }
    const Eigen::Vector3d p = pose.translation();
    std::printf("zwang demo: %s (%d joints), hold '%s' still under gravity\n", model.name().c_str(), n, tool.c_str());
    std::printf("  tool position [m]            %9.4f %9.4f %9.4f\n", p.x(), p.y(), p.z());
    printVector("q [rad]", q);
    printVector("qdd [rad/s^2]", s.qdd);
    printVector("nu (tool wrench, world)", s.nu);
    printVector("tau_constraint [Nm]", s.tau_constraint);
    printVector("tau_control [Nm]", s.tau_control);
    std::printf("  tool acceleration (check 0)  %9.2e\n", a_tool.norm());
    std::printf("  Gauss function Z            %9.4f\n", s.gauss);
    std::printf("  balance (line 25): rows %d, rank %d, condition %.3g, damping %.3g, singular %s\n", s.balance.rows,
                s.balance.rank, s.balance.condition, s.balance.damping, s.balance.singular ? "yes" : "no");

    // For comparison: holding every joint still takes the gravity torques.
    zwang::Task free_task(model);
    if (zwang::inverseDynamics(model, ws, q, qd, qd, free_task)) printVector("gravity torques (RNEA) [Nm]", ws.tau);
  } catch (const zwang::ModelError& e) {
    std::fprintf(stderr, "zwang_demo: %s\n", e.what());
    return 1;
  }
  return 0;
}
