// solveHybridDynamics: the stages of Algorithm 1 in order
// (src/dynamics/popov_vereshchagin.cpp holds each stage, next to the report's lines).
#include "zwang/hybrid_dynamics.hpp"

#include "dynamics/popov_vereshchagin.hpp"

namespace zwang {

Status solveHybridDynamics(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                           const Eigen::Ref<const Eigen::VectorXd>& qd, const Eigen::Ref<const Eigen::VectorXd>& tau,
                           const Task& task) noexcept {
  using namespace internal;
  ws.kinematics.stage = KinematicsStage::None;  // until the sweeps below compute them
  if (Status s = checkSolveInputs(model, task, q, qd, tau, ws); !s) return s;
  if (Status s = roomForTask(model, task, ws); !s) return s;  // allocates only for more rows than ever before
  WorkspaceScratch& sw = scratchOf(ws);
  bindTaskModes(task, sw);  // the sweeps read the DOF modes from here
  Solution& out = ws.solution;
  jointsOutsideLimits(model, q, out);                              // a warning: solved as given
  outwardSweep(model, task, q, qd, ws);                            // lines 2–10
  if (Status s = inwardSweep(model, task, tau, ws); !s) return s;  // lines 11–22
  balance(task, ws);                                               // lines 23–25
  outwardAccelerations(model, task, ws, out.qdd);                  // lines 26–30
  ws.kinematics.stage = KinematicsStage::Accelerations;
  out.base_acceleration_world = baseClassicalAcceleration(model, ws);
  taskResidual(task, ws);  // how well Aᵀ Ẍ = b is met
  publishNu(task, ws);
  constraintTorques(model, task, ws, sw.nu_columns.head(task.solverColumns()), out.tau_constraint);
  prescribedTorques(model, task, ws, sw.nu_columns.head(task.solverColumns()), out.qdd, tau, out.tau_constraint);
  controlTorques(model, tau, out);  // the leaders carry their mimic joints' torques
  out.gauss = gaussFunction(model, task, out.qdd, tau, ws);
  return {};
}

// The unconstrained solve is the same stages with no task rows (the mimic
// couplings, which the model carries, stay).
Status forwardDynamics(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                       const Eigen::Ref<const Eigen::VectorXd>& qd, const Eigen::Ref<const Eigen::VectorXd>& tau,
                       const Task& task) noexcept {
  if (task.constraintRows() != 0) {
    ws.kinematics.stage = KinematicsStage::None;  // as any call that fails its input checks
    return Status::error(StatusCode::BadOption,
                         "forwardDynamics: the task has %d constraint rows; forwardDynamics is the unconstrained "
                         "solve (gravity and wrenches only): use solveHybridDynamics to meet them",
                         task.constraintRows());
  }
  return solveHybridDynamics(model, ws, q, qd, tau, task);
}

Status forwardDynamics(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                       const Eigen::Ref<const Eigen::VectorXd>& qd,
                       const Eigen::Ref<const Eigen::VectorXd>& tau) noexcept {
  return solveHybridDynamics(model, ws, q, qd, tau, ws.defaultTask());
}

}  // namespace zwang
