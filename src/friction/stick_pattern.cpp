// The pattern search: μ* by one pass of the sweeps per stick/slip pattern, no K formed (FrictionMethod::
// StickPatterns, the automatic choice, FrictionOptions::warm_start; docs/friction.md, "The pattern search";
// issue #28).
//
// For a pattern — each stuck DOF sticking (q̈ = 0, μ free), at a limit stop (likewise) or slipping (μ at its box's
// bound) — the motion is a joint-level hybrid dynamics problem: the sticking DOFs locked (the prescribed-joint
// machinery, q̈ = 0), the slipping ones driven by τ ∓ f, the task's rows as they are. One pass of the sweeps gives
// q̈ and ν, and each locked DOF's friction is what its joint's equation leaves over (prescribedDofResiduals): O(N).
// The pattern holds when these are the box QP's optimality conditions: every locked DOF's μ inside its box, every
// slipping DOF moving the way its friction allows. It is then the maximiser; the only one when the sticking DOFs'
// block of K is regular, which is the balance with them locked being regular (its rows and the locks
// independent), and strict complementarity on the slipping DOFs. Anything less certain goes to the full solve,
// which chooses among maximisers by least effort: so the answer never depends on which path ran.
//
// Between passes the DOFs whose conditions the pass broke change their part of the pattern — Júdice and Pires's
// block principal pivoting for the box LCP (q̈_Θ = q̈_Θ(0) − K_ΘΘ μ), the Newton-like step that changes every broken
// DOF at once, with Murty's one-at-a-time rule as its backup, which cannot cycle when K_ΘΘ is positive definite.
#include "friction/stick_pattern.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace zwang::internal {

