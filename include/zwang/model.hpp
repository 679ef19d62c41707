/// \file
/// The robot model: a kinematic tree of joints of any type (revolute,
/// continuous, prismatic, spherical, planar, free) with rigid bodies, immutable
/// once built and safe to share between threads. Scratch memory lives in a
/// Workspace (workspace.hpp); a Model never changes during a solve.
///
/// Joints (docs/architecture.md, "Joint types"): joints() lists the joints
/// below the root in depth-first order; a floating base is the root's joint
/// (rootJoint(), a free or planar joint to the world). Each joint has nq()
/// configuration and nv() velocity coordinates, at q_index and v_index in the
/// model's q (nq() entries) and q̇, τ, q̈ (nv() entries), the root's first.
///
/// Bodies, as the sweeps see them: one per degree of freedom (DOF). Body 0 is
/// the world (a fixed base: the root link and what is welded to it); body
/// k + 1 moves relative to its parent by DOF k (entry k of v), a rotation
/// about or a translation along one axis (dofs()). A joint of nv DOFs moves nv
/// bodies in a row: the first nv − 1 are its intermediate bodies, with no
/// inertia and no frame, the last is the child link. Eliminating a joint's
/// DOFs one at a time in the sweeps is exactly the block step with its nv × nv
/// D (the intermediate bodies carry nothing: the pivots are the LDLᵀ factor of
/// D), so the sweeps never look at a joint's type. Bodies are in depth-first
/// order: every body comes after its parent, and the bodies of a subtree are
/// the contiguous range [b, subtreeEnd(b)). The sweeps rely on that range: the
/// constraints a body feels are those on its subtree, a contiguous block of
/// columns (the task's solver order, docs/solver.md). Fixed URDF joints are merged into their parent
/// body at load time, but every link stays addressable as a Frame attached to
/// a body.
#pragma once

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "zwang/spatial/cross.hpp"
#include "zwang/spatial/inertia.hpp"

