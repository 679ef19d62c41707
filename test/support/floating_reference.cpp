#include "support/floating_reference.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <Eigen/LU>
#include <Eigen/SVD>

#include "support/reference_rows.hpp"

#include "support/random_problem.hpp"

namespace zwang::testing {

namespace {

using namespace reference_rows;

using LongMatrix = Eigen::Matrix<long double, Eigen::Dynamic, Eigen::Dynamic>;
using LongVector = Eigen::Matrix<long double, Eigen::Dynamic, 1>;

void checkBase(const FloatingBase& base) {
  if (base.kind != BaseKind::Planar && !base.plane.matrix().isIdentity(0.0))
    throw std::invalid_argument("floating reference: a plane pose is only for a Planar base");
  if (!base.plane.matrix().allFinite()) throw std::invalid_argument("floating reference: plane pose not finite");
}

// The base orientation of a Free base from q's quaternion (w, x, y, z), normalised.
Eigen::Quaterniond baseQuaternion(const Eigen::VectorXd& q) {
  const Eigen::Quaterniond quat(q(3), q(4), q(5), q(6));
  if (!(std::abs(quat.norm() - 1.0) <= 1e-6))
    throw std::invalid_argument("floating reference: the base quaternion q[3..6] is not of unit length");
  return quat.normalized();
}

void checkSizes(const ChainSpec& spec, const FloatingBase& base, const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
  spec.check();
  checkBase(base);
  if (q.size() != base.nq(spec)) throw std::invalid_argument("floating reference: q must have nq entries");
  if (v.size() != base.nv(spec)) throw std::invalid_argument("floating reference: v must have nv entries");
}

// Σ_i J_iᵀ (I_i a_i + v_i ×* I_i v_i − f_ext,i − I_i g) + d ∘ v̇: the generalized force for v̇.
Eigen::VectorXd generalizedForce(const ChainSpec& spec, const FloatingKinematics& kin, const Eigen::VectorXd& qdd,
                                 const Eigen::Vector3d& gravity, const std::vector<WrenchInput>& wrenches) {
  const std::vector<Vector6d> f_ext = externalWrenches(spec, kin, wrenches);
  const Vector6d g = stack(gravity, Eigen::Vector3d::Zero());
  Eigen::VectorXd tau = kin.reflected.cwiseProduct(qdd);
  for (std::size_t i = 0; i < spec.links.size(); ++i) {
    const Matrix6d& I = kin.inertia[i];
    const Vector6d a = kin.J[i] * qdd + kin.bias[i];
    tau += kin.J[i].transpose() * (I * a + forceCross(kin.v[i]) * I * kin.v[i] - f_ext[i] - I * g);
  }
  return tau;
}

}  // namespace

Eigen::VectorXd motorRows(const FloatingInput& input, int rows) {
  Eigen::VectorXd motor = Eigen::VectorXd::Ones(rows);
  int row = 0;
  for (const ConstraintInput& c : input.constraints) {
    if (c.contact) motor.segment(row, c.A.cols()).setZero();
    row += static_cast<int>(c.A.cols());
  }
  return motor;
}

const char* toString(BaseKind kind) {
  switch (kind) {
    case BaseKind::Fixed: return "fixed";
    case BaseKind::Free: return "free";
    case BaseKind::Planar: return "planar";
  }
  return "?";
}

int FloatingInput::constraintRows() const {
  int m = 0;
  for (const ConstraintInput& c : constraints) m += static_cast<int>(c.A.cols());
  return m;
}

Eigen::Isometry3d basePose(const FloatingBase& base, const Eigen::VectorXd& q) {
  checkBase(base);
  if (q.size() < base.baseConfigurationSize())
    throw std::invalid_argument("floating reference: q too short for the base");
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (base.kind == BaseKind::Free) {
    T.translation() = q.head<3>();
    T.linear() = baseQuaternion(q).toRotationMatrix();
  } else if (base.kind == BaseKind::Planar) {
    T = base.plane;
    T.translate(Eigen::Vector3d(q(0), q(1), 0.0));
    T.rotate(Eigen::AngleAxisd(q(2), Eigen::Vector3d::UnitZ()));
  }
  return T;
}

Eigen::VectorXd configurationRate(const FloatingBase& base, const Eigen::VectorXd& q, const Eigen::VectorXd& v) {
  const int base_velocity_size = base.baseVelocitySize();
  if (v.size() - base_velocity_size != q.size() - base.baseConfigurationSize())
    throw std::invalid_argument("floating reference: q and v sizes do not match the base");
  Eigen::VectorXd qdot(q.size());
  qdot.tail(v.size() - base_velocity_size) = v.tail(v.size() - base_velocity_size);
  if (base.kind == BaseKind::Free) {
    const Eigen::Quaterniond quat(q(3), q(4), q(5), q(6));  // not normalised: the exact field of q̇ at q
    qdot.head<3>() = quat.normalized().toRotationMatrix() * v.head<3>();
    // q̇uat = ½ quat ⊗ (0, ω), ω in base axes.
    const Eigen::Quaterniond rate = quat * Eigen::Quaterniond(0.0, v(3), v(4), v(5));
    qdot.segment<4>(3) << 0.5 * rate.w(), 0.5 * rate.x(), 0.5 * rate.y(), 0.5 * rate.z();
  } else if (base.kind == BaseKind::Planar) {
    qdot.head<3>() = v.head<3>();
  }
  return qdot;
}

Eigen::VectorXd integrateConfiguration(const FloatingBase& base, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
                                       double dt, int steps) {
  Eigen::VectorXd x = q;
  const double h = dt / steps;
  for (int s = 0; s < steps; ++s) {
    const Eigen::VectorXd k1 = configurationRate(base, x, v);
    const Eigen::VectorXd k2 = configurationRate(base, x + 0.5 * h * k1, v);
    const Eigen::VectorXd k3 = configurationRate(base, x + 0.5 * h * k2, v);
    const Eigen::VectorXd k4 = configurationRate(base, x + h * k3, v);
    x += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
  }
  if (base.kind == BaseKind::Free) x.segment<4>(3).normalize();
  return x;
}

FloatingKinematics floatingKinematics(const ChainSpec& spec, const FloatingBase& base, const Eigen::VectorXd& q,
                                      const Eigen::VectorXd& v) {
  checkSizes(spec, base, q, v);
  const int base_velocity_size = base.baseVelocitySize(), base_configuration_size = base.baseConfigurationSize();
  const int nv = base.nv(spec);
  const std::size_t links = spec.links.size();
  FloatingKinematics kin;
  kin.poses.assign(links, Eigen::Isometry3d::Identity());
  kin.J.assign(links, Eigen::MatrixXd::Zero(6, nv));
  kin.v.assign(links, Vector6d::Zero());
  kin.bias.assign(links, Vector6d::Zero());
  kin.inertia.assign(links, Matrix6d::Zero());
  kin.dof_of_joint.assign(spec.joints.size(), -1);
  kin.reflected = Eigen::VectorXd::Zero(nv);

  // The base: pose, columns, velocity, J̇ v.
  kin.poses[0] = basePose(base, q);
  const Eigen::Vector3d p = kin.poses[0].translation();
  if (base.kind == BaseKind::Free) {
    const Eigen::Matrix3d R = kin.poses[0].linear();
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d e = R.col(k);
      kin.J[0].col(k) = stack(e, Eigen::Vector3d::Zero());
      kin.J[0].col(3 + k) = stack(p.cross(e), e);
    }
    kin.v[0] = kin.J[0] * v;
    // d/dt s_k = v_B × s_k for all six columns: J̇_B v = v_B × v_B = 0.
    kin.bias[0] = motionCross(kin.v[0]) * kin.v[0];
  } else if (base.kind == BaseKind::Planar) {
    const Eigen::Matrix3d RP = base.plane.linear();
    const Eigen::Vector3d ux = RP.col(0), uy = RP.col(1), uz = RP.col(2);
    kin.J[0].col(0) = stack(ux, Eigen::Vector3d::Zero());
    kin.J[0].col(1) = stack(uy, Eigen::Vector3d::Zero());
    kin.J[0].col(2) = stack(p.cross(uz), uz);
    kin.v[0] = kin.J[0] * v;
    // The translations along the plane's fixed axes are constant; the yaw column's moment arm moves with the
    // base origin: d/dt [p × u_z; u_z] = [ṗ × u_z; 0], ṗ = ẋ u_x + ẏ u_y.
    const Eigen::Vector3d pdot = v(0) * ux + v(1) * uy;
    kin.bias[0] = stack(v(2) * pdot.cross(uz), Eigen::Vector3d::Zero());
  }

