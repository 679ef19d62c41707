#include "zwang/configuration.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include <Eigen/Geometry>

#include "model/split_mix64.hpp"

namespace zwang {
namespace {

using ConstVector = Eigen::Ref<const Eigen::VectorXd>;
using Vector = Eigen::Ref<Eigen::VectorXd>;
using ConstVec3Map = Eigen::Map<const Vec3>;
using Vec3Map = Eigen::Map<Vec3>;

constexpr double kPi = 3.14159265358979323846;

// The series below replace closed forms that divide by θ (or θ²) and lose all
// their digits as θ → 0. Below θ = 1e-3 the first omitted term is of order
// θ⁶/10⁶ ≈ 1e-24 relative to the leading one, far under rounding; above it
// the closed forms lose at most about eps/θ² · θ² = eps absolute, since each
// coefficient multiplies a term of size θ² (or θ).
constexpr double kSeriesBelow = 1e-3;

// The most coordinates one joint has (a free joint's q).
constexpr int kMaxJointCoordinates = 7;

// No joint's integrate or difference overflows when every entry of q (q0, q1)
// and v·dt is at most this large: the largest intermediate, a free joint's
// [w]×²u with |w|, |u| ≤ √3·1e100, stays under 1e301.
constexpr double kCannotOverflow = 1e100;

double largestMagnitude(const ConstVector& x) { return x.size() == 0 ? 0.0 : x.cwiseAbs().maxCoeff(); }

// ---- What each joint type's coordinates are (the one place a new type adds its names)

// Where a joint's unit quaternion starts among its own q entries; −1: it has none.
int quaternionOffset(JointType type) {
  switch (type) {
    case JointType::Spherical: return 0;
    case JointType::Free: return 3;
    default: return -1;
  }
}

// The name of coordinate `index` of a multi-DOF joint's q (or v); nullptr for
// a one-DOF joint, whose name alone names its entry.
const char* coordinateName(JointType type, int index, bool velocity) {
  static const char* const kFreeQ[] = {"position x",   "position y",   "position z",  "quaternion w",
                                       "quaternion x", "quaternion y", "quaternion z"};
  static const char* const kFreeV[] = {"linear velocity x",  "linear velocity y",  "linear velocity z",
                                       "angular velocity x", "angular velocity y", "angular velocity z"};
  static const char* const kPlanarQ[] = {"x", "y", "yaw psi"};
  static const char* const kPlanarV[] = {"x rate", "y rate", "yaw rate"};
  switch (type) {
    case JointType::Spherical: return velocity ? kFreeV[3 + index] : kFreeQ[3 + index];
    case JointType::Planar: return velocity ? kPlanarV[index] : kPlanarQ[index];
    case JointType::Free: return velocity ? kFreeV[index] : kFreeQ[index];
    default: return nullptr;
  }
}

// ---- Messages

// What q[k] or v[k] is, for messages: "base quaternion w", "joint 'hip'
// quaternion w", "joint 'elbow'".
struct EntryName {
  char text[128] = {};
};

bool isRoot(const Model& model, const Joint& joint) {
  return model.hasFloatingBase() && &joint == &model.allJoints().front();
}

// Who owns a coordinate: "base" for a floating base's root joint, else "joint '<name>'".
EntryName ownerName(const Model& model, const Joint& joint) {
  EntryName name;
  if (isRoot(model, joint))
    std::snprintf(name.text, sizeof name.text, "base");
  else
    std::snprintf(name.text, sizeof name.text, "joint '%.60s'", joint.name.c_str());
  return name;
}

// Entry `entry` of q (or of v) of the model: its joint and that joint's coordinate.
// Angular and free-joint linear velocities are in the child's axes: the root
// joint's child is the base.
EntryName entryName(const Model& model, Eigen::Index entry, bool velocity) {
  const Joint* owner = &model.allJoints().back();
  for (const Joint& joint : model.allJoints())
    if (entry < (velocity ? joint.v_index + joint.nv() : joint.q_index + joint.nq())) {
      owner = &joint;
      break;
    }
  const int index = static_cast<int>(entry) - (velocity ? owner->v_index : owner->q_index);
  const char* coordinate = coordinateName(owner->type, index, velocity);
  const bool child_axes = velocity && (owner->type == JointType::Free || owner->type == JointType::Spherical);
  EntryName name = ownerName(model, *owner);
  if (coordinate != nullptr) {
    const std::size_t used = std::strlen(name.text);
    std::snprintf(name.text + used, sizeof name.text - used, " %s%s", coordinate,
                  !child_axes             ? ""
                  : isRoot(model, *owner) ? " (base axes)"
                                          : " (child axes)");
  }
  return name;
}

EntryName configurationEntry(const Model& model, Eigen::Index entry) { return entryName(model, entry, false); }
EntryName velocityEntry(const Model& model, Eigen::Index entry) { return entryName(model, entry, true); }

// `what` has the wrong size: say what the model's nq (or nv) entries are,
// worded as the solver's other state vectors are (dynamics/checks.cpp).
Status sizeMismatch(const Model& model, const char* what, Eigen::Index size, bool velocity) {
  const int n = velocity ? model.nv() : model.nq();
  const int base = velocity ? model.baseVelocitySize() : model.baseConfigurationSize();
  const int joints = static_cast<int>(model.joints().size());
  const long given = static_cast<long>(size);
  if (base == 0 && n == joints)  // one-DOF joints on a fixed base
    return Status::error(StatusCode::SizeMismatch, "%s has %ld entries, the model has %d joints", what, given, joints);
  // "joints" while every joint below the root has one coordinate, else what they have.
  const char* below = n - base == joints ? "joints" : velocity ? "joint DOFs" : "joint coordinates";
  return Status::error(StatusCode::SizeMismatch, "%s has %ld entries, the model has %s = %d (%d base %s + %d %s)", what,
                       given, velocity ? "nv" : "nq", n, base, velocity ? "velocity coordinates" : "coordinates",
                       n - base, below);
}

Status checkConfigurationSize(const Model& model, const char* what, Eigen::Index size) {
  return size == model.nq() ? Status{} : sizeMismatch(model, what, size, false);
}

Status checkVelocity(const Model& model, const char* what, const ConstVector& v) {
  if (v.size() != model.nv()) return sizeMismatch(model, what, v.size(), true);
  if (v.allFinite()) return {};  // the usual case: one vectorised pass
  for (Eigen::Index k = 0; k < v.size(); ++k)
    if (!std::isfinite(v[k]))
      return Status::error(StatusCode::NonFinite, "%s[%ld] (%s) is %g (not finite)", what, static_cast<long>(k),
                           velocityEntry(model, k).text, v[k]);
  return {};
}

// ---- Rotations

// The norm of the 4 entries from q, robust to overflow and underflow (scaled
// by the largest entry first); the entries must be finite.
double quaternionNorm(const double* q) {
  const Eigen::Map<const Eigen::Vector4d> Q(q);
  const double scale = Q.cwiseAbs().maxCoeff();
  return scale == 0.0 ? 0.0 : scale * (Q / scale).norm();
}

// The unit quaternion stored from q (w x y z) of a configuration already
// checked (its norm is within kQuaternionNormTolerance of 1: made exactly
// unit, so R is a rotation).
Eigen::Quaterniond quaternionAt(const double* q) {
  Eigen::Quaterniond Q(q[0], q[1], q[2], q[3]);
  Q.normalize();
  return Q;
}

void storeQuaternion(const Eigen::Quaterniond& Q, double* q) {
  q[0] = Q.w();
  q[1] = Q.x();
  q[2] = Q.y();
  q[3] = Q.z();
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

// ---- Random draws

// Uniform in [0, 1) from the top 53 bits of one draw.
double uniform01(std::uint64_t& state) { return static_cast<double>(internal::splitMix64(state) >> 11) * 0x1.0p-53; }

// Uniform in [lo, hi); (1 − u)·lo + u·hi stays finite for any finite lo, hi.
double uniform(std::uint64_t& state, double lo, double hi) {
  const double u = uniform01(state);
  return (1.0 - u) * lo + u * hi;
}

// A uniform random rotation as a unit quaternion stored from q (w x y z):
// Shoemake (1992), uniform on the unit sphere S³, three draws.
void randomQuaternion(std::uint64_t& state, double* q) {
  const double u1 = uniform01(state), u2 = uniform01(state), u3 = uniform01(state);
  const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
  Eigen::Quaterniond Q(b * std::cos(2.0 * kPi * u3), a * std::sin(2.0 * kPi * u2), a * std::cos(2.0 * kPi * u2),
                       b * std::sin(2.0 * kPi * u3));
  Q.normalize();  // unit to rounding already; exactly so for the tolerance check's sake
  storeQuaternion(Q, q);
}

// ---- One-DOF joints: limits and mimic laws

// The range of independent joint j (in joints()) that keeps it and every
// mimic joint that follows it within their limits (q_m = a·q_j + b ∈
// [lower_m, upper_m]). When the mimic laws and limits cannot all hold, the
// joint's own limits.
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

// The mimic joints set from their leaders (Model::followLeaders).
void followLeaders(const Model& model, Vector q) {
  Eigen::Map<Eigen::VectorXd> no_velocity(nullptr, 0);
  model.followLeaders(q, no_velocity);
}

// The index in joints() of allJoints()[j] (−1 for a floating base's root joint).
int jointIndexBelowRoot(const Model& model, std::size_t j) {
  return static_cast<int>(j) - (model.hasFloatingBase() ? 1 : 0);
}

// ---- The configuration operations of one joint, per type. Each reads the
// joint's own entries (q from q_index, v from v_index) and writes its nq()
// or nv() entries to `out`, which must not share memory with its inputs.

// out = q ⊕ v·dt.
void integrateJoint(JointType type, const double* q, const double* v, double dt, double* out) {
  switch (type) {
    case JointType::Revolute:
    case JointType::Continuous:
    case JointType::Prismatic: out[0] = q[0] + v[0] * dt; return;
    case JointType::Planar:
      // ẋ, ẏ are in the joint frame's axes (not the child's): constant rates
      // move the child on a straight line while it turns, so the exact step is linear.
      for (int k = 0; k < 3; ++k) out[k] = q[k] + v[k] * dt;
      return;
    case JointType::Spherical:  // R_out = R·exp([ω dt]×), ω in the child frame
      storeQuaternion((quaternionAt(q) * expRotation(ConstVec3Map(v) * dt)).normalized(), out);
      return;
    case JointType::Free: {  // the SE(3) exponential of the constant child-frame twist [v; ω]·dt
      const Eigen::Quaterniond R = quaternionAt(q + 3);
      const Vec3 u = ConstVec3Map(v) * dt, w = ConstVec3Map(v + 3) * dt;
      Vec3Map{out} = ConstVec3Map(q) + R * leftJacobianTimes(w, u);
      storeQuaternion((R * expRotation(w)).normalized(), out + 3);
      return;
    }
  }
}

// out = q1 ⊖ q0.
void differenceJoint(JointType type, const double* q0, const double* q1, double* out) {
  switch (type) {
    case JointType::Revolute:
    case JointType::Continuous:
    case JointType::Prismatic: out[0] = q1[0] - q0[0]; return;  // not wrapped, continuous joints neither
    case JointType::Planar:
      out[0] = q1[0] - q0[0];
      out[1] = q1[1] - q0[1];
      out[2] = wrapAngle(q1[2] - q0[2]);
      return;
    case JointType::Spherical: Vec3Map{out} = logRotation(quaternionAt(q0).conjugate() * quaternionAt(q1)); return;
    case JointType::Free: {
      // M0⁻¹ M1 = (R0ᵀ R1, R0ᵀ (p1 − p0)) = exp([u; w]) with ω = log(R0ᵀ R1)
      // and R0ᵀ (p1 − p0) = V(ω) u.
      const Eigen::Quaterniond R0 = quaternionAt(q0 + 3), R1 = quaternionAt(q1 + 3);
      const Vec3 w = logRotation(R0.conjugate() * R1);
      const Vec3 p = R0.conjugate() * Vec3(ConstVec3Map(q1) - ConstVec3Map(q0));
      Vec3Map{out} = inverseLeftJacobianTimes(w, p);
      Vec3Map{out + 3} = w;
      return;
    }
  }
}

// out = dexp⁻¹_u(v) to second order in u: v + ½[u, v] + (1/12)[u, [u, v]], [·,·] the joint's Lie bracket.
void tangentRateJoint(JointType type, const double* u, const double* v, double* out) {
  switch (type) {
    case JointType::Revolute:
    case JointType::Continuous:
    case JointType::Prismatic: out[0] = v[0]; return;
    case JointType::Planar:
      for (int k = 0; k < 3; ++k) out[k] = v[k];
      return;
    case JointType::Spherical: {  // so(3): [u, ω] = u × ω
      const Vec3 phi = ConstVec3Map(u), w = ConstVec3Map(v);
      const Vec3 bracket = phi.cross(w);
      Vec3Map{out} = w + 0.5 * bracket + phi.cross(bracket) / 12.0;
      return;
    }
    case JointType::Free: {  // se(3): [(ρ, φ), (v, ω)] = (φ × v + ρ × ω, φ × ω)
      const Vec3 rho = ConstVec3Map(u), phi = ConstVec3Map(u + 3), lin = ConstVec3Map(v), w = ConstVec3Map(v + 3);
      const Vec3 b_lin = phi.cross(lin) + rho.cross(w), b_ang = phi.cross(w);
      const Vec3 bb_lin = phi.cross(b_lin) + rho.cross(b_ang), bb_ang = phi.cross(b_ang);
      Vec3Map{out} = lin + 0.5 * b_lin + bb_lin / 12.0;
      Vec3Map{out + 3} = w + 0.5 * b_ang + bb_ang / 12.0;
      return;
    }
  }
}

// The neutral coordinates of allJoints()[j]: the identity pose, a one-DOF
// joint's 0 clamped into its (leader) range.
void neutralJoint(const Model& model, std::size_t j, double* out) {
  const Joint& joint = model.allJoints()[j];
  if (joint.nq() == 1) {
    double lo, hi;
    leaderRange(model, jointIndexBelowRoot(model, j), lo, hi);
    out[0] = std::min(std::max(0.0, lo), hi);
    return;
  }
  std::fill(out, out + joint.nq(), 0.0);
  if (const int at = quaternionOffset(joint.type); at >= 0) out[at] = 1.0;  // identity quaternion, w first
}

// Random coordinates of allJoints()[j], drawn in the order of its entries.
void randomJoint(const Model& model, std::size_t j, std::uint64_t& state, double* out) {
  const Joint& joint = model.allJoints()[j];
  switch (joint.type) {
    case JointType::Free:
      for (int k = 0; k < 3; ++k) out[k] = uniform(state, -1.0, 1.0);
      randomQuaternion(state, out + 3);
      return;
    case JointType::Spherical: randomQuaternion(state, out); return;
    case JointType::Planar:
      out[0] = uniform(state, -1.0, 1.0);
      out[1] = uniform(state, -1.0, 1.0);
      out[2] = uniform(state, -kPi, kPi);
      return;
    case JointType::Revolute:
    case JointType::Continuous:
    case JointType::Prismatic: {
      if (joint.mimic.active()) return;  // set from its leader afterwards; no draw
      double lo, hi;
      leaderRange(model, jointIndexBelowRoot(model, j), lo, hi);
      // Continuous joints and joints without limits get [−h, h] from this.
      const double h = joint.isRevolute() ? kPi : 1.0;
      if (!std::isfinite(lo)) lo = std::min(-h, hi - 2.0 * h);
      if (!std::isfinite(hi)) hi = std::max(h, lo + 2.0 * h);
      out[0] = uniform(state, lo, hi);
      return;
    }
  }
}

// A joint's quaternion in a message: "base quaternion (entries 3-6, w x y z)".
struct QuaternionName {
  char text[160] = {};
};
QuaternionName quaternionName(const Model& model, const Joint& joint) {
  QuaternionName name;
  const int first = joint.q_index + quaternionOffset(joint.type);
  std::snprintf(name.text, sizeof name.text, "%s quaternion (entries %d-%d, w x y z)", ownerName(model, joint).text,
                first, first + 3);
  return name;
}

// checkConfiguration with the input's name in the messages ("q", "q0", …).
Status checkConfigurationNamed(const Model& model, const char* what, const ConstVector& q) {
  if (Status s = checkConfigurationSize(model, what, q.size()); !s) return s;
  const bool finite = q.allFinite();  // the usual case: one vectorised pass; the loop names the entry
  for (Eigen::Index k = 0; !finite && k < q.size(); ++k)
    if (!std::isfinite(q[k]))
      return Status::error(StatusCode::NonFinite, "%s[%ld] (%s) is %g (not finite)", what, static_cast<long>(k),
                           configurationEntry(model, k).text, q[k]);
  if (model.nq() == model.nv()) return {};  // no quaternion (each has one entry more than its velocity)
  for (const Joint& joint : model.allJoints()) {
    const int at = quaternionOffset(joint.type);
    if (at < 0) continue;
    const double norm = quaternionNorm(q.data() + joint.q_index + at);
    if (norm == 0.0)
      return Status::error(StatusCode::BadConfiguration,
                           "%s: %s is zero: not an orientation (the identity is w = 1, x = y = z = 0)", what,
                           quaternionName(model, joint).text);
    if (!(std::abs(norm - 1.0) <= kQuaternionNormTolerance))
      return Status::error(StatusCode::BadConfiguration,
                           "%s: %s has norm %.9g, not 1 within %g (normalizeConfiguration fixes it)", what,
                           quaternionName(model, joint).text, norm, kQuaternionNormTolerance);
  }
  return {};
}

}  // namespace

std::uint64_t internal::splitMix64(std::uint64_t& state) noexcept {
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

  // An error must leave q_out unchanged: unless the sizes rule an overflow
  // out, every joint's step is taken and checked before q_out is touched.
  // Each joint reads only its own entries, so q_out may be q.
  double next[kMaxJointCoordinates];
  const bool may_overflow =
      !(largestMagnitude(q) <= kCannotOverflow && largestMagnitude(v) * std::abs(dt) <= kCannotOverflow);
  for (std::size_t j = 0; may_overflow && j < model.allJoints().size(); ++j) {
    const Joint& joint = model.allJoints()[j];
    integrateJoint(joint.type, q.data() + joint.q_index, v.data() + joint.v_index, dt, next);
    for (int k = 0; k < joint.nq(); ++k)
      if (!std::isfinite(next[k]))
        return Status::error(StatusCode::NonFinite, "q_out[%d] (%s) would be %g: v*dt is too large", joint.q_index + k,
                             configurationEntry(model, joint.q_index + k).text, next[k]);
  }
  for (const Joint& joint : model.allJoints()) {
    integrateJoint(joint.type, q.data() + joint.q_index, v.data() + joint.v_index, dt, next);
    std::copy(next, next + joint.nq(), q_out.data() + joint.q_index);
  }
  followLeaders(model, q_out);
  return {};
}

Status difference(const Model& model, const ConstVector& q0, const ConstVector& q1, Vector v_out) noexcept {
  if (Status s = checkConfigurationNamed(model, "q0", q0); !s) return s;
  if (Status s = checkConfigurationNamed(model, "q1", q1); !s) return s;
  if (v_out.size() != model.nv()) return sizeMismatch(model, "v_out", v_out.size(), true);

  // Differences of finite numbers may still overflow (1e308 − (−1e308)), and
  // an error must leave v_out unchanged: unless the sizes rule an overflow
  // out, every joint's difference is checked before v_out is touched.
  double d[kMaxJointCoordinates];
  const bool may_overflow = !(largestMagnitude(q0) <= kCannotOverflow && largestMagnitude(q1) <= kCannotOverflow);
  for (std::size_t j = 0; may_overflow && j < model.allJoints().size(); ++j) {
    const Joint& joint = model.allJoints()[j];
    differenceJoint(joint.type, q0.data() + joint.q_index, q1.data() + joint.q_index, d);
    for (int k = 0; k < joint.nv(); ++k)
      if (!std::isfinite(d[k]))
        return Status::error(StatusCode::NonFinite, "v_out[%d] (%s) would be %g: q1 and q0 are too far apart",
                             joint.v_index + k, velocityEntry(model, joint.v_index + k).text, d[k]);
  }
  for (const Joint& joint : model.allJoints())
    differenceJoint(joint.type, q0.data() + joint.q_index, q1.data() + joint.q_index, v_out.data() + joint.v_index);
  return {};
}

Status tangentRate(const Model& model, const ConstVector& u, const ConstVector& v, Vector u_dot_out) noexcept {
  if (Status s = checkVelocity(model, "u", u); !s) return s;
  if (Status s = checkVelocity(model, "v", v); !s) return s;
  if (u_dot_out.size() != model.nv()) return sizeMismatch(model, "u_dot_out", u_dot_out.size(), true);
  for (const Joint& joint : model.allJoints())
    tangentRateJoint(joint.type, u.data() + joint.v_index, v.data() + joint.v_index, u_dot_out.data() + joint.v_index);
  return {};
}

Status neutralConfiguration(const Model& model, Vector q_out) noexcept {
  if (Status s = checkConfigurationSize(model, "q_out", q_out.size()); !s) return s;
  for (std::size_t j = 0; j < model.allJoints().size(); ++j)
    neutralJoint(model, j, q_out.data() + model.allJoints()[j].q_index);
  followLeaders(model, q_out);
  return {};
}

Status randomConfiguration(const Model& model, std::uint64_t& state, Vector q_out) noexcept {
  if (Status s = checkConfigurationSize(model, "q_out", q_out.size()); !s) return s;
  for (std::size_t j = 0; j < model.allJoints().size(); ++j)
    randomJoint(model, j, state, q_out.data() + model.allJoints()[j].q_index);
  followLeaders(model, q_out);
  return {};
}

Status normalizeConfiguration(const Model& model, Vector q) noexcept {
  if (Status s = checkConfigurationSize(model, "q", q.size()); !s) return s;
  // Every quaternion is checked before any is scaled: an error leaves q unchanged.
  for (const Joint& joint : model.allJoints()) {
    const int at = quaternionOffset(joint.type);
    if (at < 0) continue;
    const int first = joint.q_index + at;
    for (int k = first; k < first + 4; ++k)
      if (!std::isfinite(q[k]))
        return Status::error(StatusCode::NonFinite,
                             "q[%d] (%s) is %g (not finite): the quaternion cannot be normalised", k,
                             configurationEntry(model, k).text, q[k]);
    if (quaternionNorm(q.data() + first) == 0.0)
      return Status::error(StatusCode::BadConfiguration, "q: %s is zero: no orientation to normalise",
                           quaternionName(model, joint).text);
  }
  for (const Joint& joint : model.allJoints())
    if (const int at = quaternionOffset(joint.type); at >= 0) {
      const int first = joint.q_index + at;
      q.segment<4>(first) /= quaternionNorm(q.data() + first);
    }
  return {};
}

}  // namespace zwang
