/// \file
/// Loading a model from MJCF (MuJoCo's XML) through MuJoCo's own compiler: an
/// optional component, the library zwang_mujoco (CMake target zwang::mujoco),
/// built only when MuJoCo is found. The core library does not need MuJoCo.
///
/// The file is compiled by mj_loadXML into an mjModel (defaults, classes,
/// degrees, euler sequences, fromto, inertias from geoms: all MuJoCo's), and
/// the compiled model is read (docs/mujoco.md has the whole mapping):
/// * every body is a frame of its name (unnamed: "body<id>"), every site a
///   frame of its name (a site whose name is a body's is skipped, with an
///   Unmapped warning);
/// * `hinge` → revolute (continuous when not limited), `slide` → prismatic,
///   `ball` → spherical, anywhere in the tree; `free` → the floating base when
///   the world has exactly one child body and that body's joint is free, else a
///   free joint hanging from the world (MuJoCo puts free joints on the world's
///   children only). q is MuJoCo's qpos, also for a joint with a `ref` (the
///   reference is folded into the joint's placement); v is MuJoCo's qvel except
///   for free joints, whose linear velocity zwang takes in the child frame
///   (MuJoCo: world axes);
/// * a joint anchor off the body origin (`pos`) is a joint frame at the anchor
///   and the body's frame placed back by −pos; several joints in one body are a
///   chain of massless intermediate bodies, one per joint but the last (frames
///   "<body>:<joint>"), composed in MuJoCo's order;
/// * `range` with `limited` → position limits, `armature` → rotor inertia,
///   `frictionloss` → breakaway and kinetic friction, `damping` → viscous
///   friction (all per DOF); a joint `<equality>` with a degree-1 polynomial →
///   a mimic joint;
/// * what zwang does not model (tendons, actuators, contacts and geoms, other
///   equalities, joint springs, ball-joint limits, the base joint's
///   armature, friction and damping) is named in an Unmapped warning; what an
///   `<option><flag>` disables (limits, friction loss, passive forces,
///   equalities, gravity) is not mapped either.
#pragma once

#include <string>

#include "zwang/model.hpp"

namespace zwang {

/// How to load an MJCF model.
struct MjcfOptions {
  /// Refuse doubtful data: every ModelWarning the load would record (the
  /// Unmapped ones included, and MuJoCo's compiler warning) becomes a
  /// ModelError, as UrdfOptions::strict does.
  bool strict = false;
};

/// A model loaded from MJCF and what the file says beside it.
struct MjcfModel {
  Model model;  ///< the robot
  /// `<option gravity>` [m/s²] in the world frame (zero when `<flag gravity="disable">`);
  /// a Task's gravity is the caller's to set.
  Vec3 gravity = Vec3(0.0, 0.0, -9.81);
};

/// Load the MJCF file at `path`. Throws ModelError naming the file and, for a
/// file MuJoCo refuses, MuJoCo's message; a model zwang cannot represent (a
/// joint type where zwang has none, a moving body without mass) is refused
/// with the body or joint and the reason. Warnings as urdf.hpp's loader
/// records them (Model::warnings(), each message starting with the file).
MjcfModel readMjcfFile(const std::string& path, const MjcfOptions& options = {});
/// The same from MJCF text in memory (through MuJoCo's virtual file system:
/// the text may not include other files); messages name the source "<string>".
MjcfModel readMjcfString(const std::string& xml, const MjcfOptions& options = {});

/// readMjcfFile(path, options).model, as loadUrdfFile.
Model loadMjcfFile(const std::string& path, const MjcfOptions& options = {});
/// readMjcfString(xml, options).model, as loadUrdfString.
Model loadMjcfString(const std::string& xml, const MjcfOptions& options = {});

}  // namespace zwang
