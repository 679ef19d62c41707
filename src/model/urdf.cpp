// URDF → Model (see urdf.hpp).
//
// Three readers look at the same text:
//  1. TinyXML (the parser urdfdom itself uses) checks that the XML is well
//     formed, so a syntax error is reported with its line and column, and
//     checks every number zwang reads (origins, axes, masses, inertias,
//     limits, dynamics) so that a NaN, an infinity or a word where a number
//     belongs is reported with the link or joint and the attribute at fault
//     rather than as urdfdom's generic "could not parse" lines.
//  2. urdfdom builds the link/joint tree. Its console_bridge messages are
//     captured. urdfdom sometimes logs an error and still returns a model
//     (an unreadable <mass> or <inertia> leaves zeros behind, which pass 1
//     refuses first, naming the link; an unreadable <visual>): an error is a
//     failure, unless the file reads without its <visual>, <collision> and
//     <material> elements, which never enter the dynamics; then it loads
//     without them, with a warning naming each link or material at fault.
//  3. TinyXML again for what urdfdom drops: <transmission> elements with
//     Drake's rotor-inertia tags.
//
// What is loaded (urdf.hpp, UrdfOptions): without a tip, the whole tree below
// the root link, walked depth first with each link's children in the order of
// their joints' names; with a tip, the chain from the root link to the tip
// link (a tree that does not branch into moving joints is such a chain, to its
// unique leaf, and is loaded as one). Revolute,
// continuous and prismatic joints become the model's joints; fixed joints
// become frames and their links' inertias are merged into the body they are
// welded to. Every link connected to a loaded link through fixed joints only
// (side branches, links below the tip, fixed parents of the root) is a frame.
// For a chain, links connected through a moving joint that is not on it are
// NOT part of the model: their mass is ignored, as KDL's tree→chain
// conversion does, with a warning when they ride on a moving body (beyond the
// tip, or a side branch). A <mimic> joint among the loaded ones follows its
// leader (Joint::mimic; the leader must be loaded too), or is welded at the
// position its leader at rest implies (MimicJoints::Lock), or refused
// (MimicJoints::Refuse): never loaded as an independent joint.
//
// The base (chooseBase): a floating or planar joint that is the URDF root
// link's only joint becomes a Free or Planar base under its child link (the
// links above it are the world); UrdfOptions::base adds one under the root
// link instead. Either way the root link's own inertia is the base's
// (addRootLinkInertia), and every link of a floating base is judged like a
// moving one.
#include "zwang/urdf.hpp"

#include <console_bridge/console.h>
#include <tinyxml.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <mutex>
#include <set>
#include <sstream>
#include <vector>

#include "model/loader_messages.hpp"
#include "model/urdf_option_names.hpp"
#include "model/validate.hpp"

namespace zwang {
namespace {

using internal::NamedUrdfOptions;

constexpr double kInf = std::numeric_limits<double>::infinity();

using internal::fmt;
using internal::nameList;
using internal::Reporter;

// ---------------------------------------------------------------------------
// Numbers as text (pass 1)

enum class Parsed { Ok, NotANumber, NotFinite };

// Locale-independent, like urdfdom's strToDouble, but telling a non-number
// apart from NaN / infinity / out of range.
Parsed parseNumber(std::string token, double& value) {
  if (token.size() > 1 && token[0] == '+' && token[1] != '-' && token[1] != '+') token.erase(0, 1);
  const char* begin = token.data();
  const char* end = begin + token.size();
  const auto result = std::from_chars(begin, end, value, std::chars_format::general);
  if (result.ec == std::errc::result_out_of_range) return Parsed::NotFinite;
  if (result.ec != std::errc() || result.ptr != end) return Parsed::NotANumber;
  return std::isfinite(value) ? Parsed::Ok : Parsed::NotFinite;
}

std::vector<std::string> splitWhitespace(const std::string& text) {
  std::vector<std::string> tokens;
  std::istringstream in(text);
  std::string token;
  while (in >> token) tokens.push_back(token);
  return tokens;
}

// Checks attribute `attr` of `element` (if present): `count` finite numbers.
// `what` names the owner and the element path, e.g. "joint 'j': <origin>".
void checkNumbers(const Reporter& report, const std::string& what, const TiXmlElement* element, const char* attr,
                  std::size_t count) {
  if (element == nullptr) return;
  const char* text = element->Attribute(attr);
  if (text == nullptr) return;
  const std::string field = what + " " + attr + " \"" + text + "\"";
  const std::vector<std::string> tokens = splitWhitespace(text);
  if (tokens.size() != count) {
    report.fail(field + " must hold " + std::to_string(count) + (count == 1 ? " number" : " numbers") + ", not " +
                std::to_string(tokens.size()));
  }
  for (const std::string& token : tokens) {
    double value = 0.0;
    switch (parseNumber(token, value)) {
      case Parsed::Ok: break;
      case Parsed::NotANumber: report.fail(field + ": '" + token + "' is not a number");
      case Parsed::NotFinite: report.fail(field + ": '" + token + "' is not finite");
    }
  }
}

std::string nameOf(const TiXmlElement* element) {
  const char* name = element->Attribute("name");
  return name ? name : "";
}

// An <inertial> that urdfdom cannot read whole: it logs an error and keeps
// the link with its mass or moments silently zeroed, so refuse it here,
// naming the link.
void checkInertialComplete(const Reporter& report, const std::string& who, const TiXmlElement* inertial) {
  const TiXmlElement* mass = inertial->FirstChildElement("mass");
  if (mass == nullptr || mass->Attribute("value") == nullptr)
    report.fail(who + "<inertial> has no " + (mass ? "value attribute in its <mass>" : "<mass> element") +
                ": urdfdom would silently read the link's mass and inertia as zero (write <mass value=\"…\"/>)");
  const TiXmlElement* inertia = inertial->FirstChildElement("inertia");
  if (inertia == nullptr)
    report.fail(who + "<inertial> has no <inertia> element: urdfdom would silently read all six moments as zero " +
                "(write <inertia ixx=\"…\" ixy=\"…\" ixz=\"…\" iyy=\"…\" iyz=\"…\" izz=\"…\"/>)");
  for (const char* attr : {"ixx", "ixy", "ixz", "iyy", "iyz", "izz"})
    if (inertia->Attribute(attr) == nullptr)
      report.fail(who + "<inertial> <inertia> has no " + attr +
                  " attribute: urdfdom would silently read all six moments as zero (give ixx, ixy, ixz, iyy, iyz "
                  "and izz, 0 where the moment is zero)");
}

// Every number of every link and joint zwang reads, anywhere in the file.
void checkAllNumbers(const Reporter& report, const TiXmlElement* robot) {
  for (const TiXmlElement* link = robot->FirstChildElement("link"); link; link = link->NextSiblingElement("link")) {
    const TiXmlElement* inertial = link->FirstChildElement("inertial");
    if (inertial == nullptr) continue;
    const std::string who = "link '" + nameOf(link) + "': ";
    checkInertialComplete(report, who, inertial);
    const TiXmlElement* origin = inertial->FirstChildElement("origin");
    checkNumbers(report, who + "<inertial> <origin>", origin, "xyz", 3);
    checkNumbers(report, who + "<inertial> <origin>", origin, "rpy", 3);
    checkNumbers(report, who + "<inertial> <mass>", inertial->FirstChildElement("mass"), "value", 1);
    for (const char* attr : {"ixx", "ixy", "ixz", "iyy", "iyz", "izz"})
      checkNumbers(report, who + "<inertial> <inertia>", inertial->FirstChildElement("inertia"), attr, 1);
  }
  for (const TiXmlElement* joint = robot->FirstChildElement("joint"); joint;
       joint = joint->NextSiblingElement("joint")) {
    const std::string who = "joint '" + nameOf(joint) + "': ";
    checkNumbers(report, who + "<origin>", joint->FirstChildElement("origin"), "xyz", 3);
    checkNumbers(report, who + "<origin>", joint->FirstChildElement("origin"), "rpy", 3);
    checkNumbers(report, who + "<axis>", joint->FirstChildElement("axis"), "xyz", 3);
    for (const char* attr : {"lower", "upper", "effort", "velocity"})
      checkNumbers(report, who + "<limit>", joint->FirstChildElement("limit"), attr, 1);
    for (const char* attr : {"friction", "damping"})
      checkNumbers(report, who + "<dynamics>", joint->FirstChildElement("dynamics"), attr, 1);
    for (const char* attr : {"multiplier", "offset"})
      checkNumbers(report, who + "<mimic>", joint->FirstChildElement("mimic"), attr, 1);
  }
}

// ---------------------------------------------------------------------------
// urdfdom with its console_bridge messages captured (pass 2)

// console_bridge keeps one global handler (and remembers the one before it),
// so the capturing handler is a process-lifetime object: if anybody later
// restores "the previous handler" and gets this one, it forwards to the
// handler that was active when the last load started. Loads are serialised
// by a mutex while the handler is installed. During a load nothing reaches
// the console: errors fail the load, warnings become ModelWarnings (once
// each), informational and debug lines are dropped.
class CaptureHandler final : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char* filename, int line) override {
    if (errors != nullptr) {
      if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR)
        errors->push_back(text);
      else if (level == console_bridge::CONSOLE_BRIDGE_LOG_WARN)
        warnings->push_back(text);
    } else if (forward != nullptr && forward != this && level >= forward_level) {
      forward->log(text, level, filename, line);
    }
  }
  std::vector<std::string>* errors = nullptr;
  std::vector<std::string>* warnings = nullptr;
  console_bridge::OutputHandler* forward = nullptr;
  console_bridge::LogLevel forward_level = console_bridge::CONSOLE_BRIDGE_LOG_WARN;
};

