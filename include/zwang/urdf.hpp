/// \file
/// Loading a model (a whole tree, a subtree or a chain) from URDF (via urdfdom).
#pragma once

#include <map>
#include <string>

#include "zwang/model.hpp"

namespace zwang {

/// What the loader does with a URDF `<mimic>` joint (q = multiplier · q_leader +
/// offset) among the joints it loads.
enum class MimicJoints {
  /// The joint follows its leader (Joint::mimic; the default): its q, q̇, q̈
  /// obey the law, its torque is carried by the leader's motor and its
  /// friction joins the leader's (docs/solver.md, "Mimic joints"). The leader
  /// must be loaded too (ModelError otherwise, naming both joints).
  Model,
  /// Weld each mimic joint (and the links behind it) to its parent link at
  /// UrdfOptions::locked_positions[joint], by default at the position its leader
  /// at rest implies: multiplier · q_leader + offset with q_leader =
  /// locked_positions[leader] if that is given, else 0 (so `offset`). Each
  /// locked joint is noted with a MimicLocked warning (strict mode lets it pass).
  Lock,
  /// ModelError naming the joint and its leader: for callers that want no
  /// coupled joints at all.
  Refuse,
};

/// What to load from the URDF, and rotor inertias it does not state.
///
/// * No tip: the whole tree below `root` (default: the URDF's root link),
///   every moving joint of it, bodies in depth-first order: a depth-first walk
///   over the links from the root, each link's children taken in the
///   byte-wise order of the names of the joints that lead to them (urdfdom's
///   own order). A tree that does not branch into moving joints is a chain and
///   loads exactly as the chain to its unique leaf.
/// * `root` and `tip`: the chain from `root` to `tip`; moving joints off that
///   path are not in the model (MassOffChain, MassBeyondTip, attach_beyond_tip).
///
/// Fixed joints are merged into their parent body, and every link that is
/// loaded, or welded to one that is, is a named frame (also the links welded
/// above the root).
///
/// The base (docs/conventions.md, "Floating base"; the root link and the links
/// welded to it, Model::baseBody()):
/// * A URDF whose root link's only joint is `floating` or `planar` (the
///   "world → base_link" pattern) loads with a Free or Planar base under that
///   joint's child link, which becomes the base (when the model starts at the
///   URDF's root link, the default, or at that child link). The links above
///   the joint are the world: not frames, their mass ignored. Free: the base
///   pose is the configuration, the base link's pose in the root link's (the
///   world's) frame; the joint's `<origin>` would only offset the zero of
///   those coordinates, so it is folded in (q = [origin xyz, origin
///   quaternion] puts the base where the URDF draws it). Planar: the joint
///   frame (`<origin>`), turned as for a planar joint below the root (next
///   item) so that its z is the `<axis>`, is the plane
///   (Model::basePlacement()); the base link keeps the URDF's orientation
///   (its frame is placed on the base's body by the inverse rotation).
/// * A `floating` or `planar` joint anywhere else is a joint of the model:
///   JointType::Free (q = [x, y, z, q_w, q_x, q_y, q_z] of the
///   child link in the joint frame, the URDF `<origin>`) or JointType::Planar
///   (q = [x, y, ψ]). URDF moves a planar joint's child in the plane normal to
///   its `<axis>`: zwang turns the joint frame by the shortest rotation that
///   takes its z onto the axis (about z × axis; a half turn about x for −z),
///   so x and y are along that rotation's images of the joint frame's x and y
///   and ψ turns about the axis; the child link keeps the URDF's orientation
///   (its frame is placed on the joint's child body by the inverse rotation).
///   `<dynamics>` friction and damping apply to each DOF (a box per DOF);
///   a `<limit>` on such a joint is ignored with an IgnoredLimits warning
///   (which of its coordinates would it bound? strict mode refuses it). Such
///   a joint is locked (beyond the tip, or as a locked mimic joint) at its
///   origin; a locked position for it is a ModelError.
/// * Otherwise `base` may give the root link a free-flyer or a planar joint
///   (the world's x-y plane) for the many legged-robot URDFs that leave it out.
/// * The root link's own `<inertial>` is the base's (with the links welded to
///   it): in the dynamics when the base floats (Model::inertia(baseBody())),
///   only counted (Model::inertia(0), the "base mass") on a fixed base.
struct UrdfOptions {
  /// The model starts at this link (its base). Empty: the URDF's root link.
  std::string root;
  /// The tip link of a chain from root to tip; empty: the whole tree below root (see above).
  std::string tip;
  /// Rotor (armature) inertia per joint name, overriding the URDF's
  /// `<transmission>/<actuator>/<drake:rotor_inertia>` · `<drake:gear_ratio>`².
  std::map<std::string, double> rotor_inertia;
  /// Refuse doubtful data: every ModelWarning the load would record (point
  /// masses, placeholder inertias or limits, triangle-inequality violations,
  /// mass beyond the tip, urdfdom's warnings) becomes a ModelError instead
  /// (PayloadAttached and MimicLocked, notes on what attach_beyond_tip and
  /// MimicJoints::Lock did, are let pass).
  bool strict = false;
  /// Links behind moving joints below the tip (a gripper's fingers) are not on
  /// the chain. false: their mass is ignored, with a MassBeyondTip warning.
  /// true: they are welded to the tip body as a rigid payload, each of those
  /// joints locked at locked_positions[joint] (default 0; a mimic joint's default
  /// is as for MimicJoints::Lock), and become frames.
  bool attach_beyond_tip = false;
  /// Mimic joints among the loaded ones: modelled (default), locked or refused; see MimicJoints.
  MimicJoints mimic = MimicJoints::Model;
  /// Position of each locked joint, by name: the joints beyond the tip
  /// (attach_beyond_tip) and the mimic joints (MimicJoints::Lock). Any other
  /// name is a ModelError.
  std::map<std::string, double> locked_positions;
  /// Give the root link a floating base: BaseType::Free (a free-flyer) or
  /// BaseType::Planar (x, y, yaw in the world's x-y plane). BaseType::Fixed
  /// (the default) adds none: the base is fixed unless the URDF has a floating
  /// or planar root joint (see above). Free or Planar on a URDF that has such
  /// a root joint already is a ModelError, unless base_may_match_file.
  BaseType base = BaseType::Fixed;
  /// With `base` Free or Planar and a URDF that already has a floating or
  /// planar root joint: false (default), ModelError ("drop the base option");
  /// true, the file's joint is used when its type is the one `base` asks for,
  /// ModelError otherwise. For callers that always name the base (the CLI's "base").
  bool base_may_match_file = false;
};

/// Throw ModelError with a message naming the file (or "<string>"), the link or
/// joint, and the field at fault. Doubtful but usable data loads, with
/// Model::warnings() saying what and where (each message starts with the
/// source); console output of urdfdom is captured into those warnings.
///
/// Placeholder limits: `<limit lower="x" upper="x" effort="0" velocity="0"/>`
/// (what CAD exporters write when they know no limits) means "no limits":
/// position, effort and velocity limits are all infinite (PlaceholderLimits).
/// A negative effort or velocity limit (-1: "unlimited" in some files) is no
/// such limit (PlaceholderLimits).
///
/// urdfdom's errors fail the load, except those about what only draws the
/// robot: when the file reads without its links' `<visual>` and `<collision>`
/// elements and its top-level `<material>`s, it loads without them, with an
/// Urdfdom warning naming each link or material urdfdom cannot read. An
/// `<inertial>` urdfdom would read as zeros (no `<mass>`, no `<inertia>` or one
/// of its six attributes missing) is a ModelError naming the link; a file with
/// no `<inertial>` at all is one ModelError saying so.
Model loadUrdfFile(const std::string& path, const UrdfOptions& options = {});
/// The same from URDF text in memory; messages name the source "<string>".
Model loadUrdfString(const std::string& xml, const UrdfOptions& options = {});

}  // namespace zwang
