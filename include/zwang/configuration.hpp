/// \file
/// Configuration helpers: integrate a velocity into a configuration, take the
/// difference of two configurations, and make neutral, random, normalised and
/// checked configurations, joint by joint for every joint type anywhere in the
/// tree, a floating base's root joint included (docs/conventions.md,
/// "Configuration helpers" and "Joint types").
///
/// Layout: q = each joint's nq() coordinates from its q_index, v = its nv()
/// velocity coordinates from its v_index, in Model::allJoints() order (a
/// floating base's root joint first: lengths Model::nq() and Model::nv()).
///   Free      : q = [x, y, z, q_w, q_x, q_y, q_z], the child origin in the
///               joint frame (for the root: the base origin in the world) and
///               the unit quaternion of the child's orientation R (child →
///               joint frame, w first); v = [v; ω], the velocity of the child
///               origin and the angular velocity, both in child axes, so
///               ṗ = R v and Ṙ = R [ω]×.
///   Spherical : q = [q_w, q_x, q_y, q_z], the orientation's unit quaternion;
///               v = ω in child axes (Ṙ = R [ω]×).
///   Planar    : q = [x, y, ψ], v = [ẋ, ẏ, ψ̇], in the joint frame's axes (for
///               the root: the plane's, Model::basePlacement()).
///   One-DOF   : q = the angle or displacement, v = its rate.
#pragma once

#include <cstdint>

#include <Eigen/Core>

#include "zwang/model.hpp"
#include "zwang/status.hpp"

