// Configuration helpers (include/zwang/configuration.hpp) on every joint type
// anywhere in the tree: revolute, continuous, prismatic, spherical, planar and
// free joints mixed below fixed, free and planar bases. The references are
// independent of the code under test: rotation matrices from quaternions and
// from axis-angle by Rodrigues' formula, written out here; the exponential of
// a twist as a matrix exponential (Taylor series with scaling and squaring, no
// closed form); SplitMix64 and Shoemake's method redrawn by hand for the
// documented order of draws. Every case prints what it measured.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>

#include "support/random_chain.hpp"
#include "zwang/zwang.hpp"

using namespace zwang;
using namespace zwang::testing;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr JointType kTypes[] = {JointType::Revolute,  JointType::Continuous, JointType::Prismatic,
                                JointType::Spherical, JointType::Planar,     JointType::Free};

// R from a unit quaternion (w, x, y, z), written out here (not Eigen's).
Eigen::Matrix3d rotationOf(const double* q) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  Eigen::Matrix3d R;
  R << 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),  //
      2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),   //
      2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y);
  return R;
}

Eigen::Matrix3d skew(const Vec3& w) {
  Eigen::Matrix3d S;
  S << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return S;
}

// exp([w]×) by Rodrigues: 1 + sin θ [a]× + (1 − cos θ) [a]×², a = w/θ.
Eigen::Matrix3d rodrigues(const Vec3& w) {
  const double theta = w.norm();
  if (theta == 0.0) return Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d A = skew(w / theta);
  return Eigen::Matrix3d::Identity() + std::sin(theta) * A + (1.0 - std::cos(theta)) * A * A;
}

// exp(M) by scaling and squaring: M/2^s of norm under 1/2, 30 Taylor terms
// (the remainder 0.5^30/30! is far under rounding), then s squarings.
Eigen::Matrix4d expm(const Eigen::Matrix4d& M) {
  int s = 0;
  double norm = M.cwiseAbs().rowwise().sum().maxCoeff();
  while (norm > 0.5) norm *= 0.5, ++s;
  const Eigen::Matrix4d A = M / std::ldexp(1.0, s);
  Eigen::Matrix4d E = Eigen::Matrix4d::Identity(), term = Eigen::Matrix4d::Identity();
  for (int k = 1; k <= 30; ++k) {
    term = term * A / k;
    E += term;
  }
  for (int k = 0; k < s; ++k) E = E * E;
  return E;
}

// The homogeneous pose [R p; 0 1] of a free joint's q.
Eigen::Matrix4d poseOf(const double* q) {
  Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
  M.topLeftCorner<3, 3>() = rotationOf(q + 3);
  M.topRightCorner<3, 1>() = Vec3(q[0], q[1], q[2]);
  return M;
}

// The 4 × 4 matrix of the child-frame twist [v; ω]: exp of it moves a pose by the twist.
Eigen::Matrix4d twistMatrix(const double* v) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Zero();
  T.topLeftCorner<3, 3>() = skew(Vec3(v[3], v[4], v[5]));
  T.topRightCorner<3, 1>() = Vec3(v[0], v[1], v[2]);
  return T;
}

// How far apart two configurations of one joint are as poses: a quaternion
// and its negative are one orientation, ψ counts modulo 2π.
double jointDistance(const Joint& joint, const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const double *x = a.data() + joint.q_index, *y = b.data() + joint.q_index;
  switch (joint.type) {
    case JointType::Spherical: return (rotationOf(x) - rotationOf(y)).cwiseAbs().maxCoeff();
    case JointType::Free: return (poseOf(x) - poseOf(y)).cwiseAbs().maxCoeff();
    case JointType::Planar:
      return std::max({std::abs(x[0] - y[0]), std::abs(x[1] - y[1]), std::abs(std::remainder(x[2] - y[2], 2 * kPi))});
    default: return std::abs(x[0] - y[0]);
  }
}

