/// \file
/// Placing a floating-base robot on the ground: move its free base so that
/// given frames touch the plane z = height of the world.
#pragma once

#include <vector>

#include "zwang/status.hpp"
#include "zwang/workspace.hpp"

namespace zwang {

/// How placeOnPlane moves the base.
enum class PlaneContact {
  /// Translate the base along the world z only (orientation and joints kept):
  /// the lowest of the frames' origins ends exactly on the plane, the others
  /// above it.
  Lowest,
  /// Turn the whole robot rigidly about the frames' centroid by the smallest
  /// rotation that makes their best-fit plane horizontal, then translate it
  /// along z as Lowest. The frames' origins then all lie on the plane when
  /// they are coplanar in the robot's posture (the four feet of a standing
  /// quadruped), and `distance` says how far they are from it otherwise. The
  /// best-fit plane of three or more origins is the least-squares plane
  /// through them (the singular vector of their spread with the least
  /// singular value as its normal); of two, or of collinear origins, the
  /// plane through their line closest to horizontal (the line is made
  /// horizontal); of one, any: no rotation.
  All,
};

/// q_out: q with the free base moved (see PlaneContact) so that the origins
/// of `frames` touch the plane z = `height` in world coordinates. Joints are
/// not moved; the base's quaternion stays unit. `distance` is the largest
/// distance of a frame's origin from the plane afterwards (0 for a single
/// frame; with Lowest, the highest frame's height above the plane).
/// Uses forwardKinematics(q) (the workspace then holds poses at q). Errors:
/// a model without a free base (ModelMismatch "placeOnPlane needs a free
/// base …"), no frames or a frame index out of range (ModelMismatch), q not
/// a configuration (checkConfiguration's statuses), q_out of the wrong size
/// (SizeMismatch), a non-finite height (NonFinite). q_out may be q itself.
Status placeOnPlane(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                    const std::vector<int>& frames, double height, PlaneContact contact,
                    Eigen::Ref<Eigen::VectorXd> q_out, double& distance) noexcept;

}  // namespace zwang