std::mutex& captureMutex() {
  static std::mutex mutex;
  return mutex;
}

CaptureHandler& captureHandler() {
  static CaptureHandler* handler = new CaptureHandler;  // never destroyed (see above)
  return *handler;
}

// One run of urdfdom over `xml`: its model (possibly null) and what it logged.
struct UrdfdomRun {
  urdf::ModelInterfaceSharedPtr model;
  std::vector<std::string> errors;
  std::vector<std::string> warnings;
};

UrdfdomRun runUrdfdom(const std::string& xml) {
  UrdfdomRun run;
  const std::lock_guard<std::mutex> lock(captureMutex());
  CaptureHandler& handler = captureHandler();
  console_bridge::OutputHandler* const previous = console_bridge::getOutputHandler();
  const console_bridge::LogLevel previous_level = console_bridge::getLogLevel();
  handler.forward = previous;
  handler.forward_level = previous_level;
  handler.errors = &run.errors;
  handler.warnings = &run.warnings;
  console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_WARN);  // warnings reach the handler
  console_bridge::useOutputHandler(&handler);
  struct Restore {
    CaptureHandler& handler;
    console_bridge::OutputHandler* previous;
    console_bridge::LogLevel level;
    ~Restore() {
      console_bridge::useOutputHandler(previous);
      console_bridge::setLogLevel(level);
      handler.errors = nullptr;
      handler.warnings = nullptr;
    }
  } restore{handler, previous, previous_level};
  try {
    run.model = urdf::parseURDF(xml);
  } catch (const std::exception& e) {
    run.errors.push_back(e.what());
    run.model.reset();
  }
  return run;
}

std::string joined(const std::vector<std::string>& texts) {
  std::string all;
  for (const std::string& t : texts) all += (all.empty() ? "" : "; ") + t;
  return all;
}

// `element` (a copy) as the whole of a <robot>, with an empty link after it
// when `with_link` (urdfdom wants one), as text for urdfdom (NUL-padded as in load()).
std::string probeText(const TiXmlElement& element, bool with_link) {
  TiXmlElement robot("robot");
  robot.SetAttribute("name", "probe");
  robot.InsertEndChild(element);
  if (with_link) {
    TiXmlElement link("link");
    link.SetAttribute("name", "probe");
    robot.InsertEndChild(link);
  }
  TiXmlDocument doc;
  doc.InsertEndChild(robot);
  TiXmlPrinter printer;
  doc.Accept(&printer);
  return printer.Str() + std::string(8, '\0');
}

// The file without what only draws the robot: each link's <visual> and
// <collision>, the top-level <material>s.
std::string withoutAppearance(const TiXmlElement* robot) {
  TiXmlElement bare(*robot);
  for (TiXmlElement* link = bare.FirstChildElement("link"); link; link = link->NextSiblingElement("link"))
    for (const char* tag : {"visual", "collision"})
      while (TiXmlElement* child = link->FirstChildElement(tag)) link->RemoveChild(child);
  while (TiXmlElement* material = bare.FirstChildElement("material")) bare.RemoveChild(material);
  TiXmlDocument doc;
  doc.InsertEndChild(bare);
  TiXmlPrinter printer;
  doc.Accept(&printer);
  return printer.Str() + std::string(8, '\0');
}

// One Urdfdom warning per link or top-level <material> urdfdom cannot read
// alone (links and materials are parsed independently of each other), or one
// for all when none of them fails alone.
void appearanceWarnings(const TiXmlElement* robot, const std::vector<std::string>& errors,
                        std::vector<ModelWarning>& warnings) {
  const std::string loaded = "; they do not enter the dynamics: loaded without them";
  bool named = false;
  for (const TiXmlElement* link = robot->FirstChildElement("link"); link; link = link->NextSiblingElement("link")) {
    if (!link->FirstChildElement("visual") && !link->FirstChildElement("collision")) continue;
    const UrdfdomRun alone = runUrdfdom(probeText(*link, false));
    if (alone.errors.empty()) continue;
    warnings.push_back({WarningCode::Urdfdom, "link '" + nameOf(link) +
                                                  "': urdfdom cannot read its <visual> or <collision> elements (" +
                                                  joined(alone.errors) + ")" + loaded});
    named = true;
  }
  for (const TiXmlElement* material = robot->FirstChildElement("material"); material;
       material = material->NextSiblingElement("material")) {
    const UrdfdomRun alone = runUrdfdom(probeText(*material, true));
    if (alone.errors.empty()) continue;
    const char* name = material->Attribute("name");
    warnings.push_back(
        {WarningCode::Urdfdom, (name ? "<material> '" + std::string(name) + "'" : "a <material> without a name") +
                                   ": urdfdom cannot read it (" + joined(alone.errors) +
                                   "); materials do not enter the dynamics: loaded without it"});
    named = true;
  }
  if (!named)
    warnings.push_back({WarningCode::Urdfdom, "urdfdom: " + joined(errors) +
                                                  "; the file reads without its <visual>, <collision> and <material> "
                                                  "elements" +
                                                  loaded});
}

// urdfdom's model; its logged warnings are appended to `warnings`. urdfdom
// logs an error and still returns a model for an unreadable <visual>,
// <collision> or <material> (a material without a name, a visual without
// geometry): Pinocchio and ROS load such files. When the file reads without
// those elements, it is loaded so, with a warning per link or material at
// fault; any other error fails the load.
urdf::ModelInterfaceSharedPtr parseWithUrdfdom(const Reporter& report, const TiXmlElement* robot,
                                               const std::string& xml, std::vector<ModelWarning>& warnings) {
  const UrdfdomRun run = runUrdfdom(xml);
  for (const std::string& text : run.warnings) warnings.push_back({WarningCode::Urdfdom, "urdfdom: " + text});
  if (run.errors.empty()) {
    if (!run.model) report.fail("urdfdom could not parse the URDF (it gave no reason)");
    return run.model;
  }
  const UrdfdomRun bare = runUrdfdom(withoutAppearance(robot));
  if (!bare.errors.empty() || !bare.model)
    report.fail("urdfdom rejected the URDF: " + joined(bare.errors.empty() ? run.errors : bare.errors));
  appearanceWarnings(robot, run.errors, warnings);
  return bare.model;
}

// ---------------------------------------------------------------------------
// Drake rotor inertia from <transmission> (pass 3)

// Reads <tag value="…"/> under `actuator`; returns false when absent.
bool drakeValue(const Reporter& report, const std::string& who, const TiXmlElement* actuator, const char* tag,
                double& value) {
  const TiXmlElement* element = actuator->FirstChildElement(tag);
  if (element == nullptr) return false;
  const std::string field = who + ": <" + std::string(tag) + ">";
  const char* text = element->Attribute("value");
  if (text == nullptr) report.fail(field + " has no value attribute");
  const std::vector<std::string> tokens = splitWhitespace(text);
  if (tokens.size() != 1) report.fail(field + " value \"" + text + "\" is not a number");
  switch (parseNumber(tokens[0], value)) {
    case Parsed::Ok: break;
    case Parsed::NotANumber: report.fail(field + " value \"" + text + "\" is not a number");
    case Parsed::NotFinite: report.fail(field + " value \"" + text + "\" is not finite");
  }
  if (value < 0.0) report.fail(field + " value " + fmt(value) + " is negative");
  return true;
}

