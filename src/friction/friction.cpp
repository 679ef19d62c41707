// Static friction: the exact maximum-dissipation motion (docs/friction.md; the
// report's chapter 5). One pass of the Popov–Vereshchagin sweeps with μ = 0,
// plus one extra right-hand side per stuck joint through the same sweeps,
// gives the characteristic equation q̈(μ) = q̈(0) − K_Θ μ (eq. 5.10); the dual
// g(μ) = g(0) + μᵀ q̈_Θ(0) − ½ μᵀ K_ΘΘ μ is then maximised over the box Λ.
//
// How it differs from the report (section 5.4):
//  * g is maximised exactly, as the concave box QP it is, instead of by
//    sampling μ on a grid: the sweeps give K_ΘΘ and q̈_Θ(0) directly;
//  * ∂q̈/∂μ for all k stuck joints comes from one extra pass of the sweeps
//    with k right-hand sides (O(N·k)), not from k further solves;
//  * where the maximiser is not unique, the one with the least motor effort
//    is chosen (src/friction/friction_maximisers.cpp);
//  * joint position limits are one-sided reactions in the same box.
//
// solveWithFriction is the driver; each stage below is named after its
// section of docs/friction.md.
#include "zwang/friction.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "dynamics/checks.hpp"
#include "dynamics/popov_vereshchagin.hpp"
#include "friction/friction_scratch.hpp"
#include "friction/stick_pattern.hpp"
#include "qp/box_qp.hpp"

