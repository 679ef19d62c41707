/// \file
/// Loading a chain from URDF (via urdfdom).
#pragma once

#include <map>
#include <string>

#include "zwang/model.hpp"

namespace zwang {

/// Which chain to load from the URDF, and rotor inertias it does not state.
struct UrdfOptions {
  /// The chain runs from `root` down to `tip`. Empty root: the URDF's root link.
  /// Empty tip: allowed only when the tree below root does not branch into moving
  /// joints (the unique leaf is used).
  std::string root;
  /// The tip link; see root.
  std::string tip;
  /// Rotor (armature) inertia per joint name, overriding the URDF's
  /// `<transmission>/<actuator>/<drake:rotor_inertia>` · `<drake:gear_ratio>`².
  std::map<std::string, double> rotor_inertia;
  /// Refuse doubtful data: every ModelWarning the load would record (point
  /// masses, placeholder inertias or limits, triangle-inequality violations,
  /// mass beyond the tip, urdfdom's warnings) becomes a ModelError instead
  /// (PayloadAttached, a note on what attach_beyond_tip did, is let pass).
  bool strict = false;
  /// Links behind moving joints below the tip (a gripper's fingers) are not on
  /// the chain. false: their mass is ignored, with a MassBeyondTip warning.
  /// true: they are welded to the tip body as a rigid payload, each of those
  /// joints locked at locked_positions[joint] (default 0), and become frames.
  bool attach_beyond_tip = false;
  /// Position of each locked joint beyond the tip, by name (default 0); see attach_beyond_tip.
  std::map<std::string, double> locked_positions;
  /// How the caller spells these options, for the hints in messages (the CLI
  /// says "--tip", Python "tip=").
  struct Names {
    std::string tip = "UrdfOptions::tip";                              ///< the name of the tip option
    std::string rotor_inertia = "UrdfOptions::rotor_inertia";          ///< the name of the rotor_inertia option
    std::string attach_beyond_tip = "UrdfOptions::attach_beyond_tip";  ///< the name of the attach_beyond_tip option
  } names;                                                             ///< see Names
};

/// Throw ModelError with a message naming the file (or "<string>"), the link or
/// joint, and the field at fault. Doubtful but usable data loads, with
/// Model::warnings() saying what and where (each message starts with the
/// source); console output of urdfdom is captured into those warnings.
///
/// Placeholder limits: `<limit lower="x" upper="x" effort="0" velocity="0"/>`
/// (what CAD exporters write when they know no limits) means "no limits":
/// position, effort and velocity limits are all infinite (PlaceholderLimits).
Model loadUrdfFile(const std::string& path, const UrdfOptions& options = {});
/// The same from URDF text in memory; messages name the source "<string>".
Model loadUrdfString(const std::string& xml, const UrdfOptions& options = {});

}  // namespace zwang
