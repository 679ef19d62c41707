// The third scenario of `zwang energy` (docs/evaluation.md, section 4,
// "Standing"): two robots on a free base standing still on the ground, the
// humanoid models/simple_humanoid.urdf (29 joints) on both feet and the
// quadruped models/solo12.urdf (12 joints) on four point feet, with the motor
// effort of the plain and the friction-aware solver, as for the Panda.
//
// The task. Each foot is a contact (Task::addContact, world axes, zero set
// points: the ground supplies its force, so it is not in τ_control): six rows
// for the humanoid's flat feet (l_ankle, r_ankle: force and moment), three for
// Solo's point feet (FL/FR/HL/HR_FOOT: force). The feet alone leave the body
// free to sag (legs, base and ground form closed chains with 35 − 12 = 23 and
// 18 − 12 = 6 degrees of freedom left), so every joint also gets a joint row
// q̈_j = 0 (Task::addJointConstraint: its own motor holds it). The rows then
// have rank nv and q̈ = 0 is the only motion. Six rows are beyond the rank:
// the ground's split between the feet is statically indeterminate (internal
// forces between them), and the balance returns the least-norm ν, the least
// Σν² over ground forces, moments and motor torques together (docs/solver.md,
// "Singular tasks"). That choice fixes the split and with it τ_control:
//   plain (solveHybridDynamics): τ_control = the joint rows' ν;
//   friction-aware (solveWithFriction, every joint stuck, μ* indeterminate):
//     the maximiser with the least ‖τ_control‖² within margin·f_j. The split
//     moves with μ, so this is not max(0, |τ_j| − margin·f_j) joint by joint
//     as on the Panda.
// Checked before anything is written: rank nv in every solve (else q̈ is not
// determined and the report means nothing), and ‖τ_control‖² with friction
// not above the plain one (the effort table's "check"). That the solver's
// answer is right (q̈ = 0, RNEA with the ground's wrenches, the least-norm
// split, |μ_j| ≤ margin·f_j, the least ‖τ_control‖² over the margin box) is
// the tests' to show (test_cli_standing), not the tool's.
//
// The postures are chosen (kHumanoidPostures, kSoloPostures). The base is
// placed from the legs' kinematics (framePose): the feet on z = 0 (the
// humanoid's flat, identity orientation), their midpoint at the origin. The
// humanoid's WAIST_P undoes the pelvis's tilt, so its chest stays upright.
// The contacts are ideal (the URDF has no soles): the ground gives whatever
// moment the posture needs, and the output shows where the centre of mass
// and each foot's centre of pressure are. The breakaway friction is chosen
// too (neither URDF has any) and given per solve (FrictionOptions::breakaway):
// see humanoidBreakaway and soloBreakaway.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "cli.hpp"
#include "energy_report.hpp"
#include "standing_reference.hpp"
#include "zwang/zwang.hpp"