double configurationDistance(const Model& model, const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  double d = 0.0;
  for (const Joint& joint : model.allJoints()) d = std::max(d, jointDistance(joint, a, b));
  return d;
}

// A random tree of 2 to 10 joints, each of a random type, hanging from a
// random link on the path from the root to the last link added (the builder
// adds depth first), on a fixed, free or planar base.
Model randomMixedTree(std::mt19937_64& rng, BaseType base) {
  ModelBuilder builder("mixed", "base");
  const RigidInertia I =
      RigidInertia::fromMassComInertia(1.0, Vec3(0.05, 0.02, 0.1), Eigen::Matrix3d::Identity() * 0.01);
  std::vector<std::string> links{"base"};
  std::vector<int> parent{-1};
  const int joints = 2 + static_cast<int>(rng() % 9);
  for (int j = 0; j < joints; ++j) {
    std::vector<int> path;  // the last link and its ancestors
    for (int l = static_cast<int>(links.size()) - 1; l >= 0; l = parent[static_cast<std::size_t>(l)]) path.push_back(l);
    const int p = path[rng() % path.size()];
    Joint joint;
    joint.name = "j" + std::to_string(j);
    joint.type = kTypes[rng() % 6];
    joint.axis = randomUnitVector(rng);
    joint.placement =
        Transform::fromPose(rodrigues(randomUnitVector(rng) * uniform(rng, 0, 3)), randomVector(rng, 3, 0.3));
    if (joint.type == JointType::Revolute || joint.type == JointType::Prismatic) {
      joint.lower = uniform(rng, -2.0, 0.0);
      joint.upper = uniform(rng, 0.0, 2.0);
    }
    links.push_back("link" + std::to_string(j));
    parent.push_back(p);
    builder.addJoint(joint, links.back(), I, links[static_cast<std::size_t>(p)]);
  }
  if (base != BaseType::Fixed) {
    builder.addBaseLinkInertia(I);
    builder.setBase(base);
  }
  return builder.build();
}

// A random velocity: rotations of angle log-uniform from 1e-12 to 1 or uniform
// up to 3 (under π, where the logarithm is unique); yaw rates within ±3; the
// rest in [−2, 2].
Eigen::VectorXd randomVelocity(std::mt19937_64& rng, const Model& model) {
  Eigen::VectorXd v = randomVector(rng, model.nv(), 2.0);
  for (const Joint& joint : model.allJoints()) {
    const int at = joint.type == JointType::Spherical ? 0 : joint.type == JointType::Free ? 3 : -1;
    if (at >= 0) {
      const double angle = uniform01(rng) < 0.5 ? std::pow(10.0, uniform(rng, -12.0, 0.0)) : uniform(rng, 0.0, 3.0);
      v.segment<3>(joint.v_index + at) = angle * randomUnitVector(rng);
    }
    if (joint.type == JointType::Planar) v[joint.v_index + 2] = uniform(rng, -3.0, 3.0);
  }
  return v;
}

// A mixed model with one joint of each type, multi-DOF ones in the middle of
// the tree: free base → hip (spherical) → knee (revolute) → slider (planar) →
// drone (free) → slide (prismatic); and a second branch off the base: wheel
// (continuous).
Model handModel(BaseType base = BaseType::Free) {
  ModelBuilder b("hand", "base");
  const RigidInertia I = RigidInertia::fromMassComInertia(1.0, Vec3(0.1, 0, 0), Eigen::Matrix3d::Identity() * 0.01);
  auto add = [&](const char* name, JointType type, const char* parent) {
    Joint j;
    j.name = name;
    j.type = type;
    j.axis = Vec3::UnitY();
    j.placement = Transform::translation(Vec3(0.1, 0, 0));
    b.addJoint(j, std::string("link_") + name, I, parent);
  };
  add("hip", JointType::Spherical, "base");
  add("knee", JointType::Revolute, "link_hip");
  add("slider", JointType::Planar, "link_knee");
  add("drone", JointType::Free, "link_slider");
  add("slide", JointType::Prismatic, "link_drone");
  add("wheel", JointType::Continuous, "base");
  b.addBaseLinkInertia(I);
  if (base != BaseType::Fixed) b.setBase(base);
  return b.build();
}

