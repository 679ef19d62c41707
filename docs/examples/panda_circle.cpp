// docs/controller.md: the Panda's tool draws a circle at 1 kHz. Each cycle a PD
// law on the tool's position and pointing direction sets the task's true
// accelerations, joint 7 is prescribed (the solver returns its torque), a
// posture torque acts in the null space, solveWithFriction finds the motion
// and the motor torques, and semi-implicit Euler integrates it.
//   panda_circle [--model PATH] [--csv PATH] [--duration S] [--max-error M]
// --max-error: exit 1 when the tracking error after the first 0.2 s exceeds M
// (the test's bound); a failed solve or a joint outside its limits always does.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <zwang/zwang.hpp>

namespace {

struct Options {
  std::string model = "models/panda.urdf";
  std::string csv = (std::filesystem::temp_directory_path() / "panda_circle.csv").string();
  double duration = 4.0;        // [s]
  double max_error = HUGE_VAL;  // [m]
};

bool parse(int argc, char** argv, Options& o) {
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--model"))
      o.model = argv[i + 1];
    else if (!std::strcmp(argv[i], "--csv"))
      o.csv = argv[i + 1];
    else if (!std::strcmp(argv[i], "--duration"))
      o.duration = std::atof(argv[i + 1]);
    else if (!std::strcmp(argv[i], "--max-error"))
      o.max_error = std::atof(argv[i + 1]);
    else
      return false;
  }
  return argc % 2 == 1;
}

}  // namespace

