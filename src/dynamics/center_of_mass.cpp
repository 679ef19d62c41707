// Centre of mass, its velocity, acceleration and Jacobian, and the centroidal
// momentum, from the poses, velocities and accelerations the sweeps leave in
// the workspace (base coordinates, src/dynamics/sweeps.hpp). Unlike
// Pinocchio's centerOfMass, which sums subtree by subtree into per-joint
// arrays, each call sums over the bodies of the one subtree asked for: no
// scratch array, so nothing is added to a Workspace, and the Jacobian walks
// each body's path to the world (O(bodies × depth), the depth small).
#include "zwang/center_of_mass.hpp"

#include "zwang/kinematics.hpp"

#include "dynamics/checks.hpp"
#include "dynamics/sweeps.hpp"

namespace zwang {

namespace {

// The bodies of a subtree: [first, end) (model.hpp: a subtree is contiguous).
struct BodyRange {
  int first = 1;
  int end = 1;
};

Status checkJoint(const Model& model, int joint) noexcept {
  const int joints = static_cast<int>(model.joints().size());
  if (joint == kWholeRobot || (joint >= 0 && joint < joints)) return {};
  return Status::error(StatusCode::ModelMismatch,
                       "joint index %d is not a joint of this model (it has %d joints below the root; kWholeRobot = "
                       "-1 selects the whole robot)",
                       joint, joints);
}

// Every moving body for kWholeRobot (body 0, a fixed base, does not move), else the joint's child and its subtree.
BodyRange bodiesOf(const Model& model, int joint) {
  if (joint == kWholeRobot) return {1, model.bodyCount()};
  const int first = model.joints()[static_cast<std::size_t>(joint)].v_index + 1;
  return {first, model.subtreeEnd(first)};
}

double massOf(const Model& model, BodyRange bodies) {
  double mass = 0.0;
  for (int i = bodies.first; i < bodies.end; ++i) mass += model.inertia(i).mass;
  return mass;
}

// BadConfiguration when the subtree has no mass: a centre of mass needs some.
Status checkMass(const Model& model, int joint, double mass) noexcept {
  if (mass > 0.0) return {};
  if (joint == kWholeRobot)
    return Status::error(StatusCode::BadConfiguration, "the robot has no moving mass: its centre of mass is undefined");
  return Status::error(StatusCode::BadConfiguration,
                       "the subtree of joint '%s' has no mass: its centre of mass is undefined",
                       model.joints()[static_cast<std::size_t>(joint)].name.c_str());
}

// Body i's centre of mass in world coordinates, from its pose ⁱX₀ (E: world → body axes, r: its origin).
Vec3 bodyCom(const Model& model, const WorkspaceScratch& sw, int i) {
  const Transform& X = sw.Xworld[static_cast<std::size_t>(i)];
  return X.r + X.E.transpose() * model.inertia(i).com();
}

// The velocity of the world point p moving with the spatial velocity (or motion subspace column) m, base coordinates.
Vec3 pointVelocity(const Vec6& m, const Vec3& p) { return m.head<3>() + m.tail<3>().cross(p); }

// The bodies a call sums over and their mass.
struct Subtree {
  BodyRange bodies;
  double mass = 0.0;
};

// The checks every call shares: the joint, the workspace (holding the `needed` kinematics at q, qd; None: only made
// for this model), the subtree's mass; `subtree` is what they passed.
Status checkCall(const Model& model, const Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                 const Eigen::Ref<const Eigen::VectorXd>& qd, int joint, KinematicsStage needed, const char* query,
                 Subtree& subtree) noexcept {
  if (Status s = checkJoint(model, joint); !s) return s;
  if (Status s = needed == KinematicsStage::None ? internal::checkKinematicsWorkspace(model, ws)
                                                 : internal::checkKinematicsHeld(model, ws, q, qd, needed, query);
      !s)
    return s;
  subtree.bodies = bodiesOf(model, joint);
  subtree.mass = massOf(model, subtree.bodies);
  return checkMass(model, joint, subtree.mass);
}

}  // namespace

Status subtreeMass(const Model& model, int joint, double& mass) noexcept {
  if (Status s = checkJoint(model, joint); !s) return s;
  mass = massOf(model, bodiesOf(model, joint));
  return {};
}

Status centerOfMass(const Model& model, const Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q, int joint,
                    Vec3& position) noexcept {
  Subtree subtree;
  if (Status s = checkCall(model, ws, q, Eigen::VectorXd(), joint, KinematicsStage::Poses, "centerOfMass", subtree); !s)
    return s;
  const WorkspaceScratch& sw = scratchOf(ws);
  Vec3 moment = Vec3::Zero();  // Σ m_i c_i
  for (int i = subtree.bodies.first; i < subtree.bodies.end; ++i)
    if (model.inertia(i).mass > 0.0) moment += model.inertia(i).mass * bodyCom(model, sw, i);
  position = moment / subtree.mass;
  return {};
}

Status centerOfMassVelocity(const Model& model, const Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                            const Eigen::Ref<const Eigen::VectorXd>& qd, int joint, Vec3& velocity) noexcept {
  Subtree subtree;
  if (Status s = checkCall(model, ws, q, qd, joint, KinematicsStage::Velocities, "centerOfMassVelocity", subtree); !s)
    return s;
  const WorkspaceScratch& sw = scratchOf(ws);
  Vec3 sum = Vec3::Zero();  // Σ m_i ċ_i: the linear momentum
  for (int i = subtree.bodies.first; i < subtree.bodies.end; ++i) {
    const double m = model.inertia(i).mass;
    if (m > 0.0) sum += m * pointVelocity(sw.v[static_cast<std::size_t>(i)], bodyCom(model, sw, i));
  }
  velocity = sum / subtree.mass;
  return {};
}

Status centerOfMassAcceleration(const Model& model, const Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                                const Eigen::Ref<const Eigen::VectorXd>& qd, int joint, Vec3& acceleration) noexcept {
  Subtree subtree;
  if (Status s =
          checkCall(model, ws, q, qd, joint, KinematicsStage::Accelerations, "centerOfMassAcceleration", subtree);
      !s)
    return s;
  const WorkspaceScratch& sw = scratchOf(ws);
  Vec3 sum = Vec3::Zero();  // Σ m_i c̈_i: the rate of the linear momentum
  for (int i = subtree.bodies.first; i < subtree.bodies.end; ++i) {
    const double m = model.inertia(i).mass;
    if (m <= 0.0) continue;
    const auto b = static_cast<std::size_t>(i);
    // sw.a holds the sweep's accelerations, true + [−g; 0] (= sw.a_world): the shift is removed.
    sum += m * internal::classicalAtPoint(sw.a[b] - sw.a_world, sw.v[b], bodyCom(model, sw, i)).head<3>();
  }
  acceleration = sum / subtree.mass;
  return {};
}

Status jacobianCenterOfMass(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q, int joint,
                            Eigen::Ref<Eigen::MatrixXd> J) noexcept {
  if (J.rows() != 3 || J.cols() != model.nv())
    return Status::error(StatusCode::SizeMismatch, "centre-of-mass Jacobian output is %ldx%ld, expected 3x%d (nv)",
                         static_cast<long>(J.rows()), static_cast<long>(J.cols()), model.nv());
  Subtree subtree;
  if (Status s =
          checkCall(model, ws, q, Eigen::VectorXd(), joint, KinematicsStage::None, "jacobianCenterOfMass", subtree);
      !s)
    return s;
  if (!internal::posesHeldAt(model, ws, q))  // the poses a solve or forwardKinematics left at this q serve as they are
    if (Status s = forwardKinematics(model, ws, q); !s) return s;
  const WorkspaceScratch& sw = scratchOf(ws);
  J.setZero();
  // Column k gathers the velocity a unit rate of DOF k gives each body's centre of mass it moves, weighted by mass.
  for (int i = subtree.bodies.first; i < subtree.bodies.end; ++i) {
    const double m = model.inertia(i).mass;
    if (m <= 0.0) continue;
    const Vec3 c = bodyCom(model, sw, i);
    for (int k = i; k >= 1; k = model.parent(k))
      J.col(k - 1) += (m / subtree.mass) * pointVelocity(sw.S[static_cast<std::size_t>(k)], c);
  }
  return {};
}

Status centroidalMomentum(const Model& model, const Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                          const Eigen::Ref<const Eigen::VectorXd>& qd, int joint, Vec6& momentum) noexcept {
  Subtree subtree;
  if (Status s = checkCall(model, ws, q, qd, joint, KinematicsStage::Velocities, "centroidalMomentum", subtree); !s)
    return s;
  const WorkspaceScratch& sw = scratchOf(ws);
  Vec6 about_origin = Vec6::Zero();  // Σ I_i Ẋ_i: [linear; angular about the world origin]
  Vec3 moment = Vec3::Zero();        // Σ m_i c_i
  for (int i = subtree.bodies.first; i < subtree.bodies.end; ++i) {
    const RigidInertia& inertia = model.inertia(i);
    if (inertia.mass <= 0.0 && inertia.Ibar.isZero(0.0)) continue;  // a joint's intermediate body
    const auto b = static_cast<std::size_t>(i);
    about_origin += spatial::inverseTransformInertia(sw.Xworld[b], inertia) * sw.v[b];
    moment += inertia.mass * bodyCom(model, sw, i);
  }
  const Vec3 c = moment / subtree.mass;
  momentum.head<3>() = about_origin.head<3>();
  momentum.tail<3>() = about_origin.tail<3>() - c.cross(about_origin.head<3>());  // moved from the origin to c
  return {};
}

}  // namespace zwang
