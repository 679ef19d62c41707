// Deterministic random chains and vectors for property tests.
//
// Only the raw 64-bit output of std::mt19937_64 (fully specified by the C++
// standard) is used; the distributions are written here rather than taken from
// <random>, whose distributions differ between standard libraries. The same seed
// therefore gives the same chain on every platform.
#pragma once

#include <cstdint>
#include <random>

#include <Eigen/Core>

#include "support/chain_spec.hpp"

namespace zwang::testing {

struct RandomChainOptions {
  int min_moving_joints = 1;
  int max_moving_joints = 12;
  // Probability of a fixed joint in each gap between moving joints, including
  // the gap before the first and the one after the last.
  double fixed_joint_probability = 0.15;
  double prismatic_probability = 0.2;
  // Of the rotational joints, the share written as "continuous" (no limits).
  double continuous_probability = 0.2;
  // Probability that a joint axis (and separately a joint offset) is along ±x, ±y or ±z.
  double axis_aligned_probability = 0.3;
  bool rotor_inertia = true;                      // random rotor inertias and gear ratios
  double friction_min = 0.0, friction_max = 5.0;  // breakaway friction [N·m or N]
  double damping_min = 0.0, damping_max = 1.0;    // viscous damping
};

// A random test's seed: ci_seed, or ci_seed + N when ZWANG_STRESS_SEED=N is set
// (other draws than CI's, for stress runs).
unsigned long long stressSeedOr(unsigned long long ci_seed);

// Uniform in [0, 1) from the top 53 bits of one draw.
double uniform01(std::mt19937_64& rng);
// Uniform in [lo, hi).
double uniform(std::mt19937_64& rng, double lo, double hi);
// Uniform integer in [lo, hi] (tiny modulo bias, irrelevant for tests).
int uniformInt(std::mt19937_64& rng, int lo, int hi);
// Standard normal (Box–Muller).
double gaussian(std::mt19937_64& rng);
// Uniformly distributed unit vector (normalised Gaussian).
Eigen::Vector3d randomUnitVector(std::mt19937_64& rng);
// Uniformly distributed rotation (normalised Gaussian quaternion).
Eigen::Matrix3d randomRotation(std::mt19937_64& rng);
// n entries uniform in [-scale, scale].
Eigen::VectorXd randomVector(std::mt19937_64& rng, int n, double scale = 1.0);
// A physically valid rotational inertia for `mass`: principal moments built from
// random second moments s_x, s_y, s_z (so I_1 = s_y + s_z etc. satisfy the triangle
// inequality strictly), turned by a random rotation.
Eigen::Matrix3d randomInertia(std::mt19937_64& rng, double mass);

// A random serial chain (see RandomChainOptions): links "base", "link1", …,
// joints "joint1", …; moving joints are revolute, continuous or prismatic,
// fixed joints may sit between, before and after them. Masses 0.2–5 kg, offsets
// 0.05–0.5 m, random COMs and inertias; reflected rotor inertias ≤ 0.5.
ChainSpec randomChain(std::mt19937_64& rng, const RandomChainOptions& options = {});

struct RandomTreeOptions {
  RandomChainOptions joints;  // joint kinds, friction, rotor inertias (moving-joint counts below)
  int min_moving_joints = 2;
  int max_moving_joints = 30;
  int min_branching = 1;  // the most children any link may have, drawn per tree in [min, max]
  int max_branching = 4;
  double branch_probability = 0.4;  // that a joint starts a new branch off an earlier link of the path
};

// A random kinematic tree in depth-first order (ChainSpec with parents): links
// "base", "link1", …, joints "joint1", …, each link with at most `branching`
// children, fixed joints anywhere (also as parents of moving ones). Masses,
// offsets and joints as randomChain.
ChainSpec randomTree(std::mt19937_64& rng, const RandomTreeOptions& options = {});

struct RandomMimicOptions {
  int min_mimics = 1;  // at most dof − 1: one joint at least stays independent
  int max_mimics = 3;
  double max_multiplier = 2.0;     // a uniform in [−max, max]
  double max_offset = 0.5;         // b uniform in [−max, max]
  double chain_probability = 0.3;  // that a mimic joint follows another mimic joint (a chain m → k → l)
};

// Make min..max of the spec's moving joints mimic joints (JointSpec::mimic):
// each follows an independent moving joint or, with chain_probability, a mimic
// joint chosen before it (so there is never a cycle), with a random multiplier
// and offset. Returns the number made.
int addRandomMimics(std::mt19937_64& rng, ChainSpec& spec, const RandomMimicOptions& options = {});

}  // namespace zwang::testing
