// Popov–Vereshchagin constrained hybrid dynamics. Read next to Algorithm 1 of
// the report (chapter 4.2); "line N" refers to it. Two deliberate differences:
//  * sign of ν: SPEC fixes the constraint wrench on a body as +A ν (the report
//    and KDL apply −A ν). So 𝓛 below is the report's −𝓛 (positive
//    semi-definite) and line 28 has −A ν where the report has +A ν;
//  * constraints may sit on any bodies (the report's section 4.4 extension):
//    A_i collects the unit constraint forces of every constraint on bodies
//    i..N, and each body adds its own columns as the inward sweep reaches it.
#include "zwang/hybrid_dynamics.hpp"

#include "internal/checks.hpp"
#include "internal/coupling.hpp"
#include "internal/sweeps.hpp"

namespace zwang {
namespace {

using spatial::crossForce;

Status checkInputs(const Model& model, const Task& task, const internal::VectorRef& q, const internal::VectorRef& qd,
                   const internal::VectorRef& tau, const Workspace& ws) {
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
  if (Status s = internal::checkVector("q", q, model.dof()); !s) return s;
  if (Status s = internal::checkVector("qd", qd, model.dof()); !s) return s;
  if (Status s = internal::checkVector("tau", tau, model.dof()); !s) return s;
  if (Status s = internal::checkFinite("gravity", task.gravity); !s) return s;
  if (Status s = internal::checkFinite("constraint targets b", task.targets()); !s) return s;
  for (int w = 0; w < task.wrenchCount(); ++w)
    if (!task.wrench(w).allFinite())
      return Status::error(StatusCode::NonFinite, "wrench %d (on frame '%s') is not finite", w,
                           model.frame(task.wrenches()[static_cast<std::size_t>(w)].frame).name.c_str());
  return {};
}

// The task's constraints as unit forces on their bodies, in body axes, and the
// set points b as the sweep sees them (SPEC: b is the true classical
// acceleration of the frame origin; the sweep works with spatial accelerations
// shifted by gravity).
void constraintsInBodyForm(const Model& model, const Task& task, Workspace& ws) {
  const std::vector<int>& user_row = task.solverRowToUserRow();
  int col = 0;
  for (const Task::ConstraintGroup& g : task.groups()) {
    const Frame& frame = model.frame(g.frame);
    const auto body = static_cast<std::size_t>(g.body);
    const Vec6 vf = frame.placement.applyMotion(ws.v[body]);  // frame velocity, frame axes
    const Vec3 classical_shift = vf.tail<3>().cross(vf.head<3>());  // ω × v of the origin
    const Vec6 gravity_shift = internal::gravityShift(ws, g.body, task.gravity);
    Mat3 Rt = Mat3::Identity();
    if (g.expressed != Expressed::Local) Rt = internal::frameRotation(model, ws, g.frame).transpose();
    for (int k = 0; k < g.rows; ++k, ++col) {
      Vec6 a_local = g.A.col(k);
      if (g.expressed != Expressed::Local) a_local << Rt * g.A.col(k).head<3>(), Rt * g.A.col(k).tail<3>();
      ws.A_body.col(col) = frame.placement.inverseApplyForce(a_local);
      const double b = task.targets()[user_row[static_cast<std::size_t>(col)]];
      ws.b_body[col] = b - a_local.head<3>().dot(classical_shift) + ws.A_body.col(col).dot(gravity_shift);
    }
  }
}

}  // namespace

Status solveHybridDynamics(const Model& model, const Task& task, const Eigen::Ref<const Eigen::VectorXd>& q,
                           const Eigen::Ref<const Eigen::VectorXd>& qd, const Eigen::Ref<const Eigen::VectorXd>& tau,
                           Workspace& ws) noexcept {
  if (Status s = checkInputs(model, task, q, qd, tau, ws); !s) return s;
  const int N = model.dof();
  const int m = task.constraintRows();
  auto at = [](int i) { return static_cast<std::size_t>(i); };

  // ---- Outward sweep of position, velocity and bias components (lines 2–10)
  internal::outwardKinematics(model, q, qd, ws);  // lines 3–6
  for (int i = 1; i <= N; ++i) {
    const RigidInertia& I = model.inertia(i);
    ws.Fbias[at(i)] = crossForce(ws.v[at(i)], I * ws.v[at(i)]);  // line 7, without F_ext
  }
  internal::applyExternalWrenches(model, task, ws);  // line 7: − ⁱX₀* F_ext
  for (int i = 1; i <= N; ++i) {
    ws.FA[at(i)] = ws.Fbias[at(i)];                 // line 8
    ws.IA[at(i)] = model.inertia(i).matrix();       // line 9
  }
  constraintsInBodyForm(model, task, ws);

  // ---- Inward sweep of inertia, force and acceleration energy (lines 11–22)
  ws.U.head(m).setZero();          // U_N = 0
  ws.L.topLeftCorner(m, m).setZero();  // 𝓛_N = 0
  // Body N's own constraints start A_N.
  const int kN = task.activeColumns(N);
  ws.Ahat[at(N)].leftCols(kN) = ws.A_body.leftCols(kN);
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
    const double tau_i = tau[i - 1];
    ws.u[at(i)] = tau_i - S.dot(ws.FA[at(i)] + IA * c);

    // P^A = 1 − I^A S D⁻¹ Sᵀ (line 14) is applied, never formed.
    const Mat6 Ia = IA - IAS * IAS.transpose() / D;              // line 15: I^a = P^A I^A
    const Vec6 Fa = ws.FA[at(i)] + IA * c + IAS * (ws.u[at(i)] / D);  // line 17 (= P^A F^A + I^A S D⁻¹τ + I^a Ẍ_bias)

    const int k = task.activeColumns(i);
    auto A = ws.Ahat[at(i)].leftCols(k);
    auto sA = ws.scratch.head(k);
    sA.noalias() = A.transpose() * S;                            // (Sᵀ A_i)ᵀ
    ws.U.head(k).noalias() += A.transpose() * c;                 // line 20: A_iᵀ Ẍ_bias …
    ws.U.head(k) += sA * (ws.u[at(i)] / D);                      //          … + Aᵀ S D⁻¹ (τ − Sᵀ(F^A + I^A Ẍ_bias))
    ws.L.topLeftCorner(k, k).noalias() += sA * sA.transpose() / D;  // line 21 (sign: see top)

    const Transform& X = ws.Xup[at(i)];
    if (i > 1) {
      ws.IA[at(i - 1)] += X.inverseApplyInertia(Ia);             // line 16
      ws.FA[at(i - 1)] += X.inverseApplyForce(Fa);               // line 18
    }
    // line 19: A_{i−1} = ⁱX_{i−1}ᵀ P^A A_i, then body i−1's own columns.
    ConstraintMatrix& Aparent = ws.Ahat[at(i - 1)];
    for (int col = 0; col < k; ++col)
      Aparent.col(col) = X.inverseApplyForce(A.col(col) - IAS * (sA[col] / D));
    const int kp = task.activeColumns(i - 1);
    Aparent.middleCols(k, kp - k) = ws.A_body.middleCols(k, kp - k);
  }