bool contains(const char* message, const char* part) { return std::strstr(message, part) != nullptr; }

}  // namespace

TEST_CASE("configuration joints: the layout of every joint type", "[configuration]") {
  const Model model = handModel();
  REQUIRE(model.allJoints().size() == 7);
  CHECK(model.nq() == 7 + 4 + 1 + 3 + 7 + 1 + 1);
  CHECK(model.nv() == 6 + 3 + 1 + 3 + 6 + 1 + 1);
  Eigen::VectorXd q(model.nq());
  REQUIRE(neutralConfiguration(model, q));
  Eigen::VectorXd expected(model.nq());
  //          root free            hip          knee slider  drone                slide wheel
  expected << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0;
  CHECK(q == expected);
  CHECK(checkConfiguration(model, q));
}

TEST_CASE("configuration joints: integrate against Rodrigues and the matrix exponential", "[configuration]") {
  std::mt19937_64 rng(2511);
  double worst = 0.0;
  int counts[6] = {};
  for (int draw = 0; draw < 300; ++draw) {
    const BaseType base = static_cast<BaseType>(draw % 3);
    const Model model = randomMixedTree(rng, base);
    std::uint64_t state = rng();
    Eigen::VectorXd q(model.nq()), q_out(model.nq());
    REQUIRE(randomConfiguration(model, state, q));
    const Eigen::VectorXd v = randomVelocity(rng, model);
    const double dt = uniform(rng, -1.5, 1.5);
    REQUIRE(integrate(model, q, v, dt, q_out));
    for (const Joint& joint : model.allJoints()) {
      ++counts[static_cast<int>(joint.type)];
      const double *x = q.data() + joint.q_index, *y = q_out.data() + joint.q_index, *w = v.data() + joint.v_index;
      double error = 0.0;
      switch (joint.type) {
        case JointType::Spherical:
          error = (rotationOf(y) - rotationOf(x) * rodrigues(Vec3(w[0], w[1], w[2]) * dt)).cwiseAbs().maxCoeff();
          break;
        case JointType::Free: error = (poseOf(y) - poseOf(x) * expm(twistMatrix(w) * dt)).cwiseAbs().maxCoeff(); break;
        case JointType::Planar:
          for (int k = 0; k < 3; ++k) error = std::max(error, std::abs(y[k] - (x[k] + w[k] * dt)));
          break;
        default: error = std::abs(y[0] - (x[0] + w[0] * dt));
      }
      INFO(toString(joint.type) << " joint '" << joint.name << "'");
      // Poses of size ~3 (positions up to |v dt| ≈ 5): a few dozen roundings of 2.2e-16 each.
      CHECK(error < 1e-13);
      worst = std::max(worst, error);
      const int at = joint.type == JointType::Spherical ? 0 : joint.type == JointType::Free ? 3 : -1;
      if (at >= 0) CHECK(std::abs(q_out.segment<4>(joint.q_index + at).norm() - 1.0) < 4e-16);  // renormalised
    }
  }
  std::printf("configuration joints: integrate on 300 mixed trees (joints per type: %d %d %d %d %d %d): worst %.2e\n",
              counts[0], counts[1], counts[2], counts[3], counts[4], counts[5], worst);
  for (const int count : counts) CHECK(count > 100);
}

