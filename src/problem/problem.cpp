// The problem layer's checks and messages (problem.hpp).
#include "problem.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

namespace zwang::problem {

namespace {

// Length of the valid UTF-8 sequence starting at text[at], 0 if it is not one
// (a stray continuation byte, an overlong or truncated sequence).
std::size_t utf8Length(const std::string& text, std::size_t at) {
  const auto lead = static_cast<unsigned char>(text[at]);
  const std::size_t length = lead >= 0xF0 && lead <= 0xF4 ? 4 : lead >= 0xE0 ? 3 : lead >= 0xC2 && lead < 0xE0 ? 2 : 0;
  if (length == 0 || at + length > text.size()) return 0;
  for (std::size_t k = 1; k < length; ++k)
    if ((static_cast<unsigned char>(text[at + k]) & 0xC0) != 0x80) return 0;
  return length;
}

// A number as %g writes it: the short form users typed.
std::string number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", value);
  return buffer;
}

[[noreturn]] void badValue(const std::string& key, const std::string& what, double value) {
  throw ProblemError(Fault::Value, key, what + ", got " + number(value));
}

// "1 entry", "3 entries".
std::string entries(Eigen::Index n) { return std::to_string(n) + (n == 1 ? " entry" : " entries"); }

// Each entry of a per-joint array finite and >= 0 (NaN fails the comparison).
void checkEntries(const std::string& name, const Eigen::Ref<const Eigen::VectorXd>& values) {
  for (Eigen::Index k = 0; k < values.size(); ++k)
    if (!(values[k] >= 0.0 && std::isfinite(values[k])))
      throw ProblemError(Fault::Value, name + "[" + std::to_string(k) + "]",
                         "must be finite and >= 0, got " + number(values[k]));
}

// The one value of each joint from an array of one per DOF; ProblemError(Model) where a joint's DOFs disagree.
Eigen::VectorXd jointsOfDofs(const Model& model, const std::string& name, const Eigen::Ref<const Eigen::VectorXd>& v) {
  Eigen::VectorXd per_joint(static_cast<Eigen::Index>(model.joints().size()));
  for (std::size_t j = 0; j < model.joints().size(); ++j) {
    const Joint& joint = model.joints()[j];
    const int first = joint.v_index - model.baseVelocitySize();
    per_joint[static_cast<Eigen::Index>(j)] = v[first];
    for (int k = first + 1; k < first + joint.nv(); ++k)
      if (v[k] != v[first])
        throw ProblemError(Fault::Model, name,
                           "entries " + std::to_string(first) + "-" + std::to_string(first + joint.nv() - 1) +
                               " (the DOFs of joint '" + joint.name +
                               "') differ: a joint has one value for all its DOFs");
  }
  return per_joint;
}

// A fault of the model's (a ModelError) as the part `key` of the item.
template <class F>
auto keyed(const char* key, F lookup) -> decltype(lookup()) {
  try {
    return lookup();
  } catch (const ProblemError& e) {
    throw ProblemError(e.fault(), key, e.what());
  } catch (const ModelError& e) {
    throw ProblemError(Fault::Model, key, e.what());
  }
}

}  // namespace

ProblemError::ProblemError(Fault fault, std::string key, const std::string& what)
    : std::runtime_error(what), fault_(fault), key_(std::move(key)) {}

std::string jointNames(const Model& model) {
  std::string list;
  for (const Joint& joint : model.joints()) list += (list.empty() ? "" : ", ") + joint.name;
  return list;
}

std::string printable(const std::string& text, std::size_t max_length) {
  std::string out;
  for (std::size_t at = 0; at < text.size();) {
    const auto c = static_cast<unsigned char>(text[at]);
    std::string piece;
    std::size_t used = 1;
    if (c >= 0x20 && c < 0x7f) {
      piece = text.substr(at, 1);
    } else if (const std::size_t n = c >= 0x80 ? utf8Length(text, at) : 0; n > 0) {
      piece = text.substr(at, n);  // UTF-8 (names, "…", "·") passes through whole
      used = n;
    } else {
      char buffer[8];
      std::snprintf(buffer, sizeof buffer, "\\x%02X", static_cast<unsigned>(c));
      piece = buffer;
    }
    if (out.size() + piece.size() > max_length) {  // cut between characters, never inside one
      out += "...";
      break;
    }
    out += piece;
    at += used;
  }
  return out;
}

