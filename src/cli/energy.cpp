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
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
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

// A joint in the charts: its number, from 1.
std::string jointNumber(int j) { return std::to_string(j + 1); }

// What the Panda's report adds to a pose's solves: where the tool is.
struct PoseDetail {
  Eigen::Vector3d tool;  // tool0's position [m], world
};

energy::PostureResult run(const Model& model, const Pose& pose, PoseDetail& detail) {
  const int n = model.dof();
  Task task(model);  // gravity (0, 0, −9.81)
  task.addConstraint("tool0", ConstraintMatrix::Identity(6, 6), Expressed::World);
  ConstraintMatrix lock = ConstraintMatrix::Zero(6, 1);
  lock(5, 0) = 1.0;  // angular z of panda_link1, its own axes: q̈₁
  task.addConstraint("panda_link1", lock, Expressed::Local);
  Workspace ws(model, task);

  energy::PostureResult r;
  r.name = pose.name;
  r.q = Eigen::Map<const Eigen::VectorXd>(pose.q, n);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  const std::string where = std::string("energy: pose ") + pose.name + ": ";

  Task free_task(model);
  if (const Status s = inverseDynamics(model, ws, r.q, zero, zero, free_task); !s)
    throw CliError(kExitError, where + "RNEA: " + s.message);
  const Eigen::VectorXd gravity = ws.tau;  // G(q) from RNEA
  Eigen::Isometry3d tool;
  Status s = forwardKinematics(model, ws, r.q);
  if (s) s = framePose(model, ws, r.q, model.frameIndex("tool0"), tool);
  if (!s) throw CliError(kExitError, where + s.message);
  detail.tool = tool.translation();

  int rank = 0;
  double worst_qdd = 0, worst_check = 0;
  for (int v = 0; v < energy::kVariantCount; ++v) {
    const energy::Variant& variant = energy::kVariants[v];
    if (const Status status = energy::solveAtRest(model, task, r.q, ws, variant); !status)
      throw CliError(kExitError, where + variant.name + ": " + status.message);
    const energy::VariantResult& e = r.variant[static_cast<std::size_t>(v)] =
        energy::variantResult(variant, ws.solution.tau_control, ws);
    rank = ws.solution.balance.rank;
    worst_qdd = std::max(worst_qdd, ws.solution.qdd.cwiseAbs().maxCoeff());
    if (ws.solution.balance.singular) throw CliError(kExitError, where + "the hold-still task is singular here");
    // The closed form: τ_control = G(q) + μ with the effort-minimising μ.
    for (int j = 0; j < n; ++j) {
      const double f = variant.margin < 0 ? 0.0 : variant.margin * model.joint(j).breakaway_friction;
      const double expected = std::copysign(std::max(0.0, std::abs(gravity[j]) - f), gravity[j]);
      worst_check = std::max(worst_check, std::abs(e.tau[j] - expected));
    }
  }
  r.ok = rank == 7 && worst_qdd < 1e-9 && worst_check < 1e-9;
  return r;
}

// The Panda holding still in each pose of kPoses.
class PandaScenario final : public Scenario {
 public:
  explicit PandaScenario(const ReportCommand& report) : report_(report) {
    for (const Pose& pose : kPoses) {
      details_.emplace_back();
      poses_.push_back(run(report.model, pose, details_.back()));
    }
  }
  ScenarioFiles files() const override {
    return {{"panda_energy.csv"},
            "pose, variant, q1-7, tau1-7 = tau_control, mu1-7, tau_norm, tau_sq, tau_abs_sum",
            "energy.gp",
            "panda_energy.png, panda_energy_joints.png"};
  }
  bool ok() const override {
    return std::all_of(poses_.begin(), poses_.end(), [](const energy::PostureResult& r) { return r.ok; });
  }
  void print() const override;
  std::string csvText(std::size_t) const override { return energy::armCsv(poses_); }
  std::string plotScript() const override;

 private:
  void printSetting() const;
  void printPoses() const;
  void printTorques() const;

  const ReportCommand& report_;
  std::vector<energy::PostureResult> poses_;
  std::vector<PoseDetail> details_;
};

