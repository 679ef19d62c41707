#include "support/random_chain.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>

#include <Eigen/Geometry>

namespace zwang::testing {

namespace {
constexpr double kPi = 3.14159265358979323846;

// One of ±x, ±y, ±z.
Eigen::Vector3d randomAxisAligned(std::mt19937_64& rng) {
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();
  axis(uniformInt(rng, 0, 2)) = uniform01(rng) < 0.5 ? -1.0 : 1.0;
  return axis;
}

LinkSpec randomLink(std::mt19937_64& rng, const std::string& name) {
  LinkSpec link;
  link.name = name;
  link.mass = uniform(rng, 0.2, 5.0);
  link.com = randomVector(rng, 3, 0.2);
  link.inertial_rpy = uniform01(rng) < 0.3 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(randomVector(rng, 3, kPi));
  link.inertia = randomInertia(rng, link.mass);
  return link;
}
}  // namespace

unsigned long long stressSeedOr(unsigned long long ci_seed) {
  const char* seed_text = std::getenv("ZWANG_STRESS_SEED");
  return seed_text ? ci_seed + std::strtoull(seed_text, nullptr, 10) : ci_seed;
}

double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

double uniform(std::mt19937_64& rng, double lo, double hi) { return lo + (hi - lo) * uniform01(rng); }

int uniformInt(std::mt19937_64& rng, int lo, int hi) {
  const auto span = static_cast<std::uint64_t>(hi - lo + 1);
  return lo + static_cast<int>(rng() % span);
}

double gaussian(std::mt19937_64& rng) {
  // Box–Muller; 1 - u lies in (0, 1], so the logarithm is finite.
  const double u = 1.0 - uniform01(rng);
  const double v = uniform01(rng);
  return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * kPi * v);
}

Eigen::Vector3d randomUnitVector(std::mt19937_64& rng) {
  for (;;) {
    // Named draws: the order of a call's arguments is unspecified in C++, so
    // draws inside one call would differ between compilers (these are in the
    // order g++ evaluated the former one-call form: last argument first).
    const double z = gaussian(rng), y = gaussian(rng), x0 = gaussian(rng);
    const Eigen::Vector3d x(x0, y, z);
    if (x.norm() > 1e-6) return x.normalized();
  }
}

Eigen::Matrix3d randomRotation(std::mt19937_64& rng) {
  for (;;) {
    const double z = gaussian(rng), y = gaussian(rng), x = gaussian(rng), w = gaussian(rng);  // named: see above
    Eigen::Quaterniond quat(w, x, y, z);
    if (quat.norm() > 1e-6) return quat.normalized().toRotationMatrix();
  }
}

Eigen::VectorXd randomVector(std::mt19937_64& rng, int n, double scale) {
  Eigen::VectorXd x(n);
  for (int i = 0; i < n; ++i) x(i) = uniform(rng, -scale, scale);
  return x;
}

Eigen::Matrix3d randomInertia(std::mt19937_64& rng, double mass) {
  // s_k = ∫ x_k² dm of a body of size ~3–30 cm; I_x = s_y + s_z, … are then the
  // principal moments of a real mass distribution.
  const double s_z = mass * uniform(rng, 5e-4, 5e-2), s_y = mass * uniform(rng, 5e-4, 5e-2),
               s_x = mass * uniform(rng, 5e-4, 5e-2);  // named draws: see randomUnitVector
  const Eigen::Vector3d s(s_x, s_y, s_z);
  const Eigen::Vector3d principal(s.y() + s.z(), s.x() + s.z(), s.x() + s.y());
  const Eigen::Matrix3d R = randomRotation(rng);
  const Eigen::Matrix3d I = R * principal.asDiagonal() * R.transpose();
  return 0.5 * (I + I.transpose());  // exactly symmetric
}

namespace {

// A joint of the given kind with a random placement, axis, limits, friction
// and rotor (shared by randomChain and randomTree).
JointSpec randomJoint(std::mt19937_64& rng, const RandomChainOptions& options, const std::string& name, bool fixed) {
  JointSpec joint;
  joint.name = name;
  if (fixed) {
    joint.type = "fixed";
  } else if (uniform01(rng) < options.prismatic_probability) {
    joint.type = "prismatic";
  } else {
    joint.type = uniform01(rng) < options.continuous_probability ? "continuous" : "revolute";
  }
  const double length = uniform(rng, 0.05, 0.5);
  joint.xyz =
      length * (uniform01(rng) < options.axis_aligned_probability ? randomAxisAligned(rng) : randomUnitVector(rng));
  joint.rpy = uniform01(rng) < 0.2 ? Eigen::Vector3d::Zero() : Eigen::Vector3d(randomVector(rng, 3, kPi));
  joint.axis = uniform01(rng) < options.axis_aligned_probability ? randomAxisAligned(rng) : randomUnitVector(rng);
  if (!joint.isFixed()) {
    if (joint.isPrismatic()) {
      joint.lower = -uniform(rng, 0.1, 1.0);
      joint.upper = uniform(rng, 0.1, 1.0);
    } else if (joint.type == "revolute") {
      joint.lower = -uniform(rng, 0.5, kPi);
      joint.upper = uniform(rng, 0.5, kPi);
    }
    joint.effort = uniform(rng, 10.0, 300.0);
    joint.velocity = uniform(rng, 1.0, 5.0);
    joint.friction = uniform(rng, options.friction_min, options.friction_max);
    joint.damping = uniform(rng, options.damping_min, options.damping_max);
    if (options.rotor_inertia && uniform01(rng) < 0.8) {
      joint.rotor_inertia = uniform(rng, 1e-5, 0.05);
      joint.gear_ratio = uniform(rng, 1.0, 100.0);
      // Keep the reflected inertia rotor·ratio² at most 0.5 (ratio stays ≥ √10).
      const double reflected = joint.rotor_inertia * joint.gear_ratio * joint.gear_ratio;
      if (reflected > 0.5) joint.gear_ratio = std::sqrt(0.5 / joint.rotor_inertia);
    }
  }
  return joint;
}

}  // namespace

