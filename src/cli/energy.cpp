// `zwang energy [--out DIR] [--models DIR] [--no-plots]`: the energy result of
// docs/evaluation.md. The Franka Panda (models/panda.urdf) at rest in several
// poses, holding still against gravity; the actuator effort with and without
// friction awareness. The same command then runs the dual arm holding a box
// (energy_dual.cpp) and the humanoid and Solo 12 standing
// (energy_standing.cpp); energy_report.hpp holds what the three share.
//
// The task holds everything still: six world-axis rows on tool0 (the tool's
// classical acceleration is zero) and one row that locks the redundant
// elbow's self-motion (panda_link1's angular acceleration about its own z,
// which is q̈₁). Seven independent rows on seven joints fix q̈ = 0, so
//   plain solver  (solveHybridDynamics): τ_control = G(q), the gravity torques;
//   friction-aware (solveWithFriction, all joints stuck): μ* is not unique
//     (g is flat on the whole box), and the library picks the maximiser with
//     the least ‖τ_control‖² using at most margin·f_j of each breakaway torque:
//     |τ_control,j| = max(0, |G_j| − margin·f_j).
// Both are checked (against RNEA and the closed form) before anything is written.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "cli.hpp"
#include "energy_report.hpp"
#include "zwang/zwang.hpp"

