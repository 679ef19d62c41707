// Forward kinematics, frame velocities, accelerations and Jacobians.
// Velocities and accelerations are classical: [linear of the frame origin;
// angular], expressed in the frame's axes (Local) or the world axes (World).
#pragma once

#include <Eigen/Geometry>

#include "zwang/status.hpp"
#include "zwang/workspace.hpp"

namespace zwang {

// Poses (and velocities when qd is given) of every body into the workspace.
Status forwardKinematics(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                         const Eigen::Ref<const Eigen::VectorXd>& qd = Eigen::VectorXd());

// After forwardKinematics (or a solve): the frame's pose in the world.
Eigen::Isometry3d framePose(const Model& model, const Workspace& ws, int frame);
// After forwardKinematics with qd (or a solve): the frame's velocity.
Vec6 frameVelocity(const Model& model, const Workspace& ws, int frame, Expressed expressed = Expressed::Local);
// After a solve: the frame's true classical acceleration.
Vec6 frameAcceleration(const Model& model, const Workspace& ws, int frame, Expressed expressed = Expressed::Local);

// J (6×dof) with frameVelocity = J q̇. Runs forwardKinematics(q) itself.
Status frameJacobian(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q, int frame,
                     Expressed expressed, Eigen::Ref<Eigen::MatrixXd> J);

}  // namespace zwang
