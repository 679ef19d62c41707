// Writing the solution of `zwang solve` as JSON.
#include "solution_writer.hpp"

#include <algorithm>
#include <string>

#include "cli.hpp"

namespace zwang::cli {

Json array(const Eigen::Ref<const Eigen::VectorXd>& v) {
  Json out = Json::array();
  for (Eigen::Index k = 0; k < v.size(); ++k) out.push_back(v[k]);
  return out;
}

namespace {

void pretty(const Json& value, int indent, std::string& out) {
  const std::string pad(static_cast<std::size_t>(indent), ' ');
  if (value.is_object() && !value.empty()) {
    out += "{\n";
    std::size_t k = 0;
    for (const auto& item : value.items()) {
      out += pad + "  " + Json(item.key()).dump() + ": ";
      pretty(item.value(), indent + 2, out);
      out += ++k < value.size() ? ",\n" : "\n";
    }
    out += pad + "}";
  } else if (value.is_array() && !value.empty()) {
    bool flat = true;
    for (const Json& element : value) flat = flat && !element.is_structured();
    if (flat) {
      out += "[";
      for (std::size_t k = 0; k < value.size(); ++k) out += (k ? ", " : "") + value[k].dump();
      out += "]";
    } else {
      out += "[\n";
      for (std::size_t k = 0; k < value.size(); ++k) {
        out += pad + "  ";
        pretty(value[k], indent + 2, out);
        out += k + 1 < value.size() ? ",\n" : "\n";
      }
      out += pad + "]";
    }
  } else {
    out += value.dump();
  }
}

// The robot's centre of mass in the solve's motion (world axes, classical acceleration); null when no moving
// body has mass (its centre of mass is undefined).
Json comJson(const Model& model, const Workspace& ws) {
  const Eigen::VectorXd& q = ws.kinematics.q;
  const Eigen::VectorXd& qd = ws.kinematics.qd;
  Vec3 position, velocity, acceleration;
  if (!centerOfMass(model, ws, q, kWholeRobot, position) ||
      !centerOfMassVelocity(model, ws, q, qd, kWholeRobot, velocity) ||
      !centerOfMassAcceleration(model, ws, q, qd, kWholeRobot, acceleration))
    return Json();
  return {{"position", array(position)}, {"velocity", array(velocity)}, {"acceleration", array(acceleration)}};
}

// The task's constraint wrench on frame f (constraintWrench: [f; n] at its origin), world and local axes.
void addConstraintWrench(const Model& model, const Workspace& ws, const Task& task, int f, Json& entry) {
  const auto wrench = [&](Expressed expressed) {
    Vec6 w;
    if (const Status s = constraintWrench(model, ws, task, ws.kinematics.q, f, expressed, w); !s)
      throw CliError(kExitError, std::string("solve: ") + s.message);
    return array(w);
  };
  entry["wrench_world"] = wrench(Expressed::World);
  entry["wrench_local"] = wrench(Expressed::Local);
}

}  // namespace

std::string prettyDump(const Json& value) {
  std::string out;
  pretty(value, 0, out);
  return out;
}

Json solutionJson(const Model& model, const Workspace& ws, const Task& task, bool with_friction, const Status& status,
                  const std::vector<int>& frames, const std::vector<int>& constrained_frames) {
  const Solution& s = ws.solution;
  Json out = Json::object();
  Json joints = Json::array();
  for (const Joint& joint : model.joints()) joints.push_back(joint.name);
  out["joints"] = std::move(joints);
  // The entries of the per-DOF arrays below: a one-DOF joint's name, "<joint>.<coordinate>" for a multi-DOF one.
  Json dofs = Json::array();
  for (int k = 0; k < model.dof(); ++k) dofs.push_back(problem::dofName(model, k));
  out["dofs"] = std::move(dofs);
  // Per DOF; a floating base's entries (they come first) go to "base".
  const int n = model.dof(), base_velocity_size = model.baseVelocitySize();
  out["qdd"] = array(s.qdd.tail(n));
  out["tau_constraint"] = array(s.tau_constraint.tail(n));
  out["tau_control"] = array(s.tau_control.tail(n));
  if (model.hasFloatingBase())
    out["base"] = {{"type", toString(model.baseType())},
                   {"acceleration", array(s.qdd.head(base_velocity_size))},
                   {"acceleration_world", array(s.base_acceleration_world)},
                   {"tau_constraint", array(s.tau_constraint.head(base_velocity_size))},
                   {"tau_control", array(s.tau_control.head(base_velocity_size))}};
  out["nu"] = array(s.nu);
  out["gauss"] = s.gauss;
  if (with_friction) {
    const FrictionResult& f = ws.friction;
    Json states = Json::array();
    for (const JointState state : f.state) states.push_back(toString(state));
    Json stuck = Json::array();  // DOF indices below the root, as names
    for (const int j : f.stuck) stuck.push_back(problem::dofName(model, j));
    const std::string impact = problem::impactDofName(model, f);
    out["friction"] = {{"mu", array(f.mu)},
                       {"state", std::move(states)},
                       {"tau_friction", array(f.tau_friction)},
                       {"stuck", std::move(stuck)},
                       {"gauss_dual", f.gauss_dual},
                       {"converged", f.converged},
                       {"indeterminate", f.indeterminate},
                       {"iterations", f.iterations},
                       {"kkt_residual", f.kkt_residual},
                       {"limit_impact", f.limit_impact},
                       {"impact_joint", impact.empty() ? Json() : Json(impact)}};
  }
  Json beyond = Json::array();
  for (const std::string& name : problem::beyondEffortLimit(model, s.tau_control)) beyond.push_back(name);
  out["effort_exceeded"] = std::move(beyond);
  out["status"] = {{"singular", s.balance.singular},
                   {"rows", s.balance.rows},
                   {"rank", s.balance.rank},
                   {"nu_unique", s.balance.nu_unique},
                   {"condition", s.balance.condition},
                   {"damping", s.balance.damping},
                   {"residual", s.balance.residual},
                   {"consistent", s.balance.consistent},
                   {"infeasible", status.code == StatusCode::Infeasible}};
  Json frame_map = Json::object();
  for (const int f : frames) {
    Vec6 a;
    if (const Status s = frameAcceleration(model, ws, ws.kinematics.q, ws.kinematics.qd, f, Expressed::World, a); !s)
      throw CliError(kExitError, std::string("solve: ") + s.message);
    Json& entry = frame_map[model.frame(f).name] = {{"acceleration_world", array(a)}};
    if (std::find(constrained_frames.begin(), constrained_frames.end(), f) != constrained_frames.end())
      addConstraintWrench(model, ws, task, f, entry);
  }
  out["frames"] = std::move(frame_map);
  out["com"] = comJson(model, ws);
  return out;
}

}  // namespace zwang::cli