  int dof = base_velocity_size;
  Eigen::Index qi = base_configuration_size;
  for (std::size_t k = 0; k < spec.joints.size(); ++k) {
    const JointSpec& joint = spec.joints[k];
    const auto parent = static_cast<std::size_t>(spec.parentLink(k));
    Eigen::Isometry3d joint_frame = kin.poses[parent];
    joint_frame.translate(joint.xyz);
    joint_frame.rotate(rpyToMatrix(joint.rpy));
    Eigen::Isometry3d child = joint_frame;
    kin.J[k + 1] = kin.J[parent];
    kin.v[k + 1] = kin.v[parent];
    kin.bias[k + 1] = kin.bias[parent];
    if (joint.isFixed()) {
      kin.poses[k + 1] = child;
      continue;
    }
    kin.dof_of_joint[k] = dof;
    const int nj = joint.nv();
    kin.reflected.segment(dof, nj).setConstant(joint.reflectedInertia());  // rotor inertia on each DOF
    // The child's pose, then the joint's columns (world Plücker at the origin) and which of them are fixed in the
    // child (d/dt s = v_child × s) rather than in the parent (d/dt s = v_parent × s).
    Eigen::Matrix<double, 6, Eigen::Dynamic> S(6, nj);
    std::vector<bool> moves_with_child(static_cast<std::size_t>(nj), true);
    const Eigen::Vector3d o = joint_frame.translation();
    if (joint.isSpherical() || joint.isFree()) {
      const Eigen::Index qr = joint.isFree() ? qi + 3 : qi;
      const Eigen::Quaterniond quat(q(qr), q(qr + 1), q(qr + 2), q(qr + 3));
      if (!(std::abs(quat.norm() - 1.0) <= 1e-6))
        throw std::invalid_argument("floating reference: joint " + joint.name + "'s quaternion is not of unit length");
      if (joint.isFree()) child.translate(Eigen::Vector3d(q(qi), q(qi + 1), q(qi + 2)));
      child.rotate(quat.normalized().toRotationMatrix());
      // v = ω (spherical) or [v; ω] (free) in the CHILD frame: the child's own unit twists, at its origin c.
      const Eigen::Matrix3d Rc = child.linear();
      const Eigen::Vector3d c = child.translation();
      const int lin0 = joint.isFree() ? 3 : 0;  // first angular column
      for (int a = 0; a < 3; ++a) {
        if (joint.isFree()) S.col(a) = stack(Rc.col(a), Eigen::Vector3d::Zero());
        S.col(lin0 + a) = stack(c.cross(Rc.col(a)), Rc.col(a));
      }
    } else if (joint.isPlanar()) {
      // q = [x, y, ψ]: translation in the joint frame's xy plane, then yaw about its z; rates along the JOINT
      // frame's axes, so the translations are fixed in the parent and the yaw axis (through the child origin) in
      // the child.
      child.translate(Eigen::Vector3d(q(qi), q(qi + 1), 0.0));
      child.rotate(Eigen::AngleAxisd(q(qi + 2), Eigen::Vector3d::UnitZ()));
      const Eigen::Matrix3d Rj = joint_frame.linear();
      const Eigen::Vector3d c = child.translation();
      S.col(0) = stack(Rj.col(0), Eigen::Vector3d::Zero());
      S.col(1) = stack(Rj.col(1), Eigen::Vector3d::Zero());
      S.col(2) = stack(c.cross(Rj.col(2)), Rj.col(2));
      moves_with_child[0] = moves_with_child[1] = false;
    } else {
      const Eigen::Vector3d u = joint_frame.linear() * joint.axis;
      const double qj = q(qi);
      if (joint.isPrismatic()) {
        S.col(0) = stack(u, Eigen::Vector3d::Zero());
        child.translate(qj * joint.axis);
      } else {
        S.col(0) = stack(o.cross(u), u);
        child.rotate(Eigen::AngleAxisd(qj, joint.axis));
      }
    }
    kin.J[k + 1].middleCols(dof, nj) = S;
    kin.v[k + 1] += S * v.segment(dof, nj);
    for (int a = 0; a < nj; ++a) {
      const Vector6d& moving = moves_with_child[static_cast<std::size_t>(a)] ? kin.v[k + 1] : kin.v[parent];
      kin.bias[k + 1] += motionCross(moving) * S.col(a) * v(dof + a);
    }
    dof += nj;
    qi += joint.nq();
    kin.poses[k + 1] = child;
  }

