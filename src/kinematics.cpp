#include "zwang/kinematics.hpp"

#include "internal/checks.hpp"
#include "internal/sweeps.hpp"

namespace zwang {
namespace internal {

void outwardKinematics(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q,
                       const Eigen::Ref<const Eigen::VectorXd>& qd, Workspace& ws) {
  const bool with_velocity = qd.size() == model.dof();
  for (int i = 1; i <= model.dof(); ++i) {
    const auto b = static_cast<std::size_t>(i);
    const Joint& joint = model.joint(i - 1);
    ws.Xup[b] = joint.transform(q[i - 1]);             // line 4
    ws.Xworld[b] = ws.Xup[b] * ws.Xworld[b - 1];
    ws.S[b] = joint.motionSubspace();
    if (with_velocity) {
      const Vec6 vJ = ws.S[b] * qd[i - 1];
      ws.v[b] = ws.Xup[b].applyMotion(ws.v[b - 1]) + vJ;  // line 5
      ws.c[b] = spatial::crossMotion(ws.v[b], vJ);       // line 6
    } else {
      ws.v[b].setZero();
      ws.c[b].setZero();
    }
  }
}

void applyExternalWrenches(const Model& model, const Task& task, Workspace& ws) {
  for (const Task::AppliedWrench& w : task.wrenches()) {
    const int body = model.frame(w.frame).body;
    if (body == 0) continue;  // a wrench on the fixed base moves nothing
    ws.Fbias[static_cast<std::size_t>(body)] -= internal::wrenchOnBody(model, ws, w.frame, w.expressed, w.value);
  }
}

}  // namespace internal

Status forwardKinematics(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                         const Eigen::Ref<const Eigen::VectorXd>& qd) {
  if (ws.dof() != model.dof())
    return Status::error(StatusCode::ModelMismatch, "workspace was made for %d joints, the model has %d", ws.dof(),
                         model.dof());
  if (Status s = internal::checkVector("q", q, model.dof()); !s) return s;
  if (qd.size() != 0)
    if (Status s = internal::checkVector("qd", qd, model.dof()); !s) return s;
  internal::outwardKinematics(model, q, qd, ws);
  return {};
}

Eigen::Isometry3d framePose(const Model& model, const Workspace& ws, int frame) {
  const Frame& f = model.frame(frame);
  const Transform X = f.placement * ws.Xworld[static_cast<std::size_t>(f.body)];  // ᶠX_0
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = X.E.transpose();
  T.translation() = X.r;
  return T;
}

namespace {
// [lin; ang] of a frame-local 6-vector, re-expressed as asked.
Vec6 express(const Model& model, const Workspace& ws, int frame, Expressed expressed, const Vec6& local) {
  if (expressed == Expressed::Local) return local;
  const Mat3 R = internal::frameRotation(model, ws, frame);
  Vec6 out;
  out << R * local.head<3>(), R * local.tail<3>();
  return out;
}
}  // namespace

Vec6 frameVelocity(const Model& model, const Workspace& ws, int frame, Expressed expressed) {
  const Frame& f = model.frame(frame);
  return express(model, ws, frame, expressed, f.placement.applyMotion(ws.v[static_cast<std::size_t>(f.body)]));
}

Vec6 frameAcceleration(const Model& model, const Workspace& ws, int frame, Expressed expressed) {
  const Frame& f = model.frame(frame);
  const auto b = static_cast<std::size_t>(f.body);
  // The body's true spatial acceleration is held in the solution (classical,
  // body frame); recover the spatial one, carry it to the frame, then add ω×v
  // of the frame origin (SPEC: a_classical = a_spatial + ω × v).
  const Vec6& classical_body = ws.solution.body_acc_local[b];
  const Vec6& vb = ws.v[b];
  Vec6 spatial_body = classical_body;
  spatial_body.head<3>() -= vb.tail<3>().cross(vb.head<3>());
  const Vec6 vf = f.placement.applyMotion(vb);
  Vec6 af = f.placement.applyMotion(spatial_body);
  af.head<3>() += vf.tail<3>().cross(vf.head<3>());
  return express(model, ws, frame, expressed, af);
}

Status frameJacobian(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q, int frame,
                     Expressed expressed, Eigen::Ref<Eigen::MatrixXd> J) {
  if (J.rows() != 6 || J.cols() != model.dof())
    return Status::error(StatusCode::SizeMismatch, "Jacobian output is %ldx%ld, expected 6x%d",
                         static_cast<long>(J.rows()), static_cast<long>(J.cols()), model.dof());
  if (Status s = forwardKinematics(model, ws, q); !s) return s;
  const Frame& f = model.frame(frame);
  // Column j: the frame-origin velocity of a unit rate of joint j, in frame
  // axes: ᶠX_{j+1} S_{j+1} for the joints that move the frame's body.
  const Transform Xf0 = f.placement * ws.Xworld[static_cast<std::size_t>(f.body)];
  J.setZero();
  for (int i = 1; i <= f.body; ++i) {
    const auto b = static_cast<std::size_t>(i);
    const Transform Xfi = Xf0 * ws.Xworld[b].inverse();  // ᶠX_i
    J.col(i - 1) = express(model, ws, frame, expressed, Xfi.applyMotion(ws.S[b]));
  }
  return {};
}

}  // namespace zwang
