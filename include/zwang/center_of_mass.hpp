/// \file
/// Centre of mass and centroidal momentum of the robot or of the subtree below
/// one joint: position, velocity, classical acceleration, the COM Jacobian and
/// the momentum about the COM, all in world axes (Pinocchio's `centerOfMass`,
/// `jacobianCenterOfMass` and `computeCentroidalMomentum`; MuJoCo's
/// `subtree_com`, `subtree_linvel` and `subtree_angmom`).
///
/// Which bodies count: the subtree of `joint` (an index in Model::joints(), as
/// Model::jointIndex gives it) is the child link of that joint and every link
/// below it; kWholeRobot is every moving body, a floating base's root link and
/// the links welded to it included. A fixed base's own mass (body 0: the root
/// link and the links welded to it) is never counted: it does not move and is
/// not in the dynamics (docs/conventions.md, "World"). Rotor inertias are not
/// part of the momentum (a rotor's spin is not a body's motion; Pinocchio and
/// MuJoCo leave armature out alike).
///
/// The calls follow kinematics.hpp: noexcept, no allocation, a Status on bad
/// input, the output left unchanged on an error. The position, velocity,
/// acceleration and momentum read the workspace after the call that computed
/// its kinematics at the state given (Workspace::kinematics): poses for the
/// position, velocities for the velocity and the momentum, a solve's or
/// inverseDynamics' accelerations for the acceleration; otherwise NotComputed
/// naming what to call first. jacobianCenterOfMass computes the poses itself
/// when the workspace does not hold them at q, as frameJacobian does. A joint
/// index outside [0, joints().size()) other than kWholeRobot is
/// ModelMismatch; a subtree without mass (its centre of mass undefined) is
/// BadConfiguration "… has no mass: its centre of mass is undefined".
#pragma once

#include "zwang/status.hpp"
#include "zwang/workspace.hpp"

namespace zwang {

/// The `joint` argument that selects the whole robot rather than a joint's subtree.
constexpr int kWholeRobot = -1;

/// The mass [kg] of the subtree of `joint` (kWholeRobot: of every moving body).
Status subtreeMass(const Model& model, int joint, double& mass) noexcept;

/// The centre of mass c = Σ m_i c_i / Σ m_i, world coordinates [m], at q, after
/// forwardKinematics(q), frameJacobian(q), jointSpaceInertia(q), inverseDynamics
/// or a solve at q.
Status centerOfMass(const Model& model, const Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q, int joint,
                    Vec3& position) noexcept;

/// ċ, world axes [m/s], at (q, q̇), after forwardKinematics(q, qd), inverseDynamics or a solve.
Status centerOfMassVelocity(const Model& model, const Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                            const Eigen::Ref<const Eigen::VectorXd>& qd, int joint, Vec3& velocity) noexcept;

/// c̈, the classical (true, gravity not included) acceleration of the centre of
/// mass in world axes [m/s²], of the motion of the last solve
/// (solveHybridDynamics, solveWithFriction, forwardDynamics) or inverseDynamics
/// at (q, q̇): Σ m_i p̈_i / Σ m_i over the bodies' centres of mass.
Status centerOfMassAcceleration(const Model& model, const Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                                const Eigen::Ref<const Eigen::VectorXd>& qd, int joint, Vec3& acceleration) noexcept;

/// J_com (3 × nv()) with ċ = J_com q̇, world axes: columns in the order of v,
/// a floating base's first in its own velocity coordinates (frameJacobian's
/// columns). Reads the poses when the workspace holds them at q, otherwise runs
/// forwardKinematics(q) first. J of another size is SizeMismatch.
Status jacobianCenterOfMass(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q, int joint,
                            Eigen::Ref<Eigen::MatrixXd> J) noexcept;

/// The centroidal momentum h = [M ċ; L_c] (linear first, as every 6-vector of
/// zwang), world axes: the linear momentum [kg·m/s] and the angular momentum
/// about the subtree's centre of mass [kg·m²/s], Σ (m_i ċ_i; I_c,i ω_i + m_i
/// (c_i − c) × ċ_i) over its bodies. Needs the velocities at (q, q̇), as
/// centerOfMassVelocity. Pinocchio's `computeCentroidalMomentum` gives the same
/// six numbers ([linear; angular] too).
Status centroidalMomentum(const Model& model, const Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                          const Eigen::Ref<const Eigen::VectorXd>& qd, int joint, Vec6& momentum) noexcept;

}  // namespace zwang