std::string quoted(const Spelling& spelling, const std::string& text, std::size_t max_length) {
  return spelling.quote + printable(text, max_length) + spelling.quote;
}

Expressed parseExpressed(const Spelling& spelling, const std::string& text, AxesOf item) {
  if (text == "local") return Expressed::Local;
  if (text == "world") return Expressed::World;
  if (item != AxesOf::Wrench && text == "aligned") return Expressed::Aligned;
  if (item == AxesOf::RelativeConstraint && text == "reference") return Expressed::Reference;
  const auto q = [&](const char* word) { return quoted(spelling, word); };
  const std::string expected = item == AxesOf::Wrench ? q("local") + " or " + q("world")
                               : item == AxesOf::Constraint
                                   ? q("local") + ", " + q("world") + " or " + q("aligned")
                                   : q("local") + ", " + q("world") + ", " + q("aligned") + " or " + q("reference");
  const std::string hint = text == "reference" && item == AxesOf::Constraint
                               ? "; " + q("reference") + " is for a constraint with " + q("relative_to")
                               : "";
  throw ProblemError(Fault::Value, "",
                     "unknown value " + quoted(spelling, text, 40) + " (expected " + expected + hint + ")");
}

internal::NamedUrdfOptions urdfOptions(const ModelRequest& request) {
  internal::NamedUrdfOptions urdf;
  urdf.root = request.root;
  urdf.tip = request.tip;
  urdf.strict = request.strict;
  urdf.attach_beyond_tip = request.attach_beyond_tip;
  urdf.mimic = request.lock_mimic ? MimicJoints::Lock : MimicJoints::Model;
  urdf.base = request.base;
  urdf.names = request.names;
  return urdf;
}

BaseType parseBaseType(const Spelling& spelling, const std::string& text, const char* no_fixed) {
  if (text == "free") return BaseType::Free;
  if (text == "planar") return BaseType::Planar;
  if (!no_fixed && text == "fixed") return BaseType::Fixed;
  const auto q = [&](const char* word) { return quoted(spelling, word); };
  const std::string expected =
      no_fixed ? q("free") + " or " + q("planar") : q("fixed") + ", " + q("free") + " or " + q("planar");
  const std::string hint = no_fixed && text == "fixed" ? std::string("; ") + no_fixed : "";
  throw ProblemError(Fault::Value, "",
                     "unknown value " + quoted(spelling, text, 40) + " (expected " + expected + hint + ")");
}

void checkRelative(const Spelling& spelling, const ConstraintDesc& c, bool relative_given) {
  if (relative_given && c.relative_to.empty())
    throw ProblemError(Fault::Value, "relative_to", "is empty (name the frame the constraint is relative to)");
  if (relative_given &&
      c.relative_to == c.frame)  // a frame name that cannot be: a fault of the names, as an unknown one
    throw ProblemError(Fault::Model, "relative_to",
                       "is the constrained frame itself (" + quoted(spelling, c.frame) +
                           "): a relative constraint needs another frame to refer to");
  if (c.contact && !c.relative_to.empty())
    throw ProblemError(Fault::Value, "contact",
                       "is true with " + quoted(spelling, "relative_to") +
                           ": a relative constraint holds two links of the robot together and the motors give its "
                           "force; a contact is a link against the environment");
}

int frameIndex(const Model& model, const std::string& name) {
  try {
    return model.frameIndex(name);
  } catch (const ModelError& e) {  // the library's message names the model's frames
    throw ProblemError(Fault::Model, "", e.what());
  }
}

int jointIndex(const Spelling& spelling, const Model& model, const std::string& name) {
  for (int k = 0; k < static_cast<int>(model.joints().size()); ++k)
    if (model.joint(k).name == name) return k;
  if (model.hasFloatingBase() && name == model.allJoints().front().name)
    throw ProblemError(Fault::Model, "",
                       "names the root joint of the " + std::string(toString(model.baseType())) + " base: its state " +
                           spelling.base_state);
  throw ProblemError(Fault::Model, "",
                     "unknown joint " + quoted(spelling, name) + " (the model's joints: " + jointNames(model) + ")");
}

