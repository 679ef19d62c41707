// Writes a ChainSpec (a serial chain or a kinematic tree, issue #14) as MJCF text
// for MuJoCo, the oracle of test_mujoco.cpp (our own writer; it does not need
// MuJoCo and no MuJoCo code is in it). The mapping, element by element:
//  - each link is a <body> named as the link, nested in its parent link's body
//    (ChainSpec::parentLink: links[k] for joints[k] unless JointSpec::parent
//    names another), children in joint order; links[0] is a body
//    welded to the world at the identity, so MuJoCo's world is the root link's
//    frame, as zwang's (docs/conventions.md, "World");
//  - the body's pos/quat is the joint origin (xyz, rpy → R = Rz(yaw)Ry(pitch)Rx(roll)
//    as a unit quaternion "w x y z");
//  - a moving joint is a <joint> of the body, named as the joint, at the body
//    origin (pos="0 0 0"): type "hinge" (revolute, continuous) or "slide"
//    (prismatic), its axis in the body (= joint) frame, or "ball" (spherical:
//    qpos = our quaternion, qvel = our ω in the body frame) or "free" (free:
//    qpos ours, qvel's linear part in WORLD axes, support/mujoco_bridge.hpp),
//    armature = the reflected rotor inertia rotor_inertia·gear_ratio² (on each
//    DOF), no damping, stiffness, friction loss or limits (limited="false"); a
//    fixed joint writes no <joint>: the body is welded to its parent. MuJoCo
//    2.2.2 takes free joints on top-level bodies only: a free spec joint must
//    hang at the identity from links[0] of a fixed base, and its body is
//    written at the top level (links[0] is the world's frame);
//  - a link with mass gets <inertial pos=com quat mass diaginertia>: the URDF
//    inertia I (about the COM, axes R = R(inertial_rpy)) diagonalised here,
//    I = V Λ Vᵀ, quat = R V, diaginertia = Λ (not fullinertia: MuJoCo 2.2.2's
//    own diagonalisation is accurate to ~1e-6 only, see mjcf_writer.cpp). A
//    massless link (mass 0, zero inertia) gets no <inertial>;
//  - <compiler angle="radian" inertiafromgeom="false" balanceinertia="false"
//    boundmass="0" boundinertia="0"/>: the inertias are taken as written;
//    <option gravity=… integrator="Euler"> with contacts, the constraint solver,
//    limits, friction loss, equality constraints and passive forces disabled.
// Numbers are printed with %.17g (read back as the same doubles).
#pragma once

#include <string>

#include <Eigen/Core>

#include "support/chain_spec.hpp"
#include "support/floating_reference.hpp"

namespace zwang::testing {

// The MJCF document for `spec` under `gravity` (world = root link axes, m/s²).
// Throws std::invalid_argument when ChainSpec::check does (a parent after its
// child among others) or, naming the link, when a moving joint's child link has
// no mass (MuJoCo refuses a moving body without mass; the random trees and
// chains give every link mass), or when a free joint is not where MuJoCo takes
// it (above). Any tree, depth first or not: MuJoCo numbers
// the dofs depth first, children in joint order, so a caller maps vectors by
// joint name.
std::string toMjcf(const ChainSpec& spec, const Eigen::Vector3d& gravity);

// The same with links[0] floating (floating_reference.hpp): the root body is
// attached to the world by
//  - Free: a <freejoint name=kMjcfFreeJoint/> (qpos = [p; quat w x y z] as
//    ours, but qvel = [ṗ in world axes; ω in body axes] and qacc its rate,
//    qfrc_* = [force in world axes; moment about the body origin in body
//    axes]; support/mujoco_bridge.hpp converts), the body at the identity;
//  - Planar: the body at the plane pose (pos, quat), then three joints at the
//    body origin in this order: slide "1 0 0" (kMjcfPlanarX), slide "0 1 0"
//    (kMjcfPlanarY), hinge "0 0 1" (kMjcfPlanarYaw), so the pose is
//    P ∘ translate(x, y, 0) ∘ rot_z(ψ) and qpos, qvel, qacc are ours;
//  - Fixed: exactly toMjcf(spec, gravity).
// No armature, damping, limits or friction on the base joints. Throws
// std::invalid_argument when a floating root link has no mass or a spec joint
// has one of the base joints' names.
inline constexpr const char* kMjcfFreeJoint = "floating_base_free";
inline constexpr const char* kMjcfPlanarX = "floating_base_x";
inline constexpr const char* kMjcfPlanarY = "floating_base_y";
inline constexpr const char* kMjcfPlanarYaw = "floating_base_yaw";
std::string toMjcf(const ChainSpec& spec, const Eigen::Vector3d& gravity, const FloatingBase& base);

// What toMjcf writes beyond its default (the default writes none of it).
struct MjcfWriteOptions {
  // The joints' data as the URDF writer writes it, for loaders to compare (test_mjcf): limited="true" and
  // range="lower upper" on revolute and prismatic joints with lower < upper (continuous and the others:
  // limited="false"), frictionloss = JointSpec::friction, damping = JointSpec::damping; and in <option> only
  // contacts disabled (limits, friction loss, equalities and passive forces enabled, since they are the data).
  bool joint_data = false;
};
std::string toMjcf(const ChainSpec& spec, const Eigen::Vector3d& gravity, const FloatingBase& base,
                   const MjcfWriteOptions& options);

}  // namespace zwang::testing
