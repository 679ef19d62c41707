/// \file
/// Forward kinematics, frame velocities, accelerations and Jacobians.
/// Velocities and accelerations are classical: [linear of the frame origin;
/// angular], expressed in the frame's axes (Local) or the world axes (World).
#pragma once

#include <Eigen/Geometry>

#include "zwang/status.hpp"
#include "zwang/workspace.hpp"

namespace zwang {

// Every entry point is noexcept and allocates nothing: bad input comes back as
// a Status (docs/errors.md), never as an exception. A frame index outside
// [0, model.frames().size()) is ModelMismatch "frame index F is not a frame of
// this model (it has N frames)"; a workspace made for a model with another
// number of joints is ModelMismatch "workspace was made for N joints, the
// model has M". On an error the output parameter is left unchanged.

/// Poses (and velocities when qd is given) of every body into the workspace.
Status forwardKinematics(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                         const Eigen::Ref<const Eigen::VectorXd>& qd = Eigen::VectorXd()) noexcept;

/// After forwardKinematics (or a solve): the frame's pose in the world.
Status framePose(const Model& model, const Workspace& ws, int frame, Eigen::Isometry3d& pose) noexcept;
/// After forwardKinematics with qd (or a solve): the frame's velocity.
Status frameVelocity(const Model& model, const Workspace& ws, int frame, Expressed expressed, Vec6& velocity) noexcept;
/// After a solve: the frame's true classical acceleration.
Status frameAcceleration(const Model& model, const Workspace& ws, int frame, Expressed expressed,
                         Vec6& acceleration) noexcept;

/// J (6×dof) with frameVelocity = J q̇. Runs forwardKinematics(q) itself.
Status frameJacobian(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q, int frame,
                     Expressed expressed, Eigen::Ref<Eigen::MatrixXd> J) noexcept;

}  // namespace zwang
