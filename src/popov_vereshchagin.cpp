// Popov–Vereshchagin constrained hybrid dynamics, stage by stage. Read next to
// Algorithm 1 of the report (chapter 4.2); "line N" refers to it. Two
// deliberate differences:
//  * sign of ν: SPEC fixes the constraint wrench on a body as +A ν (the report
//    and KDL apply −A ν). So 𝓛 below is the report's −𝓛 (positive
//    semi-definite) and line 28 has −A ν where the report has +A ν;
//  * constraints may sit on any bodies (the report's section 4.4 extension):
//    A_i collects the unit constraint forces of every constraint on bodies
//    i..N, and each body adds its own columns as the inward sweep reaches it.
#include "internal/popov_vereshchagin.hpp"

#include "internal/checks.hpp"
#include "internal/coupling.hpp"
#include "internal/sweeps.hpp"

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

// The task's constraints as unit forces on their bodies, in body axes, and the
// set points b as the sweep sees them (SPEC: b is the true classical
// acceleration of the frame origin; the sweep works with spatial accelerations
// shifted by gravity).
void constraintsInBodyForm(const Model& model, const Task& task, Workspace& ws) {
  const std::vector<int>& user_row = task.solverRowToUserRow();
  int col = 0;
  for (const Task::ConstraintGroup& g : task.groups()) {
    const Frame& frame = model.frame(g.frame);
    const Vec6 vf = frame.placement.applyMotion(ws.v[at(g.body)]);  // frame velocity, frame axes
    const Vec3 classical_shift = vf.tail<3>().cross(vf.head<3>());   // ω × v of the origin
    const Vec6 gravity_shift = gravityShift(ws, g.body, task.gravity);
    Mat3 Rt = Mat3::Identity();
    if (g.expressed != Expressed::Local) Rt = frameRotation(model, ws, g.frame).transpose();
    for (int k = 0; k < g.rows; ++k, ++col) {
      Vec6 a_local = g.A.col(k);
      if (g.expressed != Expressed::Local) a_local << Rt * g.A.col(k).head<3>(), Rt * g.A.col(k).tail<3>();
      ws.A_body.col(col) = frame.placement.inverseApplyForce(a_local);
      const double b = task.targets()[user_row[at(col)]];
      ws.b_body[col] = b - a_local.head<3>().dot(classical_shift) + ws.A_body.col(col).dot(gravity_shift);
    }
  }
}

}  // namespace

void outwardSweep(const Model& model, const Task& task, const VectorRef& q, const VectorRef& qd, Workspace& ws) {
  outwardKinematics(model, q, qd, ws);  // lines 3–6
  for (int i = 1; i <= model.dof(); ++i)
    ws.Fbias[at(i)] = spatial::crossForce(ws.v[at(i)], model.inertia(i) * ws.v[at(i)]);  // line 7, without F_ext
  applyExternalWrenches(model, task, ws);                                                // line 7: − ⁱX₀* F_ext
  for (int i = 1; i <= model.dof(); ++i) {
    ws.FA[at(i)] = ws.Fbias[at(i)];            // line 8
    ws.IA[at(i)] = model.inertia(i).matrix();  // line 9
  }
  constraintsInBodyForm(model, task, ws);
}

