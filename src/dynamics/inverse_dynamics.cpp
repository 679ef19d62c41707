#include "zwang/inverse_dynamics.hpp"
#include "dynamics/checks.hpp"
#include "dynamics/sweeps.hpp"

namespace zwang {

Status inverseDynamics(const Model& model, const Task& task, const Eigen::Ref<const Eigen::VectorXd>& q,
                       const Eigen::Ref<const Eigen::VectorXd>& qd, const Eigen::Ref<const Eigen::VectorXd>& qdd,
                       Workspace& ws) noexcept {
  if (ws.dof() != model.dof() || task.modelDof() != model.dof())
    return Status::error(StatusCode::ModelMismatch, "workspace or task was made for another model");
  if (Status s = internal::checkVector("q", q, model.dof()); !s) return s;
  if (Status s = internal::checkVector("qd", qd, model.dof()); !s) return s;
  if (Status s = internal::checkVector("qdd", qdd, model.dof()); !s) return s;
  if (Status s = internal::checkFinite("gravity", task.gravity); !s) return s;
  const int N = model.dof();
  auto at = [](int i) { return static_cast<std::size_t>(i); };

  // In base coordinates (src/dynamics/sweeps.hpp): no transforms between bodies.
  internal::outwardKinematics(model, q, qd, ws, true);
  ws.a_world = ws.a[0] = internal::gravityAcceleration(task.gravity);  // gravity as base acceleration
  // A body whose parent is the body before it (every body of a chain, most of
  // a tree's) takes the parent's value from a register, not from the store
  // just made: a load that waits on that store costs more than the sum.
  Vec6 a_previous = ws.a[0];
  for (int i = 1; i <= N; ++i) {
    const int p = model.parent(i);
    const Vec6 a = (p == i - 1 ? a_previous : ws.a[at(p)]) + ws.S[at(i)] * qdd[i - 1] + ws.c[at(i)];
    ws.a[at(i)] = a;
    a_previous = a;
    ws.Fbias[at(i)] = spatial::crossForce(ws.v[at(i)], ws.I[at(i)] * ws.v[at(i)]);
  }
  internal::applyExternalWrenches(model, task, ws);
  for (int i = 1; i <= N; ++i) ws.f[at(i)] = ws.I[at(i)] * ws.a[at(i)] + ws.Fbias[at(i)];
  // Inward: the child just done passes its force to body i − 1 in a register
  // when that is its parent; other parents collect in ws.f.
  Vec6 to_previous = Vec6::Zero();
  for (int i = N; i >= 1; --i) {
    const Vec6 f = ws.f[at(i)] + to_previous;
    ws.tau[i - 1] = ws.S[at(i)].dot(f) + model.joint(i - 1).rotor_inertia * qdd[i - 1];
    const int p = model.parent(i);
    to_previous.setZero();
    if (p == i - 1)
      to_previous = f;
    else if (p > 0)
      ws.f[at(p)] += f;
  }
  return {};
}

Status jointSpaceInertia(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q, Workspace& ws) noexcept {
  if (ws.dof() != model.dof())
    return Status::error(StatusCode::ModelMismatch, "workspace was made for %d joints, the model has %d", ws.dof(),
                         model.dof());
  if (Status s = internal::checkVector("q", q, model.dof()); !s) return s;
  const int N = model.dof();
  auto at = [](int i) { return static_cast<std::size_t>(i); };
  internal::outwardKinematics(model, q, Eigen::VectorXd(), ws, true);
  for (int i = 1; i <= N; ++i) ws.Ic[at(i)] = ws.I[at(i)].matrix();
  for (int i = N; i >= 1; --i) {
    if (model.parent(i) > 0) ws.Ic[at(model.parent(i))] += ws.Ic[at(i)];  // base coordinates: composite inertias add
    const Vec6 F = ws.Ic[at(i)] * ws.S[at(i)];
    ws.H(i - 1, i - 1) = ws.S[at(i)].dot(F) + model.joint(i - 1).rotor_inertia;
    // H_ij ≠ 0 only for the joints j supporting i (its ancestors); the rest of
    // row i stays zero: the tree's sparsity, zero blocks between branches.
    for (int j = i - 1; j >= 1; --j) ws.H(i - 1, j - 1) = ws.H(j - 1, i - 1) = 0.0;
    for (int j = model.parent(i); j >= 1; j = model.parent(j))
      ws.H(i - 1, j - 1) = ws.H(j - 1, i - 1) = ws.S[at(j)].dot(F);
  }
  return {};
}

}  // namespace zwang
