// The standing balance's dense reference (standing_reference.hpp).
#include "standing_reference.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/LU>

#include "cli.hpp"

namespace zwang::cli::standing {

namespace {

void require(const Status& s, const std::string& context) {
  if (!s) throw CliError(kExitError, context + s.message);
}

// Gᵀ of the task's rows, built densely from the feet's world Jacobians and
// the joint rows' unit torques, independently of the solver's sweeps.
Eigen::MatrixXd balanceTranspose(const Model& model, Workspace& ws, const std::vector<std::string>& feet,
                                 int contact_rows, const Eigen::VectorXd& q) {
  const int contacts = contact_rows * static_cast<int>(feet.size()), n = model.dof(), nv = model.nv();
  Eigen::MatrixXd Gt = Eigen::MatrixXd::Zero(nv, contacts + n);
  Eigen::MatrixXd J(6, nv);
  for (std::size_t k = 0; k < feet.size(); ++k) {
    require(frameJacobian(model, ws, q, model.frameIndex(feet[k]), Expressed::World, J), "energy: ");
    Gt.middleCols(contact_rows * static_cast<int>(k), contact_rows) = J.topRows(contact_rows).transpose();
  }
  Gt.bottomRightCorner(n, n).setIdentity();
  return Gt;
}

}  // namespace

DenseBalance denseBalance(const Model& model, Workspace& ws, const std::vector<std::string>& feet, int contact_rows,
                          const Eigen::VectorXd& q, const std::string& context) {
  const int n = model.dof();
  DenseBalance d;
  d.Gt_matrix = balanceTranspose(model, ws, feet, contact_rows, q);
  d.Gt.compute(d.Gt_matrix);
  const Task gravity_only(model);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(model.nv());
  require(inverseDynamics(model, ws, q, zero, zero, gravity_only), context + "RNEA: ");
  d.gravity = ws.tau;
  d.tau0 = d.Gt.solve(d.gravity).tail(n);
  return d;
}

BestSplit bestSplit(const DenseBalance& d, int contact_rows) {
  const Eigen::Index n = d.tau0.size();
  const Eigen::MatrixXd internal = Eigen::FullPivLU<Eigen::MatrixXd>(d.Gt_matrix).kernel();
  const Eigen::MatrixXd on_joints = internal.bottomRows(n);
  const Eigen::VectorXd z = -on_joints.completeOrthogonalDecomposition().solve(d.tau0);
  const Eigen::VectorXd nu = d.Gt.solve(d.gravity) + internal * z;
  BestSplit best;
  best.sq = nu.tail(n).squaredNorm();
  for (Eigen::Index foot = 0; foot + contact_rows <= nu.size() - n; foot += contact_rows)
    best.tangential = std::max(best.tangential, nu.segment<2>(foot).norm() / nu[foot + 2]);
  return best;
}

}  // namespace zwang::cli::standing
