// Placing a free-floating robot on a plane (include/zwang/placement.hpp). Not a
// hot-path call: it runs forward kinematics once, reads the frames' origins,
// and moves the base rigidly; the frames move with it exactly, since the
// joints stay where they are.
#include "zwang/placement.hpp"

#include <cmath>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "zwang/kinematics.hpp"

#include "dynamics/checks.hpp"
#include "dynamics/sweeps.hpp"

namespace zwang {

namespace {

Status checkPlacement(const Model& model, const std::vector<int>& frames, double height,
                      const Eigen::Ref<Eigen::VectorXd>& q_out) noexcept {
  if (model.baseType() != BaseType::Free)
    return Status::error(StatusCode::ModelMismatch, "placeOnPlane needs a free base (this model's base is %s)",
                         toString(model.baseType()));
  if (frames.empty()) return Status::error(StatusCode::ModelMismatch, "placeOnPlane: no frames given");
  const int count = static_cast<int>(model.frames().size());
  for (const int f : frames)
    if (f < 0 || f >= count)
      return Status::error(StatusCode::ModelMismatch, "frame index %d is not a frame of this model (it has %d frames)",
                           f, count);
  if (!std::isfinite(height)) return Status::error(StatusCode::NonFinite, "placeOnPlane: height is %g", height);
  if (q_out.size() != model.nq())
    return Status::error(StatusCode::SizeMismatch, "q_out has %ld entries, the model has nq = %d",
                         static_cast<long>(q_out.size()), model.nq());
  return {};
}

Vec3 frameOrigin(const Model& model, const Workspace& ws, int frame) {
  return internal::framePlacementInBase(model, ws, frame).r;
}

// The smallest rotation that makes the frames' best-fit plane horizontal (PlaneContact::All), about their centroid.
Eigen::Quaterniond levelling(const Model& model, const Workspace& ws, const std::vector<int>& frames, Vec3& centroid) {
  centroid.setZero();
  for (const int f : frames) centroid += frameOrigin(model, ws, f);
  centroid /= static_cast<double>(frames.size());
  Mat3 scatter = Mat3::Zero();
  for (const int f : frames) {
    const Vec3 d = frameOrigin(model, ws, f) - centroid;
    scatter += d * d.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Mat3> eigen(scatter);  // eigenvalues ascending
  const Vec3 lambda = eigen.eigenvalues();
  const Vec3 up = Vec3::UnitZ();
  if (!(lambda[2] > 0.0)) return Eigen::Quaterniond::Identity();  // one point: any plane holds it
  Vec3 normal = eigen.eigenvectors().col(0);
  // Collinear to rounding (the spread across the line below 1e-6 of the spread along it, λ₁/λ₂ below 1e-12):
  // the plane through the line closest to horizontal, whose normal is the vertical minus its part along the line.
  if (lambda[1] <= 1e-12 * lambda[2]) {
    const Vec3 line = eigen.eigenvectors().col(2);
    normal = up - up.dot(line) * line;
    if (normal.norm() < 1e-12) normal = Vec3::UnitX() - Vec3::UnitX().dot(line) * line;  // a vertical line
    normal.normalize();
  }
  if (normal.dot(up) < 0.0) normal = -normal;
  return Eigen::Quaterniond::FromTwoVectors(normal, up);
}

}  // namespace

Status placeOnPlane(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                    const std::vector<int>& frames, double height, PlaneContact contact,
                    Eigen::Ref<Eigen::VectorXd> q_out, double& distance) noexcept {
  if (Status s = checkPlacement(model, frames, height, q_out); !s) return s;
  if (Status s = forwardKinematics(model, ws, q); !s) return s;
  Vec3 centroid = Vec3::Zero();
  const Eigen::Quaterniond turn =
      contact == PlaneContact::All ? levelling(model, ws, frames, centroid) : Eigen::Quaterniond::Identity();
  const Mat3 R = turn.toRotationMatrix();
  // Every frame origin x moves to R (x − centroid) + centroid, then up by dz.
  double lowest = INFINITY, highest = -INFINITY;
  for (const int f : frames) {
    const double z = (R * (frameOrigin(model, ws, f) - centroid) + centroid).z();
    lowest = std::min(lowest, z);
    highest = std::max(highest, z);
  }
  const double dz = height - lowest;
  // The base (q = [p, w, x, y, z], base → world) moves as its frames do.
  const Vec3 p = q.head<3>();
  const Eigen::Quaterniond base(q[3], q[4], q[5], q[6]);
  const Vec3 p_new = R * (p - centroid) + centroid + Vec3(0.0, 0.0, dz);
  const Eigen::Quaterniond base_new = (turn * base.normalized()).normalized();
  if (q_out.data() != q.data()) q_out = q;
  q_out.head<3>() = p_new;
  q_out.segment<4>(3) << base_new.w(), base_new.x(), base_new.y(), base_new.z();
  distance = highest - lowest;
  return {};
}

}  // namespace zwang
