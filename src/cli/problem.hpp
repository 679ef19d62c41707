// The JSON problem of `zwang solve` (docs/cli.md, "Problem"): reading and
// checking it, then binding it to the loaded model as a Task.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "problem/problem.hpp"
#include "zwang/zwang.hpp"

namespace zwang::cli {

struct WrenchSpec {
  std::string path;  // "wrenches[k]", for messages
  std::string frame;
  Expressed expressed = Expressed::Local;
  Vec6 value = Vec6::Zero();  // [force; torque]
};

// "frame", "relative_to", "expressed_in" (default "reference" for a relative
// constraint), "directions" (A), "contact", or "joint" (a joint row).
struct ConstraintSpec {
  std::string path;              // "constraints[k]"
  problem::ConstraintDesc desc;  // what the problem layer adds to the Task
  Eigen::VectorXd acceleration;  // one per direction (default 0), one per DOF of a joint row
};

struct FrictionSpec {
  bool present = false;  // the problem has a "friction" section
  bool enabled = true;
  FrictionOptions options;
};

// "base": the state of a floating base (docs/cli.md, "Floating base").
struct BaseSpec {
  bool present = false;             // the problem has a "base" section
  BaseType type = BaseType::Fixed;  // "type": Free or Planar when present
  Eigen::VectorXd q;                // the base's coordinates: 7 (free: x y z, w x y z) or 3 (planar: x y yaw)
  Eigen::VectorXd v;                // its velocity coordinates: 6 (free: v, ω in base axes) or 3 (planar)
  Eigen::VectorXd force;            // "force": τ of the base, 6 or 3 entries (default 0)
};

// "q", "qd" or "tau": the joints' entries (below a floating base's root
// joint) as one array in the model's order, or by joint name (a number for a
// one-DOF joint, an array of its nq or nv entries for a multi-DOF one).
struct JointValues {
  std::optional<Eigen::VectorXd> array;                        // the array form
  std::vector<std::pair<std::string, Eigen::VectorXd>> named;  // the object form, in file order
  bool present() const { return array.has_value() || !named.empty(); }
};

// One entry of "joint_modes": "<joint or DOF>": "torque" | "locked" | {"acceleration": q̈ or [q̈, …]}.
struct JointModeSpec {
  std::string path;  // "joint_modes.<name>"
  problem::JointModeDesc desc;
};

// "simulate" (zwang simulate, docs/cli.md): the run's length, step and integrator.
struct SimulateSpec {
  bool present = false;
  double duration = 0.0;  // [s]
  double dt = 1e-3;       // [s]
  Integrator integrator = Integrator::SemiImplicitEuler;
  long steps = 0;  // ceil(duration / dt)
};

// "schedule": {"tau": {"t": [...], "values": [...]}}: τ at each time (each value like "tau"), piecewise linear.
struct ScheduleSpec {
  bool present = false;
  std::vector<double> t;
  std::vector<JointValues> values;
};

// The problem as written, checked for everything that does not need the model.
struct Problem {
  std::string file;        // the problem file, as given on the command line
  std::string model;       // "model", as written
  std::string model_path;  // resolved against the problem file's directory
  std::string root, tip;
  bool strict = false;             // "strict": refuse the model's warnings
  bool attach_beyond_tip = false;  // "attach_beyond_tip": weld the links beyond the tip as a payload
  bool lock_mimic = false;         // "lock_mimic": weld the mimic joints (MimicJoints::Lock)
  bool follow_leaders = false;  // "follow_leaders": each mimic joint's q, qd from its leader's (Model::followLeaders)
  std::optional<Vec3> gravity;
  JointValues q, qd, tau;
  std::optional<Eigen::VectorXd> rotor_inertia, breakaway;
  std::vector<WrenchSpec> wrenches;
  std::vector<ConstraintSpec> constraints;
  std::vector<JointModeSpec> joint_modes;  // "joint_modes", in file order (joints not named: torque-driven)
  FrictionSpec friction;
  BalanceOptions balance;  // "balance" (defaults when absent)
  BaseSpec base;           // "base" (a fixed base when absent, unless the URDF floats: then an error)
  SimulateSpec simulate;   // "simulate" (zwang simulate only)
  ScheduleSpec schedule;   // "schedule" (zwang simulate only)
};

// Read, parse and check a problem file; CliError "FILE: PATH: what" on any fault.
Problem readProblem(const std::string& file);

// The problem bound to its model: every length and frame checked.
struct BoundProblem {
  Model model;
  std::unique_ptr<Task> task;
  Eigen::VectorXd q, qd, tau;  // full length: q has nq() entries, qd and tau nv() (the base's first)
  bool with_friction = false;  // run solveWithFriction (else solveHybridDynamics)
  FrictionOptions friction_options;
  std::vector<int> reported_frames;  // constrained, reference or loaded frames, first appearance order
  // The reported frames the task's constraint rows act on: constrained or reference frames (not joint rows'),
  // whose constraint wrench the solution reports.
  std::vector<int> constrained_frames;
  // "schedule.tau" in full (nv entries each, the base's from "base.force"), at schedule_t.
  std::vector<double> schedule_t;
  std::vector<Eigen::VectorXd> schedule_tau;
};

// Load the model (rotor_inertia applied), check lengths and frames, build the
// Task. CliError "FILE: PATH: what" on any fault.
BoundProblem bindProblem(const Problem& problem);

}  // namespace zwang::cli
