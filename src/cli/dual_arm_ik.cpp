// The dual arm's postures by damped least squares (dual_arm_ik.hpp).
#include "dual_arm_ik.hpp"

#include <algorithm>

#include "cli.hpp"

namespace zwang::cli::dual_arm {

namespace {

// The seed of the IK: make_dual_panda.py --check's grasp (left arm, right arm).
const double kSeed[2][7] = {{-0.0597, 0.9013, 0.2395, -2.0689, -0.7983, 2.8788, -0.6992},
                            {-0.1724, 0.8639, -0.0690, -2.1175, 0.3159, 2.9720, 1.0418}};

Eigen::Matrix3d rotZ(double angle) { return Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix(); }

// The world pose a hand must have: at the box's side, z axis towards the box
// (−y for the left hand, +y for the right, torso axes), x axis down.
Eigen::Isometry3d handTarget(const BoxPlacement& box, double side) {
  const Eigen::Matrix3d torso = rotZ(box.torso);
  Eigen::Matrix3d R;
  const Eigen::Vector3d z = torso * Eigen::Vector3d(0.0, -side, 0.0), x(0.0, 0.0, -1.0);
  R.col(0) = x;
  R.col(1) = z.cross(x);
  R.col(2) = z;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = R;
  pose.translation() = torso * (box.centre + Eigen::Vector3d(0.0, side * box.half_width, 0.0));
  return pose;
}

// Damped least squares on one arm's seven joints (columns first..first+6),
// the rest of q fixed; deterministic (fixed seed, fixed iteration rule).
double reachHand(const Model& model, Workspace& ws, Eigen::VectorXd& q, int frame, int first,
                 const Eigen::Isometry3d& target, const std::string& where) {
  Eigen::MatrixXd J(6, model.dof());
  Eigen::Isometry3d pose;
  Vec6 e;
  for (int iteration = 0; iteration < 500; ++iteration) {
    Status s = frameJacobian(model, ws, q, frame, Expressed::World, J);
    if (s) s = framePose(model, ws, q, frame, pose);
    if (!s) throw CliError(kExitError, where + s.message);
    const Eigen::AngleAxisd rotation(target.linear() * pose.linear().transpose());
    e << target.translation() - pose.translation(), rotation.angle() * rotation.axis();
    if (e.norm() < 1e-13) break;
    const Eigen::Matrix<double, 6, 7> Ja = J.middleCols(first, 7);
    const double damping = e.norm() > 1e-3 ? 1e-2 : 1e-6;
    const Eigen::Matrix<double, 6, 6> JJt =
        Ja * Ja.transpose() + damping * damping * Eigen::Matrix<double, 6, 6>::Identity();
    q.segment(first, 7) += Ja.transpose() * JJt.ldlt().solve(e);
  }
  return e.norm();
}

}  // namespace

Eigen::VectorXd reachBox(const Model& model, const BoxPlacement& box, double& error, const std::string& where) {
  Workspace ws(model);
  Eigen::VectorXd q(model.dof());
  q[0] = box.torso;
  for (int k = 0; k < 7; ++k) q[1 + k] = kSeed[0][k], q[8 + k] = kSeed[1][k];
  error = std::max(reachHand(model, ws, q, model.frameIndex("left_tool0"), 1, handTarget(box, 1.0), where),
                   reachHand(model, ws, q, model.frameIndex("right_tool0"), 8, handTarget(box, -1.0), where));
  return q;
}

}  // namespace zwang::cli::dual_arm
