// The URDF loader with the caller's spelling of its options in the messages'
// hints (the CLI says "--tip", Python "tip="). Not installed: the front ends'
// business; a library user sees the UrdfOptions names.
#pragma once

#include <string>

#include "zwang/urdf.hpp"

namespace zwang::internal {

// How the caller spells the options of UrdfOptions.
struct UrdfOptionNames {
  std::string tip = "UrdfOptions::tip";                                   // the name of the tip option
  std::string rotor_inertia = "UrdfOptions::rotor_inertia";               // the name of the rotor_inertia option
  std::string attach_beyond_tip = "UrdfOptions::attach_beyond_tip";       // the name of the attach_beyond_tip option
  std::string lock_mimic = "UrdfOptions::mimic = MimicJoints::Lock";      // how to ask for MimicJoints::Lock
  std::string refuse_mimic = "UrdfOptions::mimic = MimicJoints::Refuse";  // how MimicJoints::Refuse was asked for
  std::string base = "UrdfOptions::base";                                 // the name of the base option
};

// The options and how the caller spells them.
struct NamedUrdfOptions : UrdfOptions {
  UrdfOptionNames names;
};

// loadUrdfFile and loadUrdfString (urdf.hpp), their messages naming the options as `options.names` spells them.
Model loadUrdfFile(const std::string& path, const NamedUrdfOptions& options);
Model loadUrdfString(const std::string& xml, const NamedUrdfOptions& options);

}  // namespace zwang::internal
