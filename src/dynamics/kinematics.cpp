#include "zwang/kinematics.hpp"

#include <cmath>

#include "dynamics/checks.hpp"
#include "dynamics/sweeps.hpp"

namespace zwang {
namespace internal {

namespace {

// The motion subspace of a DOF in base coordinates: [p × a; a] for a rotation
// about the world axis a through the body origin p, [a; 0] for a translation.
ZWANG_ALWAYS_INLINE void motionSubspace(bool rotation, const Vec3& a, const Vec3& p, Vec6& S) {
  S.head<3>() = rotation ? Vec3(p.cross(a)) : a;
  S.tail<3>() = rotation ? a : Vec3::Zero();
}

// ʲX_parent(q) of a one-DOF joint: Joint::transform(double)'s expression, with
// the products of the placement the model precomputed (Model::OneDofTransform).
ZWANG_ALWAYS_INLINE Transform jointTransform(const Joint& joint, const Model::OneDofTransform& form, double q) {
  if (joint.type == JointType::Prismatic) return joint.transform(q);
  const double s = std::sin(q), c = std::cos(q);
  Transform X;
  for (int k = 0; k < 3; ++k)
    X.E.col(k) =
        c * joint.placement.E.col(k) - s * form.axis_cross.col(k) + ((1.0 - c) * form.axis_dot[k]) * joint.axis;
  X.r = joint.placement.r;
  return X;
}

// A one-DOF joint (most joints, so the hot path): its body's pose, S,
// inertia, velocity, bias acceleration and bias force in one step.
template <bool kInertia, bool kVelocity>
ZWANG_ALWAYS_INLINE void oneDofKinematics(const Model& model, const Joint& joint, const Model::OneDofTransform& form,
                                          const Eigen::Ref<const Eigen::VectorXd>& q,
                                          const Eigen::Ref<const Eigen::VectorXd>& qd, WorkspaceScratch& sw) {
  const int i = joint.v_index + 1;
  const auto b = static_cast<std::size_t>(i);
  const auto p = static_cast<std::size_t>(model.parent(i));
  const Transform& X = sw.Xworld[b] = jointTransform(joint, form, q[joint.q_index]) * sw.Xworld[p];  // line 4: ⁱX₀
  Vec6& S = sw.S[b];
  motionSubspace(joint.isRevolute(), X.E.transpose() * joint.axis, X.r, S);  // the axis in the world
  if (kInertia) sw.I[b] = spatial::inverseTransformInertia(X, model.inertia(i));
  if (kVelocity) {
    const Vec6 vJ = S * qd[i - 1];
    const Vec6 v = sw.v[b] = sw.v[p] + vJ;                            // line 5
    sw.c[b] = spatial::crossMotion(v, vJ);                            // line 6: Ṡ_i q̇_i = Ẋ_i × S_i q̇_i
    if (kInertia) sw.Fbias[b] = spatial::crossForce(v, sw.I[b] * v);  // line 7, without F_ext
  } else {
    sw.v[b].setZero();
    sw.c[b].setZero();
    sw.Fbias[b].setZero();
  }
}

// A joint of several DOFs: its nv bodies share the child's pose; body k + 1
// takes DOF k's axis, the last the child's inertia and the joint's bias; the
// others carry nothing (no inertia, so no bias force either).
template <bool kInertia, bool kVelocity>
void multiDofKinematics(const Model& model, const Joint& joint, const Eigen::Ref<const Eigen::VectorXd>& q,
                        const Eigen::Ref<const Eigen::VectorXd>& qd, WorkspaceScratch& sw) {
  const std::vector<Dof>& dofs = model.dofs();
  const int first = joint.v_index + 1, last = joint.v_index + joint.nv();
  const auto p = static_cast<std::size_t>(model.parent(first));
  const Transform X = joint.transform(q.data() + joint.q_index) * sw.Xworld[p];  // line 4: ⁱX₀
  // The joint frame's axes in the world, for DOFs whose axis is fixed there
  // (a planar joint's x and y); the others' axes turn with the child.
  bool any_in_joint_frame = false;
  for (int i = first; i <= last; ++i) any_in_joint_frame |= dofs[static_cast<std::size_t>(i - 1)].in_joint_frame;
  const Mat3 Et_joint_frame =
      any_in_joint_frame ? Mat3(sw.Xworld[p].E.transpose() * joint.placement.E.transpose()) : Mat3::Zero();
  const Mat3 Et_child = X.E.transpose();
  Vec6 v = sw.v[p];
  Vec6 vJ_child = Vec6::Zero(), vJ_joint_frame = Vec6::Zero();  // S q̇ by the frame its axes are fixed in
  for (int i = first; i <= last; ++i) {
    const auto b = static_cast<std::size_t>(i);
    const Dof& dof = dofs[b - 1];
    sw.Xworld[b] = X;
    Vec6& S = sw.S[b];
    motionSubspace(dof.rotation, (dof.in_joint_frame ? Et_joint_frame : Et_child) * dof.axis, X.r, S);
    sw.c[b].setZero();
    sw.Fbias[b].setZero();
    if (kInertia && i < last) sw.I[b] = RigidInertia{};
    if (kVelocity) {
      const Vec6 vJ = S * qd[i - 1];
      sw.v[b] = v += vJ;  // line 5
      (dof.in_joint_frame ? vJ_joint_frame : vJ_child) += vJ;
    } else {
      sw.v[b].setZero();
    }
  }
  const auto b = static_cast<std::size_t>(last);
  if (kInertia) sw.I[b] = spatial::inverseTransformInertia(X, model.inertia(last));
  // Line 6 on the joint's last body: Ẍ_bias = Ṡ q̇, where an axis fixed in a
  // body moving with Ẋ turns as Ṡ = Ẋ × S (the child's for most, the
  // parent's for a planar joint's x and y); line 7 there.
  if (kVelocity) {
    sw.c[b] = spatial::crossMotion(v, vJ_child);
    if (any_in_joint_frame) sw.c[b] += spatial::crossMotion(sw.v[p], vJ_joint_frame);
    if (kInertia) sw.Fbias[b] = spatial::crossForce(v, sw.I[b] * v);
  }
}

// Joint by joint: the one place a joint's type matters (its transform and
// its DOFs' axes); every other stage visits DOFs.
template <bool kInertia, bool kVelocity>
ZWANG_FLATTEN void kinematicsOfJoints(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q,
                                      const Eigen::Ref<const Eigen::VectorXd>& qd, WorkspaceScratch& sw) {
  const Model::OneDofTransform* form = model.oneDofTransforms().data();
  for (const Joint& joint : model.allJoints()) {
    if (joint.nv() == 1)
      oneDofKinematics<kInertia, kVelocity>(model, joint, *form, q, qd, sw);
    else
      multiDofKinematics<kInertia, kVelocity>(model, joint, q, qd, sw);
    ++form;
  }
}

}  // namespace

void outwardKinematics(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q,
                       const Eigen::Ref<const Eigen::VectorXd>& qd, Workspace& ws, bool with_inertia) {
  const bool with_velocity = qd.size() == model.nv();
  ws.kinematics.q = q;  // the state the results are of (the queries compare it); sizes kept, no allocation
  if (with_velocity) ws.kinematics.qd = qd;
  WorkspaceScratch& sw = scratchOf(ws);
  if (with_inertia)
    with_velocity ? kinematicsOfJoints<true, true>(model, q, qd, sw)
                  : kinematicsOfJoints<true, false>(model, q, qd, sw);
  else
    with_velocity ? kinematicsOfJoints<false, true>(model, q, qd, sw)
                  : kinematicsOfJoints<false, false>(model, q, qd, sw);
}

void applyExternalWrenches(const Model& model, const Task& task, Workspace& ws) {
  WorkspaceScratch& sw = scratchOf(ws);
  for (const Task::AppliedWrench& w : task.wrenches()) {
    const int body = model.frame(w.frame).body;
    if (body == 0) continue;  // a wrench on the world (a fixed base) moves nothing
    sw.Fbias[static_cast<std::size_t>(body)] -= wrenchInBase(model, ws, w.frame, w.expressed, w.value);
  }
}

Status checkKinematicsWorkspace(const Model& model, const Workspace& ws) noexcept {
  if (ws.dof() != model.dof())
    return Status::error(StatusCode::ModelMismatch, "workspace was made for %d joints, the model has %d", ws.dof(),
                         model.dof());
  if (!workspaceFitsModel(model, ws)) return workspaceMismatch(model, ws);
  return {};
}

}  // namespace internal

namespace {

Status checkFrame(const Model& model, int frame) noexcept {
  const int frames = static_cast<int>(model.frames().size());
  if (frame < 0 || frame >= frames)
    return Status::error(StatusCode::ModelMismatch, "frame index %d is not a frame of this model (it has %d frames)",
                         frame, frames);
  return {};
}

// What each stage is, and which calls compute it, for the messages below.
const char* const kStageNames[] = {"nothing", "poses", "velocities", "accelerations"};
const char* const kStageCalls[] = {"", "forwardKinematics or a solve", "forwardKinematics with qd, or a solve",
                                   "solveHybridDynamics, solveWithFriction or inverseDynamics"};

// The first entry where a given state differs from the one the workspace's
// kinematics were computed at, −1 when none does (entry by entry, exactly).
Eigen::Index firstDifference(const Eigen::VectorXd& held, const Eigen::Ref<const Eigen::VectorXd>& given) {
  for (Eigen::Index k = 0; k < held.size(); ++k)
    if (!(held[k] == given[k])) return k;
  return -1;
}

// NotComputed when the workspace's kinematics are of another `name` (q or qd) than `given`.
Status checkHeldState(const char* query, const char* name, const Eigen::VectorXd& held,
                      const Eigen::Ref<const Eigen::VectorXd>& given, const char* call) noexcept {
  if (given.size() != held.size())
    return Status::error(StatusCode::SizeMismatch, "%s: %s has %ld entries, expected %ld", query, name,
                         static_cast<long>(given.size()), static_cast<long>(held.size()));
  const Eigen::Index entry = firstDifference(held, given);
  if (entry < 0) return {};
  return Status::error(StatusCode::NotComputed,
                       "%s: the workspace holds kinematics at another %s (%s[%ld] = %.15g held, %.15g given); call %s "
                       "first",
                       query, name, name, static_cast<long>(entry), held[entry], given[entry], call);
}

// The frame index and the kinematics held, for the frame queries.
Status checkQuery(const Model& model, const Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                  const Eigen::Ref<const Eigen::VectorXd>& qd, int frame, KinematicsStage needed,
                  const char* query) noexcept {
  if (Status s = checkFrame(model, frame); !s) return s;
  return internal::checkKinematicsHeld(model, ws, q, qd, needed, query);
}

// A classical [linear of the frame origin; angular] 6-vector in world axes,
// re-expressed as asked.
Vec6 express(const Transform& Xf0, Expressed expressed, const Vec6& world) {
  if (expressed != Expressed::Local) return world;
  Vec6 out;
  out << Xf0.E * world.head<3>(), Xf0.E * world.tail<3>();
  return out;
}

// The classical velocity [linear of point p; angular], world axes, of a
// spatial velocity (or motion subspace column) m in base coordinates.
Vec6 velocityAtPoint(const Vec6& m, const Vec3& p) {
  Vec6 out;
  out << m.head<3>() + m.tail<3>().cross(p), m.tail<3>();
  return out;
}

// J's columns after forwardKinematics: column k is the frame-origin velocity
// of a unit rate of DOF k, S_{k+1} seen at the frame origin p, for the DOFs
// that move it: those on the path from its body to the world.
void jacobianColumns(const Model& model, const Workspace& ws, int frame, Expressed expressed,
                     Eigen::Ref<Eigen::MatrixXd>& J) {
  const WorkspaceScratch& sw = scratchOf(ws);
  const Transform X = internal::framePlacementInBase(model, ws, frame);
  J.setZero();
  for (int i = model.frame(frame).body; i >= 1; i = model.parent(i))
    J.col(i - 1) = express(X, expressed, velocityAtPoint(sw.S[static_cast<std::size_t>(i)], X.r));
}

}  // namespace

namespace internal {

Status checkKinematicsHeld(const Model& model, const Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                           const Eigen::Ref<const Eigen::VectorXd>& qd, KinematicsStage needed,
                           const char* query) noexcept {
  if (Status s = checkKinematicsWorkspace(model, ws); !s) return s;
  const auto need = static_cast<int>(needed);
  if (ws.kinematics.stage == KinematicsStage::None)
    return Status::error(StatusCode::NotComputed,
                         "%s: the workspace holds no kinematics (none computed yet, or the last call failed); "
                         "call %s first",
                         query, kStageCalls[need]);
  if (ws.kinematics.model != &model)
    return Status::error(StatusCode::NotComputed,
                         "%s: the workspace's kinematics were computed for another Model object; call %s with this "
                         "model first",
                         query, kStageCalls[need]);
  if (ws.kinematics.stage < needed)
    return Status::error(StatusCode::NotComputed,
                         "%s: the workspace holds %s only (the last call computed no %s); call %s first", query,
                         ws.kinematics.stage == KinematicsStage::Poses ? "poses" : "poses and velocities",
                         kStageNames[need], kStageCalls[need]);
  const bool with_velocity = needed >= KinematicsStage::Velocities;
  const char* redo = needed == KinematicsStage::Accelerations ? kStageCalls[need]
                     : with_velocity                          ? "forwardKinematics(model, ws, q, qd)"
                                                              : "forwardKinematics(model, ws, q)";
  if (Status s = checkHeldState(query, "q", ws.kinematics.q, q, redo); !s) return s;
  if (with_velocity)
    if (Status s = checkHeldState(query, "qd", ws.kinematics.qd, qd, redo); !s) return s;
  return {};
}

bool posesHeldAt(const Model& model, const Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q) {
  return ws.kinematics.stage >= KinematicsStage::Poses && ws.kinematics.model == &model &&
         q.size() == ws.kinematics.q.size() && firstDifference(ws.kinematics.q, q) < 0;
}

}  // namespace internal

Status forwardKinematics(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                         const Eigen::Ref<const Eigen::VectorXd>& qd) noexcept {
  ws.kinematics.stage = KinematicsStage::None;  // until computed below
  if (Status s = internal::checkKinematicsWorkspace(model, ws); !s) return s;
  if (Status s = internal::checkStateConfiguration(model, q); !s) return s;  // a free base's quaternion too
  if (qd.size() != 0)
    if (Status s = internal::checkVelocityVector(model, "qd", qd); !s) return s;
  ws.kinematics.model = &model;
  internal::outwardKinematics(model, q, qd, ws, false);
  ws.kinematics.stage = qd.size() != 0 ? KinematicsStage::Velocities : KinematicsStage::Poses;
  return {};
}

Status framePose(const Model& model, const Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q, int frame,
                 Eigen::Isometry3d& pose) noexcept {
  if (Status s = checkQuery(model, ws, q, Eigen::VectorXd(), frame, KinematicsStage::Poses, "framePose"); !s) return s;
  const Transform X = internal::framePlacementInBase(model, ws, frame);  // ᶠX_0
  pose.setIdentity();
  pose.linear() = X.E.transpose();
  pose.translation() = X.r;
  return {};
}

Status frameVelocity(const Model& model, const Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                     const Eigen::Ref<const Eigen::VectorXd>& qd, int frame, Expressed expressed,
                     Vec6& velocity) noexcept {
  const WorkspaceScratch& sw = scratchOf(ws);
  if (Status s = checkQuery(model, ws, q, qd, frame, KinematicsStage::Velocities, "frameVelocity"); !s) return s;
  const Transform X = internal::framePlacementInBase(model, ws, frame);
  // Ẋ of the frame's body (a floating base's motion included), seen at the frame origin.
  velocity = express(X, expressed, velocityAtPoint(sw.v[static_cast<std::size_t>(model.frame(frame).body)], X.r));
  return {};
}

Status frameAcceleration(const Model& model, const Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                         const Eigen::Ref<const Eigen::VectorXd>& qd, int frame, Expressed expressed,
                         Vec6& acceleration) noexcept {
  const WorkspaceScratch& sw = scratchOf(ws);
  if (Status s = checkQuery(model, ws, q, qd, frame, KinematicsStage::Accelerations, "frameAcceleration"); !s) return s;
  // sw.a holds the sweep's accelerations, true + [−g; 0] (= sw.a_world).
  const Transform X = internal::framePlacementInBase(model, ws, frame);
  const auto b = static_cast<std::size_t>(model.frame(frame).body);
  acceleration = express(X, expressed, internal::classicalAtPoint(sw.a[b] - sw.a_world, sw.v[b], X.r));
  return {};
}

Status frameJacobian(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q, int frame,
                     Expressed expressed, Eigen::Ref<Eigen::MatrixXd> J) noexcept {
  if (J.rows() != 6 || J.cols() != model.nv()) {
    if (model.baseVelocitySize() == 0)
      return Status::error(StatusCode::SizeMismatch, "Jacobian output is %ldx%ld, expected 6x%d",
                           static_cast<long>(J.rows()), static_cast<long>(J.cols()), model.nv());
    return Status::error(StatusCode::SizeMismatch,
                         "Jacobian output is %ldx%ld, expected 6x%d (nv = %d base velocity coordinates + %d %s)",
                         static_cast<long>(J.rows()), static_cast<long>(J.cols()), model.nv(), model.baseVelocitySize(),
                         model.dof(), internal::jointDofsWord(model));
  }
  if (Status s = checkFrame(model, frame); !s) return s;
  if (Status s = internal::checkKinematicsWorkspace(model, ws); !s) return s;
  if (!internal::posesHeldAt(model, ws, q))  // the poses a solve or forwardKinematics left at this q serve as they are
    if (Status s = forwardKinematics(model, ws, q); !s) return s;
  jacobianColumns(model, ws, frame, expressed, J);
  return {};
}

}  // namespace zwang
