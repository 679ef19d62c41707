#include "support/chain_spec.hpp"

#include <cmath>
#include <set>
#include <stdexcept>

#include <Eigen/Geometry>

namespace zwang::testing {

int ChainSpec::dof() const {
  int n = 0;
  for (const JointSpec& joint : joints) n += joint.nv();
  return n;
}

int ChainSpec::nq() const {
  int n = 0;
  for (const JointSpec& joint : joints) n += joint.nq();
  return n;
}

bool ChainSpec::hasMultiDofJoints() const {
  for (const JointSpec& joint : joints)
    if (joint.nv() > 1) return true;
  return false;
}

std::vector<int> ChainSpec::movingJoints() const {
  std::vector<int> moving;
  for (std::size_t k = 0; k < joints.size(); ++k)
    if (!joints[k].isFixed()) moving.push_back(static_cast<int>(k));
  return moving;
}

int ChainSpec::linkIndex(const std::string& link_name) const {
  for (std::size_t i = 0; i < links.size(); ++i)
    if (links[i].name == link_name) return static_cast<int>(i);
  throw std::invalid_argument("ChainSpec '" + name + "': no link named '" + link_name + "'");
}

void ChainSpec::check() const {
  const std::string where = "ChainSpec '" + name + "': ";
  if (links.size() != joints.size() + 1) throw std::invalid_argument(where + "needs links.size() == joints.size() + 1");
  std::set<std::string> names;
  for (const LinkSpec& link : links) {
    if (!names.insert("link:" + link.name).second) throw std::invalid_argument(where + "repeated link " + link.name);
    if (!(link.mass >= 0.0)) throw std::invalid_argument(where + "negative mass on link " + link.name);
  }
  for (const JointSpec& joint : joints) {
    if (!names.insert("joint:" + joint.name).second)
      throw std::invalid_argument(where + "repeated joint " + joint.name);
    if (joint.type != "revolute" && joint.type != "continuous" && joint.type != "prismatic" &&
        joint.type != "spherical" && joint.type != "planar" && joint.type != "free" && joint.type != "fixed")
      throw std::invalid_argument(where + "joint " + joint.name + " has unknown type '" + joint.type + "'");
    if (joint.nv() == 1 && std::abs(joint.axis.norm() - 1.0) > 1e-12)
      throw std::invalid_argument(where + "joint " + joint.name + " axis is not a unit vector");
    if (joint.nv() > 1 && joint.isMimic())
      throw std::invalid_argument(where + "joint " + joint.name + " has several DOFs and cannot mimic");
  }
  // MimicLaw counts dofs by moving joint: one DOF each.
  if (hasMimic() && hasMultiDofJoints())
    throw std::invalid_argument(where + "mimic joints need every moving joint to have one DOF");
  for (std::size_t k = 0; k < joints.size(); ++k)
    if (parentLink(k) > static_cast<int>(k))
      throw std::invalid_argument(where + "joint " + joints[k].name + " has a parent after its child");
}

std::vector<int> ChainSpec::directLeaders() const {
  const std::vector<int> moving = movingJoints();
  std::vector<int> leaders(moving.size(), -1);
  for (std::size_t j = 0; j < moving.size(); ++j) {
    const JointSpec& joint = joints[static_cast<std::size_t>(moving[j])];
    if (!joint.isMimic()) continue;
    for (std::size_t l = 0; l < moving.size(); ++l)
      if (joints[static_cast<std::size_t>(moving[l])].name == joint.mimic) leaders[j] = static_cast<int>(l);
    if (leaders[j] < 0 || leaders[j] == static_cast<int>(j))
      throw std::invalid_argument("ChainSpec '" + name + "': joint " + joint.name + " mimics '" + joint.mimic +
                                  "', which is not another moving joint");
  }
  return leaders;
}

bool ChainSpec::hasMimic() const {
  for (const JointSpec& joint : joints)
    if (!joint.isFixed() && joint.isMimic()) return true;
  return false;
}

std::vector<MimicLaw> ChainSpec::mimicLaws() const {
  const std::vector<int> moving = movingJoints();
  const std::vector<int> leaders = directLeaders();
  std::vector<MimicLaw> laws;
  for (std::size_t j = 0; j < moving.size(); ++j) {
    if (leaders[j] < 0) continue;
    // Substitute the leader's own law while it is a mimic joint: q_j = a·q_k + b
    // with q_k = a'·q_l + b' is q_j = (a·a')·q_l + (a·b' + b).
    MimicLaw law;
    law.joint = static_cast<int>(j);
    law.leader = static_cast<int>(j);
    for (std::size_t steps = 0; leaders[static_cast<std::size_t>(law.leader)] >= 0; ++steps) {
      if (steps > moving.size())
        throw std::invalid_argument("ChainSpec '" + name + "': the mimic joints through " +
                                    joints[static_cast<std::size_t>(moving[j])].name + " form a cycle");
      const JointSpec& here = joints[static_cast<std::size_t>(moving[static_cast<std::size_t>(law.leader)])];
      law.offset += law.multiplier * here.mimic_offset;
      law.multiplier *= here.mimic_multiplier;
      law.leader = leaders[static_cast<std::size_t>(law.leader)];
    }
    laws.push_back(law);
  }
  return laws;
}

void ChainSpec::followMimicLaws(Eigen::VectorXd& q, Eigen::VectorXd& qd) const {
  for (const MimicLaw& law : mimicLaws()) {
    q(law.joint) = law.multiplier * q(law.leader) + law.offset;
    if (qd.size() > 0) qd(law.joint) = law.multiplier * qd(law.leader);
  }
}

bool ChainSpec::isChain() const {
  for (std::size_t k = 0; k < joints.size(); ++k)
    if (parentLink(k) != static_cast<int>(k)) return false;
  return true;
}

Eigen::Matrix3d rpyToMatrix(const Eigen::Vector3d& rpy) {
  // Fixed axes: roll about x first, then pitch about the fixed y, then yaw about
  // the fixed z, i.e. R = Rz(yaw)·Ry(pitch)·Rx(roll) (URDF <origin rpy>).
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

ChainSpec oneDofArm() {
  ChainSpec spec;
  spec.name = "one_dof_arm";

  LinkSpec base;
  base.name = "base";
  LinkSpec link;
  link.name = "link1";
  link.mass = 1.0;
  link.com = Eigen::Vector3d(0.5, 0.0, 0.0);
  // A slender bar along x: I_zz = 2 (docs/theory.md, "The reference cases"), I_yy = 2, a small I_xx that keeps
  // the triangle inequality I_xx + I_yy >= I_zz.
  link.inertia = Eigen::Vector3d(0.01, 2.0, 2.0).asDiagonal();
  LinkSpec tool;  // massless frame at the tip, where the report applies its force
  tool.name = "tool";

  JointSpec joint;
  joint.name = "joint1";
  joint.type = "revolute";
  joint.axis = Eigen::Vector3d::UnitZ();
  joint.lower = -3.0;
  joint.upper = 3.0;
  joint.effort = 100.0;
  joint.velocity = 10.0;
  joint.friction = 10.0;
  JointSpec tip;
  tip.name = "tool_joint";
  tip.type = "fixed";
  tip.xyz = Eigen::Vector3d(1.0, 0.0, 0.0);

  spec.links = {base, link, tool};
  spec.joints = {joint, tip};
  return spec;
}

}  // namespace zwang::testing
