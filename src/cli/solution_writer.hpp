// The solution JSON of `zwang solve` (docs/cli.md, "Solution").
#pragma once

#include <vector>

#include "json_reader.hpp"
#include "zwang/zwang.hpp"

namespace zwang::cli {

// A JSON array of the vector's numbers.
Json array(const Eigen::Ref<const Eigen::VectorXd>& v);

// Keys, in this order: joints, dofs (the names of the per-DOF entries), qdd,
// tau_constraint, tau_control (per DOF below the root),
// base (only for a floating base: its type, acceleration, acceleration_world,
// tau_constraint, tau_control), nu, gauss, friction (only when
// `with_friction`), status, frames (each of `frames`: acceleration_world; those
// of `constrained_frames` also wrench_world and wrench_local, the constraint
// wrench of `task`), com (the robot's centre of mass: position,
// velocity, acceleration; null without moving mass). Numbers are written
// by nlohmann::json in their shortest form that reads back exactly.
Json solutionJson(const Model& model, const Workspace& ws, const Task& task, bool with_friction, const Status& status,
                  const std::vector<int>& frames, const std::vector<int>& constrained_frames);

// Indented JSON for humans (--pretty): objects one key per line, arrays of
// numbers, strings or booleans on one line.
std::string prettyDump(const Json& value);

}  // namespace zwang::cli
