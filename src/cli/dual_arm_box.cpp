// The dual arm's hand targets and pose errors (dual_arm_box.hpp).
#include "dual_arm_box.hpp"

#include <algorithm>

namespace zwang::cli::dual_arm {

Eigen::Isometry3d handTarget(const BoxPlacement& box, double side) {
  const Eigen::Matrix3d torso = Eigen::AngleAxisd(box.torso, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  Eigen::Matrix3d R;
  const Eigen::Vector3d z = torso * Eigen::Vector3d(0.0, -side, 0.0), x(0.0, 0.0, -1.0);
  R.col(0) = x;
  R.col(1) = z.cross(x);
  R.col(2) = z;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = R;
  pose.translation() = torso * (box.centre + Eigen::Vector3d(0.0, side * kGrip, 0.0));
  return pose;
}

Status handError(const Model& model, Workspace& ws, const Eigen::VectorXd& q, int frame,
                 const Eigen::Isometry3d& target, Vec6& error) {
  Eigen::Isometry3d pose;
  const Status s = framePose(model, ws, q, frame, pose);
  if (!s) return s;
  const Eigen::AngleAxisd rotation(target.linear() * pose.linear().transpose());
  error << target.translation() - pose.translation(), rotation.angle() * rotation.axis();
  return s;
}

Status boxError(const Model& model, Workspace& ws, const Eigen::VectorXd& q, const BoxPlacement& box, double& error) {
  Vec6 left, right;
  Status s = forwardKinematics(model, ws, q);
  if (s) s = handError(model, ws, q, model.frameIndex("left_tool0"), handTarget(box, 1.0), left);
  if (s) s = handError(model, ws, q, model.frameIndex("right_tool0"), handTarget(box, -1.0), right);
  error = std::max(left.norm(), right.norm());
  return s;
}

}  // namespace zwang::cli::dual_arm
