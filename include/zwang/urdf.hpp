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
};

/// Throw ModelError with a message naming the file (or "<string>"), the link or
/// joint, and the field at fault.
Model loadUrdfFile(const std::string& path, const UrdfOptions& options = {});
/// The same from URDF text in memory; messages name the source "<string>".
Model loadUrdfString(const std::string& xml, const UrdfOptions& options = {});

}  // namespace zwang
