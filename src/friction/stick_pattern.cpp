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

// How τ_control moves where the locks leave ν free (leastEffortFriction), as the full solve's EffortChange: Fixed
// when every row is a contact (τ_control = τ whatever ν), Own when none is (each sticking DOF's τ_control moves one
// for one with its μ); None for a mix of the two, mimic rows, or a balance on rows (its null basis is not ν's):
// the full solve chooses there.
enum class FreeNu { None, Fixed, Own };
FreeNu freeNuEffort(const Task& task) {
  const std::vector<char>& contact = solverOrder(task).contactColumns();
  const int m = task.solverColumns();
  if (solverOrder(task).balanceOnRows() || m == 0 || task.mimicRows() > 0) return FreeNu::None;
  const auto contacts = std::count_if(contact.begin(), contact.begin() + m, [](char c) { return c != 0; });
  return contacts == m ? FreeNu::Fixed : contacts == 0 ? FreeNu::Own : FreeNu::None;
}

// The balance's right-hand side on the range of 𝓛: its part along the null directions (what no force can meet)
// at rounding of it. taskResidual's test is relative to the rows' terms, ν's among them, which an ill-conditioned
// balance makes large enough to pass a row the locks leave unmet (stress seed 72).
bool onRange(const BalanceFactorisation& f, const Eigen::Ref<const Eigen::VectorXd>& rhs) {
  constexpr double kRounding = 1e-9;  // of ‖r‖: r is a difference of terms its own size, computed to ε of them
  double off2 = 0.0;
  for (int e = 0; e < f.near_null_count; ++e) {
    const double along = f.near_null_basis.col(e).head(rhs.size()).dot(rhs);
    off2 += along * along;
  }
  return off2 <= kRounding * kRounding * rhs.squaredNorm();
}

// One pass of the sweeps with the pattern's modes, the kinematics done: false when a joint has no inertia to move or
// the balance is not regular with the sticking DOFs locked (μ* may not be unique: the full solve chooses) — except,
// with free_nu, exact rank loss with every row met (leastEffortFriction then chooses).
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
  const int m = task.solverColumns();
  if (!report.nu_unique) {  // rows the locks made dependent must still be met, or the pattern cannot hold
    taskResidual(task, ws);
    if (!report.consistent || !onRange(sw.balance_factorisation, sw.rhs.head(m))) return false;
  }
  prescribedDofResiduals(model, task, ws, sw.nu_columns.head(m), ws.solution.qdd, fs.pattern_tau, fs.pattern_residual);
  return true;
}

// μ on the locked DOFs for λ = λ₀ + P z: −(λ₀ + P z) strictly inside [lo, hi] (on Θ₀) with the pattern search's
// margin (kBoxMargin of 1 + f).
bool strictlyInside(const Model& model, const FrictionResult& fr, const Eigen::Ref<const Eigen::VectorXd>& z,
                    const Eigen::Ref<const Eigen::VectorXd>& lo, const Eigen::Ref<const Eigen::VectorXd>& hi,
                    const FrictionScratch& fs) {
  const int base_velocity_size = model.baseVelocitySize();
  for (std::size_t t = 0; t < fs.locked_dofs.size(); ++t) {
    const auto a = static_cast<std::size_t>(fs.locked_dofs[t]);
    const double mu = -(fs.pattern_residual[base_velocity_size + fr.stuck[a]] +
                        fs.free_lambda.row(static_cast<Eigen::Index>(t)).head(z.size()).dot(z));
    const double margin = kBoxMargin * (1.0 + fs.breakaway[fr.stuck[a]]);
    const auto e = static_cast<Eigen::Index>(a);
    if (!(mu > lo[e] + margin && mu < hi[e] - margin)) return false;
  }
  return true;
}

// z = (PᵀP)⁻¹ Pᵀ y (R Rᵀ = PᵀP in fs.free_factor), y per locked DOF in fs.free_target.
void normalSolve(Eigen::Index nullity, Eigen::Index locked_count, const FrictionScratch& fs,
                 Eigen::Ref<Eigen::VectorXd> z) {
  const auto R = fs.free_factor.topLeftCorner(nullity, nullity);
  for (Eigen::Index c = 0; c < nullity; ++c)
    z[c] = fs.free_lambda.col(c).head(locked_count).dot(fs.free_target.head(locked_count));
  for (Eigen::Index c = 0; c < nullity; ++c) {  // R y = Pᵀ y
    for (Eigen::Index l = 0; l < c; ++l) z[c] -= R(c, l) * z[l];
    z[c] /= R(c, c);
  }
  for (Eigen::Index c = nullity - 1; c >= 0; --c) {  // Rᵀ z = y
    for (Eigen::Index l = c + 1; l < nullity; ++l) z[c] -= R(l, c) * z[l];
    z[c] /= R(c, c);
  }
}

