// The dual arm's postures for `zwang energy` (energy_dual.cpp): both hands of
// models/dual_panda.urdf at the side faces of a box, found by damped least
// squares on each arm. It makes the scenario's input, so it ships with it.
#pragma once

#include <string>

#include "zwang/zwang.hpp"

namespace zwang::cli::dual_arm {

// Where the box is: the torso's angle [rad] and the box's centre in the torso
// frame (x forward, y left, z up) [m]; the hands grip it at ±half_width along y.
struct BoxPlacement {
  double torso;
  Eigen::Vector3d centre;
  double half_width;
};

// q (torso, left arm 1-7, right arm 1-7) with each tool0 at its side of the
// box, z axis towards the box, x axis down; deterministic (make_dual_panda.py
// --check's grasp as the seed, a fixed iteration rule). `error` is set to the
// worst hand's pose error [m or rad]. CliError "<where><message>" when a
// frame query fails.
Eigen::VectorXd reachBox(const Model& model, const BoxPlacement& box, double& error, const std::string& where);

}  // namespace zwang::cli::dual_arm
