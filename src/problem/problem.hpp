// The problem layer under the front ends (the CLI's JSON, the Python module):
// the parts of a problem, their checks and their messages, once. A front end
// translates its input into these parts and prints what comes back; the layer
// builds the Task and the options before the solve and is not in it.
#pragma once

#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "zwang/zwang.hpp"

#include "model/urdf_option_names.hpp"  // the front ends spell the URDF options their own way in its messages

namespace zwang::problem {

// What is wrong: a value out of its range or form, or one the model refuses (a name it lacks).
enum class Fault { Value, Model };

// A bad input. key() is the part of the item at fault ("relative_to",
// "margin"; empty for the item itself): each front end puts its own path in
// front of it ("constraints[0].", "friction.").
class ProblemError : public std::runtime_error {
 public:
  ProblemError(Fault fault, std::string key, const std::string& what);
  Fault fault() const { return fault_; }
  const std::string& key() const { return key_; }

 private:
  Fault fault_;
  std::string key_;
};

// How a front end quotes names and values in its messages: JSON's " or Python's '.
struct Spelling {
  char quote = '"';
  std::string base_state = "goes in \"base\"";  // where a floating base's state is given, for messages
};

// One printable line: control bytes and bytes that are not valid UTF-8 as
// \xNN (valid UTF-8 passes through), at most `max_length` bytes, cut between
// characters (the rest elided with "...").
std::string printable(const std::string& text, std::size_t max_length = 200);

// The model's joints below the root, "a, b, c", for messages.
std::string jointNames(const Model& model);

// `text`, printable and cut at `max_length`, between the spelling's quotes.
std::string quoted(const Spelling& spelling, const std::string& text, std::size_t max_length = 60);

// Which axes an item may be expressed in: a wrench local or world, a
// constraint also aligned, a relative constraint also its reference's.
enum class AxesOf { Wrench, Constraint, RelativeConstraint };

// "local", "world", "aligned", "reference"; ProblemError(Value) naming the allowed ones.
Expressed parseExpressed(const Spelling& spelling, const std::string& text, AxesOf item);

// The model a front end asks for; `names` spells its keys in the loader's messages.
struct ModelRequest {
  std::string root, tip;
  bool strict = false;
  bool attach_beyond_tip = false;
  bool lock_mimic = false;  // weld the mimic joints (MimicJoints::Lock)
  BaseType base = BaseType::Fixed;
  internal::UrdfOptionNames names;
};
internal::NamedUrdfOptions urdfOptions(const ModelRequest& request);

// A model file as a front end loads it, and the gravity the file states (MJCF's <option gravity>; none for URDF).
struct LoadedModel {
  Model model;
  std::optional<Vec3> gravity;
};
// True for a path the front ends read as MJCF: it ends in ".xml" (any case); any other is URDF.
bool isMjcfPath(const std::string& path);
// The model at `path`: MJCF (isMjcfPath) through the MJCF loader (zwang/mjcf.hpp) when zwang is built with MuJoCo,
// else URDF with `options`. For MJCF the URDF-only options (root, tip, attach_beyond_tip, lock_mimic, rotor
// inertias) are refused, a base type must be the file's (options.base_may_match_file) and strict applies.
// ModelError naming the file; without MuJoCo "MJCF needs zwang built with MuJoCo".
LoadedModel loadModelFile(const std::string& path, const internal::NamedUrdfOptions& options);
// An MJCF model from a file (`from_string` false) or from text (true), as loadModelFile loads it.
LoadedModel loadMjcf(const std::string& source, bool from_string, bool strict);

// "fixed", "free", "planar"; ProblemError(Value) naming the allowed ones. Where
// "fixed" is no value (`no_fixed` given), "fixed" is refused with `no_fixed` as the hint.
BaseType parseBaseType(const Spelling& spelling, const std::string& text, const char* no_fixed = nullptr);

// One constraint as a front end describes it: a frame's rows (A, 6 × m), a
// relative one's (relative_to), a contact's, or a joint row (joint).
struct ConstraintDesc {
  std::string frame;
  std::string relative_to;  // empty: the world
  std::string joint;        // a joint row: frame, A and expressed unused
  Expressed expressed = Expressed::Local;
  ConstraintMatrix A;
  bool contact = false;
};

// relative_to neither empty when given nor the frame itself; not with a contact.
void checkRelative(const Spelling& spelling, const ConstraintDesc& c, bool relative_given);

// The index of a frame; ProblemError(Model, "") with the model's frames when unknown.
int frameIndex(const Model& model, const std::string& name);

// The index in joints() of a joint; ProblemError(Model, "") naming the model's
// joints when unknown (and where a floating base's state goes, for its root joint).
int jointIndex(const Spelling& spelling, const Model& model, const std::string& name);

// The constraint's rows into `task` by the Task::add* its kind asks for; its
// first row. ProblemError keyed "frame", "relative_to" or "joint" for a name
// the model does not have.
int addConstraint(const Spelling& spelling, const Model& model, Task& task, const ConstraintDesc& c);

// How a front end sets one joint's (or one DOF's) mode: torque-driven, locked, or its accelerations prescribed.
enum class ModeKind { Torque, Locked, Acceleration };
struct JointModeDesc {
  std::string name;  // a joint below the root, or one DOF of a multi-DOF joint ("<joint>.<coordinate>")
  ModeKind kind = ModeKind::Torque;
  Eigen::VectorXd acceleration;  // Acceleration: one per DOF named (the joint's nv, or 1 for a DOF)
};

// "torque", "locked"; ProblemError(Value) naming the allowed ones (and the acceleration form).
ModeKind parseModeKind(const Spelling& spelling, const std::string& text);

// The mode into `task` (Task::prescribe / lock / release, or setDofMode for one DOF), with its accelerations.
// ProblemError(Model, "") for a name the model does not have (naming its joints) or a mimic joint,
// (Value, "acceleration") for a count that is not the DOFs' or an entry that is not finite.
void setJointMode(const Spelling& spelling, const Model& model, Task& task, const JointModeDesc& mode);

// A wrench on a frame into `task`; its index. ProblemError keyed "frame".
int addWrench(const Model& model, Task& task, const std::string& frame, Expressed expressed);

// The name of DOF `dof` counted below the root (an index into q̈'s entries after a floating base's; the
// friction result's `stuck` and `impact_joint`): a one-DOF joint's name, "<joint>.<coordinate>" for a multi-DOF one.
const std::string& dofName(const Model& model, int dof);

// What an array of one entry per DOF below the root holds, for messages:
// "one per moving joint: a, b" (every joint one DOF) or "one per DOF: a, b.x, b.y".
std::string dofLayout(const Model& model);

// A per-joint array `name` (rotor inertia, friction) of a copy of the model:
// one entry per joint, or one per DOF as the model's per-DOF arrays list them
// (a joint's DOFs must then agree), each finite and >= 0. One per joint;
// ProblemError(Model, name) for a length the model does not have or DOFs
// that disagree, ProblemError(Value, "name[k]") for an entry.
Eigen::VectorXd perJoint(const Model& model, const std::string& name, const Eigen::Ref<const Eigen::VectorXd>& values);

// The model with these reflected rotor inertias (perJoint's rules, named `name`).
Model withRotorInertia(const Model& model, const std::string& name, const Eigen::Ref<const Eigen::VectorXd>& values);

// The per-solve friction overrides (breakaway, kinetic, viscous; empty: the
// model's): one per DOF, each finite and >= 0. ProblemError keyed as perJoint's.
void checkFrictionOverrides(const Model& model, const FrictionOptions& options);

// The ranges of the balance and friction options; ProblemError(Value) keyed by the option.
void checkBalance(const BalanceOptions& options);
void checkFriction(const FrictionOptions& options);

// A simulation's integrator: "euler" or "rk4"; ProblemError(Value) naming both.
Integrator parseIntegrator(const Spelling& spelling, const std::string& text);

// The most steps one simulation may write (each a row of the output).
constexpr long kMaxSimulationSteps = 1000000;
// The steps of a run of `duration` in steps of `dt` (the last one may end past it by less than a step):
// ProblemError(Value, "duration" or "dt") for a value not finite and > 0, or more than kMaxSimulationSteps steps.
long simulationSteps(double duration, double dt);

// A piecewise-linear schedule's knots: at least one, finite and strictly increasing (ProblemError(Value, "t")),
// with as many values (ProblemError(Value, "values")).
void checkSchedule(const std::vector<double>& t, std::size_t value_count);
// Its value at `time`: linear between knots, the first before them and the last after them.
void scheduleAt(const std::vector<double>& t, const std::vector<Eigen::VectorXd>& values, double time,
                Eigen::Ref<Eigen::VectorXd> out);

// The solve a problem asks for: with friction when it has friction options, else plain.
inline Status solve(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                    const Eigen::Ref<const Eigen::VectorXd>& qd, const Eigen::Ref<const Eigen::VectorXd>& tau,
                    const Task& task, const FrictionOptions* friction) {
  return friction ? solveWithFriction(model, ws, q, qd, tau, task, *friction)
                  : solveHybridDynamics(model, ws, q, qd, tau, task);
}

// Each one-DOF joint whose q lies outside its limits (NaN is the solve's to
// refuse), with its message; `q_offset` is subtracted from the joint's index
// in q for the message's "q[k]" (a front end whose q leaves the base out).
template <class Say>
void forEachOutsideLimits(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q, int q_offset, Say say);
std::string outsideLimitsMessage(const Joint& joint, double q, int index);

// The DOFs (Model::dofs() names) whose |τ_control| exceeds their joint's
// effort limit (URDF <limit effort>): reported, not enforced.
std::vector<std::string> beyondEffortLimit(const Model& model, const Eigen::VectorXd& tau_control);

// The name of the DOF a friction solve found moving into its limit
// (FrictionResult::impact_joint, an index below the root), and the warning
// that says so; empty when there is none.
std::string impactDofName(const Model& model, const FrictionResult& friction);
std::string limitImpactMessage(const Model& model, const FrictionResult& friction);

// What `zwang fk` prints (docs/cli.md, "zwang fk"): every frame's pose in the
// world (position, unit quaternion w first) and the robot's centre of mass.
struct FramePose {
  std::string name;
  Vec3 position = Vec3::Zero();
  Eigen::Vector4d quaternion{1.0, 0.0, 0.0, 0.0};  // frame → world, [w, x, y, z]
};
struct KinematicsReport {
  std::vector<FramePose> frames;  // Model::frames() order
  double mass = 0.0;              // of the moving bodies (subtreeMass, kWholeRobot)
  bool has_com = false;           // false without moving mass: the centre of mass is undefined
  Vec3 com = Vec3::Zero(), com_velocity = Vec3::Zero();
};
// At q (nq entries) and qd (nv); ProblemError(Value, "q" or "qd") with the
// library's message for a state the model refuses.
KinematicsReport kinematicsReport(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q,
                                  const Eigen::Ref<const Eigen::VectorXd>& qd);

template <class Say>
void forEachOutsideLimits(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q, int q_offset, Say say) {
  for (int j = 0; j < static_cast<int>(model.joints().size()); ++j) {
    const Joint& joint = model.joint(j);
    if (joint.nq() != 1) continue;  // multi-DOF joints have no position limits
    const double qj = q[joint.q_index];
    if (qj != qj || (qj >= joint.lower && qj <= joint.upper)) continue;
    say(j, outsideLimitsMessage(joint, qj, joint.q_index - q_offset));
  }
}

}  // namespace zwang::problem