TEST_CASE("configuration joints: difference is the logarithm, and round trips both ways", "[configuration]") {
  std::mt19937_64 rng(2512);
  double worst_log = 0.0, worst_trip = 0.0, worst_velocity = 0.0;
  for (int draw = 0; draw < 300; ++draw) {
    const Model model = randomMixedTree(rng, static_cast<BaseType>(draw % 3));
    std::uint64_t state = rng();
    Eigen::VectorXd q0(model.nq()), q1(model.nq()), back(model.nq()), v(model.nv()), dv(model.nv());
    REQUIRE(randomConfiguration(model, state, q0));
    REQUIRE(randomConfiguration(model, state, q1));
    REQUIRE(difference(model, q0, q1, v));
    for (const Joint& joint : model.allJoints()) {
      const double *x = q0.data() + joint.q_index, *y = q1.data() + joint.q_index, *w = v.data() + joint.v_index;
      double error = 0.0;
      switch (joint.type) {
        case JointType::Spherical: {  // exp(ω) = R0ᵀ R1, the shortest rotation
          const Vec3 omega(w[0], w[1], w[2]);
          error = (rodrigues(omega) - rotationOf(x).transpose() * rotationOf(y)).cwiseAbs().maxCoeff();
          CHECK(omega.norm() <= kPi + 1e-15);
          break;
        }
        case JointType::Free:  // exp(twist) = M0⁻¹ M1, the shortest rotation
          error = (expm(twistMatrix(w)) - poseOf(x).inverse() * poseOf(y)).cwiseAbs().maxCoeff();
          CHECK(Vec3(w[3], w[4], w[5]).norm() <= kPi + 1e-15);
          break;
        case JointType::Planar:
          error = std::max({std::abs(w[0] - (y[0] - x[0])), std::abs(w[1] - (y[1] - x[1])),
                            std::abs(std::remainder(w[2] - (y[2] - x[2]), 2 * kPi))});
          CHECK(std::abs(w[2]) <= kPi);
          break;
        default: error = std::abs(w[0] - (y[0] - x[0]));
      }
      INFO(toString(joint.type) << " joint '" << joint.name << "'");
      CHECK(error < 1e-12);  // poses of size ~3 through a logarithm: well within rounding of a few dozen operations
      worst_log = std::max(worst_log, error);
    }
    // integrate(q0, q1 ⊖ q0, 1) = q1 (up to the quaternion's sign).
    REQUIRE(integrate(model, q0, v, 1.0, back));
    const double trip = configurationDistance(model, back, q1);
    CHECK(trip < 1e-12);
    worst_trip = std::max(worst_trip, trip);
    // integrate(q0, w, dt) ⊖ q0 = w·dt for rotations under π.
    const Eigen::VectorXd w = randomVelocity(rng, model);
    const double dt = uniform01(rng) < 0.5 ? 1.0 : uniform(rng, 0.0, 1.0);
    REQUIRE(integrate(model, q0, w, dt, back));
    REQUIRE(difference(model, q0, back, dv));
    const double velocity = (dv - w * dt).cwiseAbs().maxCoeff();
    CHECK(velocity < 1e-12);
    worst_velocity = std::max(worst_velocity, velocity);
  }
  std::printf(
      "configuration joints: difference on 300 mixed trees: vs the exponential %.2e, integrate(q0, q1 - q0) vs q1 "
      "%.2e, (q0 + w dt) - q0 vs w dt %.2e\n",
      worst_log, worst_trip, worst_velocity);
}