// Two bar charts: ‖τ_control‖ per pose and variant; |τ_control,j| per joint
// and pose with the breakaway torques.
std::string PandaScenario::plotScript() const {
  const energy::ArmCharts charts{
      "pose",
      "panda_energy.png",
      "Panda holding still against gravity: motor effort ‖τ_{control}‖",
      "1200,760",
      "panda_energy_joints.png",
      "Panda holding still: |τ_{control,j}| per joint (bars) and breakaway friction f_j (red)"};
  return energy::armPlotScript(files().script, charts, poses_, report_.model, jointNumber);
}

// The model, the task and what the variants are.
void PandaScenario::printSetting() const {
  std::printf("zwang energy: %s holding still against gravity (0, 0, -9.81), at rest\n", report_.shownUrdf().c_str());
  std::printf("task: tool0 fixed (6 rows, world axes) + panda_link1 angular z (= qdd1) fixed: qdd = 0 exactly\n");
  std::printf("breakaway friction f [N·m] (URDF <dynamics friction>):");
  for (int j = 0; j < kJoints; ++j) std::printf(" %s", fmt(report_.model.joint(j).breakaway_friction).c_str());
  std::printf(
      "\nplain: solveHybridDynamics (tau_control = gravity torques G(q)); friction-aware: solveWithFriction,\n"
      "all joints stick, mu* indeterminate, the maximiser with the least |tau_control|^2 using at most\n"
      "margin*f_j, so |tau_control,j| = max(0, |G_j| - margin*f_j).\n\n");
}

// The poses: q and where the tool is.
void PandaScenario::printPoses() const {
  std::printf("poses: q [rad], tool0 position [m]\n");
  std::vector<std::vector<std::string>> poses{
      {"pose", "what", "q1", "q2", "q3", "q4", "q5", "q6", "q7", "tool x", "y", "z"}};
  for (std::size_t p = 0; p < poses_.size(); ++p) {
    std::vector<std::string> row{kPoses[p].name, kPoses[p].what};
    for (const double x : kPoses[p].q) row.push_back(fmt(x));
    const Eigen::Vector3d& tool = details_[p].tool;
    for (int k = 0; k < 3; ++k) row.push_back(fmt(std::abs(tool[k]) < 5e-4 ? 0.0 : tool[k], "%.3f"));
    poses.push_back(row);
  }
  printColumns(poses, 2);
}

// tau_control per joint and variant.
void PandaScenario::printTorques() const {
  std::printf("\ntau_control per joint [N·m]\n");
  std::vector<std::vector<std::string>> joints{
      {"pose", "variant", "tau1", "tau2", "tau3", "tau4", "tau5", "tau6", "tau7"}};
  for (const energy::PostureResult& r : poses_)
    for (int v = 0; v < energy::kVariantCount; ++v) {
      std::vector<std::string> row{v == 0 ? r.name : "", energy::kVariants[v].name};
      for (const double tau : r.variant[static_cast<std::size_t>(v)].tau) row.push_back(fmt(tau));
      joints.push_back(row);
    }
  printColumns(joints, 2);
}

void PandaScenario::print() const {
  printSetting();
  printPoses();
  printTorques();
  energy::printEffortTable("pose", poses_);
  std::printf("check: rank 7, |qdd| < 1e-9 and tau_control = the closed form within 1e-9 (G from RNEA)\n");
}

}  // namespace

int commandEnergy(int argc, char** argv) {
  const std::optional<ReportCommand> report = startReportCommand(
      "energy", argc, argv, "energy",
      {"panda.urdf", kJoints, {"tool0", "panda_link1"}, "the 7-joint Panda with frames panda_link1 and tool0"});
  if (!report) return kExitOk;  // --help
  // Every scenario is solved and checked before anything is written.
  std::vector<std::unique_ptr<Scenario>> scenarios;
  scenarios.push_back(std::make_unique<PandaScenario>(*report));
  scenarios.push_back(energy::dualArmScenario(*report));
  scenarios.push_back(energy::standingScenario(*report));

  bool plotted = true, all_ok = true;
  for (std::size_t k = 0; k < scenarios.size(); ++k) {
    const bool wrote = writeScenario(*report, *scenarios[k], plotted);
    if (k == 0) plotted = wrote;  // gnuplot failing on the first is said once, the others write their scripts only
    all_ok = scenarios[k]->ok() && all_ok;
  }
  return reportExitCode(*report, all_ok, "the closed form");
}

}  // namespace zwang::cli
