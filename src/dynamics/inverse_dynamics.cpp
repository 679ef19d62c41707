// RNEA and CRBA over the same Model/Workspace as the solver, in base
// coordinates (src/dynamics/sweeps.hpp). A floating base is the joint of body
// 0 to the world (src/dynamics/floating_base.cpp): the outward stage starts
// with its pose, velocity and acceleration, the inward stage ends by taking
// everything that reached body 0 onto the base coordinates. The state vectors
// put the base's coordinates first; the stages index the joints' part.
#include "zwang/inverse_dynamics.hpp"

#include "dynamics/checks.hpp"
#include "dynamics/floating_base.hpp"
#include "dynamics/sweeps.hpp"

namespace zwang {

Status inverseDynamics(const Model& model, const Task& task, const Eigen::Ref<const Eigen::VectorXd>& q_all,
                       const Eigen::Ref<const Eigen::VectorXd>& qd_all,
                       const Eigen::Ref<const Eigen::VectorXd>& qdd_all, Workspace& ws) noexcept {
  ws.kinematics.stage = KinematicsStage::None;  // until the outward stage computes them
  if (ws.dof() != model.dof() || task.modelDof() != model.dof())
    return Status::error(StatusCode::ModelMismatch, "workspace or task was made for another model");
  if (!internal::workspaceFitsBase(model, ws)) return internal::workspaceBaseMismatch(model, ws);
  if (Status s = internal::checkStateConfiguration(model, q_all); !s) return s;  // a free base's quaternion too
  if (Status s = internal::checkVelocityVector(model, "qd", qd_all); !s) return s;
  if (Status s = internal::checkVelocityVector(model, "qdd", qdd_all); !s) return s;
  if (Status s = internal::checkFinite("gravity", task.gravity); !s) return s;
  const int N = model.dof(), nqb = model.baseConfigurationSize(), nvb = model.baseVelocitySize();
  const bool floating = model.hasFloatingBase();
  const auto qdd = qdd_all.tail(N);
  auto tau = ws.tau.tail(N);
  auto at = [](int i) { return static_cast<std::size_t>(i); };

  // Outward: poses, velocities, accelerations. In base coordinates
  // (src/dynamics/sweeps.hpp): no transforms between bodies. Gravity is the
  // world's acceleration [−g; 0]; a floating base's true acceleration ⁰Ẍ₀
  // (from its q̈ in the user's coordinates) rides on it.
  if (floating) internal::baseKinematics(model, q_all.head(nqb), qd_all.head(nvb), ws, true);
  internal::outwardKinematics(model, q_all.tail(N), qd_all.tail(N), ws, true);
  ws.a_world = ws.a[0] = internal::gravityAcceleration(task.gravity);
  if (floating) {
    ws.a[0] += internal::baseTrueAcceleration(model, ws, qdd_all.head(nvb));
    ws.Fbias[0] = spatial::crossForce(ws.v[0], ws.I[0] * ws.v[0]);
  }
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
  ws.kinematics = {KinematicsStage::Accelerations, &model};
  internal::applyExternalWrenches(model, task, ws);  // a floating base's own wrenches too
  for (int i = floating ? 0 : 1; i <= N; ++i) ws.f[at(i)] = ws.I[at(i)] * ws.a[at(i)] + ws.Fbias[at(i)];

  // Inward: the child just done passes its force to body i − 1 in a register
  // when that is its parent; other parents collect in ws.f. A fixed base
  // takes what reaches it (the ground carries it); a floating one collects it.
  Vec6 to_previous = Vec6::Zero();
  for (int i = N; i >= 1; --i) {
    const Vec6 f = ws.f[at(i)] + to_previous;
    tau[i - 1] = ws.S[at(i)].dot(f) + model.joint(i - 1).rotor_inertia * qdd[i - 1];
    const int p = model.parent(i);
    to_previous.setZero();
    if (p == i - 1)
      to_previous = f;
    else if (p > 0 || floating)
      ws.f[at(p)] += f;
  }
  // The base joint: the whole robot's wrench on body 0 (body 1, whose parent
  // is always body 0, left its share in the register) onto the base
  // coordinates: S_userᵀ f₀, for a free base ᴮX₀* f₀, the wrench in base axes
  // at the base origin.
  if (floating) internal::baseGeneralizedForce(model, ws, ws.f[0] + to_previous, ws.tau.head(nvb));
  return {};
}

namespace {

// The CRBA's sweeps, compiled once per kind of base: on a fixed base nvb is
// the constant 0 and the base's rows, columns and offsets vanish, so its
// code (and time) is the one from before floating bases.
template <bool kFloating>
void compositeRigidBody(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q_all, Workspace& ws) {
  const int N = model.dof();
  const int nqb = kFloating ? model.baseConfigurationSize() : 0, nvb = kFloating ? model.baseVelocitySize() : 0;
  auto at = [](int i) { return static_cast<std::size_t>(i); };

  // Outward: poses, motion subspaces and inertias (no velocity: H depends on q only).
  if (kFloating) internal::baseKinematics(model, q_all.head(nqb), q_all.head(0), ws, true);
  internal::outwardKinematics(model, q_all.tail(N), Eigen::VectorXd(), ws, true);
  ws.kinematics = {KinematicsStage::Poses, &model};  // the velocities are left at rest, not the state's
  // The base's columns in the user's coordinates (6 × k; none for a fixed base).
  Matrix6Xmax S_base;
  if (kFloating) internal::baseMotionColumns(model, ws, S_base);

  // Inward: composite inertias, and row i of H from F_i = I^c_i S_i.
  for (int i = kFloating ? 0 : 1; i <= N; ++i) ws.Ic[at(i)] = ws.I[at(i)].matrix();
  for (int i = N; i >= 1; --i) {
    const int p = model.parent(i);
    if (kFloating || p > 0) ws.Ic[at(p)] += ws.Ic[at(i)];  // base coordinates: composite inertias add
    const Vec6 F = ws.Ic[at(i)] * ws.S[at(i)];
    const int row = nvb + i - 1;
    ws.H(row, row) = ws.S[at(i)].dot(F) + model.joint(i - 1).rotor_inertia;
    // H_ij ≠ 0 only for the joints j supporting i (its ancestors); the rest of
    // row i stays zero: the tree's sparsity, zero blocks between branches.
    for (int j = i - 1; j >= 1; --j) ws.H(row, nvb + j - 1) = ws.H(nvb + j - 1, row) = 0.0;
    for (int j = p; j >= 1; j = model.parent(j)) ws.H(row, nvb + j - 1) = ws.H(nvb + j - 1, row) = ws.S[at(j)].dot(F);
    // Every joint is supported by the base joint: its columns see F_i too.
    for (int k = 0; k < nvb; ++k) ws.H(row, k) = ws.H(k, row) = S_base.col(k).dot(F);
  }
  // The base block: the whole robot's composite inertia seen by the base
  // coordinates, S_userᵀ I^c₀ S_user (a free base's: the composite inertia in
  // base axes at the base origin). One triangle, mirrored: H stays exactly
  // symmetric.
  for (int c = 0; c < nvb; ++c) {
    const Vec6 F = ws.Ic[0] * S_base.col(c);
    for (int r = c; r < nvb; ++r) ws.H(r, c) = ws.H(c, r) = S_base.col(r).dot(F);
  }
}

}  // namespace

Status jointSpaceInertia(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q_all, Workspace& ws) noexcept {
  ws.kinematics.stage = KinematicsStage::None;  // until the outward stage computes the poses
  if (ws.dof() != model.dof())
    return Status::error(StatusCode::ModelMismatch, "workspace was made for %d joints, the model has %d", ws.dof(),
                         model.dof());
  if (!internal::workspaceFitsBase(model, ws)) return internal::workspaceBaseMismatch(model, ws);
  if (Status s = internal::checkStateConfiguration(model, q_all); !s) return s;  // a free base's quaternion too
  if (model.hasFloatingBase())
    compositeRigidBody<true>(model, q_all, ws);
  else
    compositeRigidBody<false>(model, q_all, ws);
  return {};
}

}  // namespace zwang