namespace zwang::cli {

namespace {

using energy::small;

constexpr double kPlacementTolerance = 1e-12;  // feet off z = 0 or off level after placing the base [m, rad]:
                                               // a few transforms of numbers below 1 round to ~1e-16
constexpr double kLimitDistance = 0.05;        // every joint at least this far inside its limits [rad]

struct JointValue {
  std::string joint;
  double q;  // [rad]
};

struct Posture {
  const char* name;
  const char* what;
  std::vector<JointValue> joints;  // every other joint at 0
};

// Both legs of the humanoid: hip pitch, knee, ankle pitch (rolls and yaws 0).
// The URDF's limits allow only knee and ankle pitch ≥ 0 on both legs (its
// right leg's limits are its left's shifted by one joint), so the shank
// always leans with the foot ahead of the knee, and the pelvis tilts back by
// the sum of the three angles when it is not 0.
std::vector<JointValue> humanoidLegs(double hip, double knee, double ankle, std::vector<JointValue> more) {
  std::vector<JointValue> joints{{"LLEG_HIP_P", hip},      {"LLEG_KNEE", knee},      {"LLEG_ANKLE_P", ankle},
                                 {"RLEG_HIP_P", hip},      {"RLEG_KNEE", knee},      {"RLEG_ANKLE_P", ankle},
                                 {"LARM_SHOULDER_R", 0.1}, {"RARM_SHOULDER_R", 0.1}, {"LARM_ELBOW", -0.1},
                                 {"RARM_ELBOW", -0.1},     {"LARM_WRIST_Y", -0.1},   {"RARM_WRIST_Y", -0.1}};
  // The arms' values keep every arm joint kLimitDistance inside the URDF's
  // limits (shoulder roll ≥ 0.0087, LARM_WRIST_Y and RARM_ELBOW ≤ 0.0035).
  joints.insert(joints.end(), more.begin(), more.end());
  return joints;
}

const std::vector<Posture> kHumanoidPostures = {
    {"upright", "legs almost straight (knee and ankle 0.06 rad), pelvis level", humanoidLegs(-0.12, 0.06, 0.06, {})},
    {"crouched", "knees bent 0.6 rad, pelvis back and tilted back 0.45 rad, chest upright",
     humanoidLegs(-0.25, 0.6, 0.1, {})},
    {"arm_raised", "upright, left arm raised forward to the horizontal",
     humanoidLegs(-0.12, 0.06, 0.06, {{"LARM_SHOULDER_P", -1.5}})},
};

// Solo's legs: hip flexion HFE and knee KFE, front legs (FL, FR) one way and
// hind legs (HL, HR) mirrored, KFE = −2·HFE so each foot is under its HFE axis.
std::vector<JointValue> soloLegs(double hfe) {
  std::vector<JointValue> joints;
  for (const std::string leg : {"FL", "FR", "HL", "HR"}) {
    const double front = leg[0] == 'F' ? 1.0 : -1.0;
    joints.push_back({leg + "_HFE", front * hfe});
    joints.push_back({leg + "_KFE", -2.0 * front * hfe});
  }
  return joints;
}

const std::vector<Posture> kSoloPostures = {
    {"stand", "HFE ±0.8, KFE ∓1.6 rad: knees towards the body, feet under the hips", soloLegs(0.8)},
    {"crouch", "HFE ±1.1, KFE ∓2.2 rad: the same, lower", soloLegs(1.1)},
};

// Breakaway friction, chosen (simple_humanoid.urdf has none): the Panda's
// published values (models/panda.urdf) by joint size, as for harmonic-drive
// joints of the same class: 5 N·m (the Panda's joint 1) for legs, waist and
// chest, 2 N·m (its joints 2, 3) for shoulders and elbows, 0.5 N·m (its wrist
// joints 6, 7) for the wrists.
double humanoidBreakaway(const std::string& joint) {
  if (joint.find("WRIST") != std::string::npos) return 0.5;
  if (joint.find("SHOULDER") != std::string::npos || joint.find("ELBOW") != std::string::npos) return 2.0;
  return 5.0;
}

// Breakaway friction, chosen (solo12.urdf says 0): 0.05 N·m per joint, 2 % of
// the 2.5 N·m the ODRI actuator module is rated for (open_robot_actuator_hardware,
// actuator_module_v1: a 9:1 two-stage belt drive, low friction by design).
double soloBreakaway(const std::string&) { return 0.05; }

struct StandingRobot {
  const char* file;
  const char* label;  // in the CSV and the plots
  const char* title;  // in the output
  int dof;
  std::vector<std::string> feet;
  int contact_rows;   // 6: a flat foot (force and moment), 3: a point foot (force)
  const char* waist;  // the joint that turns the chest back upright when the pelvis tilts (nullptr: none)
  double (*breakaway)(const std::string& joint);
  const std::vector<Posture>* postures;
};

const StandingRobot kRobots[] = {
    {"simple_humanoid.urdf",
     "humanoid",
     "simple_humanoid",
     29,
     {"l_ankle", "r_ankle"},
     6,
     "WAIST_P",
     humanoidBreakaway,
     &kHumanoidPostures},
    {"solo12.urdf",
     "solo12",
     "Solo 12",
     12,
     {"FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"},
     3,
     nullptr,
     soloBreakaway,
     &kSoloPostures},
};

// What the standing report adds to a variant's solve (energy::VariantResult).
struct VariantDetail {
  Eigen::VectorXd ground;  // ν of the contact rows: per foot [f; n] or [f], world axes at the foot origin
};

// What the standing report adds to a posture's solves (energy::PostureResult).
struct PostureDetail {
  double placement_error = 0, limit_distance = 0;
  Eigen::Vector2d com = Eigen::Vector2d::Zero();  // the centre of mass across gravity [m], world x, y
  double mass = 0;                                // [kg], from RNEA's base force
  std::array<VariantDetail, energy::kVariantCount> variant;
  int rank = 0;
  double split_shift = 0;
  standing::BestSplit best_split;  // plain: the least ‖τ_control‖² over every split of the ground's force
};

struct RobotResult {
  const StandingRobot* robot = nullptr;
  std::filesystem::path urdf;
  Model model;
  Eigen::VectorXd breakaway;
  std::vector<energy::PostureResult> postures;
  std::vector<PostureDetail> details;  // one per posture
};

// Feet with six contact rows carry a moment: they stand flat, level on the ground.
bool flatFeet(const StandingRobot& robot) { return robot.contact_rows == 6; }

std::string where(const StandingRobot& robot, const Posture& posture) {
  return std::string("energy: ") + robot.label + ", posture " + posture.name + ": ";
}

void require(const Status& s, const std::string& context) {
  if (!s) throw CliError(kExitError, context + s.message);
}

std::vector<Eigen::Isometry3d> footPoses(const Model& model, Workspace& ws, const StandingRobot& robot,
                                         const Eigen::VectorXd& q, const std::string& context) {
  require(forwardKinematics(model, ws, q), context);
  std::vector<Eigen::Isometry3d> poses(robot.feet.size());
  for (std::size_t k = 0; k < robot.feet.size(); ++k)
    require(framePose(model, ws, q, model.frameIndex(robot.feet[k]), poses[k]), context);
  return poses;
}

// Put the base where the feet stand on z = 0, their midpoint at the origin.
// With the base at the origin the feet's poses give the orientation the base
// needs for flat feet to be level (R_base = R_footᵀ) and their offsets.
// Returns how far the placed feet are off: height, midpoint, and level.
double placeBase(const Model& model, Workspace& ws, const StandingRobot& robot, Eigen::VectorXd& q,
                 const std::string& context) {
  q.head<7>() << 0, 0, 0, 1, 0, 0, 0;
  std::vector<Eigen::Isometry3d> feet = footPoses(model, ws, robot, q, context);
  const Eigen::Matrix3d R =
      flatFeet(robot) ? Eigen::Matrix3d(feet[0].linear().transpose()) : Eigen::Matrix3d::Identity();
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Isometry3d& foot : feet) mean += R * foot.translation() / static_cast<double>(feet.size());
  const Eigen::Quaterniond orientation(R);
  q.head<3>() = -mean;
  q.segment<4>(3) << orientation.w(), orientation.x(), orientation.y(), orientation.z();
  feet = footPoses(model, ws, robot, q, context);
  double error = 0;
  Eigen::Vector3d midpoint = Eigen::Vector3d::Zero();
  for (const Eigen::Isometry3d& foot : feet) {
    error = std::max(error, std::abs(foot.translation().z()));
    if (flatFeet(robot)) error = std::max(error, (foot.linear() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff());
    midpoint += foot.translation() / static_cast<double>(feet.size());
  }
  return std::max(error, midpoint.head<2>().cwiseAbs().maxCoeff());
}

// The centre of mass across gravity, world x and y, and the mass: at rest
// RNEA's base force is the wrench [f; n] (base axes, base origin) that holds
// the whole robot up, f = −m·g and n = c × f, so c's part across f is
// f × n / |f|².
Eigen::Vector2d centreOfMass(const Model& model, Workspace& ws, const Eigen::VectorXd& q, double& mass,
                             const std::string& context) {
  const Task gravity_only(model);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(model.nv());
  require(inverseDynamics(model, ws, q, zero, zero, gravity_only), context + "RNEA: ");
  const Eigen::Vector3d f = ws.tau.head<3>(), n = ws.tau.segment<3>(3);
  mass = f.norm() / gravity_only.gravity.norm();
  const Eigen::Quaterniond orientation(q[3], q[4], q[5], q[6]);
  return (q.head<3>() + orientation * (f.cross(n) / f.squaredNorm())).head<2>();
}

// The base's pitch, the angle about the world's y axis, from its quaternion.
double basePitch(const Eigen::VectorXd& q) {
  const Eigen::Matrix3d R = Eigen::Quaterniond(q[3], q[4], q[5], q[6]).toRotationMatrix();
  return std::atan2(R(0, 2), R(2, 2));
}

double limitDistance(const Model& model, const Eigen::VectorXd& q) {
  double distance = std::numeric_limits<double>::infinity();
  for (int j = 0; j < model.dof(); ++j) {
    const double qj = q[model.baseConfigurationSize() + j];
    distance = std::min({distance, qj - model.joint(j).lower, model.joint(j).upper - qj});
  }
  return distance;
}

Eigen::VectorXd postureConfiguration(const Model& model, Workspace& ws, const StandingRobot& robot,
                                     const Posture& posture, PostureDetail& r) {
  const std::string context = where(robot, posture);
  Eigen::VectorXd q = Eigen::VectorXd::Zero(model.nq());
  for (const JointValue& value : posture.joints)
    q[model.baseConfigurationSize() + model.jointIndex(value.joint)] = value.q;
  r.placement_error = placeBase(model, ws, robot, q, context);
  if (robot.waist) q[model.baseConfigurationSize() + model.jointIndex(robot.waist)] = -basePitch(q);
  r.com = centreOfMass(model, ws, q, r.mass, context);
  r.limit_distance = limitDistance(model, q);
  if (!(r.placement_error < kPlacementTolerance) || !(r.limit_distance > kLimitDistance))
    throw CliError(kExitError, context + "the feet are not level on z = 0 within the joint limits (off by " +
                                   small(r.placement_error) + ", closest limit " + fmt(r.limit_distance) + " rad)");
  return q;
}

Task standingTask(const Model& model, const StandingRobot& robot) {
  Task task(model);  // gravity (0, 0, −9.81)
  const ConstraintMatrix rows = ConstraintMatrix::Identity(6, 6).leftCols(robot.contact_rows);
  for (const std::string& foot : robot.feet) task.addContact(foot, rows, Expressed::World);
  for (int j = 0; j < model.dof(); ++j) task.addJointConstraint(j);
  return task;
}

// Whether the friction-aware picks' ‖τ_control‖² are not above plain's (μ = 0 is in the box).
bool effortsOrdered(const energy::PostureResult& s) {
  bool ordered = true;
  for (std::size_t v = 1; v < energy::kVariantCount; ++v)
    ordered = ordered && s.variant[v].effort.sq <= s.variant[0].effort.sq;
  return ordered;
}

energy::PostureResult runPosture(const Model& model, const StandingRobot& robot, const Eigen::VectorXd& breakaway,
                                 const Posture& posture, PostureDetail& r) {
  energy::PostureResult s;
  s.name = posture.name;
  Workspace check_ws(model, 0);
  s.q = postureConfiguration(model, check_ws, robot, posture, r);
  const std::string context = where(robot, posture);
  const standing::DenseBalance dense =
      standing::denseBalance(model, check_ws, robot.feet, robot.contact_rows, s.q, context);
  r.best_split = standing::bestSplit(dense, robot.contact_rows);
  const Task task = standingTask(model, robot);
  Workspace ws(model, task);
  const int n = model.dof(), contacts = robot.contact_rows * static_cast<int>(robot.feet.size());
  for (int v = 0; v < energy::kVariantCount; ++v) {
    const energy::Variant& variant = energy::kVariants[v];
    require(energy::solveAtRest(model, task, s.q, ws, variant, breakaway), context + variant.name + ": ");
    if (ws.solution.balance.rank != model.nv())
      throw CliError(kExitError, context + variant.name + ": the standing task has rank " +
                                     std::to_string(ws.solution.balance.rank) +
                                     ", not nv = " + std::to_string(model.nv()) + " (q̈ is not fully determined)");
    const auto k = static_cast<std::size_t>(v);
    s.variant[k] = energy::variantResult(variant, ws.solution.tau_control.tail(n), ws);
    r.variant[k].ground = ws.solution.nu.head(contacts);
    r.rank = ws.solution.balance.rank;
  }
  // How far the split moved with friction: the joints' τ_control − μ at margin 1 against plain (0 for a fixed split).
  r.split_shift = ((s.variant[2].tau - s.variant[2].mu) - s.variant[0].tau).cwiseAbs().maxCoeff();
  s.ok = r.rank == model.nv() && effortsOrdered(s);
  return s;
}

RobotResult runRobot(const ReportCommand& report, const StandingRobot& robot) {
  RobotResult result;
  result.robot = &robot;
  UrdfOptions options;
  options.base = BaseType::Free;
  result.model = energy::loadScenarioModel(report, robot.file, options, result.urdf);
  bool as_expected = result.model.dof() == robot.dof;
  for (const std::string& foot : robot.feet) as_expected = as_expected && result.model.hasFrame(foot);
  for (const Posture& posture : *robot.postures)
    for (const JointValue& value : posture.joints) as_expected = as_expected && result.model.hasJoint(value.joint);
  if (!as_expected)
    throw CliError(kExitError, report.name + ": " + result.urdf.string() + ": expected " + robot.title + " with " +
                                   std::to_string(robot.dof) + " joints and the feet of docs/evaluation.md, section 4");
  result.breakaway.resize(robot.dof);
  for (int j = 0; j < robot.dof; ++j) result.breakaway[j] = robot.breakaway(result.model.joint(j).name);
  for (const Posture& posture : *robot.postures) {
    result.details.emplace_back();
    result.postures.push_back(runPosture(result.model, robot, result.breakaway, posture, result.details.back()));
  }
  return result;
}

// --- output -----------------------------------------------------------------

std::string groundName(const StandingRobot& robot, Eigen::Index row) {
  static const char* const kComponents[] = {"fx", "fy", "fz", "nx", "ny", "nz"};
  return robot.feet[static_cast<std::size_t>(row / robot.contact_rows)] + "." + kComponents[row % robot.contact_rows];
}

std::string qName(const Model& model, int k) {
  static const char* const kBase[] = {"base_x", "base_y", "base_z", "base_qw", "base_qx", "base_qy", "base_qz"};
  return k < 7 ? kBase[k] : model.joint(k - 7).name;
}

void csvRow(std::ostringstream& out, const std::string& key, const std::string& name, double value) {
  out << key << "," << name << energy::csvCell(value) << "\n";
}

void csvRobot(std::ostringstream& out, const RobotResult& robot) {
  const Model& model = robot.model;
  const std::string label = robot.robot->label;
  for (int j = 0; j < model.dof(); ++j) csvRow(out, label + ",-,-,breakaway", model.joint(j).name, robot.breakaway[j]);
  for (std::size_t p = 0; p < robot.postures.size(); ++p) {
    const energy::PostureResult& r = robot.postures[p];
    const PostureDetail& d = robot.details[p];
    const std::string posture = label + "," + r.name;
    for (int k = 0; k < model.nq(); ++k) csvRow(out, posture + ",-,q", qName(model, k), r.q[k]);
    for (int v = 0; v < energy::kVariantCount; ++v) {
      const energy::VariantResult& e = r.variant[static_cast<std::size_t>(v)];
      const VariantDetail& g = d.variant[static_cast<std::size_t>(v)];
      const std::string key = posture + "," + energy::kVariants[v].name;
      for (int j = 0; j < model.dof(); ++j) csvRow(out, key + ",tau", model.joint(j).name, e.tau[j]);
      for (int j = 0; j < model.dof(); ++j) csvRow(out, key + ",mu", model.joint(j).name, e.mu[j]);
      for (Eigen::Index k = 0; k < g.ground.size(); ++k)
        csvRow(out, key + ",ground", groundName(*robot.robot, k), g.ground[k]);
      csvRow(out, key + ",effort", "tau_norm", e.effort.norm);
      csvRow(out, key + ",effort", "tau_sq", e.effort.sq);
      csvRow(out, key + ",effort", "tau_abs_sum", e.effort.abs_sum);
      if (energy::kVariants[v].margin < 0) csvRow(out, key + ",effort", "tau_sq_best_split", d.best_split.sq);
    }
  }
}

std::string standingCsv(const std::vector<RobotResult>& robots) {
  std::ostringstream out;
  out << "robot,posture,variant,quantity,name,value\n";
  for (const RobotResult& robot : robots) csvRobot(out, robot);
  return out.str();
}

std::string jointsBlock(const RobotResult& robot, std::size_t p) {
  return std::string("$joints_") + robot.robot->label + "_" + robot.postures[p].name;
}

// Text for a gnuplot title in enhanced mode: "_" would start a subscript.
std::string enhancedText(const std::string& text) {
  std::string escaped;
  for (const char c : text) escaped += c == '_' ? std::string("\\\\_") : std::string(1, c);
  return escaped;
}

// The effort chart (one panel per robot) and one per-joint chart per robot.
std::string standingPlotScript(const std::string& script, const std::vector<RobotResult>& robots) {
  std::ostringstream s;
  s << energy::scriptHeader(script);
  for (const RobotResult& robot : robots) {
    s << energy::normsData(std::string("$norms_") + robot.robot->label, "posture", robot.postures);
    std::vector<std::string> labels;
    for (const Joint& joint : robot.model.joints()) labels.push_back(joint.name);
    for (std::size_t p = 0; p < robot.postures.size(); ++p)
      s << energy::jointsData(jointsBlock(robot, p), labels, robot.postures[p].torques(), robot.breakaway);
  }
  s << energy::histogramStyle(robots[0].postures.size())
    << "\n"
       "set terminal pngcairo size 1100,520 font \"DejaVu Sans,11\"\n"
       "set output \"standing_energy.png\"\n"
       "set multiplot layout 1,2 title \"Standing still on the ground: motor effort ‖τ_{control}‖\"\n"
       "set ylabel \"‖τ_{control}‖ [N·m]\"\n"
       "set xtics noenhanced\n";
  for (const RobotResult& robot : robots)
    s << "set title \"" << robot.robot->title << "\" noenhanced\n"
      << "set xrange [-0.6:" << static_cast<double>(robot.postures.size()) - 0.4 << "]\n"
      << energy::normsPlot(std::string("$norms_") + robot.robot->label);
  s << "unset multiplot\n";
  for (const RobotResult& robot : robots) {
    const bool tall = robot.postures.size() > 2;
    s << "\nset terminal pngcairo size " << (tall ? "1500,1200" : "1300,520") << " font \"DejaVu Sans,10\"\n"
      << "set output \"standing_" << robot.robot->label << "_joints.png\"\n"
      << "set multiplot layout " << (tall ? robot.postures.size() : 1) << "," << (tall ? 1 : robot.postures.size())
      << " title \"" << enhancedText(robot.robot->title)
      << " standing: |τ_{control,j}| per joint (bars) and breakaway friction f_j (red)\"\n"
      << energy::jointsPanelStyle(static_cast<std::size_t>(robot.model.dof()))
      << "set xlabel \"\"\n"                 // the joints' names say it
         "set offsets 0, 0, graph 0.3, 0\n"  // room for the key above the bars
         "set xtics rotate by -45 noenhanced font \",8\"\n"
      << "set bmargin 6\n";
    for (std::size_t p = 0; p < robot.postures.size(); ++p)
      s << energy::jointsPanel(jointsBlock(robot, p), robot.postures[p].name, p == 0);
    s << "unset multiplot\n";
  }
  s << "unset output\n";
  return s.str();
}

void printPostures(const RobotResult& robot) {
  std::printf(
      "\npostures: the base pose (placed so the feet are on z = 0%s, their midpoint at the origin), how far the\n"
      "feet are off it, the centre of mass across gravity [m], the mass from RNEA [kg], the closest joint limit [rad]\n",
      flatFeet(*robot.robot) ? " and level" : "");
  std::vector<std::vector<std::string>> rows{{"posture", "what", "base z", "base pitch",
                                              robot.robot->waist ? "waist" : "", "feet off", "com x", "com y", "mass",
                                              "closest limit"}};
  for (std::size_t p = 0; p < robot.postures.size(); ++p) {
    const Eigen::VectorXd& q = robot.postures[p].q;
    const PostureDetail& r = robot.details[p];
    const Eigen::Quaterniond orientation(q[3], q[4], q[5], q[6]);
    const double pitch = std::atan2(-orientation.toRotationMatrix()(2, 0), orientation.toRotationMatrix()(2, 2));
    const std::string waist = robot.robot->waist ? fmt(q[7 + robot.model.jointIndex(robot.robot->waist)], "%.4f") : "";
    rows.push_back({robot.postures[p].name, (*robot.robot->postures)[p].what, fmt(q[2], "%.4f"), fmt(pitch, "%.4f"),
                    waist, small(r.placement_error), fmt(r.com.x(), "%.3f"), fmt(r.com.y(), "%.3f"),
                    fmt(r.mass, "%.2f"), fmt(r.limit_distance, "%.3f")});
  }
  printColumns(rows, 2);
}

void printTorques(const RobotResult& robot) {
  std::printf("\ntau_control per joint [N·m] (m = margin of the friction-aware solve)\n");
  std::vector<std::vector<std::string>> rows{{"joint"}, {""}};
  for (const Posture& posture : *robot.robot->postures)
    for (int v = 0; v < energy::kVariantCount; ++v) {
      rows[0].push_back(v == 0 ? posture.name : "");
      rows[1].push_back(v == 0 ? "plain" : (v == 1 ? "m=0.5" : "m=1"));
    }
  for (int j = 0; j < robot.model.dof(); ++j) {
    std::vector<std::string> row{robot.model.joint(j).name};
    for (const energy::PostureResult& r : robot.postures)
      for (const energy::VariantResult& e : r.variant) row.push_back(fmt(e.tau[j], "%.3g"));
    rows.push_back(row);
  }
  printColumns(rows);
}

// The joints whose plain holding torque is above the URDF's <limit effort>.
void printEffortLimits(const RobotResult& robot) {
  std::string over;
  for (std::size_t p = 0; p < robot.postures.size(); ++p)
    for (int j = 0; j < robot.model.dof(); ++j) {
      const double tau = robot.postures[p].variant[0].tau[j], limit = robot.model.joint(j).effort_limit;
      if (std::abs(tau) > limit)
        over += std::string(over.empty() ? "" : ", ") + robot.postures[p].name + " " + robot.model.joint(j).name + " " +
                fmt(std::abs(tau), "%.3g") + " > " + fmt(limit);
    }
  std::printf("above the URDF's effort limit (|tau| plain > <limit effort>) [N·m]: %s\n",
              over.empty() ? "none" : over.c_str());
}

void printGround(const RobotResult& robot) {
  const bool flat = flatFeet(*robot.robot);
  std::printf("\nthe ground's force on each foot: nu of the contact rows, world axes at the foot origin [N%s]%s\n",
              flat ? ", N·m" : "", flat ? "; cop = centre of pressure relative to the foot origin [m]" : "");
  std::vector<std::vector<std::string>> rows{{"posture", "variant", "foot", "fx", "fy", "fz"}};
  if (flat) rows[0].insert(rows[0].end(), {"nx", "ny", "nz", "cop x", "cop y"});
  for (std::size_t p = 0; p < robot.postures.size(); ++p)
    for (int v = 0; v < energy::kVariantCount; v += 2)  // plain and margin 1
      for (std::size_t k = 0; k < robot.robot->feet.size(); ++k) {
        const Eigen::VectorXd w = robot.details[p].variant[static_cast<std::size_t>(v)].ground.segment(
            robot.robot->contact_rows * static_cast<Eigen::Index>(k), robot.robot->contact_rows);
        std::vector<std::string> row{k == 0 && v == 0 ? robot.postures[p].name : "",
                                     k == 0 ? energy::kVariants[v].name : "", robot.robot->feet[k]};
        for (Eigen::Index c = 0; c < w.size(); ++c) row.push_back(fmt(w[c], "%.4g"));
        if (flat) row.insert(row.end(), {fmt(-w[4] / w[2], "%.4f"), fmt(w[3] / w[2], "%.4f")});
        rows.push_back(row);
      }
  printColumns(rows, 3);
}

// Plain's ‖τ_control‖² with the solver's split of the ground's force and
// with the best one, beside the friction-aware solves'.
void printLeastEffort(const RobotResult& robot) {
  std::printf(
      "\nleast effort [N²m²]: plain |tau|^2 with the solver's least-norm split, and with the split of the ground's\n"
      "force that needs the least motor effort (best split, over the internal forces, no friction; ft/fn = the\n"
      "largest horizontal over vertical force it puts on a foot); friction-aware |tau|^2, the least over the\n"
      "margin box (the least-norm split moving with mu)\n");
  std::vector<std::vector<std::string>> rows{
      {"posture", "|tau|^2 plain", "best split", "its ft/fn", "|tau|^2 m=0.5", "|tau|^2 m=1"}};
  for (std::size_t p = 0; p < robot.postures.size(); ++p) {
    const energy::PostureResult& r = robot.postures[p];
    const PostureDetail& d = robot.details[p];
    std::vector<std::string> row{r.name, fmt(r.variant[0].effort.sq), fmt(d.best_split.sq),
                                 fmt(d.best_split.tangential, "%.3f")};
    for (std::size_t v = 1; v < energy::kVariantCount; ++v) row.push_back(fmt(r.variant[v].effort.sq));
    rows.push_back(row);
  }
  printColumns(rows);
}

void printChecks(const RobotResult& robot) {
  double shift = 0;
  for (const PostureDetail& p : robot.details) shift = std::max(shift, p.split_shift);
  std::printf(
      "check: rank %d in every solve; |tau|^2 not above plain's. The split moves with friction: tau_control - mu\n"
      "at margin 1 differs from plain by up to %s N·m\n",
      robot.model.nv(), fmt(shift, "%.3g").c_str());
}

void printRobot(const RobotResult& robot) {
  const StandingRobot& r = *robot.robot;
  const Model& model = robot.model;
  std::printf("\nzwang energy: %s on a free base (%d joints, nv %d) standing still, at rest, gravity (0, 0, -9.81)\n",
              energy::shownPath(robot.urdf).c_str(), model.dof(), model.nv());
  const int contacts = r.contact_rows * static_cast<int>(r.feet.size());
  std::printf(
      "task: %zu feet fixed, %d contact rows each (%s, world axes; the ground's force, not in tau_control) + one\n"
      "joint row per joint (qdd_j = 0, its motor): %d rows, rank %d = nv, so qdd = 0; the %d rows beyond the rank\n"
      "are the ground's statically indeterminate split between the feet, which the solver takes least-norm\n",
      r.feet.size(), r.contact_rows, r.contact_rows == 6 ? "force and moment" : "force", contacts + model.dof(),
      model.nv(), contacts + model.dof() - model.nv());
  std::printf("breakaway friction f [N·m] (chosen, not in the URDF):");
  for (int j = 0; j < model.dof(); ++j) std::printf(" %s", fmt(robot.breakaway[j]).c_str());
  std::printf("\n");
  printPostures(robot);
  printTorques(robot);
  printEffortLimits(robot);
  printGround(robot);
  energy::printEffortTable("posture", robot.postures);
  printLeastEffort(robot);
  printChecks(robot);
}

// Each robot of kRobots standing still in each of its postures.
class StandingScenario final : public Scenario {
 public:
  explicit StandingScenario(const ReportCommand& report) {
    for (const StandingRobot& robot : kRobots) robots_.push_back(runRobot(report, robot));
  }
  ScenarioFiles files() const override {
    return {{"standing_energy.csv"},
            "robot, posture, variant, quantity, name, value: q, tau = tau_control, mu,\nground = nu of the contacts, "
            "effort; breakaway per joint",
            "standing_energy.gp",
            "standing_energy.png, standing_humanoid_joints.png, standing_solo12_joints.png"};
  }
  bool ok() const override {
    bool all_ok = true;
    for (const RobotResult& robot : robots_)
      for (const energy::PostureResult& posture : robot.postures) all_ok = all_ok && posture.ok;
    return all_ok;
  }
  void print() const override {
    for (const RobotResult& robot : robots_) printRobot(robot);
  }
  std::string csvText(std::size_t) const override { return standingCsv(robots_); }
  std::string plotScript() const override { return standingPlotScript(files().script, robots_); }

 private:
  std::vector<RobotResult> robots_;
};

}  // namespace

std::unique_ptr<Scenario> energy::standingScenario(const ReportCommand& report) {
  return std::make_unique<StandingScenario>(report);
}

}  // namespace zwang::cli
