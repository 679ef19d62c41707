#include "support/frame_values.hpp"

#include <stdexcept>
#include <string>

namespace zwang::testing {

namespace {
void require(const Status& status, const char* call) {
  if (!status) throw std::runtime_error(std::string(call) + ": " + status.message);
}
}  // namespace

Eigen::Isometry3d poseOf(const Model& model, const Workspace& ws, int frame) {
  Eigen::Isometry3d pose;
  require(framePose(model, ws, ws.kinematics.q, frame, pose), "framePose");
  return pose;
}

Vec6 velocityOf(const Model& model, const Workspace& ws, int frame, Expressed expressed) {
  Vec6 v;
  require(frameVelocity(model, ws, ws.kinematics.q, ws.kinematics.qd, frame, expressed, v), "frameVelocity");
  return v;
}

Vec6 accelerationOf(const Model& model, const Workspace& ws, int frame, Expressed expressed) {
  Vec6 a;
  require(frameAcceleration(model, ws, ws.kinematics.q, ws.kinematics.qd, frame, expressed, a), "frameAcceleration");
  return a;
}

}  // namespace zwang::testing
