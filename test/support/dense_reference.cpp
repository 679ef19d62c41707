#include "support/dense_reference.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/LU>
#include <Eigen/SVD>

#include "support/reference_rows.hpp"

namespace zwang::testing {

namespace {

using namespace reference_rows;

using LongMatrix = Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>;
using LongVector = Eigen::Matrix<long double, Eigen::Dynamic, 1>;

void checkSizes(const ChainSpec& spec, const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
  spec.check();
  const auto n = static_cast<Eigen::Index>(spec.dof());
  if (q.size() != n || qd.size() != n)
    throw std::invalid_argument("dense reference: q and qd must have spec.dof() entries");
}

}  // namespace

int DynamicsInput::constraintRows() const {
  int m = 0;
  for (const ConstraintInput& c : constraints) m += static_cast<int>(c.A.cols());
  return m;
}

Eigen::Matrix3d skew3(const Eigen::Vector3d& a) {
  Eigen::Matrix3d S;
  S << 0.0, -a.z(), a.y(), a.z(), 0.0, -a.x(), -a.y(), a.x(), 0.0;
  return S;
}

Matrix6d motionCross(const Vector6d& v) {
  Matrix6d X = Matrix6d::Zero();
  X.topLeftCorner<3, 3>() = skew3(ang(v));
  X.topRightCorner<3, 3>() = skew3(lin(v));
  X.bottomRightCorner<3, 3>() = skew3(ang(v));
  return X;
}

Matrix6d forceCross(const Vector6d& v) { return -motionCross(v).transpose(); }

Matrix6d spatialInertia(double m, const Eigen::Vector3d& c, const Eigen::Matrix3d& Ic) {
  // Momentum of the body moving with v = [v_O; ω]: linear m(v_O + ω × c),
  // angular about O: c × m(v_O + ω × c) + Ic ω.
  const Eigen::Matrix3d cx = skew3(c);
  Matrix6d I;
  I.topLeftCorner<3, 3>() = m * Eigen::Matrix3d::Identity();
  I.topRightCorner<3, 3>() = -m * cx;
  I.bottomLeftCorner<3, 3>() = m * cx;
  I.bottomRightCorner<3, 3>() = Ic - m * cx * cx;
  return I;
}

DenseKinematics denseKinematics(const ChainSpec& spec, const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
  checkSizes(spec, q, qd);
  const int n = spec.dof();
  const std::size_t links = spec.links.size();
  DenseKinematics kin;
  kin.poses.assign(links, Eigen::Isometry3d::Identity());
  kin.J.assign(links, Eigen::MatrixXd::Zero(6, n));
  kin.v.assign(links, Vector6d::Zero());
  kin.bias.assign(links, Vector6d::Zero());
  kin.inertia.assign(links, Matrix6d::Zero());
  kin.dof_of_joint.assign(spec.joints.size(), -1);
  kin.reflected = Eigen::VectorXd::Zero(n);

  int dof = 0;
  for (std::size_t k = 0; k < spec.joints.size(); ++k) {
    const JointSpec& joint = spec.joints[k];
    // URDF: the joint frame sits at (xyz, rpy) in the parent link frame.
    const auto parent = static_cast<std::size_t>(spec.parentLink(k));
    Eigen::Isometry3d joint_frame = kin.poses[parent];
    joint_frame.translate(joint.xyz);
    joint_frame.rotate(rpyToMatrix(joint.rpy));

    Eigen::Isometry3d child = joint_frame;
    kin.J[k + 1] = kin.J[parent];
    kin.v[k + 1] = kin.v[parent];
    kin.bias[k + 1] = kin.bias[parent];
    if (!joint.isFixed()) {
      kin.dof_of_joint[k] = dof;
      kin.reflected(dof) = joint.reflectedInertia();
      // Joint axis u in world axes; the joint motion leaves it (and, for a
      // revolute joint, the joint origin p) unchanged.
      const Eigen::Vector3d u = joint_frame.linear() * joint.axis;
      const Eigen::Vector3d p = joint_frame.translation();
      Vector6d s;
      if (joint.isPrismatic()) {
        s = stack(u, Eigen::Vector3d::Zero());  // pure translation along u
        child.translate(q(dof) * joint.axis);
      } else {
        s = stack(p.cross(u), u);  // rotation about the line (p, u): v_O = ω × (O − p) = p × u
        child.rotate(Eigen::AngleAxisd(q(dof), joint.axis));
      }
      kin.J[k + 1].col(dof) = s;
      kin.v[k + 1] += s * qd(dof);
      // d/dt s_j = v_body × s_j, with the body the child (or parent: s × s = 0).
      kin.bias[k + 1] += motionCross(kin.v[k + 1]) * s * qd(dof);
      ++dof;
    }
    kin.poses[k + 1] = child;
  }

  for (std::size_t i = 0; i < links; ++i) {
    const LinkSpec& link = spec.links[i];
    const Eigen::Matrix3d R = kin.poses[i].linear() * rpyToMatrix(link.inertial_rpy);
    kin.inertia[i] = spatialInertia(link.mass, kin.poses[i] * link.com, R * link.inertia * R.transpose());
  }
  return kin;
}

double gaussFunction(const ChainSpec& spec, const DynamicsInput& input, const Eigen::VectorXd& qdd) {
  const DenseKinematics kin = denseKinematics(spec, input.q, input.qd);
  const std::vector<Vector6d> f_ext = externalWrenches(spec, kin, input.wrenches);
  const Vector6d g = stack(input.gravity, Eigen::Vector3d::Zero());
  double Z = 0.0;
  for (std::size_t i = 0; i < spec.links.size(); ++i) {
    const Matrix6d& I = kin.inertia[i];
    const Vector6d a = kin.J[i] * qdd + kin.bias[i];
    const Vector6d bias_force = forceCross(kin.v[i]) * I * kin.v[i] - f_ext[i] - I * g;
    Z += 0.5 * a.dot(I * a) + bias_force.dot(a);
  }
  for (Eigen::Index j = 0; j < qdd.size(); ++j) Z += 0.5 * kin.reflected(j) * qdd(j) * qdd(j) - input.tau(j) * qdd(j);
  return Z;
}

DenseResult denseDynamics(const ChainSpec& spec, const DynamicsInput& input) {
  const DenseKinematics kin = denseKinematics(spec, input.q, input.qd);
  const int n = spec.dof();
  if (input.tau.size() != n) throw std::invalid_argument("dense reference: tau must have spec.dof() entries");
  const int m_user = input.constraintRows();
  const std::vector<int> leaders = spec.directLeaders();  // per dof, −1: independent
  const int m_mimic = static_cast<int>(std::count_if(leaders.begin(), leaders.end(), [](int l) { return l >= 0; }));
  const int m = m_user + m_mimic;
  const std::vector<Vector6d> f_ext = externalWrenches(spec, kin, input.wrenches);
  const Vector6d g = stack(input.gravity, Eigen::Vector3d::Zero());

  DenseResult out;
  out.user_rows = m_user;
  out.mimic_rows = m_mimic;
  out.poses = kin.poses;
  out.H = kin.reflected.asDiagonal();
  out.C = Eigen::VectorXd::Zero(n);
  for (std::size_t i = 0; i < spec.links.size(); ++i) {
    const Matrix6d& I = kin.inertia[i];
    out.H += kin.J[i].transpose() * I * kin.J[i];
    out.C += kin.J[i].transpose() * (I * kin.bias[i] + forceCross(kin.v[i]) * I * kin.v[i] - f_ext[i] - I * g);
  }
  out.H = (0.5 * (out.H + out.H.transpose())).eval();  // eval: the transpose aliases H

  // Constraint rows. A column [l; r] at the link origin p, in world axes, is the
  // Plücker force Ã = [l; r + p × l] at the world origin, and
  //   lᵀ p̈ + rᵀ ω̇ = Ãᵀ a + lᵀ (ω × ṗ)   (p̈ = a_O + α × p + ω × ṗ),
  // so with a = J q̈ + J̇ q̇ the row reads Ãᵀ J q̈ = b − Ãᵀ J̇ q̇ − lᵀ (ω × ṗ).
  out.G = Eigen::MatrixXd::Zero(m, n);
  out.gamma = Eigen::VectorXd::Zero(m);
  int row = 0;
  for (const ConstraintInput& c : input.constraints) {
    if (c.b.size() != c.A.cols())
      throw std::invalid_argument("dense reference: constraint b must have A.cols() entries");
    if (c.joint >= 0 || c.contact)
      throw std::invalid_argument("dense reference: joint rows and contacts are floatingDynamics' (BaseKind::Fixed)");
    const int link = spec.linkIndex(c.link);
    const auto li = static_cast<std::size_t>(link);
    const Eigen::Vector3d p = kin.poses[li].translation();
    const Eigen::Vector3d omega = ang(kin.v[li]);
    const Eigen::Vector3d pdot = lin(kin.v[li]) + omega.cross(p);
    if (!c.relative_to.empty()) {
      relativeRows(spec, kin, c, row, out.G, out.gamma);
      row += static_cast<int>(c.A.cols());
      continue;
    }
    for (Eigen::Index col = 0; col < c.A.cols(); ++col, ++row) {
      const Vector6d A_world = wrenchAtWorldOrigin(kin, link, c.A.col(col), c.axes);
      const Eigen::Vector3d l = lin(A_world);
      out.G.row(row) = A_world.transpose() * kin.J[li];
      out.gamma(row) = c.b(col) - A_world.dot(kin.bias[li]) - l.dot(omega.cross(pdot));
    }
  }
  // Mimic rows q̈_m − a·q̈_k = 0 (k the direct leader), after the user's.
  const std::vector<int> moving = spec.movingJoints();
  for (int j = 0; j < n; ++j) {
    if (leaders[static_cast<std::size_t>(j)] < 0) continue;
    const JointSpec& joint = spec.joints[static_cast<std::size_t>(moving[static_cast<std::size_t>(j)])];
    out.G(row, j) += 1.0;
    out.G(row, leaders[static_cast<std::size_t>(j)]) -= joint.mimic_multiplier;
    ++row;
  }

  // KKT: [H −Gᵀ; G 0][q̈; ν] = [τ − C; γ], full-pivot LU in long double and
  // one step of iterative refinement (residual also in long double).
  LongMatrix K = LongMatrix::Zero(n + m, n + m);
  K.topLeftCorner(n, n) = out.H.cast<long double>();
  K.topRightCorner(n, m) = -out.G.transpose().cast<long double>();
  K.bottomLeftCorner(m, n) = out.G.cast<long double>();
  LongVector rhs(n + m);
  rhs << (input.tau - out.C).cast<long double>(), out.gamma.cast<long double>();
  const Eigen::FullPivLU<LongMatrix> lu(K);
  LongVector x = lu.solve(rhs);
  x += lu.solve(LongVector(rhs - K * x));
  out.qdd = x.head(n).cast<double>();
  out.nu = x.tail(m).cast<double>();
  out.tau_c = out.G.transpose() * out.nu;
  out.tau_control = input.tau + out.tau_c;
  for (const MimicLaw& law : spec.mimicLaws()) {  // resolved leaders are independent: any order
    out.tau_control(law.leader) += law.multiplier * out.tau_control(law.joint);
    out.tau_control(law.joint) = 0.0;
  }

  // Accelerations of every link and the Gauss function at the solution.
  out.acc_world.resize(spec.links.size());
  out.acc_local.resize(spec.links.size());
  for (std::size_t i = 0; i < spec.links.size(); ++i) {
    const Vector6d a = kin.J[i] * out.qdd + kin.bias[i];
    out.acc_world[i] = classicalFromSpatial(kin.poses[i].translation(), kin.v[i], a);
    const Eigen::Matrix3d Rt = kin.poses[i].linear().transpose();
    out.acc_local[i] = stack(Rt * lin(out.acc_world[i]), Rt * ang(out.acc_world[i]));
  }
  out.gauss = gaussFunction(spec, input, out.qdd);

  // Conditioning.
  out.h_condition = conditionNumber(out.H);
  out.kkt_condition = conditionNumber(K.cast<double>());
  if (m > 0) {
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(out.G);
    const Eigen::VectorXd s = svd.singularValues();
    out.constraint_rank = 0;
    for (Eigen::Index k = 0; k < s.size(); ++k)
      if (s(k) > 1e-10 * s(0)) ++out.constraint_rank;
    const Eigen::MatrixXd L = out.G * out.H.fullPivLu().solve(out.G.transpose());
    out.coupling_condition = conditionNumber(0.5 * (L + L.transpose()));
  }
  return out;
}

Eigen::VectorXd denseInverseDynamics(const ChainSpec& spec, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                                     const Eigen::VectorXd& qdd, const Eigen::Vector3d& gravity,
                                     const std::vector<WrenchInput>& wrenches) {
  const DenseKinematics kin = denseKinematics(spec, q, qd);
  if (qdd.size() != spec.dof()) throw std::invalid_argument("dense reference: qdd must have spec.dof() entries");
  const std::vector<Vector6d> f_ext = externalWrenches(spec, kin, wrenches);
  const Vector6d g = stack(gravity, Eigen::Vector3d::Zero());
  // τ = Σ_i J_iᵀ (I_i a_i + v_i ×* I_i v_i − f_ext,i − f_grav,i) + d ∘ q̈.
  Eigen::VectorXd tau = kin.reflected.cwiseProduct(qdd);
  for (std::size_t i = 0; i < spec.links.size(); ++i) {
    const Matrix6d& I = kin.inertia[i];
    const Vector6d a = kin.J[i] * qdd + kin.bias[i];
    tau += kin.J[i].transpose() * (I * a + forceCross(kin.v[i]) * I * kin.v[i] - f_ext[i] - I * g);
  }
  return tau;
}

Eigen::MatrixXd linkJacobian(const ChainSpec& spec, const Eigen::VectorXd& q, const std::string& link, Axes axes) {
  const DenseKinematics kin = denseKinematics(spec, q, Eigen::VectorXd::Zero(q.size()));
  const auto i = static_cast<std::size_t>(spec.linkIndex(link));
  // [ṗ; ω] = [v_O + ω × p; ω] = [1 −p×; 0 1] v.
  Matrix6d shift = Matrix6d::Identity();
  shift.topRightCorner<3, 3>() = -skew3(kin.poses[i].translation());
  Eigen::MatrixXd J = shift * kin.J[i];
  if (axes == Axes::Local) {
    const Eigen::Matrix3d Rt = kin.poses[i].linear().transpose();
    J.topRows<3>() = Rt * J.topRows<3>();
    J.bottomRows<3>() = Rt * J.bottomRows<3>();
  }
  return J;
}

Vector6d linkAcceleration(const ChainSpec& spec, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                          const Eigen::VectorXd& qdd, const std::string& link, Axes axes) {
  const DenseKinematics kin = denseKinematics(spec, q, qd);
  const auto i = static_cast<std::size_t>(spec.linkIndex(link));
  const Vector6d acc = classicalFromSpatial(kin.poses[i].translation(), kin.v[i], kin.J[i] * qdd + kin.bias[i]);
  if (axes == Axes::World) return acc;
  const Eigen::Matrix3d Rt = kin.poses[i].linear().transpose();
  return stack(Rt * lin(acc), Rt * ang(acc));
}

}  // namespace zwang::testing
