#include "support/simulation_models.hpp"

namespace zwang::testing {

Model limitPendulum() {
  Joint j;
  j.name = "hinge";
  j.axis = Vec3::UnitY();
  j.lower = -0.5;
  j.upper = 0.5;
  j.breakaway_friction = j.kinetic_friction = 0.05;
  const RigidInertia link =
      RigidInertia::fromMassComInertia(1.0, Vec3(0, 0, -0.5), Vec3(0.01, 0.01, 0.01).asDiagonal());
  return ModelBuilder("pendulum", "base").addJoint(j, "link", link).build();
}

}  // namespace zwang::testing