// joint name → reflected rotor inertia rotor_inertia · gear_ratio².
std::map<std::string, double> readTransmissions(const Reporter& report, const TiXmlElement* robot,
                                                const urdf::ModelInterface& urdf_model) {
  std::map<std::string, double> reflected;
  for (const TiXmlElement* tr = robot->FirstChildElement("transmission"); tr;
       tr = tr->NextSiblingElement("transmission")) {
    const std::string who = "transmission '" + nameOf(tr) + "'";
    double rotor_inertia = 0.0;
    bool has_rotor = false;
    for (const TiXmlElement* act = tr->FirstChildElement("actuator"); act; act = act->NextSiblingElement("actuator")) {
      const std::string act_who = who + ": <actuator> '" + nameOf(act) + "'";
      double rotor = 0.0, gear = 1.0;
      const bool rotor_here = drakeValue(report, act_who, act, "drake:rotor_inertia", rotor);
      drakeValue(report, act_who, act, "drake:gear_ratio", gear);
      if (!rotor_here) continue;
      if (has_rotor) report.fail(who + ": more than one <actuator> has a <drake:rotor_inertia>");
      has_rotor = true;
      rotor_inertia = rotor * gear * gear;
    }
    if (!has_rotor) continue;
    std::vector<std::string> joints;
    for (const TiXmlElement* j = tr->FirstChildElement("joint"); j; j = j->NextSiblingElement("joint"))
      joints.push_back(nameOf(j));
    if (joints.size() != 1)
      report.fail(who + ": a <drake:rotor_inertia> needs exactly one <joint name=…> in its transmission, found " +
                  std::to_string(joints.size()));
    if (!urdf_model.getJoint(joints[0])) report.fail(who + ": <joint> '" + joints[0] + "' is not a joint of the URDF");
    if (!reflected.emplace(joints[0], rotor_inertia).second)
      report.fail(who + ": joint '" + joints[0] + "' already has a rotor inertia from another transmission");
  }
  return reflected;
}

// ---------------------------------------------------------------------------
// Geometry and inertia

Mat3 rotationOf(const urdf::Rotation& q) {
  return Eigen::Quaterniond(q.w, q.x, q.y, q.z).normalized().toRotationMatrix();
}
Vec3 vectorOf(const urdf::Vector3& v) { return Vec3(v.x, v.y, v.z); }

// ᶜX_p of a joint: the child link's frame (at q = 0) seen from its parent's.
Transform placementOf(const urdf::Joint& joint) {
  const urdf::Pose& pose = joint.parent_to_joint_origin_transform;
  return Transform::fromPose(rotationOf(pose.rotation), vectorOf(pose.position));
}

// The link's inertia in its own frame; a link without <inertial> is massless.
// Its mass is checked here, naming the URDF field; whether the rotational
// inertia is a body's is the ModelBuilder's check, made only for links that
// move (anything welded to a fixed base is skipped: it never moves; `on_base`
// is false for every link of a floating base).
RigidInertia linkInertia(const Reporter& report, const urdf::Link& link, bool on_base) {
  if (!link.inertial) return RigidInertia{};
  const urdf::Inertial& in = *link.inertial;
  const std::string who = "link '" + link.name + "': <inertial>";
  if (!on_base) {
    if (!std::isfinite(in.mass)) report.fail(who + " <mass> value is not finite");
    if (in.mass < 0.0) report.fail(who + " <mass> value " + fmt(in.mass) + " is negative");
    if (in.mass > validate::kMaxMass)
      report.fail(who + " <mass> value " + fmt(in.mass) + " kg is above " + fmt(validate::kMaxMass) +
                  " kg, the heaviest link zwang accepts (a typo?)");
  }
  Mat3 I_frame;                       // in the COM frame given by <inertial><origin>
  I_frame << in.ixx, in.ixy, in.ixz,  //
      in.ixy, in.iyy, in.iyz,         //
      in.ixz, in.iyz, in.izz;
  const Mat3 R = rotationOf(in.origin.rotation);  // COM frame axes in the link frame
  const Mat3 I_com = R * I_frame * R.transpose();
  return RigidInertia::fromMassComInertia(in.mass, vectorOf(in.origin.position), I_com);
}

bool isMoving(const urdf::Joint& joint) { return joint.type != urdf::Joint::FIXED; }

const char* typeName(int type) {
  switch (type) {
    case urdf::Joint::REVOLUTE: return "revolute";
    case urdf::Joint::CONTINUOUS: return "continuous";
    case urdf::Joint::PRISMATIC: return "prismatic";
    case urdf::Joint::FLOATING: return "floating";
    case urdf::Joint::PLANAR: return "planar";
    case urdf::Joint::FIXED: return "fixed";
    default: return "unknown";
  }
}

// <limit> into `joint`, every field checked. Placeholder limits (lower ==
// upper, effort == velocity == 0: a CAD exporter's "unknown") would lock the
// joint and give it no torque; they are read as "no limits", with a warning.
// A negative effort or velocity (-1: "unlimited" in some vendors' files) is
// read as no limit, with a warning: neither enters the dynamics.
void readLimits(const Reporter& report, const urdf::Joint& uj, Joint& joint, std::vector<ModelWarning>& warnings) {
  const std::string who = "joint '" + uj.name + "'";
  const urdf::JointLimits& lim = *uj.limits;
  const struct {
    const char* name;
    double value;
  } fields[] = {{"lower", lim.lower}, {"upper", lim.upper}, {"effort", lim.effort}, {"velocity", lim.velocity}};
  for (const auto& f : fields)
    if (!std::isfinite(f.value)) report.fail(who + ": <limit> " + f.name + " is not finite");
  if (lim.effort < 0.0 || lim.velocity < 0.0) {
    const bool both = lim.effort < 0.0 && lim.velocity < 0.0;
    const std::string given = both               ? "effort " + fmt(lim.effort) + " and velocity " + fmt(lim.velocity)
                              : lim.effort < 0.0 ? "effort " + fmt(lim.effort)
                                                 : "velocity " + fmt(lim.velocity);
    const std::string read = both               ? "no effort and no velocity limit"
                             : lim.effort < 0.0 ? "no effort limit"
                                                : "no velocity limit";
    warnings.push_back({WarningCode::PlaceholderLimits, who + ": <limit> " + given + (both ? " are" : " is") +
                                                            " negative: read as " + read +
                                                            " (how some files write \"unlimited\")"});
  }
  if (lim.lower == lim.upper && lim.effort == 0.0 && lim.velocity == 0.0) {
    warnings.push_back({WarningCode::PlaceholderLimits,
                        who + ": placeholder <limit lower=\"" + fmt(lim.lower) + "\" upper=\"" + fmt(lim.upper) +
                            "\" effort=\"0\" velocity=\"0\"/> read as no limits (position, effort and velocity)"});
    return;  // Joint's defaults are infinite
  }
  if (lim.effort >= 0.0) joint.effort_limit = lim.effort;  // else Joint's default, infinite
  if (lim.velocity >= 0.0) joint.velocity_limit = lim.velocity;
  if (joint.type == JointType::Continuous) return;  // a continuous joint has no position limits
  if (lim.lower > lim.upper)
    report.fail(who + ": <limit> lower " + fmt(lim.lower) + " is greater than upper " + fmt(lim.upper));
  joint.lower = lim.lower;
  joint.upper = lim.upper;
}

// The rotation that turns a URDF planar joint's frame so that its z is the
// joint's <axis> (unit): the shortest one, about z × axis (a half turn about x
// for −z). Its x and y span the plane of motion.
Mat3 planeRotation(const Vec3& axis) {
  if (axis == Vec3::UnitZ()) return Mat3::Identity();
  if (axis.x() == 0.0 && axis.y() == 0.0) return Vec3(1.0, -1.0, -1.0).asDiagonal();  // −z: half turn about x
  return Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), axis).toRotationMatrix();
}

// A planar joint's frame turned so that its z is the plane's normal `axis`
// (unit): planeRotation applied to the joint's <origin>.
Transform planeFrameOf(const Vec3& axis, const Transform& origin) {
  return Transform::rotation(planeRotation(axis)) * origin;
}

