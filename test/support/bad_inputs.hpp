// Inputs the solver entry points must refuse, shared by the error-message
// test (test_stress_errors: the code and the words of each message) and the
// hot-path test (test/alloc/test_no_allocation: each error return allocates
// nothing). One table, so the two cannot drift apart.
#pragma once

#include <string>
#include <vector>

#include "zwang/zwang.hpp"

namespace zwang::testing {

// The models of models/ that the error tests use.
Model pandaModel();      // panda.urdf, 7 joints, 10 frames
Model oneDofArmModel();  // one_dof_arm.urdf, the report's 1-DOF arm

// Per-solve friction options solveWithFriction refuses with BadOption on the
// 7-joint Panda, each with the words of its message (which name the Panda's
// joints). Every option of FrictionOptions that can be out of range is here.
struct BadFrictionOption {
  FrictionOptions options;
  std::string message;
};
std::vector<BadFrictionOption> badFrictionOptions();

// The report's 1-DOF arm resting on its upper limit, no gravity, with a task
// that accelerates it into the limit (link1 angular z, b = 5 rad/s²):
// solveWithFriction(arm, ws, q, zero, zero, task) returns Infeasible with
// `message`, and finite outputs. Built in place (the workspace refers to the
// task's sizes): not copyable.
struct IntoUpperLimit {
  IntoUpperLimit();
  IntoUpperLimit(const IntoUpperLimit&) = delete;
  IntoUpperLimit& operator=(const IntoUpperLimit&) = delete;

  Model arm;
  Task task;
  Workspace ws;
  Eigen::VectorXd q, zero;
  std::string message;
};

}  // namespace zwang::testing