namespace zwang {

using spatial::RigidInertia;
using spatial::Transform;

/// Thrown by model construction and URDF loading (never by a solve).
class ModelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// How the base (the root link and the links welded to it: body 0 on a fixed
/// base, baseBody() on a floating one) is attached to the world
/// (docs/conventions.md, "Floating base").
///   Fixed  : bolted down (no base coordinates);
///   Free   : a free-flyer, unactuated: q_base = [x, y, z, q_w, q_x, q_y, q_z]
///            (the base origin in the world, the unit quaternion of the base's
///            orientation), v_base = [v; ω], the velocity of the base origin and
///            the angular velocity, both in base axes (Pinocchio's convention);
///   Planar : a mobile base moving in a plane, unactuated: q_base = [x, y, ψ],
///            v_base = [ẋ, ẏ, ψ̇] in the plane's axes (the world's, unless the
///            base placement turns the plane), ψ the yaw about the plane's normal.
enum class BaseType { Fixed, Free, Planar };
/// "fixed", "free" or "planar".
const char* toString(BaseType type);

/// The kinds of moving joint (docs/conventions.md, "Joint types"):
///   Revolute, Continuous : q = angle about `axis` [rad], v = its rate (nq = nv = 1);
///   Prismatic            : q = displacement along `axis` [m] (nq = nv = 1);
///   Spherical            : q = [q_w, q_x, q_y, q_z], the unit quaternion of the
///                          child's orientation in the joint frame (w first),
///                          v = ω, the angular velocity in the child frame
///                          (nq = 4, nv = 3; Pinocchio's JointModelSpherical and
///                          MuJoCo's `ball` alike, up to Pinocchio's x y z w order);
///   Planar               : q = [x, y, ψ], v = [ẋ, ẏ, ψ̇]: the child origin in the
///                          joint frame's xy plane and the yaw about its z, rates
///                          in the joint frame's axes (nq = nv = 3);
///   Free                 : q = [x, y, z, q_w, q_x, q_y, q_z], the child origin in
///                          the joint frame and its orientation's unit quaternion,
///                          v = [v; ω], the origin's velocity and the angular
///                          velocity in the child frame (nq = 7, nv = 6; as
///                          Pinocchio's free-flyer; MuJoCo's `free` has v in world axes).
enum class JointType { Revolute, Continuous, Prismatic, Spherical, Planar, Free };
/// The name of a joint type: "revolute", "continuous", "prismatic" (as URDF
/// names them), "spherical", "planar" or "free".
const char* toString(JointType type);
/// Entries of q for a joint of this type: 1, 1, 1, 4, 3, 7.
constexpr int configurationSize(JointType type) {
  return type == JointType::Spherical ? 4 : type == JointType::Planar ? 3 : type == JointType::Free ? 7 : 1;
}
/// Entries of v (q̇, τ, q̈) for a joint of this type: 1, 1, 1, 3, 3, 6.
constexpr int velocitySize(JointType type) {
  return type == JointType::Spherical || type == JointType::Planar ? 3 : type == JointType::Free ? 6 : 1;
}

/// A joint that follows another (URDF `<mimic>`): q = multiplier·q_leader +
/// offset, so q̇ = multiplier·q̇_leader and q̈ = multiplier·q̈_leader. The
/// mechanism that couples them (gears, a linkage, a tendon) supplies the
/// coupling torque; the leader's motor carries the rest (docs/solver.md, "Mimic joints").
/// Both joints have one DOF.
struct Mimic {
  int leader = -1;          ///< the joint followed (never itself a mimic joint once built); −1: independent
  double multiplier = 1.0;  ///< a in q = a·q_leader + b
  double offset = 0.0;      ///< b [rad or m]
  /// True when the joint follows a leader.
  bool active() const { return leader >= 0; }
};

/// One moving joint of the tree: its type, axis and placement, drive (rotor
/// inertia), friction and limits. Rotor inertia and friction apply to each of
/// its DOFs alike (MuJoCo's `armature` and `frictionloss`: a box per DOF);
/// position limits only to one-DOF joints.
struct Joint {
  std::string name;                      ///< unique among the model's joints
  JointType type = JointType::Revolute;  ///< see JointType
  // The sweeps read type, the indices, axis and placement of every joint: kept
  // together, they span three cache lines, not four.
  /// First entry of the joint's coordinates in the model's q (set by ModelBuilder::build).
  int q_index = -1;
  /// First entry of its velocity coordinates in q̇, τ and q̈; its DOFs move
  /// bodies v_index + 1 … v_index + nv() (set by ModelBuilder::build).
  int v_index = -1;
  Vec3 axis = Vec3::UnitZ();        ///< unit vector in the joint (= child body) frame (one-DOF joints)
  Transform placement;              ///< ʲX_parent: parent body frame → joint frame at q = 0
  double rotor_inertia = 0.0;       ///< d_j, reflected armature inertia per DOF [kg·m² or kg]
  double breakaway_friction = 0.0;  ///< f_j ≥ 0, static friction bound per DOF
  double kinetic_friction = 0.0;    ///< f_c,j ≥ 0, Coulomb friction while moving
  double viscous_friction = 0.0;    ///< b_j ≥ 0, viscous friction coefficient (URDF `dynamics damping`)
  double lower = -std::numeric_limits<double>::infinity();  ///< position limits: lower [rad or m]
  double upper = std::numeric_limits<double>::infinity();   ///< position limits: upper [rad or m]
  /// Largest torque [N·m] or force [N] (URDF `<limit effort>`).
  double effort_limit = std::numeric_limits<double>::infinity();
  /// Largest speed [rad/s or m/s] (URDF `<limit velocity>`).
  double velocity_limit = std::numeric_limits<double>::infinity();
  /// The leader this joint follows, if it is a mimic joint (chains of mimic
  /// joints are resolved to the first leader when the model is built).
  Mimic mimic;

