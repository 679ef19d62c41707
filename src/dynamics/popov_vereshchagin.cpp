// Popov–Vereshchagin constrained hybrid dynamics, stage by stage. Read next to
// Algorithm 1 of the report (chapter 4.2); "line N" refers to it. Differences:
//  * base coordinates (src/dynamics/sweeps.hpp): every spatial quantity is in
//    world axes at the world origin, so the report's ⁱX_{i−1} are identities
//    and lines 16, 18, 19 and 29 sum instead of transforming;
//  * sign of ν: the constraint wrench on a body is +A ν (docs/solver.md, "Sign of ν"; the report
//    and KDL apply −A ν). So 𝓛 below is the report's −𝓛 (positive
//    semi-definite) and line 28 has −A ν where the report has +A ν;
//  * constraints may sit on any bodies (the report's section 4.4 extension):
//    A_i collects the unit constraint forces of every constraint on body i's
//    subtree, and each body adds its own columns as the inward sweep reaches it;
//  * trees (the report treats chains): the bodies are in depth-first order,
//    "i − 1" of the report is parent(i), a parent sums what all its children
//    pass it (lines 16–18), and the columns of a subtree are one contiguous
//    block [firstColumn(i), columnsEnd(i)), so each column is projected in
//    place by every joint between its body and the base. 𝓛 gets an entry only
//    from the bodies two columns share: columns on different branches meet
//    only at their common ancestors;
//  * relative constraints (two frames on any bodies): each row is two solver
//    columns, +A on the frame's body and −A on the reference's, swept
//    independently; the balance adds the columns of each row (condensedBalance);
//  * mimic joints (q_m = a·q_l + b): one internal row q̈_m − a·q̈_l = 0 each,
//    after the user's rows, as four columns: a unit effort along each joint on
//    its body and the opposite on its parent (jointPieceInBodyForm). Its ν is
//    the coupling torque the mechanism carries; the motor torques the leader
//    carries are folded onto it at the end (carryMimicTorques);
//  * joints of any type (model.hpp): one body per DOF, so a joint of nv DOFs
//    is nv steps of the sweeps, its first nv − 1 bodies without inertia. Each
//    step is the report's one-DOF step, and together they are the block step
//    with the joint's nv × nv D_i and nv-vector u_i: the pivots D of the steps
//    are the LDLᵀ factor of that D. The inward sweep forms them in block form
//    (jointPivots: each pivot waits on a 6-vector update, not on a 6 × 6 downdate of
//    I^A) and passes I^a to the parent once per joint; the other passes go
//    DOF by DOF (docs/solver.md, "What the DOF steps cost"). A floating base
//    is the root's joint (free or planar), visited like any other; body 0 is
//    the world. Entry k of q̇, τ and q̈ belongs to body k + 1.
#include "dynamics/popov_vereshchagin.hpp"

#include "zwang/configuration.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "dynamics/balance.hpp"
#include "dynamics/checks.hpp"
#include "dynamics/sweeps.hpp"

