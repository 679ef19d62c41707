// A bridge to KDL, the oracle for the original Popov–Vereshchagin solver.
//
// Builds a KDL::Chain from a ChainSpec the way kdl_parser does, and wraps
// KDL::ChainHdSolver_Vereshchagin and KDL::ChainIdSolver_RNE behind OUR
// conventions (docs/conventions.md; the same DynamicsInput as the dense
// reference). Every conversion between the two is made, and explained, in
// kdl_bridge.cpp; test_references.cpp establishes each one against the dense
// reference.
#pragma once

#include <vector>

#include <Eigen/Core>
#include <kdl/chain.hpp>

#include "support/chain_spec.hpp"
#include "support/dense_reference.hpp"

namespace zwang::testing {

// One KDL::Segment per URDF joint, named after the child link:
//  - joint origin F = (xyz, rpy) is the segment's f_tip, and the KDL joint is
//    placed at F.p with axis F.M·axis (expressed in the parent frame), so that
//    segment.pose(q) = parent→child link frame (this is what kdl_parser does);
//  - KDL::Joint's `inertia` = the reflected rotor inertia rotor·ratio²;
//  - fixed URDF joints become Joint::Fixed (= Joint::None) segments;
//  - the segment's RigidBodyInertia is the child link's, in the child link
//    frame (= the segment tip frame).
KDL::Chain toKdlChain(const ChainSpec& spec);

bool hasFixedJoints(const ChainSpec& spec);

// World poses of every link (links.size() entries) by KDL::ChainFkSolverPos_recursive.
std::vector<Eigen::Isometry3d> kdlLinkPoses(const ChainSpec& spec, const Eigen::VectorXd& q);

struct KdlHybridResult {
  // --- In our conventions -------------------------------------------------
  Eigen::VectorXd qdd;
  Eigen::VectorXd nu;     // our sign (docs/solver.md, "Sign of ν"): the wrench +A ν acts on the link (= −ν_KDL)
  Eigen::VectorXd tau_c;  // physical constraint torques J_tipᵀ (A ν), J from KDL
  std::vector<Vector6d> acc_world;  // classical [p̈; ω̇] of every link origin, world axes
  // --- KDL's own inputs and outputs, as passed / returned ---------------------
  Matrix6Xd alpha;                         // unit constraint forces, base axes, at the tip origin
  Eigen::VectorXd beta;                    // set points on KDL's spatial acceleration incl. −g
  Vector6d root_acc = Vector6d::Zero();    // [−g; 0]
  std::vector<Vector6d> f_ext;             // per segment, base axes, at the segment tip
  Eigen::VectorXd nu_kdl;                  // getContraintForceMagnitude
  Eigen::VectorXd constraint_torques_kdl;  // CartToJnt's constraint_torques: Sᵀ (articulated E) ν
  Eigen::VectorXd total_torques_kdl;       // getTotalTorque
  std::vector<Vector6d> x_dotdot_kdl;      // getTransformedLinkAcceleration (ns+1 entries, [0] = root)
  Eigen::MatrixXd jacobian_tip;            // ChainJntToJacSolver: base axes, tip origin, [v; ω] rows
  int error = 0;                           // CartToJnt's return code
};

// KDL's Vereshchagin solver on our problem. Accepts at most one constraint, on
// the LAST link. Throws std::invalid_argument for anything KDL cannot represent:
// a chain with fixed joints (KDL's Vereshchagin divides by the zero D of a fixed
// segment; see kdl_bridge.cpp), a constraint on another link, or more than 6 rows.
// With no constraint rows KDL is given one all-zero column (its documented way
// to run as a plain ABA), and nu / nu_kdl are empty.
KdlHybridResult kdlHybridDynamics(const ChainSpec& spec, const DynamicsInput& input);

// KDL::ChainIdSolver_RNE: τ = H q̈ + C with our gravity vector and wrenches.
// Fixed joints are fine here.
Eigen::VectorXd kdlInverseDynamics(const ChainSpec& spec, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                                   const Eigen::VectorXd& qdd, const Eigen::Vector3d& gravity,
                                   const std::vector<WrenchInput>& wrenches = {});

// Equivalent chain without fixed joints: every link behind a fixed joint is
// merged (inertia lumped) into its moving parent, and the fixed placement is
// folded into the next joint's origin. Links behind fixed joints at the base
// are merged into the base. The last link must be the child of a moving joint
// so that the tip frame survives; otherwise throws std::invalid_argument.
// Link names of the surviving links are kept.
ChainSpec mergeFixedJoints(const ChainSpec& spec);

}  // namespace zwang::testing
