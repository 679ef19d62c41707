#include "support/joint_types_problem.hpp"

#include "support/random_chain.hpp"

namespace zwang::testing {

// A random unit quaternion (w x y z), uniform on the sphere.
Eigen::Vector4d randomQuaternion(std::mt19937_64& rng) {
  for (;;) {  // the draws in sequence (a constructor's arguments are evaluated in no set order)
    const double w = gaussian(rng), x = gaussian(rng), y = gaussian(rng), z = gaussian(rng);
    const Eigen::Vector4d quat(w, x, y, z);
    if (quat.norm() > 1e-6) return quat.normalized();
  }
}
// A random tree (randomTree) whose moving joints become spherical (probability `spherical`), planar (0.1) or free
// (0.05), anywhere below the root; the rest stay one-DOF. Multi-DOF joints have no limits.
ChainSpec randomJointTypesTree(std::mt19937_64& rng, int min_moving, int max_moving, double spherical) {
  RandomTreeOptions options;
  options.min_moving_joints = min_moving;
  options.max_moving_joints = max_moving;
  ChainSpec spec = randomTree(rng, options);
  spec.name = "joint_types_tree";
  for (JointSpec& joint : spec.joints) {
    if (joint.isFixed()) continue;
    const double u = uniform01(rng);
    if (u < spherical)
      joint.type = "spherical";
    else if (u < spherical + 0.1)
      joint.type = "planar";
    else if (u < spherical + 0.15)
      joint.type = "free";
    else
      continue;
    joint.lower = joint.upper = 0.0;
  }
  spec.check();
  return spec;
}

FloatingBase randomBase(std::mt19937_64& rng) {
  FloatingBase base;
  const double u = uniform01(rng);
  base.kind = u < 0.4 ? BaseKind::Fixed : u < 0.7 ? BaseKind::Free : BaseKind::Planar;
  return base;
}

// q: the base's pose, one-DOF joints inside their limits (±π without), unit quaternions, planar x, y in ±0.5 m
// and ψ in ±π, free positions in ±1 m. v, τ: entries in ±2 and ±5 (τ 0 on the base).
void drawState(std::mt19937_64& rng, const ChainSpec& spec, const FloatingBase& base, FloatingInput& in) {
  in.q.resize(base.nq(spec));
  Eigen::Index qi = 0;
  if (base.kind == BaseKind::Free) {
    in.q.head<3>() = randomVector(rng, 3, 2.0);
    in.q.segment<4>(3) = randomQuaternion(rng);
  } else if (base.kind == BaseKind::Planar) {
    in.q.head<3>() << uniform(rng, -2.0, 2.0), uniform(rng, -2.0, 2.0), uniform(rng, -3.14159, 3.14159);
  }
  qi = base.baseConfigurationSize();
  for (const int k : spec.movingJoints()) {
    const JointSpec& joint = spec.joints[static_cast<std::size_t>(k)];
    if (joint.isSpherical()) {
      in.q.segment<4>(qi) = randomQuaternion(rng);
    } else if (joint.isFree()) {
      in.q.segment<3>(qi) = randomVector(rng, 3, 1.0);
      in.q.segment<4>(qi + 3) = randomQuaternion(rng);
    } else if (joint.isPlanar()) {
      in.q.segment<3>(qi) << uniform(rng, -0.5, 0.5), uniform(rng, -0.5, 0.5), uniform(rng, -3.14159, 3.14159);
    } else if (joint.upper > joint.lower && joint.type != "continuous") {
      const double margin = 0.05 * (joint.upper - joint.lower);
      in.q(qi) = uniform(rng, joint.lower + margin, joint.upper - margin);
    } else {
      in.q(qi) = uniform(rng, -3.14159, 3.14159);
    }
    qi += joint.nq();
  }
  const int nv = base.nv(spec);
  in.v = randomVector(rng, nv, 2.0);
  in.tau = randomVector(rng, nv, 5.0);
  in.tau.head(base.baseVelocitySize()).setZero();
}

// Friction data for n DOFs, to be filled.
FrictionSetup sizedFrictionSetup(int n) {
  FrictionSetup setup;
  setup.breakaway.resize(n);
  setup.kinetic.resize(n);
  setup.viscous.resize(n);
  return setup;
}

// Every joint DOF (after the base's) moving at 0.1–2 either way.
void moveEveryDof(std::mt19937_64& rng, int base_velocity_size, int n, FloatingInput& in) {
  for (int k = 0; k < n; ++k)
    in.v(base_velocity_size + k) = (uniform01(rng) < 0.5 ? -1.0 : 1.0) * uniform(rng, 0.1, 2.0);
}

// A random state of the tree on `base` with the loads and frame rows of randomProblem (its q unused), in that
// order of draws.
FloatingInput loadedInput(std::mt19937_64& rng, const ChainSpec& spec, const FloatingBase& base,
                          const RandomProblemOptions& options) {
  const DynamicsInput loads = randomProblem(rng, spec, options);
  FloatingInput in;
  drawState(rng, spec, base, in);
  in.gravity = loads.gravity;
  in.wrenches = loads.wrenches;
  in.constraints = loads.constraints;
  return in;
}

RandomProblemOptions rowOptions(int max_rows, double relative) {
  RandomProblemOptions options;
  options.max_constraint_rows = max_rows;
  options.relative_probability = relative;
  return options;
}

LoadedTree drawLoadedTree(std::mt19937_64& rng, int min_moving, int max_moving, double spherical,
                          const RandomProblemOptions& options) {
  ChainSpec spec = randomJointTypesTree(rng, min_moving, max_moving, spherical);
  const FloatingBase base = randomBase(rng);
  FloatingInput in = loadedInput(rng, spec, base, options);
  Model model = floatingModelFromSpec(spec, base);
  return {std::move(spec), base, std::move(in), std::move(model)};
}

bool makeContact(std::mt19937_64& rng, const FloatingBase& base, FloatingInput& in) {
  if (base.kind == BaseKind::Fixed || uniform01(rng) < 0.5) return false;
  for (ConstraintInput& c : in.constraints)
    if (c.joint < 0 && c.relative_to.empty()) {
      c.contact = true;
      return true;
    }
  return false;
}

}  // namespace zwang::testing
