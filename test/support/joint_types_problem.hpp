// Random problems on trees of every joint type (issue #25), shared by the tests that compare them with the dense
// reference and the friction brute force (test_joint_types_reference, test_prescribed, test_constraint_wrench,
// test_center_of_mass): the trees, their bases, their states and loads, and which draws are well posed.
#pragma once

#include <random>

#include "support/floating_reference.hpp"
#include "support/friction_reference.hpp"
#include "support/random_problem.hpp"

namespace zwang::testing {

// A random unit quaternion (w x y z), uniform on the sphere.
Eigen::Vector4d randomQuaternion(std::mt19937_64& rng);

// A random tree (randomTree) whose moving joints become spherical (probability `spherical`), planar (0.1) or free
// (0.05), anywhere below the root; the rest stay one-DOF. Multi-DOF joints have no limits.
ChainSpec randomJointTypesTree(std::mt19937_64& rng, int min_moving, int max_moving, double spherical);

// A fixed (0.4), free (0.3) or planar (0.3) base.
FloatingBase randomBase(std::mt19937_64& rng);

// q: the base's pose, one-DOF joints inside their limits (±π without), unit quaternions, planar x, y in ±0.5 m
// and ψ in ±π, free positions in ±1 m. v, τ: entries in ±2 and ±5 (τ 0 on the base).
void drawState(std::mt19937_64& rng, const ChainSpec& spec, const FloatingBase& base, FloatingInput& in);

// Friction data for n DOFs, to be filled.
FrictionSetup sizedFrictionSetup(int n);

// Every joint DOF (after the base's) moving at 0.1–2 either way.
void moveEveryDof(std::mt19937_64& rng, int base_velocity_size, int n, FloatingInput& in);

// A random state of the tree on `base` with the loads and frame rows of randomProblem (its q unused), in that
// order of draws.
FloatingInput loadedInput(std::mt19937_64& rng, const ChainSpec& spec, const FloatingBase& base,
                          const RandomProblemOptions& options);

// randomProblem's options with up to `max_rows` task rows (on up to three frames), a frame's rows relative to
// another link with probability `relative`.
RandomProblemOptions rowOptions(int max_rows, double relative);

// One draw of the dense-reference comparisons: a tree (randomJointTypesTree), its base (randomBase), its loaded
// input (loadedInput), in that order of draws, and its model (floatingModelFromSpec).
struct LoadedTree {
  ChainSpec spec;
  FloatingBase base;
  FloatingInput in;
  Model model;
};
LoadedTree drawLoadedTree(std::mt19937_64& rng, int min_moving, int max_moving, double spherical,
                          const RandomProblemOptions& options);

// One of the input's absolute frame constraints made a contact (the environment's force) on a floating base, half
// the time: false when none is.
bool makeContact(std::mt19937_64& rng, const FloatingBase& base, FloatingInput& in);

}  // namespace zwang::testing
