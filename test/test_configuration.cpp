// Configuration helpers (include/zwang/configuration.hpp) against independent
// references: a fourth-order Runge–Kutta integration of ṗ = R v, Ṙ = R [ω]×
// with rotation matrices (no quaternion, no exponential), the closed-form
// helix of a constant twist, the group property of the exponential, the
// distribution of uniform random rotations, SplitMix64's published outputs, and
// the test generators' own limits and mimic laws (support/chain_spec). Every
// case prints what it measured.
#include <algorithm>
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>

#include "support/random_chain.hpp"
#include "support/random_problem.hpp"
#include "zwang/zwang.hpp"

#include "model/split_mix64.hpp"  // the generator randomConfiguration draws from

#ifdef ZWANG_CONFIGURATION_COUNT_ALLOCATIONS
#include "counting_malloc.hpp"
#endif

using namespace zwang;
using namespace zwang::testing;
using zwang::internal::splitMix64;

namespace {

constexpr double kPi = 3.14159265358979323846;

// The model with its base made to float (the planar one on a turned, lifted plane:
// the helpers work in the plane's coordinates and must not care).
Model withBase(const Model& model, BaseType type) {
  Transform placement;
  if (type == BaseType::Planar)
    placement = Transform::fromPose(Eigen::AngleAxisd(0.3, Vec3::UnitX()).matrix(), Vec3(0, 0, 0.7));
  return ModelBuilder(model).setBase(type, placement).build();
}

// A random tree, with mimic joints on every other draw.
ChainSpec randomSpec(std::mt19937_64& rng, int max_joints = 12) {
  RandomTreeOptions options;
  options.max_moving_joints = max_joints;
  ChainSpec spec = randomTree(rng, options);
  if (uniform01(rng) < 0.5 && spec.dof() >= 2) {
    RandomMimicOptions mimic;
    mimic.max_mimics = std::min(3, spec.dof() - 1);
    addRandomMimics(rng, spec, mimic);
  }
  return spec;
}

// R from a unit quaternion (w, x, y, z), written out here (not Eigen's).
Eigen::Matrix3d rotationOf(double w, double x, double y, double z) {
  Eigen::Matrix3d R;
  R << 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),  //
      2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),   //
      2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y);
  return R;
}
Eigen::Matrix3d rotationOf(const Eigen::VectorXd& q) { return rotationOf(q[3], q[4], q[5], q[6]); }

Eigen::Matrix3d skew(const Vec3& w) {
  Eigen::Matrix3d S;
  S << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return S;
}

// The distance between two configurations of `model` as poses: the base
// position, the orientation as a rotation (q and −q are one), ψ modulo 2π, and
// the joints.
double configurationDistance(const Model& model, const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  double d = model.dof() > 0 ? (a.tail(model.dof()) - b.tail(model.dof())).cwiseAbs().maxCoeff() : 0.0;
  if (model.baseType() == BaseType::Free) {
    d = std::max(d, (a.head<3>() - b.head<3>()).cwiseAbs().maxCoeff());
    d = std::max(d, (rotationOf(a) - rotationOf(b)).cwiseAbs().maxCoeff());
  } else if (model.baseType() == BaseType::Planar) {
    d = std::max(d, (a.head<2>() - b.head<2>()).cwiseAbs().maxCoeff());
    d = std::max(d, std::abs(std::remainder(a[2] - b[2], 2 * kPi)));
  }
  return d;
}

// A random velocity for `model`: base linear parts in [−2, 2], the rotation
// angle |ω| log-uniform from 1e-12 to 1 or uniform up to 3.1 (under π, where
// the logarithm is unique), ψ̇ in [−3.1, 3.1], joints in [−2, 2]; mimic joints
// on their laws (integrate sets them so, difference gives them back so).
Eigen::VectorXd randomVelocity(std::mt19937_64& rng, const Model& model, const ChainSpec& spec) {
  Eigen::VectorXd v = randomVector(rng, model.nv(), 2.0);
  if (model.baseType() == BaseType::Free) {
    const double angle = uniform01(rng) < 0.5 ? std::pow(10.0, uniform(rng, -12.0, 0.0)) : uniform(rng, 0.0, 3.1);
    v.segment<3>(3) = angle * randomUnitVector(rng);
  } else if (model.baseType() == BaseType::Planar) {
    v[2] = uniform(rng, -3.1, 3.1);
  }
  const int base_velocity_size = model.baseVelocitySize();
  for (const MimicLaw& law : spec.mimicLaws())
    v[base_velocity_size + law.joint] = law.multiplier * v[base_velocity_size + law.leader];
  return v;
}

Eigen::VectorXd randomConfigurationOf(const Model& model, std::uint64_t& state) {
  Eigen::VectorXd q(model.nq());
  REQUIRE(randomConfiguration(model, state, q));
  return q;
}

