// Writes a ChainSpec as URDF text (our own writer; no URDF library involved).
#pragma once

#include <string>

#include "support/chain_spec.hpp"

namespace zwang::testing {

// A complete URDF document for `spec`. Numbers are printed with %.17g so that
// parsing them back gives the same doubles. Every joint carries
// <dynamics friction damping>; a moving joint with rotor_inertia > 0 gets a
// <transmission> whose <actuator> holds <drake:rotor_inertia value/> and
// <drake:gear_ratio value/> (docs/conventions.md, "Joints, links, frames"; xmlns:drake is declared on
// <robot>). A link with zero mass and zero inertia is written without <inertial>.
// A mimic joint (JointSpec::mimic) gets <mimic joint multiplier offset/>.
std::string toUrdf(const ChainSpec& spec);

}  // namespace zwang::testing
