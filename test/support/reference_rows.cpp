#include "support/reference_rows.hpp"

#include <limits>

#include <Eigen/SVD>

namespace zwang::testing::reference_rows {

// ⁰R_link of link i (used to turn local components into world ones).
Eigen::Matrix3d axesRotation(const DenseKinematics& kin, int link, Axes axes, int reference) {
  if (axes == Axes::World || (axes == Axes::Reference && reference < 0)) return Eigen::Matrix3d::Identity();
  return kin.poses[static_cast<std::size_t>(axes == Axes::Reference ? reference : link)].linear();
}

// A wrench [f; n] acting at the link origin p, components per `axes`, as a
// Plücker force at the world origin: [f_w; n_w + p × f_w].
Vector6d wrenchAtWorldOrigin(const DenseKinematics& kin, int link, const Vector6d& w, Axes axes) {
  const Eigen::Matrix3d R = axesRotation(kin, link, axes);
  const Eigen::Vector3d p = kin.poses[static_cast<std::size_t>(link)].translation();
  const Eigen::Vector3d f = R * lin(w);
  return stack(f, R * ang(w) + p.cross(f));
}

// Sum of the external Plücker wrenches on each link.
std::vector<Vector6d> externalWrenches(const ChainSpec& spec, const DenseKinematics& kin,
                                       const std::vector<WrenchInput>& wrenches) {
  std::vector<Vector6d> f(spec.links.size(), Vector6d::Zero());
  for (const WrenchInput& w : wrenches) {
    const int link = spec.linkIndex(w.link);
    f[static_cast<std::size_t>(link)] += wrenchAtWorldOrigin(kin, link, w.wrench, w.axes);
  }
  return f;
}

// Classical acceleration [p̈; ω̇] (world axes) of the origin p of a link with
// spatial velocity v = [v_O; ω] and spatial acceleration a = [a_O; α] (both at
// the world origin): ṗ = v_O + ω × p, p̈ = a_O + α × p + ω × ṗ.
Vector6d classicalFromSpatial(const Eigen::Vector3d& p, const Vector6d& v, const Vector6d& a) {
  const Eigen::Vector3d pdot = lin(v) + ang(v).cross(p);
  return stack(lin(a) + ang(a).cross(p) + ang(v).cross(pdot), ang(a));
}

// The rows of a relative constraint (dense_reference.hpp, ConstraintInput):
// with a = J q̈ + J̇ q̇ and the classical acceleration of a point p on a link
// p̈ = a_O + α × p + ω × ṗ, each term of p̈_rel and ω̇_rel splits into a part
// linear in q̈ (into G) and a known part (into γ, with the opposite sign).
void relativeRows(const ChainSpec& spec, const DenseKinematics& kin, const ConstraintInput& c, int first_row,
                  Eigen::MatrixXd& G, Eigen::VectorXd& gamma) {
  const auto a = static_cast<std::size_t>(spec.linkIndex(c.link));
  const auto r = static_cast<std::size_t>(spec.linkIndex(c.relative_to));
  const Eigen::Vector3d pa = kin.poses[a].translation(), pr = kin.poses[r].translation();
  const Eigen::Vector3d wa = ang(kin.v[a]), wr = ang(kin.v[r]);
  const Eigen::Vector3d pa_dot = lin(kin.v[a]) + wa.cross(pa), pr_dot = lin(kin.v[r]) + wr.cross(pr);
  const Eigen::Vector3d d = pa - pr, d_dot = pa_dot - pr_dot;
  // p̈ of a point p on link i: [1, −[p]×] (J_i q̈ + J̇_i q̇) + ω_i × ṗ.
  auto pointRows = [](const Eigen::MatrixXd& J, const Eigen::Vector3d& p) -> Eigen::MatrixXd {
    return J.topRows(3) - skew3(p) * J.bottomRows(3);
  };
  auto pointBias = [](const Vector6d& bias, const Eigen::Vector3d& p) -> Eigen::Vector3d {
    return lin(bias) - p.cross(ang(bias));
  };
  // p̈_rel = p̈_a − p̈_r − α_r × d − 2 ω_r × ḋ + ω_r × (ω_r × d), and −α_r × d = [d]× α_r.
  const Eigen::MatrixXd G_lin = pointRows(kin.J[a], pa) - pointRows(kin.J[r], pr) + skew3(d) * kin.J[r].bottomRows(3);
  const Eigen::Vector3d k_lin = pointBias(kin.bias[a], pa) + wa.cross(pa_dot) - pointBias(kin.bias[r], pr) -
                                wr.cross(pr_dot) + d.cross(ang(kin.bias[r])) - 2.0 * wr.cross(d_dot) +
                                wr.cross(wr.cross(d));
  // ω̇_rel = α_a − α_r − ω_r × (ω_a − ω_r).
  const Eigen::MatrixXd G_ang = kin.J[a].bottomRows(3) - kin.J[r].bottomRows(3);
  const Eigen::Vector3d k_ang = ang(kin.bias[a]) - ang(kin.bias[r]) - wr.cross(wa - wr);
  const Eigen::Matrix3d R = axesRotation(kin, static_cast<int>(a), c.axes, static_cast<int>(r));
  for (Eigen::Index col = 0; col < c.A.cols(); ++col) {
    const Eigen::Vector3d f = R * lin(Vector6d(c.A.col(col))), m = R * ang(Vector6d(c.A.col(col)));
    G.row(first_row + col) = f.transpose() * G_lin + m.transpose() * G_ang;
    gamma(first_row + col) = c.b(col) - f.dot(k_lin) - m.dot(k_ang);
  }
}

double conditionNumber(const Eigen::MatrixXd& M) {
  if (M.size() == 0) return 1.0;
  const Eigen::VectorXd s = Eigen::JacobiSVD<Eigen::MatrixXd>(M).singularValues();
  const double smin = s(s.size() - 1);
  return smin > 0.0 ? s(0) / smin : std::numeric_limits<double>::infinity();
}

}  // namespace zwang::testing::reference_rows
