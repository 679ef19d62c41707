#include "support/urdf_writer.hpp"

#include <cstdio>
#include <sstream>

namespace zwang::testing {

namespace {

// Shortest text that reads back as the same double.
std::string num(double x) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.17g", x);
  return buffer;
}

std::string vec(const Eigen::Vector3d& v) { return num(v.x()) + " " + num(v.y()) + " " + num(v.z()); }

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

void writeLink(std::ostringstream& out, const LinkSpec& link) {
  out << "  <link name=\"" << xmlEscape(link.name) << "\">\n";
  if (link.mass > 0.0 || !link.inertia.isZero(0.0)) {
    const Eigen::Matrix3d& I = link.inertia;
    // URDF lists the upper triangle of the symmetric matrix: ixy is the (0,1)
    // entry itself (not the negated product of inertia).
    out << "    <inertial>\n"
        << "      <origin xyz=\"" << vec(link.com) << "\" rpy=\"" << vec(link.inertial_rpy) << "\"/>\n"
        << "      <mass value=\"" << num(link.mass) << "\"/>\n"
        << "      <inertia ixx=\"" << num(I(0, 0)) << "\" ixy=\"" << num(I(0, 1)) << "\" ixz=\"" << num(I(0, 2))
        << "\" iyy=\"" << num(I(1, 1)) << "\" iyz=\"" << num(I(1, 2)) << "\" izz=\"" << num(I(2, 2)) << "\"/>\n"
        << "    </inertial>\n";
  }
  out << "  </link>\n";
}

void writeJoint(std::ostringstream& out, const JointSpec& joint, const LinkSpec& parent, const LinkSpec& child) {
  out << "  <joint name=\"" << xmlEscape(joint.name) << "\" type=\"" << xmlEscape(joint.type) << "\">\n"
      << "    <parent link=\"" << xmlEscape(parent.name) << "\"/>\n"
      << "    <child link=\"" << xmlEscape(child.name) << "\"/>\n"
      << "    <origin xyz=\"" << vec(joint.xyz) << "\" rpy=\"" << vec(joint.rpy) << "\"/>\n";
  if (!joint.isFixed()) {
    out << "    <axis xyz=\"" << vec(joint.axis) << "\"/>\n";
    // urdfdom requires <limit> for revolute and prismatic joints; a continuous
    // joint keeps only effort and velocity.
    out << "    <limit";
    if (joint.type != "continuous") out << " lower=\"" << num(joint.lower) << "\" upper=\"" << num(joint.upper) << "\"";
    out << " effort=\"" << num(joint.effort) << "\" velocity=\"" << num(joint.velocity) << "\"/>\n";
  }
  out << "    <dynamics damping=\"" << num(joint.damping) << "\" friction=\"" << num(joint.friction) << "\"/>\n";
  if (!joint.isFixed() && joint.isMimic())
    out << "    <mimic joint=\"" << xmlEscape(joint.mimic) << "\" multiplier=\"" << num(joint.mimic_multiplier)
        << "\" offset=\"" << num(joint.mimic_offset) << "\"/>\n";
  out << "  </joint>\n";
}

void writeTransmission(std::ostringstream& out, const JointSpec& joint) {
  const std::string name = xmlEscape(joint.name);
  out << "  <transmission name=\"" << name << "_transmission\">\n"
      << "    <type>transmission_interface/SimpleTransmission</type>\n"
      << "    <joint name=\"" << name << "\">\n"
      << "      <hardwareInterface>hardware_interface/EffortJointInterface</hardwareInterface>\n"
      << "    </joint>\n"
      << "    <actuator name=\"" << name << "_motor\">\n"
      << "      <mechanicalReduction>" << num(joint.gear_ratio) << "</mechanicalReduction>\n"
      << "      <drake:rotor_inertia value=\"" << num(joint.rotor_inertia) << "\"/>\n"
      << "      <drake:gear_ratio value=\"" << num(joint.gear_ratio) << "\"/>\n"
      << "    </actuator>\n"
      << "  </transmission>\n";
}

}  // namespace

std::string toUrdf(const ChainSpec& spec) {
  spec.check();
  std::ostringstream out;
  out << "<?xml version=\"1.0\"?>\n"
      << "<robot name=\"" << xmlEscape(spec.name) << "\" xmlns:drake=\"http://drake.mit.edu\">\n";
  for (const LinkSpec& link : spec.links) writeLink(out, link);
  for (std::size_t k = 0; k < spec.joints.size(); ++k)
    writeJoint(out, spec.joints[k], spec.links[static_cast<std::size_t>(spec.parentLink(k))], spec.links[k + 1]);
  for (const JointSpec& joint : spec.joints)
    if (!joint.isFixed() && joint.rotor_inertia > 0.0) writeTransmission(out, joint);
  out << "</robot>\n";
  return out.str();
}

}  // namespace zwang::testing