// A rigid body moving with the constant body twist [v; ω] for time T: ṗ = R v,
// Ṙ = R [ω]×, by classical RK4 on (p, R) with `steps` steps. No quaternion, no
// exponential: independent of the code under test.
void rk4(Vec3& p, Eigen::Matrix3d& R, const Vec3& v, const Vec3& w, double T, int steps) {
  const double h = T / steps;
  const Eigen::Matrix3d W = skew(w);
  for (int k = 0; k < steps; ++k) {
    const Vec3 kp1 = R * v;
    const Eigen::Matrix3d kR1 = R * W;
    const Eigen::Matrix3d R2 = R + 0.5 * h * kR1;
    const Vec3 kp2 = R2 * v;
    const Eigen::Matrix3d kR2 = R2 * W;
    const Eigen::Matrix3d R3 = R + 0.5 * h * kR2;
    const Vec3 kp3 = R3 * v;
    const Eigen::Matrix3d kR3 = R3 * W;
    const Eigen::Matrix3d R4 = R + h * kR3;
    const Vec3 kp4 = R4 * v;
    const Eigen::Matrix3d kR4 = R4 * W;
    p += h / 6.0 * (kp1 + 2.0 * kp2 + 2.0 * kp3 + kp4);
    R += h / 6.0 * (kR1 + 2.0 * kR2 + 2.0 * kR3 + kR4);
  }
}

// A model built by hand: one joint of each kind, limits infinite and one-sided,
// a continuous leader whose revolute follower has limits, on `type` of base.
Model handModel(BaseType type) {
  ModelBuilder b("hand", "base");
  const double inf = std::numeric_limits<double>::infinity();
  const RigidInertia I = RigidInertia::fromMassComInertia(1.0, Vec3(0.1, 0, 0), Eigen::Matrix3d::Identity() * 0.01);
  auto add = [&](const char* name, JointType t, double lower, double upper, const char* parent) {
    Joint j;
    j.name = name;
    j.type = t;
    j.axis = t == JointType::Prismatic ? Vec3::UnitX() : Vec3::UnitZ();
    j.placement = Transform::translation(Vec3(0.1, 0, 0));
    j.lower = lower;
    j.upper = upper;
    b.addJoint(j, std::string("link_") + name, I, parent);
  };
  add("free_revolute", JointType::Revolute, -inf, inf, "base");        // [−π, π]
  add("free_prismatic", JointType::Prismatic, -inf, inf, "base");      // [−1, 1]
  add("above_five", JointType::Revolute, 5.0, inf, "base");            // [5, 5 + 2π]
  add("below_minus_three", JointType::Prismatic, -inf, -3.0, "base");  // [−5, −3]
  add("wheel", JointType::Continuous, -inf, inf, "base");              // [0, 0.5] for its follower
  add("wheel_follower", JointType::Revolute, 0.0, 1.0, "link_wheel");
  add("plain", JointType::Revolute, -0.5, 0.25, "base");
  b.setMimic("wheel_follower", "wheel", 2.0, 0.0);
  if (type != BaseType::Fixed) b.setBase(type);
  return b.build();
}

// The model with a spherical, a planar and a free joint added below its last
// link: every joint type in one tree.
Model withEveryJointType(const Model& model) {
  ModelBuilder b(model);
  const RigidInertia I = RigidInertia::fromMassComInertia(1.0, Vec3(0.1, 0, 0), Eigen::Matrix3d::Identity() * 0.01);
  std::string parent = model.frame(model.bodyFrame(model.bodyCount() - 1)).name;
  for (const JointType type : {JointType::Spherical, JointType::Planar, JointType::Free}) {
    Joint j;
    j.type = type;
    j.name = std::string("added_") + toString(type);
    j.placement = Transform::translation(Vec3(0.1, 0, 0));
    b.addJoint(j, "link_" + j.name, I, parent);
    parent = "link_" + j.name;
  }
  return b.build();
}

bool contains(const char* message, const char* part) { return std::strstr(message, part) != nullptr; }

}  // namespace

TEST_CASE("configuration: SplitMix64 gives its published outputs", "[configuration]") {
  std::uint64_t state = 0;
  CHECK(splitMix64(state) == 0xE220A8397B1DCDAFULL);
  CHECK(splitMix64(state) == 0x6E789E6AA1B965F4ULL);
  CHECK(splitMix64(state) == 0x06C45D188009454FULL);
  state = 1234567;
  CHECK(splitMix64(state) == 6457827717110365317ULL);
  CHECK(splitMix64(state) == 3203168211198807973ULL);
  CHECK(splitMix64(state) == 9817491932198370423ULL);
}