// A joint's <axis>, made unit; refused when not finite or zero (`meaning`:
// what the axis must give, for the message).
Vec3 unitAxisOf(const Reporter& report, const urdf::Joint& uj, const std::string& who, const char* meaning) {
  const Vec3 axis = vectorOf(uj.axis);
  if (!axis.allFinite()) report.fail(who + ": <axis> xyz is not finite");
  if (axis.norm() < 1e-9)
    report.fail(who + ": <axis> xyz \"" + fmt(uj.axis.x) + " " + fmt(uj.axis.y) + " " + fmt(uj.axis.z) +
                "\" is zero (it must give " + meaning + ")");
  return axis.normalized();
}

// A joint's <origin>; refused when not finite.
Transform checkedPlacementOf(const Reporter& report, const urdf::Joint& uj, const std::string& who) {
  const Transform origin = placementOf(uj);
  if (!origin.E.allFinite() || !origin.r.allFinite()) report.fail(who + ": <origin> is not finite");
  return origin;
}

// The child link's frame relative to the zwang joint's child frame, ᶜX_body:
// identity except for a planar joint whose axis is not z (planeRotation turns
// the joint frame, the link keeps the URDF's orientation).
Transform linkPlacementOf(const urdf::Joint& uj) {
  if (uj.type != urdf::Joint::PLANAR) return Transform{};
  const Vec3 axis = vectorOf(uj.axis);
  if (!axis.allFinite() || axis.norm() < 1e-9) return Transform{};  // makeJoint refuses it
  return Transform::rotation(planeRotation(axis.normalized()).transpose());
}

// The zwang joint for a moving URDF joint, every field checked. A floating
// joint is a Free joint, a planar one a Planar joint whose frame is turned so
// that its z is the URDF <axis> (the plane's normal; linkPlacementOf).
Joint makeJoint(const Reporter& report, const urdf::Joint& uj, const std::map<std::string, double>& rotor,
                std::vector<ModelWarning>& warnings) {
  const std::string who = "joint '" + uj.name + "'";
  Joint joint;
  joint.name = uj.name;
  switch (uj.type) {
    case urdf::Joint::REVOLUTE: joint.type = JointType::Revolute; break;
    case urdf::Joint::CONTINUOUS: joint.type = JointType::Continuous; break;
    case urdf::Joint::PRISMATIC: joint.type = JointType::Prismatic; break;
    case urdf::Joint::FLOATING: joint.type = JointType::Free; break;
    case urdf::Joint::PLANAR: joint.type = JointType::Planar; break;
    default:
      report.fail(who + " (parent '" + uj.parent_link_name + "', child '" + uj.child_link_name + "'): type " +
                  typeName(uj.type) +
                  " is not supported (only revolute, continuous, prismatic, planar, floating and fixed joints are)");
  }

  joint.placement = checkedPlacementOf(report, uj, who);
  if (joint.type == JointType::Planar)
    joint.placement = planeFrameOf(unitAxisOf(report, uj, who, "the joint's direction, here the normal of the plane"),
                                   joint.placement);
  else if (joint.type != JointType::Free)  // urdfdom reads no axis for a floating joint
    joint.axis = unitAxisOf(report, uj, who, "the joint's direction");

  if (joint.nv() > 1) {
    // A <limit> cannot say which of the joint's coordinates it bounds (and
    // mixes forces and torques): read as none, as other loaders do, but said.
    if (uj.limits)
      warnings.push_back(
          {WarningCode::IgnoredLimits, who + ": <limit> on a " + typeName(uj.type) + " joint ignored (lower " +
                                           fmt(uj.limits->lower) + ", upper " + fmt(uj.limits->upper) + ", effort " +
                                           fmt(uj.limits->effort) + ", velocity " + fmt(uj.limits->velocity) +
                                           "): zwang's multi-DOF joints have no position, effort or velocity limits"});
  } else {
    if (uj.limits) readLimits(report, uj, joint, warnings);
    if (joint.type == JointType::Continuous) {
      joint.lower = -kInf;
      joint.upper = kInf;
    }
  }

  if (uj.dynamics) {
    const urdf::JointDynamics& dyn = *uj.dynamics;
    if (!std::isfinite(dyn.friction)) report.fail(who + ": <dynamics> friction is not finite");
    if (!std::isfinite(dyn.damping)) report.fail(who + ": <dynamics> damping is not finite");
    if (dyn.friction < 0.0) report.fail(who + ": <dynamics> friction " + fmt(dyn.friction) + " is negative");
    if (dyn.damping < 0.0) report.fail(who + ": <dynamics> damping " + fmt(dyn.damping) + " is negative");
    joint.breakaway_friction = dyn.friction;
    joint.kinetic_friction = dyn.friction;  // default f_c = f: docs/friction.md, "The model of friction"
    joint.viscous_friction = dyn.damping;   // URDF calls the viscous coefficient "damping"
  }

  const auto r = rotor.find(uj.name);
  if (r != rotor.end()) joint.rotor_inertia = r->second;
  return joint;
}

// ---------------------------------------------------------------------------
// Mimic joints

using LinkPtr = urdf::LinkConstSharedPtr;

// A moving joint that MimicJoints::Lock welds: it is not a degree of freedom.
bool isLockedMimic(const urdf::Joint& joint, const NamedUrdfOptions& options) {
  return isMoving(joint) && joint.mimic && options.mimic == MimicJoints::Lock;
}

// A joint that becomes a joint of the model (moving, and not locked).
bool isDegreeOfFreedom(const urdf::Joint& joint, const NamedUrdfOptions& options) {
  return isMoving(joint) && !isLockedMimic(joint, options);
}

std::string mimicLaw(const urdf::Joint& uj) {
  return "q = " + fmt(uj.mimic->multiplier) + "·q_" + uj.mimic->joint_name + " + " + fmt(uj.mimic->offset);
}

// Where a locked mimic joint is welded: locked_positions[joint], else the
// position its leader at rest implies, multiplier · q_leader + offset with
// q_leader = locked_positions[leader] (default 0).
double mimicLockPosition(const Reporter& report, const urdf::Joint& uj, const NamedUrdfOptions& options) {
  if (const auto given = options.locked_positions.find(uj.name); given != options.locked_positions.end())
    return given->second;
  const auto leader = options.locked_positions.find(uj.mimic->joint_name);
  const double q_leader = leader == options.locked_positions.end() ? 0.0 : leader->second;
  const double q = uj.mimic->multiplier * q_leader + uj.mimic->offset;
  if (!std::isfinite(q))
    report.fail("joint '" + uj.name + "' (" + mimicLaw(uj) + "): the position to lock it at is not finite");
  return q;
}

// A <mimic> joint follows its leader (q = a·q_leader + b); the caller asked
// for none (MimicJoints::Refuse): refused, with the ways around it.
// `chain_before` is the link before it on a chain (empty in a tree).
[[noreturn]] void refuseMimic(const Reporter& report, const urdf::Joint& uj, const NamedUrdfOptions& options,
                              const std::string& chain_before) {
  const std::string lock = options.names.lock_mimic +
                           " to weld it at q = " + fmt(mimicLockPosition(report, uj, options)) +
                           " (its position when '" + uj.mimic->joint_name + "' is at rest)";
  if (!chain_before.empty())
    report.fail("joint '" + uj.name + "' on the chain mimics joint '" + uj.mimic->joint_name + "' (" + mimicLaw(uj) +
                "): refused (" + options.names.refuse_mimic + "); choose a " + options.names.tip +
                " before it (e.g. '" + chain_before + "') or set " + lock);
  report.fail("joint '" + uj.name + "' mimics joint '" + uj.mimic->joint_name + "' (" + mimicLaw(uj) + "): refused (" +
              options.names.refuse_mimic + "); model it (the default), set " + lock + ", or choose a " +
              options.names.tip + " for a chain without it");
}

// A note on a locked mimic joint (MimicLocked, which strict mode lets pass).
ModelWarning mimicLockedNote(const urdf::Joint& uj, double q, const NamedUrdfOptions& options) {
  return {WarningCode::MimicLocked, "joint '" + uj.name + "' mimics joint '" + uj.mimic->joint_name + "' (" +
                                        mimicLaw(uj) + "): locked at q = " + fmt(q) + " (" + options.names.lock_mimic +
                                        "), link '" + uj.child_link_name + "' welded to link '" + uj.parent_link_name +
                                        "'"};
}

