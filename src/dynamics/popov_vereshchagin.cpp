// Popov–Vereshchagin constrained hybrid dynamics, stage by stage. Read next to
// Algorithm 1 of the report (chapter 4.2); "line N" refers to it. Differences:
//  * base coordinates (src/dynamics/sweeps.hpp): every spatial quantity is in
//    world axes at the world origin, so the report's ⁱX_{i−1} are identities
//    and lines 16, 18, 19 and 29 sum instead of transforming;
//  * sign of ν: the constraint wrench on a body is +A ν (docs/solver.md, "Sign of ν"; the report
//    and KDL apply −A ν). So 𝓛 below is the report's −𝓛 (positive
//    semi-definite) and line 28 has −A ν where the report has +A ν;
//  * constraints may sit on any bodies (the report's section 4.4 extension):
//    A_i collects the unit constraint forces of every constraint on bodies
//    i..N, and each body adds its own columns as the inward sweep reaches it.
#include "dynamics/popov_vereshchagin.hpp"

#include <cmath>
#include <limits>

#include "dynamics/balance.hpp"
#include "dynamics/checks.hpp"
#include "dynamics/sweeps.hpp"

namespace zwang::internal {

namespace {
inline std::size_t at(int i) { return static_cast<std::size_t>(i); }
}  // namespace

Status checkSolveInputs(const Model& model, const Task& task, const VectorRef& q, const VectorRef& qd,
                        const VectorRef& tau, const Workspace& ws) {
  if (ws.dof() != model.dof())
    return Status::error(StatusCode::ModelMismatch, "workspace was made for %d joints, the model has %d", ws.dof(),
                         model.dof());
  if (task.modelDof() != model.dof() || task.modelFrames() != static_cast<int>(model.frames().size()))
    return Status::error(StatusCode::ModelMismatch, "task was made for another model (%d joints, %d frames)",
                         task.modelDof(), task.modelFrames());
  if (task.constraintRows() > ws.constraintCapacity())
    return Status::error(StatusCode::WorkspaceTooSmall,
                         "task has %d constraint rows, the workspace was made for at most %d", task.constraintRows(),
                         ws.constraintCapacity());
  if (Status s = checkBalanceOptions(task.balance); !s) return s;
  if (Status s = checkVector("q", q, model.dof()); !s) return s;
  if (Status s = checkVector("qd", qd, model.dof()); !s) return s;
  if (Status s = checkVector("tau", tau, model.dof()); !s) return s;
  if (Status s = checkFinite("gravity", task.gravity); !s) return s;
  if (Status s = checkFinite("constraint targets b", task.targets()); !s) return s;
  for (int w = 0; w < task.wrenchCount(); ++w)
    if (!task.wrench(w).allFinite())
      return Status::error(StatusCode::NonFinite, "wrench %d (on frame '%s') is not finite", w,
                           model.frame(task.wrenches()[at(w)].frame).name.c_str());
  return {};
}

namespace {

// The task's constraints as unit forces on their bodies in base coordinates,
// and the set points b as the sweep sees them (b is the true classical
// acceleration of the frame origin p: docs/conventions.md, "What a frame's
// acceleration is"; the sweep works with spatial accelerations shifted by [−g; 0]):
//   A_w = [f; n + p × f],  A_wᵀ Ẍ = b − f·(ω × v_p) − f·g.
void constraintsInBodyForm(const Model& model, const Task& task, Workspace& ws) {
  const std::vector<int>& user_row = task.solverRowToUserRow();
  int col = 0;
  for (const Task::ConstraintGroup& g : task.groups()) {
    const Transform X = framePlacementInBase(model, ws, g.frame);  // ᶠX₀
    const Vec6& v = ws.v[at(g.body)];
    const Vec3 w = v.tail<3>();
    const Vec3 classical_shift = w.cross(v.head<3>() + w.cross(X.r));  // ω × v_p
    const Mat3 R = X.E.transpose();
    for (int k = 0; k < g.rows; ++k, ++col) {
      Vec3 f = g.A.col(k).head<3>(), n = g.A.col(k).tail<3>();
      if (g.expressed == Expressed::Local) {
        f = R * f;
        n = R * n;
      }
      ws.A_body.col(col) << f, n + X.r.cross(f);
      const double b = task.targets()[user_row[at(col)]];
      ws.b_body[col] = b - f.dot(classical_shift) - f.dot(task.gravity);
    }
  }
}

}  // namespace

void outwardSweep(const Model& model, const Task& task, const VectorRef& q, const VectorRef& qd, Workspace& ws) {
  outwardKinematics(model, q, qd, ws, true);  // lines 3–6
  for (int i = 1; i <= model.dof(); ++i)
    ws.Fbias[at(i)] = spatial::crossForce(ws.v[at(i)], ws.I[at(i)] * ws.v[at(i)]);  // line 7, without F_ext
  applyExternalWrenches(model, task, ws);                                           // line 7: − F_ext
  // Lines 8–9 (I^A_i = I_i, F^A_i = F_bias,i) are folded into the inward
  // sweep, which sets each body's articulated quantities as it reaches them.
  constraintsInBodyForm(model, task, ws);
}

Status inwardSweep(const Model& model, const Task& task, const VectorRef& tau, Workspace& ws) {
  const int N = model.dof();
  const int m = task.constraintRows();
  ws.U.head(m).setZero();  // U_N = 0
  ws.L_scale.head(m).setZero();
  ws.L.topLeftCorner(m, m).setZero();   // 𝓛_N = 0 (only the lower triangle is kept)
  ws.IA[at(N)] = ws.I[at(N)].matrix();  // line 9 for the last body
  ws.FA[at(N)] = ws.Fbias[at(N)];       // line 8
  ConstraintMatrix& A = ws.Ahat;        // A_i, updated in place
  A.leftCols(task.activeColumns(N)) = ws.A_body.leftCols(task.activeColumns(N));  // body N's own constraints
  for (int i = N; i >= 1; --i) {
    const Joint& joint = model.joint(i - 1);
    const Vec6& S = ws.S[at(i)];
    const Mat6& IA = ws.IA[at(i)];
    const Vec6& c = ws.c[at(i)];
    Vec6& IAS = ws.IAS[at(i)];
    IAS.noalias() = IA * S;
    const double D = joint.rotor_inertia + S.dot(IAS);  // line 13
    ws.D[at(i)] = D;
    if (!(D > 1e-300))
      return Status::error(StatusCode::Degenerate, "joint '%s' has no inertia to move here (D = %g)",
                           joint.name.c_str(), D);
    Vec6 pA = ws.FA[at(i)];
    pA.noalias() += IA * c;                   // F^A + I^A Ẍ_bias
    const double u = tau[i - 1] - S.dot(pA);  // τ − Sᵀ(F^A + I^A Ẍ_bias), docs/solver.md
    ws.u[at(i)] = u;
    const double inverse_D = 1.0 / D;  // one division per body; the rest multiply
    const double u_D = u * inverse_D;
    // P^A = 1 − I^A S D⁻¹ Sᵀ (line 14) is applied, never formed.

    // Lines 19–21, one constraint column at a time.
    const int k = task.activeColumns(i);
    double* sA = ws.SA.col(i).data();
    const double SS_D = S.squaredNorm() * inverse_D;
    for (int col = 0; col < k; ++col) {
      sA[col] = S.dot(A.col(col));                         // (Sᵀ A_i)ᵀ
      ws.L_scale[col] += SS_D * A.col(col).squaredNorm();  // what rounding of sA² / D is relative to
    }
    for (int col = 0; col < k; ++col) {
      const double sA_D = sA[col] * inverse_D;
      ws.U[col] += A.col(col).dot(c) + sA[col] * u_D;  // line 20: Aᵀ Ẍ_bias + Aᵀ S D⁻¹ u
      double* L_col = &ws.L(0, col);                   // line 21 (sign: see top), lower triangle
      for (int r = col; r < k; ++r) L_col[r] += sA[r] * sA_D;
      A.col(col) -= IAS * sA_D;  // line 19: A_{i−1} = P^A A_i …
    }
    const int kp = task.activeColumns(i - 1);  // … then body i−1's own columns
    A.middleCols(k, kp - k) = ws.A_body.middleCols(k, kp - k);

    if (i > 1) {
      Mat6& IA_parent = ws.IA[at(i - 1)];  // line 16: I^A_{i−1} = I_{i−1} + I^a_i, I^a = I^A − I^A S D⁻¹ Sᵀ I^A
      const Vec6 IAS_D = IAS * inverse_D;
      IA_parent.noalias() = IA - IAS.lazyProduct(IAS_D.transpose());  // one fused pass
      ws.I[at(i - 1)].addTo(IA_parent);
      ws.FA[at(i - 1)] = ws.Fbias[at(i - 1)] + pA + IAS * u_D;  // lines 17–18: F^A_{i−1} = F_bias + F^a_i
    }
  }
  return {};
}

void balance(const Task& task, Workspace& ws) {
  const int m = task.constraintRows();
  // A row no joint can move (its row of G is zero: a constraint on the base,
  // or a direction through every joint axis) has 𝓛_rr = Σ (Sᵀa)²/D = 0 up to
  // the rounding of the Sᵀa products, ~ε²·L_scale. Make it exactly zero, so
  // the balance sees the singularity and gives the row ν = 0 (docs/solver.md).
  constexpr double kRounding = 1e4 * std::numeric_limits<double>::epsilon() * std::numeric_limits<double>::epsilon();
  for (int r = 0; r < m; ++r)
    if (ws.L(r, r) <= kRounding * ws.L_scale[r]) {
      for (int col = 0; col <= r; ++col) ws.L(r, col) = 0.0;
      for (int row = r; row < m; ++row) ws.L(row, r) = 0.0;
    }
  ws.rhs.head(m) = ws.b_body.head(m) - ws.U.head(m);                                                // line 25 …
  ws.rhs.head(m).noalias() -= ws.Ahat.leftCols(m).transpose() * gravityAcceleration(task.gravity);  // … − A₀ᵀẌ₀
  ws.solution.balance =
      solveBalance(ws.L.topLeftCorner(m, m), ws.rhs.head(m), ws.nu.head(m), ws.balance_factorisation, task.balance);
}

void outwardAccelerations(const Model& model, const Task& task, Workspace& ws, Eigen::Ref<Eigen::VectorXd> qdd) {
  ws.a[0] = gravityAcceleration(task.gravity);  // Ẍ₀ = [−g; 0]
  for (int i = 1; i <= model.dof(); ++i) {
    const Vec6& a_parent = ws.a[at(i - 1)];
    const int k = task.activeColumns(i);
    const double constraint = ws.SA.col(i).head(k).dot(ws.nu.head(k));                    // Sᵀ A_i ν
    qdd[i - 1] = (ws.u[at(i)] - ws.IAS[at(i)].dot(a_parent) + constraint) / ws.D[at(i)];  // line 28
    ws.a[at(i)] = a_parent + ws.S[at(i)] * qdd[i - 1] + ws.c[at(i)];                      // line 29
  }
}

void bodyAccelerations(const Model& model, const Task& task, Workspace& ws, const VectorRef& qdd) {
  ws.a[0] = gravityAcceleration(task.gravity);  // Ẍ₀ = [−g; 0]
  for (int i = 1; i <= model.dof(); ++i)
    ws.a[at(i)] = ws.a[at(i - 1)] + ws.S[at(i)] * qdd[i - 1] + ws.c[at(i)];  // line 29
}

void unitTorqueColumns(const Model& model, const Task& task, Workspace& ws, const std::vector<int>& joints,
                       Eigen::Ref<Eigen::MatrixXd> du, Eigen::Ref<Eigen::MatrixXd> dU, Eigen::Ref<Eigen::MatrixXd> dnu,
                       Eigen::Ref<Eigen::MatrixXd> dqdd, Eigen::Ref<Matrix6X> dF, Eigen::Ref<Matrix6X> da) {
  // Only the τ-dependent terms change: u, F^a (line 17) and U (line 20); the
  // inertia terms I^A, D, P^A, A_i and 𝓛 are shared with the main pass.
  // Column c is zero outward of its joint s_c, so the inward sweep at body i
  // works on the columns with s_c ≥ i: a suffix c ≥ first, since the joints
  // ascend.
  const int N = model.dof();
  const int m = task.constraintRows();
  const auto k = static_cast<Eigen::Index>(joints.size());
  dU.setZero();
  dF.setZero();  // δF^A arriving at body i from its child, per column
  Eigen::Index first = k;
  for (int i = N; i >= 1; --i) {
    while (first > 0 && bodyOfJoint(joints[static_cast<std::size_t>(first - 1)]) >= i) --first;
    const Vec6& S = ws.S[at(i)];
    const Vec6& IAS = ws.IAS[at(i)];
    const double inverse_D = 1.0 / ws.D[at(i)];
    const int ki = task.activeColumns(i);
    for (Eigen::Index c = 0; c < first; ++c) du(i, c) = 0.0;
    for (Eigen::Index c = first; c < k; ++c) {
      const double du_ic = (bodyOfJoint(joints[static_cast<std::size_t>(c)]) == i ? 1.0 : 0.0) - S.dot(dF.col(c));
      du(i, c) = du_ic;
      const double du_D = du_ic * inverse_D;
      for (int r = 0; r < ki; ++r) dU(r, c) += ws.SA(r, i) * du_D;  // line 20
      dF.col(c) += IAS * du_D;                                      // lines 17–18
    }
  }
  du.row(0).setZero();
  dU.topRows(m) *= -1.0;  // line 25: δν = 𝓛⁻¹(−δU₀) with the same factorisation
  balanceApplyColumns(ws.balance_factorisation, dU.topRows(m), dnu.topRows(m), ws.balance_factorisation.work.head(m));
  da.setZero();
  for (int i = 1; i <= N; ++i) {  // lines 28–29 for the differences
    const Vec6& S = ws.S[at(i)];
    const Vec6& IAS = ws.IAS[at(i)];
    const double inverse_D = 1.0 / ws.D[at(i)];
    const int ki = task.activeColumns(i);
    for (Eigen::Index c = 0; c < k; ++c) {
      double constraint = 0.0;
      for (int r = 0; r < ki; ++r) constraint += ws.SA(r, i) * dnu(r, c);
      const double dq = (du(i, c) - IAS.dot(da.col(c)) + constraint) * inverse_D;
      dqdd(i - 1, c) = dq;
      da.col(c) += S * dq;
    }
  }
}

void jointsOutsideLimits(const Model& model, const VectorRef& q, Solution& out) {
  out.joints_outside_limits = 0;
  out.first_joint_outside_limits = -1;
  for (int j = 0; j < model.dof(); ++j) {
    const Joint& joint = model.joint(j);
    if (q[j] >= joint.lower && q[j] <= joint.upper) continue;
    if (out.joints_outside_limits++ == 0) out.first_joint_outside_limits = j;
  }
}

void taskResidual(const Task& task, Workspace& ws) {
  // Aᵀ Ẍ − b row by row on the final accelerations. In sweep form both sides
  // carry the same gravity and velocity shifts (constraintsInBodyForm), so the
  // difference is the row's error in its own units. A row counts as met when
  // the error is within residual_tolerance of the size of what it is computed
  // from: the accelerations it reads, its set point, and the balance's
  // right-hand side (what the constraint force had to correct).
  const int m = task.constraintRows();
  BalanceReport& report = ws.solution.balance;
  double sum2 = 0.0;
  bool met = true;
  int col = 0;
  for (const Task::ConstraintGroup& g : task.groups()) {
    const Vec6& a = ws.a[at(g.body)];
    for (int k = 0; k < g.rows; ++k, ++col) {
      const auto A = ws.A_body.col(col);
      const double error = A.dot(a) - ws.b_body[col];
      const double size = A.cwiseAbs().dot(a.cwiseAbs()) + std::abs(ws.b_body[col]) + std::abs(ws.rhs[col]);
      sum2 += error * error;
      met = met && std::abs(error) <= task.balance.residual_tolerance * size;
    }
  }
  report.residual = m > 0 ? std::sqrt(sum2) : 0.0;
  report.consistent = met;
}

void constraintTorques(const Model& model, const Task& task, const Workspace& ws, const VectorRef& nu_solver,
                       Eigen::Ref<Eigen::VectorXd> tau_c) {
  // The wrenches A ν of each body's own constraints, summed inward and
  // projected on each joint: the physical torque (docs/solver.md, "Constraint torques: why not eq. 4.4").
  const int N = model.dof();
  if (task.constraintRows() == 0) {
    tau_c.setZero();
    return;
  }
  Vec6 carried = Vec6::Zero();
  for (int i = N; i >= 1; --i) {
    const int k_below = i < N ? task.activeColumns(i + 1) : 0;
    const int k = task.activeColumns(i);
    carried.noalias() += ws.A_body.middleCols(k_below, k - k_below) * nu_solver.segment(k_below, k - k_below);
    tau_c[i - 1] = ws.S[at(i)].dot(carried);
  }
}

double gaussFunction(const Model& model, const Task& task, const VectorRef& qdd, const VectorRef& tau,
                     const Workspace& ws) {
  // Z with true accelerations and gravity as a force (the physical Gauss
  // function; the gravity-shifted sweep's version differs by a constant):
  // Σ_i ½ aᵢᵀIᵢaᵢ + (F_bias,i − I_i[g; 0])ᵀaᵢ + Σ_j ½ d_j q̈_j² − τ_j q̈_j,
  // in 3-vector pieces: with y = ½a + [−g; 0] = [y_l; y_a] and a = [a_l; α],
  // I y = [m y_l − h × y_a; h × y_l + Ī y_a].
  const Vec3& g = task.gravity;
  double Z = 0.0;
  for (int i = 1; i <= model.dof(); ++i) {
    const RigidInertia& I = ws.I[at(i)];
    const Vec6& a_sweep = ws.a[at(i)];
    const Vec3 a_lin = a_sweep.head<3>() + g;  // true acceleration: sweep − [−g; 0]
    const Vec3 alpha = a_sweep.tail<3>();
    const Vec3 y_lin = 0.5 * a_lin - g;
    const Vec3 y_ang = 0.5 * alpha;
    const Vec6& F = ws.Fbias[at(i)];
    Z += a_lin.dot(I.mass * y_lin - I.h.cross(y_ang) + F.head<3>()) +
         alpha.dot(I.h.cross(y_lin) + I.Ibar * y_ang + F.tail<3>());
    const double qdd_i = qdd[i - 1];
    Z += (0.5 * model.joint(i - 1).rotor_inertia * qdd_i - tau[i - 1]) * qdd_i;
  }
  return Z;
}

void publishNu(const Task& task, Workspace& ws) {
  const int m = task.constraintRows();
  if (ws.solution.nu.size() != m) ws.solution.nu.resize(m);  // only when the task's size changed
  for (int col = 0; col < m; ++col) ws.solution.nu[task.solverRowToUserRow()[at(col)]] = ws.nu[col];
}

}  // namespace zwang::internal
