#include "support/kdl_bridge.hpp"

#include <cmath>
#include <stdexcept>

#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainfksolvervel_recursive.hpp>
#include <kdl/chainhdsolver_vereshchagin.hpp>
#include <kdl/chainidsolver_recursive_newton_euler.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <kdl/frames.hpp>
#include <kdl/jacobian.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/jntarrayvel.hpp>
#include <kdl/rigidbodyinertia.hpp>
#include <kdl/rotationalinertia.hpp>
#include <kdl/segment.hpp>

namespace zwang::testing {

namespace {

KDL::Vector toKdl(const Eigen::Vector3d& v) { return KDL::Vector(v.x(), v.y(), v.z()); }
Eigen::Vector3d toEigen(const KDL::Vector& v) { return Eigen::Vector3d(v.x(), v.y(), v.z()); }

KDL::Rotation toKdl(const Eigen::Matrix3d& R) {
  return KDL::Rotation(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2));
}
Eigen::Matrix3d toEigen(const KDL::Rotation& R) {
  Eigen::Matrix3d M;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) M(r, c) = R(r, c);
  return M;
}
Eigen::Isometry3d toEigen(const KDL::Frame& F) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = toEigen(F.M);
  T.translation() = toEigen(F.p);
  return T;
}

// KDL Twist / Wrench store (vel, rot) / (force, torque): linear part first,
// like docs/conventions.md, so the 6-vectors map one to one.
Vector6d toEigen(const KDL::Twist& t) {
  Vector6d x;
  x << toEigen(t.vel), toEigen(t.rot);
  return x;
}
KDL::Wrench toKdlWrench(const Vector6d& w) {
  return KDL::Wrench(toKdl(Eigen::Vector3d(w.head<3>())), toKdl(Eigen::Vector3d(w.tail<3>())));
}

KDL::JntArray toKdl(const Eigen::VectorXd& x) {
  KDL::JntArray a(static_cast<unsigned int>(x.size()));
  a.data = x;
  return a;
}

// Rotates both halves of a 6-vector.
Vector6d rotate6(const Eigen::Matrix3d& R, const Vector6d& x) {
  Vector6d y;
  y << R * x.head<3>(), R * x.tail<3>();
  return y;
}

// Fixed-axis rpy of a rotation matrix (inverse of rpyToMatrix), stable away from
// and at pitch = ±π/2.
Eigen::Vector3d matrixToRpy(const Eigen::Matrix3d& R) {
  const double cos_pitch = std::hypot(R(0, 0), R(1, 0));
  const double pitch = std::atan2(-R(2, 0), cos_pitch);
  if (cos_pitch < 1e-12) return Eigen::Vector3d(0.0, pitch, std::atan2(-R(0, 1), R(1, 1)));
  return Eigen::Vector3d(std::atan2(R(2, 1), R(2, 2)), pitch, std::atan2(R(1, 0), R(0, 0)));
}

Eigen::Isometry3d jointOrigin(const JointSpec& joint) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = joint.xyz;
  T.linear() = rpyToMatrix(joint.rpy);
  return T;
}

}  // namespace

bool hasFixedJoints(const ChainSpec& spec) { return spec.dof() != static_cast<int>(spec.joints.size()); }

KDL::Chain toKdlChain(const ChainSpec& spec) {
  spec.check();
  KDL::Chain chain;
  for (std::size_t k = 0; k < spec.joints.size(); ++k) {
    const JointSpec& j = spec.joints[k];
    const LinkSpec& child = spec.links[k + 1];
    const KDL::Frame origin(toKdl(rpyToMatrix(j.rpy)), toKdl(j.xyz));
    // kdl_parser's construction: the joint's origin and axis are given in the
    // PARENT frame (origin F.p, axis F.M·axis) and the segment's f_tip is F, so
    // pose(q) = Joint::pose(q)·F = F·(motion about/along the joint-frame axis).
    const KDL::Vector axis = origin.M * toKdl(j.axis);
    KDL::Joint joint(j.name, KDL::Joint::Fixed);
    if (j.isPrismatic())
      joint = KDL::Joint(j.name, origin.p, axis, KDL::Joint::TransAxis, 1.0, 0.0, j.reflectedInertia());
    else if (!j.isFixed())
      joint = KDL::Joint(j.name, origin.p, axis, KDL::Joint::RotAxis, 1.0, 0.0, j.reflectedInertia());
    // KDL's RigidBodyInertia(m, c, I_c) wants the COM and the rotational inertia
    // about the COM, both in the segment tip frame (= the child link frame): turn
    // URDF's inertial-frame inertia into link axes.
    const Eigen::Matrix3d R = rpyToMatrix(child.inertial_rpy);
    const Eigen::Matrix3d I = R * child.inertia * R.transpose();
    const KDL::RigidBodyInertia inertia(child.mass, toKdl(child.com),
                                        KDL::RotationalInertia(I(0, 0), I(1, 1), I(2, 2), I(0, 1), I(0, 2), I(1, 2)));
    chain.addSegment(KDL::Segment(child.name, joint, origin, inertia));
  }
  return chain;
}