TEST_CASE("configuration: integrate and difference are inverse (random free and planar trees)", "[configuration]") {
  std::mt19937_64 rng(20261125);
  std::uint64_t state = 42;
  double e_qvq[2] = {0, 0}, e_vqv[2] = {0, 0}, e_self[2] = {0, 0};
  int trees = 0, draws = 0, with_mimic = 0;
  for (int t = 0; t < 150; ++t) {
    const ChainSpec spec = randomSpec(rng);
    const Model fixed = modelFromSpec(spec);
    with_mimic += spec.hasMimic() ? 1 : 0;
    for (int b = 0; b < 2; ++b) {
      const Model model = withBase(fixed, b == 0 ? BaseType::Free : BaseType::Planar);
      ++trees;
      for (int k = 0; k < 10; ++k, ++draws) {
        INFO("tree " << t << (b == 0 ? " (free)" : " (planar)") << ", draw " << k);
        const Eigen::VectorXd q0 = randomConfigurationOf(model, state), q1 = randomConfigurationOf(model, state);
        // q0 ⊕ (q1 ⊖ q0) = q1.
        Eigen::VectorXd v(model.nv()), q(model.nq());
        REQUIRE(difference(model, q0, q1, v));
        REQUIRE(integrate(model, q0, v, 1.0, q));
        const double eq = configurationDistance(model, q, q1);
        CHECK(eq < 1e-12);
        e_qvq[b] = std::max(e_qvq[b], eq);
        // (q0 ⊕ v) ⊖ q0 = v.
        const Eigen::VectorXd w = randomVelocity(rng, model, spec);
        REQUIRE(integrate(model, q0, w, 1.0, q));
        REQUIRE(difference(model, q0, q, v));
        const double ev = (v - w).cwiseAbs().maxCoeff() / (1.0 + w.cwiseAbs().maxCoeff());
        CHECK(ev < 1e-12);
        e_vqv[b] = std::max(e_vqv[b], ev);
        // q ⊖ q = 0.
        REQUIRE(difference(model, q1, q1, v));
        CHECK(v.cwiseAbs().maxCoeff() == 0.0);
        e_self[b] = std::max(e_self[b], v.cwiseAbs().maxCoeff());
      }
    }
  }
  std::printf(
      "configuration round trips: %d models (%d trees with mimic joints, x2 bases), %d draws each way\n"
      "  q0 + (q1 - q0) vs q1 (pose, rotation matrix, psi mod 2pi, joints): worst %.2e (free), %.2e (planar)\n"
      "  (q0 + v) - q0 vs v (relative to 1 + |v|, |w| 1e-12..3.1 rad): worst %.2e (free), %.2e (planar)\n"
      "  q - q: worst %.2e (free), %.2e (planar)\n",
      trees, with_mimic, draws, e_qvq[0], e_qvq[1], e_vqv[0], e_vqv[1], e_self[0], e_self[1]);
}

TEST_CASE("configuration: difference near a half turn and across the series thresholds", "[configuration]") {
  const Model model = handModel(BaseType::Free);
  std::mt19937_64 rng(7);
  double worst = 0.0;
  // Angles close to π (the logarithm's edge), at the series switch (1e-3), and tiny.
  const double angles[] = {kPi - 1e-3, kPi - 1e-6, kPi - 1e-9, 1e-3 * (1 - 1e-9), 1e-3 * (1 + 1e-9), 1e-3,
                           1e-7,       1e-15,      0.0};
  for (const double angle : angles) {
    for (int k = 0; k < 50; ++k) {
      std::uint64_t state = static_cast<std::uint64_t>(k);
      const Eigen::VectorXd q0 = randomConfigurationOf(model, state);
      Eigen::VectorXd w = Eigen::VectorXd::Zero(model.nv());
      w.head<3>() = randomVector(rng, 3, 2.0);
      w.segment<3>(3) = angle * randomUnitVector(rng);
      Eigen::VectorXd q(model.nq()), v(model.nv());
      REQUIRE(integrate(model, q0, w, 1.0, q));
      REQUIRE(difference(model, q0, q, v));
      const double e = (v - w).head<6>().cwiseAbs().maxCoeff() / (1.0 + w.cwiseAbs().maxCoeff());
      INFO("angle " << angle);
      // Within 1e-9 of π, the rotation's own rounding (1e-16 in R) moves the
      // axis by about 1e-16/(π − θ): the logarithm there is ill-conditioned.
      CHECK(e < (kPi - angle < 1e-8 ? 1e-6 : 1e-12));
      if (kPi - angle > 1e-8) worst = std::max(worst, e);
    }
  }
  // Exactly a half turn: the rotation comes back (either sign of the axis).
  Eigen::VectorXd q0(model.nq()), q1(model.nq()), v(model.nv()), q(model.nq());
  REQUIRE(neutralConfiguration(model, q0));
  q1 = q0;
  q1.segment<4>(3) << 0.0, 0.0, 0.0, 1.0;  // π about z
  q1.head<3>() << 1.0, 2.0, 3.0;
  REQUIRE(difference(model, q0, q1, v));
  CHECK(std::abs(v.segment<3>(3).norm() - kPi) < 1e-15);
  REQUIRE(integrate(model, q0, v, 1.0, q));
  CHECK(configurationDistance(model, q, q1) < 1e-14);
  std::printf("configuration: (q0 + v) - q0 near a half turn (to pi - 1e-6) and at the series switch: worst %.2e\n",
              worst);
}

