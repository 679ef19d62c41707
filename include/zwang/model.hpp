/// \file
/// The robot model: a kinematic tree of 1-DOF joints with rigid bodies (a
/// serial chain is the tree without branches), immutable once built and safe to
/// share between threads. Scratch memory lives in a Workspace (workspace.hpp); a
/// Model never changes during a solve.
///
/// Indexing: body 0 is the fixed base; joint j (0-based) moves body j+1
/// relative to its parent body parent(j+1) (for a chain, body j). Bodies are in
/// depth-first order: every body comes after its parent, and the bodies of a
/// subtree are the contiguous range [b, subtreeEnd(b)). The sweeps rely on that
/// range: the constraints a body feels are those on its subtree, a contiguous
/// block of columns (Task::columnRange). Fixed URDF joints are merged into
/// their parent body at load time, but every link stays addressable as a Frame
/// attached to a body.
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

/// How the base (body 0: the root link and the links welded to it) is attached
/// to the world (docs/conventions.md, "Floating base").
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

/// The kinds of moving joint, as URDF names them.
enum class JointType { Revolute, Continuous, Prismatic };
/// The URDF name of a joint type: "revolute", "continuous" or "prismatic".
const char* toString(JointType type);

/// A joint that follows another (URDF `<mimic>`): q = multiplier·q_leader +
/// offset, so q̇ = multiplier·q̇_leader and q̈ = multiplier·q̈_leader. The
/// mechanism that couples them (gears, a linkage, a tendon) supplies the
/// coupling torque; the leader's motor carries the rest (docs/solver.md, "Mimic joints").
struct Mimic {
  int leader = -1;          ///< the joint followed (never itself a mimic joint once built); −1: independent
  double multiplier = 1.0;  ///< a in q = a·q_leader + b
  double offset = 0.0;      ///< b [rad or m]
  /// True when the joint follows a leader.
  bool active() const { return leader >= 0; }
};

/// One moving joint of the tree: its axis and placement, drive (rotor inertia), friction and limits.
struct Joint {
  std::string name;                      ///< unique among the model's joints
  JointType type = JointType::Revolute;  ///< revolute, continuous (no position limits) or prismatic
  Vec3 axis = Vec3::UnitZ();             ///< unit vector in the joint (= child body) frame
  Transform placement;                   ///< ʲX_parent: parent body frame → joint frame at q = 0
  double rotor_inertia = 0.0;            ///< d_j, reflected armature inertia [kg·m² or kg]
  double breakaway_friction = 0.0;       ///< f_j ≥ 0, static friction bound
  double kinetic_friction = 0.0;         ///< f_c,j ≥ 0, Coulomb friction while moving
  double viscous_friction = 0.0;         ///< b_j ≥ 0, viscous friction coefficient (URDF `dynamics damping`)
  double lower = -std::numeric_limits<double>::infinity();  ///< position limits: lower [rad or m]
  double upper = std::numeric_limits<double>::infinity();   ///< position limits: upper [rad or m]
  /// Largest torque [N·m] or force [N] (URDF `<limit effort>`).
  double effort_limit = std::numeric_limits<double>::infinity();
  /// Largest speed [rad/s or m/s] (URDF `<limit velocity>`).
  double velocity_limit = std::numeric_limits<double>::infinity();
  /// The leader this joint follows, if it is a mimic joint (chains of mimic
  /// joints are resolved to the first leader when the model is built).
  Mimic mimic;

  /// True for revolute and continuous joints.
  bool isRevolute() const { return type != JointType::Prismatic; }
  /// Motion subspace S (6-vector, linear first) in the child body frame.
  Vec6 motionSubspace() const {
    return isRevolute() ? spatial::stack(Vec3::Zero(), axis) : spatial::stack(axis, Vec3::Zero());
  }
  /// ʲX_parent(q) = X_J(q) · X_T: the placement followed by the joint motion.
  Transform transform(double q) const;
};

