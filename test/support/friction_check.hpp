// Test helpers for zwang::solveWithFriction: what a result must satisfy,
// checked from the outside (no code shared with the solver).
//
// checkMaximumDissipation verifies a FrictionResult + Solution against the
// optimality conditions of docs/friction.md (maximum dissipation), per joint:
//   stuck set     = {j : |q̇_j| ≤ velocity_tolerance} (ascending), as expected;
//   Stick         ⇒ q̈_j ≈ 0 and |μ_j| ≤ f_j;
//   SlipPositive  ⇒ μ_j = f_j and q̈_j ≥ 0;
//   SlipNegative  ⇒ μ_j = −f_j and q̈_j ≤ 0;
//   AtLimit       ⇒ the joint rests on a limit, q̈_j ≈ 0 and μ_j lies beyond
//                   the friction bound on the limit's side (lower: μ_j ≤ −f_j,
//                   upper: μ_j ≥ f_j);
//   a stuck joint on its lower limit never has q̈_j < 0 (upper: > 0);
//   Moving        ⇒ μ_j = 0 and tau_friction_j = −f_c sign(q̇_j) − b q̇_j;
//   stuck         ⇒ tau_friction_j = −μ_j;
//   every number finite; kkt_residual small; τ_control = τ + τ_c.
// It returns a description of the first violation, or "" when all hold.
#pragma once

#include <string>
#include <vector>

#include "zwang/friction.hpp"
#include "zwang/zwang.hpp"

namespace zwang::testing {

// What the caller expects from the model, the state and the options — read
// straight from the Model's joints and the FrictionOptions overrides.
struct FrictionExpectation {
  std::vector<int> stuck;       // Θ₀
  Eigen::VectorXd breakaway;    // f_j
  Eigen::VectorXd kinetic;      // f_c,j
  Eigen::VectorXd viscous;      // b_j
  Eigen::VectorXd tau_kinetic;  // −f_c sign q̇ − b q̇ on moving joints, 0 on stuck ones
  Eigen::VectorXi limit_side;   // −1: stuck on the lower limit, +1: upper, 0: neither (or limits off)
  Eigen::VectorXd tau;          // the feed-forward τ (for τ_control = τ + τ_c)
};

FrictionExpectation expectFriction(const Model& model, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                                   const Eigen::VectorXd& tau, const FrictionOptions& options = {});

struct DissipationTolerances {
  double acceleration = 1e-8;  // on q̈ signs and q̈ = 0, × max(1, max |q̈|)
  double torque = 1e-8;        // on μ bounds and equalities, × max(1, max f, max |μ|)
  double kkt = 1e-7;           // on FrictionResult::kkt_residual, × max(1, max |q̈|)
};

std::string checkMaximumDissipation(const FrictionResult& result, const Solution& solution,
                                    const FrictionExpectation& expected, const DissipationTolerances& tolerances = {});

// Closure with friction (docs/friction.md, "Outputs"): the unconstrained arm (same gravity and
// wrenches) driven by τ_control + tau_friction accelerates with q̈*. Returns
// relativeError(q̈_free, q̈*). Uses solveHybridDynamics only.
double frictionClosureError(const Model& model, const Task& task, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                            const FrictionResult& result, const Solution& solution);

}  // namespace zwang::testing
