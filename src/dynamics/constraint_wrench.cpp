// The wrench a task's constraints exert on one frame (constraintWrench,
// kinematics.hpp): a query after the solve, not a stage of it, so a solve pays
// nothing for it and its stages stay as they are. It reads the ν the solve
// published (Solution::nu, in the task's row order) and the task's constraints
// as the solver laid them out (Task::Layout), turning each A to world axes the
// way constraintsInBodyForm and relativeConstraintInBodyForm do, so the
// wrench is the force the sweeps applied (docs/solver.md, "Constraint wrenches").
#include <cstddef>

#include "dynamics/checks.hpp"
#include "dynamics/sweeps.hpp"
#include "dynamics/task_solver_order.hpp"
#include "zwang/kinematics.hpp"

namespace zwang {

namespace {

using ConstraintGroup = TaskSolverOrder::ConstraintGroup;

// The rotation taking the components of g's columns to world axes: the
// frame's axes (Local), the reference's (Reference, a relative constraint
// only: for an absolute one the reference is the world) or the world's.
Mat3 columnAxesToWorld(const Model& model, const Workspace& ws, const ConstraintGroup& g) {
  if (g.expressed == Expressed::Local) return internal::framePlacementInBase(model, ws, g.frame).E.transpose();
  if (g.expressed == Expressed::Reference && g.reference >= 0)
    return internal::framePlacementInBase(model, ws, g.reference).E.transpose();
  return Mat3::Identity();
}

// Σ A ν of one constraint (its group on the constrained frame's side) in world
// axes, at the constrained frame's origin.
Vec6 groupWrenchWorld(const Model& model, const Workspace& ws, const ConstraintGroup& g) {
  const Mat3 R = columnAxesToWorld(model, ws, g);
  const Vec6 w_axes = g.A * ws.solution.nu.segment(g.first_row, g.rows);
  Vec6 w;
  w << R * w_axes.head<3>(), R * w_axes.tail<3>();
  return w;
}

Status checkWrenchQuery(const Model& model, const Workspace& ws, const Task& task,
                        const Eigen::Ref<const Eigen::VectorXd>& q, int frame) noexcept {
  const int frames = static_cast<int>(model.frames().size());
  if (frame < 0 || frame >= frames)
    return Status::error(StatusCode::ModelMismatch, "frame index %d is not a frame of this model (it has %d frames)",
                         frame, frames);
  if (task.modelDof() != model.dof() || task.modelFrames() != frames)
    return Status::error(StatusCode::ModelMismatch, "task was made for another model (%d joints, %d frames)",
                         task.modelDof(), task.modelFrames());
  if (Status s =
          internal::checkKinematicsHeld(model, ws, q, Eigen::VectorXd(), KinematicsStage::Poses, "constraintWrench");
      !s)
    return s;
  if (ws.solution.nu.size() != task.constraintRows())
    return Status::error(StatusCode::NotComputed,
                         "constraintWrench: the workspace's solution.nu has %ld entries, the task has %d constraint "
                         "rows; call solveHybridDynamics or solveWithFriction with this task first",
                         static_cast<long>(ws.solution.nu.size()), task.constraintRows());
  return {};
}

}  // namespace

Status constraintWrench(const Model& model, const Workspace& ws, const Task& task,
                        const Eigen::Ref<const Eigen::VectorXd>& q, int frame, Expressed expressed,
                        Vec6& wrench) noexcept {
  if (Status s = checkWrenchQuery(model, ws, task, q, frame); !s) return s;
  const Transform X = internal::framePlacementInBase(model, ws, frame);
  Vec6 world = Vec6::Zero();
  // Each constraint once, from its constrained frame's side (a relative
  // constraint's reference side holds the same A and rows). Joint and mimic
  // pieces (dof ≥ 0) act along a joint, between two bodies: no frame's.
  for (const ConstraintGroup& g : solverOrder(task).groups()) {
    if (g.dof >= 0 || g.reference_side) continue;
    if (g.frame != frame && g.reference != frame) continue;
    const Vec6 w = groupWrenchWorld(model, ws, g);  // at the constrained frame's origin p_a
    if (g.frame == frame) {
      world += w;
    } else {  // the reference takes −A ν, still acting at p_a: its moment about p_r shifts
      const Vec3 d = internal::framePlacementInBase(model, ws, g.frame).r - X.r;  // p_a − p_r
      world.head<3>() -= w.head<3>();
      world.tail<3>() -= w.tail<3>() + d.cross(w.head<3>());
    }
  }
  if (expressed == Expressed::Local) {
    wrench << X.E * world.head<3>(), X.E * world.tail<3>();
  } else {
    wrench = world;
  }
  return {};
}

}  // namespace zwang