inline Transform Joint::transform(double q) const {
  // X_J(q): the child frame is the joint frame rotated by q about (or shifted by
  // q along) the axis; then ʲX_parent = X_J · X_T with X_T = placement.
  if (!isRevolute()) return {placement.E, placement.r + placement.E.transpose() * (q * axis)};
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

/// Something in the model data (or in a task on it) that is physically doubtful
/// but usable: the model loads and the dynamics uses the data as given
/// (docs/errors.md, "Model warnings"). UrdfOptions::strict turns every warning
/// of the model into a ModelError.
enum class WarningCode {
  PointMass,           ///< a moving link with mass but zero rotational inertia
  PlaceholderInertia,  ///< rotational inertia too small for the mass (a body denser than osmium)
  TriangleInequality,  ///< principal moments with a + b < c (no real body has them)
  PlaceholderLimits,   ///< <limit lower == upper, effort == velocity == 0>: read as "no limits"
  MassBeyondTip,       ///< links behind a moving joint below the tip carry mass the chain ignores
  MassOffChain,        ///< links behind a moving joint off the chain (a side branch) carry mass it ignores
  /// that mass was attached to the tip body (UrdfOptions::attach_beyond_tip); a note, strict mode lets it pass
  PayloadAttached,
  /// a mimic joint was locked (UrdfOptions::mimic = MimicJoints::Lock); a note, strict mode lets it pass
  MimicLocked,
  Urdfdom,  ///< urdfdom's own warning, passed on once
  /// a contact on a fixed-base model whose base carries mass (Task::warnings): a robot meant to stand bolted down
  FixedBaseContact,
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
  /// Number of moving (1-DOF) joints n. On a fixed base this is the length of
  /// q, q̇, τ and q̈; a floating base puts its coordinates in front (nq(), nv()).
  int dof() const { return static_cast<int>(joints_.size()); }
  /// Number of bodies, n + 1 with the base (body 0).
  int bodyCount() const { return dof() + 1; }
  /// How the base is attached to the world.
  BaseType baseType() const { return base_type_; }
  /// True for a Free or Planar base: body 0 moves, unactuated.
  bool hasFloatingBase() const { return base_type_ != BaseType::Fixed; }
  /// Entries of q for the base: 0 (fixed), 7 (free), 3 (planar).
  int baseConfigurationSize() const {
    return base_type_ == BaseType::Free ? 7 : base_type_ == BaseType::Planar ? 3 : 0;
  }
  /// Entries of q̇, τ, q̈ for the base: 0 (fixed), 6 (free), 3 (planar).
  int baseVelocitySize() const { return base_type_ == BaseType::Free ? 6 : base_type_ == BaseType::Planar ? 3 : 0; }
  /// Length of q: the base's coordinates, then one per joint.
  int nq() const { return baseConfigurationSize() + dof(); }
  /// Length of q̇, τ and q̈: the base's velocity coordinates, then one per joint.
  int nv() const { return baseVelocitySize() + dof(); }
  /// Planar base: the plane's frame in the world, ᴾX_world (its x, y span the
  /// plane, z is the yaw axis; identity: the world's XY plane at height 0).
  /// Identity for the other bases.
  const Transform& basePlacement() const { return base_placement_; }
  /// The robot's name (URDF `<robot name>`).
  const std::string& name() const { return name_; }

  /// The moving joints in the model's (depth-first) order: the order of q, q̇, τ and q̈.
  const std::vector<Joint>& joints() const { return joints_; }
  /// The parent body of body b (−1 for the base, b = 0).
  int parent(int b) const { return parents_[static_cast<std::size_t>(b)]; }
  /// One past the last body of b's subtree: the subtree is [b, subtreeEnd(b)).
  int subtreeEnd(int b) const { return subtree_end_[static_cast<std::size_t>(b)]; }
  /// True when body `a` is body `b` or one of its ancestors (b lies in a's subtree).
  bool supports(int a, int b) const { return a <= b && b < subtreeEnd(a); }
  /// True when every body's parent is the body before it: a serial chain.
  bool isChain() const { return is_chain_; }
  /// The body joint j hangs from (0: the base).
  int parentBodyOfJoint(int j) const { return parent(j + 1); }
  /// Joint j (0-based; throws std::out_of_range outside [0, dof())).
  const Joint& joint(int j) const { return joints_.at(static_cast<std::size_t>(j)); }
  /// Inertia of body b (b = 0 is the base, unused by the dynamics) in its own frame.
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
  /// The frame of body b (the link the moving joint b−1 ends in; b = 0: the base link).
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
  std::vector<Joint> joints_;
  std::vector<RigidInertia> inertias_;  // bodyCount() entries
  std::vector<Frame> frames_;
  std::vector<int> body_frames_;
  std::vector<int> parents_{-1};     // bodyCount() entries, parents_[0] = −1
  std::vector<int> subtree_end_{1};  // bodyCount() entries
  bool is_chain_ = true;
  BaseType base_type_ = BaseType::Fixed;
  Transform base_placement_;
  std::vector<int> mimic_joints_;
  std::vector<ModelWarning> warnings_;
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
  /// subtree is a contiguous range of bodies.
  ModelBuilder& addJoint(const Joint& joint, const std::string& child_frame, const RigidInertia& child_inertia,
                         const std::string& parent_frame = "");
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

  /// Add the base link's own inertia (given in its frame) to body 0. It enters
  /// the dynamics only when the base floats (setBase); the links welded to the
  /// base add theirs through addFixedFrame.
  ModelBuilder& addBaseLinkInertia(const RigidInertia& inertia);
  /// Let the base float: a free-flyer or a planar joint between the world and
  /// body 0 (unactuated). `placement` is the plane's frame for a Planar base
  /// (ᴾX_world; must be identity for Free). ModelError when the base already
  /// floats (the URDF had a floating root joint, say) or the placement is not finite.
  ModelBuilder& setBase(BaseType type, const Transform& placement = Transform{});

  /// Checks the whole tree (every moving joint must carry some inertia, every
  /// moving body's merged inertia is positive semi-definite to rounding) and
  /// returns the immutable model.
  Model build() const;

 private:
  Model model_;
  Joint& jointNamed(const std::string& name);
  void checkLinkInertia(const std::string& link, int body, const RigidInertia& inertia);
};

/// Validation helpers shared by the builder and the URDF loader.
namespace validate {
/// The heaviest link and the largest moment of inertia zwang accepts [kg, kg·m²].
constexpr double kMaxMass = 1e12;
constexpr double kMaxMoment = 1e12;  ///< the largest moment of inertia [kg·m²]

/// Throws `ModelError("<where>: <what>")` when the inertia cannot be a body's:
/// negative or non-finite mass, a mass above kMaxMass, non-finite or huge
/// values, an asymmetric matrix or a principal moment at the COM that is
/// negative beyond rounding. `rounding_scale` is the size of the numbers the
/// COM inertia was computed from (kg·m²): moments within
/// roundingTolerance(rounding_scale) of zero count as zero, so point masses,
/// thin rods and inertias recovered from the origin form (I_c = Ī + m·c×c×)
/// pass. Returns the warnings (triangle inequality, point mass, placeholder
/// inertia) for the caller to record.
std::vector<ModelWarning> rigidInertia(const std::string& where, double mass, const Vec3& com, const Mat3& I_com,
                                       double rounding_scale = 0.0);
/// The same for an inertia in origin form (m, h, Ī), as the builder holds it.
std::vector<ModelWarning> rigidInertia(const std::string& where, const RigidInertia& inertia);
/// How far from zero a moment computed from numbers of size `scale` may land
/// by rounding alone.
double roundingTolerance(double scale);
}  // namespace validate

}  // namespace zwang