namespace zwang::cli {

namespace {

constexpr int kJoints = 7;

struct Pose {
  const char* name;
  const char* what;
  double q[kJoints];
};

// Inside the Panda's position limits, none on a limit; radians.
const Pose kPoses[] = {
    {"ready", "the usual start pose: elbow bent, tool down", {0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785}},
    {"reach_forward", "arm stretched forward and low", {0.0, 0.6, 0.0, -1.4, 0.0, 2.0, 0.785}},
    {"reach_up", "arm raised, tool high", {0.0, -0.3, 0.0, -0.9, 0.0, 0.6, 0.785}},
    {"side_low", "turned to the side, reaching down", {1.2, 0.9, 0.4, -1.2, -0.3, 2.3, 0.0}},
    {"elbow_out", "elbow swung out, wrist turned", {-0.8, 0.3, -1.2, -2.4, 0.9, 1.4, -0.6}},
    {"folded", "folded in close to the base", {0.0, -1.3, 0.0, -2.9, 0.0, 1.7, 0.785}},
};

struct VariantResult {
  Eigen::VectorXd tau, mu;
  std::vector<std::string> state;
  bool indeterminate = false;
  energy::Effort effort;
};

struct PoseResult {
  Eigen::VectorXd q, gravity;  // G(q) from RNEA
  Eigen::Vector3d tool;        // tool0's position [m], world
  VariantResult variant[energy::kVariantCount];
  int rank = 0;
  double worst_qdd = 0, worst_check = 0;
  bool ok = false;
};

PoseResult run(const Model& model, const Pose& pose) {
  const int n = model.dof();
  Task task(model);  // gravity (0, 0, −9.81)
  task.addConstraint("tool0", ConstraintMatrix::Identity(6, 6), Expressed::World);
  ConstraintMatrix lock = ConstraintMatrix::Zero(6, 1);
  lock(5, 0) = 1.0;  // angular z of panda_link1, its own axes: q̈₁
  task.addConstraint("panda_link1", lock, Expressed::Local);
  Workspace ws(model, task);

  PoseResult r;
  r.q = Eigen::Map<const Eigen::VectorXd>(pose.q, n);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  const std::string where = std::string("energy: pose ") + pose.name + ": ";

  Task free_task(model);
  if (const Status s = inverseDynamics(model, free_task, r.q, zero, zero, ws); !s)
    throw CliError(kExitError, where + "RNEA: " + s.message);
  r.gravity = ws.tau;
  Eigen::Isometry3d tool;
  Status s = forwardKinematics(model, ws, r.q);
  if (s) s = framePose(model, ws, model.frameIndex("tool0"), tool);
  if (!s) throw CliError(kExitError, where + s.message);
  r.tool = tool.translation();

  for (int v = 0; v < energy::kVariantCount; ++v) {
    const energy::Variant& variant = energy::kVariants[v];
    if (const Status status = energy::solveAtRest(model, task, r.q, ws, variant); !status)
      throw CliError(kExitError, where + variant.name + ": " + status.message);
    VariantResult& e = r.variant[v];
    e.tau = ws.solution.tau_control;
    e.mu = variant.margin < 0 ? zero : Eigen::VectorXd(ws.friction.mu);
    for (int j = 0; j < n; ++j) e.state.push_back(variant.margin < 0 ? "-" : toString(ws.friction.state[j]));
    e.indeterminate = variant.margin >= 0 && ws.friction.indeterminate;
    e.effort = energy::effortOf(e.tau);
    r.rank = ws.solution.balance.rank;
    r.worst_qdd = std::max(r.worst_qdd, ws.solution.qdd.cwiseAbs().maxCoeff());
    if (ws.solution.balance.singular) throw CliError(kExitError, where + "the hold-still task is singular here");
    // The closed form: τ_control = G(q) + μ with the effort-minimising μ.
    for (int j = 0; j < n; ++j) {
      const double f = variant.margin < 0 ? 0.0 : variant.margin * model.joint(j).breakaway_friction;
      const double expected = std::copysign(std::max(0.0, std::abs(r.gravity[j]) - f), r.gravity[j]);
      r.worst_check = std::max(r.worst_check, std::abs(e.tau[j] - expected));
    }
  }
  r.ok = r.rank == 7 && r.worst_qdd < 1e-9 && r.worst_check < 1e-9;
  return r;
}

std::string csvText(const std::vector<PoseResult>& results) {
  std::ostringstream out;
  out << "pose,variant";
  for (const char* column : {"q", "tau", "mu"})
    for (int j = 1; j <= kJoints; ++j) out << "," << column << j;
  out << ",tau_norm,tau_sq,tau_abs_sum\n";
  for (std::size_t p = 0; p < results.size(); ++p) {
    const PoseResult& r = results[p];
    for (int v = 0; v < energy::kVariantCount; ++v) {
      const VariantResult& e = r.variant[v];
      out << kPoses[p].name << "," << energy::kVariants[v].name;
      for (int j = 0; j < kJoints; ++j) out << energy::csvCell(r.q[j]);
      for (int j = 0; j < kJoints; ++j) out << energy::csvCell(e.tau[j]);
      for (int j = 0; j < kJoints; ++j) out << energy::csvCell(e.mu[j]);
      out << energy::csvCell(e.effort.norm) << energy::csvCell(e.effort.sq) << energy::csvCell(e.effort.abs_sum)
          << "\n";
    }
  }
  return out.str();
}

// Two bar charts: ‖τ_control‖ per pose and variant; |τ_control,j| per joint
// and pose with the breakaway torques. The data are inline (17 digits), the
// same numbers as the CSV.
std::string plotScript(const Model& model, const std::vector<PoseResult>& results) {
  std::vector<std::string> names, labels;
  std::vector<energy::VariantEfforts> efforts;
  for (std::size_t p = 0; p < results.size(); ++p) {
    names.push_back(kPoses[p].name);
    efforts.push_back({results[p].variant[0].effort, results[p].variant[1].effort, results[p].variant[2].effort});
  }
  Eigen::VectorXd breakaway(kJoints);
  for (int j = 0; j < kJoints; ++j) {
    labels.push_back(std::to_string(j + 1));
    breakaway[j] = model.joint(j).breakaway_friction;
  }
  std::ostringstream s;
  s << "# Generated by `zwang energy`; run it in this directory: gnuplot energy.gp\n"
       "set encoding utf8\n"
       "set datafile separator whitespace\n"
    << energy::normsData("$norms", "pose", names, efforts);
  for (std::size_t p = 0; p < results.size(); ++p)
    s << energy::jointsData(std::string("$joints_") + kPoses[p].name, labels,
                            {results[p].variant[0].tau, results[p].variant[1].tau, results[p].variant[2].tau},
                            breakaway);
  s << energy::histogramStyle(results.size())
    << "\n"
       "set terminal pngcairo size 900,520 font \"DejaVu Sans,11\"\n"
       "set output \"panda_energy.png\"\n"
       "set title \"Panda holding still against gravity: motor effort ‖τ_{control}‖\"\n"
       "set ylabel \"‖τ_{control}‖ [N·m]\"\n"
       "set xtics noenhanced\n"
    << energy::normsPlot("$norms")
    << "\n"
       "set terminal pngcairo size 1200,760 font \"DejaVu Sans,10\"\n"
       "set output \"panda_energy_joints.png\"\n"
       "set multiplot layout 2,3 title \"Panda holding still: |τ_{control,j}| per joint (bars) and breakaway friction f_j (red)\"\n"
    << energy::jointsPanelStyle(kJoints);
  for (std::size_t p = 0; p < results.size(); ++p)
    s << energy::jointsPanel(std::string("$joints_") + kPoses[p].name, kPoses[p].name, p == 0);
  s << "unset multiplot\nunset output\n";
  return s.str();
}

}  // namespace

int commandEnergy(int argc, char** argv) {
  const std::optional<ReportCommand> report = startReportCommand(
      "energy", argc, argv, "energy",
      {"panda.urdf", kJoints, {"tool0", "panda_link1"}, "the 7-joint Panda with frames panda_link1 and tool0"});
  if (!report) return kExitOk;  // --help
  const Model& model = report->model;
  const std::filesystem::path& out = report->out;

  std::vector<PoseResult> results;
  bool all_ok = true;
  for (const Pose& pose : kPoses) {
    results.push_back(run(model, pose));
    all_ok = all_ok && results.back().ok;
  }
  // The dual arm holding a box (energy_dual.cpp): solved and checked here, before anything is written.
  const std::function<bool(bool)> dual_arm = prepareDualArmEnergy(*report);
  // The humanoid and Solo 12 standing (energy_standing.cpp): likewise.
  const std::function<bool(bool)> standing = prepareStandingEnergy(*report);

  std::printf("zwang energy: %s holding still against gravity (0, 0, -9.81), at rest\n", report->shownUrdf().c_str());
  std::printf("task: tool0 fixed (6 rows, world axes) + panda_link1 angular z (= qdd1) fixed: qdd = 0 exactly\n");
  std::printf("breakaway friction f [N·m] (URDF <dynamics friction>):");
  for (int j = 0; j < kJoints; ++j) std::printf(" %s", energy::fmt(model.joint(j).breakaway_friction).c_str());
  std::printf(
      "\nplain: solveHybridDynamics (tau_control = gravity torques G(q)); friction-aware: solveWithFriction,\n"
      "all joints stick, mu* indeterminate, the maximiser with the least |tau_control|^2 using at most\n"
      "margin*f_j, so |tau_control,j| = max(0, |G_j| - margin*f_j).\n\n");

  std::printf("poses: q [rad], tool0 position [m]\n");
  std::vector<std::vector<std::string>> poses{
      {"pose", "what", "q1", "q2", "q3", "q4", "q5", "q6", "q7", "tool x", "y", "z"}};
  for (std::size_t p = 0; p < results.size(); ++p) {
    std::vector<std::string> row{kPoses[p].name, kPoses[p].what};
    for (const double x : kPoses[p].q) row.push_back(energy::fmt(x));
    for (int k = 0; k < 3; ++k)
      row.push_back(energy::fmt(std::abs(results[p].tool[k]) < 5e-4 ? 0.0 : results[p].tool[k], "%.3f"));
    poses.push_back(row);
  }
  printColumns(poses, 2);

  std::printf("\ntau_control per joint [N·m]\n");
  std::vector<std::vector<std::string>> joints{
      {"pose", "variant", "tau1", "tau2", "tau3", "tau4", "tau5", "tau6", "tau7"}};
  for (std::size_t p = 0; p < results.size(); ++p)
    for (int v = 0; v < energy::kVariantCount; ++v) {
      std::vector<std::string> row{v == 0 ? kPoses[p].name : "", energy::kVariants[v].name};
      for (int j = 0; j < kJoints; ++j) row.push_back(energy::fmt(results[p].variant[v].tau[j]));
      joints.push_back(row);
    }
  printColumns(joints, 2);

  std::vector<std::string> names;
  std::vector<energy::VariantEfforts> efforts;
  std::vector<bool> ok;
  for (std::size_t p = 0; p < results.size(); ++p) {
    names.push_back(kPoses[p].name);
    efforts.push_back({results[p].variant[0].effort, results[p].variant[1].effort, results[p].variant[2].effort});
    ok.push_back(results[p].ok);
  }
  energy::printEffortTable("pose", names, efforts, ok);
  std::printf("check: rank 7, |qdd| < 1e-9 and tau_control = the closed form within 1e-9 (G from RNEA)\n");

  writeOutput((out / "panda_energy.csv").string(), csvText(results));
  std::printf(
      "wrote %s/panda_energy.csv (pose, variant, q1-7, tau1-7 = tau_control, mu1-7, tau_norm, tau_sq, tau_abs_sum)\n",
      out.string().c_str());
  const bool plotted =
      writePlots(*report, "energy.gp", plotScript(model, results), "panda_energy.png, panda_energy_joints.png");
  all_ok = dual_arm(plotted) && all_ok;
  all_ok = standing(plotted) && all_ok;
  return reportExitCode(*report, all_ok, "the closed form");
}

}  // namespace zwang::cli