  /// Entries of q: configurationSize(type).
  int nq() const { return configurationSize(type); }
  /// Entries of v: velocitySize(type).
  int nv() const { return velocitySize(type); }
  /// The child body: the body its last DOF moves.
  int body() const { return v_index + nv(); }
  /// True for revolute and continuous joints.
  bool isRevolute() const { return type == JointType::Revolute || type == JointType::Continuous; }
  /// Motion subspace S (6-vector, linear first) of a one-DOF joint in the child body frame.
  Vec6 motionSubspace() const {
    return isRevolute() ? spatial::stack(Vec3::Zero(), axis) : spatial::stack(axis, Vec3::Zero());
  }
  /// ʲX_parent(q) = X_J(q) · X_T of a one-DOF joint: the placement followed by the joint motion.
  Transform transform(double q) const;
  /// ʲX_parent(q) of any joint, from its nq() coordinates (a quaternion already
  /// of unit norm: checkConfiguration).
  Transform transform(const double* q) const;
};

ZWANG_ALWAYS_INLINE Transform Joint::transform(double q) const {
  // X_J(q): the child frame is the joint frame rotated by q about (or shifted by
  // q along) the axis; then ʲX_parent = X_J · X_T with X_T = placement.
  if (type == JointType::Prismatic) return {placement.E, placement.r + placement.E.transpose() * (q * axis)};
  // X_J = rotation(R), R = c·1 + s·[a]× + (1 − c)·a aᵀ (Rodrigues), so
  // E = Rᵀ E_T = c·E_T − s·(a × E_T) + (1 − c)·a (aᵀ E_T), column by column.
  const double s = std::sin(q), c = std::cos(q);
  Transform X;
  for (int j = 0; j < 3; ++j) {
    const Vec3 e = placement.E.col(j);
    X.E.col(j) = c * e - s * axis.cross(e) + ((1.0 - c) * axis.dot(e)) * axis;
  }
  X.r = placement.r;
  return X;
}

/// One degree of freedom as the sweeps see it (Model::dofs(), entry k of v):
/// body k + 1 moves relative to its parent by a rotation about `axis` through
/// the body's origin, or by a translation along it. Its joint's drive and
/// friction, per DOF.
struct Dof {
  int joint = -1;          ///< the joint it belongs to: its index in Model::joints(), −1 for the root's joint
  int index_in_joint = 0;  ///< 0 … nv − 1 within its joint
  bool rotation = true;    ///< a rotation about `axis` through the body origin; false: a translation along it
  /// `axis` is fixed in the joint frame (the parent's side: a planar joint's x
  /// and y); false: in the child body's frame.
  bool in_joint_frame = false;
  Vec3 axis = Vec3::UnitZ();                                ///< unit axis in that frame
  double rotor_inertia = 0.0;                               ///< d_k [kg·m² or kg]
  double breakaway_friction = 0.0;                          ///< f_k ≥ 0
  double kinetic_friction = 0.0;                            ///< f_c,k ≥ 0
  double viscous_friction = 0.0;                            ///< b_k ≥ 0
  double lower = -std::numeric_limits<double>::infinity();  ///< position limit (one-DOF joints)
  double upper = std::numeric_limits<double>::infinity();   ///< position limit (one-DOF joints)
  std::string name;  ///< the joint's name, with ".<coordinate>" for a multi-DOF joint ("hip.wx")
};

/// Something in the model data (or in a task on it) that is physically doubtful
/// but usable: the model loads and the dynamics uses the data as given
/// (docs/errors.md, "Model warnings"). UrdfOptions::strict turns every warning
/// of the model into a ModelError.
enum class WarningCode {
  PointMass,           ///< a moving link with mass but zero rotational inertia
  PlaceholderInertia,  ///< rotational inertia too small for the mass (a body denser than osmium)
  TriangleInequality,  ///< principal moments with a + b < c (no real body has them)
  PlaceholderLimits,   ///< <limit lower == upper, effort == velocity == 0>: read as "no limits"
  /// a `<limit>` on a floating or planar URDF joint, ignored: a multi-DOF joint has no limits in zwang
  IgnoredLimits,
  MassBeyondTip,  ///< links behind a moving joint below the tip carry mass the chain ignores
  MassOffChain,   ///< links behind a moving joint off the chain (a side branch) carry mass it ignores
  /// that mass was attached to the tip body (UrdfOptions::attach_beyond_tip); a note, strict mode lets it pass
  PayloadAttached,
  /// a mimic joint was locked (UrdfOptions::mimic = MimicJoints::Lock); a note, strict mode lets it pass
  MimicLocked,
  Urdfdom,  ///< urdfdom's own warning, passed on once
  /// a contact on a fixed-base model whose base carries mass (Task::warnings): a robot meant to stand bolted down
  FixedBaseContact,
  /// something an MJCF file holds that zwang does not model (tendons, actuators, contacts, springs, …): ignored
  Unmapped,
  Mujoco,  ///< MuJoCo's compiler warning on an MJCF file, passed on once
};
/// "point_mass", "placeholder_inertia", …: stable names for scripts and the CLI's JSON.
const char* toString(WarningCode code);

/// A warning recorded while building a model (Model::warnings()).
struct ModelWarning {
  WarningCode code;     ///< what kind of doubt
  std::string message;  ///< one line naming the source, the link or joint and the figures
};

/// A named frame (a URDF link) rigidly attached to a body of the tree.
struct Frame {
  std::string name;     ///< the URDF link name, unique among the frames
  int body = 0;         ///< the body it is rigidly attached to
  Transform placement;  ///< ᶠX_body
};

/// The robot: a tree of moving joints and rigid bodies, immutable once built (ModelBuilder, loadUrdfFile).
class Model {
 public:
  /// Degrees of freedom of the joints below the root: nv() without a floating
  /// base's. The length of the per-DOF friction vectors (FrictionOptions,
  /// FrictionResult); with one-DOF joints only, the number of joints.
  int dof() const { return nv_ - baseVelocitySize(); }
  /// Number of bodies, nv() + 1 with body 0 (the world, or a fixed base).
  int bodyCount() const { return nv_ + 1; }
  /// How the base is attached to the world: its root joint's type.
  BaseType baseType() const { return base_type_; }
  /// True for a Free or Planar base: the root link moves, on an unactuated root joint.
  bool hasFloatingBase() const { return base_type_ != BaseType::Fixed; }
  /// Entries of q for the base: 0 (fixed), 7 (free), 3 (planar).
  int baseConfigurationSize() const { return hasFloatingBase() ? root_.front().nq() : 0; }
  /// Entries of q̇, τ, q̈ for the base: 0 (fixed), 6 (free), 3 (planar).
  int baseVelocitySize() const { return hasFloatingBase() ? root_.front().nv() : 0; }
  /// Length of q: the base's coordinates, then each joint's nq().
  int nq() const { return nq_; }
  /// Length of q̇, τ and q̈: the base's velocity coordinates, then each joint's nv().
  int nv() const { return nv_; }
  /// Planar base: the plane's frame in the world, ᴾX_world (its x, y span the
  /// plane, z is the yaw axis; identity: the world's XY plane at height 0).
  /// Identity for the other bases.
  const Transform& basePlacement() const { return base_placement_; }
  /// The robot's name (URDF `<robot name>`).
  const std::string& name() const { return name_; }
  /// The body of the root link (the base): body 0 on a fixed base, the root
  /// joint's last body on a floating one.
  int baseBody() const { return baseVelocitySize(); }