// ᶜX_p of a joint locked at position q (revolute and continuous turn about the
// axis, prismatic slides along it). A floating or planar joint is locked at
// its origin: one number cannot place it, so any other is refused.
Transform lockedPlacement(const Reporter& report, const urdf::Joint& uj, double q) {
  if ((uj.type == urdf::Joint::FLOATING || uj.type == urdf::Joint::PLANAR) && q != 0.0)
    report.fail("joint '" + uj.name + "': a " + typeName(uj.type) + " joint cannot be locked at q = " + fmt(q) +
                " (one number cannot place it); it is locked at its origin: give it no locked position");
  if (q == 0.0 ||
      (uj.type != urdf::Joint::REVOLUTE && uj.type != urdf::Joint::CONTINUOUS && uj.type != urdf::Joint::PRISMATIC))
    return placementOf(uj);
  std::vector<ModelWarning> ignored;
  const Joint joint = makeJoint(report, uj, {}, ignored);
  return joint.transform(q);
}

// ---------------------------------------------------------------------------
// Choosing what to load: a chain, or the whole tree below the root

// The links of the subtree below `root` (root first, parents before children).
std::vector<LinkPtr> subtreeLinks(const LinkPtr& root) {
  std::vector<LinkPtr> links{root};
  for (std::size_t head = 0; head < links.size(); ++head)
    for (const auto& child : links[head]->child_links) links.push_back(child);
  return links;
}

// Whether some link below `root` has two or more children that lead to moving
// joints: then the subtree is a tree, not a chain.
bool branchesIntoMovingJoints(const LinkPtr& root) {
  const std::vector<LinkPtr> links = subtreeLinks(root);
  std::map<const urdf::Link*, bool> moving_below;             // a moving joint at or below the link's child joints
  for (auto it = links.rbegin(); it != links.rend(); ++it) {  // children before parents
    const urdf::Link& link = **it;
    int leading = 0;
    for (std::size_t k = 0; k < link.child_joints.size(); ++k)
      leading += isMoving(*link.child_joints[k]) || moving_below[link.child_links[k].get()] ? 1 : 0;
    if (leading > 1) return true;
    moving_below[&link] = leading > 0;
  }
  return false;
}

// The links from root to tip (root first). No tip: the unique leaf of the
// branch that leads to moving joints (only called when there is one).
std::vector<LinkPtr> chainLinks(const Reporter& report, const urdf::ModelInterface& model, const LinkPtr& root,
                                const std::string& tip_name) {
  std::vector<LinkPtr> path;
  if (!tip_name.empty()) {
    const LinkPtr tip = model.getLink(tip_name);
    for (LinkPtr link = tip; link; link = link->getParent()) {
      path.push_back(link);
      if (link == root) {
        std::reverse(path.begin(), path.end());
        return path;
      }
    }
    report.fail("tip link '" + tip_name + "' is not below root link '" + root->name + "' (its ancestors: " + [&] {
      std::vector<std::string> names;
      for (std::size_t k = 1; k < path.size(); ++k) names.push_back(path[k]->name);
      return names.empty() ? std::string("none") : nameList(names);
    }() + ")");
  }
  // No tip: follow the single branch that leads to moving joints.
  const std::vector<LinkPtr> links = subtreeLinks(root);
  std::set<const urdf::Link*> moving_below;
  for (auto it = links.rbegin(); it != links.rend(); ++it)
    for (std::size_t k = 0; k < (*it)->child_joints.size(); ++k)
      if (isMoving(*(*it)->child_joints[k]) || moving_below.count((*it)->child_links[k].get()))
        moving_below.insert(it->get());
  LinkPtr link = root;
  path.push_back(link);
  for (;;) {
    LinkPtr next;
    for (std::size_t k = 0; k < link->child_joints.size() && !next; ++k)
      if (isMoving(*link->child_joints[k]) || moving_below.count(link->child_links[k].get()))
        next = link->child_links[k];
    if (!next) return path;
    link = next;
    path.push_back(link);
  }
}

std::vector<std::string> allLinkNames(const urdf::ModelInterface& model) {
  std::vector<std::string> names;
  for (const auto& entry : model.links_) names.push_back(entry.first);
  return names;
}

// ---------------------------------------------------------------------------

// Pass 1: well-formed XML with a <robot> on top.
const TiXmlElement* parseXml(const Reporter& report, const std::string& xml, TiXmlDocument& doc) {
  doc.Parse(xml.c_str());
  if (doc.Error()) {
    std::string where;
    if (doc.ErrorRow() > 0)
      where = " at line " + std::to_string(doc.ErrorRow()) + ", column " + std::to_string(doc.ErrorCol());
    report.fail("malformed XML" + where + ": " + doc.ErrorDesc());
  }
  const TiXmlElement* robot = doc.RootElement();
  if (robot == nullptr || std::string(robot->Value()) != "robot")
    report.fail("the XML's top element is not <robot>" +
                (robot ? std::string(" (found <") + robot->Value() + ">)" : std::string()));
  return robot;
}

// zwang needs a joint that moves somewhere; say so before any root/tip
// reasoning (a floating or planar joint counts here: the chain check names it).
void requireMovingJoint(const Reporter& report, const urdf::ModelInterface& model) {
  for (const auto& entry : model.joints_)
    if (entry.second->type != urdf::Joint::FIXED) return;
  report.fail("the URDF has no moving joint (" +
              (model.joints_.empty() ? std::string("it has no joint at all")
                                     : "all " + std::to_string(model.joints_.size()) + " joints are fixed") +
              "): zwang needs at least one revolute, continuous or prismatic joint");
}

std::map<std::string, double> rotorInertias(const Reporter& report, const TiXmlElement* robot,
                                            const urdf::ModelInterface& urdf_model, const NamedUrdfOptions& options) {
  std::map<std::string, double> rotor = readTransmissions(report, robot, urdf_model);
  for (const auto& [name, value] : options.rotor_inertia) {
    if (!std::isfinite(value) || value < 0.0)
      report.fail(options.names.rotor_inertia + " for joint '" + name + "': " + fmt(value) +
                  " is not a finite non-negative number");
    rotor[name] = value;
  }
  return rotor;
}

// Every rotor_inertia override names a joint of the model (`moving`, described by `what`).
void checkRotorNames(const Reporter& report, const urdf::ModelInterface& urdf_model, const NamedUrdfOptions& options,
                     const std::vector<std::string>& moving, const std::string& what) {
  for (const auto& entry : options.rotor_inertia) {
    if (std::find(moving.begin(), moving.end(), entry.first) != moving.end()) continue;
    report.fail(
        options.names.rotor_inertia + " names joint '" + entry.first + "', which is not a moving joint of " + what +
        " (its joints: " + nameList(moving) + ")" +
        (urdf_model.getJoint(entry.first) ? std::string() : std::string("; the URDF has no joint of that name")));
  }
}

// Each loaded mimic joint follows its leader (MimicJoints::Model), which must
// be a loaded moving joint too: a coupling to a joint outside the model
// cannot be kept, and dropping it would be a silent wrong answer.
void addMimicLaws(const Reporter& report, const urdf::ModelInterface& urdf_model, const NamedUrdfOptions& options,
                  const std::vector<std::string>& moving, const std::string& what, ModelBuilder& builder) {
  if (options.mimic != MimicJoints::Model) return;
  for (const std::string& name : moving) {
    const urdf::Joint& uj = *urdf_model.getJoint(name);
    if (!uj.mimic) continue;
    const std::string& leader = uj.mimic->joint_name;
    const std::string who = "joint '" + name + "' (" + mimicLaw(uj) + ") mimics joint '" + leader + "'";
    const urdf::JointConstSharedPtr leader_joint = urdf_model.getJoint(leader);
    const auto lock = [&] {  // only on the error path: the position may not be finite
      return ": set " + options.names.lock_mimic + " to weld it at q = " + fmt(mimicLockPosition(report, uj, options)) +
             " (its position when '" + leader + "' is at rest)";
    };
    if (!leader_joint) report.fail(who + ", which the URDF does not have" + lock());
    if (!isMoving(*leader_joint))
      report.fail(who + ", which is not a moving joint (a fixed, floating or planar joint)" + lock());
    if (std::find(moving.begin(), moving.end(), leader) == moving.end())
      report.fail(who + ", which is not in " + what + ": load a tree or chain that holds both, or set " +
                  options.names.lock_mimic);
    report.builder([&] { builder.setMimic(name, leader, uj.mimic->multiplier, uj.mimic->offset); });
  }
}

// Links placed into the builder, and the ones on the last body (the tip body).
struct Placement {
  bool base_floats = false;  // a free or planar base: the links welded to the base move and are judged
  std::set<std::string> placed;
  std::vector<LinkPtr> tip_body;
  std::vector<std::string> locked_mimic;  // mimic joints welded by MimicJoints::Lock
  std::vector<ModelWarning> warnings;     // the loader's own (limits, beyond the tip, locks, urdfdom)
};

