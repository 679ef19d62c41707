// Pieces shared by several algorithms (not installed).
#pragma once

#include "zwang/workspace.hpp"

namespace zwang::internal {

// Outward sweep of poses, velocities and velocity-product accelerations
// (Algorithm 1, lines 3–6): Xup, Xworld, S, v, c. q̇ may be zero-length to skip
// velocities.
void outwardKinematics(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q,
                       const Eigen::Ref<const Eigen::VectorXd>& qd, Workspace& ws);

// World-frame rotation ᵂR_f of a frame, after outwardKinematics.
inline Mat3 frameRotation(const Model& model, const Workspace& ws, int frame) {
  const Frame& f = model.frame(frame);
  return (f.placement * ws.Xworld[static_cast<std::size_t>(f.body)]).E.transpose();
}

// A spatial force given at a frame's origin (local or world axes) as a force
// on the frame's body, in body coordinates.
inline Vec6 wrenchOnBody(const Model& model, const Workspace& ws, int frame, Expressed expressed, const Vec6& w) {
  const Frame& f = model.frame(frame);
  Vec6 local = w;
  if (expressed != Expressed::Local) {
    const Mat3 Rt = frameRotation(model, ws, frame).transpose();
    local << Rt * w.head<3>(), Rt * w.tail<3>();
  }
  return f.placement.inverseApplyForce(local);
}

// Subtract the task's external wrenches from Fbias (line 7: F_bias −= ⁱX₀* F_ext).
void applyExternalWrenches(const Model& model, const Task& task, Workspace& ws);

// Gravity as the base acceleration Ẍ₀ = [−g; 0] (SPEC): its shift of body i's
// sweep acceleration, ⁱX₀ Ẍ₀.
inline Vec6 gravityShift(const Workspace& ws, int body, const Vec3& gravity) {
  Vec6 out;
  out << ws.Xworld[static_cast<std::size_t>(body)].E * (-gravity), Vec3::Zero();
  return out;
}

}  // namespace zwang::internal