TEST_CASE("configuration joints: a joint anywhere behaves as the root's joint of its type", "[configuration]") {
  // The free and planar bases' behaviour is the Free and Planar joints': the
  // same numbers through a mid-tree joint give the same bits as through the root's.
  std::mt19937_64 rng(2513);
  for (const BaseType base : {BaseType::Free, BaseType::Planar}) {
    const Model model = handModel(base);
    const Joint& root = model.allJoints().front();
    const Joint& inner =
        model.allJoints()[static_cast<std::size_t>(model.jointIndex(base == BaseType::Free ? "drone" : "slider") + 1)];
    REQUIRE(inner.type == root.type);
    for (int draw = 0; draw < 100; ++draw) {
      std::uint64_t state = rng();
      Eigen::VectorXd q(model.nq()), q1(model.nq()), out(model.nq()), dv(model.nv());
      REQUIRE(randomConfiguration(model, state, q));
      REQUIRE(randomConfiguration(model, state, q1));
      q.segment(inner.q_index, inner.nq()) = q.segment(root.q_index, root.nq());
      q1.segment(inner.q_index, inner.nq()) = q1.segment(root.q_index, root.nq());
      Eigen::VectorXd v = randomVelocity(rng, model);
      v.segment(inner.v_index, inner.nv()) = v.segment(root.v_index, root.nv());
      REQUIRE(integrate(model, q, v, 0.7, out));
      CHECK(out.segment(inner.q_index, inner.nq()) == out.segment(root.q_index, root.nq()));
      REQUIRE(difference(model, q, q1, dv));
      CHECK(dv.segment(inner.v_index, inner.nv()) == dv.segment(root.v_index, root.nv()));
    }
  }
}