int addConstraint(const Spelling& spelling, const Model& model, Task& task, const ConstraintDesc& c) {
  if (!c.joint.empty()) {
    const int j = keyed("joint", [&] { return jointIndex(spelling, model, c.joint); });
    return keyed("joint", [&] { return task.addJointConstraint(j); });
  }
  const int f = keyed("frame", [&] { return frameIndex(model, c.frame); });
  if (c.contact) return keyed("", [&] { return task.addContact(f, c.A, c.expressed); });
  if (c.relative_to.empty()) return keyed("", [&] { return task.addConstraint(f, c.A, c.expressed); });
  const int reference = keyed("relative_to", [&] { return frameIndex(model, c.relative_to); });
  return keyed("", [&] { return task.addRelativeConstraint(f, reference, c.A, c.expressed); });
}

ModeKind parseModeKind(const Spelling& spelling, const std::string& text) {
  if (text == "torque") return ModeKind::Torque;
  if (text == "locked") return ModeKind::Locked;
  const char q = spelling.quote;
  throw ProblemError(Fault::Value, "",
                     "unknown mode " + quoted(spelling, text) + " (use " + q + "torque" + q + ", " + q + "locked" + q +
                         " or {" + q + "acceleration" + q + ": q̈} for a prescribed acceleration)");
}

namespace {
// The DOFs a mode's name covers: a joint's [v_index, v_index + nv), or one DOF of a multi-DOF joint by its name.
std::pair<int, int> modeDofs(const Spelling& spelling, const Model& model, const std::string& name) {
  for (const Joint& joint : model.joints())
    if (joint.name == name) return {joint.v_index, joint.nv()};
  for (int k = 0; k < model.dof(); ++k)
    if (dofName(model, k) == name) return {model.baseVelocitySize() + k, 1};
  return {model.joint(jointIndex(spelling, model, name)).v_index, 0};  // throws, naming the joints
}
}  // namespace

void setJointMode(const Spelling& spelling, const Model& model, Task& task, const JointModeDesc& mode) {
  const std::pair<int, int> covered = modeDofs(spelling, model, mode.name);
  const int first = covered.first, dofs = covered.second;  // named: a lambda cannot capture a structured binding
  if (mode.kind == ModeKind::Acceleration) {
    if (mode.acceleration.size() != dofs)
      throw ProblemError(Fault::Value, "acceleration",
                         "has " + entries(mode.acceleration.size()) + ", expected " + std::to_string(dofs) +
                             " (one per DOF of " + quoted(spelling, mode.name) + ")");
    for (Eigen::Index k = 0; k < dofs; ++k)
      if (!std::isfinite(mode.acceleration[k]))
        throw ProblemError(Fault::Value, "acceleration[" + std::to_string(k) + "]",
                           "must be finite, got " + number(mode.acceleration[k]));
  }
  const DofMode dof_mode = mode.kind == ModeKind::Torque ? DofMode::Torque : DofMode::Prescribed;
  keyed("", [&] {
    for (int k = 0; k < dofs; ++k) task.setDofMode(first + k, dof_mode);
    return 0;
  });
  if (mode.kind == ModeKind::Locked) task.prescribedAccelerations().segment(first, dofs).setZero();
  if (mode.kind == ModeKind::Acceleration) task.prescribedAccelerations().segment(first, dofs) = mode.acceleration;
}

int addWrench(const Model& model, Task& task, const std::string& frame, Expressed expressed) {
  const int f = keyed("frame", [&] { return frameIndex(model, frame); });
  return keyed("", [&] { return task.addWrench(f, expressed); });
}

const std::string& dofName(const Model& model, int dof) {
  return model.dofs()[static_cast<std::size_t>(model.baseVelocitySize() + dof)].name;
}

std::string dofLayout(const Model& model) {
  if (model.dof() == static_cast<int>(model.joints().size())) return "one per moving joint: " + jointNames(model);
  std::string list;
  for (int k = 0; k < model.dof(); ++k) list += (list.empty() ? "" : ", ") + dofName(model, k);
  return "one per DOF: " + list;
}

