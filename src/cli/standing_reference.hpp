// The standing balance written densely from the feet's Jacobians and RNEA,
// independently of the solver's sweeps, for what the standing report
// (energy_standing.cpp) prints from it: the best split of the ground's force.
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
// [0; μ]); τ₀ is its joint rows' part at μ = 0.
struct DenseBalance {
  Eigen::MatrixXd Gt_matrix;  // Gᵀ: nv × rows, the contacts' columns first, then the joint rows'
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> Gt;
  Eigen::VectorXd gravity;  // RNEA(q, 0, 0), nv
  Eigen::VectorXd tau0;     // τ_control(0)
};

// The balance at q for `feet` with contact_rows rows each (6: force and
// moment, 3: force), every joint with a joint row.
DenseBalance denseBalance(const Model& model, Workspace& ws, const std::vector<std::string>& feet, int contact_rows,
                          const Eigen::VectorXd& q, const std::string& context);

// The least ‖τ_control‖² over every split of the ground's force, without
// friction: ν = ν₀ + N z solves the balance for any z (N spans null(Gᵀ), the
// internal forces), and z is chosen for the least motor torques.
BestSplit bestSplit(const DenseBalance& d, int contact_rows);

}  // namespace zwang::cli::standing
