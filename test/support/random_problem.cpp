#include "support/random_problem.hpp"

#include <Eigen/SVD>

#include "support/random_chain.hpp"
#include "support/urdf_writer.hpp"

namespace zwang::testing {

namespace {

Vector6d randomColumn(std::mt19937_64& rng) {
  Vector6d a = Vector6d::Zero();
  if (uniform01(rng) < 0.5) {
    a[uniformInt(rng, 0, 5)] = 1.0;  // a pure force or moment along an axis
  } else {
    for (int k = 0; k < 6; ++k) a[k] = gaussian(rng);
    a.normalize();
  }
  return a;
}

const std::string& randomLink(std::mt19937_64& rng, const ChainSpec& spec) {
  // Any link but the base (constraints and wrenches on the fixed base are
  // tested separately).
  return spec.links[static_cast<std::size_t>(uniformInt(rng, 1, static_cast<int>(spec.links.size()) - 1))].name;
}

}  // namespace

DynamicsInput randomProblem(std::mt19937_64& rng, const ChainSpec& spec, const RandomProblemOptions& options) {
  DynamicsInput in;
  const int n = spec.dof();
  in.q = randomVector(rng, n, 3.0);
  in.qd = randomVector(rng, n, 2.0);
  in.tau = randomVector(rng, n, 10.0);
  if (uniform01(rng) < options.gravity_probability)
    in.gravity = 9.81 * randomUnitVector(rng);
  else
    in.gravity.setZero();
  const int wrenches = uniformInt(rng, 0, options.max_wrenches);
  for (int w = 0; w < wrenches; ++w) {
    WrenchInput wi;
    wi.link = randomLink(rng, spec);
    for (int k = 0; k < 6; ++k) wi.wrench[k] = 5.0 * gaussian(rng);
    wi.axes = uniform01(rng) < 0.5 ? Axes::Local : Axes::World;
    in.wrenches.push_back(wi);
  }
  int rows = uniformInt(rng, 0, options.max_constraint_rows);
  const int frames = options.end_effector_only ? 1 : uniformInt(rng, 1, options.max_constraint_frames);
  for (int f = 0; f < frames && rows > 0; ++f) {
    const int here = f == frames - 1 ? rows : uniformInt(rng, 1, rows);
    rows -= here;
    ConstraintInput c;
    c.link = options.end_effector_only ? spec.links.back().name : randomLink(rng, spec);
    c.A.resize(6, here);
    for (int k = 0; k < here; ++k) c.A.col(k) = randomColumn(rng);
    c.b = randomVector(rng, here, 3.0);
    c.axes = uniform01(rng) < 0.5 ? Axes::Local : Axes::World;
    if (options.relative_probability > 0.0 && uniform01(rng) < options.relative_probability) {
      c.relative_to = randomLink(rng, spec);
      if (c.relative_to == c.link) c.relative_to = spec.links[0].name;  // the base: an absolute row in disguise
      const double axes = uniform01(rng);
      c.axes = axes < 1.0 / 3 ? Axes::Local : axes < 2.0 / 3 ? Axes::World : Axes::Reference;
    }
    in.constraints.push_back(c);
  }
  spec.followMimicLaws(in.q, in.qd);  // a mimic joint's q and q̇ are its leader's (no draws)
  return in;
}

Model modelFromSpec(const ChainSpec& spec) {
  // A chain's <mimic> joints are loaded as mimic joints (UrdfOptions::mimic = MimicJoints::Model, the default).
  return spec.isChain() ? loadUrdfString(toUrdf(spec)) : modelFromSpecByBuilder(spec);
}

Model modelFromSpecByBuilder(const ChainSpec& spec) {
  // What the spec means (chain_spec.hpp): the joint frame at (xyz, rpy) in the
  // parent link, the child link frame = joint frame moved by q, the link's
  // inertia about its COM in the frame (com, inertial_rpy).
  ModelBuilder builder(spec.name, spec.links[0].name);
  for (std::size_t k = 0; k < spec.joints.size(); ++k) {
    const JointSpec& js = spec.joints[k];
    const LinkSpec& child = spec.links[k + 1];
    const std::string& parent = spec.links[static_cast<std::size_t>(spec.parentLink(k))].name;
    const Eigen::Matrix3d R_inertial = rpyToMatrix(child.inertial_rpy);
    const RigidInertia inertia =
        RigidInertia::fromMassComInertia(child.mass, child.com, R_inertial * child.inertia * R_inertial.transpose());
    const Transform placement = Transform::fromPose(rpyToMatrix(js.rpy), js.xyz);
    if (js.isFixed()) {
      builder.addFixedFrame(child.name, parent, placement, inertia);
      continue;
    }
    Joint joint;
    joint.name = js.name;
    joint.type = js.isPrismatic()          ? JointType::Prismatic
                 : js.type == "continuous" ? JointType::Continuous
                 : js.isSpherical()        ? JointType::Spherical
                 : js.isFree()             ? JointType::Free
                 : js.isPlanar()           ? JointType::Planar
                                           : JointType::Revolute;
    joint.axis = js.axis;
    joint.placement = placement;
    joint.rotor_inertia = js.reflectedInertia();
    joint.breakaway_friction = js.friction;
    joint.kinetic_friction = js.friction;
    joint.viscous_friction = js.damping;
    if (joint.type != JointType::Continuous && js.nv() == 1) {  // multi-DOF joints have no position limits
      joint.lower = js.lower;
      joint.upper = js.upper;
    }
    joint.effort_limit = js.effort;
    joint.velocity_limit = js.velocity;
    builder.addJoint(joint, child.name, inertia, parent);
  }
  // Mimic laws once every joint exists (a leader may come after its follower),
  // as written: chains of mimics are the builder's to resolve.
  for (const JointSpec& js : spec.joints)
    if (!js.isFixed() && js.isMimic()) builder.setMimic(js.name, js.mimic, js.mimic_multiplier, js.mimic_offset);
  return builder.build();
}

Task taskFromInput(const Model& model, const DynamicsInput& input) {
  Task task(model);
  task.gravity = input.gravity;
  auto expressed = [](Axes axes) {
    return axes == Axes::Local ? Expressed::Local : axes == Axes::World ? Expressed::World : Expressed::Reference;
  };
  for (const WrenchInput& w : input.wrenches) task.wrench(task.addWrench(w.link, expressed(w.axes))) = w.wrench;
  for (const ConstraintInput& c : input.constraints) {
    int first = 0;
    if (c.joint >= 0)
      first = task.addJointConstraint(c.joint);
    else if (c.contact)
      first = task.addContact(c.link, c.A, expressed(c.axes));
    else if (c.relative_to.empty())
      first = task.addConstraint(c.link, c.A, expressed(c.axes));
    else
      first = task.addRelativeConstraint(c.link, c.relative_to, c.A, expressed(c.axes));
    task.targets().segment(first, c.b.size()) = c.b;
  }
  return task;
}

Model floatingModelFromSpec(const ChainSpec& spec, const FloatingBase& base) {
  ModelBuilder builder(modelFromSpecByBuilder(spec));
  const LinkSpec& root = spec.links[0];  // the fixed-base builder leaves the root link's own inertia out
  const Eigen::Matrix3d R = rpyToMatrix(root.inertial_rpy);
  builder.addBaseLinkInertia(RigidInertia::fromMassComInertia(root.mass, root.com, R * root.inertia * R.transpose()));
  if (base.kind == BaseKind::Free) builder.setBase(BaseType::Free);
  if (base.kind == BaseKind::Planar)
    builder.setBase(BaseType::Planar, Transform::fromPose(base.plane.linear(), base.plane.translation()));
  return builder.build();
}

Task floatingTaskFromInput(const Model& model, const FloatingInput& input) {
  DynamicsInput as_fixed;
  as_fixed.gravity = input.gravity;
  as_fixed.wrenches = input.wrenches;
  as_fixed.constraints = input.constraints;
  return taskFromInput(model, as_fixed);
}

double relativeError(const Eigen::VectorXd& x, const Eigen::VectorXd& y) {
  if (x.size() != y.size()) return std::numeric_limits<double>::infinity();
  if (x.size() == 0) return 0.0;
  return (x - y).cwiseAbs().maxCoeff() / std::max(1.0, y.cwiseAbs().maxCoeff());
}

bool wellPosed(const DenseResult& dense, const DynamicsInput& input) {
  // Every row of G: the input's and one per mimic joint.
  const auto rows = static_cast<int>(dense.G.rows());
  if (!dense.wellConditioned(1e6) || dense.constraint_rank < rows || rows < input.constraintRows()) return false;
  return rows == 0 || Eigen::JacobiSVD<Eigen::MatrixXd>(dense.G).singularValues().minCoeff() >= 1e-6;
}

RandomInverseDynamics::RandomInverseDynamics(std::mt19937_64& rng)
    : spec(randomChain(rng)),
      in(randomProblem(rng, spec)),
      model(modelFromSpec(spec)),
      task(taskFromInput(model, in)),
      ws(model, task),
      qdd(randomVector(rng, spec.dof(), 5.0)) {}

Status RandomInverseDynamics::solve() { return inverseDynamics(model, ws, in.q, in.qd, qdd, task); }

}  // namespace zwang::testing