TEST_CASE("configuration: integrate follows ṗ = R v, Ṙ = R [ω]× (RK4 reference, helix)", "[configuration]") {
  const Model model = handModel(BaseType::Free);
  std::mt19937_64 rng(3);
  std::uint64_t state = 3;
  double e_p = 0.0, e_R = 0.0;
  for (int k = 0; k < 100; ++k) {
    const Eigen::VectorXd q0 = randomConfigurationOf(model, state);
    Eigen::VectorXd v = Eigen::VectorXd::Zero(model.nv());
    v.head<3>() = randomVector(rng, 3, 2.0);
    v.segment<3>(3) = uniform(rng, 0.0, 3.0) * randomUnitVector(rng);  // up to 3 rad/s: up to 6 rad in dt
    const double dt = uniform(rng, -2.0, 2.0);
    Eigen::VectorXd q(model.nq());
    REQUIRE(integrate(model, q0, v, dt, q));
    Vec3 p = q0.head<3>();
    Eigen::Matrix3d R = rotationOf(q0);
    rk4(p, R, v.head<3>(), v.segment<3>(3), dt, 4000);
    e_p = std::max(e_p, (p - q.head<3>()).cwiseAbs().maxCoeff());
    e_R = std::max(e_R, (R - rotationOf(q)).cwiseAbs().maxCoeff());
    // The joints move linearly; the follower stays on its law.
    CHECK(q[7 + 0] == q0[7 + 0] + v[6 + 0] * dt);
    CHECK(q[7 + 5] == 2.0 * q[7 + 4]);
  }
  CHECK(e_p < 1e-11);
  CHECK(e_R < 1e-11);
  // A helix: from the identity at the origin, ω = 2 about z, v = (0.5, 0, 0.3) in
  // base axes: p(t) = (0.5 sin 2t / 2, 0.5 (1 − cos 2t) / 2, 0.3 t), ψ(t) = 2t.
  Eigen::VectorXd q0(model.nq()), q(model.nq()), v = Eigen::VectorXd::Zero(model.nv());
  REQUIRE(neutralConfiguration(model, q0));
  v.head<3>() << 0.5, 0.0, 0.3;
  v[5] = 2.0;
  double e_helix = 0.0;
  for (const double t : {1e-9, 0.3, 1.0, 2.5, 10.0}) {
    REQUIRE(integrate(model, q0, v, t, q));
    const Vec3 p(0.25 * std::sin(2 * t), 0.25 * (1 - std::cos(2 * t)), 0.3 * t);
    e_helix = std::max(e_helix, (q.head<3>() - p).cwiseAbs().maxCoeff());
    e_helix =
        std::max(e_helix, (rotationOf(q) - Eigen::AngleAxisd(2 * t, Vec3::UnitZ()).matrix()).cwiseAbs().maxCoeff());
  }
  CHECK(e_helix < 1e-14);
  std::printf(
      "configuration: integrate vs RK4 (4000 steps, 100 twists, |w dt| up to 6 rad): worst %.2e (position), "
      "%.2e (rotation); vs the closed-form helix: %.2e\n",
      e_p, e_R, e_helix);
}

TEST_CASE("configuration: the quaternion stays unit over 10^6 small steps", "[configuration]") {
  const Model model = handModel(BaseType::Free);
  std::uint64_t state = 11;
  const Eigen::VectorXd q0 = randomConfigurationOf(model, state);
  Eigen::VectorXd v(model.nv());
  v << 0.3, -0.2, 0.1, 0.7, -1.1, 0.4, Eigen::VectorXd::Zero(model.dof());
  const double dt = 1e-3;
  const int steps = 1000000;
  Eigen::VectorXd q = q0;
  double worst_norm = 0.0;
  bool all_ok = true;
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < steps; ++k) {
    all_ok = integrate(model, q, v, dt, q).ok() && all_ok;  // in place
    worst_norm = std::max(worst_norm, std::abs(q.segment<4>(3).norm() - 1.0));
  }
  const double ns = std::chrono::duration<double, std::nano>(std::chrono::steady_clock::now() - start).count() / steps;
  REQUIRE(all_ok);
  CHECK(worst_norm < 1e-15);
  // A constant twist: 10^6 steps of exp(ξ dt) are exp(ξ · 1000 s) (one step).
  Eigen::VectorXd q_once(model.nq());
  REQUIRE(integrate(model, q0, v, steps * dt, q_once));
  const double drift_R = (rotationOf(q) - rotationOf(q_once)).cwiseAbs().maxCoeff();
  const double drift_p = (q - q_once).head<3>().cwiseAbs().maxCoeff() / (1.0 + q_once.head<3>().norm());
  CHECK(drift_R < 1e-9);
  CHECK(drift_p < 1e-9);
  std::printf(
      "configuration: 10^6 steps of 1 ms (in place, %.0f ns a step with 7 joints): | |quaternion| - 1 | at "
      "most %.2e; drift from one 1000 s step: %.2e (rotation), %.2e (position, relative)\n",
      ns, worst_norm, drift_R, drift_p);
}

