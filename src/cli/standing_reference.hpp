// The dense reference the standing report compares the solver against
// (energy_standing.cpp): the standing balance written densely from the feet's
// Jacobians and RNEA, independently of the solver's sweeps, with what the
// report prints from it: the least effort over the margin box, the best split
// of the ground's force and how far a μ is from the optimality conditions.
#pragma once

#include <string>
#include <vector>

#include <Eigen/QR>

#include "zwang/zwang.hpp"

namespace zwang::cli::standing {

// Plain, with the split of the ground's force that needs the least motor effort (bestSplit).
struct BestSplit {
  double sq = 0;          // ‖τ_control‖²
  double tangential = 0;  // the largest |horizontal force| / vertical force on a foot
};

// The standing balance written densely, independently of the solver's
// sweeps: the least-norm ν for a friction torque μ is Gᵀ⁺ (RNEA(q, 0, 0) +
// [0; μ]), so τ_control(μ) = τ₀ + M μ, its joint rows' part, is affine in μ.
struct DenseBalance {
  Eigen::MatrixXd Gt_matrix;  // Gᵀ: nv × rows, the contacts' columns first, then the joint rows'
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> Gt;
  Eigen::VectorXd gravity;  // RNEA(q, 0, 0), nv
  Eigen::VectorXd tau0;     // τ_control(0)
  Eigen::MatrixXd M;        // ∂τ_control/∂μ (n × n; the identity if the split did not move)
};

// RNEA with the ground wrenches on the feet: the generalized force the
// motors and friction must supply for q̈ = 0 (0 on the base when the ground
// carries the robot).
Eigen::VectorXd torquesWithGround(const Model& model, Workspace& ws, const std::vector<std::string>& feet,
                                  int contact_rows, const Eigen::VectorXd& q, const Eigen::VectorXd& ground);
// The balance at q for `feet` with contact_rows rows each (6: force and
// moment, 3: force), every joint with a joint row.
DenseBalance denseBalance(const Model& model, Workspace& ws, const std::vector<std::string>& feet, int contact_rows,
                          const Eigen::VectorXd& q, const std::string& context);

// The least ‖τ_control‖² over every split of the ground's force, without
// friction: ν = ν₀ + N z solves the balance for any z (N spans null(Gᵀ), the
// internal forces), and z is chosen for the least motor torques.
BestSplit bestSplit(const DenseBalance& d, int contact_rows);

// The worst violation of the optimality conditions of min ½‖τ₀ + M μ‖² over
// |μ_j| ≤ bound_j: the gradient Mᵀτ is 0 inside the box and points out of
// it on a bound [N·m].
double kktViolation(const DenseBalance& d, const Eigen::VectorXd& mu, const Eigen::VectorXd& bound);

// The least ‖τ_control(μ)‖² over the margin box, by projected gradient with
// the step 1/λ_max(MᵀM) (a convex quadratic: every step lowers it), until
// the optimality conditions hold to 1e-12 N·m (the gradient sums torques of
// at most a few hundred N·m, rounding at ~1e-13; the result is judged at
// the report's 1e-9) or 10⁵ steps. The reference for the friction-aware
// solve's pick.
Eigen::VectorXd leastEffort(const DenseBalance& d, const Eigen::VectorXd& bound);

}  // namespace zwang::cli::standing