// Every link welded to `anchor` (down, and up off the root), breadth first.
// `down_from_anchor` false: only what is welded above the anchor (and hangs
// off those links), the anchor's own subtree being loaded otherwise.
void addWelded(const Reporter& report, ModelBuilder& builder, Placement& placement, const LinkPtr& anchor, bool on_base,
               bool down_from_anchor = true) {
  std::vector<LinkPtr> queue{anchor};
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const LinkPtr from = queue[head];
    for (std::size_t k = 0; k < from->child_joints.size() && (head > 0 || down_from_anchor); ++k) {
      const auto& joint = from->child_joints[k];
      const LinkPtr child = from->child_links[k];
      if (isMoving(*joint) || placement.placed.count(child->name)) continue;
      const RigidInertia inertia = linkInertia(report, *child, on_base);
      report.builder([&] { builder.addFixedFrame(child->name, from->name, placementOf(*joint), inertia); });
      placement.placed.insert(child->name);
      placement.tip_body.push_back(child);
      queue.push_back(child);
    }
    // Upwards: a parent welded to this link (only ever off the root).
    const LinkPtr parent = from->getParent();
    if (parent && from->parent_joint && !isMoving(*from->parent_joint) && !placement.placed.count(parent->name)) {
      const RigidInertia inertia = linkInertia(report, *parent, on_base);
      const Transform X = placementOf(*from->parent_joint).inverse();  // ᵖX_from
      report.builder([&] { builder.addFixedFrame(parent->name, from->name, X, inertia); });
      placement.placed.insert(parent->name);
      queue.push_back(parent);
    }
  }
}

// A mimic joint welded by MimicJoints::Lock: its child link becomes a frame of the parent's body.
void addLockedMimic(const Reporter& report, ModelBuilder& builder, Placement& placement, const urdf::Joint& uj,
                    const urdf::Link& child, bool on_base, const NamedUrdfOptions& options) {
  const double q = mimicLockPosition(report, uj, options);
  const Transform X = lockedPlacement(report, uj, q);
  const RigidInertia inertia = linkInertia(report, child, on_base);
  report.builder([&] { builder.addFixedFrame(child.name, uj.parent_link_name, X, inertia); });
  placement.locked_mimic.push_back(uj.name);
  placement.warnings.push_back(mimicLockedNote(uj, q, options));
}

// The chain links in order; after each, the links welded to it.
void addChain(const Reporter& report, ModelBuilder& builder, Placement& placement, const std::vector<LinkPtr>& chain,
              const std::map<std::string, double>& rotor, const NamedUrdfOptions& options) {
  for (const LinkPtr& link : chain) placement.placed.insert(link->name);
  bool on_base = !placement.base_floats;  // until the first moving joint (a floating base moves: never)
  placement.tip_body = {chain.front()};
  addWelded(report, builder, placement, chain.front(), on_base);
  for (std::size_t k = 1; k < chain.size(); ++k) {
    const LinkPtr& link = chain[k];
    const urdf::Joint& uj = *link->parent_joint;
    if (isDegreeOfFreedom(uj, options)) {
      on_base = false;
      placement.tip_body.clear();
      const Joint joint = makeJoint(report, uj, rotor, placement.warnings);
      const RigidInertia inertia = linkInertia(report, *link, on_base);
      report.builder([&] { builder.addJoint(joint, link->name, inertia, uj.parent_link_name, linkPlacementOf(uj)); });
    } else if (isLockedMimic(uj, options)) {
      addLockedMimic(report, builder, placement, uj, *link, on_base, options);
    } else {
      const RigidInertia inertia = linkInertia(report, *link, on_base);
      report.builder([&] { builder.addFixedFrame(link->name, uj.parent_link_name, placementOf(uj), inertia); });
    }
    placement.tip_body.push_back(link);
    addWelded(report, builder, placement, link, on_base);
  }
}

// The whole tree below `root`: depth first over the links, each link's
// children in the byte-wise order of their joints' names (urdfdom's own
// order, made explicit here), so that every moving joint's parent body is the
// last body added or one of its ancestors (ModelBuilder::addJoint). Before it,
// the links welded above the root. Explicit stack: no recursion, whatever the depth.
void addTree(const Reporter& report, ModelBuilder& builder, Placement& placement, const LinkPtr& root,
             const std::map<std::string, double>& rotor, const NamedUrdfOptions& options,
             std::vector<std::string>& moving) {
  placement.placed.insert(root->name);
  addWelded(report, builder, placement, root, !placement.base_floats, false);
  struct Pending {
    urdf::JointConstSharedPtr joint;
    LinkPtr child;
    bool parent_on_base;
  };
  std::vector<Pending> stack;
  const auto pushChildren = [&stack](const urdf::Link& link, bool on_base) {
    std::vector<std::size_t> order(link.child_joints.size());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
    std::sort(order.begin(), order.end(), [&link](std::size_t a, std::size_t b) {
      return link.child_joints[a]->name < link.child_joints[b]->name;
    });
    for (auto k = order.rbegin(); k != order.rend(); ++k)
      stack.push_back({link.child_joints[*k], link.child_links[*k], on_base});
  };
  pushChildren(*root, !placement.base_floats);
  while (!stack.empty()) {
    const Pending next = stack.back();
    stack.pop_back();
    const urdf::Joint& uj = *next.joint;
    const urdf::Link& child = *next.child;
    bool on_base = next.parent_on_base;
    if (isMoving(uj) && uj.mimic && options.mimic == MimicJoints::Refuse) refuseMimic(report, uj, options, "");
    if (isDegreeOfFreedom(uj, options)) {
      on_base = false;
      const Joint joint = makeJoint(report, uj, rotor, placement.warnings);
      const RigidInertia inertia = linkInertia(report, child, on_base);
      report.builder([&] { builder.addJoint(joint, child.name, inertia, uj.parent_link_name, linkPlacementOf(uj)); });
      moving.push_back(uj.name);
    } else if (isLockedMimic(uj, options)) {
      addLockedMimic(report, builder, placement, uj, child, on_base, options);
    } else {
      const RigidInertia inertia = linkInertia(report, child, on_base);
      report.builder([&] { builder.addFixedFrame(child.name, uj.parent_link_name, placementOf(uj), inertia); });
    }
    placement.placed.insert(child.name);
    pushChildren(child, on_base);
  }
}

// Whether a link moves with the chain: a moving joint lies between it and the
// chain's root (a branch off the fixed base never affects the dynamics), or
// the base floats (a branch off a floating base rides on it).
bool movesWithChain(const LinkPtr& link, const std::string& root, const NamedUrdfOptions& options, bool base_floats) {
  if (base_floats) return true;
  for (LinkPtr l = link; l && l->name != root; l = l->getParent())
    if (l->parent_joint && isDegreeOfFreedom(*l->parent_joint, options)) return true;
  return false;
}

// Links behind a moving joint that leaves the chain above the tip body (a
// side branch off a moving body, e.g. the other finger of a gripper) are not
// in the model, though they would ride on it: say how much mass that is, as
// for the mass beyond the tip.
void warnMassOffChain(Placement& placement, const urdf::ModelInterface& model, const std::string& root,
                      const NamedUrdfOptions& options) {
  std::set<std::string> tip_body;
  for (const LinkPtr& link : placement.tip_body) tip_body.insert(link->name);
  std::vector<std::string> joints, links;
  double mass = 0.0;
  std::vector<LinkPtr> queue;
  for (const std::string& name : placement.placed) {
    if (tip_body.count(name)) continue;  // below the tip body: handleBeyondTip's business
    const LinkPtr link = model.getLink(name);
    if (!movesWithChain(link, root, options, placement.base_floats)) continue;
    for (std::size_t k = 0; k < link->child_joints.size(); ++k)
      if (isMoving(*link->child_joints[k]) && !placement.placed.count(link->child_links[k]->name)) {
        joints.push_back(link->child_joints[k]->name);
        queue.push_back(link->child_links[k]);
      }
  }
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const LinkPtr link = queue[head];
    links.push_back(link->name);
    if (link->inertial && std::isfinite(link->inertial->mass)) mass += link->inertial->mass;
    for (const auto& child : link->child_links) queue.push_back(child);
  }
  if (mass <= 0.0) return;
  placement.warnings.push_back(
      {WarningCode::MassOffChain, std::to_string(links.size()) + (links.size() == 1 ? " link (" : " links (") +
                                      nameList(links) + ", " + fmt(mass) + " kg in all) behind moving joint" +
                                      (joints.size() == 1 ? " " : "s ") + nameList(joints) +
                                      " off the chain (side branches) are not in the model: their mass is ignored"});
}

