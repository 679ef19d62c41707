/// \file
/// Forward kinematics, frame velocities, accelerations and Jacobians.
/// Velocities and accelerations are classical: [linear of the frame origin;
/// angular], expressed in the frame's axes (Local) or the world axes (World).
///
/// Fixed and floating bases alike (docs/conventions.md, "Floating base"): q has
/// Model::nq() entries and q̇ Model::nv(), the base's coordinates first; a
/// floating base's pose and velocity move every frame, the base link's too.
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
// model has M" (or for the same joints on another base: "… nv = …"). q must
// pass checkConfiguration (nq() entries, finite, a free base's quaternion unit
// to 1e-6); q̇ has nv() finite entries. On an error the output parameter is
// left unchanged.
//
// framePose, frameVelocity and frameAcceleration read what the last call that
// computes kinematics left in the workspace (Workspace::kinematics, whose
// comment lists what each call leaves), and take the state the caller means:
// the workspace records the q (and q̇) those results were computed at, so a
// query after forwardKinematics(model, ws, q, qd) or a solve at (q, qd) only
// compares the state (nq + nv entries) and reads. A query for another state,
// another Model object, or more than the last call computed returns
// NotComputed naming what to call first, e.g. "framePose: the workspace holds
// kinematics at another q (q[3] = 0.5 held, 0.25 given); call
// forwardKinematics(model, ws, q) first" or "frameAcceleration: the workspace
// holds poses and velocities only (the last call computed no accelerations);
// call solveHybridDynamics, solveWithFriction or inverseDynamics first".
// States are compared entry by entry, exactly: pass the same vectors.

/// Poses (and velocities when qd is given) of every body into the workspace:
/// q has nq() entries, qd nv(). Without qd the workspace holds poses only
/// (frameVelocity is then NotComputed; it does not read the state as at rest).
Status forwardKinematics(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                         const Eigen::Ref<const Eigen::VectorXd>& qd = Eigen::VectorXd()) noexcept;

/// The frame's pose in the world at q, after forwardKinematics(q), frameJacobian(q),
/// jointSpaceInertia(q), inverseDynamics or a solve at q.
Status framePose(const Model& model, const Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q, int frame,
                 Eigen::Isometry3d& pose) noexcept;
/// The frame's velocity at (q, q̇), after forwardKinematics(q, qd), inverseDynamics or a solve at (q, q̇).
Status frameVelocity(const Model& model, const Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                     const Eigen::Ref<const Eigen::VectorXd>& qd, int frame, Expressed expressed,
                     Vec6& velocity) noexcept;
/// After a solve (solveHybridDynamics, solveWithFriction, forwardDynamics) or
/// inverseDynamics at (q, q̇): the frame's true classical acceleration of that
/// call's motion (gravity's shift of the sweep removed).
Status frameAcceleration(const Model& model, const Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                         const Eigen::Ref<const Eigen::VectorXd>& qd, int frame, Expressed expressed,
                         Vec6& acceleration) noexcept;

/// After a solve (solveHybridDynamics, solveWithFriction) at q with `task`:
/// the 6-D wrench [f; n] the task's constraints exert on `frame`, at the
/// frame's origin, in its axes (Local) or the world's (World; Reference is
/// World too), from the ν the workspace holds (Solution::nu, read as it is,
/// in the task's row order) and the poses at q. It is the sum over the task's
/// constraints on the frame of A ν: an absolute constraint's, a contact's
/// (the ground's force on the robot) and a relative constraint's +A ν on its
/// frame; a frame that is the reference of a relative constraint gets −A ν,
/// the force acting at the constrained frame's origin p_a, so that its moment
/// about the reference's origin p_r is −(n + (p_a − p_r) × f). Joint rows and
/// mimic couplings act along joints, not on frames: they are left out. A frame
/// the task does not constrain gets zero. ModelMismatch for a task made for
/// another model; NotComputed when solution.nu does not have the task's rows
/// (no solve with it yet) or the workspace holds no poses at q
/// (docs/solver.md, "Constraint wrenches").
Status constraintWrench(const Model& model, const Workspace& ws, const Task& task,
                        const Eigen::Ref<const Eigen::VectorXd>& q, int frame, Expressed expressed,
                        Vec6& wrench) noexcept;

/// J (6 × nv()) with frameVelocity = J q̇. Reads the poses when the workspace
/// holds them at q (after forwardKinematics(q) or a solve at q: its results are
/// kept); otherwise runs forwardKinematics(q) first, and the workspace then
/// holds the poses at q only.
/// A floating base's columns come first, in the user's velocity coordinates:
/// d(frame velocity)/d v_base, for a free base v_B = [v; ω] in base axes, for
/// a planar one [ẋ, ẏ, ψ̇] in the plane's axes; then one column per joint, zero
/// for the joints that do not move the frame. J of the wrong size is
/// SizeMismatch "Jacobian output is 6x5, expected 6x13 (nv = 6 base velocity
/// coordinates + 7 joints)" ("expected 6x7" on a fixed base).
Status frameJacobian(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q, int frame,
                     Expressed expressed, Eigen::Ref<Eigen::MatrixXd> J) noexcept;

}  // namespace zwang
