// RNEA and CRBA over the same Model/Workspace as the solver, in base
// coordinates (src/dynamics/sweeps.hpp), one body per DOF (model.hpp): a
// floating base's root joint is visited as any other joint, and body 0 is the
// world, which takes what reaches it.
#include "zwang/inverse_dynamics.hpp"

#include "dynamics/checks.hpp"
#include "dynamics/sweeps.hpp"

namespace zwang {

namespace {

// The two sweeps of RNEA, after the checks.
ZWANG_FLATTEN void recursiveNewtonEuler(const Model& model, const Task& task,
                                        const Eigen::Ref<const Eigen::VectorXd>& q_all,
                                        const Eigen::Ref<const Eigen::VectorXd>& qd_all,
                                        const Eigen::Ref<const Eigen::VectorXd>& qdd, Workspace& ws) {
  WorkspaceScratch& sw = scratchOf(ws);
  const int N = model.nv();
  Eigen::VectorXd& tau = ws.tau;
  const Eigen::VectorXd& rotor_inertia = model.rotorInertia();
  auto at = [](int i) { return static_cast<std::size_t>(i); };

  // Outward: poses, velocities, bias forces, accelerations. In base coordinates
  // (src/dynamics/sweeps.hpp): no transforms between bodies. Gravity is the
  // world's acceleration [−g; 0].
  internal::outwardKinematics(model, q_all, qd_all, ws, true);
  sw.a_world = sw.a[0] = internal::gravityAcceleration(task.gravity);
  // A body whose parent is the body before it (every body of a chain, most of
  // a tree's) takes the parent's value from a register, not from the store
  // just made: a load that waits on that store costs more than the sum.
  Vec6 a_previous = sw.a[0];
  for (int i = 1; i <= N; ++i) {
    const int p = model.parent(i);
    const Vec6 a = (p == i - 1 ? a_previous : sw.a[at(p)]) + sw.S[at(i)] * qdd[i - 1] + sw.c[at(i)];
    sw.a[at(i)] = a;
    a_previous = a;
  }
  ws.kinematics.stage = KinematicsStage::Accelerations;
  ws.kinematics.model = &model;
  internal::applyExternalWrenches(model, task, ws);
  for (int i = 1; i <= N; ++i) sw.f[at(i)] = sw.I[at(i)] * sw.a[at(i)] + sw.Fbias[at(i)];

  // Inward: the child just done passes its force to body i − 1 in a register
  // when that is its parent; other parents collect in sw.f. The world (body
  // 0) takes what reaches it: the ground carries it.
  Vec6 to_previous = Vec6::Zero();
  for (int i = N; i >= 1; --i) {
    const Vec6 f = sw.f[at(i)] + to_previous;
    tau[i - 1] = sw.S[at(i)].dot(f) + rotor_inertia[i - 1] * qdd[i - 1];
    const int p = model.parent(i);
    to_previous.setZero();
    if (p == i - 1)
      to_previous = f;
    else if (p > 0)
      sw.f[at(p)] += f;
  }
}

}  // namespace

Status inverseDynamics(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q_all,
                       const Eigen::Ref<const Eigen::VectorXd>& qd_all,
                       const Eigen::Ref<const Eigen::VectorXd>& qdd_all, const Task& task) noexcept {
  ws.kinematics.stage = KinematicsStage::None;  // until the outward stage computes them
  if (ws.dof() != model.dof() || task.modelDof() != model.dof())
    return Status::error(StatusCode::ModelMismatch, "workspace or task was made for another model");
  if (!internal::workspaceFitsModel(model, ws)) return internal::workspaceMismatch(model, ws);
  if (Status s = internal::checkStateConfiguration(model, q_all); !s) return s;  // quaternions too
  if (Status s = internal::checkVelocityVector(model, "qd", qd_all); !s) return s;
  if (Status s = internal::checkVelocityVector(model, "qdd", qdd_all); !s) return s;
  if (Status s = internal::checkFinite("gravity", task.gravity); !s) return s;
  recursiveNewtonEuler(model, task, q_all, qd_all, qdd_all, ws);
  return {};
}

Status inverseDynamics(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                       const Eigen::Ref<const Eigen::VectorXd>& qd,
                       const Eigen::Ref<const Eigen::VectorXd>& qdd) noexcept {
  return inverseDynamics(model, ws, q, qd, qdd, ws.defaultTask());
}

namespace {

void compositeRigidBody(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q_all, Workspace& ws) {
  WorkspaceScratch& sw = scratchOf(ws);
  const int N = model.nv();
  const Eigen::VectorXd& rotor_inertia = model.rotorInertia();
  auto at = [](int i) { return static_cast<std::size_t>(i); };

  // Outward: poses, motion subspaces and inertias (no velocity: H depends on q only).
  internal::outwardKinematics(model, q_all, Eigen::VectorXd(), ws, true);
  ws.kinematics.stage = KinematicsStage::Poses;  // the velocities are left at rest, not the state's
  ws.kinematics.model = &model;

  // Inward, joint by joint: composite inertias, and row k of H from F_k =
  // I^c S_k. A multi-DOF joint's intermediate bodies carry no mass and have
  // one child, so all its DOFs see its last body's I^c: only that one is
  // formed and handed to the parent (the world, body 0, takes nothing).
  for (int i = 1; i <= N; ++i)
    if (i == N || model.jointStart(i + 1) == i + 1) sw.Ic[at(i)] = sw.I[at(i)].matrix();
  double* const H = ws.H.data();  // column-major N × N; H_rc at H[r + c·N] (the loop's stores do not reload ws.H)
  for (int last = N; last >= 1;) {
    const int first = model.jointStart(last), p = model.parent(first);
    const Mat6& Ic = sw.Ic[at(last)];
    if (p > 0) sw.Ic[at(p)] += Ic;  // base coordinates: composite inertias add
    for (int i = last; i >= first; --i) {
      const Vec6 F = Ic * sw.S[at(i)];
      const int row = i - 1;
      H[row + row * N] = sw.S[at(i)].dot(F) + rotor_inertia[row];
      // H_kj ≠ 0 only for the DOFs j supporting k (its ancestors); the rest of
      // row k below the diagonal is the zeros of the branches between them
      // (none on a chain): each entry written once, with no pass over all of H.
      for (int j = i - 1, a = model.parent(i); j >= 1; --j) {
        double h = 0.0;
        if (j == a) {
          h = sw.S[at(j)].dot(F);
          a = model.parent(a);
        }
        H[row + (j - 1) * N] = H[(j - 1) + row * N] = h;
      }
    }
    last = first - 1;
  }
}

}  // namespace

Status jointSpaceInertia(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q_all) noexcept {
  ws.kinematics.stage = KinematicsStage::None;  // until the outward stage computes the poses
  if (ws.dof() != model.dof())
    return Status::error(StatusCode::ModelMismatch, "workspace was made for %d joints, the model has %d", ws.dof(),
                         model.dof());
  if (!internal::workspaceFitsModel(model, ws)) return internal::workspaceMismatch(model, ws);
  if (Status s = internal::checkStateConfiguration(model, q_all); !s) return s;  // quaternions too
  compositeRigidBody(model, q_all, ws);
  return {};
}

}  // namespace zwang