  /// The moving joints below the root in the model's (depth-first) order: the
  /// order of their entries in q, q̇, τ and q̈, after the base's.
  const std::vector<Joint>& joints() const { return joints_; }
  /// Every joint in the order of q and v: a floating base's root joint first
  /// (named "root_joint", unactuated and frictionless), then joints(). What
  /// the kinematics visits.
  const std::vector<Joint>& allJoints() const { return all_joints_; }
  /// What Joint::transform(double) of a revolute joint computes from the
  /// placement alone, precomputed when the model is built: column k of E is
  /// c·e_k − s·(a × e_k) + ((1 − c)·(a·e_k))·a with e_k column k of E_T, so
  /// the sweeps evaluate the same expression (to the bit) without the cross
  /// and dot products.
  struct OneDofTransform {
    Mat3 axis_cross = Mat3::Zero();  ///< column k: a × e_k
    Vec3 axis_dot = Vec3::Zero();    ///< entry k: a · e_k
  };
  /// OneDofTransform of every joint of allJoints() (zero for other than revolute joints).
  const std::vector<OneDofTransform>& oneDofTransforms() const { return one_dof_transforms_; }
  /// Every DOF in the order of v (nv() entries): DOF k moves body k + 1.
  const std::vector<Dof>& dofs() const { return dofs_; }
  /// d_k of every DOF in the order of v (nv() entries; 0 on a floating root):
  /// Dof::rotor_inertia, contiguous as the sweeps read it.
  const Eigen::VectorXd& rotorInertia() const { return rotor_inertia_; }
  /// The parent body of body b (−1 for body 0).
  int parent(int b) const { return parents_[static_cast<std::size_t>(b)]; }
  /// One past the last body of b's subtree: the subtree is [b, subtreeEnd(b)).
  int subtreeEnd(int b) const { return subtree_end_[static_cast<std::size_t>(b)]; }
  /// The first DOF body of the joint that moves body b (b ≥ 1): b itself for a
  /// one-DOF joint; a joint of nv DOFs moves bodies jointStart(b) … jointStart(b) + nv − 1.
  int jointStart(int b) const { return joint_start_[static_cast<std::size_t>(b)]; }
  /// A one-DOF joint's position limits, with the index of its coordinate in q.
  struct PositionLimits {
    int joint = -1;      ///< its index in joints()
    int q_index = 0;     ///< its coordinate in q
    double lower = 0.0;  ///< q[q_index] ≥ lower (−∞: none)
    double upper = 0.0;  ///< q[q_index] ≤ upper (+∞: none)
  };
  /// The joints with a finite position limit, in joints() order: a compact
  /// array for the check every solve makes (multi-DOF joints have none).
  const std::vector<PositionLimits>& positionLimits() const { return position_limits_; }
  /// True when body `a` is body `b` or one of its ancestors (b lies in a's subtree).
  bool supports(int a, int b) const { return a <= b && b < subtreeEnd(a); }
  /// True when every body's parent is the body before it: a serial chain.
  bool isChain() const { return is_chain_; }
  /// The body joint j hangs from (the base's body for the joints on the root link).
  int parentBodyOfJoint(int j) const { return parent(joint(j).v_index + 1); }
  /// Joint j (0-based; throws std::out_of_range outside [0, joints().size())).
  const Joint& joint(int j) const { return joints_.at(static_cast<std::size_t>(j)); }
  /// Inertia of body b in its own frame (zero for a joint's intermediate
  /// bodies; body 0's, a fixed base's, is unused by the dynamics).
  const RigidInertia& inertia(int b) const { return inertias_.at(static_cast<std::size_t>(b)); }
  /// Every frame: the base, each body's link and the links on fixed joints.
  const std::vector<Frame>& frames() const { return frames_; }
  /// Frame f (throws std::out_of_range outside [0, frames().size())).
  const Frame& frame(int f) const { return frames_.at(static_cast<std::size_t>(f)); }