Eigen::VectorXd perJoint(const Model& model, const std::string& name, const Eigen::Ref<const Eigen::VectorXd>& values) {
  const auto joints = static_cast<Eigen::Index>(model.joints().size());
  if (values.size() != joints && values.size() != model.dof()) {
    const std::string or_dofs =
        model.dof() == joints ? "" : " or " + std::to_string(model.dof()) + " (" + dofLayout(model) + ")";
    throw ProblemError(Fault::Model, name,
                       "has " + entries(values.size()) + ", expected " + std::to_string(joints) +
                           " (one per moving joint: " + jointNames(model) + ")" + or_dofs);
  }
  checkEntries(name, values);
  return values.size() == joints ? Eigen::VectorXd(values) : jointsOfDofs(model, name, values);
}

Model withRotorInertia(const Model& model, const std::string& name, const Eigen::Ref<const Eigen::VectorXd>& values) {
  const Eigen::VectorXd inertia = perJoint(model, name, values);
  return keyed(name.c_str(), [&] {
    ModelBuilder builder(model);
    for (std::size_t j = 0; j < model.joints().size(); ++j)
      builder.setRotorInertia(model.joints()[j].name, inertia[static_cast<Eigen::Index>(j)]);
    return builder.build();
  });
}

void checkFrictionOverrides(const Model& model, const FrictionOptions& o) {
  const std::pair<const char*, const Eigen::VectorXd*> overrides[] = {
      {"breakaway", &o.breakaway}, {"kinetic", &o.kinetic}, {"viscous", &o.viscous}};
  for (const auto& [name, values] : overrides) {
    if (values->size() == 0) continue;  // the model's
    if (values->size() != model.dof())
      throw ProblemError(Fault::Model, name,
                         "has " + entries(values->size()) + ", expected " + std::to_string(model.dof()) + " (" +
                             dofLayout(model) + ")");
    checkEntries(name, *values);
  }
}

void checkBalance(const BalanceOptions& o) {
  // The equilibrated eigenvalues lie in [0, m] with one at least 1: a threshold of 1 calls every task singular.
  if (!(o.singular_threshold > 0.0 && o.singular_threshold < 1.0))
    badValue("singular_threshold", "must be between 0 and 1 (exclusive)", o.singular_threshold);
  if (!(o.rank_tolerance >= 0.0 && o.rank_tolerance < o.singular_threshold))
    badValue("rank_tolerance", "must be >= 0 and below singular_threshold (" + number(o.singular_threshold) + ")",
             o.rank_tolerance);
  if (!(o.residual_tolerance > 0.0 && std::isfinite(o.residual_tolerance)))
    badValue("residual_tolerance", "must be finite and positive", o.residual_tolerance);
}

Integrator parseIntegrator(const Spelling& spelling, const std::string& text) {
  if (text == "euler") return Integrator::SemiImplicitEuler;
  if (text == "rk4") return Integrator::RungeKutta4;
  throw ProblemError(Fault::Value, "",
                     "unknown integrator " + quoted(spelling, text) + " (one of " + quoted(spelling, "euler") + ", " +
                         quoted(spelling, "rk4") + ")");
}

long simulationSteps(double duration, double dt) {
  if (!(duration > 0.0 && std::isfinite(duration))) badValue("duration", "must be finite and > 0 [s]", duration);
  if (!(dt > 0.0 && std::isfinite(dt))) badValue("dt", "must be finite and > 0 [s]", dt);
  const double steps = std::ceil(duration / dt - 1e-9);  // a duration that is a whole number of steps, to rounding
  if (!(steps <= static_cast<double>(kMaxSimulationSteps)))
    throw ProblemError(Fault::Value, "dt",
                       "gives " + number(steps) + " steps for duration " + number(duration) + " s; at most " +
                           std::to_string(kMaxSimulationSteps) + " (a larger dt or a shorter run)");
  return static_cast<long>(steps);
}

void checkSchedule(const std::vector<double>& t, std::size_t value_count) {
  if (t.empty()) throw ProblemError(Fault::Value, "t", "is empty (at least one time)");
  for (std::size_t k = 0; k < t.size(); ++k) {
    if (!std::isfinite(t[k])) badValue("t[" + std::to_string(k) + "]", "must be finite", t[k]);
    if (k > 0 && !(t[k] > t[k - 1]))
      badValue("t[" + std::to_string(k) + "]",
               "must be after t[" + std::to_string(k - 1) + "] (" + number(t[k - 1]) + ")", t[k]);
  }
  if (value_count != t.size())
    throw ProblemError(Fault::Value, "values",
                       "has " + std::to_string(value_count) + " entries, expected one per time (" +
                           std::to_string(t.size()) + ")");
}