TEST_CASE("configuration: neutral and random configurations keep limits and mimic laws", "[configuration]") {
  std::mt19937_64 rng(99);
  std::uint64_t state = 5;
  int models = 0, draws = 0, mimic_in_limits = 0, mimic_checked = 0;
  double e_law = 0.0;
  for (int t = 0; t < 120; ++t) {
    const ChainSpec spec = randomSpec(rng);
    const Model fixed = modelFromSpec(spec);
    const std::vector<MimicLaw> laws = spec.mimicLaws();
    const std::vector<int> moving = spec.movingJoints();
    std::vector<bool> is_mimic(static_cast<std::size_t>(spec.dof()), false);
    for (const MimicLaw& law : laws) is_mimic[static_cast<std::size_t>(law.joint)] = true;
    // Can a leader keep all its followers within their limits? (the spec's own
    // data) A continuous leader of a limited follower is drawn in the range
    // that keeps its follower in, which may reach beyond ±π.
    std::vector<bool> feasible(static_cast<std::size_t>(spec.dof()), true), leads_limited = feasible;
    for (int j = 0; j < spec.dof(); ++j) leads_limited[static_cast<std::size_t>(j)] = false;
    for (int j = 0; j < spec.dof(); ++j) {
      const JointSpec& leader = spec.joints[static_cast<std::size_t>(moving[static_cast<std::size_t>(j)])];
      double lo = leader.type == "continuous" ? -1e300 : leader.lower,
             hi = leader.type == "continuous" ? 1e300 : leader.upper;
      for (const MimicLaw& law : laws) {
        if (law.leader != j) continue;
        const JointSpec& m = spec.joints[static_cast<std::size_t>(moving[static_cast<std::size_t>(law.joint)])];
        if (m.type == "continuous") continue;
        leads_limited[static_cast<std::size_t>(j)] = true;
        if (law.multiplier == 0.0) {
          if (law.offset < m.lower || law.offset > m.upper) hi = -1e300;
          continue;
        }
        const double a = (m.lower - law.offset) / law.multiplier, b = (m.upper - law.offset) / law.multiplier;
        lo = std::max(lo, std::min(a, b));
        hi = std::min(hi, std::max(a, b));
      }
      feasible[static_cast<std::size_t>(j)] = lo <= hi;
    }
    for (const BaseType type : {BaseType::Fixed, BaseType::Free, BaseType::Planar}) {
      const Model model = type == BaseType::Fixed ? fixed : withBase(fixed, type);
      const int base_configuration_size = model.baseConfigurationSize();
      ++models;
      for (int k = 0; k <= 10; ++k, ++draws) {
        Eigen::VectorXd q(model.nq());
        if (k == 0)
          REQUIRE(neutralConfiguration(model, q));
        else
          REQUIRE(randomConfiguration(model, state, q));
        INFO("tree " << t << ", base " << toString(type) << (k == 0 ? ", neutral" : ", random"));
        REQUIRE(checkConfiguration(model, q));
        if (type == BaseType::Free) {
          CHECK(q.head<3>().cwiseAbs().maxCoeff() <= 1.0);
          CHECK(std::abs(q.segment<4>(3).norm() - 1.0) < 1e-15);
          if (k == 0) CHECK(q.head<7>() == (Eigen::VectorXd(7) << 0, 0, 0, 1, 0, 0, 0).finished());
        } else if (type == BaseType::Planar) {
          CHECK(q.head<2>().cwiseAbs().maxCoeff() <= 1.0);
          CHECK(std::abs(q[2]) <= kPi);
          if (k == 0) CHECK(q.head<3>().isZero(0.0));
        }
        for (int j = 0; j < spec.dof(); ++j) {
          const JointSpec& joint = spec.joints[static_cast<std::size_t>(moving[static_cast<std::size_t>(j)])];
          const double x = q[base_configuration_size + j];
          const bool limited = joint.type != "continuous";
          if (!is_mimic[static_cast<std::size_t>(j)]) {
            INFO("joint " << joint.name << " = " << x);
            if (limited) CHECK((joint.lower <= x && x <= joint.upper));
            if (!limited && !leads_limited[static_cast<std::size_t>(j)]) CHECK(std::abs(x) <= kPi);
          } else if (limited) {
            const MimicLaw& law =
                *std::find_if(laws.begin(), laws.end(), [&](const MimicLaw& l) { return l.joint == j; });
            if (feasible[static_cast<std::size_t>(law.leader)]) {
              ++mimic_checked;
              const bool in = joint.lower - 1e-12 <= x && x <= joint.upper + 1e-12;
              CHECK(in);
              mimic_in_limits += in ? 1 : 0;
            }
          }
        }
        for (const MimicLaw& law : laws) {
          const double e = std::abs(q[base_configuration_size + law.joint] -
                                    (law.multiplier * q[base_configuration_size + law.leader] + law.offset));
          CHECK(e < 1e-15);
          e_law = std::max(e_law, e);
        }
      }
    }
  }
  std::printf(
      "configuration: neutral + random on %d models (fixed, free, planar), %d configurations: every joint "
      "within its limits; mimic joints within theirs where the leader can keep them (%d of %d); mimic "
      "laws to %.2e\n",
      models, draws, mimic_in_limits, mimic_checked, e_law);
}