namespace {

// What counts as inside a box and as moving, against what the full solve's classification draws as a line: a
// pattern this close to changing is left to the full solve.
constexpr double kBoxMargin = 1e-9;   // of 1 + f: μ this close to a bound may be at it
constexpr double kSlipMargin = 1e-6;  // of 1 + the largest |q̈| on Θ₀: a slip this slow may be a stick
// Passes without fewer broken conditions before the search changes one DOF at a time (Júdice and Pires's p̄).
constexpr int kBlockTries = 3;

bool locked(JointState state) { return state == JointState::Stick || state == JointState::AtLimit; }

// The kept states mapped onto Θ₀ (both ascending): a DOF stuck then keeps its state, a newly stuck one sticks, and
// a slip towards a side a limit stop now holds without bound locks instead.
void startFromKept(const FrictionResult& fr, FrictionScratch& fs) {
  fs.trial_state.clear();  // reserved for every DOF: no allocation
  std::size_t b = 0;
  for (std::size_t a = 0; a < fr.stuck.size(); ++a) {
    const int j = fr.stuck[a];
    while (b < fs.pattern_stuck.size() && fs.pattern_stuck[b] < j) ++b;
    JointState state =
        b < fs.pattern_stuck.size() && fs.pattern_stuck[b] == j ? fs.pattern_state[b] : JointState::Stick;
    const auto e = static_cast<Eigen::Index>(a);
    if ((state == JointState::SlipPositive && !std::isfinite(fs.hi[e])) ||
        (state == JointState::SlipNegative && !std::isfinite(fs.lo[e])))
      state = JointState::Stick;
    fs.trial_state.push_back(state);
  }
}

void startSticking(const FrictionResult& fr, FrictionScratch& fs) {
  fs.trial_state.assign(fr.stuck.size(), JointState::Stick);
}

// The task's modes, prescribed accelerations and τ_effective, copied once per search: each pass changes only the
// stuck DOFs' entries (lockPattern).
void copyTaskModes(const Task& task, FrictionScratch& fs) {
  std::copy(task.dofModes().begin(), task.dofModes().end(), fs.pattern_modes.begin());
  fs.pattern_qdd = task.prescribedAccelerations();
  fs.pattern_tau = fs.tau_effective;
}

// The stuck DOFs' entries for the pattern: the sticking ones locked (q̈ = 0), the slipping ones driven by their
// friction bound; returns how many DOFs are prescribed then.
int lockPattern(const Model& model, const Task& task, const FrictionResult& fr, FrictionScratch& fs) {
  const int base_velocity_size = model.baseVelocitySize();
  int prescribed = task.prescribedCount();
  for (std::size_t a = 0; a < fr.stuck.size(); ++a) {
    const int v = base_velocity_size + fr.stuck[a];
    const auto e = static_cast<Eigen::Index>(a);
    const JointState state = fs.trial_state[a];
    if (locked(state)) {
      fs.pattern_modes[static_cast<std::size_t>(v)] = DofMode::Prescribed;
      fs.pattern_qdd[v] = 0.0;
      fs.pattern_tau[v] = fs.tau_effective[v];
      ++prescribed;
    } else {  // μ enters as the torque −μ
      fs.pattern_modes[static_cast<std::size_t>(v)] = DofMode::Torque;
      fs.pattern_tau[v] = fs.tau_effective[v] - (state == JointState::SlipPositive ? fs.hi[e] : fs.lo[e]);
    }
  }
  return prescribed;
}

// Whether ν may be left free by the locks (smallestFriction): every row a contact, so that τ_control = τ whatever ν
// (the full solve's EffortChange::Fixed) and the balance is on the solver's columns (its null basis is ν's).
bool contactsOnly(const Task& task) {
  const std::vector<char>& contact = solverOrder(task).contactColumns();
  if (solverOrder(task).balanceOnRows() || task.solverColumns() == 0) return false;
  return std::all_of(contact.begin(), contact.begin() + task.solverColumns(), [](char c) { return c != 0; });
}

// One pass of the sweeps with the pattern's modes, the kinematics done: false when a joint has no inertia to move or
// the balance is not regular with the sticking DOFs locked (μ* may not be unique: the full solve chooses) — except,
// with free_nu, exact rank loss with every row met (smallestFriction then chooses).
bool passOfSweeps(const Model& model, const Task& task, bool free_nu, Workspace& ws, FrictionScratch& fs) {
  WorkspaceScratch& sw = scratchOf(ws);
  const BalanceReport& report = ws.solution.balance;
  if (sw.prescribed_count == model.nv() && task.solverColumns() == 0) {
    // Every DOF locked or prescribed and no rows (a cold search's first pass on a fixed base, a robot held by its
    // friction): q̈ is given, nothing for the inward sweep and the balance to solve.
    ws.solution.qdd = fs.pattern_qdd;
    bodyAccelerations(model, task, ws, ws.solution.qdd);
    ws.solution.balance = BalanceReport{};
  } else {
    if (!inwardSweep(model, task, fs.pattern_tau, ws)) return false;  // Degenerate: the full solve reports it
    balance(task, ws);
    if ((report.singular || !report.nu_unique) && !(free_nu && !report.nu_unique && report.damping == 0.0))
      return false;
    outwardAccelerations(model, task, ws, ws.solution.qdd);
  }
  if (!report.nu_unique) {  // rows the locks made dependent must still be met, or the pattern cannot hold
    taskResidual(task, ws);
    if (!report.consistent) return false;
  }
  const int m = task.solverColumns();
  prescribedDofResiduals(model, task, ws, sw.nu_columns.head(m), ws.solution.qdd, fs.pattern_tau, fs.pattern_residual);
  return true;
}

// Contacts the locks make dependent (feet on the ground, every joint sticking: the rigid robot stands on more rows
// than it has coordinates). The pattern's motion is unique, but ν is free along the balance's null directions n,
// and with it the locked DOFs' friction: λ = λ₀ + P z, P's columns the λ a unit ν along each n gives (−Sᵀ Σ A n over
// the subtree). These are the maximisers with this motion, and with every row a contact every one costs the same
// effort (τ_control = τ): the full solve's choice is the smallest μ = −λ on the sticking DOFs, λ₀'s projection off
// range(P): λ ← λ₀ + P z, ν ← ν + N z, z = −(PᵀP)⁻¹Pᵀλ₀. False when P's columns are nearly dependent
// (a contact direction the joints hardly feel: the full solve decides).
bool smallestFriction(const Model& model, const Task& task, const FrictionResult& fr, Workspace& ws,
                      FrictionScratch& fs) {
  // A column of P this close to the span of the others: the balance with the DOFs free would see its rows as
  // near-singular (σ̃ ~ the square of it against singular_threshold = 1e-6), which the full solve damps.
  constexpr double kIndependent = 1e-3;
  WorkspaceScratch& sw = scratchOf(ws);
  const BalanceFactorisation& f = sw.balance_factorisation;
  const int m = task.solverColumns(), base_velocity_size = model.baseVelocitySize();
  const Eigen::Index nullity = f.near_null_count;
  fs.locked_dofs.clear();  // reserved for every DOF: no allocation
  for (std::size_t a = 0; a < fr.stuck.size(); ++a)
    if (locked(fs.trial_state[a])) fs.locked_dofs.push_back(base_velocity_size + fr.stuck[a]);
  const auto locked_count = static_cast<Eigen::Index>(fs.locked_dofs.size());
  const int* rows = fs.locked_dofs.data();
  auto P = fs.free_lambda.topLeftCorner(locked_count, nullity);
  for (Eigen::Index e = 0; e < nullity; ++e) {
    prescribedContactTorques(model, task, ws, f.near_null_basis.col(e).head(m), fs.pattern_direction);
    for (Eigen::Index t = 0; t < locked_count; ++t) P(t, e) = fs.pattern_direction[rows[t]];
  }
  // z = −(PᵀP)⁻¹ Pᵀλ₀ by the Cholesky factor R of PᵀP (P's columns are independent to kIndependent, so squaring
  // their condition costs at most 1e-6 of the rounding the least-norm λ can have), then λ ← λ₀ + P z.
  auto R = fs.free_factor.topLeftCorner(nullity, nullity);
  auto z = fs.free_step.head(nullity);
  for (Eigen::Index c = 0; c < nullity; ++c) {
    const double* p_c = P.col(c).data();
    for (Eigen::Index d = 0; d <= c; ++d) {
      const double* p_d = P.col(d).data();
      double dot = 0.0;
      for (Eigen::Index t = 0; t < locked_count; ++t) dot += p_c[t] * p_d[t];
      R(c, d) = dot;
    }
    double along = 0.0;
    for (Eigen::Index t = 0; t < locked_count; ++t) along += p_c[t] * fs.pattern_residual[rows[t]];
    z[c] = -along;
  }
  for (Eigen::Index c = 0; c < nullity; ++c) {  // R Rᵀ = PᵀP in place (lower); R_cc² is P_c's distance² from the
    const double length2 = R(c, c);             // span of the columns before it
    for (Eigen::Index d = 0; d <= c; ++d) {
      double value = R(c, d);
      for (Eigen::Index l = 0; l < d; ++l) value -= R(c, l) * R(d, l);
      if (d < c) {
        R(c, d) = value / R(d, d);
      } else {
        if (!(value > kIndependent * kIndependent * length2)) return false;
        R(c, c) = std::sqrt(value);
      }
    }
  }
  for (Eigen::Index c = 0; c < nullity; ++c) {  // R y = −Pᵀλ₀
    for (Eigen::Index l = 0; l < c; ++l) z[c] -= R(c, l) * z[l];
    z[c] /= R(c, c);
  }
  for (Eigen::Index c = nullity - 1; c >= 0; --c) {  // Rᵀ z = y
    for (Eigen::Index l = c + 1; l < nullity; ++l) z[c] -= R(l, c) * z[l];
    z[c] /= R(c, c);
  }
  for (Eigen::Index c = 0; c < nullity; ++c) {
    const double* p_c = P.col(c).data();
    for (Eigen::Index t = 0; t < locked_count; ++t) fs.pattern_residual[rows[t]] += z[c] * p_c[t];
  }
  sw.nu_columns.head(m).noalias() += f.near_null_basis.topLeftCorner(m, nullity) * z;
  // Given μ, ν is the only one (P's columns independent): the report says so, as the full solve's does.
  BalanceReport& report = ws.solution.balance;
  report.rank = report.rows;
  report.nu_unique = true;
  report.singular = false;
  report.condition = f.regular_condition;
  fs.pattern_indeterminate = true;
  return true;
}

// Marks each DOF whose condition the pass broke — a locked DOF's μ (into fs.mu) beyond its box, a slipping DOF
// moving against its friction — and returns how many; −1 when the pass overflowed (the full solve reports it).
int brokenConditions(const Model& model, const FrictionResult& fr, const Eigen::VectorXd& qdd, FrictionScratch& fs) {
  const int base_velocity_size = model.baseVelocitySize();
  int broken = 0;
  for (std::size_t a = 0; a < fr.stuck.size(); ++a) {
    const int v = base_velocity_size + fr.stuck[a];
    const auto e = static_cast<Eigen::Index>(a);
    const JointState state = fs.trial_state[a];
    bool breaks = false;
    if (locked(state)) {
      const double mu = -fs.pattern_residual[v];
      if (!std::isfinite(mu)) return -1;
      fs.mu[e] = mu;
      breaks = mu > fs.hi[e] || mu < fs.lo[e];
    } else {
      if (!std::isfinite(qdd[v])) return -1;
      breaks = state == JointState::SlipPositive ? qdd[v] < 0.0 : qdd[v] > 0.0;
    }
    fs.pattern_breaks[a] = breaks ? 1 : 0;
    broken += breaks ? 1 : 0;
  }
  return broken;
}

// The next pattern: each marked DOF (with last_only, the last of them) changes — a locked one slips the way its μ
// left its box, a slipping one locks.
void changeMarked(const FrictionResult& fr, bool last_only, FrictionScratch& fs) {
  for (std::size_t b = fr.stuck.size(); b-- > 0;) {
    if (!fs.pattern_breaks[b]) continue;
    JointState& state = fs.trial_state[b];
    const auto e = static_cast<Eigen::Index>(b);
    state = !locked(state) ? JointState::Stick
                           : (fs.mu[e] > fs.hi[e] ? JointState::SlipPositive : JointState::SlipNegative);
    if (last_only) return;
  }
}

// The box QP's optimality conditions at the pattern's motion, strictly (nothing broken, every condition with its
// margin): μ* into fs.mu when they hold.
bool patternHolds(const Model& model, const FrictionResult& fr, const Eigen::VectorXd& qdd, FrictionScratch& fs,
                  double& acc_tolerance) {
  const int base_velocity_size = model.baseVelocitySize();
  double acc_max = 0.0;
  for (const int j : fr.stuck) acc_max = std::max(acc_max, std::abs(qdd[base_velocity_size + j]));
  const double slip_margin = kSlipMargin * (1.0 + acc_max);
  for (std::size_t a = 0; a < fr.stuck.size(); ++a) {
    const int j = fr.stuck[a], v = base_velocity_size + j;
    const auto e = static_cast<Eigen::Index>(a);
    const JointState state = fs.trial_state[a];
    if (locked(state)) {  // μ already in fs.mu
      const double margin = kBoxMargin * (1.0 + fs.breakaway[j]);
      if (!(fs.mu[e] > fs.lo[e] + margin && fs.mu[e] < fs.hi[e] - margin)) return false;
    } else if (state == JointState::SlipPositive) {
      if (!(qdd[v] > slip_margin)) return false;
      fs.mu[e] = fs.hi[e];
    } else {
      if (!(qdd[v] < -slip_margin)) return false;
      fs.mu[e] = fs.lo[e];
    }
  }
  acc_tolerance = 1e-9 * (1.0 + acc_max);  // as the full solve's, of the motion found
  return true;
}

// The passes from the start pattern: true when one holds.
bool pivotToOptimum(const Model& model, const Task& task, const FrictionResult& fr, int max_passes, Workspace& ws,
                    FrictionScratch& fs, double& acc_tolerance, int& passes) {
  WorkspaceScratch& sw = scratchOf(ws);
  const bool free_nu = contactsOnly(task);
  copyTaskModes(task, fs);
  sw.dof_modes = fs.pattern_modes.data();
  sw.prescribed_qdd = fs.pattern_qdd.data();
  int fewest = std::numeric_limits<int>::max(), block_tries = kBlockTries;
  while (passes < max_passes) {
    sw.prescribed_count = lockPattern(model, task, fr, fs);
    // More rows and locks than the motion has coordinates: the balance is singular (μ* not unique), which
    // smallestFriction resolves only for contacts.
    if (!free_nu && sw.prescribed_count + task.balanceRows() > model.nv()) return false;
    ++passes;
    fs.pattern_indeterminate = false;
    if (!passOfSweeps(model, task, free_nu, ws, fs)) return false;
    if (!ws.solution.balance.nu_unique && !smallestFriction(model, task, fr, ws, fs)) return false;
    const int broken = brokenConditions(model, fr, ws.solution.qdd, fs);
    if (broken < 0) return false;
    if (broken == 0) return patternHolds(model, fr, ws.solution.qdd, fs, acc_tolerance);
    if (broken < fewest) {
      fewest = broken;
      block_tries = kBlockTries;
    } else if (block_tries > 0) {
      --block_tries;
    }
    changeMarked(fr, block_tries == 0, fs);
  }
  return false;
}

}  // namespace

bool keptPatternApplies(const Model& model, const Task& task, const FrictionScratch& fs) {
  return fs.pattern_model == &model && fs.pattern_task == &task;
}

bool searchPatterns(const Model& model, const Task& task, const FrictionResult& fr, bool from_kept, int max_passes,
                    Workspace& ws, FrictionScratch& fs, double& acc_tolerance, int& passes) {
  passes = 0;
  if (fr.stuck.empty() || max_passes < 1) return false;
  if (from_kept)
    startFromKept(fr, fs);
  else
    startSticking(fr, fs);
  const bool held = pivotToOptimum(model, task, fr, max_passes, ws, fs, acc_tolerance, passes);
  bindTaskModes(task, scratchOf(ws));  // the stages after it (the task's prescribed torques, the full solve) read them
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