Status inwardSweep(const Model& model, const Task& task, const VectorRef& tau, Workspace& ws) {
  const int N = model.dof();
  const int m = task.constraintRows();
  ws.U.head(m).setZero();              // U_N = 0
  ws.L.topLeftCorner(m, m).setZero();  // 𝓛_N = 0
  const int kN = task.activeColumns(N);
  ws.Ahat[at(N)].leftCols(kN) = ws.A_body.leftCols(kN);  // body N's own constraints start A_N
  for (int i = N; i >= 1; --i) {
    const Joint& joint = model.joint(i - 1);
    const Vec6& S = ws.S[at(i)];
    const Mat6& IA = ws.IA[at(i)];
    const Vec6& c = ws.c[at(i)];
    ws.IAS[at(i)].noalias() = IA * S;
    const Vec6& IAS = ws.IAS[at(i)];
    const double D = joint.rotor_inertia + S.dot(IAS);  // line 13
    ws.D[at(i)] = D;
    if (!(D > 1e-300))
      return Status::error(StatusCode::Degenerate, "joint '%s' has no inertia to move here (D = %g)",
                           joint.name.c_str(), D);
    ws.u[at(i)] = tau[i - 1] - S.dot(ws.FA[at(i)] + IA * c);  // τ − Sᵀ(F^A + I^A Ẍ_bias), see docs/solver.md

    // P^A = 1 − I^A S D⁻¹ Sᵀ (line 14) is applied, never formed.
    const Mat6 Ia = IA - IAS * IAS.transpose() / D;                   // line 15: I^a = P^A I^A
    const Vec6 Fa = ws.FA[at(i)] + IA * c + IAS * (ws.u[at(i)] / D);  // line 17: P^A F^A + I^A S D⁻¹τ + I^a Ẍ_bias

    const int k = task.activeColumns(i);
    const auto A = ws.Ahat[at(i)].leftCols(k);
    auto sA = ws.SA.col(i).head(k);
    sA.noalias() = A.transpose() * S;                                // (Sᵀ A_i)ᵀ
    ws.U.head(k).noalias() += A.transpose() * c;                     // line 20: Aᵀ Ẍ_bias …
    ws.U.head(k) += sA * (ws.u[at(i)] / D);                          //          … + Aᵀ S D⁻¹ u
    for (int r = 0; r < k; ++r) ws.L.col(r).head(k) += sA * (sA[r] / D);  // line 21 (sign: see top)

    const Transform& X = ws.Xup[at(i)];
    if (i > 1) {
      ws.IA[at(i - 1)] += X.inverseApplyInertia(Ia);  // line 16
      ws.FA[at(i - 1)] += X.inverseApplyForce(Fa);    // line 18
    }
    // line 19: A_{i−1} = ⁱX_{i−1}ᵀ P^A A_i, then body i−1's own columns.
    ConstraintMatrix& Aparent = ws.Ahat[at(i - 1)];
    for (int col = 0; col < k; ++col) Aparent.col(col) = X.inverseApplyForce(A.col(col) - IAS * (sA[col] / D));
    const int kp = task.activeColumns(i - 1);
    Aparent.middleCols(k, kp - k) = ws.A_body.middleCols(k, kp - k);
  }
  return {};
}

void balance(const Task& task, Workspace& ws) {
  const int m = task.constraintRows();
  const Vec6 a0 = gravityShift(ws, 0, task.gravity);  // Ẍ₀ = [−g; 0]
  ws.rhs.head(m) = ws.b_body.head(m) - ws.U.head(m);  // line 25 …
  ws.rhs.head(m).noalias() -= ws.Ahat[0].leftCols(m).transpose() * a0;  // … − A₀ᵀẌ₀
  ws.solution.coupling = solveBalance(ws.L.topLeftCorner(m, m), ws.rhs.head(m), ws.nu.head(m),
                                      ws.eigvec.topLeftCorner(m, m), ws.eigval.head(m), ws.scratch.head(m), task.balance);
}

void balanceSolve(const Workspace& ws, int m, const VectorRef& r, Eigen::Ref<Eigen::VectorXd> out) {
  // out = V diag(σ/(σ² + λ²)) Vᵀ r, one entry at a time to need no scratch.
  const auto V = ws.eigvec.topLeftCorner(m, m);
  const double damping2 = ws.solution.coupling.damping * ws.solution.coupling.damping;
  out.setZero();
  for (int k = 0; k < m; ++k) {
    const double s = std::max(0.0, ws.eigval[k]);
    const double denominator = s * s + damping2;
    if (denominator > 0.0) out += V.col(k) * (V.col(k).dot(r) * s / denominator);
  }
}

void outwardAccelerations(const Model& model, const Task& task, Workspace& ws, Eigen::Ref<Eigen::VectorXd> qdd) {
  ws.a[0] = gravityShift(ws, 0, task.gravity);
  for (int i = 1; i <= model.dof(); ++i) {
    const Vec6 Xa = ws.Xup[at(i)].applyMotion(ws.a[at(i - 1)]);
    const int k = task.activeColumns(i);
    const double constraint = ws.SA.col(i).head(k).dot(ws.nu.head(k));  // Sᵀ A_i ν
    qdd[i - 1] = (ws.u[at(i)] - ws.IAS[at(i)].dot(Xa) + constraint) / ws.D[at(i)];  // line 28
    ws.a[at(i)] = Xa + ws.S[at(i)] * qdd[i - 1] + ws.c[at(i)];                     // line 29
  }
}

