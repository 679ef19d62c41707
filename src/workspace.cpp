#include "zwang/workspace.hpp"

#include <new>

#include "dynamics/checks.hpp"
#include "dynamics/workspace_scratch.hpp"
#include "friction/friction_scratch.hpp"

namespace zwang {

WorkspaceScratch::WorkspaceScratch(const Model& model, int columns, int m) {
  const auto bodies = static_cast<std::size_t>(model.bodyCount());
  const int n = model.dof();
  Xworld.assign(bodies, Transform{});
  S.assign(bodies, Vec6::Zero());
  I.assign(bodies, RigidInertia{});
  v.assign(bodies, Vec6::Zero());
  c.assign(bodies, Vec6::Zero());
  Fbias.assign(bodies, Vec6::Zero());
  IA.assign(bodies, Mat6::Zero());
  FA.assign(bodies, Vec6::Zero());
  IAS.assign(bodies, Vec6::Zero());
  D.assign(bodies, 0.0);
  inverse_D.assign(bodies, 0.0);
  u.assign(bodies, 0.0);
  SA.setZero(columns, static_cast<Eigen::Index>(bodies));
  Ahat.setZero(6, columns);
  U.setZero(columns);
  L.setZero(columns, columns);
  L_scale.setZero(columns);
  A_body.setZero(6, columns);
  b_body.setZero(columns);
  L_rows.setZero(m, m);
  L_scale_rows.setZero(m);
  nu_rows.setZero(m);
  dU_rows.setZero(m, n);
  dnu_rows.setZero(m, n);
  row_error.setZero(m);
  row_size.setZero(m);
  balance_factorisation.factor.setZero(m, m);
  balance_factorisation.pivots.setZero(m);
  balance_factorisation.eigenvalues.setZero(m);
  balance_factorisation.gain.setZero(m);
  balance_factorisation.equilibration.setZero(m);
  balance_factorisation.near_null_basis.setZero(m, m);
  balance_factorisation.near_null_weight.setZero(m);
  balance_factorisation.work.setZero(m);
  rhs.setZero(m);
  nu_columns.setZero(columns);
  nu_motors.setZero(columns);
  a.assign(bodies, Vec6::Zero());
  f.assign(bodies, Vec6::Zero());
  constraint_wrench.assign(bodies, Vec6::Zero());
  Ic.assign(bodies, Mat6::Zero());
  friction_scratch = std::make_unique<internal::FrictionScratch>(n, model.nv(), static_cast<int>(bodies), columns);
}

WorkspaceScratch::~WorkspaceScratch() = default;

Workspace::Workspace(const Model& model, int max_constraint_rows)
    : dof_(model.dof()),
      capacity_(max_constraint_rows < 0 ? 0 : max_constraint_rows),
      mimic_rows_(static_cast<int>(model.mimicJoints().size())) {
  const int n = dof_;
  const int nv = model.nv();
  solution.qdd.setZero(nv);
  solution.nu.setZero(0);
  solution.tau_constraint.setZero(nv);
  solution.tau_control.setZero(nv);
  kinematics.q.setZero(model.nq());
  kinematics.qd.setZero(nv);
  H.setZero(nv, nv);
  tau.setZero(nv);

  friction.mu.setZero(n);
  friction.state.assign(static_cast<std::size_t>(n), JointState::Moving);
  friction.tau_friction.setZero(n);
  friction.dqdd_dmu.setZero(nv, n);
  friction.stuck.reserve(static_cast<std::size_t>(n));
  scratch_ = std::make_unique<WorkspaceScratch>(model, columnCapacity(), balanceCapacity());
  default_task_ = std::make_unique<Task>(model);
}

Workspace::~Workspace() = default;
Workspace::Workspace(Workspace&&) noexcept = default;
Workspace& Workspace::operator=(Workspace&&) noexcept = default;

Status Workspace::reserve(const Model& model, int constraint_rows) noexcept {
  if (constraint_rows <= capacity_) return {};
  // The scratch's sizes follow the model's bodies and mimic joints: another model's would not fit.
  if (dof_ != model.dof() || !internal::workspaceFitsModel(model, *this) ||
      mimic_rows_ != static_cast<int>(model.mimicJoints().size()))
    return Status::error(StatusCode::ModelMismatch,
                         "Workspace::reserve: the workspace was made for another model (%d joints, %d mimic joints)",
                         dof_, mimic_rows_);
  const int old_capacity = capacity_;
  try {
    capacity_ = constraint_rows;
    scratch_ = std::make_unique<WorkspaceScratch>(model, columnCapacity(), balanceCapacity());
  } catch (const std::bad_alloc&) {  // the old scratch is kept when the new one cannot be made
    capacity_ = old_capacity;
    return Status::error(StatusCode::WorkspaceTooSmall,
                         "could not make room for %d constraint rows (out of memory); the workspace keeps room for %d",
                         constraint_rows, old_capacity);
  }
  kinematics.stage = KinematicsStage::None;  // they lived in the scratch just replaced
  return {};
}

Workspace::Workspace(const Model& model, const Task& task) : Workspace(model, task.constraintRows()) {
  solution.nu.setZero(task.constraintRows());
}

}  // namespace zwang