TEST_CASE("configuration: random ranges for unlimited joints; uniform rotations; deterministic", "[configuration]") {
  const Model model = handModel(BaseType::Free);
  const int n = 100000;
  std::uint64_t state = 2026;
  Eigen::VectorXd lo = Eigen::VectorXd::Constant(model.nq(), 1e300), hi = -lo;
  double mean_angle = 0.0, mean_angle2 = 0.0;
  Eigen::Vector4d mean_sq = Eigen::Vector4d::Zero();
  Eigen::VectorXd q(model.nq());
  for (int k = 0; k < n; ++k) {
    REQUIRE(randomConfiguration(model, state, q));
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
    const double angle = 2.0 * std::acos(std::min(1.0, std::abs(q[3])));
    mean_angle += angle / n;
    mean_angle2 += angle * angle / n;
    mean_sq += q.segment<4>(3).cwiseAbs2() / n;
  }
  // joints: free_revolute [−π, π], free_prismatic [−1, 1], above_five [5, 5 + 2π],
  // below_minus_three [−5, −3], wheel [0, 0.5] (its follower's limits [0, 1] / 2),
  // wheel_follower = 2·wheel, plain [−0.5, 0.25].
  const double expect_lo[] = {-kPi, -1.0, 5.0, -5.0, 0.0, 0.0, -0.5};
  const double expect_hi[] = {kPi, 1.0, 5.0 + 2 * kPi, -3.0, 0.5, 1.0, 0.25};
  for (int j = 0; j < model.dof(); ++j) {
    INFO("joint " << model.joint(j).name << ": drawn in [" << lo[7 + j] << ", " << hi[7 + j] << "]");
    const double width = expect_hi[j] - expect_lo[j];
    CHECK(lo[7 + j] >= expect_lo[j]);
    CHECK(hi[7 + j] <= expect_hi[j]);
    CHECK(lo[7 + j] < expect_lo[j] + 1e-3 * width);
    CHECK(hi[7 + j] > expect_hi[j] - 1e-3 * width);
  }
  for (int k = 0; k < 3; ++k) CHECK((lo[k] >= -1.0 && lo[k] < -0.999 && hi[k] <= 1.0 && hi[k] > 0.999));
  // Uniform rotations: the angle has density (1 − cos θ)/π on [0, π], mean
  // π/2 + 2/π, mean square π²/3 + 2 (standard deviation 0.646: the means of
  // 10^5 draws are within 0.002 of theirs 1 time in 3); each quaternion
  // component squared averages 1/4.
  CHECK(std::abs(mean_angle - (kPi / 2 + 2 / kPi)) < 0.01);
  CHECK(std::abs(mean_angle2 - (kPi * kPi / 3 + 2)) < 0.03);
  CHECK((mean_sq.array() - 0.25).abs().maxCoeff() < 0.005);
  // The same state gives the same configuration; the state moves on.
  std::uint64_t a = 77, b = 77;
  Eigen::VectorXd qa(model.nq()), qb(model.nq());
  REQUIRE(randomConfiguration(model, a, qa));
  REQUIRE(randomConfiguration(model, b, qb));
  CHECK(qa == qb);
  CHECK(a == b);
  CHECK(a != 77);
  // The draws are specified (docs): state 77's first draw is the base x.
  std::uint64_t c = 77;
  const double u = static_cast<double>(splitMix64(c) >> 11) * 0x1.0p-53;
  CHECK(qa[0] == (1.0 - u) * -1.0 + u * 1.0);
  std::printf(
      "configuration: 10^5 random rotations: mean angle %.4f (uniform: %.4f), mean square %.4f (%.4f), "
      "mean q_i^2 %.4f %.4f %.4f %.4f (0.25)\n",
      mean_angle, kPi / 2 + 2 / kPi, mean_angle2, kPi * kPi / 3 + 2, mean_sq[0], mean_sq[1], mean_sq[2], mean_sq[3]);
}

TEST_CASE("configuration: a fixed base is a plain vector", "[configuration]") {
  std::mt19937_64 rng(5);
  ChainSpec spec = randomSpec(rng);
  while (!spec.hasMimic()) spec = randomSpec(rng);
  const Model model = modelFromSpec(spec);
  REQUIRE(model.nq() == model.dof());
  REQUIRE(model.nv() == model.dof());
  std::uint64_t state = 1;
  const Eigen::VectorXd q0 = randomConfigurationOf(model, state), q1 = randomConfigurationOf(model, state);
  Eigen::VectorXd v(model.nv()), q(model.nq());
  REQUIRE(difference(model, q0, q1, v));
  CHECK(v == q1 - q0);
  const Eigen::VectorXd w = randomVector(rng, model.nv(), 3.0);
  REQUIRE(integrate(model, q0, w, 0.25, q));
  Eigen::VectorXd expected = q0 + w * 0.25, no_velocity;
  spec.followMimicLaws(expected, no_velocity);
  CHECK((q - expected).cwiseAbs().maxCoeff() < 1e-15);
  q = q1;
  REQUIRE(normalizeConfiguration(model, q));
  CHECK(q == q1);
  // Large entries are still a configuration: there is no quaternion to check.
  q = q1 * 1e6;
  CHECK(checkConfiguration(model, q));
}

TEST_CASE("configuration: integrate in place gives what it gives out of place", "[configuration]") {
  for (const BaseType type : {BaseType::Fixed, BaseType::Free, BaseType::Planar}) {
    const Model model = withEveryJointType(handModel(type));
    std::uint64_t state = 8;
    std::mt19937_64 rng(8);
    Eigen::VectorXd q = randomConfigurationOf(model, state), out(model.nq());
    const Eigen::VectorXd v = randomVector(rng, model.nv(), 2.0);
    REQUIRE(integrate(model, q, v, 0.1, out));
    REQUIRE(integrate(model, q, v, 0.1, q));
    CHECK(q == out);
  }
}