  for (std::size_t i = 0; i < links; ++i) {
    const LinkSpec& link = spec.links[i];
    const Eigen::Matrix3d R = kin.poses[i].linear() * rpyToMatrix(link.inertial_rpy);
    kin.inertia[i] = spatialInertia(link.mass, kin.poses[i] * link.com, R * link.inertia * R.transpose());
  }
  return kin;
}

double floatingGaussFunction(const ChainSpec& spec, const FloatingBase& base, const FloatingInput& input,
                             const Eigen::VectorXd& qdd) {
  const FloatingKinematics kin = floatingKinematics(spec, base, input.q, input.v);
  if (qdd.size() != base.nv(spec) || input.tau.size() != base.nv(spec))
    throw std::invalid_argument("floating reference: qdd and tau must have nv entries");
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

FloatingResult floatingDynamics(const ChainSpec& spec, const FloatingBase& base, const FloatingInput& input) {
  const FloatingKinematics kin = floatingKinematics(spec, base, input.q, input.v);
  const int base_velocity_size = base.baseVelocitySize();
  const int n = base.nv(spec);
  if (input.tau.size() != n) throw std::invalid_argument("floating reference: tau must have nv entries");
  const int m_user = input.constraintRows();
  const std::vector<int> leaders = spec.directLeaders();  // per joint dof, −1: independent
  const int m_mimic = static_cast<int>(std::count_if(leaders.begin(), leaders.end(), [](int l) { return l >= 0; }));
  const int m = m_user + m_mimic;

  FloatingResult out;
  out.user_rows = m_user;
  out.mimic_rows = m_mimic;
  out.poses = kin.poses;
  out.H = kin.reflected.asDiagonal();
  for (std::size_t i = 0; i < spec.links.size(); ++i) out.H += kin.J[i].transpose() * kin.inertia[i] * kin.J[i];
  out.H = (0.5 * (out.H + out.H.transpose())).eval();
  out.C = generalizedForce(spec, kin, Eigen::VectorXd::Zero(n), input.gravity, input.wrenches);

  // Constraint rows (as denseDynamics): a column [l; r] at the link origin p is Ã = [l; r + p × l] at the world
  // origin, and lᵀp̈ + rᵀω̇ = Ãᵀ(J v̇ + J̇ v) + lᵀ(ω × ṗ).
  out.G = Eigen::MatrixXd::Zero(m, n);
  out.gamma = Eigen::VectorXd::Zero(m);
  int row = 0;
  for (const ConstraintInput& c : input.constraints) {
    if (c.b.size() != c.A.cols())
      throw std::invalid_argument("floating reference: constraint b must have A.cols() entries");
    if (c.contact && (c.joint >= 0 || c.base_dof >= 0 || !c.relative_to.empty()))
      throw std::invalid_argument("floating reference: a contact is an absolute frame constraint");
    if (c.joint >= 0 || c.base_dof >= 0) {  // q̈_joint = b: its force is the joint's own generalized force
      if (c.A.cols() != 1 || c.joint >= spec.dof() || c.base_dof >= base_velocity_size)
        throw std::invalid_argument("floating reference: a joint row has one column and a joint of the spec");
      out.G(row, c.base_dof >= 0 ? c.base_dof : base_velocity_size + c.joint) = 1.0;
      out.gamma(row) = c.b(0);
      ++row;
      continue;
    }
    if (!c.relative_to.empty()) {
      relativeRows(spec, kin, c, row, out.G, out.gamma);
      row += static_cast<int>(c.A.cols());
      continue;
    }
    const int link = spec.linkIndex(c.link);
    const auto li = static_cast<std::size_t>(link);
    const Eigen::Vector3d p = kin.poses[li].translation();
    const Eigen::Vector3d omega = ang(kin.v[li]);
    const Eigen::Vector3d pdot = lin(kin.v[li]) + omega.cross(p);
    for (Eigen::Index col = 0; col < c.A.cols(); ++col, ++row) {
      const Vector6d A_world = wrenchAtWorldOrigin(kin, link, c.A.col(col), c.axes);
      out.G.row(row) = A_world.transpose() * kin.J[li];
      out.gamma(row) = c.b(col) - A_world.dot(kin.bias[li]) - lin(A_world).dot(omega.cross(pdot));
    }
  }
  // Mimic rows v̇_m − a·v̇_k = 0 (k the direct leader), after the user's.
  const std::vector<int> moving = spec.movingJoints();
  for (std::size_t j = 0; j < leaders.size(); ++j) {
    if (leaders[j] < 0) continue;
    const JointSpec& joint = spec.joints[static_cast<std::size_t>(moving[j])];
    out.G(row, base_velocity_size + static_cast<int>(j)) += 1.0;
    out.G(row, base_velocity_size + leaders[j]) -= joint.mimic_multiplier;
    ++row;
  }

  // KKT [H −Gᵀ; G 0][v̇; ν] = [τ − C; γ]: full-pivot LU in long double, one refinement step.
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
  out.tau_c = out.G.transpose() * motorRows(input, m).cwiseProduct(out.nu);  // the contacts' force is not the motors'
  out.tau_control = input.tau + out.tau_c;
  for (const MimicLaw& law : spec.mimicLaws()) {
    out.tau_control(base_velocity_size + law.leader) +=
        law.multiplier * out.tau_control(base_velocity_size + law.joint);
    out.tau_control(base_velocity_size + law.joint) = 0.0;
  }

  out.acc_world.resize(spec.links.size());
  out.acc_local.resize(spec.links.size());
  for (std::size_t i = 0; i < spec.links.size(); ++i) {
    const Vector6d a = kin.J[i] * out.qdd + kin.bias[i];
    out.acc_world[i] = classicalFromSpatial(kin.poses[i].translation(), kin.v[i], a);
    const Eigen::Matrix3d Rt = kin.poses[i].linear().transpose();
    out.acc_local[i] = stack(Rt * lin(out.acc_world[i]), Rt * ang(out.acc_world[i]));
  }
  out.base_acc_world = out.acc_world[0];
  out.gauss = floatingGaussFunction(spec, base, input, out.qdd);

  out.h_condition = conditionNumber(out.H);
  out.kkt_condition = conditionNumber(K.cast<double>());
  if (m > 0) {
    const Eigen::VectorXd s = Eigen::JacobiSVD<Eigen::MatrixXd>(out.G).singularValues();
    out.constraint_rank = 0;
    for (Eigen::Index k = 0; k < s.size(); ++k)
      if (s(k) > 1e-10 * s(0)) ++out.constraint_rank;
    const Eigen::MatrixXd L = out.G * out.H.fullPivLu().solve(out.G.transpose());
    out.coupling_condition = conditionNumber(0.5 * (L + L.transpose()));
  }
  return out;
}

Eigen::VectorXd floatingInverseDynamics(const ChainSpec& spec, const FloatingBase& base, const Eigen::VectorXd& q,
                                        const Eigen::VectorXd& v, const Eigen::VectorXd& qdd,
                                        const Eigen::Vector3d& gravity, const std::vector<WrenchInput>& wrenches) {
  const FloatingKinematics kin = floatingKinematics(spec, base, q, v);
  if (qdd.size() != base.nv(spec)) throw std::invalid_argument("floating reference: qdd must have nv entries");
  return generalizedForce(spec, kin, qdd, gravity, wrenches);
}

Eigen::MatrixXd floatingMassMatrix(const ChainSpec& spec, const FloatingBase& base, const Eigen::VectorXd& q) {
  const FloatingKinematics kin = floatingKinematics(spec, base, q, Eigen::VectorXd::Zero(base.nv(spec)));
  Eigen::MatrixXd H = kin.reflected.asDiagonal();
  for (std::size_t i = 0; i < spec.links.size(); ++i) H += kin.J[i].transpose() * kin.inertia[i] * kin.J[i];
  return 0.5 * (H + H.transpose());
}

Vector6d floatingLinkAcceleration(const ChainSpec& spec, const FloatingBase& base, const Eigen::VectorXd& q,
                                  const Eigen::VectorXd& v, const Eigen::VectorXd& qdd, const std::string& link,
                                  Axes axes) {
  const FloatingKinematics kin = floatingKinematics(spec, base, q, v);
  if (qdd.size() != base.nv(spec)) throw std::invalid_argument("floating reference: qdd must have nv entries");
  const auto i = static_cast<std::size_t>(spec.linkIndex(link));
  const Vector6d acc = classicalFromSpatial(kin.poses[i].translation(), kin.v[i], kin.J[i] * qdd + kin.bias[i]);
  if (axes == Axes::World) return acc;
  const Eigen::Matrix3d Rt = kin.poses[i].linear().transpose();
  return stack(Rt * lin(acc), Rt * ang(acc));
}

Vector6d floatingMomentum(const ChainSpec& spec, const FloatingBase& base, const Eigen::VectorXd& q,
                          const Eigen::VectorXd& v) {
  const FloatingKinematics kin = floatingKinematics(spec, base, q, v);
  Vector6d h = Vector6d::Zero();
  for (std::size_t i = 0; i < spec.links.size(); ++i) h += kin.inertia[i] * kin.v[i];
  return h;
}

FloatingBase randomFloatingBase(std::mt19937_64& rng, const RandomFloatingOptions& options) {
  FloatingBase base;
  base.kind = uniform01(rng) < options.free_probability ? BaseKind::Free : BaseKind::Planar;
  if (base.kind == BaseKind::Planar && uniform01(rng) >= options.identity_plane_probability) {
    const Eigen::Matrix3d R = randomRotation(rng);
    const Eigen::Vector3d o = randomVector(rng, 3, 1.0);
    base.plane.linear() = R;
    base.plane.translation() = o;
  }
  return base;
}

FloatingInput randomFloatingInput(std::mt19937_64& rng, const ChainSpec& spec, const FloatingBase& base,
                                  const RandomFloatingOptions& options) {
  RandomProblemOptions problem;
  problem.max_constraint_rows = options.max_constraint_rows;
  problem.max_constraint_frames = options.max_constraint_frames;
  problem.max_wrenches = options.max_wrenches;
  problem.gravity_probability = options.gravity_probability;
  problem.relative_probability = options.relative_probability;
  if (spec.links.size() < 2) problem.max_wrenches = problem.max_constraint_rows = 0;  // randomProblem skips the base
  DynamicsInput joints = randomProblem(rng, spec, problem);
  // Move some wrenches and constraints onto the base link (randomProblem keeps off the fixed base).
  for (WrenchInput& w : joints.wrenches)
    if (uniform01(rng) < options.base_link_probability) w.link = spec.links[0].name;
  for (ConstraintInput& c : joints.constraints)
    if (uniform01(rng) < options.base_link_probability && c.relative_to != spec.links[0].name)
      c.link = spec.links[0].name;

  const int base_configuration_size = base.baseConfigurationSize(), base_velocity_size = base.baseVelocitySize(),
            n = spec.dof();
  FloatingInput in;
  in.q.resize(base_configuration_size + n);
  in.v.resize(base_velocity_size + n);
  in.tau = Eigen::VectorXd::Zero(base_velocity_size + n);
  if (base.kind == BaseKind::Free) {
    const Eigen::Vector3d p = randomVector(rng, 3, options.base_position_scale);
    const Eigen::Quaterniond quat(randomRotation(rng));
    in.q.head<3>() = p;
    in.q.segment<4>(3) << quat.w(), quat.x(), quat.y(), quat.z();
  } else if (base.kind == BaseKind::Planar) {
    const Eigen::VectorXd xy = randomVector(rng, 2, options.base_position_scale);
    const double psi = uniform(rng, -3.14159265358979, 3.14159265358979);
    in.q.head<3>() << xy(0), xy(1), psi;
  }
  in.v.head(base_velocity_size) = randomVector(rng, base_velocity_size, options.base_speed_scale);
  if (uniform01(rng) < options.base_tau_probability)
    in.tau.head(base_velocity_size) = randomVector(rng, base_velocity_size, 10.0);
  in.q.tail(n) = joints.q;
  in.v.tail(n) = joints.qd;
  in.tau.tail(n) = joints.tau;
  in.gravity = joints.gravity;
  in.wrenches = joints.wrenches;
  in.constraints = joints.constraints;
  return in;
}

FloatingProblem randomFloatingProblem(std::mt19937_64& rng, const RandomFloatingOptions& options) {
  FloatingProblem problem;
  problem.spec =
      uniform01(rng) < options.chain_probability ? randomChain(rng, options.chain) : randomTree(rng, options.tree);
  problem.base = randomFloatingBase(rng, options);
  problem.input = randomFloatingInput(rng, problem.spec, problem.base, options);
  return problem;
}

bool wellPosed(const FloatingResult& dense) {
  const auto rows = static_cast<int>(dense.G.rows());
  if (!dense.wellConditioned(1e6) || dense.constraint_rank < rows) return false;
  return rows == 0 || Eigen::JacobiSVD<Eigen::MatrixXd>(dense.G).singularValues().minCoeff() >= 1e-6;
}

}  // namespace zwang::testing
