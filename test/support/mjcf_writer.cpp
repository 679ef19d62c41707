#include "support/mjcf_writer.hpp"

#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

namespace zwang::testing {

namespace {

// Shortest text that reads back as the same double.
std::string num(double x) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", x);
  return buffer;
}

std::string vec(const Eigen::Vector3d& v) { return num(v.x()) + " " + num(v.y()) + " " + num(v.z()); }

// MJCF's quat attribute is "w x y z" (MuJoCo's XML reference, <body quat>).
std::string quat(const Eigen::Matrix3d& R) {
  const Eigen::Quaterniond q(R);
  return num(q.w()) + " " + num(q.x()) + " " + num(q.y()) + " " + num(q.z());
}

// Attribute values are quoted with "; escape what XML requires.
std::string xmlEscape(const std::string& text) {
  std::string out;
  for (const char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  }
  return out;
}

struct Writer {
  const ChainSpec& spec;
  bool joint_data;
  std::vector<std::vector<int>> child_joints;  // per link: the joints it is the parent of, in index order
  std::ostringstream out;

  void inertial(const LinkSpec& link, const std::string& indent) {
    if (link.mass == 0.0 && link.inertia.isZero(0.0)) return;  // massless: no <inertial>
    // MJCF's inertia is diaginertia about the COM in the principal axes `quat` of the inertial frame (MuJoCo's XML
    // reference, <inertial>). The URDF inertia I is about the COM in the axes R = R(inertial_rpy), so in the link's
    // axes it is R I Rᵀ = (R V) Λ (R V)ᵀ with I = V Λ Vᵀ: quat = R V, diaginertia = Λ.
    // Not fullinertia, which would let MuJoCo diagonalise: 2.2.2 refuses it next to quat ("multiple orientation
    // specifiers for the same field are not allowed"), and its 3×3 eigen-solver (mju_eig3) stops early: R Λ Rᵀ
    // rebuilt from its body_iquat/body_inertia misses fullinertia by up to 1.4e-6 relative (10⁵ random inertias
    // of randomInertia's kind), which shows as ~4e-7 in q̈. Eigen's symmetric solver is accurate to round-off;
    // test_mujoco checks what MuJoCo compiled against R I Rᵀ, without this decomposition.
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(0.5 * (link.inertia + link.inertia.transpose()));
    Eigen::Matrix3d V = eigen.eigenvectors();
    if (V.determinant() < 0.0) V.col(2) = -V.col(2);  // a proper rotation
    out << indent << "<inertial pos=\"" << vec(link.com) << "\" quat=\"" << quat(rpyToMatrix(link.inertial_rpy) * V)
        << "\" mass=\"" << num(link.mass) << "\" diaginertia=\"" << vec(eigen.eigenvalues()) << "\"/>\n";
  }

  // The body of links[k + 1], child of joints[k], and everything below it.
  void body(int k, const std::string& indent) {
    const JointSpec& joint = spec.joints[static_cast<std::size_t>(k)];
    const LinkSpec& link = spec.links[static_cast<std::size_t>(k) + 1];
    out << indent << "<body name=\"" << xmlEscape(link.name) << "\" pos=\"" << vec(joint.xyz) << "\" quat=\""
        << quat(rpyToMatrix(joint.rpy)) << "\">\n";
    const std::string inner = indent + "  ";
    if (joint.isPlanar())  // MJCF has no planar joint type (a slide-slide-hinge triple would be three joints)
      throw std::invalid_argument("toMjcf('" + spec.name + "'): planar joint " + joint.name + " has no MJCF type");
    if (!joint.isFixed()) {
      const char* type = joint.isPrismatic()   ? "slide"
                         : joint.isSpherical() ? "ball"
                         : joint.isFree()      ? "free"
                                               : "hinge";
      out << inner << "<joint name=\"" << xmlEscape(joint.name) << "\" type=\"" << type << "\" pos=\"0 0 0\"";
      if (joint.nv() == 1) out << " axis=\"" << vec(joint.axis) << "\"";
      if (!joint_data) {
        out << " limited=\"false\" armature=\"" << num(joint.reflectedInertia())
            << "\" damping=\"0\" stiffness=\"0\" frictionloss=\"0\"/>\n";
      } else {
        const bool limited = joint.nv() == 1 && joint.type != "continuous" && joint.lower < joint.upper;
        out << (limited ? " limited=\"true\" range=\"" + num(joint.lower) + " " + num(joint.upper) + "\""
                        : std::string(" limited=\"false\""))
            << " armature=\"" << num(joint.reflectedInertia()) << "\" damping=\"" << num(joint.damping)
            << "\" stiffness=\"0\" frictionloss=\"" << num(joint.friction) << "\"/>\n";
      }
    }
    inertial(link, inner);
    for (const int child : child_joints[static_cast<std::size_t>(k) + 1]) body(child, inner);
    out << indent << "</body>\n";
  }
};

}  // namespace

std::string toMjcf(const ChainSpec& spec, const Eigen::Vector3d& gravity) {
  return toMjcf(spec, gravity, FloatingBase{BaseKind::Fixed, Eigen::Isometry3d::Identity()});
}

std::string toMjcf(const ChainSpec& spec, const Eigen::Vector3d& gravity, const FloatingBase& base) {
  return toMjcf(spec, gravity, base, MjcfWriteOptions{});
}