namespace zwang {

// Every function here is noexcept and allocates nothing: bad input comes back
// as a Status naming the input and the entry at fault (SizeMismatch, NonFinite,
// BadConfiguration), never as an exception. On an error the output is left unchanged.

/// How far the norm of a quaternion (free and spherical joints) may be from 1 before
/// checkConfiguration (and with it every helper here and the solver) refuses q.
/// A unit quaternion stored in float32 comes back with a norm within about
/// 6e-8 of 1, and a few hundred float32 operations on it stay within a few
/// 1e-7; a long integration that renormalises now and then drifts by rounding
/// (about 1e-16 a step). A norm further off than 1e-6 is not rounding but a
/// quaternion that was never normalised (or not a quaternion at all):
/// normalizeConfiguration fixes the first, only the caller the second.
constexpr double kQuaternionNormTolerance = 1e-6;

/// q_out = q ⊕ v·dt: the configuration reached from q by moving with the
/// constant velocity v for the time dt (dt may be negative or zero).
///   Free      : the exact motion under the constant child-frame twist [v; ω]:
///               R_out = R·exp([ω dt]×), p_out = p + R·V(ω dt)·v dt, with V the
///               left Jacobian of SO(3) (the SE(3) exponential, as Pinocchio's
///               integrate for a free-flyer); the quaternion is renormalised.
///   Spherical : R_out = R·exp([ω dt]×), the quaternion renormalised.
///   Planar    : x += ẋ dt, y += ẏ dt, ψ += ψ̇ dt (ψ is not wrapped): the rates
///               are in the joint frame's axes, so constant rates move on a line.
///   One-DOF   : q += q̇ dt; then every mimic joint is set from its leader
///               (its own entry of v is ignored).
/// q must pass checkConfiguration; v must have nv() finite entries; dt finite.
/// q_out (nq() entries) may be the same vector as q.
Status integrate(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q,
                 const Eigen::Ref<const Eigen::VectorXd>& v, double dt, Eigen::Ref<Eigen::VectorXd> q_out) noexcept;

/// v_out = q1 ⊖ q0: the velocity with integrate(q0, v_out, 1) = q1.
///   Free      : the SE(3) logarithm of the relative pose M0⁻¹·M1, the shortest
///               rotation (angle in [0, π]); integrate may give back −quaternion
///               of q1 (the same orientation) when the angle is π.
///   Spherical : ω = log(R0ᵀ R1), the shortest rotation (the same caveat at π).
///   Planar    : x1 − x0, y1 − y0 and ψ1 − ψ0 wrapped into (−π, π], so
///               integrate gives back ψ1 up to a multiple of 2π.
///   One-DOF   : q1 − q0 (continuous joints too: their angles are not wrapped).
/// q0 and q1 must pass checkConfiguration; v_out has nv() entries and must not
/// share memory with q0 or q1.
Status difference(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q0,
                  const Eigen::Ref<const Eigen::VectorXd>& q1, Eigen::Ref<Eigen::VectorXd> v_out) noexcept;

/// u̇ for q(t) = q₀ ⊕ u(t) moving with the velocity v (q₀ fixed; u, v, u̇_out
/// nv() entries each, u̇_out not sharing memory with them): what a Runge–Kutta
/// step on the configuration space integrates (the Munthe-Kaas form: u
/// starts at 0 each step, q = q₀ ⊕ u stays on the space, quaternions unit).
///   Spherical : dexp⁻¹_u(ω) = ω + ½ u × ω + (1/12) u × (u × ω), the inverse
///               right Jacobian of SO(3) to second order in u;
///   Free      : the same series in the bracket of se(3), with u = [ρ; φ] and
///               v = [v; ω]: [u, v] = [φ × v + ρ × ω; φ × ω];
///   Planar, one-DOF : v itself (their coordinates add).
/// Second order in u is what a method of order four needs (the terms left
/// out are O(h³) in a step of length h and enter its error at O(h⁵):
/// Munthe-Kaas, "High order Runge–Kutta methods on manifolds", 1999).
Status tangentRate(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& u,
                   const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::Ref<Eigen::VectorXd> u_dot_out) noexcept;

/// The neutral configuration: every multi-DOF joint (the base's root joint
/// too) at the origin of its joint frame with the identity orientation (q_w =
/// 1, ψ = 0), each one-DOF joint at 0 clamped into its limits. A leader is clamped into the range that also keeps
/// its mimic joints within theirs, when there is one; every mimic joint is then
/// set from its leader (the law wins over the mimic joint's own limits when
/// they cannot both hold). q_out has nq() entries.
Status neutralConfiguration(const Model& model, Eigen::Ref<Eigen::VectorXd> q_out) noexcept;

/// A random configuration drawn from `state` (advanced; the same state gives
/// the same q on every platform), joint by joint in allJoints() order:
///   Free      : x, y, z uniform in [−1, 1] m, then a uniform random unit
///               quaternion (Shoemake's method, three draws);
///   Spherical : a uniform random unit quaternion (Shoemake, three draws);
///   Planar    : x, y uniform in [−1, 1] m, ψ uniform in [−π, π];
///   One-DOF   : one draw per independent joint, uniform in its
///               range: its limits (none for a continuous joint), narrowed to
///               keep the mimic joints that follow it within their limits when
///               that is possible; then each infinite end replaced so that the
///               range is at least 2h wide (h = π rad, or 1 m for prismatic
///               joints): lower by min(−h, upper − 2h), upper by max(h, lower +
///               2h). So continuous joints and joints without limits draw from
///               [−π, π] (prismatic: [−1, 1] m). Mimic joints draw nothing: they
///               are set from their leaders.
/// Each draw is u = (x >> 11)·2⁻⁵³ ∈ [0, 1), mapped to (1 − u)·lo + u·hi,
/// with x the next number of SplitMix64 (state += 0x9E3779B97F4A7C15, then two
/// xor-shift-multiply rounds): the same on every platform. q_out has nq() entries.
Status randomConfiguration(const Model& model, std::uint64_t& state, Eigen::Ref<Eigen::VectorXd> q_out) noexcept;

/// Normalise every quaternion of q (free and spherical joints, a free base's
/// entries 3–6 among them) in place; nothing else changes (without one: only
/// the size is checked). NonFinite when a quaternion entry is not finite,
/// BadConfiguration when a quaternion is zero; every quaternion is checked
/// before any is scaled, so an error leaves q unchanged.
Status normalizeConfiguration(const Model& model, Eigen::Ref<Eigen::VectorXd> q) noexcept;

/// Ok when q is a configuration of this model: nq() entries (SizeMismatch),
/// all finite (NonFinite, naming the entry and what it is: "base quaternion
/// x", "joint 'hip' quaternion w", "joint 'elbow'"), and every quaternion
/// (free and spherical joints) of norm within kQuaternionNormTolerance of 1
/// (BadConfiguration, naming the joint and entries, with the norm found, or
/// saying that it is zero). Joint limits and mimic laws are not
/// checked here: a solve reports joints outside their limits, and refuses a
/// mimic joint off its law (MimicMismatch) together with its velocity.
Status checkConfiguration(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q) noexcept;

}  // namespace zwang
