// What the two dense references (dense_reference.cpp, fixed base;
// floating_reference.cpp, floating base) compute the same way from the
// world-origin kinematics of every link (DenseKinematics: the Jacobians J_i have
// one column per entry of the velocity vector, base columns first): the
// external wrenches, the classical acceleration of a point, the rows of a
// relative constraint. For those two files only; tests use the references.
#pragma once

#include <vector>

#include "support/dense_reference.hpp"

namespace zwang::testing::reference_rows {

inline Eigen::Vector3d lin(const Vector6d& x) { return x.head<3>(); }
inline Eigen::Vector3d ang(const Vector6d& x) { return x.tail<3>(); }
inline Vector6d stack(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  Vector6d x;
  x << a, b;
  return x;
}

// ⁰R of the axes a constraint or wrench is given in: the world's, the link's,
// or (Axes::Reference) the reference link's (the world's when there is none).
Eigen::Matrix3d axesRotation(const DenseKinematics& kin, int link, Axes axes, int reference = -1);

// A wrench [f; n] acting at the link origin p, components per `axes`, as a
// Plücker force at the world origin: [f_w; n_w + p × f_w].
Vector6d wrenchAtWorldOrigin(const DenseKinematics& kin, int link, const Vector6d& w, Axes axes);

// Sum of the external Plücker wrenches on each link.
std::vector<Vector6d> externalWrenches(const ChainSpec& spec, const DenseKinematics& kin,
                                       const std::vector<WrenchInput>& wrenches);

// Classical acceleration [p̈; ω̇] (world axes) of the origin p of a link with
// spatial velocity v = [v_O; ω] and spatial acceleration a = [a_O; α] (both at
// the world origin): ṗ = v_O + ω × p, p̈ = a_O + α × p + ω × ṗ.
Vector6d classicalFromSpatial(const Eigen::Vector3d& p, const Vector6d& v, const Vector6d& a);

// Writes the rows of a relative constraint (ConstraintInput::relative_to) into
// G (one column per velocity entry) and γ from row first_row on.
void relativeRows(const ChainSpec& spec, const DenseKinematics& kin, const ConstraintInput& c, int first_row,
                  Eigen::MatrixXd& G, Eigen::VectorXd& gamma);

// σ_max/σ_min (1 for an empty matrix, ∞ for a singular one).
double conditionNumber(const Eigen::MatrixXd& M);

}  // namespace zwang::testing::reference_rows