TEST_CASE("configuration joints: random draws in the documented order, reproducible, unit quaternions",
          "[configuration]") {
  const Model model = handModel(BaseType::Planar);
  // The draws by hand: SplitMix64 → u ∈ [0, 1) → the documented maps, joint by joint.
  std::uint64_t state = 0x25, hand_state = 0x25;
  auto u01 = [&] {
    std::uint64_t z = (hand_state += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return static_cast<double>((z ^ (z >> 31)) >> 11) / 9007199254740992.0;
  };
  auto in = [&](double lo, double hi) {
    const double u = u01();
    return (1 - u) * lo + u * hi;
  };
  auto shoemake = [&](double* q) {
    const double u1 = u01(), u2 = u01(), u3 = u01();
    q[0] = std::sqrt(u1) * std::cos(2 * kPi * u3);
    q[1] = std::sqrt(1 - u1) * std::sin(2 * kPi * u2);
    q[2] = std::sqrt(1 - u1) * std::cos(2 * kPi * u2);
    q[3] = std::sqrt(u1) * std::sin(2 * kPi * u3);
  };
  Eigen::VectorXd expected(model.nq()), q(model.nq()), again(model.nq());
  double* e = expected.data();
  e[0] = in(-1, 1), e[1] = in(-1, 1), e[2] = in(-kPi, kPi);   // root planar
  shoemake(e + 3);                                            // hip
  e[7] = in(-kPi, kPi);                                       // knee: no limits
  e[8] = in(-1, 1), e[9] = in(-1, 1), e[10] = in(-kPi, kPi);  // slider
  for (int k = 11; k < 14; ++k) e[k] = in(-1, 1);             // drone
  shoemake(e + 14);
  e[18] = in(-1, 1);      // slide: no limits
  e[19] = in(-kPi, kPi);  // wheel
  REQUIRE(randomConfiguration(model, state, q));
  CHECK(state == hand_state);
  CHECK((q - expected).cwiseAbs().maxCoeff() < 1e-15);  // Shoemake's square roots and the normalisation round
  std::uint64_t state2 = 0x25;
  REQUIRE(randomConfiguration(model, state2, again));
  CHECK(again == q);
  // Unit quaternions on every draw, and every draw a configuration.
  double worst = 0.0;
  for (int draw = 0; draw < 1000; ++draw) {
    REQUIRE(randomConfiguration(model, state, q));
    REQUIRE(checkConfiguration(model, q));
    for (const int at : {3, 14}) worst = std::max(worst, std::abs(q.segment<4>(at).norm() - 1.0));
  }
  CHECK(worst < 4e-16);  // a normalised quaternion's norm: 1 to a rounding or two
  std::printf("configuration joints: 1000 random draws: | |quaternion| - 1 | at most %.2e\n", worst);
}

TEST_CASE("configuration joints: normalisation of every quaternion", "[configuration]") {
  const Model model = handModel();
  const Joint& hip = model.allJoints()[static_cast<std::size_t>(model.jointIndex("hip") + 1)];
  const Joint& drone = model.allJoints()[static_cast<std::size_t>(model.jointIndex("drone") + 1)];
  std::uint64_t state = 7;
  Eigen::VectorXd q(model.nq());
  REQUIRE(randomConfiguration(model, state, q));
  Eigen::VectorXd scaled = q;
  scaled.segment<4>(3) *= 1e-200;  // root
  scaled.segment<4>(hip.q_index) *= 3.0;
  scaled.segment<4>(drone.q_index + 3) *= 1e200;
  CHECK(checkConfiguration(model, scaled).code == StatusCode::BadConfiguration);
  REQUIRE(normalizeConfiguration(model, scaled));
  CHECK((scaled - q).cwiseAbs().maxCoeff() < 4e-16);  // x·s/|x·s| = x/|x| to a rounding or two
  CHECK(checkConfiguration(model, scaled));

  // A zero or non-finite quaternion anywhere: named, and q left as it was (also the quaternions before it).
  Eigen::VectorXd bad = q;
  bad.segment<4>(3) *= 2.0;
  bad.segment<4>(drone.q_index + 3).setZero();
  const Eigen::VectorXd before = bad;
  Status s = normalizeConfiguration(model, bad);
  INFO(s.message);
  CHECK(s.code == StatusCode::BadConfiguration);
  CHECK(contains(s.message, "q: joint 'drone' quaternion (entries 18-21, w x y z) is zero"));
  CHECK(bad == before);
  bad[hip.q_index + 2] = std::nan("");
  s = normalizeConfiguration(model, bad);
  CHECK(s.code == StatusCode::NonFinite);
  CHECK(contains(s.message, "q[9] (joint 'hip' quaternion y) is nan"));
}

TEST_CASE("configuration joints: messages name the joint and the coordinate", "[configuration]") {
  const Model model = handModel();
  Eigen::VectorXd q(model.nq()), v = Eigen::VectorXd::Zero(model.nv()), out(model.nq()), dv(model.nv());
  REQUIRE(neutralConfiguration(model, q));
  std::printf("configuration joints: error messages\n");
  auto expect = [&](const Status& s, StatusCode code, std::initializer_list<const char*> parts) {
    std::printf("  %s\n", s.message);
    INFO(s.message);
    CHECK(s.code == code);
    for (const char* part : parts) CHECK(contains(s.message, part));
  };
  // Every entry of q and v named: its joint and coordinate.
  const char* q_names[] = {
      "base position x",  "base quaternion w",      "joint 'hip' quaternion w", "joint 'knee'",
      "joint 'slider' x", "joint 'slider' yaw psi", "joint 'drone' position z", "joint 'drone' quaternion z",
      "joint 'slide'",    "joint 'wheel'"};
  const int q_at[] = {0, 3, 7, 11, 12, 14, 17, 21, 22, 23};
  for (int k = 0; k < 10; ++k) {
    Eigen::VectorXd bad = q;
    bad[q_at[k]] = INFINITY;
    char part[96];
    std::snprintf(part, sizeof part, "q[%d] (%s) is inf", q_at[k], q_names[k]);
    expect(checkConfiguration(model, bad), StatusCode::NonFinite, {part});
  }
  const char* v_names[] = {"base linear velocity x (base axes)",
                           "base angular velocity z (base axes)",
                           "joint 'hip' angular velocity x (child axes)",
                           "joint 'knee'",
                           "joint 'slider' x rate",
                           "joint 'slider' yaw rate",
                           "joint 'drone' linear velocity y (child axes)",
                           "joint 'drone' angular velocity z (child axes)",
                           "joint 'wheel'"};
  const int v_at[] = {0, 5, 6, 9, 10, 12, 14, 18, 20};
  for (int k = 0; k < 9; ++k) {
    Eigen::VectorXd bad = v;
    bad[v_at[k]] = std::nan("");
    char part[96];
    std::snprintf(part, sizeof part, "v[%d] (%s) is nan", v_at[k], v_names[k]);
    expect(integrate(model, q, bad, 0.1, out), StatusCode::NonFinite, {part});
  }
  // Quaternions off unit norm, anywhere.
  Eigen::VectorXd bad = q;
  bad.segment<4>(7) *= 1.5;
  expect(checkConfiguration(model, bad), StatusCode::BadConfiguration,
         {"q: joint 'hip' quaternion (entries 7-10, w x y z) has norm 1.5", "normalizeConfiguration fixes it"});
  expect(difference(model, q, bad, dv), StatusCode::BadConfiguration, {"q1: joint 'hip' quaternion"});
  bad = q;
  bad.segment<4>(18).setZero();
  expect(checkConfiguration(model, bad), StatusCode::BadConfiguration,
         {"q: joint 'drone' quaternion (entries 18-21, w x y z) is zero: not an orientation"});
  // Sizes: multi-DOF joints count their coordinates (worded as the solver words qd, tau).
  Eigen::VectorXd short_q = q.head(model.nq() - 1);
  expect(checkConfiguration(model, short_q), StatusCode::SizeMismatch,
         {"q has 23 entries, the model has nq = 24 (7 base coordinates + 17 joint coordinates)"});
  expect(integrate(model, q, v.head(model.nv() - 1), 0.1, out), StatusCode::SizeMismatch,
         {"v has 20 entries, the model has nv = 21 (6 base velocity coordinates + 15 joint DOFs)"});
  const Model fixed = handModel(BaseType::Fixed);
  expect(checkConfiguration(fixed, short_q), StatusCode::SizeMismatch,
         {"q has 23 entries, the model has nq = 17 (0 base coordinates + 17 joint coordinates)"});
  // Overflows name the entry.
  Eigen::VectorXd big = v;
  big[13] = 1e300;  // drone linear velocity x
  expect(integrate(model, q, big, 1e10, out), StatusCode::NonFinite, {"joint 'drone' position", "too large"});
}

TEST_CASE("configuration joints: entries up to 1e100 never overflow (one pass), beyond them errors change nothing",
          "[configuration]") {
  // integrate and difference skip their overflow checks when every entry of
  // q and v·dt is at most 1e100 (configuration.cpp): the outputs must then be finite.
  const Model model = handModel();
  std::mt19937_64 rng(2514);
  Eigen::VectorXd q(model.nq()), q1(model.nq()), out(model.nq()), dv(model.nv());
  for (int draw = 0; draw < 2000; ++draw) {
    std::uint64_t state = rng();
    REQUIRE(randomConfiguration(model, state, q));
    REQUIRE(randomConfiguration(model, state, q1));
    Eigen::VectorXd v(model.nv());
    for (Eigen::Index k = 0; k < v.size(); ++k) v[k] = (rng() % 2 ? 1e100 : -1e100) * uniform(rng, 0.5, 1.0);
    for (const Joint& joint : model.allJoints())  // positions and one-DOF coordinates at the bound too
      for (int k = 0; k < (joint.type == JointType::Spherical ? 0
                           : joint.type == JointType::Free    ? 3
                                                              : joint.nq());
           ++k) {
        q[joint.q_index + k] = rng() % 2 ? 1e100 : -1e100;
        q1[joint.q_index + k] = rng() % 2 ? 1e100 : -1e100;
      }
    REQUIRE(integrate(model, q, v, 1.0, out));
    CHECK(out.allFinite());
    REQUIRE(difference(model, q, q1, dv));
    CHECK(dv.allFinite());
  }
  // Beyond the bound the checks run: an overflow in the last joint leaves q_out as it was.
  Eigen::VectorXd v = Eigen::VectorXd::Constant(model.nv(), 1e200);
  out.setConstant(-7.0);
  const Status s = integrate(model, q, v, 1e200, out);
  CHECK(s.code == StatusCode::NonFinite);
  CHECK((out.array() == -7.0).all());
}