TEST_CASE("configuration: bad inputs give a Status naming the entry, and change nothing", "[configuration]") {
  const Model free = handModel(BaseType::Free), planar = handModel(BaseType::Planar),
              fixed = handModel(BaseType::Fixed);
  Eigen::VectorXd q(free.nq()), q1(free.nq()), v = Eigen::VectorXd::Zero(free.nv()), out(free.nq()), dv(free.nv());
  REQUIRE(neutralConfiguration(free, q));
  q1 = q;
  out.setConstant(-7.0);
  dv.setConstant(-7.0);
  const Eigen::VectorXd untouched = out, untouched_v = dv;
  std::printf("configuration: error messages\n");
  auto expect = [&](const Status& s, StatusCode code, std::initializer_list<const char*> parts) {
    std::printf("  %s\n", s.message);
    INFO(s.message);
    CHECK(s.code == code);
    for (const char* part : parts) CHECK(contains(s.message, part));
    CHECK(out == untouched);
    CHECK(dv == untouched_v);
  };

  // Sizes, for every input and output.
  Eigen::VectorXd short_q = q.head(free.nq() - 1), short_v = v.head(free.nv() - 1);
  expect(checkConfiguration(free, short_q), StatusCode::SizeMismatch,
         {"q has 13 entries", "nq = 14", "7 base", "7 joints"});
  expect(integrate(free, q, short_v, 0.1, out), StatusCode::SizeMismatch, {"v has 12 entries", "nv = 13", "6 base"});
  expect(integrate(free, q, v, 0.1, dv), StatusCode::SizeMismatch, {"q_out has 13 entries"});
  expect(difference(free, short_q, q, dv), StatusCode::SizeMismatch, {"q0 has 13"});
  expect(difference(free, q, short_q, dv), StatusCode::SizeMismatch, {"q1 has 13"});
  expect(difference(free, q, q1, out), StatusCode::SizeMismatch, {"v_out has 14 entries", "nv = 13"});
  expect(neutralConfiguration(free, dv), StatusCode::SizeMismatch, {"q_out has 13"});
  std::uint64_t state = 5;
  expect(randomConfiguration(free, state, dv), StatusCode::SizeMismatch, {"q_out has 13"});
  CHECK(state == 5);
  expect(normalizeConfiguration(planar, dv), StatusCode::SizeMismatch, {"q has 13", "nq = 10", "3 base"});

  // Non-finite entries, named by what they are.
  Eigen::VectorXd bad = q;
  bad[4] = std::nan("");
  expect(checkConfiguration(free, bad), StatusCode::NonFinite, {"q[4] (base quaternion x) is nan"});
  expect(integrate(free, bad, v, 0.1, out), StatusCode::NonFinite, {"q[4] (base quaternion x)"});
  expect(difference(free, q, bad, dv), StatusCode::NonFinite, {"q1[4] (base quaternion x)"});
  bad = q;
  bad[7 + 2] = -INFINITY;
  expect(checkConfiguration(free, bad), StatusCode::NonFinite, {"q[9] (joint 'above_five') is -inf"});
  expect(difference(free, bad, q, dv), StatusCode::NonFinite, {"q0[9] (joint 'above_five')"});
  bad = q;
  bad[1] = INFINITY;
  expect(checkConfiguration(free, bad), StatusCode::NonFinite, {"q[1] (base position y) is inf"});
  Eigen::VectorXd pq(planar.nq());
  REQUIRE(neutralConfiguration(planar, pq));
  pq[2] = std::nan("");
  expect(checkConfiguration(planar, pq), StatusCode::NonFinite, {"q[2] (base yaw psi)"});
  Eigen::VectorXd bad_v = v;
  bad_v[5] = std::nan("");
  expect(integrate(free, q, bad_v, 0.1, out), StatusCode::NonFinite, {"v[5] (base angular velocity z (base axes))"});
  bad_v = v;
  bad_v[6 + 6] = INFINITY;
  expect(integrate(free, q, bad_v, 0.1, out), StatusCode::NonFinite, {"v[12] (joint 'plain')"});
  expect(integrate(free, q, v, std::nan(""), out), StatusCode::NonFinite, {"dt is nan"});
  // Finite inputs whose step overflows.
  bad_v = v;
  bad_v[0] = 1e300;
  expect(integrate(free, q, bad_v, 1e10, out), StatusCode::NonFinite,
         {"q_out[0] (base position x) would be", "too large"});
  bad_v = v;
  bad_v[6 + 1] = 1e300;
  expect(integrate(free, q, bad_v, 1e10, out), StatusCode::NonFinite,
         {"q_out[8] (joint 'free_prismatic') would be inf"});
  bad = q;
  bad[7 + 1] = 1.5e308;
  Eigen::VectorXd bad1 = q;
  bad1[7 + 1] = -1.5e308;
  expect(difference(free, bad1, bad, dv), StatusCode::NonFinite, {"v_out[7] (joint 'free_prismatic') would be inf"});
  bad = q;
  bad[0] = 1.5e308;
  bad1 = q;
  bad1[0] = -1.5e308;
  expect(difference(free, bad1, bad, dv), StatusCode::NonFinite,
         {"v_out[0] (base linear velocity x (base axes)) would be", "too far apart"});
  Eigen::VectorXd pq0(planar.nq()), pq1(planar.nq()), pv(planar.nv());
  REQUIRE(neutralConfiguration(planar, pq0));
  pq1 = pq0;
  pq0[1] = -1.5e308;
  pq1[1] = 1.5e308;
  pv.setConstant(-7.0);
  CHECK(difference(planar, pq0, pq1, pv).code == StatusCode::NonFinite);
  CHECK((pv.array() == -7.0).all());

  // The quaternion: not unit beyond the tolerance, zero.
  bad = q;
  bad.segment<4>(3) *= 1.2;
  expect(checkConfiguration(free, bad), StatusCode::BadConfiguration,
         {"q: base quaternion (entries 3-6, w x y z) has norm 1.2", "not 1 within 1e-06",
          "normalizeConfiguration fixes it"});
  expect(integrate(free, bad, v, 0.1, out), StatusCode::BadConfiguration, {"q: base quaternion", "norm 1.2"});
  expect(difference(free, q, bad, dv), StatusCode::BadConfiguration, {"q1: base quaternion", "norm 1.2"});
  bad = q;
  bad.segment<4>(3) *= 1.0 + 0.9 * kQuaternionNormTolerance;
  CHECK(checkConfiguration(free, bad));
  bad = q;
  bad.segment<4>(3) *= 1.0 + 1.1 * kQuaternionNormTolerance;
  expect(checkConfiguration(free, bad), StatusCode::BadConfiguration, {"has norm 1.0000011"});
  bad = q;
  bad.segment<4>(3).setZero();
  expect(checkConfiguration(free, bad), StatusCode::BadConfiguration,
         {"q: base quaternion (entries 3-6, w x y z) is zero: not an orientation"});
  Eigen::VectorXd zero = bad;
  expect(normalizeConfiguration(free, zero), StatusCode::BadConfiguration,
         {"base quaternion (entries 3-6, w x y z) is zero"});
  CHECK(zero == bad);
  zero[6] = std::nan("");
  expect(normalizeConfiguration(free, zero), StatusCode::NonFinite, {"q[6] (base quaternion z) is nan"});

  // normalizeConfiguration: any non-zero finite quaternion, however small or large.
  for (const double scale : {1e-300, 1e-170, 0.5, 1.2, 1e170, 1e300}) {
    bad = q;
    bad.segment<4>(3) << 0.5 * scale, -0.5 * scale, 0.5 * scale, 0.5 * scale;
    REQUIRE(normalizeConfiguration(free, bad));
    CHECK(std::abs(bad.segment<4>(3).norm() - 1.0) < 1e-15);
    CHECK(std::abs(bad[3] - 0.5) < 1e-15);
    CHECK(checkConfiguration(free, bad));
    CHECK(bad.head<3>() == q.head<3>());
    CHECK(bad.tail(fixed.dof()) == q.tail(fixed.dof()));
  }
  // Fixed base: no quaternion to check.
  Eigen::VectorXd fq(fixed.nq());
  REQUIRE(neutralConfiguration(fixed, fq));
  CHECK(checkConfiguration(fixed, fq));
  expect(checkConfiguration(fixed, q), StatusCode::SizeMismatch, {"q has 14 entries", "the model has 7 joints"});
}