std::vector<Eigen::Isometry3d> kdlLinkPoses(const ChainSpec& spec, const Eigen::VectorXd& q) {
  const KDL::Chain chain = toKdlChain(spec);
  KDL::ChainFkSolverPos_recursive fk(chain);
  std::vector<KDL::Frame> frames(chain.getNrOfSegments());
  if (fk.JntToCart(toKdl(q), frames) < 0) throw std::runtime_error("KDL forward kinematics failed");
  std::vector<Eigen::Isometry3d> poses{Eigen::Isometry3d::Identity()};
  for (const KDL::Frame& F : frames) poses.push_back(toEigen(F));
  return poses;
}

KdlHybridResult kdlHybridDynamics(const ChainSpec& spec, const DynamicsInput& input) {
  // KDL's Vereshchagin has no fixed-joint support: for a Joint::Fixed segment
  // its D = Sᵀ P S is 0 and the inward sweep divides by it (q̈ turns NaN), and
  // the outward sweep reads q(j) one past the end behind a trailing fixed
  // segment. Measured in test_references.cpp ("KDL Vereshchagin and fixed
  // segments"). Use mergeFixedJoints first.
  if (hasFixedJoints(spec))
    throw std::invalid_argument(
        "kdlHybridDynamics: KDL's Vereshchagin solver cannot handle fixed joints; "
        "merge them first (mergeFixedJoints)");
  if (input.constraints.size() > 1)
    throw std::invalid_argument("kdlHybridDynamics: KDL takes one constraint, on the last link");
  const std::string& tip_name = spec.links.back().name;
  if (!input.constraints.empty() && input.constraints[0].link != tip_name)
    throw std::invalid_argument("kdlHybridDynamics: KDL constrains only the last link '" + tip_name + "', not '" +
                                input.constraints[0].link + "'");
  const int m = input.constraintRows();
  if (m > 6) throw std::invalid_argument("kdlHybridDynamics: at most 6 constraint rows");
  const int n = spec.dof();
  const auto ns = static_cast<unsigned int>(spec.joints.size());

  const KDL::Chain chain = toKdlChain(spec);
  const KDL::JntArray q = toKdl(input.q), qd = toKdl(input.qd), tau = toKdl(input.tau);

  // Poses and velocities of every link from KDL itself: frames[i] is the tip of
  // segment i = links[i + 1]; .p.v is the origin velocity ṗ and .M.w the angular
  // velocity ω, both in base axes.
  KDL::ChainFkSolverVel_recursive fk_vel(chain);
  std::vector<KDL::FrameVel> frames(ns);
  if (fk_vel.JntToCart(KDL::JntArrayVel(q, qd), frames) < 0) throw std::runtime_error("KDL velocity kinematics failed");
  auto rotation = [&](std::size_t link) {
    return link == 0 ? Eigen::Matrix3d::Identity() : toEigen(frames[link - 1].M.R);
  };
  auto omega = [&](std::size_t link) { return link == 0 ? Eigen::Vector3d::Zero() : toEigen(frames[link - 1].M.w); };
  auto origin_velocity = [&](std::size_t link) {
    return link == 0 ? Eigen::Vector3d::Zero() : toEigen(frames[link - 1].p.v);
  };

  KdlHybridResult out;
  const Eigen::Vector3d& g = input.gravity;

  // Gravity: KDL's Vereshchagin takes the ROOT ACCELERATION itself, [−g; 0]
  // (Featherstone's trick; its header: "opposite sign compared to the KDL's FD
  // and RNE solvers", which take g and negate it internally).
  out.root_acc << -g, Eigen::Vector3d::Zero();
  const KDL::Twist root_acc(toKdl(Eigen::Vector3d(-g)), KDL::Vector::Zero());

  // Constraint. KDL's alpha columns are wrenches [f; n] in BASE axes acting at
  // the TIP ORIGIN (it rotates them into the tip frame, never shifts them), and
  // beta constrains KDL's tip acceleration, which is the SPATIAL acceleration
  // (linear part = p̈ − ω × ṗ at the tip origin) INCLUDING the root
  // acceleration −g. For our column [l; r] with world components (l_w, r_w)
  // and set point b on the true classical acceleration:
  //   β = l_wᵀ(p̈ − ω × ṗ − g) + r_wᵀ ω̇ = b − l_wᵀ(ω × ṗ) − l_wᵀ g.
  // With no rows, one zero column turns the constraint off (M₀ = 0 and KDL's
  // truncated SVD gives ν = 0).
  const unsigned int nc = m > 0 ? static_cast<unsigned int>(m) : 1u;
  out.alpha = Matrix6Xd::Zero(6, nc);
  out.beta = Eigen::VectorXd::Zero(nc);
  const std::size_t tip = spec.links.size() - 1;
  if (m > 0) {
    const ConstraintInput& c = input.constraints[0];
    if (c.b.size() != m) throw std::invalid_argument("kdlHybridDynamics: b must have A.cols() entries");
    const Eigen::Matrix3d R = c.axes == Axes::Local ? rotation(tip) : Eigen::Matrix3d::Identity();
    const Eigen::Vector3d w_x_pdot = omega(tip).cross(origin_velocity(tip));
    for (int k = 0; k < m; ++k) {
      out.alpha.col(k) = rotate6(R, c.A.col(k));
      const Eigen::Vector3d l = out.alpha.col(k).head<3>();
      out.beta(k) = c.b(k) - l.dot(w_x_pdot) - l.dot(g);
    }
  }
  KDL::Jacobian alpha(nc);
  alpha.data = out.alpha;
  const KDL::JntArray beta = toKdl(out.beta);

  // External wrenches: KDL's Vereshchagin reads f_ext[i] in BASE axes, acting at
  // the tip origin of segment i (it only rotates it into the segment frame), and
  // counts it as a force ON the segment (bias = v ×* I v − f_ext).
  out.f_ext.assign(ns, Vector6d::Zero());
  for (const WrenchInput& w : input.wrenches) {
    const auto link = static_cast<std::size_t>(spec.linkIndex(w.link));
    if (link == 0) continue;  // a wrench on the fixed base does nothing
    out.f_ext[link - 1] += w.axes == Axes::Local ? rotate6(rotation(link), w.wrench) : w.wrench;
  }
  KDL::Wrenches f_ext(ns);
  for (unsigned int i = 0; i < ns; ++i) f_ext[i] = toKdlWrench(out.f_ext[i]);

  KDL::ChainHdSolver_Vereshchagin solver(chain, root_acc, nc);
  KDL::JntArray qdd(static_cast<unsigned int>(n)), constraint_torques(static_cast<unsigned int>(n));
  out.error = solver.CartToJnt(q, qd, qdd, alpha, beta, f_ext, tau, constraint_torques);
  out.qdd = qdd.data;
  out.constraint_torques_kdl = constraint_torques.data;
  KDL::JntArray total(static_cast<unsigned int>(n));
  solver.getTotalTorque(total);
  out.total_torques_kdl = total.data;
  out.nu_kdl.resize(nc);
  solver.getContraintForceMagnitude(out.nu_kdl);
  std::vector<KDL::Twist> x_dotdot(ns + 1);
  solver.getTransformedLinkAcceleration(x_dotdot);
  for (const KDL::Twist& a : x_dotdot) out.x_dotdot_kdl.push_back(toEigen(a));

  // ν: KDL applies −E ν (its constraint_torques = −Sᵀ E ν), i.e. the wrench
  // on the tip is −α ν_KDL; we apply +A ν (docs/solver.md, "Sign of ν"). Hence ν = −ν_KDL.
  out.nu = m > 0 ? Eigen::VectorXd(-out.nu_kdl) : Eigen::VectorXd();
  if (m == 0) out.nu_kdl.resize(0);

  // Physical constraint torques: the tip wrench α ν (base axes, tip origin)
  // mapped by KDL's tip Jacobian (base axes, reference point at the tip,
  // rows [v; ω]). NOT KDL's constraint_torques, which project the articulated
  // (propagated) unit forces and differ from this except at the last joint.
  KDL::ChainJntToJacSolver jac_solver(chain);
  KDL::Jacobian jac(static_cast<unsigned int>(n));
  if (jac_solver.JntToJac(q, jac) < 0) throw std::runtime_error("KDL Jacobian failed");
  out.jacobian_tip = jac.data;
  out.tau_c = m > 0 ? Eigen::VectorXd(jac.data.transpose() * out.alpha * out.nu) : Eigen::VectorXd::Zero(n);

  // Link accelerations: KDL's x_dotdot[i] (i ≥ 1: links[i]) is the spatial
  // acceleration with −g, base axes, at the link origin; classical:
  //   p̈ = a_lin + g + ω × ṗ,  ω̇ = a_ang.
  out.acc_world.resize(spec.links.size());
  for (std::size_t i = 0; i < spec.links.size(); ++i) {
    const Vector6d& a = out.x_dotdot_kdl[i];
    out.acc_world[i] << a.head<3>() + g + omega(i).cross(origin_velocity(i)), a.tail<3>();
  }
  return out;
}

