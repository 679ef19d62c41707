// Warm start: the last solve's stick/slip pattern, tried first (FrictionOptions::warm_start; docs/friction.md,
// "Warm start"; issue #28).
//
// For a pattern — each stuck DOF sticking (q̈ = 0, μ free), at a limit stop (likewise) or slipping (μ at its box's
// bound) — the motion is a joint-level hybrid dynamics problem: the sticking DOFs locked (the prescribed-joint
// machinery, q̈ = 0), the slipping ones driven by τ ∓ f, the task's rows as they are. One pass of the sweeps gives
// q̈ and ν, and each locked DOF's friction is what its joint's equation leaves over (prescribedDofResiduals): no K
// formed, O(N). The pattern holds when these are the box QP's optimality conditions: every locked DOF's μ inside its
// box, every slipping DOF moving the way its friction allows. It is then the maximiser; the only one when the
// sticking DOFs' block of K is regular, which is the balance with them locked being regular (its rows and the locks
// independent), and strict complementarity on the slipping DOFs. Anything less certain goes to the full solve,
// which chooses among maximisers by least effort: so the answer never depends on which path ran.
#include "friction/stick_pattern.hpp"

#include <algorithm>
#include <cmath>

namespace zwang::internal {

namespace {

// What counts as inside a box and as moving, against what the full solve's classification draws as a line: a
// pattern this close to changing is left to the full solve.
constexpr double kBoxMargin = 1e-9;   // of 1 + f: μ this close to a bound may be at it
constexpr double kSlipMargin = 1e-6;  // of 1 + the largest |q̈| on Θ₀: a slip this slow may be a stick

bool locked(JointState state) { return state == JointState::Stick || state == JointState::AtLimit; }

// The kept pattern is for this model, this task object and this stuck set.
bool patternApplies(const Model& model, const Task& task, const FrictionResult& fr, const FrictionScratch& fs) {
  return fs.pattern_model == &model && fs.pattern_task == &task && !fr.stuck.empty() && fs.pattern_stuck == fr.stuck;
}

// The task's modes with the sticking DOFs locked, and τ_effective with the slipping DOFs' friction bound.
int lockPattern(const Model& model, const Task& task, const FrictionResult& fr, FrictionScratch& fs) {
  const int base_velocity_size = model.baseVelocitySize();
  std::copy(task.dofModes().begin(), task.dofModes().end(), fs.pattern_modes.begin());
  fs.pattern_qdd = task.prescribedAccelerations();
  fs.pattern_tau = fs.tau_effective;
  int prescribed = task.prescribedCount();
  for (std::size_t a = 0; a < fr.stuck.size(); ++a) {
    const int v = base_velocity_size + fr.stuck[a];
    const auto e = static_cast<Eigen::Index>(a);
    const JointState state = fs.pattern_state[a];
    if (locked(state)) {
      fs.pattern_modes[static_cast<std::size_t>(v)] = DofMode::Prescribed;
      fs.pattern_qdd[v] = 0.0;
      ++prescribed;
    } else {  // μ enters as the torque −μ
      fs.pattern_tau[v] -= state == JointState::SlipPositive ? fs.hi[e] : fs.lo[e];
    }
  }
  return prescribed;
}

// The sweeps with the pattern's modes: false when a joint has no inertia to move or the balance is not regular
// with the sticking DOFs locked (μ* may not be unique: the full solve chooses).
bool sweepPattern(const Model& model, const Task& task, const Eigen::Ref<const Eigen::VectorXd>& q,
                  const Eigen::Ref<const Eigen::VectorXd>& qd, Workspace& ws, FrictionScratch& fs) {
  WorkspaceScratch& sw = scratchOf(ws);
  outwardSweep(model, task, q, qd, ws);
  if (!inwardSweep(model, task, fs.pattern_tau, ws)) return false;  // Degenerate: the full solve reports it
  balance(task, ws);
  const BalanceReport& report = ws.solution.balance;
  if (report.singular || !report.nu_unique) return false;
  outwardAccelerations(model, task, ws, ws.solution.qdd);
  const int m = task.solverColumns();
  prescribedDofResiduals(model, task, ws, sw.nu_columns.head(m), ws.solution.qdd, fs.pattern_tau, fs.pattern_residual);
  return true;
}

// The box QP's optimality conditions at the pattern's motion, strictly: μ* into fs.mu when they hold.
bool patternHolds(const Model& model, const FrictionResult& fr, const Eigen::VectorXd& qdd, FrictionScratch& fs,
                  double& acc_tolerance) {
  if (!qdd.allFinite()) return false;  // an overflow is the full solve's to report
  const int base_velocity_size = model.baseVelocitySize();
  double acc_max = 0.0;
  for (const int j : fr.stuck) acc_max = std::max(acc_max, std::abs(qdd[base_velocity_size + j]));
  const double slip_margin = kSlipMargin * (1.0 + acc_max);
  for (std::size_t a = 0; a < fr.stuck.size(); ++a) {
    const int j = fr.stuck[a], v = base_velocity_size + j;
    const auto e = static_cast<Eigen::Index>(a);
    const JointState state = fs.pattern_state[a];
    if (locked(state)) {
      const double mu = -fs.pattern_residual[v], margin = kBoxMargin * (1.0 + fs.breakaway[j]);
      if (!(mu > fs.lo[e] + margin && mu < fs.hi[e] - margin)) return false;
      fs.mu[e] = mu;
    } else if (state == JointState::SlipPositive) {
      if (!(std::isfinite(fs.hi[e]) && qdd[v] > slip_margin)) return false;
      fs.mu[e] = fs.hi[e];
    } else {
      if (!(std::isfinite(fs.lo[e]) && qdd[v] < -slip_margin)) return false;
      fs.mu[e] = fs.lo[e];
    }
  }
  acc_tolerance = 1e-9 * (1.0 + acc_max);  // as the full solve's, of the motion found
  return true;
}

}  // namespace

bool solveLastPattern(const Model& model, const Task& task, const Eigen::Ref<const Eigen::VectorXd>& q,
                      const Eigen::Ref<const Eigen::VectorXd>& qd, const FrictionResult& fr, Workspace& ws,
                      FrictionScratch& fs, double& acc_tolerance) {
  if (!patternApplies(model, task, fr, fs)) return false;
  WorkspaceScratch& sw = scratchOf(ws);
  sw.prescribed_count = lockPattern(model, task, fr, fs);
  sw.dof_modes = fs.pattern_modes.data();
  sw.prescribed_qdd = fs.pattern_qdd.data();
  const bool held =
      sweepPattern(model, task, q, qd, ws, fs) && patternHolds(model, fr, ws.solution.qdd, fs, acc_tolerance);
  bindTaskModes(task, sw);  // the stages after it (the task's prescribed torques) read the task's
  return held;
}

void rememberPattern(const Model& model, const Task& task, const FrictionResult& fr, bool keep, FrictionScratch& fs) {
  fs.pattern_model = keep ? &model : nullptr;
  if (!keep) return;
  fs.pattern_task = &task;
  fs.pattern_stuck = fr.stuck;  // room for every DOF reserved: no allocation
  fs.pattern_state.clear();
  for (const int j : fr.stuck) fs.pattern_state.push_back(fr.state[static_cast<std::size_t>(j)]);
}

}  // namespace zwang::internal