void unitTorqueColumn(const Model& model, const Task& task, Workspace& ws, int joint, Eigen::Ref<Eigen::VectorXd> du,
                      Eigen::Ref<Eigen::VectorXd> dU, Eigen::Ref<Eigen::VectorXd> dnu,
                      Eigen::Ref<Eigen::VectorXd> dqdd) {
  // Only the τ-dependent terms change: u, F^a (line 17) and U (line 20); the
  // inertia terms I^A, D, P^A, A_i and 𝓛 are shared with the main pass.
  const int N = model.dof();
  const int m = task.constraintRows();
  const int s = joint + 1;
  du.setZero();
  dU.head(m).setZero();
  Vec6 dFA = Vec6::Zero();  // δF^A arriving at body i from its child
  for (int i = s; i >= 1; --i) {
    du[i] = (i == s ? 1.0 : 0.0) - ws.S[at(i)].dot(dFA);
    const double du_D = du[i] / ws.D[at(i)];
    const int k = task.activeColumns(i);
    dU.head(k) += ws.SA.col(i).head(k) * du_D;                        // line 20
    dFA = ws.Xup[at(i)].inverseApplyForce(dFA + ws.IAS[at(i)] * du_D);  // lines 17–18
  }
  auto r = dnu.head(m);  // line 25: δν = 𝓛⁻¹(−δU₀) with the same factorisation
  dU.head(m) *= -1.0;
  balanceSolve(ws, m, dU.head(m), r);
  Vec6 da = Vec6::Zero();
  for (int i = 1; i <= N; ++i) {  // lines 28–29 for the differences
    const Vec6 Xda = ws.Xup[at(i)].applyMotion(da);
    const int k = task.activeColumns(i);
    const double dq = (du[i] - ws.IAS[at(i)].dot(Xda) + ws.SA.col(i).head(k).dot(dnu.head(k))) / ws.D[at(i)];
    dqdd[i - 1] = dq;
    da = Xda + ws.S[at(i)] * dq;
  }
}

void constraintTorques(const Model& model, const Task& task, const Workspace& ws, const VectorRef& nu_solver,
                       Eigen::Ref<Eigen::VectorXd> tau_c) {
  // The wrenches A ν of each body's own constraints, carried inward as one
  // force and projected on each joint: the physical torque (SPEC §1, not eq. 4.4).
  const int N = model.dof();
  Vec6 carried = Vec6::Zero();
  for (int i = N; i >= 1; --i) {
    const int k_below = i < N ? task.activeColumns(i + 1) : 0;
    const int k = task.activeColumns(i);
    if (i < N) carried = ws.Xup[at(i + 1)].inverseApplyForce(carried);
    carried.noalias() += ws.A_body.middleCols(k_below, k - k_below) * nu_solver.segment(k_below, k - k_below);
    tau_c[i - 1] = ws.S[at(i)].dot(carried);
  }
}

double gaussAndBodyAccelerations(const Model& model, const Task& task, const VectorRef& qdd, const VectorRef& tau,
                                 Workspace& ws) {
  // Z with true accelerations and gravity as a force (the physical Gauss
  // function; the gravity-shifted sweep's version differs by a constant).
  double Z = 0.0;
  for (int i = 1; i <= model.dof(); ++i) {
    const RigidInertia& I = model.inertia(i);
    const Vec6 shift = gravityShift(ws, i, task.gravity);
    const Vec6 a_true = ws.a[at(i)] - shift;
    Z += 0.5 * a_true.dot(I * a_true) + (ws.Fbias[at(i)] + I * shift).dot(a_true);
    Z += 0.5 * model.joint(i - 1).rotor_inertia * qdd[i - 1] * qdd[i - 1] - tau[i - 1] * qdd[i - 1];

    const Vec6& v = ws.v[at(i)];
    Vec6 classical = a_true;
    classical.head<3>() += v.tail<3>().cross(v.head<3>());
    ws.solution.body_acc_local[at(i)] = classical;
    const Mat3 R = ws.Xworld[at(i)].E.transpose();
    ws.solution.body_acc_world[at(i)] << R * classical.head<3>(), R * classical.tail<3>();
  }
  return Z;
}

void publishNu(const Task& task, Workspace& ws) {
  const int m = task.constraintRows();
  if (ws.solution.nu.size() != m) ws.solution.nu.resize(m);  // only when the task's size changed
  for (int col = 0; col < m; ++col) ws.solution.nu[task.solverRowToUserRow()[at(col)]] = ws.nu[col];
}

}  // namespace zwang::internal