namespace zwang::internal {

namespace {
inline std::size_t at(int i) { return static_cast<std::size_t>(i); }
}  // namespace

namespace {
// A mimic joint's q and q̇ must follow its leader's: the mechanism cannot be
// anywhere else, and solving such a state would be a silent wrong answer.
// Allowed: the rounding of a·q + b and what an integrator's steps add to it
// (1e-9 of the terms' size; Model::followLeaders sets the entries exactly).
Status checkMimicState(const Model& model, const VectorRef& q_all, const VectorRef& qd_all) {
  for (const int m : model.mimicJoints()) {
    const Joint& joint = model.joint(m);
    const Mimic& law = joint.mimic;
    const Joint& leader_joint = model.joint(law.leader);
    const char* leader = leader_joint.name.c_str();
    const double q_m = q_all[joint.q_index], q_law = law.multiplier * q_all[leader_joint.q_index] + law.offset;
    if (std::abs(q_m - q_law) > 1e-9 * (1.0 + std::abs(q_m) + std::abs(q_law) + std::abs(law.offset)))
      return Status::error(StatusCode::MimicMismatch,
                           "joint '%s' mimics '%s' (q = %g·q_leader + %g): q is %.17g, the law gives %.17g "
                           "(set by Model::followLeaders, Python follow_leaders, CLI \"follow_leaders\": true)",
                           joint.name.c_str(), leader, law.multiplier, law.offset, q_m, q_law);
    const double qd_m = qd_all[joint.v_index], qd_law = law.multiplier * qd_all[leader_joint.v_index];
    if (std::abs(qd_m - qd_law) > 1e-9 * (1.0 + std::abs(qd_m) + std::abs(qd_law)))
      return Status::error(StatusCode::MimicMismatch,
                           "joint '%s' mimics '%s' (multiplier %g): qd is %.17g, the law gives %.17g "
                           "(set by Model::followLeaders, Python follow_leaders, CLI \"follow_leaders\": true)",
                           joint.name.c_str(), leader, law.multiplier, qd_m, qd_law);
  }
  return {};
}

// The prescribed accelerations: a resizable public VectorXd, read only on the prescribed DOFs.
Status checkPrescribed(const Model& model, const Task& task) {
  const Eigen::VectorXd& qdd = task.prescribedAccelerations();
  if (qdd.size() != model.nv())
    return Status::error(StatusCode::SizeMismatch,
                         "prescribed accelerations have %ld entries, expected nv = %d "
                         "(Task::prescribedAccelerations() must keep its size)",
                         static_cast<long>(qdd.size()), model.nv());
  if (task.prescribedCount() == 0) return {};
  for (int v = 0; v < model.nv(); ++v)
    if (isPrescribed(task, v) && !std::isfinite(qdd[v]))
      return Status::error(StatusCode::NonFinite, "the prescribed acceleration of '%s' is %g",
                           model.dofs()[at(v)].name.c_str(), qdd[v]);
  return {};
}

// The results a solve writes in place: public vectors a user could resize
// (or swap out), which the solve would then write past.
Status checkSolutionSizes(const Model& model, const Solution& out) {
  const struct {
    const char* name;
    Eigen::Index size;
  } results[] = {
      {"qdd", out.qdd.size()}, {"tau_constraint", out.tau_constraint.size()}, {"tau_control", out.tau_control.size()}};
  for (const auto& r : results)
    if (r.size != model.nv())
      return Status::error(StatusCode::SizeMismatch,
                           "workspace result solution.%s has %ld entries, expected nv = %d (a workspace's results "
                           "must keep their sizes)",
                           r.name, static_cast<long>(r.size), model.nv());
  return {};
}
}  // namespace

Status checkSolveInputs(const Model& model, const Task& task, const VectorRef& q, const VectorRef& qd,
                        const VectorRef& tau, const Workspace& ws) {
  if (ws.dof() != model.dof())
    return Status::error(StatusCode::ModelMismatch, "workspace was made for %d joints, the model has %d", ws.dof(),
                         model.dof());
  if (task.modelDof() != model.dof() || task.modelFrames() != static_cast<int>(model.frames().size()))
    return Status::error(StatusCode::ModelMismatch, "task was made for another model (%d joints, %d frames)",
                         task.modelDof(), task.modelFrames());
  if (Status s = checkBalanceOptions(task.balance); !s) return s;
  if (Status s = checkConfiguration(model, q); !s) return s;  // size, finite (naming the joint), unit quaternions
  if (!workspaceFitsModel(model, ws)) return workspaceMismatch(model, ws);
  if (Status s = checkVelocityVector(model, "qd", qd); !s) return s;
  if (Status s = checkVelocityVector(model, "tau", tau); !s) return s;
  if (Status s = checkSolutionSizes(model, ws.solution); !s) return s;
  if (!task.mimicLawsMatch(model))
    return Status::error(StatusCode::ModelMismatch,
                         "task was made for a model with other mimic joints (%d; this one has %d, or other laws)",
                         task.mimicRows(), static_cast<int>(model.mimicJoints().size()));
  if (Status s = checkMimicState(model, q, qd); !s) return s;
  if (Status s = checkFinite("gravity", task.gravity); !s) return s;
  if (task.targets().size() != task.constraintRows())  // Task::targets() is a resizable VectorXd&
    return Status::error(StatusCode::SizeMismatch,
                         "constraint targets b has %ld entries, the task has %d constraint rows (Task::targets() "
                         "must keep its size)",
                         static_cast<long>(task.targets().size()), task.constraintRows());
  if (Status s = checkFinite("constraint targets b", task.targets()); !s) return s;
  if (Status s = checkPrescribed(model, task); !s) return s;
  for (int w = 0; w < task.wrenchCount(); ++w)
    if (!task.wrench(w).allFinite())
      return Status::error(StatusCode::NonFinite, "wrench %d (on frame '%s') is not finite", w,
                           model.frame(task.wrenches()[at(w)].frame).name.c_str());
  return {};
}

Status roomForTask(const Model& model, const Task& task, Workspace& ws) noexcept {
  if (Status s = ws.reserve(model, task.constraintRows()); !s) return s;
  // Left when the model has more mimic joints than the one the workspace was made for (same joints otherwise).
  if (task.solverColumns() > ws.columnCapacity() || task.balanceRows() > ws.balanceCapacity())
    return Status::error(StatusCode::WorkspaceTooSmall,
                         "task has %d balance rows (%d constraint, %d mimic), the workspace was made for at most %d",
                         task.balanceRows(), task.constraintRows(), task.mimicRows(), ws.balanceCapacity());
  return {};
}

namespace {

// One side of a relative constraint (Task::addRelativeConstraint) in body
// form. The row constrains p̈_rel and ω̇_rel, the acceleration of frame a's
// origin and angular velocity as seen riding on the reference frame r
// (docs/solver.md, "Relative constraints"). With d = p_a − p_r, world axes:
//   p̈_rel = (a_a − a_r)_lin + (α_a − α_r) × p_a + β_lin,
//   β_lin = ω_a × v_a − ω_r × v_r − 2 ω_r × (v_a − v_r) + ω_r × (ω_r × d),
//   ω̇_rel = α_a − α_r + ω_a × ω_r,
// v_a, v_r the velocities of the two origins. So the column is A = [f; n + p_a × f]
// on a's body and −A on r's, and b − f·β_lin − n·(ω_a × ω_r) is the set point
// (kept on a's side; r's side has 0, the balance adds the two). Gravity
// shifts both bodies' sweep accelerations alike and cancels.
void relativeConstraintInBodyForm(const Model& model, const Task& task, const TaskSolverOrder::ConstraintGroup& g,
                                  int col, Workspace& ws) {
  WorkspaceScratch& sw = scratchOf(ws);
  const Transform Xa = framePlacementInBase(model, ws, g.frame);
  const Transform Xr = framePlacementInBase(model, ws, g.reference);
  const Vec6& va = sw.v[at(model.frame(g.frame).body)];
  const Vec6& vr = sw.v[at(model.frame(g.reference).body)];
  const Vec3 wa = va.tail<3>(), wr = vr.tail<3>();
  const Vec3 pa_dot = va.head<3>() + wa.cross(Xa.r), pr_dot = vr.head<3>() + wr.cross(Xr.r);
  const Vec3 d = Xa.r - Xr.r;
  const Vec3 beta_lin = wa.cross(pa_dot) - wr.cross(pr_dot) - 2.0 * wr.cross(pa_dot - pr_dot) + wr.cross(wr.cross(d));
  const Vec3 beta_ang = wa.cross(wr);
  const Mat3 R = g.expressed == Expressed::Local       ? Mat3(Xa.E.transpose())
                 : g.expressed == Expressed::Reference ? Mat3(Xr.E.transpose())
                                                       : Mat3::Identity();
  const double sign = g.reference_side ? -1.0 : 1.0;
  for (int k = 0; k < g.rows; ++k) {
    const Vec3 f = R * g.A.col(k).head<3>(), n = R * g.A.col(k).tail<3>();
    sw.A_body.col(col + k) << sign * f, sign * (n + Xa.r.cross(f));
    const double b = task.targets()[g.first_row + k];
    sw.b_body[col + k] = g.reference_side ? 0.0 : b - f.dot(beta_lin) - n.dot(beta_ang);
  }
}

// One piece of a joint row (Task::addJointConstraint) or a mimic row
// (Task::addMimicRows): coefficient·q̈_j, read with
// a unit effort F along joint j (F·S_j = 1): a couple about a revolute axis,
// a force along a prismatic axis through the body origin. Since
// Ẍ_body − Ẍ_parent = S q̈ + Ẍ_bias (line 29), F·(Ẍ_body − Ẍ_parent) = q̈ + F·Ẍ_bias:
// the column is +F on the joint's body and −F on its parent, and F·Ẍ_bias
// goes to the set point (on the body's side, with the row's b). A different F
// with F·S = 1 would differ by a force the joint itself transmits: same motion, same ν.
void jointPieceInBodyForm(const Model& model, const Task& task, const TaskSolverOrder::ConstraintGroup& g, int col,
                          Workspace& ws) {
  WorkspaceScratch& sw = scratchOf(ws);
  const int body = bodyOfDof(g.dof);  // the body the DOF moves (g.body is this side's: it or its parent)
  const Vec6& S = sw.S[at(body)];
  Vec6 F;
  if (model.dofs()[at(g.dof)].rotation)
    F << Vec3::Zero(), S.tail<3>();
  else
    F << S.head<3>(), sw.Xworld[at(body)].r.cross(S.head<3>());
  sw.A_body.col(col) = ((g.reference_side ? -1.0 : 1.0) * g.coefficient) * F;
  // A joint row's set point q̈_j = b (a mimic row's is 0) joins F·Ẍ_bias on the body's side.
  const double b = g.mimic_row ? 0.0 : task.targets()[g.first_row];
  sw.b_body[col] = g.reference_side ? 0.0 : b + g.coefficient * F.dot(sw.c[at(body)]);
}

// The task's constraints as unit forces on their bodies in base coordinates,
// and the set points b as the sweep sees them (b is the true classical
// acceleration of the frame origin p: docs/conventions.md, "What a frame's
// acceleration is"; the sweep works with spatial accelerations shifted by [−g; 0]):
//   A_w = [f; n + p × f],  A_wᵀ Ẍ = b − f·(ω × v_p) − f·g.
void constraintsInBodyForm(const Model& model, const Task& task, Workspace& ws) {
  WorkspaceScratch& sw = scratchOf(ws);
  const std::vector<int>& user_row = solverOrder(task).solverRowToUserRow();
  int col = 0;
  for (const TaskSolverOrder::ConstraintGroup& g : solverOrder(task).groups()) {
    if (g.dof >= 0) {
      jointPieceInBodyForm(model, task, g, col++, ws);
      continue;
    }
    if (g.reference >= 0) {
      relativeConstraintInBodyForm(model, task, g, col, ws);
      col += g.rows;
      continue;
    }
    const Transform X = framePlacementInBase(model, ws, g.frame);  // ᶠX₀
    const Vec6& v = sw.v[at(g.body)];
    const Vec3 w = v.tail<3>();
    const Vec3 classical_shift = w.cross(v.head<3>() + w.cross(X.r));  // ω × v_p
    const Mat3 R = X.E.transpose();
    for (int k = 0; k < g.rows; ++k, ++col) {
      Vec3 f = g.A.col(k).head<3>(), n = g.A.col(k).tail<3>();
      if (g.expressed == Expressed::Local) {
        f = R * f;
        n = R * n;
      }
      sw.A_body.col(col) << f, n + X.r.cross(f);
      const double b = task.targets()[user_row[at(col)]];
      sw.b_body[col] = b - f.dot(classical_shift) - f.dot(task.gravity);
    }
  }
}

}  // namespace

void outwardSweep(const Model& model, const Task& task, const VectorRef& q, const VectorRef& qd, Workspace& ws) {
  const bool moving = qd.size() == model.nv();
  outwardKinematics(model, q, qd, ws, true);  // lines 3–7, line 7 without F_ext
  ws.kinematics.stage = moving ? KinematicsStage::Velocities : KinematicsStage::Poses;
  ws.kinematics.model = &model;
  applyExternalWrenches(model, task, ws);  // line 7: − F_ext
  // Lines 8–9 (I^A_i = I_i, F^A_i = F_bias,i) are folded into the inward
  // sweep, which sets each body's articulated quantities as it reaches them.
  constraintsInBodyForm(model, task, ws);
}

namespace {

// constraintColumns on a block of K ≤ 6 columns [first, first + K), K fixed:
// on so few columns, loops of run-time length cost more than their
// arithmetic. 𝓛's block takes the whole outer product (its upper triangle is
// never read), the same products as the loops'.
template <int K, bool kBalance, bool kBias>
ZWANG_ALWAYS_INLINE void constraintColumnsBlock(int i, int first, double u_D, WorkspaceScratch& sw) {
  using ColumnK = Eigen::Matrix<double, K, 1>;
  const Vec6& S = sw.S[at(i)];
  const Vec6& IAS = sw.IAS[at(i)];
  const Vec6& c = sw.c[at(i)];
  const double inverse_D = sw.inverse_D[at(i)];
  const double SS_D = S.squaredNorm() * inverse_D;
  ColumnK sA;
  for (int k = 0; k < K; ++k) {
    const Eigen::Map<const Vec6> A(&sw.Ahat(0, first + k));
    sA[k] = S.dot(A);                                                 // (Sᵀ A_i)ᵀ
    sw.L_scale[first + k] += SS_D * A.squaredNorm();                  // what rounding of sA² / D is relative to
    sw.U[first + k] += kBias ? A.dot(c) + sA[k] * u_D : sA[k] * u_D;  // line 20: Aᵀ Ẍ_bias + Aᵀ S D⁻¹ u
  }
  sw.SA.col(i).template segment<K>(first) = sA;
  for (int k = 0; k < K; ++k) {
    const double sA_D = sA[k] * inverse_D;
    if (kBalance) sw.L.col(first + k).template segment<K>(first) += sA * sA_D;  // line 21 (sign: see top)
    Eigen::Map<Vec6>(&sw.Ahat(0, first + k)) -= IAS * sA_D;                     // line 19: A_{parent} = P^A A_i
  }
}

// Lines 19–21 for DOF body i, one constraint column of its subtree [first, columns_end) at a time:
// (SᵀA_i)ᵀ, U (line 20), 𝓛 (line 21, lower triangle; without kBalance,
// jointBalanceUpdate adds a joint's DOFs at once) and
// A_parent = P^A A_i (line 19). Without kBias, Ẍ_bias,i = 0 (a multi-DOF
// joint's bodies before its last) and line 20 skips Aᵀ Ẍ_bias.
template <bool kBalance, bool kBias>
void constraintColumns(int i, int first, int columns_end, double u_D, WorkspaceScratch& sw) {
  ConstraintMatrix& A = sw.Ahat;
  const Vec6& S = sw.S[at(i)];
  const Vec6& IAS = sw.IAS[at(i)];
  const Vec6& c = sw.c[at(i)];
  const double inverse_D = sw.inverse_D[at(i)];
  switch (columns_end - first) {
    case 1: return constraintColumnsBlock<1, kBalance, kBias>(i, first, u_D, sw);
    case 2: return constraintColumnsBlock<2, kBalance, kBias>(i, first, u_D, sw);
    case 3: return constraintColumnsBlock<3, kBalance, kBias>(i, first, u_D, sw);
    case 4: return constraintColumnsBlock<4, kBalance, kBias>(i, first, u_D, sw);
    case 5: return constraintColumnsBlock<5, kBalance, kBias>(i, first, u_D, sw);
    case 6: return constraintColumnsBlock<6, kBalance, kBias>(i, first, u_D, sw);
    default: break;
  }
  double* sA = sw.SA.col(i).data();
  const double SS_D = S.squaredNorm() * inverse_D;
  for (int col = first; col < columns_end; ++col) {
    sA[col] = S.dot(A.col(col));                         // (Sᵀ A_i)ᵀ
    sw.L_scale[col] += SS_D * A.col(col).squaredNorm();  // what rounding of sA² / D is relative to
  }
  for (int col = first; col < columns_end; ++col) {
    const double sA_D = sA[col] * inverse_D;
    sw.U[col] += kBias ? A.col(col).dot(c) + sA[col] * u_D : sA[col] * u_D;  // line 20: Aᵀ Ẍ_bias + Aᵀ S D⁻¹ u
    double* L_col = &sw.L(0, col);                                           // line 21 (sign: see top), lower triangle
    if (kBalance)
      for (int r = col; r < columns_end; ++r) L_col[r] += sA[r] * sA_D;
    A.col(col) -= IAS * sA_D;  // line 19: A_{parent} = P^A A_i
  }
}

// Lines 19–21 for DOF body i: nothing to do on a body whose subtree has no
// constraint column (most bodies of most tasks, so checked inline).
template <bool kBalance, bool kBias>
ZWANG_ALWAYS_INLINE void constraintColumnsStep(const Task& task, int i, double u_D, WorkspaceScratch& sw) {
  const int first = solverOrder(task).firstColumn(i), columns_end = solverOrder(task).columnsEnd(i);
  if (columns_end > first) constraintColumns<kBalance, kBias>(i, first, columns_end, u_D, sw);
}

// Line 21 for a joint of several DOFs, after its steps: 𝓛 += Σ_k (SᵀA_k)ᵀ
// SᵀA_k / D_k over its n DOF bodies in one pass over 𝓛's lower triangle (not
// a pass per DOF; n a constant, so the sum over k stays in registers). Body k
// sees the columns before columnsEnd(k) (a joint row on one of the joint's
// DOFs sits on that DOF's body): its SᵀA is zero beyond. kDofs 0: n at run time.
template <int kDofs>
void jointBalanceUpdate(const Task& task, int first, int dofs, WorkspaceScratch& sw) {
  const int n = kDofs > 0 ? kDofs : dofs;
  const int c0 = solverOrder(task).firstColumn(first), c1 = solverOrder(task).columnsEnd(first);
  const double* sA[6];
  for (int k = 0; k < n; ++k) {
    double* sA_k = sw.SA.col(first + k).data();
    for (int r = solverOrder(task).columnsEnd(first + k); r < c1; ++r) sA_k[r] = 0.0;
    sA[k] = sA_k;
  }
  for (int col = c0; col < c1; ++col) {
    double w[6];  // SᵀA_k / D_k of this column
    for (int k = 0; k < n; ++k) w[k] = sA[k][col] * sw.inverse_D[at(first + k)];
    const Eigen::Index len = c1 - col;
    Eigen::Map<Eigen::VectorXd> L_col(&sw.L(col, col), len);
    auto term = [&](int k) { return Eigen::Map<const Eigen::VectorXd>(sA[k] + col, len) * w[k]; };
    // One expression: one vectorised pass over the column, the sum in k order.
    if (kDofs == 6)
      L_col += term(0) + term(1) + term(2) + term(3) + term(4) + term(5);
    else if (kDofs == 3)
      L_col += term(0) + term(1) + term(2);
    else
      for (Eigen::Index r = 0; r < len; ++r) {
        double sum = 0.0;
        for (int k = 0; k < n; ++k) sum += sA[k][col + r] * w[k];
        L_col[r] += sum;
      }
  }
}

// The joint types' DOF counts as constants: a free joint's 6, a spherical or planar one's 3.
void jointBalanceUpdate(const Task& task, int first, int last, WorkspaceScratch& sw) {
  const int n = last - first + 1;
  if (n == 6)
    jointBalanceUpdate<6>(task, first, n, sw);
  else if (n == 3)
    jointBalanceUpdate<3>(task, first, n, sw);
  else
    jointBalanceUpdate<0>(task, first, n, sw);
}

// Line 13's D and 1/D of DOF body i from its I^A S, or Degenerate.
inline Status pivot(const Model& model, int i, WorkspaceScratch& sw) {
  const double D = model.rotorInertia()[i - 1] + sw.S[at(i)].dot(sw.IAS[at(i)]);  // line 13
  sw.D[at(i)] = D;
  if (!(D > 1e-300))
    return Status::error(StatusCode::Degenerate, "joint '%s' has no inertia to move here (D = %g)",
                         model.dofs()[at(i - 1)].name.c_str(), D);
  sw.inverse_D[at(i)] = 1.0 / D;  // one division per DOF; the rest multiply
  return {};
}

// M += I's 6×6 matrix [m·1  −h×; h×  Ī], entry by entry (RigidInertia::addTo
// forms the two skew matrices first).
ZWANG_ALWAYS_INLINE void addInertia(const RigidInertia& I, Mat6& M) {
  const double m = I.mass, hx = I.h.x(), hy = I.h.y(), hz = I.h.z();
  M(0, 0) += m;
  M(1, 1) += m;
  M(2, 2) += m;
  M(0, 4) += hz;
  M(0, 5) -= hy;
  M(1, 3) -= hz;
  M(1, 5) += hx;
  M(2, 3) += hy;
  M(2, 4) -= hx;
  M(3, 1) -= hz;
  M(3, 2) += hy;
  M(4, 0) += hz;
  M(4, 2) -= hx;
  M(5, 0) -= hy;
  M(5, 1) += hx;
  M.bottomRightCorner<3, 3>() += I.Ibar;
}

// Lines 16–18: the parent p gets I^a = I^A − Σ I^A S D⁻¹ Sᵀ I^A over the
// joint's DOF bodies [first, last] and F^a = p^A + Σ I^A S D⁻¹ u. The first
// child to arrive (the last in depth-first order: its subtree ends where p's
// does) starts p's sums from I_p and F_bias,p.
inline void passToParent(const Model& model, int first, int last, const Mat6& IA, const Vec6& pA,
                         WorkspaceScratch& sw) {
  const int p = model.parent(first);
  if (p == 0) return;  // the world takes nothing
  Mat6& IA_parent = sw.IA[at(p)];
  Vec6& FA_parent = sw.FA[at(p)];
  const Vec6& IAS = sw.IAS[at(last)];
  const Vec6 IAS_D = IAS * sw.inverse_D[at(last)];
  if (model.subtreeEnd(last) == model.subtreeEnd(p)) {
    IA_parent.noalias() = IA - IAS.lazyProduct(IAS_D.transpose());  // one fused pass
    addInertia(sw.I[at(p)], IA_parent);
    FA_parent = sw.Fbias[at(p)] + pA + IAS_D * sw.u[at(last)];
  } else {
    IA_parent.noalias() += IA - IAS.lazyProduct(IAS_D.transpose());
    FA_parent += pA + IAS_D * sw.u[at(last)];
  }
  for (int k = first; k < last; ++k) {  // a multi-DOF joint's other DOFs
    const Vec6 IAS_k_D = sw.IAS[at(k)] * sw.inverse_D[at(k)];
    IA_parent.noalias() -= sw.IAS[at(k)].lazyProduct(IAS_k_D.transpose());
    FA_parent += IAS_k_D * sw.u[at(k)];
  }
}

// Lines 13–15 for a joint of nv DOFs, its bodies [first, last] (the last
// carries the inertia; the others have none and Ẍ_bias = 0): the one-DOF steps
// last, …, first in block form. Their I^A_k S_k = I^A S_k − Σ_{m>k} I^A_m S_m
// (S_kᵀ I^A_m S_m)/D_m and u_k = τ_k − S_kᵀ p^A − Σ_{m>k} (S_kᵀ I^A_m S_m) u_m/D_m
// (the LDLᵀ of the joint's D, last DOF first) are the one-DOF steps' numbers,
// but each pivot waits on a 6-vector update, not on a 6 × 6 downdate of I^A.
inline Status jointPivots(const Model& model, int first, int last, const Mat6& IA, const Vec6& pA, const VectorRef& tau,
                          WorkspaceScratch& sw) {
  for (int k = first; k <= last; ++k) {
    sw.IAS[at(k)].noalias() = IA * sw.S[at(k)];  // the columns of I^A S: independent
    sw.u[at(k)] = tau[k - 1] - sw.S[at(k)].dot(pA);
  }
  for (int m = last; m >= first; --m) {
    if (Status s = pivot(model, m, sw); !s) return s;
    const Vec6& IAS_m = sw.IAS[at(m)];
    const double inverse_D = sw.inverse_D[at(m)], u_m = sw.u[at(m)];
    for (int k = first; k < m; ++k) {
      const double g = sw.S[at(k)].dot(IAS_m) * inverse_D;
      sw.IAS[at(k)] -= IAS_m * g;
      sw.u[at(k)] -= g * u_m;
    }
  }
  return {};
}

}  // namespace

namespace {

// Line 20 for a prescribed DOF body i (q̈_i = y given): Aᵀ Ẍ_i = Aᵀ Ẍ_parent + Aᵀ(Ẍ_bias + S y), so U takes
// Aᵀ(Ẍ_bias + S y), and A_i reaches the parent as it is: no projection (line 19), no term of 𝓛 (line 21).
inline void prescribedColumnsStep(const Task& task, int i, double y, WorkspaceScratch& sw) {
  const Vec6 motion = sw.c[at(i)] + sw.S[at(i)] * y;
  const int first = solverOrder(task).firstColumn(i), columns_end = solverOrder(task).columnsEnd(i);
  for (int col = first; col < columns_end; ++col) sw.U[col] += sw.Ahat.col(col).dot(motion);
}

// Lines 16–18 for a prescribed DOF body i: the joint is rigid for the sweep, so the parent takes I^A whole and
// F^A + I^A(Ẍ_bias + S y) (= p^A + I^A S y). The first child to arrive starts p's sums, as in passToParent.
inline void passRigidly(const Model& model, int i, const Mat6& IA, const Vec6& pA, double y, WorkspaceScratch& sw) {
  const int p = model.parent(i);
  if (p == 0) return;  // the world takes nothing
  Mat6& IA_parent = sw.IA[at(p)];
  Vec6& FA_parent = sw.FA[at(p)];
  if (model.subtreeEnd(i) == model.subtreeEnd(p)) {
    IA_parent = IA;
    addInertia(sw.I[at(p)], IA_parent);
    FA_parent = sw.Fbias[at(p)] + pA;
  } else {
    IA_parent += IA;
    FA_parent += pA;
  }
  if (y != 0.0) FA_parent.noalias() += IA * (sw.S[at(i)] * y);  // a locked DOF (y = 0: a sticking joint) adds none
}

// A joint some of whose DOFs are prescribed (bodies [first, last]): its DOF steps one at a time, from the last —
// each the report's one-DOF step or the rigid pass (the other DOF bodies carry no inertia and no bias, so the
// steps in a row are the joint's).
Status mixedJointSteps(const Model& model, const Task& task, int first, int last, const VectorRef& tau,
                       WorkspaceScratch& sw) {
  for (int k = last; k >= first; --k) {
    const Mat6& IA = sw.IA[at(k)];
    Vec6 pA = sw.FA[at(k)];
    pA.noalias() += IA * sw.c[at(k)];
    if (isPrescribed(sw, k - 1)) {
      const double y = prescribedAcceleration(sw, k - 1);
      prescribedColumnsStep(task, k, y, sw);
      passRigidly(model, k, IA, pA, y, sw);
      continue;
    }
    sw.IAS[at(k)].noalias() = IA * sw.S[at(k)];
    if (Status s = pivot(model, k, sw); !s) return s;
    sw.u[at(k)] = tau[k - 1] - sw.S[at(k)].dot(pA);
    constraintColumnsStep<true, true>(task, k, sw.u[at(k)] * sw.inverse_D[at(k)], sw);
    passToParent(model, k, k, IA, pA, sw);
  }
  return {};
}

bool anyPrescribed(const WorkspaceScratch& sw, int first, int last) {
  for (int k = first; k <= last; ++k)
    if (isPrescribed(sw, k - 1)) return true;
  return false;
}

// The inward sweep joint by joint from the leaves (body i a joint's last DOF body). Without kPrescribed no
// DOF is prescribed, and the loop has no test for it.
template <bool kPrescribed>
Status inwardJoints(const Model& model, const Task& task, const VectorRef& tau, WorkspaceScratch& sw) {
  for (int i = model.nv(); i >= 1;) {
    const int first = model.jointStart(i);
    if (model.subtreeEnd(i) == i + 1) {  // a leaf: lines 8–9, I^A = I, F^A = F_bias
      sw.IA[at(i)].setZero();
      addInertia(sw.I[at(i)], sw.IA[at(i)]);
      sw.FA[at(i)] = sw.Fbias[at(i)];
    }
    if (kPrescribed && anyPrescribed(sw, first, i)) {
      if (Status s = mixedJointSteps(model, task, first, i, tau, sw); !s) return s;
      i = first - 1;
      continue;
    }
    const Mat6& IA = sw.IA[at(i)];
    Vec6 pA = sw.FA[at(i)];
    pA.noalias() += IA * sw.c[at(i)];  // F^A + I^A Ẍ_bias
    if (first == i) {                  // one DOF: lines 13–15 as the report has them
      sw.IAS[at(i)].noalias() = IA * sw.S[at(i)];
      if (Status s = pivot(model, i, sw); !s) return s;
      sw.u[at(i)] = tau[i - 1] - sw.S[at(i)].dot(pA);  // τ − Sᵀ(F^A + I^A Ẍ_bias), docs/solver.md
    } else if (Status s = jointPivots(model, first, i, IA, pA, tau, sw); !s) {
      return s;
    }
    // P^A = 1 − I^A S D⁻¹ Sᵀ (line 14) is applied, never formed.
    if (first == i) {
      constraintColumnsStep<true, true>(task, i, sw.u[at(i)] * sw.inverse_D[at(i)], sw);
    } else {
      constraintColumnsStep<false, true>(task, i, sw.u[at(i)] * sw.inverse_D[at(i)], sw);
      for (int k = i - 1; k >= first; --k)
        constraintColumnsStep<false, false>(task, k, sw.u[at(k)] * sw.inverse_D[at(k)], sw);
      jointBalanceUpdate(task, first, i, sw);
    }
    passToParent(model, first, i, IA, pA, sw);
    i = first - 1;
  }
  return {};
}

}  // namespace

Status inwardSweep(const Model& model, const Task& task, const VectorRef& tau, Workspace& ws) {
  WorkspaceScratch& sw = scratchOf(ws);
  const int m = task.solverColumns();
  sw.U.head(m).setZero();  // U_N = 0
  sw.L_scale.head(m).setZero();
  sw.L.topLeftCorner(m, m).setZero();           // 𝓛_N = 0 (only the lower triangle is kept)
  sw.Ahat.leftCols(m) = sw.A_body.leftCols(m);  // A_i, each column updated in place on its way to the base
  return sw.prescribed_count > 0 ? inwardJoints<true>(model, task, tau, sw) : inwardJoints<false>(model, task, tau, sw);
}

namespace {

// With relative constraints, each balance row is the sum of its solver
// columns (the two sides): 𝓛_rows = Mᵀ 𝓛 M, and likewise U, L_scale, b and
// A₀ᵀẌ₀, with M the 0/1 map of columns to rows. Into sw.L_rows (lower
// triangle), sw.L_scale_rows and sw.rhs.
void condensedBalance(const Task& task, Workspace& ws) {
  WorkspaceScratch& sw = scratchOf(ws);
  const int columns = task.solverColumns(), m = task.balanceRows();
  const std::vector<int>& row = solverOrder(task).balanceRowOfColumn();
  sw.L_rows.topLeftCorner(m, m).setZero();
  sw.L_scale_rows.head(m).setZero();
  sw.rhs.head(m).setZero();
  const Vec6 a0 = gravityAcceleration(task.gravity);
  for (int q = 0; q < columns; ++q) {
    const int rq = row[at(q)];
    sw.L_scale_rows[rq] += sw.L_scale[q];
    sw.rhs[rq] += sw.b_body[q] - sw.U[q] - sw.Ahat.col(q).dot(a0);
    for (int p = q; p < columns; ++p) {  // 𝓛(p, q), p ≥ q, stands for (p, q) and (q, p)
      const int rp = row[at(p)];
      const double value = sw.L(p, q) * (p != q && rp == rq ? 2.0 : 1.0);
      sw.L_rows(std::max(rp, rq), std::min(rp, rq)) += value;
    }
  }
}

// ν of each solver column from ν of its balance row (both sides carry the row's ν).
void expandToColumns(const Task& task, const Eigen::Ref<const Eigen::MatrixXd>& rows,
                     Eigen::Ref<Eigen::MatrixXd> columns) {
  const std::vector<int>& row = solverOrder(task).balanceRowOfColumn();
  for (int col = 0; col < task.solverColumns(); ++col) columns.row(col) = rows.row(row[at(col)]);
}

}  // namespace

void balance(const Task& task, Workspace& ws) {
  WorkspaceScratch& sw = scratchOf(ws);
  const int m = task.balanceRows();
  const bool condensed = solverOrder(task).balanceOnRows();
  if (condensed) condensedBalance(task, ws);
  Eigen::MatrixXd& L = condensed ? sw.L_rows : sw.L;
  const Eigen::VectorXd& L_scale = condensed ? sw.L_scale_rows : sw.L_scale;
  // A row no joint can move (its row of G is zero: a constraint on the base,
  // or a direction through every joint axis) has 𝓛_rr = Σ (Sᵀa)²/D = 0 up to
  // the rounding of the Sᵀa products, ~ε²·L_scale. Make it exactly zero, so
  // the balance sees the singularity and gives the row ν = 0 (docs/solver.md).
  // A condensed row (the sum of a relative row's two sides, or of a joint
  // row's) is a difference of large terms: what nothing can move cancels only
  // to ~ε·L_scale there (a relative row between two links whose relative
  // motion no joint gives, on a free base: test_floating_algorithms). Real
  // rows sit far above 1e3·ε of their terms.
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  const double rounding = condensed ? 1e3 * kEps : 1e4 * kEps * kEps;
  for (int r = 0; r < m; ++r)
    if (L(r, r) <= rounding * L_scale[r]) {
      for (int col = 0; col <= r; ++col) L(r, col) = 0.0;
      for (int row = r; row < m; ++row) L(row, r) = 0.0;
    }
  if (!condensed) {
    sw.rhs.head(m) = sw.b_body.head(m) - sw.U.head(m);                                                // line 25 …
    sw.rhs.head(m).noalias() -= sw.Ahat.leftCols(m).transpose() * gravityAcceleration(task.gravity);  // … − A₀ᵀẌ₀
  }
  Eigen::VectorXd& nu = condensed ? sw.nu_rows : sw.nu_columns;
  BalanceReport& report = ws.solution.balance;
  report = solveBalance(L.topLeftCorner(m, m), sw.rhs.head(m), nu.head(m), sw.balance_factorisation, task.balance);
  if (condensed) expandToColumns(task, sw.nu_rows.head(m), sw.nu_columns);
  // The report counts the task's rows. The mimic rows are independent of each
  // other whatever the task (each alone moves its own mimic joint; a leader is
  // never a mimic joint), so every direction the balance lost lies in the
  // task's rows, and their rank on the coupled robot is the balance's less the
  // mimic rows.
  report.rows = task.constraintRows();
  report.rank = std::max(0, report.rank - task.mimicRows());  // ≥ 0 even should rounding lose a mimic row
}

namespace {
// Lines 26–30; without kPrescribed no DOF is prescribed, and the loop has no test for it.
template <bool kPrescribed>
void outwardBodies(const Model& model, const Task& task, WorkspaceScratch& sw, Eigen::Ref<Eigen::VectorXd> qdd) {
  // Each body's q̈ waits on its parent's Ẍ: that chain sets the time. So the
  // parent's Ẍ comes from a register when it is the body before (a chain, a
  // joint's DOFs), and line 28 multiplies by the 1/D the inward sweep formed.
  Vec6 a_previous = sw.a[0];
  for (int i = 1; i <= model.nv(); ++i) {
    const int p = model.parent(i);
    const Vec6 a_parent = p == i - 1 ? a_previous : sw.a[at(p)];
    if (kPrescribed && isPrescribed(sw, i - 1)) {
      qdd[i - 1] = prescribedAcceleration(sw, i - 1);
    } else {
      const int first = solverOrder(task).firstColumn(i), column_count = solverOrder(task).columnsEnd(i) - first;
      const double constraint =  // Sᵀ A_i ν; most bodies have no column
          column_count == 0 ? 0.0
                            : sw.SA.col(i).segment(first, column_count).dot(sw.nu_columns.segment(first, column_count));
      qdd[i - 1] = (sw.u[at(i)] - sw.IAS[at(i)].dot(a_parent) + constraint) * sw.inverse_D[at(i)];  // line 28
    }
    a_previous = sw.a[at(i)] = a_parent + sw.S[at(i)] * qdd[i - 1] + sw.c[at(i)];  // line 29
  }
}
}  // namespace

void outwardAccelerations(const Model& model, const Task& task, Workspace& ws, Eigen::Ref<Eigen::VectorXd> qdd) {
  WorkspaceScratch& sw = scratchOf(ws);
  sw.a_world = sw.a[0] = gravityAcceleration(task.gravity);  // Ẍ₀ = [−g; 0]
  if (sw.prescribed_count > 0)
    outwardBodies<true>(model, task, sw, qdd);
  else
    outwardBodies<false>(model, task, sw, qdd);
}

void bodyAccelerations(const Model& model, const Task& task, Workspace& ws, const VectorRef& qdd) {
  WorkspaceScratch& sw = scratchOf(ws);
  sw.a_world = sw.a[0] = gravityAcceleration(task.gravity);  // Ẍ₀ = [−g; 0]
  for (int i = 1; i <= model.nv(); ++i)
    sw.a[at(i)] = sw.a[at(model.parent(i))] + sw.S[at(i)] * qdd[i - 1] + sw.c[at(i)];  // line 29
}

Vec6 baseClassicalAcceleration(const Model& model, const Workspace& ws) {
  const WorkspaceScratch& sw = scratchOf(ws);
  if (!model.hasFloatingBase()) return Vec6::Zero();  // the world's
  const auto b = at(model.baseBody());
  return classicalAtPoint(sw.a[b] - sw.a_world, sw.v[b], sw.Xworld[b].r);
}

namespace {
// Line 25 for W columns as lanes: x ← 𝓛⁻¹ x with 𝓛 = C Cᵀ (a regular
// balance's Cholesky factor), x the W × m block at `lanes` (leading dimension
// `stride`; row w: column w's right-hand side). Forward and backward
// substitution on whole lanes: each step is one vector operation for all W
// columns (a column at a time, each step is a short scalar loop).
template <int W>
void balanceSolveLanes(const Eigen::MatrixXd& C, int m, double* lanes, Eigen::Index stride) {
  using Lanes = Eigen::Matrix<double, W, 1>;
  for (int i = 0; i < m; ++i) {  // C y = x
    Eigen::Map<Lanes> x(lanes + i * stride);
    for (int l = 0; l < i; ++l) x -= C(i, l) * Eigen::Map<const Lanes>(lanes + l * stride);
    x *= 1.0 / C(i, i);
  }
  for (int i = m - 1; i >= 0; --i) {  // Cᵀ x = y
    Eigen::Map<Lanes> x(lanes + i * stride);
    for (int l = i + 1; l < m; ++l) x -= C(l, i) * Eigen::Map<const Lanes>(lanes + l * stride);
    x *= 1.0 / C(i, i);
  }
}

// Lines 28–29 for the differences, for the W columns from c0 side by side:
// each body's step is a few loops over W lanes, one per column, which the
// compiler vectorises, and reads the body's S, I^A S, 1/D and SᵀA once for all
// W. Body i's δẌ hangs from its parent's: s.da's column i, W × 6 (a column
// per component).
template <int W>
void outwardLanes(const Model& model, const Task& task, const WorkspaceScratch& sw, Eigen::Index c0, bool solve_balance,
                  UnitTorqueScratch& s, Eigen::Ref<Eigen::MatrixXd> dnu, Eigen::Ref<Eigen::MatrixXd> dqdd) {
  using Lanes = Eigen::Matrix<double, W, 1>;  // one entry per column
  const int N = model.nv(), m = task.solverColumns();
  auto dnu_lanes = s.dnu_lanes.topLeftCorner(W, m);  // SᵀA δν: whole lanes per row
  if (solve_balance) {
    dnu_lanes = s.dU.block(0, c0, m, W).transpose();  // −δU₀
    balanceSolveLanes<W>(sw.balance_factorisation.factor, m, dnu_lanes.data(), s.dnu_lanes.outerStride());
    dnu.middleCols(c0, W) = dnu_lanes.transpose();
  } else {
    dnu_lanes = dnu.middleCols(c0, W).transpose();
  }
  double* da = s.da.data();
  const Eigen::Index da_stride = s.da.outerStride();
  const bool prescribed = sw.prescribed_count > 0;
  for (int e = 0; e < 6 * W; ++e) da[e] = 0.0;  // the world: δẌ₀ = 0
  for (int i = 1; i <= N; ++i) {
    if (prescribed && isPrescribed(sw, i - 1)) {  // δq̈_i = 0: the child moves with its parent
      dqdd.template block<1, W>(i - 1, c0).setZero();
      for (int e = 0; e < 6 * W; ++e) da[i * da_stride + e] = da[model.parent(i) * da_stride + e];
      continue;
    }
    Lanes dq = Lanes::Zero();  // δu_i: non-zero on the columns whose path runs through i
    const Eigen::Index from = std::max(c0, s.run_begin[i]), to = std::min(c0 + W, s.run_end[i]);
    for (Eigen::Index c = from; c < to; ++c) dq[c - c0] = s.du(i, c);
    const int first = solverOrder(task).firstColumn(i), columns_end = solverOrder(task).columnsEnd(i);
    for (int r = first; r < columns_end; ++r) dq += sw.SA(r, i) * Eigen::Map<const Lanes>(s.dnu_lanes.col(r).data());
    const double* parent = da + model.parent(i) * da_stride;
    const Vec6& IAS = sw.IAS[at(i)];
    for (int e = 0; e < 6; ++e) dq -= IAS[e] * Eigen::Map<const Lanes>(parent + e * W);
    dq *= sw.inverse_D[at(i)];
    dqdd.template block<1, W>(i - 1, c0) = dq.transpose();
    const Vec6& S = sw.S[at(i)];
    double* child = da + i * da_stride;
    for (int e = 0; e < 6; ++e) Eigen::Map<Lanes>(child + e * W) = Eigen::Map<const Lanes>(parent + e * W) + S[e] * dq;
  }
}
}  // namespace

namespace {
// Each body's run of unit-torque columns [run_begin, run_end): those whose
// DOF's body lies in its subtree, a contiguous run since the DOFs ascend.
void columnRuns(const Model& model, const std::vector<int>& dofs, UnitTorqueScratch& s) {
  const auto unit_torque_count = static_cast<Eigen::Index>(dofs.size());
  Eigen::Index c_begin = unit_torque_count;  // the first column with its DOF's body ≥ i: falls with i
  for (int i = model.nv(); i >= 1; --i) {
    while (c_begin > 0 && bodyOfDof(dofs[at(static_cast<int>(c_begin) - 1)]) >= i) --c_begin;
    // The run ends at the first column beyond the subtree (a chain's: past the last column).
    const int end = model.subtreeEnd(i);
    s.run_begin[i] = c_begin;
    s.run_end[i] = unit_torque_count == 0 || end > bodyOfDof(dofs.back())
                       ? unit_torque_count
                       : std::lower_bound(dofs.begin(), dofs.end(), end, [](int d, int b) {
                           return bodyOfDof(d) < b;
                         }) - dofs.begin();
  }
}

// Line 20 at body i for one column: δU₀ += SᵀA_i δu_i / D_i on the rows
// [first, columns_end) of i's subtree (dU_c: the column's δU₀).
ZWANG_ALWAYS_INLINE void constraintColumnsDelta(const WorkspaceScratch& sw, int i, int first, int columns_end,
                                                double du_D, double* dU_c) {
  for (int r = first; r < columns_end; ++r) dU_c[r] += sw.SA(r, i) * du_D;
}

// Lines 13–20 of a one-DOF joint (body i) on its run of columns: δu_i = [i is
// the column's DOF] − Sᵀ δF^a, then δU₀ and δF^a for the parent.
void oneDofColumns(const Model& model, const Task& task, const WorkspaceScratch& sw, const std::vector<int>& dofs,
                   int i, UnitTorqueScratch& s) {
  const Vec6& S = sw.S[at(i)];
  const Vec6& IAS = sw.IAS[at(i)];
  const double inverse_D = sw.inverse_D[at(i)];
  const bool to_world = model.parent(i) == 0;  // the world takes δF^a and does nothing with it
  const int first = solverOrder(task).firstColumn(i), columns_end = solverOrder(task).columnsEnd(i);
  const Eigen::Index begin = s.run_begin[i], run_end = s.run_end[i];
  const Eigen::Index own = begin < run_end && bodyOfDof(dofs[at(static_cast<int>(begin))]) == i ? begin : -1;
  double* const du = s.du.data() + i;  // row i
  const Eigen::Index du_stride = s.du.outerStride(), dU_stride = s.dU.outerStride();
  for (Eigen::Index c = begin; c < run_end; ++c) {
    Eigen::Map<Vec6> dF(s.dF.data() + 6 * c);
    const double du_ic = (c == own ? 1.0 : 0.0) - S.dot(dF);
    du[c * du_stride] = du_ic;
    const double du_D = du_ic * inverse_D;
    constraintColumnsDelta(sw, i, first, columns_end, du_D, s.dU.data() + c * dU_stride);
    if (!to_world) dF += IAS * du_D;  // lines 17–18
  }
}

// The same for a joint of several DOFs (bodies first..last), its steps in
// block form as jointPivots formed them (offsets k, l from first): a column
// entering at the joint's DOF o has δu_o = 1 and δu_k = −Σ_{k<l≤o} g_kl δu_l
// below it, g_kl = S_kᵀ I^A_l S_l / D_l; a column from below with δF^a has
// δu = −W δF^a, W's rows W_k = S_kᵀ − Σ_{l>k} g_kl W_l, formed once per
// joint. So each column costs one 6 × 6 product, not a 6-vector update per
// DOF (a free root's six bodies carry every column); the parent gets
// Σ_k I^A_k S_k δu_k / D_k more (lines 17–18).
void multiDofColumns(const Model& model, const Task& task, const WorkspaceScratch& sw, const std::vector<int>& dofs,
                     int first, int last, UnitTorqueScratch& s) {
  const int n = last - first + 1;
  double g[6][6];  // g[k][l] for 0 ≤ k < l < n
  Mat6 W = Mat6::Zero(), IAS_D = Mat6::Zero();
  for (int k = n - 1; k >= 0; --k) {
    const Vec6& S_k = sw.S[at(first + k)];
    IAS_D.col(k) = sw.IAS[at(first + k)] * sw.inverse_D[at(first + k)];
    W.row(k) = S_k.transpose();
    for (int l = k + 1; l < n; ++l) {
      g[k][l] = S_k.dot(IAS_D.col(l));
      W.row(k) -= g[k][l] * W.row(l);
    }
  }
  // The joint's constraint rows: its subtree's [rows_first, rows_first +
  // rows), DOF body k taking those before rows_end[k] (a joint row on one of
  // the joint's DOFs sits on that DOF's body, and only the bodies before see it).
  const int rows_first = solverOrder(task).firstColumn(first), rows = solverOrder(task).columnsEnd(first) - rows_first;
  int rows_end[6];
  for (int k = 0; k < n; ++k) rows_end[k] = solverOrder(task).columnsEnd(first + k) - rows_first;
  // Line 20 for a column from below, all DOFs at once: δU₀ −= Y δF^a with
  // Y = Σ_k SᵀA_k W_k / D_k (kept transposed: a row's 6 entries side by side).
  auto Yt = s.joint_rows.leftCols(rows);
  Yt.setZero();
  for (int k = 0; k < n; ++k) {
    const auto SA_k = sw.SA.col(first + k).segment(rows_first, rows);
    const Vec6 W_k_D = W.row(k).transpose() * sw.inverse_D[at(first + k)];
    for (int r = 0; r < rows_end[k]; ++r) Yt.col(r) += W_k_D * SA_k[r];
  }
  const bool to_world = model.parent(first) == 0;
  const Eigen::Index du_stride = s.du.outerStride();
  for (Eigen::Index c = s.run_begin[first]; c < s.run_end[first]; ++c) {
    const int own = bodyOfDof(dofs[at(static_cast<int>(c))]) - first;  // a DOF of this joint (< n), or below it
    Eigen::Map<Vec6> dF(s.dF.data() + 6 * c);
    auto dU = s.dU.col(c).segment(rows_first, rows);
    Vec6 du = Vec6::Zero();
    if (own >= n) {
      const Vec6 F = dF;  // in registers: a store to dU could alias dF's memory, so each row would reload it
      du.noalias() = -W * F;
      for (int r = 0; r < rows; ++r) dU[r] -= Yt.col(r).dot(F);
    } else {  // δF^a is zero where the column enters
      du[own] = 1.0;
      for (int k = own - 1; k >= 0; --k)
        for (int l = k + 1; l <= own; ++l) du[k] -= g[k][l] * du[l];
      for (int k = 0; k <= own; ++k)
        dU.head(rows_end[k]) +=
            sw.SA.col(first + k).segment(rows_first, rows_end[k]) * (du[k] * sw.inverse_D[at(first + k)]);
    }
    // All n entries (those above the column's own DOF are zero and never read):
    // fixed sizes, not a call to memcpy per column.
    double* const du_c = s.du.data() + c * du_stride + first;
    if (n == 6)
      Eigen::Map<Vec6>{du_c} = du;
    else if (n == 3)
      Eigen::Map<Vec3>{du_c} = du.head<3>();
    else
      for (int k = 0; k < n; ++k) du_c[k] = du[k];
    if (!to_world) dF.noalias() += IAS_D * du;
  }
}

// A joint with prescribed DOFs (bodies first..last), its DOF steps one at a time as mixedJointSteps took them: a
// torque-driven DOF's as oneDofColumns, a prescribed one's nothing — its q̈ is fixed, so a unit torque elsewhere
// changes neither its δq̈ nor its term of δU₀, and δF^a reaches the parent whole (the rigid pass).
void mixedJointColumns(const Model& model, const Task& task, const WorkspaceScratch& sw, const std::vector<int>& dofs,
                       int first, int last, UnitTorqueScratch& s) {
  for (int k = last; k >= first; --k)
    if (!isPrescribed(sw, k - 1)) oneDofColumns(model, task, sw, dofs, k, s);
}
}  // namespace

void unitTorqueColumns(const Model& model, const Task& task, Workspace& ws, const std::vector<int>& dofs,
                       UnitTorqueScratch& s, Eigen::Ref<Eigen::MatrixXd> dnu, Eigen::Ref<Eigen::MatrixXd> dqdd) {
  WorkspaceScratch& sw = scratchOf(ws);
  // Only the τ-dependent terms change: u, F^a (line 17) and U (line 20); the
  // inertia terms I^A, D, P^A, A_i and 𝓛 are shared with the main pass.
  // Column c is zero except on the path from its DOF's body to the world, so
  // the inward sweep at body i works on i's run of columns (columnRuns).
  // dF.col(c) carries δF^a from the path's last body to the next.
  const int m = task.solverColumns();
  const auto unit_torque_count = static_cast<Eigen::Index>(dofs.size());
  auto dU = s.dU.topLeftCorner(m, unit_torque_count);
  dU.setZero();
  s.dF.leftCols(unit_torque_count).setZero();  // du is written where it is read: on each body's run of columns
  columnRuns(model, dofs, s);
  for (int i = model.nv(); i >= 1;) {  // joint by joint from the leaves; body i is a joint's last DOF body
    const int first = model.jointStart(i);
    if (sw.prescribed_count > 0 && anyPrescribed(sw, first, i))
      mixedJointColumns(model, task, sw, dofs, first, i, s);
    else if (first == i)
      oneDofColumns(model, task, sw, dofs, i, s);
    else
      multiDofColumns(model, task, sw, dofs, first, i, s);
    i = first - 1;
  }
  // A regular 𝓛 on the columns themselves (no relative rows) is solved in the
  // outward pass's lanes, a block of columns at a time; else here, all at once.
  const bool solve_in_lanes =
      !solverOrder(task).balanceOnRows() && sw.balance_factorisation.kind == BalanceFactorisation::Kind::Cholesky;
  dU *= -1.0;                               // line 25: δν = 𝓛⁻¹(−δU₀) with the same factorisation
  if (solverOrder(task).balanceOnRows()) {  // on the balance's rows: each the sum of its columns
    const int rows = task.balanceRows();
    auto dU_rows = sw.dU_rows.topLeftCorner(rows, unit_torque_count);
    dU_rows.setZero();
    for (int col = 0; col < m; ++col) dU_rows.row(solverOrder(task).balanceRowOfColumn()[at(col)]) += dU.row(col);
    auto dnu_rows = sw.dnu_rows.topLeftCorner(rows, unit_torque_count);
    balanceApplyColumns(sw.balance_factorisation, dU_rows, dnu_rows, sw.balance_factorisation.work.head(rows));
    expandToColumns(task, dnu_rows, dnu.topRows(m));
  } else if (!solve_in_lanes) {
    balanceApplyColumns(sw.balance_factorisation, dU, dnu.topRows(m), sw.balance_factorisation.work.head(m));
  }
  // Lines 28–29 for the differences: the widest blocks of columns first, so
  // that few lanes idle (29 stuck joints: 8 + 8 + 8 + 4 + 1).
  constexpr int kLanes = UnitTorqueScratch::kLanes;
  for (Eigen::Index c0 = 0; c0 < unit_torque_count;) {
    const Eigen::Index left = unit_torque_count - c0;
    if (left >= kLanes) {
      outwardLanes<kLanes>(model, task, sw, c0, solve_in_lanes, s, dnu, dqdd);
      c0 += kLanes;
    } else if (left >= 4) {
      outwardLanes<4>(model, task, sw, c0, solve_in_lanes, s, dnu, dqdd);
      c0 += 4;
    } else if (left >= 2) {
      outwardLanes<2>(model, task, sw, c0, solve_in_lanes, s, dnu, dqdd);
      c0 += 2;
    } else {
      outwardLanes<1>(model, task, sw, c0, solve_in_lanes, s, dnu, dqdd);
      c0 += 1;
    }
  }
}

void jointsOutsideLimits(const Model& model, const VectorRef& q, Solution& out) {
  out.joints_outside_limits = 0;
  out.first_joint_outside_limits = -1;
  for (const Model::PositionLimits& limits : model.positionLimits()) {  // a compact array: one pass per solve
    const double q_j = q[limits.q_index];
    if (q_j >= limits.lower && q_j <= limits.upper) continue;
    if (out.joints_outside_limits++ == 0) out.first_joint_outside_limits = limits.joint;
  }
}

namespace {
// The size of a row's term Aᵀa for taskResidual: ‖A‖₁ ‖a‖_∞ (≥ |A|ᵀ|a|).
template <class Column>
double termSize(const Column& A, const Vec6& a) {
  return A.cwiseAbs().sum() * a.cwiseAbs().maxCoeff();
}
}  // namespace

void taskResidual(const Task& task, Workspace& ws) {
  WorkspaceScratch& sw = scratchOf(ws);
  // Aᵀ Ẍ − b row by row on the final accelerations. In sweep form both sides
  // carry the same gravity and velocity shifts (constraintsInBodyForm), so the
  // difference is the row's error in its own units. A row counts as met when
  // the error is within residual_tolerance of the size of what it is computed
  // from: the accelerations it reads, its set point, and the balance's
  // right-hand side (what the constraint force had to correct).
  // The accelerations' size is that of the whole body acceleration, not of the
  // components the row picks (termSize): the sweeps' rounding is set by all
  // of it. A row can pick components that are ≈ 0 on both sides — a joint row
  // whose axis sees no angular acceleration while the gravity shift puts
  // 9.81 m/s² in the linear part — and its 1e-12 of rounding must not read as
  // a missed row (Solo 12 on four contacts with all joints held).
  const int m = task.balanceRows();
  BalanceReport& report = ws.solution.balance;
  if (!solverOrder(task).balanceOnRows()) {  // one column per row
    double sum2 = 0.0;
    bool met = true;
    int col = 0;
    for (const TaskSolverOrder::ConstraintGroup& g : solverOrder(task).groups()) {
      const Vec6& a = sw.a[at(g.body)];
      for (int k = 0; k < g.rows; ++k, ++col) {
        const auto A = sw.A_body.col(col);
        const double error = A.dot(a) - sw.b_body[col];
        const double size = termSize(A, a) + std::abs(sw.b_body[col]) + std::abs(sw.rhs[col]);
        sum2 += error * error;
        met = met && std::abs(error) <= task.balance.residual_tolerance * size;
      }
    }
    report.residual = m > 0 ? std::sqrt(sum2) : 0.0;
    report.consistent = met;
    return;
  }
  // A relative row sums its two columns' terms (the balance's rows).
  auto error = sw.row_error.head(m);
  auto size = sw.row_size.head(m);
  error.setZero();
  size.setZero();
  const std::vector<int>& row = solverOrder(task).balanceRowOfColumn();
  int col = 0;
  for (const TaskSolverOrder::ConstraintGroup& g : solverOrder(task).groups()) {
    const Vec6& a = sw.a[at(g.body)];
    for (int k = 0; k < g.rows; ++k, ++col) {
      const auto A = sw.A_body.col(col);
      const int r = row[at(col)];
      error[r] += A.dot(a) - sw.b_body[col];
      size[r] += termSize(A, a) + std::abs(sw.b_body[col]);
    }
  }
  bool met = true;
  for (int r = 0; r < m; ++r)
    met = met && std::abs(error[r]) <= task.balance.residual_tolerance * (size[r] + std::abs(sw.rhs[r]));
  report.residual = m > 0 ? error.norm() : 0.0;
  report.consistent = met;
}

void constraintTorques(const Model& model, const Task& task, Workspace& ws, const VectorRef& nu_all,
                       Eigen::Ref<Eigen::VectorXd> tau_c) {
  WorkspaceScratch& sw = scratchOf(ws);
  // The motors give every constraint force but the contacts' (the
  // environment's): those columns count with ν = 0 here.
  const int columns = task.solverColumns();
  if (task.hasContacts()) {
    sw.nu_motors.head(columns) = nu_all.head(columns);
    for (int col = 0; col < columns; ++col)
      if (solverOrder(task).contactColumns()[at(col)]) sw.nu_motors[col] = 0.0;
  }
  const VectorRef nu_solver = task.hasContacts() ? VectorRef(sw.nu_motors.head(columns)) : nu_all;
  // The wrenches A ν of each body's own constraints, summed inward and
  // projected on each joint: the physical torque (docs/solver.md, "Constraint torques: why not eq. 4.4").
  // On a tree each body carries its own wrenches and its children's: the
  // body's slot of `carried` collects them, then passes them to the parent.
  const int N = model.nv();
  if (task.solverColumns() == 0) {
    tau_c.setZero();
    return;
  }
  if (model.isChain()) {  // one running sum from the tip inward
    Vec6 carried = Vec6::Zero();
    for (int i = N; i >= 1; --i) {
      const int own_first = solverOrder(task).columnsEnd(i + 1), own_end = solverOrder(task).columnsEnd(i);
      if (own_end > own_first)  // most bodies carry none: no product of zero width
        carried.noalias() +=
            sw.A_body.middleCols(own_first, own_end - own_first) * nu_solver.segment(own_first, own_end - own_first);
      tau_c[i - 1] = sw.S[at(i)].dot(carried);
    }
    return;
  }
  std::vector<Vec6>& carried = sw.constraint_wrench;
  for (int i = 1; i <= N; ++i) {  // body i's own columns: those on bodies ≥ i but not ≥ i + 1
    const int own_first = solverOrder(task).columnsEnd(i + 1), own_end = solverOrder(task).columnsEnd(i);
    if (own_end == own_first)  // most bodies carry none: no product of zero width
      carried[at(i)].setZero();
    else
      carried[at(i)].noalias() =
          sw.A_body.middleCols(own_first, own_end - own_first) * nu_solver.segment(own_first, own_end - own_first);
  }
  for (int i = N; i >= 1; --i) {
    tau_c[i - 1] = sw.S[at(i)].dot(carried[at(i)]);
    if (model.parent(i) > 0) carried[at(model.parent(i))] += carried[at(i)];  // the world takes the rest
  }
}

namespace {
// prescribedTorques and prescribedContactTorques: with kMotion the whole torque, without it the contacts' part;
// with kEveryColumn every constraint force acts on the bodies, not only the contacts' (prescribedDofResiduals).
// What the joint of body i transmits to its subtree: on a chain (kChain) one running sum from the tip, kept in a
// register; on a tree each body's slot of sw.f collects its children's.
template <bool kMotion, bool kEveryColumn, bool kChain>
void subtreeTorques(const Model& model, const Task& task, WorkspaceScratch& sw, int lowest, const VectorRef& nu_solver,
                    const double* qdd, const double* tau, Eigen::Ref<Eigen::VectorXd> tau_c) {
  const int N = model.nv();
  const std::vector<char>& contact = solverOrder(task).contactColumns();
  const Eigen::VectorXd& rotor_inertia = model.rotorInertia();
  Vec6 carried = Vec6::Zero();
  if (!kChain)
    for (int i = lowest; i <= N; ++i) sw.f[at(i)].setZero();
  for (int i = N; i >= lowest; --i) {
    Vec6& f = kChain ? carried : sw.f[at(i)];
    if (kMotion) f += sw.I[at(i)] * sw.a[at(i)] + sw.Fbias[at(i)];
    const int own_first = solverOrder(task).columnsEnd(i + 1), own_end = solverOrder(task).columnsEnd(i);
    for (int col = own_first; col < own_end; ++col)
      if (kEveryColumn || contact[at(col)]) f.noalias() -= sw.A_body.col(col) * nu_solver[col];
    if (isPrescribed(sw, i - 1))
      tau_c[i - 1] = sw.S[at(i)].dot(f) + (kMotion ? rotor_inertia[i - 1] * qdd[i - 1] - tau[i - 1] : 0.0);
    if (!kChain && model.parent(i) >= lowest) sw.f[at(model.parent(i))] += f;
  }
}

template <bool kMotion, bool kEveryColumn = false>
void prescribedDofTorques(const Model& model, const Task& task, Workspace& ws, const VectorRef& nu_solver,
                          const double* qdd, const double* tau, Eigen::Ref<Eigen::VectorXd> tau_c) {
  WorkspaceScratch& sw = scratchOf(ws);
  if (sw.prescribed_count == 0) return;
  // The bodies before the first prescribed DOF's lie in no prescribed DOF's subtree (depth-first order).
  int lowest = 1;
  while (!isPrescribed(sw, lowest - 1)) ++lowest;
  if (model.isChain())
    subtreeTorques<kMotion, kEveryColumn, true>(model, task, sw, lowest, nu_solver, qdd, tau, tau_c);
  else
    subtreeTorques<kMotion, kEveryColumn, false>(model, task, sw, lowest, nu_solver, qdd, tau, tau_c);
}
}  // namespace

void prescribedTorques(const Model& model, const Task& task, Workspace& ws, const VectorRef& nu_solver,
                       const VectorRef& qdd, const VectorRef& tau, Eigen::Ref<Eigen::VectorXd> tau_c) {
  prescribedDofTorques<true>(model, task, ws, nu_solver, qdd.data(), tau.data(), tau_c);
}

void prescribedContactTorques(const Model& model, const Task& task, Workspace& ws, const VectorRef& nu_solver,
                              Eigen::Ref<Eigen::VectorXd> tau_c) {
  prescribedDofTorques<false>(model, task, ws, nu_solver, nullptr, nullptr, tau_c);
}

void prescribedConstraintTorques(const Model& model, const Task& task, Workspace& ws, const VectorRef& nu_solver,
                                 Eigen::Ref<Eigen::VectorXd> tau_c) {
  prescribedDofTorques<false, true>(model, task, ws, nu_solver, nullptr, nullptr, tau_c);
}

void prescribedDofResiduals(const Model& model, const Task& task, Workspace& ws, const VectorRef& nu_solver,
                            const VectorRef& qdd, const VectorRef& tau, Eigen::Ref<Eigen::VectorXd> residual) {
  prescribedDofTorques<true, true>(model, task, ws, nu_solver, qdd.data(), tau.data(), residual);
}

double gaussFunction(const Model& model, const Task& task, const VectorRef& qdd, const VectorRef& tau,
                     const Workspace& ws) {
  const WorkspaceScratch& sw = scratchOf(ws);
  // Z with true accelerations and gravity as a force (the physical Gauss
  // function; the gravity-shifted sweep's version differs by a constant):
  // Σ_i ½ aᵢᵀIᵢaᵢ + (F_bias,i − I_i[g; 0])ᵀaᵢ + Σ_j ½ d_j q̈_j² − τ_j q̈_j,
  // in 3-vector pieces: with y = ½a + [−g; 0] = [y_l; y_a] and a = [a_l; α],
  // aᵀI y = m a_l·y_l + h·((a_l − g) × α) + ½ αᵀĪα (the two moments of h
  // are one triple product; Ī symmetric).
  const Vec3& g = task.gravity;
  const Eigen::VectorXd& rotor_inertia = model.rotorInertia();
  double Z = 0.0;
  for (int i = 1; i <= model.nv(); ++i) {
    const RigidInertia& I = sw.I[at(i)];
    const Vec6& a_sweep = sw.a[at(i)];
    const Vec3 a_lin = a_sweep.head<3>() + g;  // true acceleration: sweep − [−g; 0]
    const Vec3 alpha = a_sweep.tail<3>();
    const Vec3 y_lin = 0.5 * a_lin - g;
    const Vec6& F = sw.Fbias[at(i)];
    const Mat3& J = I.Ibar;
    const double half_aIa =
        0.5 * (J(0, 0) * alpha[0] * alpha[0] + J(1, 1) * alpha[1] * alpha[1] + J(2, 2) * alpha[2] * alpha[2]) +
        J(1, 0) * alpha[0] * alpha[1] + J(2, 0) * alpha[0] * alpha[2] + J(2, 1) * alpha[1] * alpha[2];
    Z +=
        a_lin.dot(I.mass * y_lin + F.head<3>()) + I.h.dot((a_lin - g).cross(alpha)) + half_aIa + alpha.dot(F.tail<3>());
    const double qdd_i = qdd[i - 1];
    Z += (0.5 * rotor_inertia[i - 1] * qdd_i - tau[i - 1]) * qdd_i;
  }
  return Z;
}

void publishNu(const Task& task, Workspace& ws) {
  WorkspaceScratch& sw = scratchOf(ws);
  const int m = task.constraintRows();
  if (ws.solution.nu.size() != m) ws.solution.nu.resize(m);  // only when the task's size changed
  // Both columns of a relative row carry the row's ν: either may write it.
  // Mimic rows (after the user's) are the mechanism's, not the task's.
  for (int col = 0; col < task.solverColumns(); ++col) {
    const int row = solverOrder(task).solverRowToUserRow()[at(col)];
    if (row < m) ws.solution.nu[row] = sw.nu_columns[col];
  }
}

void carryMimicTorques(const Model& model, Eigen::Ref<Eigen::VectorXd> tau_control) {
  // Power-equivalent: a torque τ_m at the mimic joint moves the robot as
  // a·τ_m at its leader does (q̇_m = a·q̇_l), the difference being a coupling
  // torque the mechanism supplies. So the leader's motor carries it.
  for (const int m : model.mimicJoints()) {
    const Joint& joint = model.joint(m);
    const int v_leader = model.joint(joint.mimic.leader).v_index;
    tau_control[v_leader] += joint.mimic.multiplier * tau_control[joint.v_index];
    tau_control[joint.v_index] = 0.0;
  }
}

void controlTorques(const Model& model, const VectorRef& tau, Solution& out) {
  out.tau_control = tau + out.tau_constraint;
  if (model.mimicJoints().empty()) return;
  carryMimicTorques(model, out.tau_control);
  out.tau_constraint = out.tau_control - tau;  // so that τ_control = τ + τ_c still holds
}

}  // namespace zwang::internal