// Links behind moving joints below the tip body: the joint that leads to each
// and the links, parents before children.
struct BeyondTip {
  std::vector<std::pair<urdf::JointConstSharedPtr, LinkPtr>> links;
  double mass = 0.0;
};

BeyondTip findBeyondTip(const Placement& placement) {
  BeyondTip beyond;
  std::vector<std::pair<urdf::JointConstSharedPtr, LinkPtr>> queue;
  for (const LinkPtr& link : placement.tip_body)
    for (std::size_t k = 0; k < link->child_joints.size(); ++k)
      if (isMoving(*link->child_joints[k]) && !placement.placed.count(link->child_links[k]->name))
        queue.emplace_back(link->child_joints[k], link->child_links[k]);
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const LinkPtr link = queue[head].second;
    beyond.links.push_back(queue[head]);
    if (link->inertial && std::isfinite(link->inertial->mass)) beyond.mass += link->inertial->mass;
    for (std::size_t k = 0; k < link->child_joints.size(); ++k)
      queue.emplace_back(link->child_joints[k], link->child_links[k]);
  }
  return beyond;
}

// Every locked_positions entry names a joint that was locked (`beyond`: the
// moving joints beyond the tip, empty for a tree; and the locked mimic joints).
void checkLockedPositions(const Reporter& report, const NamedUrdfOptions& options,
                          const std::vector<std::string>& beyond, const std::vector<std::string>& mimic, bool chain) {
  for (const auto& [name, q] : options.locked_positions) {
    const bool known = std::find(beyond.begin(), beyond.end(), name) != beyond.end() ||
                       std::find(mimic.begin(), mimic.end(), name) != mimic.end();
    if (known && std::isfinite(q)) continue;
    const auto list = [](const std::vector<std::string>& names) {
      return names.empty() ? std::string("none") : nameList(names);
    };
    const std::string head = "locked position for joint '" + name + "' (" + fmt(q) + "): not a finite position of ";
    if (chain && mimic.empty())
      report.fail(head + "a moving joint beyond the tip (those joints: " + list(beyond) + ")");
    if (!chain) report.fail(head + "a locked mimic joint (those joints: " + list(mimic) + ")");
    report.fail(head + "a locked joint (moving joints beyond the tip: " + list(beyond) +
                "; locked mimic joints: " + list(mimic) + ")");
  }
}

// Report the mass beyond the tip, or weld it to the tip body as a payload.
void handleBeyondTip(const Reporter& report, ModelBuilder& builder, Placement& placement, const std::string& tip,
                     const NamedUrdfOptions& options) {
  const BeyondTip beyond = findBeyondTip(placement);
  std::vector<std::string> links, joints;
  for (const auto& [joint, link] : beyond.links) {
    links.push_back(link->name);
    if (isMoving(*joint)) joints.push_back(joint->name);
  }
  checkLockedPositions(report, options, joints, placement.locked_mimic, true);
  if (beyond.links.empty() || (beyond.mass <= 0.0 && !options.attach_beyond_tip)) return;
  const std::string what = std::to_string(links.size()) + " link" + (links.size() == 1 ? "" : "s") + " (" +
                           nameList(links) + ", " + fmt(beyond.mass) + " kg in all) behind moving joint" +
                           (joints.size() == 1 ? " " : "s ") + nameList(joints) + " beyond the tip '" + tip + "'";
  if (!options.attach_beyond_tip) {
    const char* verb = links.size() == 1 ? " is" : " are";
    placement.warnings.push_back({WarningCode::MassBeyondTip, what + verb +
                                                                  " not on the chain: their mass is ignored (set " +
                                                                  options.names.attach_beyond_tip +
                                                                  " to carry them as a payload of the tip body)"});
    return;
  }
  for (const auto& [joint, link] : beyond.links) {
    const auto locked = options.locked_positions.find(joint->name);
    const double q = locked != options.locked_positions.end() ? locked->second
                     : isMoving(*joint) && joint->mimic       ? mimicLockPosition(report, *joint, options)
                                                              : 0.0;
    const Transform X = lockedPlacement(report, *joint, q);
    const RigidInertia inertia = linkInertia(report, *link, false);
    const std::string& name = link->name;  // clang 14: a lambda cannot capture structured bindings
    const std::string& parent = joint->parent_link_name;
    report.builder([&] { builder.addFixedFrame(name, parent, X, inertia); });
  }
  placement.warnings.push_back(
      {WarningCode::PayloadAttached,
       what + (links.size() == 1 ? " is" : " are") + " welded to the tip body as a payload, those joints locked"});
}

// ---------------------------------------------------------------------------
// The base: a floating or planar root joint in the file, or UrdfOptions::base

bool isMultiDof(const urdf::Joint& joint) {
  return joint.type == urdf::Joint::FLOATING || joint.type == urdf::Joint::PLANAR;
}

BaseType baseTypeOf(const urdf::Joint& joint) {
  return joint.type == urdf::Joint::FLOATING ? BaseType::Free : BaseType::Planar;
}

// The URDF's root joint: the only joint of the root link, when it is floating
// or planar (the "world → base_link" pattern). A floating or planar joint
// anywhere else is refused when it is loaded (makeJoint).
urdf::JointConstSharedPtr floatingRootJoint(const urdf::ModelInterface& model) {
  const LinkPtr root = model.getRoot();
  if (!root || root->child_joints.size() != 1 || !isMultiDof(*root->child_joints[0])) return nullptr;
  return root->child_joints[0];
}

// Where the model starts and how its base is attached. A floating root joint
// is used when the model starts at the URDF's root link or at the joint's
// child link; its child becomes the base, the links above it are the world.
struct BaseChoice {
  LinkPtr root;                     // the model's root link (the base)
  urdf::JointConstSharedPtr joint;  // the file's floating or planar root joint in use, if any
  BaseType type = BaseType::Fixed;  // the model's base
  Transform plane;                  // a planar base's plane, ᴾX_world
  Transform root_link;              // the root link's frame on its body, ᶜX_link (a turned plane's: linkPlacementOf)
};

// The plane of a planar root joint, ᴾX_world: the joint frame (its <origin>
// in the root link) turned as a planar joint's below the root (makeJoint), so
// that its z is the joint's <axis>, the plane's normal.
Transform planeOf(const Reporter& report, const urdf::Joint& uj) {
  const Vec3 axis = unitAxisOf(report, uj, "planar root joint '" + uj.name + "'", "the normal of the plane");
  return planeFrameOf(axis, checkedPlacementOf(report, uj, "joint '" + uj.name + "'"));
}

BaseChoice chooseBase(const Reporter& report, const urdf::ModelInterface& model, const NamedUrdfOptions& options) {
  BaseChoice choice;
  const LinkPtr file_root = model.getRoot();
  choice.root = options.root.empty() ? file_root : model.getLink(options.root);
  if (!choice.root)
    report.fail("root link '" + options.root + "' not found (links: " + nameList(allLinkNames(model)) + ")");
  const urdf::JointConstSharedPtr joint = floatingRootJoint(model);
  if (joint && (choice.root == file_root || choice.root->name == joint->child_link_name)) {
    const std::string who = std::string(typeName(joint->type)) + " root joint '" + joint->name + "' (from '" +
                            joint->parent_link_name + "' to '" + joint->child_link_name + "')";
    if (options.base != BaseType::Fixed && !options.base_may_match_file)
      report.fail("the URDF already has a " + who + ", a " + toString(baseTypeOf(*joint)) + " base; drop " +
                  options.names.base);
    if (options.base != BaseType::Fixed && options.base != baseTypeOf(*joint))
      report.fail("the URDF has a " + who + ", a " + toString(baseTypeOf(*joint)) + " base, not the " +
                  toString(options.base) + " base that " + options.names.base + " asks for");
    if (joint->dynamics && (joint->dynamics->friction != 0.0 || joint->dynamics->damping != 0.0))
      report.fail(who + ": <dynamics> friction " + fmt(joint->dynamics->friction) + ", damping " +
                  fmt(joint->dynamics->damping) + ": a floating base has no friction in zwang (remove them)");
    choice.root = model.getLink(joint->child_link_name);
    choice.joint = joint;
    choice.type = baseTypeOf(*joint);
    if (choice.type == BaseType::Planar) {
      choice.plane = planeOf(report, *joint);
      choice.root_link = linkPlacementOf(*joint);
    }
    return choice;
  }
  choice.type = options.base;
  return choice;
}