namespace zwang {

const char* toString(JointState state) {
  switch (state) {
    case JointState::Moving: return "moving";
    case JointState::Stick: return "stick";
    case JointState::SlipPositive: return "slip+";
    case JointState::SlipNegative: return "slip-";
    case JointState::AtLimit: return "at-limit";
    case JointState::Prescribed: return "prescribed";
  }
  return "unknown";
}

const char* toString(FrictionMethod method) {
  switch (method) {
    case FrictionMethod::Automatic: return "automatic";
    case FrictionMethod::ActiveSet: return "active_set";
    case FrictionMethod::ProjectedGradient: return "projected_gradient";
    case FrictionMethod::StickPatterns: return "stick_patterns";
  }
  return "unknown";
}

namespace {

using namespace internal;
constexpr double kInf = std::numeric_limits<double>::infinity();

// The friction vectors (FrictionOptions, FrictionResult) have one entry per
// DOF below the root: entry j is DOF baseVelocitySize() + j of v. The root
// joint of a floating base is unactuated: no friction unknowns.
int dofOfEntry(const Model& model, int j) { return model.baseVelocitySize() + j; }
const Dof& frictionDof(const Model& model, int j) {
  return model.dofs()[static_cast<std::size_t>(dofOfEntry(model, j))];
}
// The friction entry of a one-DOF joint (a mimic joint or its leader).
int entryOfJoint(const Model& model, int joint) { return model.joint(joint).v_index - model.baseVelocitySize(); }

Status checkOptions(const Model& model, const FrictionOptions& o) {
  const int n = model.dof();
  const struct {
    const char* name;
    const Eigen::VectorXd& v;
  } overrides[] = {{"breakaway", o.breakaway}, {"kinetic", o.kinetic}, {"viscous", o.viscous}};
  for (const auto& ov : overrides) {
    if (ov.v.size() != 0 && ov.v.size() != n)
      return Status::error(StatusCode::BadOption, "friction override '%s' has %ld entries, the model has %d joints",
                           ov.name, static_cast<long>(ov.v.size()), n);
    for (Eigen::Index j = 0; j < ov.v.size(); ++j)
      if (!std::isfinite(ov.v[j]) || ov.v[j] < 0.0)
        return Status::error(StatusCode::BadOption,
                             "friction override '%s' for joint '%s' is %g (must be finite and >= 0)", ov.name,
                             frictionDof(model, static_cast<int>(j)).name.c_str(), ov.v[j]);
  }
  if (!(o.velocity_tolerance >= 0.0) || !std::isfinite(o.velocity_tolerance))
    return Status::error(StatusCode::BadOption, "velocity_tolerance %g must be finite and >= 0", o.velocity_tolerance);
  if (!(o.limit_tolerance >= 0.0) || !std::isfinite(o.limit_tolerance))
    return Status::error(StatusCode::BadOption, "limit_tolerance %g must be finite and >= 0", o.limit_tolerance);
  if (!(o.margin >= 0.0 && o.margin <= 1.0))
    return Status::error(StatusCode::BadOption, "margin %g must be in [0, 1]", o.margin);
  if (o.max_iterations < 1) return Status::error(StatusCode::BadOption, "max_iterations must be at least 1");
  if (!(o.kkt_tolerance > 0.0)) return Status::error(StatusCode::BadOption, "kkt_tolerance must be positive");
  return {};
}

// The friction results a solve writes in place: public vectors a user could
// resize (or swap out), which the solve would then write past (or, for the
// stuck set, grow by allocating).
Status checkFrictionResultSizes(const Model& model, const FrictionResult& fr) {
  const int n = model.dof();
  const struct {
    const char* name;
    const char* unit;
    Eigen::Index size, expected;
  } results[] = {{"mu", "entries", fr.mu.size(), n},
                 {"tau_friction", "entries", fr.tau_friction.size(), n},
                 {"state", "entries", static_cast<Eigen::Index>(fr.state.size()), n},
                 {"dqdd_dmu", "rows", fr.dqdd_dmu.rows(), model.nv()},
                 {"dqdd_dmu", "columns", fr.dqdd_dmu.cols(), n}};
  for (const auto& r : results)
    if (r.size != r.expected)
      return Status::error(StatusCode::SizeMismatch,
                           "workspace result friction.%s has %ld %s, expected %ld (a workspace's results must keep "
                           "their sizes)",
                           r.name, static_cast<long>(r.size), r.unit, static_cast<long>(r.expected));
  if (fr.stuck.capacity() < static_cast<std::size_t>(n))
    return Status::error(StatusCode::SizeMismatch,
                         "workspace result friction.stuck has room for %ld joints, expected %d (a workspace's "
                         "results must keep their sizes)",
                         static_cast<long>(fr.stuck.capacity()), n);
  return {};
}

// ---- The model of friction: f, f_c, b per joint; the stuck set Θ₀ and its
// box Λ (a joint on a position limit gets an unbounded side: the stop pushes);
// kinetic and viscous friction of the moving joints folded into τ.
void stuckSetAndKineticFriction(const Model& model, const Task& task, const Eigen::Ref<const Eigen::VectorXd>& q,
                                const Eigen::Ref<const Eigen::VectorXd>& qd,
                                const Eigen::Ref<const Eigen::VectorXd>& tau, const FrictionOptions& options,
                                FrictionScratch& fs, FrictionResult& fr) {
  const int n = model.dof();
  const int base_velocity_size = model.baseVelocitySize();  // entry j is DOF base_velocity_size + j
  const std::vector<Dof>& dofs = model.dofs();
  for (int j = 0; j < n; ++j) {
    const Dof& dof = dofs[static_cast<std::size_t>(base_velocity_size + j)];
    fs.breakaway[j] = options.breakaway.size() ? options.breakaway[j] : dof.breakaway_friction;
    fs.kinetic[j] = options.kinetic.size() ? options.kinetic[j] : dof.kinetic_friction;
    fs.viscous[j] = options.viscous.size() ? options.viscous[j] : dof.viscous_friction;
    fs.is_mimic[j] = 0;
  }
  // A mimic joint moves with its leader (q̇_m = a·q̇_l, sticks when it sticks),
  // and its friction torque acts on the motion as a times it at the leader:
  // the two boxes add, f_l + |a|·f_m (likewise kinetic), and viscous b_l + a²·b_m.
  // The leader carries it all; the mimic joint is not in the stuck set.
  for (const int mimic : model.mimicJoints()) {
    const Mimic& law = model.joint(mimic).mimic;
    const double a = law.multiplier;
    const int m = entryOfJoint(model, mimic), l = entryOfJoint(model, law.leader);
    fs.breakaway[l] += std::abs(a) * fs.breakaway[m];
    fs.kinetic[l] += std::abs(a) * fs.kinetic[m];
    fs.viscous[l] += a * a * fs.viscous[m];
    fs.breakaway[m] = fs.kinetic[m] = fs.viscous[m] = 0.0;
    fs.is_mimic[m] = 1;
  }
  fr.stuck.clear();
  fr.limit_impact = false;
  fr.impact_joint = -1;
  fs.tau_effective = tau;
  fr.tau_friction.setZero();
  for (int j = 0; j < n; ++j) {
    if (fs.is_mimic[j]) {  // friction and limits are its leader's (above)
      fr.state[static_cast<std::size_t>(j)] = JointState::Moving;
      continue;
    }
    const int v = base_velocity_size + j;
    const Dof& dof = dofs[static_cast<std::size_t>(v)];
    // Limits belong to one-DOF joints (a multi-DOF joint's are ±∞: never at one).
    const bool limited = options.joint_limits && (std::isfinite(dof.lower) || std::isfinite(dof.upper));
    const double qj = limited ? q[model.joint(dof.joint).q_index] : 0.0, qdj = qd[v];
    const bool at_lower = limited && qj <= dof.lower + options.limit_tolerance;
    const bool at_upper = limited && qj >= dof.upper - options.limit_tolerance;
    const bool prescribed = isPrescribed(task, v);
    if (std::abs(qdj) <= options.velocity_tolerance && !prescribed) {
      const auto a = static_cast<Eigen::Index>(fr.stuck.size());
      fr.stuck.push_back(j);
      fs.lo[a] = at_lower ? -kInf : -fs.breakaway[j];  // the stop pushes positively without bound
      fs.hi[a] = at_upper ? kInf : fs.breakaway[j];
      fr.state[static_cast<std::size_t>(j)] = JointState::Stick;
    } else if (prescribed && std::abs(qdj) <= options.velocity_tolerance) {  // its motor gives all it takes
      fr.state[static_cast<std::size_t>(j)] = JointState::Prescribed;
    } else {
      fr.tau_friction[j] = -fs.kinetic[j] * (qdj > 0 ? 1.0 : -1.0) - fs.viscous[j] * qdj;
      fs.tau_effective[v] += fr.tau_friction[j];
      fr.state[static_cast<std::size_t>(j)] = prescribed ? JointState::Prescribed : JointState::Moving;
      if ((at_lower && qdj < 0) || (at_upper && qdj > 0)) {
        fr.limit_impact = true;  // it needs an impulse to stop: reported, not modelled
        if (fr.impact_joint < 0) fr.impact_joint = j;
      }
    }
  }
}

// ---- ∂q̈/∂μ in the same sweeps: the motion at μ = 0 (q̈(0), ν(0)) and, per
// stuck joint, the columns δq̈, δν of a unit torque there (the kinematics done).
Status sweepsWithSensitivities(const Model& model, const Task& task, const std::vector<int>& stuck, Workspace& ws,
                               FrictionScratch& fs) {
  WorkspaceScratch& sw = scratchOf(ws);
  const int m = task.solverColumns();
  const auto stuck_count = static_cast<Eigen::Index>(stuck.size());
  if (Status s = inwardSweep(model, task, fs.tau_effective, ws); !s) return s;
  balance(task, ws);
  outwardAccelerations(model, task, ws, fs.qdd0);
  fs.nu0.head(m) = sw.nu_columns.head(m);
  fs.stuck_dofs.clear();  // reserved for every DOF: no allocation
  for (const int j : stuck) fs.stuck_dofs.push_back(dofOfEntry(model, j));
  if (stuck_count > 0)
    unitTorqueColumns(model, task, ws, fs.stuck_dofs, fs.unit_torques, fs.dnu.topLeftCorner(m, stuck_count),
                      fs.dqdd.leftCols(stuck_count));
  return {};
}

// ---- The size of the terms each stuck joint's entries of K_ΘΘ and q̈_Θ(0)
// are sums of (line 28 of the sweep, for q̈(0) and for a unit torque at
// joint j, body i): a joint the task holds still has both at rounding level
// of these, however small they come out.
//   q̈_j(0) = (u_i − (I^A_iS_i)ᵀ Ẍ_parent + S_iᵀA_i ν) / D_i
//   −K_jj  = (1 − (I^A_iS_i)ᵀ δẌ_parent + S_iᵀA_i δν) / D_i
// Each sum is taken term by term in absolute value; δẌ_parent, sweep
// scratch by now, is rebuilt term by term from the column's δq̈ on the path
// to the base (line 29, every motion in the world frame).
Vec6 parentAccelerationTerms(const Model& model, const Workspace& ws, const FrictionScratch& fs, Eigen::Index a,
                             int body) {
  const WorkspaceScratch& sw = scratchOf(ws);
  // A joint's motion S δq̈ is one term, however many DOFs it has (its DOFs
  // share a body: their parts are the components of one motion).
  Vec6 terms = Vec6::Zero(), joint_motion = Vec6::Zero();
  for (int l = model.parent(body); l > 0; l = model.parent(l)) {
    joint_motion += sw.S[static_cast<std::size_t>(l)] * fs.dqdd(l - 1, a);
    if (model.jointStart(l) != l) continue;  // the compact array: cheaper to read than a Dof
    terms += joint_motion.cwiseAbs();
    joint_motion.setZero();
  }
  return terms;
}

void termSizes(const Model& model, const Task& task, const Workspace& ws, const std::vector<int>& stuck,
               FrictionScratch& fs) {
  const WorkspaceScratch& sw = scratchOf(ws);
  for (std::size_t b = 0; b < stuck.size(); ++b) {
    const auto a = static_cast<Eigen::Index>(b);
    const int i = bodyOfDof(dofOfEntry(model, stuck[b]));
    const auto at_i = static_cast<std::size_t>(i);
    const int first = solverOrder(task).firstColumn(i), count = solverOrder(task).columnsEnd(i) - first;
    const auto SA = sw.SA.col(i).segment(first, count).cwiseAbs();
    const Vec6 IAS = sw.IAS[at_i].cwiseAbs();
    fs.curvature_terms[a] = (1.0 + IAS.dot(parentAccelerationTerms(model, ws, fs, a, i)) +
                             SA.dot(fs.dnu.col(a).segment(first, count).cwiseAbs())) *
                            sw.inverse_D[at_i];
    fs.slope_terms[a] = (std::abs(sw.u[at_i]) + IAS.dot(sw.a[static_cast<std::size_t>(model.parent(i))].cwiseAbs()) +
                         SA.dot(sw.nu_columns.segment(first, count).cwiseAbs())) *
                        sw.inverse_D[at_i];
  }
}

// ---- The maximiser: K_ΘΘ and q̈_Θ(0) gathered from the columns, the scales
// its tests are relative to, and the box QP. μ* into fs.mu.
QpReport maximiseDual(const Model& model, const Task& task, const Workspace& ws, const std::vector<int>& stuck,
                      const FrictionOptions& options, double acc_scale, FrictionScratch& fs) {
  const WorkspaceScratch& sw = scratchOf(ws);
  const auto stuck_count = static_cast<Eigen::Index>(stuck.size());
  const int base_velocity_size = model.baseVelocitySize();  // the friction entries' rows of q̈ follow
  auto K = fs.K.topLeftCorner(stuck_count, stuck_count);
  for (Eigen::Index a = 0; a < stuck_count; ++a)
    fs.qdd0_stuck[a] = fs.qdd0[base_velocity_size + stuck[static_cast<std::size_t>(a)]];
  if (stuck_count > 0) {  // K_ΘΘ = rows Θ of −∂q̈/∂μ (raw gathers); none stuck: dqdd may be empty, data() null
    const int* rows = stuck.data();
    const double* dqdd = fs.dqdd.data() + base_velocity_size;
    const Eigen::Index dqdd_stride = fs.dqdd.outerStride();
    double* p = K.data();
    const Eigen::Index p_stride = K.outerStride();
    for (Eigen::Index b = 0; b < stuck_count; ++b) {  // symmetric in exact arithmetic (K is): the mean of both halves
      const double* dqdd_b = dqdd + b * dqdd_stride;
      const int row_b = rows[b];
      p[b + b * p_stride] = dqdd_b[row_b];
      for (Eigen::Index a = b + 1; a < stuck_count; ++a)
        p[a + b * p_stride] = p[b + a * p_stride] = 0.5 * (dqdd_b[rows[a]] + dqdd[row_b + a * dqdd_stride]);
    }
  }
  // The size of the terms K_ΘΘ is computed from (1/D_j, and the columns'
  // entries): where the task pins the stuck joints, K_ΘΘ is that times
  // rounding, and a stop the task pushes into must come out unbounded
  // rather than as a 1e16 N·m torque (the maximiser's reach rule).
  double curvature_scale = 0.0;
  if (stuck_count > 0) {
    double min_D = kInf;
    for (Eigen::Index a = 0; a < stuck_count; ++a)
      min_D = std::min(min_D, dofInertia(ws, dofOfEntry(model, stuck[static_cast<std::size_t>(a)])));
    curvature_scale = std::max(1.0 / min_D, fs.dqdd.leftCols(stuck_count).cwiseAbs().maxCoeff());
    // The task's part of ∂q̈/∂μ, Sᵀ A δν / D, is a sum of terms of size
    // |SᵀA|·|δν|/D, which an ill-conditioned balance makes large while their
    // sum, where the task pins a stuck joint, is rounding of them (a stop the
    // task pushes into through relative rows: test_mimic).
    const int m = task.solverColumns();
    if (m > 0)
      curvature_scale = std::max(
          curvature_scale, fs.dnu.topLeftCorner(m, stuck_count).cwiseAbs().maxCoeff() *
                               sw.SA.block(0, bodyOfDof(dofOfEntry(model, 0)), m, model.dof()).cwiseAbs().maxCoeff() /
                               min_D);  // over the DOFs friction acts on
  }
  termSizes(model, task, ws, stuck, fs);
  const double tolerance = options.kkt_tolerance * acc_scale;
  auto mu = fs.mu.head(stuck_count);
  mu.setZero();  // feasible: 0 ∈ Λ
  if (stuck_count == 0) return {};
  const TermSizes terms{curvature_scale, Eigen::Map<const Eigen::VectorXd>(fs.curvature_terms.data(), stuck_count),
                        Eigen::Map<const Eigen::VectorXd>(fs.slope_terms.data(), stuck_count)};
  return options.method != FrictionMethod::ProjectedGradient
             ? boxQpActiveSet(K, fs.qdd0_stuck.head(stuck_count), fs.lo.head(stuck_count), fs.hi.head(stuck_count), mu,
                              fs.qp, options.max_iterations, tolerance, terms)
             : boxQpProjectedGradient(K, fs.qdd0_stuck.head(stuck_count), fs.lo.head(stuck_count),
                                      fs.hi.head(stuck_count), mu, fs.qp, options.max_iterations, tolerance, terms);
}

// ---- The motion at μ*: the sweeps are linear in the torques, so
// q̈(μ*) = q̈(0) + (∂q̈/∂τ_Θ)(−μ*) and ν(μ*) likewise (lines 26–30 by
// superposition), then Ẍ from q̈ (line 29). With nothing stuck, μ* is
// empty and the μ = 0 sweep already gave it.
void motionAtMaximiser(const Model& model, const Task& task, Eigen::Index stuck_count, Workspace& ws,
                       FrictionScratch& fs) {
  WorkspaceScratch& sw = scratchOf(ws);
  const int m = task.solverColumns();
  Solution& out = ws.solution;
  out.qdd = fs.qdd0;
  if (stuck_count == 0) return;
  const auto mu = fs.mu.head(stuck_count);
  out.qdd.noalias() -= fs.dqdd.leftCols(stuck_count) * mu;
  sw.nu_columns.head(m) = fs.nu0.head(m);
  sw.nu_columns.head(m).noalias() -= fs.dnu.topLeftCorner(m, stuck_count) * mu;
  bodyAccelerations(model, task, ws, out.qdd);
}

// ---- When μ* is not unique: what each stuck joint's motor would carry at the
// QP's maximiser without friction, h = τ + τ_c(μ*) − μ*, and the margin box.
void effortAtFirstMaximiser(const Model& model, const Task& task, const Eigen::Ref<const Eigen::VectorXd>& tau,
                            const std::vector<int>& stuck, const FrictionOptions& options, Workspace& ws,
                            FrictionScratch& fs) {
  const int m = task.solverColumns();
  const auto stuck_count = static_cast<Eigen::Index>(stuck.size());
  fs.nu_first.head(m) = fs.nu0.head(m);  // ν(μ*) by superposition
  fs.nu_first.head(m).noalias() -= fs.dnu.topLeftCorner(m, stuck_count) * fs.mu.head(stuck_count);
  constraintTorques(model, task, ws, fs.nu_first.head(m), fs.tau_constraint_first);
  if (task.prescribedCount() > 0) {  // their torques need the motion: that of every maximiser (q̈* is unique)
    motionAtMaximiser(model, task, stuck_count, ws, fs);
    prescribedTorques(model, task, ws, fs.nu_first.head(m), ws.solution.qdd, fs.tau_effective, fs.tau_constraint_first);
  }
  fs.tau_control_first = tau + fs.tau_constraint_first;
  carryMimicTorques(model, fs.tau_control_first);
  for (Eigen::Index a = 0; a < stuck_count; ++a) {
    const int j = stuck[static_cast<std::size_t>(a)];
    fs.effort_offset[a] = fs.tau_control_first[dofOfEntry(model, j)] - fs.mu[a];
    fs.margin_limit[a] = options.margin * fs.breakaway[j];
  }
}

// ---- When μ* is not unique, how the joints' τ_control moves along the flat
// directions N (EffortChange). Without contacts every row's force is in
// τ_control, so on the maximisers τ_control moves one for one with μ on Σ and
// nowhere else (Own). With them, τ_control = τ + τ_c(ν), ν(μ) = ν(0) − δν μ
// and τ_c linear in ν (contacts excluded): along N's column e it moves by
// B_e = −τ_c(δν_Σ N_e), the mimic joints' carried by their leaders as
// controlTorques does; one pass of constraintTorques per flat direction. B
// is then compared with Own's E_Σ N (E_Σ: the sticking joints' unit rows):
// a contact that takes no share of the friction keeps the Own path.
EffortChange effortAlongFlatDirections(const Model& model, const Task& task, const std::vector<int>& stuck,
                                       Eigen::Index ns, Eigen::Index nullity, Workspace& ws, FrictionScratch& fs) {
  if (!task.hasContacts()) return EffortChange::Own;
  const int m = task.solverColumns(), n = model.dof();
  bool motor_rows = false;
  for (int col = 0; col < m && !motor_rows; ++col)
    motor_rows = !solverOrder(task).contactColumns()[static_cast<std::size_t>(col)];
  if (!motor_rows) return EffortChange::Fixed;  // τ_c ≡ 0: τ_control = τ whatever μ
  MaximiserChoiceScratch& s = fs.choice;
  const auto N = s.null_basis.topLeftCorner(ns, nullity);
  const auto sticking = s.sticking.head(ns);
  auto B = s.effort_gradient.topLeftCorner(n, nullity);
  auto nu_direction = s.nu_direction.head(m);
  auto tau_direction = s.tau_direction.tail(n);
  // B is τ_control per unit of friction: 1e-9 of it moves τ_control by 1e-9
  // of the box's width, what the choice counts as one maximiser (mu_scale).
  constexpr double kSameChange = 1e-9;
  double largest = 0.0, off_own = 0.0;
  for (Eigen::Index e = 0; e < nullity; ++e) {
    nu_direction.setZero();  // −δν_Σ N_e
    for (Eigen::Index t = 0; t < ns; ++t) nu_direction.noalias() -= N(t, e) * fs.dnu.col(sticking[t]).head(m);
    constraintTorques(model, task, ws, nu_direction, s.tau_direction);
    prescribedContactTorques(model, task, ws, nu_direction, s.tau_direction);
    carryMimicTorques(model, s.tau_direction);
    B.col(e) = tau_direction;
    largest = std::max(largest, tau_direction.cwiseAbs().maxCoeff());
    for (Eigen::Index t = 0; t < ns; ++t) tau_direction[stuck[static_cast<std::size_t>(sticking[t])]] -= N(t, e);
    off_own = std::max(off_own, tau_direction.cwiseAbs().maxCoeff());
  }
  s.effort_first.head(n) = fs.tau_control_first.tail(n);
  if (!(largest > kSameChange)) return EffortChange::Fixed;
  return off_own <= kSameChange ? EffortChange::Own : EffortChange::Shared;
}

// ---- Outputs: μ* per joint, the state of each stuck joint, the torques the
// joints feel; returns Σ μ*_j q̈*_j (the dual's term beyond Z).
double frictionStates(const Model& model, const Eigen::VectorXd& qdd_all, double acc_tolerance, FrictionScratch& fs,
                      FrictionResult& fr) {
  const int base_velocity_size = model.baseVelocitySize();
  const auto qdd = qdd_all.tail(model.dof());
  fr.mu.setZero();
  fs.tau_joint = fs.tau_effective;  // the torques the joints feel: τ − kinetic − Wᵀμ
  double mu_dot_qdd = 0.0;
  for (std::size_t a = 0; a < fr.stuck.size(); ++a) {
    const int j = fr.stuck[a];
    const double mu = fs.mu[static_cast<Eigen::Index>(a)], f = fs.breakaway[j];
    fr.mu[j] = mu;
    fr.tau_friction[j] = -mu;
    fs.tau_joint[base_velocity_size + j] -= mu;
    mu_dot_qdd += mu * qdd[j];
    JointState& state = fr.state[static_cast<std::size_t>(j)];
    // Beyond what friction can give (to rounding of f): the stop pushes.
    if (mu < -f - 1e-12 * (1.0 + f) || mu > f + 1e-12 * (1.0 + f))
      state = JointState::AtLimit;
    else if (qdd[j] > acc_tolerance)
      state = JointState::SlipPositive;
    else if (qdd[j] < -acc_tolerance)
      state = JointState::SlipNegative;
    else
      state = JointState::Stick;
  }
  return mu_dot_qdd;
}

// ---- The solution at μ* (q̈*, ν and the bodies' accelerations in the sweep): the solve's results, the torques,
// the joints' states, and Z and g(μ*).
void publishSolution(const Model& model, const Task& task, const Eigen::Ref<const Eigen::VectorXd>& tau,
                     double acc_tolerance, Workspace& ws, FrictionScratch& fs, FrictionResult& fr) {
  WorkspaceScratch& sw = scratchOf(ws);
  Solution& out = ws.solution;
  const int m = task.solverColumns();
  ws.kinematics.stage = KinematicsStage::Accelerations;  // those of q̈*
  out.base_acceleration_world = baseClassicalAcceleration(model, ws);
  taskResidual(task, ws);
  publishNu(task, ws);
  constraintTorques(model, task, ws, sw.nu_columns.head(m), out.tau_constraint);
  prescribedTorques(model, task, ws, sw.nu_columns.head(m), out.qdd, fs.tau_effective, out.tau_constraint);
  controlTorques(model, tau, out);  // the leaders carry their mimic joints' torques
  const double mu_dot_qdd = frictionStates(model, out.qdd, acc_tolerance, fs, fr);
  for (const int j : model.mimicJoints())  // it moves, sticks or slips with its leader
    fr.state[static_cast<std::size_t>(entryOfJoint(model, j))] =
        fr.state[static_cast<std::size_t>(entryOfJoint(model, model.joint(j).mimic.leader))];
  // g(μ*) = Z₀(q̈*) + μ*ᵀ W q̈* = Z with the joint torques τ − kinetic − Wᵀμ (eq. 5.7).
  fr.gauss_dual = gaussFunction(model, task, out.qdd, fs.tau_joint, ws);
  out.gauss = fr.gauss_dual - mu_dot_qdd;
}

// ---- The pattern search answered (src/friction/stick_pattern.cpp): its passes for iterations, no ∂q̈/∂μ (zeroed
// once after a full solve wrote it).
void publishPatternSolution(const Model& model, const Task& task, const Eigen::Ref<const Eigen::VectorXd>& tau,
                            double acc_tolerance, int passes, bool from_kept, Workspace& ws, FrictionScratch& fs,
                            FrictionResult& fr) {
  publishSolution(model, task, tau, acc_tolerance, ws, fs, fr);
  fr.method = FrictionMethod::StickPatterns;
  fr.warm_started = from_kept;
  fr.iterations = passes;
  fr.converged = true;
  fr.indeterminate = fs.pattern_indeterminate;
  fr.kkt_residual = 0.0;  // q̈ = 0 on the locked DOFs by construction, μ inside the boxes, the slips' signs checked
  if (fs.sensitivities_written) fr.dqdd_dmu.setZero();
  fs.sensitivities_written = false;
}

// ---- Which method: how many passes of the pattern search are tried before the K-based solve. A pass costs about
// half the plain solve (the sweeps without the kinematics); the K-based solve some 0.15 of it per stuck DOF and
// O(k³) on top. From every DOF sticking the search takes 4–8 passes whatever k (block pivoting changes every broken
// DOF at once), which pays from some 24 stuck DOFs on; from a kept pattern one pass mostly answers (docs/friction.md,
// "Which method": the crossover measured).
int patternPassBudget(const FrictionOptions& options, Eigen::Index stuck_count, bool from_kept) {
  constexpr Eigen::Index kColdSearchFrom = 24;  // stuck DOFs; fewer: the K-based solve costs less than the passes
  const int k = static_cast<int>(stuck_count);
  const int from_kept_passes = 2 + k / 6, cold_passes = 8 + k / 16;
  switch (options.method) {
    case FrictionMethod::StickPatterns: return options.max_iterations;
    case FrictionMethod::Automatic:
      if (from_kept) return from_kept_passes;
      return stuck_count >= kColdSearchFrom ? cold_passes : 0;
    case FrictionMethod::ActiveSet:
    case FrictionMethod::ProjectedGradient: return from_kept ? from_kept_passes : 0;
  }
  return 0;
}

// ---- Joint position limits: a stop the task pushes into makes g unbounded.
Status limitInfeasible(const Model& model, const QpReport& report, const std::vector<int>& stuck,
                       const FrictionScratch& fs) {
  const Dof& dof = frictionDof(model, stuck[static_cast<std::size_t>(report.unbounded_index)]);
  const bool lower = !std::isfinite(fs.lo[report.unbounded_index]);
  return Status::error(StatusCode::Infeasible, "the task drives joint '%s' into its %s limit (%g)", dof.name.c_str(),
                       lower ? "lower" : "upper", lower ? dof.lower : dof.upper);
}

}  // namespace

Status solveWithFriction(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                         const Eigen::Ref<const Eigen::VectorXd>& qd, const Eigen::Ref<const Eigen::VectorXd>& tau,
                         const Task& task, const FrictionOptions& options) noexcept {
  ws.kinematics.stage = KinematicsStage::None;  // until the sweeps compute them
  if (Status s = checkSolveInputs(model, task, q, qd, tau, ws); !s) return s;
  if (Status s = roomForTask(model, task, ws); !s) return s;  // allocates only for more rows than ever before
  WorkspaceScratch& sw = scratchOf(ws);
  bindTaskModes(task, sw);  // the sweeps read the DOF modes from here
  if (Status s = checkOptions(model, options); !s) return s;
  if (Status s = checkFrictionResultSizes(model, ws.friction); !s) return s;
  FrictionScratch& fs = (*sw.friction_scratch);
  FrictionResult& fr = ws.friction;
  Solution& out = ws.solution;

  jointsOutsideLimits(model, q, out);  // a warning: solved as given
  stuckSetAndKineticFriction(model, task, q, qd, tau, options, fs, fr);
  outwardSweep(model, task, q, qd, ws);  // the kinematics, whichever method runs
  const auto stuck_count = static_cast<Eigen::Index>(fr.stuck.size());
  double acc_tolerance = 0.0;  // what counts as q̈_j = 0 (a sticking joint): set by the method that answers
  const bool from_kept = options.warm_start && keptPatternApplies(model, task, fs);
  int passes = 0;
  if (searchPatterns(model, task, fr, from_kept, patternPassBudget(options, stuck_count, from_kept), options, ws, fs,
                     acc_tolerance, passes)) {
    publishPatternSolution(model, task, tau, acc_tolerance, passes, from_kept, ws, fs, fr);
    rememberPattern(model, task, fr, true, fs);
    return {};
  }
  fr.method = options.method == FrictionMethod::ProjectedGradient ? FrictionMethod::ProjectedGradient
                                                                  : FrictionMethod::ActiveSet;
  fr.warm_started = false;
  if (Status s = sweepsWithSensitivities(model, task, fr.stuck, ws, fs); !s) return s;
  if (stuck_count < model.dof()) fr.dqdd_dmu.setZero();  // a moving joint has no μ (all stuck: every column is written)
  for (Eigen::Index a = 0; a < stuck_count; ++a)         // μ_j enters as the torque −μ_j
    fr.dqdd_dmu.col(fr.stuck[static_cast<std::size_t>(a)]) = -fs.dqdd.col(a);
  fs.sensitivities_written = stuck_count > 0;
  const int base_velocity_size = model.baseVelocitySize();

  // The acceleration scale, of the stuck joints only (a light, fast joint
  // elsewhere in the chain must not set it): their accelerations q̈_Θ(0).
  double acc_max = 0.0;
  for (const int j : fr.stuck) acc_max = std::max(acc_max, std::abs(fs.qdd0[base_velocity_size + j]));
  const double acc_scale = 1.0 + acc_max;
  acc_tolerance = 1e-9 * acc_scale;
  const QpReport report = maximiseDual(model, task, ws, fr.stuck, options, acc_scale, fs);
  fr.iterations = report.iterations;
  fr.converged = stuck_count == 0 || report.converged;

  fr.indeterminate = false;
  Eigen::Index sticking = 0;
  const Eigen::Index nullity =
      stuck_count > 0 && !report.unbounded
          ? flatDirections(fs.K.topLeftCorner(stuck_count, stuck_count), fs.qdd0_stuck.head(stuck_count),
                           fs.mu.head(stuck_count), fs.lo.head(stuck_count), fs.hi.head(stuck_count),
                           fs.curvature_terms.head(stuck_count), acc_tolerance, fs.choice, sticking)
          : 0;
  if (nullity > 0) {
    effortAtFirstMaximiser(model, task, tau, fr.stuck, options, ws, fs);
    const EffortChange change = effortAlongFlatDirections(model, task, fr.stuck, sticking, nullity, ws, fs);
    const double mu_scale = 1e-9 * (1.0 + fs.breakaway.cwiseAbs().maxCoeff());  // maximisers this close are one
    fr.indeterminate =
        leastEffortMaximiser(fs.lo.head(stuck_count), fs.hi.head(stuck_count), fs.margin_limit.head(stuck_count),
                             fs.effort_offset.head(stuck_count), sticking, nullity, change, model.dof(), mu_scale,
                             options.max_iterations, fs.mu.head(stuck_count), fs.choice);
  }

  motionAtMaximiser(model, task, stuck_count, ws, fs);
  publishSolution(model, task, tau, acc_tolerance, ws, fs, fr);
  fr.kkt_residual =
      stuck_count > 0 ? boxQpKktResidual(fs.K.topLeftCorner(stuck_count, stuck_count), fs.qdd0_stuck.head(stuck_count),
                                         fs.lo.head(stuck_count), fs.hi.head(stuck_count), fs.mu.head(stuck_count))
                      : 0.0;
  rememberPattern(model, task, fr, !report.unbounded && fr.converged && !fr.indeterminate && stuck_count > 0, fs);
  if (report.unbounded) return limitInfeasible(model, report, fr.stuck, fs);
  return {};
}

}  // namespace zwang