std::string toMjcf(const ChainSpec& spec, const Eigen::Vector3d& gravity, const FloatingBase& base,
                   const MjcfWriteOptions& options) {
  spec.check();  // among others: every joint's parent link comes before its child, so the links form a tree
  // Per link, the joints it is the parent of; one more entry: the free joints (top-level bodies).
  Writer writer{spec, options.joint_data, std::vector<std::vector<int>>(spec.links.size() + 1), {}};
  for (std::size_t k = 0; k < spec.joints.size(); ++k) {
    const JointSpec& joint = spec.joints[k];
    const LinkSpec& child = spec.links[k + 1];
    if (!joint.isFixed() && !(child.mass > 0.0))
      throw std::invalid_argument("toMjcf('" + spec.name + "'): link " + child.name + " moves on joint " + joint.name +
                                  " but has no mass (MuJoCo refuses a moving body without mass)");
    if (joint.isFree() &&
        (base.kind != BaseKind::Fixed || spec.parentLink(k) != 0 || !joint.xyz.isZero(0.0) || !joint.rpy.isZero(0.0)))
      throw std::invalid_argument("toMjcf('" + spec.name + "'): free joint " + joint.name +
                                  " must hang at the identity from the root link of a fixed base (MuJoCo's free "
                                  "joints are on top-level bodies)");
    // A free joint's body is written at the top level, beside links[0]'s (the same place: the root link is the
    // world); every other body in its parent link's.
    writer.child_joints[joint.isFree() ? spec.links.size() : static_cast<std::size_t>(spec.parentLink(k))].push_back(
        static_cast<int>(k));
    if (base.kind != BaseKind::Fixed && (joint.name == kMjcfFreeJoint || joint.name == kMjcfPlanarX ||
                                         joint.name == kMjcfPlanarY || joint.name == kMjcfPlanarYaw))
      throw std::invalid_argument("toMjcf('" + spec.name + "'): joint " + joint.name +
                                  " has the name of a floating-base joint");
  }
  if (base.kind != BaseKind::Fixed && !(spec.links[0].mass > 0.0))
    throw std::invalid_argument("toMjcf('" + spec.name + "'): the floating root link " + spec.links[0].name +
                                " has no mass (MuJoCo refuses a moving body without mass)");
  if (base.kind != BaseKind::Planar && !base.plane.matrix().isIdentity(0.0))
    throw std::invalid_argument("toMjcf('" + spec.name + "'): a plane pose is only for a Planar base");

  std::ostringstream& out = writer.out;
  out << "<mujoco model=\"" << xmlEscape(spec.name)
      << "\">\n"
      // Inertias as written: none from geoms (there are none), no balancing of the triangle inequality, no lower
      // bounds on masses and inertias (MuJoCo's XML reference, <compiler>).
      << "  <compiler angle=\"radian\" inertiafromgeom=\"false\" balanceinertia=\"false\" boundmass=\"0\" "
         "boundinertia=\"0\"/>\n"
      << "  <option gravity=\"" << vec(gravity)
      << "\" integrator=\"Euler\">\n"
      // The smooth dynamics only: no contacts, no constraint solver (hence no limits, friction loss or equality
      // constraints), no passive forces (springs, damping); with the joints' data, no contacts only.
      << (options.joint_data ? "    <flag contact=\"disable\"/>\n"
                             : "    <flag contact=\"disable\" constraint=\"disable\" limit=\"disable\" "
                               "frictionloss=\"disable\" equality=\"disable\" passive=\"disable\"/>\n")
      << "  </option>\n"
      << "  <worldbody>\n";
  if (base.kind == BaseKind::Planar) {
    out << "    <body name=\"" << xmlEscape(spec.links[0].name) << "\" pos=\"" << vec(base.plane.translation())
        << "\" quat=\"" << quat(base.plane.linear()) << "\">\n";
  } else {
    out << "    <body name=\"" << xmlEscape(spec.links[0].name) << "\" pos=\"0 0 0\" quat=\"1 0 0 0\">\n";
  }
  if (base.kind == BaseKind::Free) {
    out << "      <freejoint name=\"" << kMjcfFreeJoint << "\"/>\n";
  } else if (base.kind == BaseKind::Planar) {
    const char* names[] = {kMjcfPlanarX, kMjcfPlanarY, kMjcfPlanarYaw};
    const char* types[] = {"slide", "slide", "hinge"};
    const char* axes[] = {"1 0 0", "0 1 0", "0 0 1"};
    for (int k = 0; k < 3; ++k)
      out << "      <joint name=\"" << names[k] << "\" type=\"" << types[k] << "\" pos=\"0 0 0\" axis=\"" << axes[k]
          << "\" limited=\"false\" armature=\"0\" damping=\"0\" stiffness=\"0\" frictionloss=\"0\"/>\n";
  }
  writer.inertial(spec.links[0], "      ");
  for (const int k : writer.child_joints[0]) writer.body(k, "      ");
  out << "    </body>\n";
  for (const int k : writer.child_joints[spec.links.size()]) writer.body(k, "    ");
  out << "  </worldbody>\n"
      << "</mujoco>\n";
  return out.str();
}

}  // namespace zwang::testing
