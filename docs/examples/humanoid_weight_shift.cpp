// docs/controller.md: the humanoid, standing on both feet, shifts its weight
// over its right foot at 1 kHz, once with plain hybrid dynamics and once
// friction-aware, and prints the motor effort of both.
// The feet are contacts (the ground's force); the right leg's hip and ankle
// roll are prescribed together (a parallelogram: the pelvis moves sideways and
// stays level, the feet stay flat) with the acceleration a PD law on the
// centre of mass asks for; the other leg joints are held by their motors
// (joint rows), except the left leg's two roll joints, which the closed loop
// through the ground moves.
//   humanoid_weight_shift [--model PATH] [--duration S] [--upper-body-rows] [--check]
// The upper body (waist, chest, arms) is held where it started by prescribed
// accelerations, or with --upper-body-rows by joint rows.
// --check: exit 1 unless the feet stayed still, the COM reached its target and
// no joint left its limits (the test's bounds).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <tuple>
#include <utility>
#include <vector>
#include <zwang/zwang.hpp>

namespace {

struct Run {
  double effort = 0.0;       // ∫‖τ_control‖² dt [N²m²s]
  double com_error = 0.0;    // |c_y − target| at the end [m]
  double foot_drift = 0.0;   // largest distance of a foot from where it started [m]
  double foot_acc = 0.0;     // largest |Ẍ − b| of a contact row [m/s², rad/s²]
  int limit_violations = 0;  // joint samples outside their limits
  double mean_us = 0.0, max_us = 0.0;
  bool ok = true;
};

// Breakaway friction per joint (the URDF has none): docs/evaluation.md, section 4.
double breakaway(const std::string& joint) {
  if (joint.find("WRIST") != std::string::npos) return 0.5;
  if (joint.find("SHOULDER") != std::string::npos || joint.find("ELBOW") != std::string::npos) return 2.0;
  return 5.0;
}

void setJoint(const zwang::Model& model, Eigen::VectorXd& q, const char* name, double value) {
  q[model.joint(model.jointIndex(name)).q_index] = value;
}

// The standing posture of docs/evaluation.md ("upright"), on the ground.
Eigen::VectorXd upright(const zwang::Model& model, zwang::Workspace& ws, const std::vector<int>& feet, double roll) {
  Eigen::VectorXd q(model.nq());
  zwang::neutralConfiguration(model, q);
  for (const char* leg : {"LLEG_", "RLEG_"}) {
    const std::string l(leg);
    setJoint(model, q, (l + "HIP_P").c_str(), -0.12);
    setJoint(model, q, (l + "KNEE").c_str(), 0.06);
    setJoint(model, q, (l + "ANKLE_P").c_str(), 0.06);
    setJoint(model, q, (l + "HIP_R").c_str(), roll);
    setJoint(model, q, (l + "ANKLE_R").c_str(), -roll);
  }
  for (const char* name : {"LARM_SHOULDER_R", "RARM_SHOULDER_R"}) setJoint(model, q, name, 0.1);
  for (const char* name : {"LARM_ELBOW", "RARM_ELBOW", "LARM_WRIST_Y", "RARM_WRIST_Y"}) setJoint(model, q, name, -0.1);
  double distance = 0.0;
  zwang::placeOnPlane(model, ws, q, feet, 0.0, zwang::PlaneContact::All, q, distance);
  return q;
}

// The COM's sideways position relative to the right foot.
double comOverFoot(const zwang::Model& model, zwang::Workspace& ws, const Eigen::VectorXd& q, int foot) {
  zwang::Vec3 c;
  Eigen::Isometry3d pose;
  zwang::forwardKinematics(model, ws, q);
  zwang::centerOfMass(model, ws, q, zwang::kWholeRobot, c);
  zwang::framePose(model, ws, q, foot, pose);
  return c.y() - pose.translation().y();
}

Run simulate(const zwang::Model& model, double duration, bool with_friction, bool upper_rows) {
  const int l_foot = model.frameIndex("l_ankle"), r_foot = model.frameIndex("r_ankle");
  const int hip = model.jointIndex("RLEG_HIP_R"), ankle = model.jointIndex("RLEG_ANKLE_R");
  const int hip_v = model.joint(hip).v_index, ankle_v = model.joint(ankle).v_index;
  zwang::Task task(model);
  const int l_row = task.addContact(l_foot, zwang::ConstraintMatrix::Identity(6, 6), zwang::Expressed::World);
  const int r_row = task.addContact(r_foot, zwang::ConstraintMatrix::Identity(6, 6), zwang::Expressed::World);
  task.prescribe(hip);
  task.prescribe(ankle);
  struct Held {
    int row, q_index, v_index;
  };
  std::vector<Held> held;
  for (int j = 0; j < static_cast<int>(model.joints().size()); ++j) {
    const std::string& name = model.joint(j).name;
    if (j == hip || j == ankle || name == "LLEG_HIP_R" || name == "LLEG_ANKLE_R") continue;
    // The upper body is off the loop: prescribed it costs no row of the
    // balance; held by rows, its motors' torques are friction's to share.
    if (!upper_rows && name.find("LEG") == std::string::npos) {
      task.prescribe(j);
      held.push_back({-1, model.joint(j).q_index, model.joint(j).v_index});
    } else {
      held.push_back({task.addJointConstraint(j), model.joint(j).q_index, model.joint(j).v_index});
    }
  }
  zwang::Workspace ws(model, task);
  zwang::FrictionOptions friction;
  friction.breakaway.resize(static_cast<int>(model.joints().size()));  // one per joint
  for (int j = 0; j < friction.breakaway.size(); ++j) friction.breakaway[j] = breakaway(model.joint(j).name);

  // dc_y/dφ of the parallelogram, by a finite difference, to scale the COM law.
  const std::vector<int> feet{l_foot, r_foot};
  Eigen::VectorXd q = upright(model, ws, feet, 0.0);
  const double eps = 1e-6;
  const double c0 = comOverFoot(model, ws, q, r_foot);
  const double gain = (comOverFoot(model, ws, upright(model, ws, feet, eps), r_foot) - c0) / eps;
  const Eigen::VectorXd q_start = q;
  Eigen::VectorXd qd = Eigen::VectorXd::Zero(model.nv()), tau = Eigen::VectorXd::Zero(model.nv());
  Eigen::Isometry3d l_start, r_start, pose;
  zwang::forwardKinematics(model, ws, q);
  zwang::framePose(model, ws, q, l_foot, l_start);
  zwang::framePose(model, ws, q, r_foot, r_start);

  // The COM follows a minimum-jerk path to over the right foot in 1.5 s.
  const double dt = 1e-3, shift_time = 1.5, kp = 100.0, kd = 20.0, kp_joint = 400.0, kd_joint = 40.0;
  const double kp_foot = 400.0, kd_foot = 40.0;  // drift correction of the contacts
  Run run;
  const int steps = static_cast<int>(std::lround(duration / dt));
  double effort = 0.0, us_sum = 0.0;
  for (int k = 0; k < steps; ++k) {
    const double t = k * dt, s = std::min(t / shift_time, 1.0);
    const double c_ref = c0 * (1.0 - (10 * s * s * s - 15 * s * s * s * s + 6 * s * s * s * s * s));
    const double v_ref = t < shift_time ? -c0 * (30 * s * s - 60 * s * s * s + 30 * s * s * s * s) / shift_time : 0.0;
    const double a_ref =
        t < shift_time ? -c0 * (60 * s - 180 * s * s + 120 * s * s * s) / (shift_time * shift_time) : 0.0;

    zwang::Vec3 c, cd;
    zwang::Vec6 v;
    Eigen::Isometry3d r_pose;
    zwang::forwardKinematics(model, ws, q, qd);
    zwang::centerOfMass(model, ws, q, zwang::kWholeRobot, c);
    zwang::centerOfMassVelocity(model, ws, q, qd, zwang::kWholeRobot, cd);
    zwang::framePose(model, ws, q, r_foot, r_pose);
    const double c_y = c.y() - r_pose.translation().y();

    // The feet: zero acceleration, plus a PD pull back to where they started.
    for (const auto& [row, frame, start] :
         {std::make_tuple(l_row, l_foot, &l_start), std::make_tuple(r_row, r_foot, &r_start)}) {
      zwang::framePose(model, ws, q, frame, pose);
      zwang::frameVelocity(model, ws, q, qd, frame, zwang::Expressed::World, v);
      zwang::Vec6 e;
      e << start->translation() - pose.translation(), zwang::orientationError(pose.linear(), start->linear());
      task.targets().segment<6>(row) = kp_foot * e - kd_foot * v;
    }
    for (const Held& h : held)
      (h.row < 0 ? task.prescribedAccelerations()[h.v_index] : task.targets()[h.row]) =
          kp_joint * (q_start[h.q_index] - q[h.q_index]) - kd_joint * qd[h.v_index];
    // The COM law, turned into the parallelogram's φ̈ by dc_y/dφ.
    const double phi_dd = (a_ref + kp * (c_ref - c_y) + kd * (v_ref - cd.y())) / gain;
    task.prescribedAccelerations()[hip_v] = phi_dd;
    task.prescribedAccelerations()[ankle_v] = -phi_dd;

    const auto start = std::chrono::steady_clock::now();
    const zwang::Status status = with_friction ? zwang::solveWithFriction(model, ws, q, qd, tau, task, friction)
                                               : zwang::solveHybridDynamics(model, ws, q, qd, tau, task);
    const double us = std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
    us_sum += us, run.max_us = std::max(run.max_us, us);
    if (!status) {
      std::fprintf(stderr, "t = %.3f: %s\n", t, status.message);
      run.ok = false;
      return run;
    }
    effort += ws.solution.tau_control.squaredNorm() * dt;
    for (const auto& [row, frame] : {std::make_pair(l_row, l_foot), std::make_pair(r_row, r_foot)}) {
      zwang::Vec6 a;
      zwang::frameAcceleration(model, ws, q, qd, frame, zwang::Expressed::World, a);
      run.foot_acc = std::max(run.foot_acc, (a - task.targets().segment<6>(row)).cwiseAbs().maxCoeff());
    }
    if (k == steps - 1) run.com_error = std::abs(c_y);

    qd += ws.solution.qdd * dt;  // semi-implicit Euler
    zwang::integrate(model, q, qd, dt, q);
    for (const zwang::Joint& joint : model.joints())
      if (q[joint.q_index] < joint.lower || q[joint.q_index] > joint.upper) ++run.limit_violations;
  }
  zwang::forwardKinematics(model, ws, q);
  zwang::framePose(model, ws, q, l_foot, pose);
  run.foot_drift = (pose.translation() - l_start.translation()).norm();
  zwang::framePose(model, ws, q, r_foot, pose);
  run.foot_drift = std::max(run.foot_drift, (pose.translation() - r_start.translation()).norm());
  run.effort = effort;
  run.mean_us = us_sum / steps;
  return run;
}

}  // namespace

