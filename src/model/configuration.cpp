#include "zwang/configuration.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <Eigen/Geometry>

namespace zwang {
namespace {

using ConstVector = Eigen::Ref<const Eigen::VectorXd>;
using Vector = Eigen::Ref<Eigen::VectorXd>;

constexpr double kPi = 3.14159265358979323846;

// The series below replace closed forms that divide by θ (or θ²) and lose all
// their digits as θ → 0. Below θ = 1e-3 the first omitted term is of order
// θ⁶/10⁶ ≈ 1e-24 relative to the leading one, far under rounding; above it
// the closed forms lose at most about eps/θ² · θ² = eps absolute, since each
// coefficient multiplies a term of size θ² (or θ).
constexpr double kSeriesBelow = 1e-3;

// What q[k] or v[k] is, for messages: "base quaternion w", "joint 'elbow'".
struct EntryName {
  char text[96] = {};
};

// Entry k of a state vector whose first `base` entries are the base's, named
// by `base_names` (free or planar), the rest one per joint.
EntryName stateEntry(const Model& model, Eigen::Index k, int base, const char* const* free_names,
                     const char* const* planar_names) {
  EntryName name;
  if (k < base)
    std::snprintf(name.text, sizeof name.text, "%s",
                  model.baseType() == BaseType::Free ? free_names[std::min<Eigen::Index>(k, 6)]
                                                     : planar_names[std::min<Eigen::Index>(k, 2)]);
  else
    std::snprintf(name.text, sizeof name.text, "joint '%.60s'",
                  model.joints()[static_cast<std::size_t>(k - base)].name.c_str());
  return name;
}

EntryName configurationEntry(const Model& model, Eigen::Index k) {
  static const char* const kFree[] = {"base position x",   "base position y",   "base position z",  "base quaternion w",
                                      "base quaternion x", "base quaternion y", "base quaternion z"};
  static const char* const kPlanar[] = {"base x", "base y", "base yaw psi"};
  return stateEntry(model, k, model.baseConfigurationSize(), kFree, kPlanar);
}

EntryName velocityEntry(const Model& model, Eigen::Index k) {
  static const char* const kFree[] = {"base linear velocity x (base axes)",  "base linear velocity y (base axes)",
                                      "base linear velocity z (base axes)",  "base angular velocity x (base axes)",
                                      "base angular velocity y (base axes)", "base angular velocity z (base axes)"};
  static const char* const kPlanar[] = {"base x rate", "base y rate", "base yaw rate"};
  return stateEntry(model, k, model.baseVelocitySize(), kFree, kPlanar);
}

Status checkConfigurationSize(const Model& model, const char* what, Eigen::Index size) {
  if (size == model.nq()) return {};
  if (!model.hasFloatingBase())  // worded as the solver's other state vectors are
    return Status::error(StatusCode::SizeMismatch, "%s has %ld entries, the model has %d joints", what,
                         static_cast<long>(size), model.dof());
  return Status::error(StatusCode::SizeMismatch,
                       "%s has %ld entries, the model has nq = %d (%d base coordinates + %d joints)", what,
                       static_cast<long>(size), model.nq(), model.baseConfigurationSize(), model.dof());
}

Status checkVelocity(const Model& model, const char* what, const ConstVector& v) {
  if (v.size() != model.nv() && !model.hasFloatingBase())
    return Status::error(StatusCode::SizeMismatch, "%s has %ld entries, the model has %d joints", what,
                         static_cast<long>(v.size()), model.dof());
  if (v.size() != model.nv())
    return Status::error(StatusCode::SizeMismatch,
                         "%s has %ld entries, the model has nv = %d (%d base velocity coordinates + %d joints)", what,
                         static_cast<long>(v.size()), model.nv(), model.baseVelocitySize(), model.dof());
  for (Eigen::Index k = 0; k < v.size(); ++k)
    if (!std::isfinite(v[k]))
      return Status::error(StatusCode::NonFinite, "%s[%ld] (%s) is %g (not finite)", what, static_cast<long>(k),
                           velocityEntry(model, k).text, v[k]);
  return {};
}

// The norm of the 4 entries from q[3], robust to overflow and underflow
// (scaled by the largest entry first); the entries must be finite.
double quaternionNorm(const ConstVector& q) {
  const double scale = q.segment<4>(3).cwiseAbs().maxCoeff();
  return scale == 0.0 ? 0.0 : scale * (q.segment<4>(3) / scale).norm();
}

// checkConfiguration with the input's name in the messages ("q", "q0", …).
Status checkConfigurationNamed(const Model& model, const char* what, const ConstVector& q) {
  if (Status s = checkConfigurationSize(model, what, q.size()); !s) return s;
  for (Eigen::Index k = 0; k < q.size(); ++k)
    if (!std::isfinite(q[k]))
      return Status::error(StatusCode::NonFinite, "%s[%ld] (%s) is %g (not finite)", what, static_cast<long>(k),
                           configurationEntry(model, k).text, q[k]);
  if (model.baseType() == BaseType::Free) {
    const double norm = quaternionNorm(q);
    if (norm == 0.0)
      return Status::error(StatusCode::BadConfiguration,
                           "%s: base quaternion (entries 3-6, w x y z) is zero: not an orientation (the identity is "
                           "w = 1, x = y = z = 0)",
                           what);
    if (!(std::abs(norm - 1.0) <= kQuaternionNormTolerance))
      return Status::error(StatusCode::BadConfiguration,
                           "%s: base quaternion (entries 3-6, w x y z) has norm %.9g, not 1 within %g "
                           "(normalizeConfiguration fixes it)",
                           what, norm, kQuaternionNormTolerance);
  }
  return {};
}

// The unit quaternion of a configuration already checked (its norm is within
// kQuaternionNormTolerance of 1: made exactly unit, so R is a rotation).
Eigen::Quaterniond baseQuaternion(const ConstVector& q) {
  Eigen::Quaterniond Q(q[3], q[4], q[5], q[6]);
  Q.normalize();
  return Q;
}

// exp([w]×) as a unit quaternion: [cos(θ/2), sin(θ/2)/θ · w], θ = |w|.
Eigen::Quaterniond expRotation(const Vec3& w) {
  const double theta = w.norm();
  const double t2 = theta * theta;
  const double half_sinc = theta < kSeriesBelow ? 0.5 - t2 / 48.0 + t2 * t2 / 3840.0 : std::sin(0.5 * theta) / theta;
  const Vec3 xyz = half_sinc * w;
  return Eigen::Quaterniond(std::cos(0.5 * theta), xyz.x(), xyz.y(), xyz.z());
}

// V(w) u, V = 1 + (1 − cos θ)/θ² [w]× + (θ − sin θ)/θ³ [w]×²: the left Jacobian
// of SO(3), which turns the body-frame linear displacement of a constant twist
// into the displacement of the origin (in the start frame's axes).
Vec3 leftJacobianTimes(const Vec3& w, const Vec3& u) {
  const double theta = w.norm(), t2 = theta * theta;
  double a, b;
  if (theta < kSeriesBelow) {
    a = 0.5 - t2 / 24.0 + t2 * t2 / 720.0;
    b = 1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0;
  } else {
    const double s = std::sin(0.5 * theta);
    a = 2.0 * s * s / t2;  // 1 − cos θ = 2 sin²(θ/2), without the cancellation
    b = (theta - std::sin(theta)) / (t2 * theta);
  }
  const Vec3 wu = w.cross(u);
  return u + a * wu + b * w.cross(wu);
}

// V(w)⁻¹ u = u − ½ [w]× u + c [w]×² u, c = (1 − (θ/2) cot(θ/2))/θ², for θ ≤ π
// (V is singular only at θ = 2π, never reached by a logarithm).
Vec3 inverseLeftJacobianTimes(const Vec3& w, const Vec3& u) {
  const double theta = w.norm(), t2 = theta * theta;
  const double c = theta < kSeriesBelow ? 1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0
                                        : (1.0 - 0.5 * theta * std::cos(0.5 * theta) / std::sin(0.5 * theta)) / t2;
  const Vec3 wu = w.cross(u);
  return u - 0.5 * wu + c * w.cross(wu);
}

// log of a unit quaternion as a rotation vector, the shortest rotation (angle
// in [0, π]): Q and −Q are one rotation, so the one with w ≥ 0 is taken.
Vec3 logRotation(Eigen::Quaterniond Q) {
  if (Q.w() < 0.0) Q.coeffs() = -Q.coeffs();
  const double s = Q.vec().norm();
  // θ = 2 atan2(s, w), ω = θ/s · vec; atan2 keeps its relative accuracy for
  // tiny s, so θ/s is exact to rounding for every s > 0; s = 0 is the identity.
  const double theta_over_s = s > 0.0 ? 2.0 * std::atan2(s, Q.w()) / s : 2.0;
  return theta_over_s * Q.vec();
}

// ψ1 − ψ0 wrapped into (−π, π].
double wrapAngle(double d) {
  d = std::remainder(d, 2.0 * kPi);  // [−π, π]
  return d <= -kPi ? d + 2.0 * kPi : d;
}

// The range of independent joint j that keeps it and every mimic joint that
// follows it within their limits (q_m = a·q_j + b ∈ [lower_m, upper_m]). When
// the mimic laws and limits cannot all hold, the joint's own limits.
void leaderRange(const Model& model, int j, double& lo, double& hi) {
  const Joint& joint = model.joints()[static_cast<std::size_t>(j)];
  const double inf = std::numeric_limits<double>::infinity();
  const bool continuous = joint.type == JointType::Continuous;  // its limits, if any, mean nothing
  const double own_lo = continuous ? -inf : joint.lower, own_hi = continuous ? inf : joint.upper;
  lo = own_lo;
  hi = own_hi;
  for (const int m : model.mimicJoints()) {
    const Joint& mimic = model.joints()[static_cast<std::size_t>(m)];
    if (mimic.mimic.leader != j || mimic.type == JointType::Continuous) continue;
    const double a = mimic.mimic.multiplier, b = mimic.mimic.offset;
    if (a == 0.0) {  // q_m = b whatever the leader does: within its limits or never
      if (b < mimic.lower || b > mimic.upper) lo = inf, hi = -inf;
      continue;
    }
    const double from = (mimic.lower - b) / a, to = (mimic.upper - b) / a;  // ±∞ stay ±∞
    lo = std::max(lo, std::min(from, to));
    hi = std::min(hi, std::max(from, to));
  }
  if (!(lo <= hi)) lo = own_lo, hi = own_hi;
}

// The mimic joints set from their leaders (Model::followLeaders reads past the base's entries).
void followLeaders(const Model& model, Vector q) {
  Eigen::Map<Eigen::VectorXd> no_velocity(nullptr, 0);
  model.followLeaders(q, no_velocity);
}

// Uniform in [0, 1) from the top 53 bits of one draw.
double uniform01(std::uint64_t& state) { return static_cast<double>(splitMix64(state) >> 11) * 0x1.0p-53; }

// Uniform in [lo, hi); (1 − u)·lo + u·hi stays finite for any finite lo, hi.
double uniform(std::uint64_t& state, double lo, double hi) {
  const double u = uniform01(state);
  return (1.0 - u) * lo + u * hi;
}

}  // namespace

std::uint64_t splitMix64(std::uint64_t& state) noexcept {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

Status checkConfiguration(const Model& model, const ConstVector& q) noexcept {
  return checkConfigurationNamed(model, "q", q);
}

Status integrate(const Model& model, const ConstVector& q, const ConstVector& v, double dt, Vector q_out) noexcept {
  if (Status s = checkConfigurationNamed(model, "q", q); !s) return s;
  if (Status s = checkVelocity(model, "v", v); !s) return s;
  if (!std::isfinite(dt)) return Status::error(StatusCode::NonFinite, "dt is %g (not finite)", dt);
  if (Status s = checkConfigurationSize(model, "q_out", q_out.size()); !s) return s;

  // Everything is computed before q_out is touched (it may be q itself, and
  // an overflow must leave it unchanged).
  const int nqb = model.baseConfigurationSize(), nvb = model.baseVelocitySize();
  Eigen::Matrix<double, 7, 1> base;
  if (model.baseType() == BaseType::Free) {
    const Eigen::Quaterniond R = baseQuaternion(q);
    const Vec3 u = v.head<3>() * dt, w = v.segment<3>(3) * dt;
    base.head<3>() = q.head<3>() + R * leftJacobianTimes(w, u);
    const Eigen::Quaterniond R_out = (R * expRotation(w)).normalized();
    base.tail<4>() << R_out.w(), R_out.x(), R_out.y(), R_out.z();
  } else if (model.baseType() == BaseType::Planar) {
    // ẋ, ẏ are in the plane's axes (not the base's): constant rates move the
    // base on a straight line while it turns, so the exact step is linear.
    base.head<3>() = q.head<3>() + v.head<3>() * dt;
  }
  for (int k = 0; k < nqb; ++k)
    if (!std::isfinite(base[k]))
      return Status::error(StatusCode::NonFinite, "q_out[%d] (%s) would be %g: v*dt is too large", k,
                           configurationEntry(model, k).text, base[k]);
  for (int j = 0; j < model.dof(); ++j) {
    const double next = q[nqb + j] + v[nvb + j] * dt;
    if (!std::isfinite(next))
      return Status::error(StatusCode::NonFinite, "q_out[%d] (%s) would be %g: v*dt is too large", nqb + j,
                           configurationEntry(model, nqb + j).text, next);
  }

  q_out.head(nqb) = base.head(nqb);
  for (int j = 0; j < model.dof(); ++j) q_out[nqb + j] = q[nqb + j] + v[nvb + j] * dt;
  followLeaders(model, q_out);
  return {};
}

Status difference(const Model& model, const ConstVector& q0, const ConstVector& q1, Vector v_out) noexcept {
  if (Status s = checkConfigurationNamed(model, "q0", q0); !s) return s;
  if (Status s = checkConfigurationNamed(model, "q1", q1); !s) return s;
  if (v_out.size() != model.nv())
    return Status::error(StatusCode::SizeMismatch,
                         "v_out has %ld entries, the model has nv = %d (%d base velocity coordinates + %d joints)",
                         static_cast<long>(v_out.size()), model.nv(), model.baseVelocitySize(), model.dof());

  // Everything is computed and checked before v_out is touched: differences
  // of finite numbers may still overflow (1e308 − (−1e308)), and an error
  // leaves v_out unchanged.
  const int nqb = model.baseConfigurationSize(), nvb = model.baseVelocitySize();
  Vec6 base;
  if (model.baseType() == BaseType::Free) {
    // M0⁻¹ M1 = (R0ᵀ R1, R0ᵀ (p1 − p0)) = exp([u; w]) with ω = log(R0ᵀ R1) and
    // R0ᵀ (p1 − p0) = V(ω) u.
    const Eigen::Quaterniond R0 = baseQuaternion(q0), R1 = baseQuaternion(q1);
    const Vec3 w = logRotation(R0.conjugate() * R1);
    const Vec3 p = R0.conjugate() * Vec3(q1.head<3>() - q0.head<3>());
    base << inverseLeftJacobianTimes(w, p), w;
  } else if (model.baseType() == BaseType::Planar) {
    base.head<3>() << q1[0] - q0[0], q1[1] - q0[1], wrapAngle(q1[2] - q0[2]);
  }
  for (int k = 0; k < nvb; ++k)
    if (!std::isfinite(base[k]))
      return Status::error(StatusCode::NonFinite, "v_out[%d] (%s) would be %g: q1 and q0 are too far apart", k,
                           velocityEntry(model, k).text, base[k]);
  for (int j = 0; j < model.dof(); ++j)
    if (!std::isfinite(q1[nqb + j] - q0[nqb + j]))
      return Status::error(StatusCode::NonFinite, "v_out[%d] (%s) would be %g: q1 and q0 are too far apart", nvb + j,
                           velocityEntry(model, nvb + j).text, q1[nqb + j] - q0[nqb + j]);

  v_out.head(nvb) = base.head(nvb);
  v_out.tail(model.dof()) = q1.tail(model.dof()) - q0.tail(model.dof());
  return {};
}

Status neutralConfiguration(const Model& model, Vector q_out) noexcept {
  if (Status s = checkConfigurationSize(model, "q_out", q_out.size()); !s) return s;
  const int nqb = model.baseConfigurationSize();
  q_out.head(nqb).setZero();
  if (model.baseType() == BaseType::Free) q_out[3] = 1.0;  // identity quaternion, w first
  for (int j = 0; j < model.dof(); ++j) {
    double lo, hi;
    leaderRange(model, j, lo, hi);
    q_out[nqb + j] = std::min(std::max(0.0, lo), hi);
  }
  followLeaders(model, q_out);
  return {};
}

Status randomConfiguration(const Model& model, std::uint64_t& state, Vector q_out) noexcept {
  if (Status s = checkConfigurationSize(model, "q_out", q_out.size()); !s) return s;
  const int nqb = model.baseConfigurationSize();
  if (model.baseType() == BaseType::Free) {
    for (int k = 0; k < 3; ++k) q_out[k] = uniform(state, -1.0, 1.0);
    // Shoemake (1992): uniform on the unit sphere S³, so uniform over rotations.
    const double u1 = uniform01(state), u2 = uniform01(state), u3 = uniform01(state);
    const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
    Eigen::Quaterniond Q(b * std::cos(2.0 * kPi * u3), a * std::sin(2.0 * kPi * u2), a * std::cos(2.0 * kPi * u2),
                         b * std::sin(2.0 * kPi * u3));
    Q.normalize();  // unit to rounding already; exactly so for the tolerance check's sake
    q_out.segment<4>(3) << Q.w(), Q.x(), Q.y(), Q.z();
  } else if (model.baseType() == BaseType::Planar) {
    q_out[0] = uniform(state, -1.0, 1.0);
    q_out[1] = uniform(state, -1.0, 1.0);
    q_out[2] = uniform(state, -kPi, kPi);
  }
  for (int j = 0; j < model.dof(); ++j) {
    const Joint& joint = model.joints()[static_cast<std::size_t>(j)];
    if (joint.mimic.active()) continue;  // set from its leader below; no draw
    double lo, hi;
    leaderRange(model, j, lo, hi);
    // Continuous joints and joints without limits get [−h, h] from this.
    const double h = joint.isRevolute() ? kPi : 1.0;
    if (!std::isfinite(lo)) lo = std::min(-h, hi - 2.0 * h);
    if (!std::isfinite(hi)) hi = std::max(h, lo + 2.0 * h);
    q_out[nqb + j] = uniform(state, lo, hi);
  }
  followLeaders(model, q_out);
  return {};
}

Status normalizeConfiguration(const Model& model, Vector q) noexcept {
  if (Status s = checkConfigurationSize(model, "q", q.size()); !s) return s;
  if (model.baseType() != BaseType::Free) return {};
  for (int k = 3; k < 7; ++k)
    if (!std::isfinite(q[k]))
      return Status::error(StatusCode::NonFinite, "q[%d] (%s) is %g (not finite): the quaternion cannot be normalised",
                           k, configurationEntry(model, k).text, q[k]);
  const double norm = quaternionNorm(q);
  if (norm == 0.0)
    return Status::error(StatusCode::BadConfiguration,
                         "q: base quaternion (entries 3-6, w x y z) is zero: no orientation to normalise");
  q.segment<4>(3) /= norm;
  return {};
}

}  // namespace zwang