// The base's own inertia: the root link's <inertial>. A floating base moves it;
// on a fixed base it is only counted (Model::inertia(0), "base mass"): there
// an inertia that is not a body's is left out rather than refused, as nothing
// welded to a fixed base is judged.
void addRootLinkInertia(const Reporter& report, ModelBuilder& builder, const urdf::Link& root, bool base_floats) {
  const RigidInertia inertia = linkInertia(report, root, !base_floats);
  if (!base_floats) {
    try {
      (void)validate::rigidInertia("link '" + root.name + "'", inertia);
    } catch (const ModelError&) {
      return;
    }
  }
  report.builder([&] { builder.addBaseLinkInertia(inertia); });
}

// Strict mode: every warning about the data is an error. PayloadAttached and
// MimicLocked only report what the options asked for, so they do not count.
void refuseWarnings(const Reporter& report, const Model& model) {
  std::string all;
  std::size_t count = 0;
  for (const ModelWarning& w : model.warnings()) {
    if (w.code == WarningCode::PayloadAttached || w.code == WarningCode::MimicLocked) continue;
    all += (all.empty() ? "" : "; ") + w.message.substr(report.source().size() + 2);  // without the "<source>: " prefix
    ++count;
  }
  if (count > 0)
    report.fail("refused in strict mode (" + std::to_string(count) + " warning" + (count == 1 ? "" : "s") +
                "): " + all);
}

// A file without any <inertial> (a kinematics-only description) has no
// masses at all: say so once, rather than "zero mass" on its first leaf
// (ModelBuilder::build), unless rotor inertias alone give every joint of a
// fixed base something to move.
void requireInertialData(const Reporter& report, const TiXmlElement* robot, const std::vector<std::string>& moving,
                         const std::map<std::string, double>& rotor, bool base_floats) {
  for (const TiXmlElement* link = robot->FirstChildElement("link"); link; link = link->NextSiblingElement("link"))
    if (link->FirstChildElement("inertial")) return;
  const bool rotors_carry = !base_floats && std::all_of(moving.begin(), moving.end(), [&rotor](const std::string& j) {
    const auto r = rotor.find(j);
    return r != rotor.end() && r->second > 0.0;
  });
  if (rotors_carry) return;
  report.fail(
      "the URDF has no <inertial> element on any link: it describes the kinematics only (no masses, no inertias), "
      "and dynamics need them; use a description of the robot with its inertial data");
}

// The chain from `root` to the tip (options.tip, or the unique leaf of a tree
// that does not branch into moving joints).
void loadChain(const Reporter& report, const urdf::ModelInterface& urdf_model, const TiXmlElement* robot,
               const LinkPtr& root, const std::map<std::string, double>& rotor, const NamedUrdfOptions& options,
               ModelBuilder& builder, Placement& placement) {
  const std::vector<LinkPtr> chain = chainLinks(report, urdf_model, root, options.tip);
  const std::string tip_name = chain.back()->name;
  std::vector<std::string> moving;  // moving joints of the chain
  std::size_t locked = 0;
  for (std::size_t k = 1; k < chain.size(); ++k) {
    const urdf::Joint& uj = *chain[k]->parent_joint;
    if (isMoving(uj) && uj.mimic && options.mimic == MimicJoints::Refuse)
      refuseMimic(report, uj, options, chain[k - 1]->name);
    if (isDegreeOfFreedom(uj, options)) moving.push_back(uj.name);
    if (isLockedMimic(uj, options)) ++locked;
  }
  if (moving.empty() && !placement.base_floats)  // a floating base alone is a rigid body: fine
    report.fail("the chain from root link '" + root->name + "' to tip link '" + tip_name + "' has no moving joint" +
                (locked ? " (its mimic joints are locked)" : ""));
  checkRotorNames(report, urdf_model, options, moving, "the chain from '" + root->name + "' to '" + tip_name + "'");
  requireInertialData(report, robot, moving, rotor, placement.base_floats);
  addChain(report, builder, placement, chain, rotor, options);
  addMimicLaws(report, urdf_model, options, moving, "the chain from '" + root->name + "' to '" + tip_name + "'",
               builder);
  handleBeyondTip(report, builder, placement, tip_name, options);
  warnMassOffChain(placement, urdf_model, root->name, options);
}

// The whole tree below `root` (no tip, and it branches into moving joints).
void loadTree(const Reporter& report, const urdf::ModelInterface& urdf_model, const TiXmlElement* robot,
              const LinkPtr& root, const std::map<std::string, double>& rotor, const NamedUrdfOptions& options,
              ModelBuilder& builder, Placement& placement) {
  std::vector<std::string> moving;
  addTree(report, builder, placement, root, rotor, options, moving);
  if (moving.empty() && !placement.base_floats)
    report.fail("the tree below root link '" + root->name + "' has no moving joint (its mimic joints are locked)");
  checkRotorNames(report, urdf_model, options, moving, "the tree below '" + root->name + "'");
  requireInertialData(report, robot, moving, rotor, placement.base_floats);
  addMimicLaws(report, urdf_model, options, moving, "the tree below '" + root->name + "'", builder);
  checkLockedPositions(report, options, {}, placement.locked_mimic, false);
}

Model load(const Reporter& report, const std::string& text, const NamedUrdfOptions& options) {
  // TinyXML 2.6 (what urdfdom parses with) trusts a UTF-8 lead byte's length:
  // a text that ends inside a multi-byte name makes it step over the final
  // NUL and read on into whatever memory follows (fuzz_urdf's case). Both
  // parsers stop at the first NUL, so eight more of them (the longest step is
  // four bytes) give the same parse and keep every read inside this string.
  const std::string xml = text + std::string(8, '\0');
  TiXmlDocument doc;
  const TiXmlElement* robot = parseXml(report, xml, doc);
  checkAllNumbers(report, robot);  // every number finite, anywhere

  Placement placement;
  const urdf::ModelInterfaceSharedPtr urdf_model = parseWithUrdfdom(report, robot, xml, placement.warnings);
  if (!urdf_model->getRoot()) report.fail("the URDF has no root link");
  if (options.base == BaseType::Fixed) requireMovingJoint(report, *urdf_model);  // a floating body needs none
  const std::map<std::string, double> rotor = rotorInertias(report, robot, *urdf_model, options);

  const BaseChoice base = chooseBase(report, *urdf_model, options);
  const LinkPtr root = base.root;
  if (!options.tip.empty() && !urdf_model->getLink(options.tip))
    report.fail("tip link '" + options.tip + "' not found (links: " + nameList(allLinkNames(*urdf_model)) + ")");

  ModelBuilder builder(urdf_model->getName(), root->name);
  placement.base_floats = base.type != BaseType::Fixed;
  if (placement.base_floats) report.builder([&] { builder.setBase(base.type, base.plane, base.root_link); });
  addRootLinkInertia(report, builder, *root, placement.base_floats);
  if (options.tip.empty() && branchesIntoMovingJoints(root))
    loadTree(report, *urdf_model, robot, root, rotor, options, builder, placement);
  else
    loadChain(report, *urdf_model, robot, root, rotor, options, builder, placement);
  for (const ModelWarning& w : placement.warnings) builder.addWarning(w.code, w.message);
  builder.prefixWarnings(report.source() + ": ");
  Model model;
  report.builder([&] { model = builder.build(); });
  if (options.strict) refuseWarnings(report, model);
  return model;
}

}  // namespace

Model internal::loadUrdfString(const std::string& xml, const internal::NamedUrdfOptions& options) {
  return load(Reporter("<string>"), xml, options);
}

Model internal::loadUrdfFile(const std::string& path, const internal::NamedUrdfOptions& options) {
  const Reporter report(path);
  std::ifstream in = report.open();
  std::ostringstream content;
  content << in.rdbuf();
  if (in.bad()) report.fail("cannot read the file");
  return load(report, content.str(), options);
}

// Without names: the messages name the options as UrdfOptions spells them.
Model loadUrdfString(const std::string& xml, const UrdfOptions& options) {
  return internal::loadUrdfString(xml, internal::NamedUrdfOptions{options, {}});
}

Model loadUrdfFile(const std::string& path, const UrdfOptions& options) {
  return internal::loadUrdfFile(path, internal::NamedUrdfOptions{options, {}});
}

}  // namespace zwang
