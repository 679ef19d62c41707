// The kinematics accessors return a Status and write an output parameter
// (issue #6: noexcept, no allocation). Tests that only want the value use
// these: the value, or a std::runtime_error carrying the Status message when
// the call fails (Catch2 reports it as a failed test). Not for the hot-path
// tests (test/alloc), which call the accessors themselves. They read the
// state the workspace holds (Workspace::kinematics): the last call's.
#pragma once

#include "zwang/zwang.hpp"

namespace zwang::testing {

Eigen::Isometry3d poseOf(const Model& model, const Workspace& ws, int frame);
Vec6 velocityOf(const Model& model, const Workspace& ws, int frame, Expressed expressed);
Vec6 accelerationOf(const Model& model, const Workspace& ws, int frame, Expressed expressed);

}  // namespace zwang::testing