// R Rᵀ = PᵀP in place (lower); false when a column of P is within kIndependent of the others' span (R_cc² is its
// distance² from the span of the columns before it).
bool factorNormalMatrix(Eigen::Index nullity, Eigen::Index locked_count, FrictionScratch& fs) {
  // A column of P this close to the span of the others: the balance with the DOFs free would see its rows as
  // near-singular (σ̃ ~ the square of it against singular_threshold = 1e-6), which the full solve damps.
  constexpr double kIndependent = 1e-3;
  const auto P = fs.free_lambda.topLeftCorner(locked_count, nullity);
  auto R = fs.free_factor.topLeftCorner(nullity, nullity);
  for (Eigen::Index c = 0; c < nullity; ++c)
    for (Eigen::Index d = 0; d <= c; ++d) R(c, d) = P.col(c).dot(P.col(d));
  for (Eigen::Index c = 0; c < nullity; ++c) {
    const double length2 = R(c, c);
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
  return true;
}

// (b) where the unbounded least effort leaves the margin box: the bounded least-distance problem the full solve
// solves, min ‖w − w_b‖² over lo ≤ μ_ref − Q w ≤ hi with P = Q Rᵀ (Q orthonormal, w = Rᵀ(z − z_a)), from μ_ref
// (inside the margin box by its construction). On success μ (clamped into the box: rounding) into λ = −μ on the
// locked DOFs, and z. z holds z_b on entry; fs.free_reference holds z_a.
bool boundedLeastEffort(const FrictionResult& fr, int base_velocity_size, Eigen::Index nullity,
                        Eigen::Index locked_count, int max_iterations, Eigen::Ref<Eigen::VectorXd> z,
                        FrictionScratch& fs) {
  const auto row = [&](Eigen::Index t) {
    return base_velocity_size + fr.stuck[static_cast<std::size_t>(fs.locked_dofs[static_cast<std::size_t>(t)])];
  };
  const auto P = fs.free_lambda.topLeftCorner(locked_count, nullity);
  const auto R = fs.free_factor.topLeftCorner(nullity, nullity);
  auto M = fs.free_bounded.topLeftCorner(locked_count, nullity);  // −Q: Q_c = (P_c − Σ_{d<c} Q_d R_cd) / R_cc
  for (Eigen::Index c = 0; c < nullity; ++c) {
    M.col(c) = -P.col(c);
    for (Eigen::Index d = 0; d < c; ++d) M.col(c) -= R(c, d) * M.col(d);
    M.col(c) /= R(c, c);
  }
  auto target = fs.free_shift.head(nullity);  // Rᵀ(z_b − z_a)
  auto shift = fs.free_dw.head(nullity);
  for (Eigen::Index c = 0; c < nullity; ++c) {
    double value = 0.0;
    for (Eigen::Index d = c; d < nullity; ++d) value += R(d, c) * (z[d] - fs.free_reference[d]);
    target[c] = value;
  }
  auto mu = fs.free_mu.head(locked_count), lo = fs.free_lo.head(locked_count), hi = fs.free_hi.head(locked_count);
  for (Eigen::Index t = 0; t < locked_count; ++t) {
    const auto a = static_cast<Eigen::Index>(fs.locked_dofs[static_cast<std::size_t>(t)]);
    mu[t] = -(fs.pattern_residual[row(t)] + P.row(t).dot(fs.free_reference.head(nullity)));
    lo[t] = fs.margin_lo[a];
    hi[t] = fs.margin_hi[a];
  }
  shift.setZero();
  if (!leastDistanceQp(M, target, mu, lo, hi, shift, fs.qp, max_iterations).converged) return false;
  for (Eigen::Index t = 0; t < locked_count; ++t)
    fs.pattern_residual[row(t)] = -std::clamp(mu[t] + M.row(t).dot(shift), lo[t], hi[t]);
  for (Eigen::Index c = nullity - 1; c >= 0; --c) {  // z = z_a + R⁻ᵀ shift
    double value = shift[c];
    for (Eigen::Index d = c + 1; d < nullity; ++d) value -= R(d, c) * (z[d] - fs.free_reference[d]);
    z[c] = fs.free_reference[c] + value / R(c, c);
  }
  return true;
}

// Rows the locks make dependent (feet on the ground with every joint sticking: the rigid robot stands on more rows
// than it has coordinates; an arm holding a 6-D pose with every joint sticking: nothing moves). The pattern's
// motion is unique, but ν is free along the balance's null directions n, and with it the locked DOFs' friction:
// λ = λ₀ + P z, P's columns the λ a unit ν along each n gives (−Sᵀ Σ A n over the subtree). These are the
// maximisers with this motion; among them the full solve's choice ("When μ* is not unique"):
//  (a) the smallest μ = −λ, λ₀ projected off range(P): z = −(PᵀP)⁻¹Pᵀλ₀ (Fixed stops here);
//  (b) Own, where (a) is strictly inside its box: the least ‖h + μ‖² within the margin box about it,
//      h = d q̈ + Sᵀ Σ (I a + F_bias) what each motor carries without friction: z = (PᵀP)⁻¹Pᵀ(h − λ₀).
// Then λ ← λ₀ + P z, ν ← ν + N z. A smallest μ outside its box breaks the pattern (the pivoting goes on); a pick
// (b) outside the margin box (the full solve's bounded least-distance problem decides), or P's columns nearly
// dependent (a direction the joints hardly feel): false.
bool leastEffortFriction(const Model& model, const Task& task, const FrictionResult& fr, FreeNu effort,
                         const FrictionOptions& options, Workspace& ws, FrictionScratch& fs) {
  WorkspaceScratch& sw = scratchOf(ws);
  const BalanceFactorisation& f = sw.balance_factorisation;
  const int m = task.solverColumns(), base_velocity_size = model.baseVelocitySize();
  const Eigen::Index nullity = f.near_null_count;
  fs.locked_dofs.clear();  // reserved for every DOF: no allocation
  for (std::size_t a = 0; a < fr.stuck.size(); ++a)
    if (locked(fs.trial_state[a])) fs.locked_dofs.push_back(static_cast<int>(a));
  const auto locked_count = static_cast<Eigen::Index>(fs.locked_dofs.size());
  const auto row = [&](Eigen::Index t) {
    return base_velocity_size + fr.stuck[static_cast<std::size_t>(fs.locked_dofs[static_cast<std::size_t>(t)])];
  };
  auto P = fs.free_lambda.topLeftCorner(locked_count, nullity);
  for (Eigen::Index e = 0; e < nullity; ++e) {
    prescribedConstraintTorques(model, task, ws, f.near_null_basis.col(e).head(m), fs.pattern_direction);
    for (Eigen::Index t = 0; t < locked_count; ++t) P(t, e) = fs.pattern_direction[row(t)];
  }
  if (!factorNormalMatrix(nullity, locked_count, fs)) return false;
  auto z = fs.free_step.head(nullity);
  for (Eigen::Index t = 0; t < locked_count; ++t) fs.free_target[t] = -fs.pattern_residual[row(t)];  // (a): −λ₀
  normalSolve(nullity, locked_count, fs, z);
  const auto lo = fs.lo.head(static_cast<Eigen::Index>(fr.stuck.size()));
  const auto hi = fs.hi.head(static_cast<Eigen::Index>(fr.stuck.size()));
  if (effort == FreeNu::Own && strictlyInside(model, fr, z, lo, hi, fs)) {
    for (Eigen::Index t = 0; t < locked_count; ++t) {  // the margin box about μ_ref (finite bounds only)
      const auto a = static_cast<Eigen::Index>(fs.locked_dofs[static_cast<std::size_t>(t)]);
      const double f_a = options.margin * fs.breakaway[fr.stuck[static_cast<std::size_t>(a)]];
      const double mu_ref = -(fs.pattern_residual[row(t)] + P.row(t).dot(z));
      fs.margin_lo[a] = std::isfinite(lo[a]) ? std::max(lo[a], std::min(-f_a, mu_ref)) : lo[a];
      fs.margin_hi[a] = std::isfinite(hi[a]) ? std::min(hi[a], std::max(f_a, mu_ref)) : hi[a];
    }
    // (b): h − λ₀, h the residual without ν (prescribedTorques counts the contacts' forces only: none here) + τ.
    prescribedTorques(model, task, ws, sw.nu_columns.head(m), ws.solution.qdd, fs.pattern_tau, fs.pattern_direction);
    for (Eigen::Index t = 0; t < locked_count; ++t)
      fs.free_target[t] = fs.pattern_direction[row(t)] + fs.pattern_tau[row(t)] - fs.pattern_residual[row(t)];
    fs.free_reference.head(nullity) = z;  // z_a
    normalSolve(nullity, locked_count, fs, z);
    if (!strictlyInside(model, fr, z, fs.margin_lo.head(lo.size()), fs.margin_hi.head(hi.size()), fs)) {
      if (!boundedLeastEffort(fr, base_velocity_size, nullity, locked_count, options.max_iterations, z, fs))
        return false;
      fs.pattern_on_bounds = true;  // λ set: μ may sit on the margin box
    }
  }
  if (!fs.pattern_on_bounds)
    for (Eigen::Index t = 0; t < locked_count; ++t) fs.pattern_residual[row(t)] += P.row(t).dot(z);
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

// Own's choice is the full solve's only where the balance with the stuck DOFs free is regular: rows nearly
// dependent with them free (which the full solve damps) can be exactly dependent with them locked, and then P
// cannot tell (one null direction has no others to be near). One inward sweep and balance with the task's own
// modes (𝓛 does not depend on τ) tell; the pass's ν, right-hand side and report are put back.
bool freeBalanceRegular(const Model& model, const Task& task, Workspace& ws, FrictionScratch& fs) {
  WorkspaceScratch& sw = scratchOf(ws);
  const int m = task.solverColumns();
  fs.pattern_nu.head(m) = sw.nu_columns.head(m);
  fs.pattern_rhs.head(m) = sw.rhs.head(m);
  const BalanceReport kept = ws.solution.balance;
  bindTaskModes(task, sw);
  bool regular = inwardSweep(model, task, fs.tau_effective, ws).ok();
  if (regular) {
    balance(task, ws);
    // Certified as the regular path certifies (κ̃_F·threshold < 1): a balance the full solve cannot certify may
    // carry rounding of its condition into its answer (stress seed 72: κ̃_F 1.3e6, nothing damped).
    const BalanceReport& free = ws.solution.balance;
    regular = !free.singular && free.condition * task.balance.singular_threshold < 1.0;
  }
  sw.nu_columns.head(m) = fs.pattern_nu.head(m);
  sw.rhs.head(m) = fs.pattern_rhs.head(m);
  ws.solution.balance = kept;
  return regular;
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
      // The bounded least effort puts μ on its margin box by choice, among maximisers that all stick: inside Λ
      // is all it needs.
      const double margin = fs.pattern_on_bounds ? 0.0 : kBoxMargin * (1.0 + fs.breakaway[j]);
      const bool inside = fs.pattern_on_bounds ? fs.mu[e] >= fs.lo[e] && fs.mu[e] <= fs.hi[e]
                                               : fs.mu[e] > fs.lo[e] + margin && fs.mu[e] < fs.hi[e] - margin;
      if (!inside) return false;
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
bool pivotToOptimum(const Model& model, const Task& task, const FrictionResult& fr, int max_passes,
                    const FrictionOptions& options, Workspace& ws, FrictionScratch& fs, double& acc_tolerance,
                    int& passes) {
  WorkspaceScratch& sw = scratchOf(ws);
  const FreeNu effort = freeNuEffort(task);
  const bool free_nu = effort != FreeNu::None;
  copyTaskModes(task, fs);
  sw.dof_modes = fs.pattern_modes.data();
  sw.prescribed_qdd = fs.pattern_qdd.data();
  int fewest = std::numeric_limits<int>::max(), block_tries = kBlockTries;
  while (passes < max_passes) {
    sw.prescribed_count = lockPattern(model, task, fr, fs);
    // More rows and locks than the motion has coordinates: the balance is singular (μ* not unique), which
    // leastEffortFriction resolves where every row is a contact or none is.
    if (!free_nu && sw.prescribed_count + task.balanceRows() > model.nv()) return false;
    ++passes;
    fs.pattern_indeterminate = false;
    fs.pattern_on_bounds = false;
    if (!passOfSweeps(model, task, free_nu, ws, fs)) return false;
    if (!ws.solution.balance.nu_unique && !leastEffortFriction(model, task, fr, effort, options, ws, fs)) return false;
    const int broken = brokenConditions(model, fr, ws.solution.qdd, fs);
    if (broken < 0) return false;
    if (broken == 0)
      return patternHolds(model, fr, ws.solution.qdd, fs, acc_tolerance) &&
             (effort != FreeNu::Own || !fs.pattern_indeterminate || freeBalanceRegular(model, task, ws, fs));
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
                    const FrictionOptions& options, Workspace& ws, FrictionScratch& fs, double& acc_tolerance,
                    int& passes) {
  passes = 0;
  if (fr.stuck.empty() || max_passes < 1) return false;
  if (from_kept)
    startFromKept(fr, fs);
  else
    startSticking(fr, fs);
  const bool held = pivotToOptimum(model, task, fr, max_passes, options, ws, fs, acc_tolerance, passes);
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