ChainSpec randomChain(std::mt19937_64& rng, const RandomChainOptions& options) {
  const int n =
      uniformInt(rng, options.min_moving_joints, std::max(options.min_moving_joints, options.max_moving_joints));

  // Joint sequence: maybe a fixed joint, then (moving joint, maybe a fixed joint) × n.
  std::vector<bool> is_fixed;
  if (uniform01(rng) < options.fixed_joint_probability) is_fixed.push_back(true);
  for (int k = 0; k < n; ++k) {
    is_fixed.push_back(false);
    if (uniform01(rng) < options.fixed_joint_probability) is_fixed.push_back(true);
  }

  ChainSpec spec;
  spec.name = "random_chain";
  spec.links.push_back(randomLink(rng, "base"));
  for (std::size_t k = 0; k < is_fixed.size(); ++k) {
    const std::string index = std::to_string(k + 1);
    JointSpec joint = randomJoint(rng, options, "joint" + index, is_fixed[k]);
    spec.joints.push_back(joint);
    spec.links.push_back(randomLink(rng, "link" + index));
  }
  spec.check();
  return spec;
}

ChainSpec randomTree(std::mt19937_64& rng, const RandomTreeOptions& options) {
  const int n =
      uniformInt(rng, options.min_moving_joints, std::max(options.min_moving_joints, options.max_moving_joints));
  const int branching = uniformInt(rng, options.min_branching, std::max(options.min_branching, options.max_branching));
  ChainSpec spec;
  spec.name = "random_tree";
  spec.links.push_back(randomLink(rng, "base"));
  std::vector<int> children(1, 0);
  std::vector<int> path{0};  // links from the base to the last one added: where a depth-first tree may grow
  int moving = 0;
  while (moving < n) {
    // Start a new branch: go back up the path to an earlier link that may
    // still take a child; otherwise grow from the last link.
    const std::vector<int> grow_here = path;
    if (branching > 1 && path.size() > 1 && uniform01(rng) < options.branch_probability)
      path.resize(static_cast<std::size_t>(uniformInt(rng, 1, static_cast<int>(path.size()) - 1)));
    while (path.size() > 1 && children[static_cast<std::size_t>(path.back())] >= branching) path.pop_back();
    if (children[static_cast<std::size_t>(path.back())] >= branching) path = grow_here;  // the last link has none
    const int parent = path.back();
    const bool fixed = uniform01(rng) < options.joints.fixed_joint_probability;
    const std::string index = std::to_string(spec.joints.size() + 1);
    JointSpec joint = randomJoint(rng, options.joints, "joint" + index, fixed);
    joint.parent = parent;
    spec.joints.push_back(joint);
    spec.links.push_back(randomLink(rng, "link" + index));
    ++children[static_cast<std::size_t>(parent)];
    children.push_back(0);
    path.push_back(static_cast<int>(spec.links.size()) - 1);
    if (!fixed) ++moving;
  }
  spec.check();
  return spec;
}

int addRandomMimics(std::mt19937_64& rng, ChainSpec& spec, const RandomMimicOptions& options) {
  std::vector<int> moving = spec.movingJoints();  // indices into spec.joints
  const int n = static_cast<int>(moving.size());
  const int most = std::min(options.max_mimics, n - 1);
  if (most < 1) return 0;
  const int k = uniformInt(rng, std::min(options.min_mimics, most), most);
  for (int s = 0; s < n; ++s)  // Fisher–Yates with the portable uniformInt
    std::swap(moving[static_cast<std::size_t>(s)], moving[static_cast<std::size_t>(uniformInt(rng, s, n - 1))]);
  // moving[0, k): the mimic joints, in the order they are given leaders; the rest independent.
  for (int i = 0; i < k; ++i) {
    JointSpec& joint = spec.joints[static_cast<std::size_t>(moving[static_cast<std::size_t>(i)])];
    const bool chain = i > 0 && uniform01(rng) < options.chain_probability;
    const int leader = chain ? uniformInt(rng, 0, i - 1) : uniformInt(rng, k, n - 1);
    joint.mimic = spec.joints[static_cast<std::size_t>(moving[static_cast<std::size_t>(leader)])].name;
    const double a = uniform(rng, -options.max_multiplier, options.max_multiplier);
    const double b = uniform(rng, -options.max_offset, options.max_offset);
    joint.mimic_multiplier = a;
    joint.mimic_offset = b;
  }
  spec.check();
  return k;
}

}  // namespace zwang::testing
