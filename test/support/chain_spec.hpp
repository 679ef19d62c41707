// A plain, URDF-shaped description of a serial chain, shared by the test
// references (random generator, URDF writer, dense KKT reference, KDL bridge).
// It deliberately does not use the zwang model classes: the references must
// stay independent of the code they test.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace zwang::testing {

// One URDF <link>. The inertia is about the COM, in the inertial frame whose
// pose in the link frame is (com, inertial_rpy) — exactly URDF's <inertial>.
// mass 0 with a zero inertia is a massless link (written without <inertial>).
struct LinkSpec {
  std::string name;
  double mass = 0.0;
  Eigen::Vector3d com = Eigen::Vector3d::Zero();
  Eigen::Vector3d inertial_rpy = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
};

// One URDF <joint>. Semantics (URDF, docs/conventions.md, "Joints, links, frames"):
//  - (xyz, rpy) is the pose of the joint frame in the parent link frame, with
//    fixed-axis roll-pitch-yaw: R = Rz(yaw)·Ry(pitch)·Rx(roll);
//  - the child link frame is the joint frame after the joint motion: a rotation
//    by q about `axis` (revolute, continuous) or a translation by q along
//    `axis` (prismatic); `axis` is a unit vector in the joint frame;
//  - beyond URDF, two multi-DOF kinds (issue #25), `axis` unused:
//    "spherical" (MJCF's ball): q = [w, x, y, z], the unit quaternion of the
//    child's orientation in the joint frame, v = ω in the child frame (nq = 4, nv = 3);
//    "free": q = [p; w, x, y, z], the child origin in the joint frame and its
//    orientation, v = [v; ω], the origin's velocity and the angular velocity,
//    both in the child frame (nq = 7, nv = 6); "planar": q = [x, y, ψ], the child origin in the joint frame's
//    xy plane and the yaw about its z, v = q̇, rates along the JOINT frame's axes (nq = nv = 3); none has
//    limits or a mimic;
//  - the reflected rotor inertia on the joint is rotor_inertia·gear_ratio².
struct JointSpec {
  std::string name;
  std::string type = "revolute";  // "revolute", "continuous", "prismatic", "spherical", "planar", "free", "fixed"
  Eigen::Vector3d xyz = Eigen::Vector3d::Zero();
  Eigen::Vector3d rpy = Eigen::Vector3d::Zero();
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();
  double lower = 0.0, upper = 0.0, effort = 0.0, velocity = 0.0;  // <limit>
  double friction = 0.0, damping = 0.0;                           // <dynamics>
  double rotor_inertia = 0.0;                                     // <drake:rotor_inertia>; 0: no <transmission>
  double gear_ratio = 1.0;                                        // <drake:gear_ratio>
  // Index into ChainSpec::links of the parent link; −1: links[k] for joints[k]
  // (a chain). The child of joints[k] is always links[k + 1].
  int parent = -1;
  // URDF <mimic joint= multiplier= offset=>: this joint follows the moving joint
  // named `mimic` (empty: independent), q = mimic_multiplier·q_mimic + mimic_offset.
  // The leader may itself be a mimic joint (ChainSpec::mimicLaws resolves it).
  std::string mimic;
  double mimic_multiplier = 1.0, mimic_offset = 0.0;

  bool isFixed() const { return type == "fixed"; }
  bool isPrismatic() const { return type == "prismatic"; }
  bool isSpherical() const { return type == "spherical"; }
  bool isFree() const { return type == "free"; }
  bool isPlanar() const { return type == "planar"; }
  // Entries of q and of v (q̇, τ, q̈) the joint contributes: 0 fixed, 4 and 3 spherical, 3 and 3 planar, 7 and 6
  // free, else 1.
  int nq() const { return isFixed() ? 0 : isSpherical() ? 4 : isPlanar() ? 3 : isFree() ? 7 : 1; }
  int nv() const { return isFixed() ? 0 : isSpherical() ? 3 : isPlanar() ? 3 : isFree() ? 6 : 1; }
  bool isMimic() const { return !mimic.empty(); }
  // rotor_inertia · gear_ratio² (docs/conventions.md, "Joints, links, frames"); 0 for fixed joints.
  double reflectedInertia() const { return isFixed() ? 0.0 : rotor_inertia * gear_ratio * gear_ratio; }
};

// A mimic joint's law resolved to its first independent leader, in dof
// indices: q[joint] = multiplier·q[leader] + offset (so q̇ and q̈ scale by
// multiplier). Composed along a chain of mimics: m → k → l with
// q_m = a·q_k + b, q_k = a'·q_l + b' gives q_m = a·a'·q_l + a·b' + b.
struct MimicLaw {
  int joint = -1;   // the mimic joint (dof index)
  int leader = -1;  // its first independent leader (dof index)
  double multiplier = 1.0, offset = 0.0;
};

// A serial chain or a tree: joints[k] connects the parent link
// links[parentLink(k)] (links[k] unless the joint names another) to the child
// links[k + 1], so links.size() == joints.size() + 1 and links[0] is the fixed
// base link. A parent always comes before its child; a tree is depth first
// when each parent is on the path from links[k] to the base (isDepthFirst).
struct ChainSpec {
  std::string name = "chain";
  std::vector<LinkSpec> links;
  std::vector<JointSpec> joints;

  // Length of v (q̇, τ, q̈): Σ nv of the moving joints; their number when every one has one DOF.
  int dof() const;
  // Length of q: Σ nq of the moving joints.
  int nq() const;
  // True when some moving joint has more than one DOF (spherical, free).
  bool hasMultiDofJoints() const;
  // Index into `links` of joints[k]'s parent link.
  int parentLink(std::size_t k) const { return joints[k].parent < 0 ? static_cast<int>(k) : joints[k].parent; }
  // True when no joint names a parent other than the previous link.
  bool isChain() const;
  // Indices into `joints` of the non-fixed joints, in chain order: the order of
  // their coordinates in q and v (the k-th entry's position is q(k) when every
  // joint has one DOF).
  std::vector<int> movingJoints() const;
  // Index into `links` of the link with this name; throws std::invalid_argument
  // naming the link when there is none.
  int linkIndex(const std::string& name) const;
  // Throws std::invalid_argument when the sizes or joint types are inconsistent,
  // an axis is not unit, or a name repeats. (A mimic naming a joint that is
  // not a moving one, or itself, is left to the model builder to refuse, as
  // is a cycle: the error tests need such specs.)
  void check() const;
  // The dof index of each mimic joint's direct leader (−1: independent), per dof.
  std::vector<int> directLeaders() const;
  // Every mimic joint's law resolved to its first independent leader, in dof
  // order; std::invalid_argument for a cycle or a leader that is not a moving joint.
  std::vector<MimicLaw> mimicLaws() const;
  // True when some moving joint is a mimic joint.
  bool hasMimic() const;
  // Set every mimic joint's q and q̇ from its resolved leader (q̇ may be empty).
  void followMimicLaws(Eigen::VectorXd& q, Eigen::VectorXd& qd) const;
};

// R = Rz(yaw)·Ry(pitch)·Rx(roll) for rpy = (roll, pitch, yaw) (URDF).
Eigen::Matrix3d rpyToMatrix(const Eigen::Vector3d& rpy);

// The single-joint arm of docs/theory.md, "The reference cases": revolute joint about z at the
// base origin, a 1 m link along x of mass 1 kg with its COM at 0.5 m and
// I_zz = 2 kg·m² at the COM (2.25 kg·m² about the joint), breakaway friction 10 N·m.
ChainSpec oneDofArm();

}  // namespace zwang::testing