Eigen::VectorXd kdlInverseDynamics(const ChainSpec& spec, const Eigen::VectorXd& q, const Eigen::VectorXd& qd,
                                   const Eigen::VectorXd& qdd, const Eigen::Vector3d& gravity,
                                   const std::vector<WrenchInput>& wrenches) {
  const KDL::Chain chain = toKdlChain(spec);
  const auto ns = static_cast<unsigned int>(spec.joints.size());
  const KDL::JntArray q_kdl = toKdl(q);
  // RNE takes the gravity vector g itself (it sets the base acceleration to −g
  // internally) and reads f_ext[i] in the SEGMENT's own axes at its tip origin
  // (= our link-local wrench on links[i + 1]), as a force on the segment.
  std::vector<Eigen::Isometry3d> poses;
  KDL::Wrenches f_ext(ns, KDL::Wrench::Zero());
  for (const WrenchInput& w : wrenches) {
    const auto link = static_cast<std::size_t>(spec.linkIndex(w.link));
    if (link == 0) continue;
    Vector6d local = w.wrench;
    if (w.axes == Axes::World) {
      if (poses.empty()) poses = kdlLinkPoses(spec, q);
      local = rotate6(poses[link].linear().transpose(), w.wrench);
    }
    f_ext[link - 1] = f_ext[link - 1] + toKdlWrench(local);
  }
  KDL::ChainIdSolver_RNE rne(chain, toKdl(gravity));
  KDL::JntArray tau(static_cast<unsigned int>(spec.dof()));
  if (rne.CartToJnt(q_kdl, toKdl(qd), toKdl(qdd), f_ext, tau) < 0) throw std::runtime_error("KDL RNE failed");
  return tau.data;
}

