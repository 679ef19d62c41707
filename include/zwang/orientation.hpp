/// \file
/// Orientation helpers for controllers: the rotation vector (the logarithm of
/// a rotation) and its inverse (the exponential), the orientation error
/// between two rotations, and quaternion conversions between zwang's order
/// and the other common one.
///
/// Quaternion order: zwang stores a quaternion **w first**, [w, x, y, z], as
/// MuJoCo does (q of a spherical or free joint, docs/conventions.md). SciPy's
/// `Rotation.as_quat()`, ROS's `geometry_msgs/Quaternion` fields in order,
/// Pinocchio's configuration vectors and Eigen's `Quaterniond::coeffs()` put
/// it **last**, [x, y, z, w]. The two conversion functions name both orders,
/// so that a call reads the way the data flows. (Eigen's constructor
/// `Quaterniond(w, x, y, z)` takes w first, while its coeffs() return it last.)
///
/// A rotation vector φ is the axis times the angle [rad], `R = exp([φ]×)`;
/// the logarithm returns the shortest one, |φ| in [0, π]. At exactly a half
/// turn the axis' sign is arbitrary (both give the same rotation). Every
/// function is noexcept and allocates nothing.
#pragma once

#include <Eigen/Core>

namespace zwang {

/// [w, x, y, z] (zwang's, MuJoCo's) from [x, y, z, w] (SciPy's as_quat(), ROS's, Pinocchio's, Eigen's coeffs()).
Eigen::Vector4d quaternionWxyzFromXyzw(const Eigen::Vector4d& xyzw) noexcept;
/// [x, y, z, w] (SciPy's, ROS's, Pinocchio's, Eigen's coeffs()) from [w, x, y, z] (zwang's, MuJoCo's).
Eigen::Vector4d quaternionXyzwFromWxyz(const Eigen::Vector4d& wxyz) noexcept;

/// The rotation vector φ of a rotation matrix (orthonormal, det +1): log(R),
/// |φ| in [0, π], accurate to rounding near 0 and near π (it goes through the
/// quaternion of R, whose largest component is taken first, then 2·atan2).
Eigen::Vector3d rotationLog(const Eigen::Matrix3d& R) noexcept;
/// The rotation vector of a quaternion [w, x, y, z] (any non-zero norm: it is
/// normalised first; q and −q give the same φ, |φ| in [0, π]). The zero
/// quaternion gives the zero vector.
Eigen::Vector3d quaternionLog(const Eigen::Vector4d& wxyz) noexcept;
/// exp([φ]×): the rotation matrix of a rotation vector (any length; a series
/// near 0).
Eigen::Matrix3d rotationExp(const Eigen::Vector3d& phi) noexcept;
/// The unit quaternion [w, x, y, z] of exp([φ]×), w ≥ 0 when |φ| ≤ π.
Eigen::Vector4d quaternionExp(const Eigen::Vector3d& phi) noexcept;

/// The orientation error of a frame at R_current from R_desired (both frame →
/// world), as a rotation vector in **world axes**: e = log(R_desired
/// R_currentᵀ), the rotation that, applied in the world, turns the current
/// orientation into the desired one (exp([e]×) R_current = R_desired). A
/// proportional controller commands ω = K e. In the frame's own axes it is
/// R_currentᵀ e = log(R_currentᵀ R_desired).
Eigen::Vector3d orientationError(const Eigen::Matrix3d& R_current, const Eigen::Matrix3d& R_desired) noexcept;

}  // namespace zwang