int main(int argc, char** argv) {
  Options opt;
  if (!parse(argc, argv, opt)) {
    std::fprintf(stderr, "usage: panda_circle [--model PATH] [--csv PATH] [--duration S] [--max-error M]\n");
    return 2;
  }
  const zwang::Model model = zwang::loadUrdfFile(opt.model);
  const int n = model.nv(), tool = model.frameIndex("tool0"), j7 = model.jointIndex("panda_joint7");
  const double dt = 1e-3;  // 1 kHz

  // Rows on the tool: its origin's position (3 rows, world axes) and the
  // direction of its z axis (2 rows: angular x and y in the tool's own axes).
  // The spin about the tool axis is left free: 7 joints − 1 prescribed − 5
  // rows leave one DOF of null space for the posture (with all 6 rows none).
  zwang::Task task(model);
  zwang::ConstraintMatrix A_pos = zwang::ConstraintMatrix::Zero(6, 3), A_dir = zwang::ConstraintMatrix::Zero(6, 2);
  A_pos.topRows<3>().setIdentity();
  A_dir(3, 0) = A_dir(4, 1) = 1.0;
  const int pos_row = task.addConstraint(tool, A_pos, zwang::Expressed::World);
  const int dir_row = task.addConstraint(tool, A_dir, zwang::Expressed::Local);
  task.prescribe(j7);
  zwang::Workspace ws(model, task);
  zwang::Workspace ws_gravity(model);  // a second workspace: g(q) must not replace the state ws holds

  Eigen::VectorXd q(n), qd = Eigen::VectorXd::Zero(n), tau(n), g(n), zero = Eigen::VectorXd::Zero(n);
  q << 0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785;  // "ready": tool pointing down, in front of the base
  const Eigen::VectorXd q_rest = q;

  // The set points: a circle of radius r at f Hz in the vertical plane x =
  // const through the start, starting at its point nearest the base's axis;
  // the tool keeps its start orientation; joint 7 swings by 2a.
  zwang::Status status = zwang::forwardKinematics(model, ws, q);
  Eigen::Isometry3d pose;
  if (status) status = zwang::framePose(model, ws, q, tool, pose);
  if (!status) return std::fprintf(stderr, "%s\n", status.message), 1;
  const Eigen::Vector3d start = pose.translation(), center = start + Eigen::Vector3d(0.0, 0.05, 0.0);
  const Eigen::Matrix3d R_desired = pose.linear();
  const double pi = std::acos(-1.0), r = 0.05, w = 2.0 * pi * 0.5, ramp = 0.5, a7 = 0.2, w7 = 2.0 * pi * 0.25,
               q7_0 = q[j7];

  // Gains: critically damped, 20 rad/s on the task, 30 rad/s on joint 7; the
  // posture's stiffness is soft so that it only steers the elbow.
  const double kp = 400.0, kd = 40.0, kp7 = 900.0, kd7 = 60.0, k_rest = 20.0, d_rest = 5.0;

  std::FILE* csv = std::fopen(opt.csv.c_str(), "w");
  if (!csv) return std::fprintf(stderr, "cannot write %s\n", opt.csv.c_str()), 1;
  std::fprintf(csv, "t,position_error,direction_error,effort\n");

  const int steps = static_cast<int>(std::lround(opt.duration / dt));
  double max_error = 0.0, max_dir_error = 0.0, effort_sum = 0.0, solve_us_sum = 0.0, solve_us_max = 0.0;
  double cycle_us_sum = 0.0, cycle_us_max = 0.0;
  int limit_violations = 0;
  for (int k = 0; k < steps; ++k) {
    const double t = k * dt;
    const auto cycle_start = std::chrono::steady_clock::now();

    // The state: the tool's pose and classical velocity [v; ω], world axes.
    zwang::Vec6 v;
    status = zwang::forwardKinematics(model, ws, q, qd);
    if (status) status = zwang::framePose(model, ws, q, tool, pose);
    if (status) status = zwang::frameVelocity(model, ws, q, qd, tool, zwang::Expressed::World, v);
    // Gravity in the null space: its component along the rows is the solver's.
    if (status) status = zwang::inverseDynamics(model, ws_gravity, q, zero, zero);
    if (!status) return std::fprintf(stderr, "t = %.3f: %s\n", t, status.message), 1;
    g = ws_gravity.tau;

    // Set point + feedback = the rows' true accelerations (the solver adds J̇q̇).
    // The phase θ speeds up smoothly to w over the first ramp seconds, so
    // that the set point starts at rest, as the robot does.
    const double tau_r = std::min(t / ramp, 1.0);
    const double th =
        t < ramp ? w * ramp * (tau_r * tau_r * tau_r - 0.5 * tau_r * tau_r * tau_r * tau_r) : w * (t - 0.5 * ramp);
    const double thd = w * tau_r * tau_r * (3.0 - 2.0 * tau_r), thdd = w / ramp * 6.0 * tau_r * (1.0 - tau_r);
    const Eigen::Vector3d radial(0.0, -std::cos(th), std::sin(th)), tangent(0.0, std::sin(th), std::cos(th));
    const Eigen::Vector3d p_d = center + r * radial, v_d = r * thd * tangent;
    const Eigen::Vector3d a_d = r * thdd * tangent - r * thd * thd * radial;
    const Eigen::Vector3d e_p = p_d - pose.translation();
    const Eigen::Vector3d e_o = zwang::orientationError(pose.linear(), R_desired);  // world axes
    task.targets().segment<3>(pos_row) = a_d + kp * e_p + kd * (v_d - v.head<3>());
    const Eigen::Vector3d alpha = kp * e_o - kd * v.tail<3>();  // world axes; ω_d = 0
    task.targets().segment<2>(dir_row) = (pose.linear().transpose() * alpha).head<2>();

    // Joint 7 follows q7_0 + a(1 − cos w7 t): prescribed, the solve returns its torque.
    const double q7_d = q7_0 + a7 * (1.0 - std::cos(w7 * t)), qd7_d = a7 * w7 * std::sin(w7 * t);
    task.prescribedAccelerations()[j7] =
        a7 * w7 * w7 * std::cos(w7 * t) + kp7 * (q7_d - q[j7]) + kd7 * (qd7_d - qd[j7]);

    // Posture: gravity and a damped pull to rest, acting in the null space.
    tau = g - d_rest * qd - k_rest * (q - q_rest);

    const auto solve_start = std::chrono::steady_clock::now();
    status = zwang::solveWithFriction(model, ws, q, qd, tau, task);
    const auto solve_end = std::chrono::steady_clock::now();
    if (!status) return std::fprintf(stderr, "t = %.3f: %s\n", t, status.message), 1;
    const double solve_us = std::chrono::duration<double, std::micro>(solve_end - solve_start).count();
    const double cycle_us = std::chrono::duration<double, std::micro>(solve_end - cycle_start).count();
    solve_us_sum += solve_us, solve_us_max = std::max(solve_us_max, solve_us);
    cycle_us_sum += cycle_us, cycle_us_max = std::max(cycle_us_max, cycle_us);

    // The pointing error: the tilt of the tool axis (its spin is free).
    const double dir_error = std::hypot((pose.linear().transpose() * e_o)[0], (pose.linear().transpose() * e_o)[1]);
    const double effort = ws.solution.tau_control.squaredNorm();
    std::fprintf(csv, "%.3f,%.6e,%.6e,%.6e\n", t, e_p.norm(), dir_error, effort);
    if (t >= 0.2) max_error = std::max(max_error, e_p.norm()), max_dir_error = std::max(max_dir_error, dir_error);
    effort_sum += effort;

    // Semi-implicit Euler: the new velocity moves the configuration.
    qd += ws.solution.qdd * dt;
    status = zwang::integrate(model, q, qd, dt, q);
    if (!status) return std::fprintf(stderr, "t = %.3f: %s\n", t, status.message), 1;
    for (int j = 0; j < n; ++j)
      if (q[j] < model.joint(j).lower || q[j] > model.joint(j).upper) ++limit_violations;
  }
  std::fclose(csv);

  std::printf("%d cycles at 1 kHz (%.1f s); data in %s\n", steps, steps * dt, opt.csv.c_str());
  std::printf("max tracking error after 0.2 s: position %.3e m, tool axis %.3e rad\n", max_error, max_dir_error);
  std::printf("RMS effort |tau_control|: %.2f N m\n", std::sqrt(effort_sum / steps));
  std::printf("solveWithFriction: mean %.1f us, max %.1f us; whole cycle: mean %.1f us, max %.1f us\n",
              solve_us_sum / steps, solve_us_max, cycle_us_sum / steps, cycle_us_max);
  std::printf("joint samples outside their limits: %d\n", limit_violations);
  if (limit_violations > 0 || max_error > opt.max_error) return std::fprintf(stderr, "FAILED a bound\n"), 1;
}
