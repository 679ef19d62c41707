// Random dynamics problems (state, torques, wrenches, constraints) on a
// ChainSpec, and their translation into zwang's Model and Task.
#pragma once

#include <random>

#include "support/dense_reference.hpp"
#include "zwang/zwang.hpp"

namespace zwang::testing {

struct RandomProblemOptions {
  int max_constraint_rows = 6;  // 0..max rows in all
  int max_constraint_frames = 3;
  int max_wrenches = 2;
  bool end_effector_only = false;  // all constraint rows on the last link (KDL's case)
  double gravity_probability = 0.8;
};

// q, q̇, τ, gravity, wrenches and constraints drawn for `spec`. Constraint
// columns are random unit 6-vectors or axis-aligned unit forces/moments;
// targets and wrenches of a few units.
DynamicsInput randomProblem(std::mt19937_64& rng, const ChainSpec& spec, const RandomProblemOptions& options = {});

// The chain through the URDF loader (writer → loader: both are exercised).
Model modelFromSpec(const ChainSpec& spec);

// The same problem as a zwang Task (rows in the same order).
Task taskFromInput(const Model& model, const DynamicsInput& input);

// max |x − y| / max(1, max |y|): error relative to the magnitudes involved.
double relativeError(const Eigen::VectorXd& x, const Eigen::VectorXd& y);

}  // namespace zwang::testing