ChainSpec mergeFixedJoints(const ChainSpec& spec) {
  spec.check();
  if (!spec.joints.empty() && spec.joints.back().isFixed())
    throw std::invalid_argument("mergeFixedJoints: the last joint is fixed, so the tip link would disappear");

  // Each surviving body accumulates (mass, first moment, inertia about its
  // origin) of the original links rigidly attached to it, in its own frame.
  struct Lump {
    double mass = 0.0;
    Eigen::Vector3d moment = Eigen::Vector3d::Zero();
    Eigen::Matrix3d Ibar = Eigen::Matrix3d::Zero();
  };
  auto add = [](Lump& lump, const LinkSpec& link, const Eigen::Isometry3d& T_body_link) {
    const Eigen::Matrix3d R = T_body_link.linear() * rpyToMatrix(link.inertial_rpy);
    const Eigen::Vector3d c = T_body_link * link.com;
    const Eigen::Matrix3d cx = skew3(c);
    lump.mass += link.mass;
    lump.moment += link.mass * c;
    lump.Ibar += R * link.inertia * R.transpose() - link.mass * cx * cx;  // parallel axis
  };
  auto finish = [](LinkSpec& link, const Lump& lump) {
    link.mass = lump.mass;
    link.inertial_rpy.setZero();
    link.com = lump.mass > 0.0 ? Eigen::Vector3d(lump.moment / lump.mass) : Eigen::Vector3d::Zero();
    const Eigen::Matrix3d cx = skew3(link.com);
    link.inertia = lump.Ibar + lump.mass * cx * cx;
    link.inertia = (0.5 * (link.inertia + link.inertia.transpose())).eval();  // eval: aliasing
  };

  ChainSpec out;
  out.name = spec.name;
  out.links.push_back(spec.links[0]);
  Lump lump;
  add(lump, spec.links[0], Eigen::Isometry3d::Identity());
  Eigen::Isometry3d T_body_current = Eigen::Isometry3d::Identity();  // current original link in the body frame
  for (std::size_t k = 0; k < spec.joints.size(); ++k) {
    const JointSpec& joint = spec.joints[k];
    const Eigen::Isometry3d T_body_joint = T_body_current * jointOrigin(joint);
    if (joint.isFixed()) {
      T_body_current = T_body_joint;
      add(lump, spec.links[k + 1], T_body_current);
      continue;
    }
    finish(out.links.back(), lump);
    JointSpec moved = joint;
    moved.xyz = T_body_joint.translation();
    moved.rpy = matrixToRpy(T_body_joint.linear());
    out.joints.push_back(moved);
    out.links.push_back(spec.links[k + 1]);
    lump = Lump();
    add(lump, spec.links[k + 1], Eigen::Isometry3d::Identity());
    T_body_current = Eigen::Isometry3d::Identity();
  }
  finish(out.links.back(), lump);
  return out;
}

}  // namespace zwang::testing