void scheduleAt(const std::vector<double>& t, const std::vector<Eigen::VectorXd>& values, double time,
                Eigen::Ref<Eigen::VectorXd> out) {
  if (time <= t.front()) {
    out = values.front();
    return;
  }
  if (time >= t.back()) {
    out = values.back();
    return;
  }
  const std::size_t k =
      static_cast<std::size_t>(std::upper_bound(t.begin(), t.end(), time) - t.begin());  // t[k−1] < time < t[k]
  const double w = (time - t[k - 1]) / (t[k] - t[k - 1]);
  out = (1.0 - w) * values[k - 1] + w * values[k];
}

void checkFriction(const FrictionOptions& o) {
  if (!(o.velocity_tolerance >= 0.0 && std::isfinite(o.velocity_tolerance)))
    badValue("velocity_tolerance", "must be finite and >= 0", o.velocity_tolerance);
  if (!(o.limit_tolerance >= 0.0 && std::isfinite(o.limit_tolerance)))
    badValue("limit_tolerance", "must be finite and >= 0", o.limit_tolerance);
  if (!(o.margin >= 0.0 && o.margin <= 1.0)) badValue("margin", "must be between 0 and 1", o.margin);
  if (o.max_iterations < 1) badValue("max_iterations", "must be at least 1", o.max_iterations);
  if (!(o.kkt_tolerance > 0.0 && std::isfinite(o.kkt_tolerance)))
    badValue("kkt_tolerance", "must be finite and positive", o.kkt_tolerance);
}

std::string outsideLimitsMessage(const Joint& joint, double q, int index) {
  return "q[" + std::to_string(index) + "] = " + number(q) + " puts joint '" + printable(joint.name, 4000) +
         "' outside its limits [" + number(joint.lower) + ", " + number(joint.upper) + "]";
}

std::vector<std::string> beyondEffortLimit(const Model& model, const Eigen::VectorXd& tau_control) {
  std::vector<std::string> names;
  for (std::size_t v = 0; v < model.dofs().size(); ++v) {
    const Dof& dof = model.dofs()[v];
    if (dof.joint < 0) continue;  // the floating root is unactuated
    if (std::abs(tau_control[static_cast<Eigen::Index>(v)]) > model.joint(dof.joint).effort_limit)
      names.push_back(dof.name);
  }
  return names;
}

std::string impactDofName(const Model& model, const FrictionResult& friction) {
  if (!friction.limit_impact || friction.impact_joint < 0) return {};
  return dofName(model, friction.impact_joint);
}

std::string limitImpactMessage(const Model& model, const FrictionResult& friction) {
  const std::string name = impactDofName(model, friction);
  if (name.empty()) return {};
  return "joint '" + printable(name, 4000) +
         "' moves into its limit: stopping it needs an impulse, which the solve does not model "
         "(friction.limit_impact)";
}

KinematicsReport kinematicsReport(const Model& model, const Eigen::Ref<const Eigen::VectorXd>& q,
                                  const Eigen::Ref<const Eigen::VectorXd>& qd) {
  Workspace ws(model, 0);
  if (const Status s = forwardKinematics(model, ws, q, qd); !s)
    throw ProblemError(Fault::Value, s.message[0] == 'q' && s.message[1] == 'd' ? "qd" : "q", s.message);
  KinematicsReport report;
  for (int f = 0; f < static_cast<int>(model.frames().size()); ++f) {
    Eigen::Isometry3d pose;
    (void)framePose(model, ws, q, f, pose);  // the state just computed: nothing to refuse
    const Eigen::Quaterniond turn(pose.linear());
    report.frames.push_back({model.frame(f).name, pose.translation(), {turn.w(), turn.x(), turn.y(), turn.z()}});
  }
  (void)subtreeMass(model, kWholeRobot, report.mass);
  report.has_com = centerOfMass(model, ws, q, kWholeRobot, report.com) &&
                   centerOfMassVelocity(model, ws, q, qd, kWholeRobot, report.com_velocity);
  return report;
}

}  // namespace zwang::problem
