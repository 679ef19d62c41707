// Random dynamics problems (state, torques, wrenches, constraints) on a
// ChainSpec, and their translation into zwang's Model and Task.
#pragma once

#include <random>

#include "support/dense_reference.hpp"
#include "support/floating_reference.hpp"
#include "zwang/zwang.hpp"

namespace zwang::testing {

struct RandomProblemOptions {
  int max_constraint_rows = 6;  // 0..max rows in all
  int max_constraint_frames = 3;
  int max_wrenches = 2;
  bool end_effector_only = false;  // all constraint rows on the last link (KDL's case)
  double gravity_probability = 0.8;
  double relative_probability = 0.0;  // that a constraint is relative to another random link (or the base)
};

// q, q̇, τ, gravity, wrenches and constraints drawn for `spec`. Constraint
// columns are random unit 6-vectors or axis-aligned unit forces/moments;
// targets and wrenches of a few units. Mimic joints' q and q̇ follow their
// leaders (ChainSpec::followMimicLaws; no draws of their own beyond the rest).
DynamicsInput randomProblem(std::mt19937_64& rng, const ChainSpec& spec, const RandomProblemOptions& options = {});

// The chain through the URDF loader (writer → loader: both are exercised,
// <mimic> included); a tree through the ModelBuilder (modelFromSpecByBuilder).
Model modelFromSpec(const ChainSpec& spec);
// The spec built joint by joint with the ModelBuilder, as the URDF loader
// would; then ModelBuilder::setMimic for each mimic joint, as written.
Model modelFromSpecByBuilder(const ChainSpec& spec);

// The same problem as a zwang Task (rows in the same order).
Task taskFromInput(const Model& model, const DynamicsInput& input);

// The spec's model (modelFromSpecByBuilder, with the root link's own inertia
// in body 0) with its base let float as `base` says, and a floating problem
// as a zwang Task (rows in the same order).
Model floatingModelFromSpec(const ChainSpec& spec, const FloatingBase& base);
Task floatingTaskFromInput(const Model& model, const FloatingInput& input);

// A draw the solver comparisons keep (test_dense, test_kdl): the dense KKT
// system well conditioned (condition at most 1e6) and every constraint row
// reachable — G (the input's rows and the mimic rows) of full row rank with
// its smallest singular value at least 1e-6 (a row the joints cannot affect, e.g. a moment about a prismatic-only
// chain, has G ≈ 0 and is singular by nature).
bool wellPosed(const DenseResult& dense, const DynamicsInput& input);

// A random inverse-dynamics case (test_dense, test_kdl): a chain, a problem
// on it (state, gravity, wrenches), zwang's model, task and workspace for it,
// and q̈ of a few units; the draws in that order. Built in place.
struct RandomInverseDynamics {
  explicit RandomInverseDynamics(std::mt19937_64& rng);
  RandomInverseDynamics(const RandomInverseDynamics&) = delete;
  RandomInverseDynamics& operator=(const RandomInverseDynamics&) = delete;

  ChainSpec spec;
  DynamicsInput in;
  Model model;
  Task task;
  Workspace ws;
  Eigen::VectorXd qdd;

  // zwang's RNEA for the case: τ into ws.tau.
  Status solve();
};

// max |x − y| / max(1, max |y|): error relative to the magnitudes involved.
double relativeError(const Eigen::VectorXd& x, const Eigen::VectorXd& y);

}  // namespace zwang::testing