#ifdef ZWANG_CONFIGURATION_COUNT_ALLOCATIONS
TEST_CASE("configuration: the helpers allocate nothing (also on errors)", "[configuration]") {
  for (const BaseType type : {BaseType::Fixed, BaseType::Free, BaseType::Planar}) {
    const Model model = withEveryJointType(handModel(type));
    Eigen::VectorXd q0(model.nq()), q1(model.nq()), q(model.nq()), v(model.nv()), short_q(1);
    Eigen::VectorXd w = Eigen::VectorXd::Constant(model.nv(), 0.3);
    std::uint64_t state = 9;
    bool all_ok = true;
    const long count = allocationsDuring([&] {
      for (int k = 0; k < 10; ++k) {
        all_ok = randomConfiguration(model, state, q0).ok() && all_ok;
        all_ok = neutralConfiguration(model, q1).ok() && all_ok;
        all_ok = integrate(model, q0, w, 0.1, q).ok() && all_ok;
        all_ok = integrate(model, q, w, 0.1, q).ok() && all_ok;
        all_ok = difference(model, q0, q, v).ok() && all_ok;
        all_ok = normalizeConfiguration(model, q).ok() && all_ok;
        all_ok = checkConfiguration(model, q).ok() && all_ok;
        all_ok = !checkConfiguration(model, short_q).ok() && all_ok;
        all_ok = !integrate(model, q0, w, std::nan(""), q).ok() && all_ok;
      }
    });
    CHECK(all_ok);
    CHECK(count == 0);
    std::printf("configuration: %s base: %ld allocations in 90 calls\n", toString(type), count);
  }
}
#endif