  /// Index lookups; throw ModelError naming the unknown name and the known ones.
  int jointIndex(const std::string& name) const;
  /// True when a moving joint of that name exists.
  bool hasJoint(const std::string& name) const;
  /// Index of the frame called `name`; throws ModelError naming the known frames.
  int frameIndex(const std::string& name) const;
  /// True when a frame of that name exists.
  bool hasFrame(const std::string& name) const;
  /// The frame of body b: the link its joint ends in (an intermediate body:
  /// the link of the joint it belongs to, whose pose it shares), the base link for body 0.
  int bodyFrame(int b) const { return body_frames_.at(static_cast<std::size_t>(b)); }
  /// The mimic joints (Joint::mimic active), in model order. Every solve adds
  /// one internal balance row per mimic joint, q̈_m − a·q̈_leader = 0.
  const std::vector<int>& mimicJoints() const { return mimic_joints_; }
  /// Set each mimic joint's q and q̇ from its leader's (q = a·q_leader + b, q̇ =
  /// a·q̇_leader); the other entries are left as they are. q has nq() entries
  /// and q̇ nv() (a floating base's first); either may be empty (left alone).
  void followLeaders(Eigen::Ref<Eigen::VectorXd> q, Eigen::Ref<Eigen::VectorXd> qd) const;
  /// What was doubtful in the data the model was built from (each once, in the
  /// order found); empty for clean data.
  const std::vector<ModelWarning>& warnings() const { return warnings_; }

 private:
  friend class ModelBuilder;
  std::string name_;
  // What the builder works on: links (0: the root link; j + 1: joint j's child)
  // and the frames on them. build() lays the bodies out from these.
  std::vector<Joint> joints_;
  std::vector<int> link_parents_{-1};            // per link, its parent link
  std::vector<RigidInertia> link_inertias_{{}};  // per link, with the links welded to it
  std::vector<int> frame_links_;                 // per frame, its link
  std::vector<int> link_frames_;                 // per link, its frame
  BaseType base_type_ = BaseType::Fixed;
  Transform base_placement_;
  std::vector<ModelWarning> warnings_;
  // What build() lays out.
  std::vector<Joint> root_;                          // the root joint of a floating base (none on a fixed one)
  std::vector<Joint> all_joints_;                    // root_, then joints_
  std::vector<OneDofTransform> one_dof_transforms_;  // per entry of all_joints_
  std::vector<Dof> dofs_;
  Eigen::VectorXd rotor_inertia_;  // per DOF, from dofs_
  int nq_ = 0, nv_ = 0;
  std::vector<RigidInertia> inertias_{{}};  // bodyCount() entries
  std::vector<Frame> frames_;
  std::vector<int> body_frames_{0};
  std::vector<int> parents_{-1};     // bodyCount() entries, parents_[0] = −1
  std::vector<int> subtree_end_{1};  // bodyCount() entries
  std::vector<int> joint_start_{0};  // bodyCount() entries
  std::vector<PositionLimits> position_limits_;
  bool is_chain_ = true;
  std::vector<int> mimic_joints_;
};

/// Builds a Model link by link (the URDF loader and the test generators use it).
/// Checks every value as it arrives and throws ModelError naming the joint or
/// link and the field.
class ModelBuilder {
 public:
  /// An empty chain: only the fixed base, a frame called `base_frame`.
  explicit ModelBuilder(std::string robot_name = "robot", std::string base_frame = "base");
  /// Start from an existing model (e.g. to set rotor inertias after loading).
  explicit ModelBuilder(const Model& model);