int main(int argc, char** argv) {
  std::string path = "models/simple_humanoid.urdf";
  double duration = 2.5;
  bool check = false, upper_rows = false;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--check"))
      check = true;
    else if (!std::strcmp(argv[i], "--upper-body-rows"))
      upper_rows = true;
    else if (!std::strcmp(argv[i], "--model") && i + 1 < argc)
      path = argv[++i];
    else if (!std::strcmp(argv[i], "--duration") && i + 1 < argc)
      duration = std::atof(argv[++i]);
    else
      return std::fprintf(stderr,
                          "usage: humanoid_weight_shift [--model PATH] [--duration S] [--upper-body-rows] [--check]\n"),
             2;
  }
  zwang::UrdfOptions options;
  options.base = zwang::BaseType::Free;
  const zwang::Model model = zwang::loadUrdfFile(path, options);

  const Run plain = simulate(model, duration, false, upper_rows),
            friction = simulate(model, duration, true, upper_rows);
  for (const auto& [name, run] : {std::make_pair("plain", &plain), std::make_pair("friction-aware", &friction)})
    std::printf(
        "%-14s: effort %.1f N^2 m^2 s, COM %.2e m from over the right foot, feet moved %.2e m, "
        "contact rows met to %.1e, %d joint samples outside limits, solve mean %.0f us max %.0f us\n",
        name, run->effort, run->com_error, run->foot_drift, run->foot_acc, run->limit_violations, run->mean_us,
        run->max_us);
  std::printf("friction saves %.1f %% of the effort\n", 100.0 * (1.0 - friction.effort / plain.effort));
  if (!check) return 0;
  bool pass = plain.ok && friction.ok && friction.effort <= plain.effort;
  for (const Run* run : {&plain, &friction})
    pass =
        pass && run->com_error < 5e-3 && run->foot_drift < 1e-4 && run->foot_acc < 1e-6 && run->limit_violations == 0;
  if (!pass) return std::fprintf(stderr, "FAILED a bound\n"), 1;
}
