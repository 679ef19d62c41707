// Validation helpers shared by the builder and the URDF loader (not installed).
#pragma once

#include <string>
#include <vector>

#include "zwang/model.hpp"

namespace zwang::validate {
// The heaviest link and the largest moment of inertia zwang accepts [kg, kg·m²].
constexpr double kMaxMass = 1e12;
constexpr double kMaxMoment = 1e12;  // the largest moment of inertia [kg·m²]
// The largest rotor inertia, friction and viscous friction: beyond it a solve's products (b·q̇) leave double's range.
constexpr double kMaxJointCoefficient = 1e12;

// Throws `ModelError("<where>: <what>")` when the inertia cannot be a body's:
// negative or non-finite mass, a mass above kMaxMass, non-finite or huge
// values, an asymmetric matrix or a principal moment at the COM that is
// negative beyond rounding. `rounding_scale` is the size of the numbers the
// COM inertia was computed from (kg·m²): moments within
// roundingTolerance(rounding_scale) of zero count as zero, so point masses,
// thin rods and inertias recovered from the origin form (I_c = Ī + m·c×c×)
// pass. Returns the warnings (triangle inequality, point mass, placeholder
// inertia) for the caller to record.
std::vector<ModelWarning> rigidInertia(const std::string& where, double mass, const Vec3& com, const Mat3& I_com,
                                       double rounding_scale = 0.0);
// The same for an inertia in origin form (m, h, Ī), as the builder holds it.
std::vector<ModelWarning> rigidInertia(const std::string& where, const RigidInertia& inertia);
// How far from zero a moment computed from numbers of size `scale` may land
// by rounding alone.
double roundingTolerance(double scale);
}  // namespace zwang::validate