  /// Append a moving joint whose child link is `child_frame`, with the child's
  /// own inertia. The parent is the body of `parent_frame` (default: the last
  /// body added). Joints are added depth first: the parent must be the last
  /// body added or one of its ancestors (ModelError otherwise), so that every
  /// subtree is a contiguous range of bodies. `child_placement` is the child
  /// link's frame relative to the joint's child frame, ᶜX_body (identity: the
  /// same frame); `child_inertia` is given in the link's frame. The URDF loader
  /// turns a planar joint's frame so its z is the URDF axis and gives the link
  /// back its own orientation this way.
  ModelBuilder& addJoint(const Joint& joint, const std::string& child_frame, const RigidInertia& child_inertia,
                         const std::string& parent_frame = "", const Transform& child_placement = Transform{});
  /// Attach a frame rigidly to an existing frame (a fixed URDF joint); its
  /// inertia (given in the new frame) is merged into the parent body.
  ModelBuilder& addFixedFrame(const std::string& name, const std::string& parent_frame, const Transform& placement,
                              const RigidInertia& inertia = {});

  /// Set the reflected rotor inertia d_j of a joint (finite, ≥ 0).
  ModelBuilder& setRotorInertia(const std::string& joint, double value);
  /// Record a warning on the model (kept once: an identical message is dropped).
  ModelBuilder& addWarning(WarningCode code, const std::string& message);
  /// Prefix every message (e.g. with the URDF's file name), for the loader.
  ModelBuilder& prefixWarnings(const std::string& prefix);
  /// Set a joint's breakaway friction f_j, kinetic (Coulomb) friction f_c,j and viscous friction b_j (finite, ≥ 0).
  ModelBuilder& setFriction(const std::string& joint, double breakaway, double kinetic, double viscous);

  /// Make `joint` follow `leader`: q = multiplier·q_leader + offset (a URDF
  /// `<mimic>`). The leader may itself be a mimic joint: build() resolves the
  /// chain to its first leader, and refuses a cycle. ModelError for an unknown
  /// joint, a joint that mimics itself, or a multiplier or offset that is not finite.
  ModelBuilder& setMimic(const std::string& joint, const std::string& leader, double multiplier, double offset);

  /// Add the base link's own inertia (given in its frame) to the root link's
  /// body (body 0 on a fixed base, Model::baseBody() on a floating one). It
  /// enters the dynamics only when the base floats (setBase); the links welded
  /// to the base add theirs through addFixedFrame.
  ModelBuilder& addBaseLinkInertia(const RigidInertia& inertia);
  /// Let the base float: a free-flyer or a planar joint between the world and
  /// the root link (unactuated: the root joint, Model::allJoints()). `placement` is the plane's frame for a Planar base
  /// (ᴾX_world; must be identity for Free). `root_link_placement` is the root
  /// link's frame on the joint's child body, ᶜX_link, as addJoint's
  /// `child_placement` (the URDF loader turns a planar root joint's frame so its
  /// z is the URDF axis and gives the link back its own orientation this way);
  /// not the identity only for a Planar base, and only before anything is
  /// attached to the root link. ModelError when the base already floats (the
  /// URDF had a floating root joint, say), a placement is not finite, or
  /// `root_link_placement` comes too late or with a Free base.
  ModelBuilder& setBase(BaseType type, const Transform& placement = Transform{},
                        const Transform& root_link_placement = Transform{});

  /// Checks the whole tree (every moving joint must carry some inertia, every
  /// moving body's merged inertia is positive semi-definite to rounding) and
  /// returns the immutable model.
  Model build() const;

 private:
  Model model_;
  Joint& jointNamed(const std::string& name);
  void checkLinkInertia(const std::string& link_name, int link, const RigidInertia& inertia);
  static void layOutBodies(Model& model);
};

}  // namespace zwang