  // ---- Balance of acceleration energy at the base (lines 23–25)
  const Vec6 a0 = internal::gravityShift(ws, 0, task.gravity);  // Ẍ₀ = [−g; 0]
  ws.rhs.head(m) = ws.b_body.head(m) - ws.Ahat[0].leftCols(m).transpose() * a0 - ws.U.head(m);
  ws.solution.coupling =
      internal::solveBalance(ws.L.topLeftCorner(m, m), ws.rhs.head(m), ws.nu.head(m), ws.eigvec.topLeftCorner(m, m),
                             ws.eigval.head(m), ws.scratch.head(m), task.balance);

  // ---- Outward sweep of resulting torque and acceleration (lines 26–30)
  Solution& out = ws.solution;
  ws.a[0] = a0;
  for (int i = 1; i <= N; ++i) {
    const Vec6 Xa = ws.Xup[at(i)].applyMotion(ws.a[at(i - 1)]);
    const int k = task.activeColumns(i);
    const double constraint = (ws.Ahat[at(i)].leftCols(k).transpose() * ws.S[at(i)]).dot(ws.nu.head(k));
    const double qdd = (ws.u[at(i)] - ws.IAS[at(i)].dot(Xa) + constraint) / ws.D[at(i)];  // line 28
    out.qdd[i - 1] = qdd;
    ws.a[at(i)] = Xa + ws.S[at(i)] * qdd + ws.c[at(i)];  // line 29
  }

  // ---- Outputs beyond Algorithm 1
  // τ_c = Σ J_iᵀ A_i ν_i: the constraint wrenches, carried inward as a force
  // and projected on each joint (the physical torque, SPEC §1, not eq. 4.4).
  if (out.nu.size() != m) out.nu.resize(m);
  for (int col = 0; col < m; ++col) out.nu[task.solverRowToUserRow()[at(col)]] = ws.nu[col];
  Vec6 carried = Vec6::Zero();
  for (int i = N; i >= 1; --i) {
    const int k_below = i < N ? task.activeColumns(i + 1) : 0;
    const int k = task.activeColumns(i);
    if (i < N) carried = ws.Xup[at(i + 1)].inverseApplyForce(carried);
    carried.noalias() += ws.A_body.middleCols(k_below, k - k_below) * ws.nu.segment(k_below, k - k_below);
    out.tau_constraint[i - 1] = ws.S[at(i)].dot(carried);
  }
  out.tau_control = tau + out.tau_constraint;

  // Z at the solution, with true accelerations and gravity as a force (the
  // physical Gauss function; the sweep's version differs by a constant).
  double Z = 0.0;
  for (int i = 1; i <= N; ++i) {
    const RigidInertia& I = model.inertia(i);
    const Vec6 shift = internal::gravityShift(ws, i, task.gravity);
    const Vec6 a_true = ws.a[at(i)] - shift;
    Z += 0.5 * a_true.dot(I * a_true) + (ws.Fbias[at(i)] + I * shift).dot(a_true);
    const double qdd = out.qdd[i - 1];
    Z += 0.5 * model.joint(i - 1).rotor_inertia * qdd * qdd - tau[i - 1] * qdd;

    const Vec6& v = ws.v[at(i)];
    Vec6 classical = a_true;
    classical.head<3>() += v.tail<3>().cross(v.head<3>());
    out.body_acc_local[at(i)] = classical;
    const Mat3 R = ws.Xworld[at(i)].E.transpose();
    out.body_acc_world[at(i)] << R * classical.head<3>(), R * classical.tail<3>();
  }
  out.gauss = Z;
  return {};
}

}  // namespace zwang
