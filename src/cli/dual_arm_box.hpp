// Where the dual arm's hands must be to hold the box of `zwang energy`
// (energy_dual.cpp): both tool0 frames of models/dual_panda.urdf at the side
// faces of a box. The CLI checks its stored postures with it; the program
// that solves them (test/cli/dual_panda_postures.cpp) aims at the same poses.
#pragma once

#include "zwang/zwang.hpp"

namespace zwang::cli::dual_arm {

constexpr double kGrip = 0.15;  // half the box's width: the hands at ±kGrip along the torso's y [m]

// Where the box is: the torso's angle [rad] and the box's centre in the torso
// frame (x forward, y left, z up) [m]; the hands grip it at ±kGrip along y.
struct BoxPlacement {
  double torso;
  Eigen::Vector3d centre;
};

// The world pose a hand must have (side +1 left, −1 right): at the box's
// side, z axis towards the box, x axis down.
Eigen::Isometry3d handTarget(const BoxPlacement& box, double side);

// The pose error of `frame` at q against `target`: position [m] stacked over
// the rotation vector [rad], world axes; ws must hold q's kinematics (framePose).
Status handError(const Model& model, Workspace& ws, const Eigen::VectorXd& q, int frame,
                 const Eigen::Isometry3d& target, Vec6& error);

// The worst of the two hands' errors' norms at q [m or rad].
Status boxError(const Model& model, Workspace& ws, const Eigen::VectorXd& q, const BoxPlacement& box, double& error);

}  // namespace zwang::cli::dual_arm
