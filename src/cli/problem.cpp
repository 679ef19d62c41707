// Reading the JSON problem of `zwang solve` and binding it to its model.
#include "problem.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "cli.hpp"
#include "json_reader.hpp"

namespace zwang::cli {

namespace {

// Messages quote JSON's way.
const problem::Spelling kJson{};

// The problem layer's fault at `path` (its key, when it names one, below it).
[[noreturn]] void fail(const JsonReader& in, const std::string& path, const problem::ProblemError& e) {
  in.fail(e.key().empty() ? path : childPath(path, e.key()), e.what());
}

// Run a step of the problem layer, its fault said at `path`.
template <class F>
auto atPath(const JsonReader& in, const std::string& path, F step) -> decltype(step()) {
  try {
    return step();
  } catch (const problem::ProblemError& e) {
    fail(in, path, e);
  }
}

Expressed parseExpressed(const JsonReader& in, const Json& value, const std::string& path, problem::AxesOf item) {
  const std::string text = in.string(value, path);
  return atPath(in, path, [&] { return problem::parseExpressed(kJson, text, item); });
}

WrenchSpec parseWrench(const JsonReader& in, const Json& value, const std::string& path) {
  in.object(value, path, {"frame", "expressed_in", "force", "torque"});
  WrenchSpec w;
  w.path = path;
  if (!value.contains("frame")) in.fail(path, "missing key \"frame\" (the link the wrench acts on)");
  w.frame = in.string(value["frame"], childPath(path, "frame"));
  if (value.contains("expressed_in"))
    w.expressed = parseExpressed(in, value["expressed_in"], childPath(path, "expressed_in"), problem::AxesOf::Wrench);
  if (value.contains("force"))
    w.value.head<3>() = in.numbers(value["force"], childPath(path, "force"), 3, "fx, fy, fz");
  if (value.contains("torque"))
    w.value.tail<3>() = in.numbers(value["torque"], childPath(path, "torque"), 3, "nx, ny, nz");
  return w;
}

// {"joint": NAME, "acceleration": [b]}: one row q̈_joint = b (Task::addJointConstraint).
ConstraintSpec parseJointRow(const JsonReader& in, const Json& value, const std::string& path) {
  in.object(value, path, {"joint", "acceleration"});
  ConstraintSpec c;
  c.path = path;
  c.desc.joint = in.string(value["joint"], childPath(path, "joint"));
  if (c.desc.joint.empty()) in.fail(childPath(path, "joint"), "is empty (name the joint whose acceleration is held)");
  // One per DOF of the joint (checked against the model in jointRowIndex); absent: zeros.
  if (value.contains("acceleration"))
    c.acceleration = in.numbers(value["acceleration"], childPath(path, "acceleration"));
  return c;
}

// "directions": the columns of A, and "acceleration", one per direction (default 0).
void parseDirections(const JsonReader& in, const Json& value, ConstraintSpec& c) {
  if (!value.contains("directions"))
    in.fail(c.path, "missing key \"directions\" (a list of 6-vectors, linear part first)");
  const std::string dpath = childPath(c.path, "directions");
  const Json& directions = in.array(value["directions"], dpath);
  if (directions.empty()) in.fail(dpath, "needs at least one direction");
  ConstraintMatrix& A = c.desc.A;
  A.resize(6, static_cast<Eigen::Index>(directions.size()));
  for (std::size_t k = 0; k < directions.size(); ++k)
    A.col(static_cast<Eigen::Index>(k)) =
        in.numbers(directions[k], childPath(dpath, k), 6, "linear part first: lx, ly, lz, rx, ry, rz");
  if (value.contains("acceleration"))
    c.acceleration =
        in.numbers(value["acceleration"], childPath(c.path, "acceleration"), A.cols(), "one per direction");
  else
    c.acceleration = Eigen::VectorXd::Zero(A.cols());
}

ConstraintSpec parseConstraint(const JsonReader& in, const Json& value, const std::string& path) {
  if (value.is_object() && value.contains("joint") && !value.contains("frame")) return parseJointRow(in, value, path);
  in.object(value, path, {"frame", "relative_to", "expressed_in", "directions", "acceleration", "contact"});
  ConstraintSpec c;
  c.path = path;
  problem::ConstraintDesc& d = c.desc;
  if (!value.contains("frame"))
    in.fail(path, "missing key \"frame\" (the link whose acceleration is constrained) or \"joint\" (a joint row)");
  d.frame = in.string(value["frame"], childPath(path, "frame"));
  const bool relative = value.contains("relative_to");
  if (relative) d.relative_to = in.string(value["relative_to"], childPath(path, "relative_to"));
  if (value.contains("contact")) d.contact = in.boolean(value["contact"], childPath(path, "contact"));
  atPath(in, path, [&] { problem::checkRelative(kJson, d, relative); });
  d.expressed = relative ? Expressed::Reference : Expressed::Local;  // the default axes
  if (value.contains("expressed_in"))
    d.expressed = parseExpressed(in, value["expressed_in"], childPath(path, "expressed_in"),
                                 relative ? problem::AxesOf::RelativeConstraint : problem::AxesOf::Constraint);
  parseDirections(in, value, c);
  return c;
}

// "joint_modes": {"<joint or DOF>": "torque" | "locked" | {"acceleration": q̈ or [one per DOF]}, …}.
std::vector<JointModeSpec> parseJointModes(const JsonReader& in, const Json& value, const std::string& path) {
  if (!value.is_object())
    in.fail(path, "must be an object of joint names to modes (\"locked\", \"torque\" or {\"acceleration\": …}), got " +
                      describe(value));
  std::vector<JointModeSpec> modes;
  for (const auto& item : value.items()) {  // not a structured binding: the lambda below reads the mode
    const Json& mode = item.value();
    JointModeSpec m;
    m.path = childPath(path, item.key());
    m.desc.name = item.key();
    if (mode.is_string()) {
      const std::string text = mode.get<std::string>();
      m.desc.kind = atPath(in, m.path, [&] { return problem::parseModeKind(kJson, text); });
    } else if (mode.is_object()) {
      in.object(mode, m.path, {"acceleration"});
      if (!mode.contains("acceleration")) in.fail(m.path, "needs \"acceleration\" (q̈, or one per DOF)");
      const Json& a = mode["acceleration"];
      const std::string a_path = childPath(m.path, "acceleration");
      m.desc.kind = problem::ModeKind::Acceleration;
      m.desc.acceleration = a.is_array() ? in.numbers(a, a_path) : Eigen::VectorXd::Constant(1, in.number(a, a_path));
    } else {
      in.fail(m.path, "must be \"torque\", \"locked\" or {\"acceleration\": …}, got " + describe(mode));
    }
    modes.push_back(std::move(m));
  }
  return modes;
}

FrictionSpec parseFriction(const JsonReader& in, const Json& value, const std::string& path) {
  in.object(value, path, {"enabled", "velocity_tolerance", "margin", "limits"});
  FrictionSpec f;
  f.present = true;
  if (value.contains("enabled")) f.enabled = in.boolean(value["enabled"], childPath(path, "enabled"));
  if (value.contains("velocity_tolerance"))
    f.options.velocity_tolerance = in.number(value["velocity_tolerance"], childPath(path, "velocity_tolerance"));
  if (value.contains("margin")) f.options.margin = in.number(value["margin"], childPath(path, "margin"));
  if (value.contains("limits")) f.options.joint_limits = in.boolean(value["limits"], childPath(path, "limits"));
  atPath(in, path, [&] { problem::checkFriction(f.options); });
  return f;
}

// The balance of line 25 (docs/solver.md, "Singular tasks"); its ranges are the problem layer's.
BalanceOptions parseBalance(const JsonReader& in, const Json& value, const std::string& path) {
  in.object(value, path, {"singular_threshold", "rank_tolerance", "residual_tolerance"});
  BalanceOptions o;
  for (const auto& [key, field] : {std::pair<const char*, double*>{"singular_threshold", &o.singular_threshold},
                                   {"rank_tolerance", &o.rank_tolerance},
                                   {"residual_tolerance", &o.residual_tolerance}})
    if (value.contains(key)) *field = in.number(value[key], childPath(path, key));
  atPath(in, path, [&] { problem::checkBalance(o); });
  return o;
}

// "base": {"type": "free", "position", "orientation", "linear_velocity",
// "angular_velocity", "force"} or {"type": "planar", "position", "yaw",
// "velocity", "force"}; every entry but "type" optional (the origin, the
// identity orientation, at rest, no force).
BaseSpec parseBase(const JsonReader& in, const Json& value, const std::string& path) {
  if (!value.is_object()) in.fail(path, "expected an object, got " + describe(value));
  if (!value.contains("type"))
    in.fail(path, "missing key \"type\" (\"free\" or \"planar\": how the base moves in the world)");
  const std::string tpath = childPath(path, "type");
  const std::string type = in.string(value["type"], tpath);
  BaseSpec b;
  b.present = true;
  const auto vector = [&](const char* key, long size, const std::string& what) -> Eigen::VectorXd {
    if (!value.contains(key)) return Eigen::VectorXd::Zero(size);
    return in.numbers(value[key], childPath(path, key), size, what);
  };
  b.type =
      atPath(in, tpath, [&] { return problem::parseBaseType(kJson, type, "a fixed base needs no \"base\" section"); });
  if (b.type == BaseType::Free) {
    in.object(value, path, {"type", "position", "orientation", "linear_velocity", "angular_velocity", "force"});
    b.q.resize(7);
    b.q.head<3>() = vector("position", 3, "x, y, z of the base origin in the world");
    b.q.tail<4>() << 1.0, 0.0, 0.0, 0.0;
    if (value.contains("orientation")) {
      const std::string opath = childPath(path, "orientation");
      const Eigen::Vector4d quaternion =
          in.numbers(value["orientation"], opath, 4, "a unit quaternion w, x, y, z: base to world");
      const double norm = quaternion.norm();
      if (norm == 0.0) in.fail(opath, "is zero: give a unit quaternion [w, x, y, z] (the identity: [1, 0, 0, 0])");
      if (std::abs(norm - 1.0) > kQuaternionNormTolerance) {
        std::string unit;
        for (int k = 0; k < 4; ++k) unit += (k ? ", " : "") + formatNumber(quaternion[k] / norm);
        in.fail(opath, "has norm " + formatNumber(norm) + ", not 1 within " + formatNumber(kQuaternionNormTolerance) +
                           ": write it normalised, [" + unit + "]");
      }
      b.q.tail<4>() = quaternion;
    }
    b.v.resize(6);
    b.v.head<3>() = vector("linear_velocity", 3, "the base origin's velocity in base axes");
    b.v.tail<3>() = vector("angular_velocity", 3, "in base axes");
    b.force = vector("force", 6, "fx, fy, fz, nx, ny, nz: a wrench at the base origin in base axes");
  } else {
    in.object(value, path, {"type", "position", "yaw", "velocity", "force"});
    b.q.resize(3);
    b.q.head<2>() = vector("position", 2, "x, y in the plane");
    b.q[2] = value.contains("yaw") ? in.number(value["yaw"], childPath(path, "yaw")) : 0.0;
    b.v = vector("velocity", 3, "x, y and yaw rates in the plane's axes");
    b.force = vector("force", 3, "fx, fy in the plane's axes and the torque about its normal");
  }
  return b;
}

// "q", "qd", "tau": an array, or an object of joint name → number or array.
JointValues parseJointValues(const JsonReader& in, const Json& value, const std::string& path) {
  JointValues v;
  if (!value.is_object()) {
    if (!value.is_array())
      in.fail(path, "expected an array (the joints' entries in the model's order) or an object (by joint name), got " +
                        describe(value));
    v.array = in.numbers(value, path);
    return v;
  }
  for (const auto& item : value.items()) {
    const std::string entry = childPath(path, item.key());
    if (item.value().is_number())
      v.named.emplace_back(item.key(), Eigen::VectorXd::Constant(1, in.number(item.value(), entry)));
    else
      v.named.emplace_back(item.key(), in.numbers(item.value(), entry));
  }
  return v;
}

// True when every joint below the root has one DOF (the per-joint arrays are then one per joint).
bool oneDofJoints(const Model& model) { return model.dof() == static_cast<int>(model.joints().size()); }

// The coordinates of a joint's q, for messages ("" for a one-DOF joint).
const char* coordinateNames(JointType type) {
  switch (type) {
    case JointType::Spherical: return "qw, qx, qy, qz";
    case JointType::Planar: return "x, y, yaw";
    case JointType::Free: return "x, y, z, qw, qx, qy, qz";
    default: return "";
  }
}

// What an array of the joints' q (configuration) or v (velocity) entries holds, for messages.
std::string layout(const Model& model, bool configuration) {
  if (!configuration) return problem::dofLayout(model);
  if (oneDofJoints(model)) return "one per moving joint: " + problem::jointNames(model);
  std::string list;
  for (const Joint& joint : model.joints()) {
    list += (list.empty() ? "" : ", ") + joint.name;
    if (joint.nq() > 1) list += std::string(" ") + toString(joint.type) + " [" + coordinateNames(joint.type) + "]";
  }
  return "the joints' coordinates in order: " + list;
}

// The index in joints() of the joint called `name` at `path` (the problem layer's message when unknown).
int jointIndexAt(const JsonReader& in, const Model& model, const std::string& name, const std::string& path) {
  return atPath(in, path, [&] { return problem::jointIndex(kJson, model, name); });
}

// The joint of a joint row, named in the error with the model's joints when unknown.
int jointRowIndex(const JsonReader& in, const Model& model, const ConstraintSpec& c) {
  const int j = jointIndexAt(in, model, c.desc.joint, childPath(c.path, "joint"));
  const Joint& joint = model.joint(j);
  if (c.acceleration.size() != 0 && c.acceleration.size() != joint.nv()) {
    std::string dofs;
    for (int k = 0; k < joint.nv(); ++k)
      dofs += (k ? ", " : "") + model.dofs()[static_cast<std::size_t>(joint.v_index + k)].name;
    in.fail(childPath(c.path, "acceleration"), "has " + std::to_string(c.acceleration.size()) +
                                                   (c.acceleration.size() == 1 ? " entry" : " entries") +
                                                   ", expected " + std::to_string(joint.nv()) +
                                                   " (one per DOF of joint '" + joint.name + "': " + dofs + ")");
  }
  return j;
}

// The joints' entries of "q" (configuration) or "qd"/"tau" (velocity) into `full` (the model's vector, a
// floating base's entries first), over the defaults already there.
void placeJointValues(const JsonReader& in, const Model& model, const JointValues& values, const char* key,
                      bool configuration, Eigen::VectorXd& full) {
  const int base = configuration ? model.baseConfigurationSize() : model.baseVelocitySize();
  const long n = (configuration ? model.nq() : model.nv()) - base;
  if (values.array) {
    const Eigen::VectorXd& v = *values.array;
    if (v.size() != n) {
      // A floating base's coordinates go in "base", not in front of the joints' as in the library.
      const bool with_base = model.hasFloatingBase() && (v.size() == model.nq() || v.size() == model.nv());
      in.fail(key, "has " + std::to_string(v.size()) + (v.size() == 1 ? " entry" : " entries") + ", expected " +
                       std::to_string(n) + " (" + layout(model, configuration) + ")" +
                       (with_base ? "; the base's state goes in \"base\", not here" : ""));
    }
    full.tail(n) = v;
    return;
  }
  for (const auto& [name, v] : values.named) {
    const std::string path = childPath(key, name);
    const Joint& joint = model.joint(jointIndexAt(in, model, name, path));
    const int size = configuration ? joint.nq() : joint.nv();
    if (v.size() != size) {
      std::string what = "one number";
      if (size > 1) {
        what = std::to_string(size) + " numbers: ";
        if (configuration) {
          what += coordinateNames(joint.type);
        } else {
          for (int k = 0; k < size; ++k)
            what += (k ? ", " : "") + model.dofs()[static_cast<std::size_t>(joint.v_index + k)].name;
        }
      }
      in.fail(path, "has " + std::to_string(v.size()) + (v.size() == 1 ? " entry" : " entries") + ", expected " + what +
                        " (joint '" + joint.name + "' is " + toString(joint.type) + ")");
    }
    full.segment(configuration ? joint.q_index : joint.v_index, size) = v;
  }
}

// The URDF options of the problem's keys, named as the problem names them in the loader's messages.
internal::NamedUrdfOptions urdfOptions(const Problem& p) {
  problem::ModelRequest request{p.root, p.tip, p.strict, p.attach_beyond_tip, p.lock_mimic, p.base.type, {}};
  request.names = {"\"tip\"", "\"rotor_inertia\"", "\"attach_beyond_tip\"", "\"lock_mimic\": true"};
  request.names.base = "base.type";
  internal::NamedUrdfOptions urdf = problem::urdfOptions(request);  // a fixed base when there is no "base"
  urdf.base_may_match_file = true;  // "base" also names a floating root joint of the file
  return urdf;
}

// The model (URDF or MJCF: the problem layer's choice) and the gravity its file states (MJCF).
Model loadModel(const JsonReader& in, const Problem& p, std::optional<Vec3>& file_gravity) {
  Model model;
  try {
    problem::LoadedModel loaded = problem::loadModelFile(p.model_path, urdfOptions(p));
    model = std::move(loaded.model);
    file_gravity = loaded.gravity;
  } catch (const ModelError& e) {
    // A relative "model" the loader could not open: say what it was resolved to and why.
    std::error_code ec;
    if (!std::filesystem::path(p.model).is_absolute() && !std::filesystem::is_regular_file(p.model_path, ec))
      in.fail("model", "\"" + printable(p.model, 200) + "\", relative to the problem file, is " + e.what());
    in.fail("model", e.what());
  }
  if (model.hasFloatingBase() && !p.base.present)
    in.fail("base", std::string(problem::isMjcfPath(p.model_path) ? "missing: the MJCF's free joint gives"
                                                                  : "missing: the URDF's root joint gives") +
                        " the robot a " + toString(model.baseType()) +
                        " base, whose state the problem must give: \"base\": {\"type\": \"" +
                        toString(model.baseType()) + "\", …} (docs/cli.md, \"Floating base\")");
  // An option that would change nothing is refused, as "breakaway" without "friction" is.
  if (p.follow_leaders && model.mimicJoints().empty())
    in.fail("follow_leaders", std::string("has no effect: the model has no mimic joints") +
                                  (p.lock_mimic ? " (\"lock_mimic\": true welded them)" : ""));
  return model;
}

// q, qd, tau in full: the base's coordinates first, then the joints' (docs/conventions.md, "Floating base").
// Unset entries: zero, each quaternion the identity (a free base's from "base").
void placeState(const JsonReader& in, const Problem& p, BoundProblem& b) {
  const Model& m = b.model;
  b.q = Eigen::VectorXd::Zero(m.nq());
  b.qd = Eigen::VectorXd::Zero(m.nv());
  b.tau = Eigen::VectorXd::Zero(m.nv());
  for (const Joint& joint : m.joints())
    if (joint.type == JointType::Spherical || joint.type == JointType::Free)
      b.q[joint.q_index + (joint.type == JointType::Free ? 3 : 0)] = 1.0;  // w first
  b.q.head(p.base.q.size()) = p.base.q;
  b.qd.head(p.base.v.size()) = p.base.v;
  b.tau.head(p.base.force.size()) = p.base.force;
  placeJointValues(in, m, p.q, "q", true, b.q);
  placeJointValues(in, m, p.qd, "qd", false, b.qd);
  placeJointValues(in, m, p.tau, "tau", false, b.tau);
  for (std::size_t k = 0; k < p.schedule.values.size(); ++k) {  // each knot as "tau", the base's force held
    Eigen::VectorXd tau = Eigen::VectorXd::Zero(m.nv());
    tau.head(p.base.force.size()) = p.base.force;
    placeJointValues(in, m, p.schedule.values[k], childPath("schedule.tau.values", k).c_str(), false, tau);
    b.schedule_tau.push_back(tau);
  }
  b.schedule_t = p.schedule.t;
  for (const ConstraintSpec& c : p.constraints)  // joint rows: every joint known, one target per DOF
    if (!c.desc.joint.empty()) (void)jointRowIndex(in, m, c);
  if (p.follow_leaders) m.followLeaders(b.q, b.qd);  // the followers' entries of "q" and "qd" are replaced
}

// A frame the solution reports: constrained, reference or loaded, in first appearance order; a constrained or
// reference frame also in constrained_frames (its constraint wrench is reported).
void reportFrame(BoundProblem& b, const std::string& name, bool constrained = false) {
  const int f = problem::frameIndex(b.model, name);
  if (constrained &&
      std::find(b.constrained_frames.begin(), b.constrained_frames.end(), f) == b.constrained_frames.end())
    b.constrained_frames.push_back(f);
  for (const int g : b.reported_frames)
    if (g == f) return;
  b.reported_frames.push_back(f);
}

// The Task: constraints (the problem layer's choice of Task::add*) with their targets, then the wrenches.
void buildTask(const JsonReader& in, const Problem& p, BoundProblem& b) {
  const Model& m = b.model;
  b.task = std::make_unique<Task>(m);
  Task& task = *b.task;
  if (p.gravity) task.gravity = *p.gravity;
  task.balance = p.balance;
  for (const ConstraintSpec& c : p.constraints) {
    const int first = atPath(in, c.path, [&] { return problem::addConstraint(kJson, m, task, c.desc); });
    Eigen::VectorXd targets = c.acceleration;
    if (!c.desc.joint.empty() && targets.size() == 0)
      targets = Eigen::VectorXd::Zero(m.joint(problem::jointIndex(kJson, m, c.desc.joint)).nv());
    task.targets().segment(first, targets.size()) = targets;
    if (c.desc.joint.empty()) reportFrame(b, c.desc.frame, true);
    if (!c.desc.relative_to.empty()) reportFrame(b, c.desc.relative_to, true);
  }
  for (const JointModeSpec& mode : p.joint_modes)
    atPath(in, mode.path, [&] { problem::setJointMode(kJson, m, task, mode.desc); });
  for (const WrenchSpec& w : p.wrenches) {
    const int k = atPath(in, w.path, [&] { return problem::addWrench(m, task, w.frame, w.expressed); });
    task.wrench(k) = w.value;
    reportFrame(b, w.frame);
  }
}

// "simulate": {"duration", "dt", "integrator"}; the ranges are the problem layer's.
SimulateSpec parseSimulate(const JsonReader& in, const Json& value, const std::string& path) {
  in.object(value, path, {"duration", "dt", "integrator"});
  SimulateSpec s;
  s.present = true;
  if (!value.contains("duration")) in.fail(childPath(path, "duration"), "missing (the simulated time [s])");
  s.duration = in.number(value["duration"], childPath(path, "duration"));
  if (value.contains("dt")) s.dt = in.number(value["dt"], childPath(path, "dt"));
  if (value.contains("integrator")) {
    const std::string text = in.string(value["integrator"], childPath(path, "integrator"));
    s.integrator = atPath(in, childPath(path, "integrator"), [&] { return problem::parseIntegrator(kJson, text); });
  }
  s.steps = atPath(in, path, [&] { return problem::simulationSteps(s.duration, s.dt); });
  return s;
}

// "schedule": {"tau": {"t": [t0, t1, …], "values": [τ0, τ1, …]}}, each τ_k as "tau" is written.
ScheduleSpec parseSchedule(const JsonReader& in, const Json& value, const std::string& path) {
  in.object(value, path, {"tau"});
  ScheduleSpec s;
  s.present = true;
  const std::string tau_path = childPath(path, "tau");
  if (!value.contains("tau")) in.fail(tau_path, "missing (\"t\" and \"values\")");
  const Json& tau = value["tau"];
  in.object(tau, tau_path, {"t", "values"});
  if (!tau.contains("t") || !tau.contains("values")) in.fail(tau_path, "needs \"t\" and \"values\"");
  const Eigen::VectorXd t = in.numbers(tau["t"], childPath(tau_path, "t"));
  s.t.assign(t.data(), t.data() + t.size());
  const Json& list = in.array(tau["values"], childPath(tau_path, "values"));
  for (std::size_t k = 0; k < list.size(); ++k)
    s.values.push_back(parseJointValues(in, list[k], childPath(childPath(tau_path, "values"), k)));
  atPath(in, tau_path, [&] { problem::checkSchedule(s.t, s.values.size()); });
  return s;
}

}  // namespace

Problem readProblem(const std::string& file) {
  const std::string text = readFile(file, kMaxInputBytes);
  const Json doc = parseJson(text, file);
  const JsonReader in(file);
  if (!doc.is_object()) in.fail("", "the problem must be a JSON object, got " + describe(doc));
  in.object(doc, "", {"model",       "root",           "tip",       "strict",   "attach_beyond_tip",
                      "lock_mimic",  "follow_leaders", "gravity",   "q",        "qd",
                      "tau",         "rotor_inertia",  "breakaway", "wrenches", "constraints",
                      "joint_modes", "friction",       "balance",   "base",     "simulate",
                      "schedule"});

  Problem p;
  p.file = file;
  if (!doc.contains("model")) in.fail("model", "missing (the URDF file, relative to the problem file)");
  const std::string model = in.string(doc["model"], "model");
  if (model.empty()) in.fail("model", "is empty");
  p.model = model;
  const std::filesystem::path model_path(model);
  p.model_path = model_path.is_absolute() ? model : (std::filesystem::path(file).parent_path() / model_path).string();

  if (doc.contains("root")) p.root = in.string(doc["root"], "root");
  if (doc.contains("tip")) p.tip = in.string(doc["tip"], "tip");
  if (doc.contains("strict")) p.strict = in.boolean(doc["strict"], "strict");
  if (doc.contains("attach_beyond_tip"))
    p.attach_beyond_tip = in.boolean(doc["attach_beyond_tip"], "attach_beyond_tip");
  if (doc.contains("lock_mimic")) p.lock_mimic = in.boolean(doc["lock_mimic"], "lock_mimic");
  if (doc.contains("follow_leaders")) p.follow_leaders = in.boolean(doc["follow_leaders"], "follow_leaders");
  if (doc.contains("gravity")) p.gravity = Vec3(in.numbers(doc["gravity"], "gravity", 3, "gx, gy, gz"));
  for (const char* key : {"q", "qd", "tau"})
    if (doc.contains(key)) (key[1] == '\0' ? p.q : key[1] == 'd' ? p.qd : p.tau) = parseJointValues(in, doc[key], key);
  if (doc.contains("rotor_inertia")) p.rotor_inertia = in.numbers(doc["rotor_inertia"], "rotor_inertia");
  if (doc.contains("breakaway")) p.breakaway = in.numbers(doc["breakaway"], "breakaway");
  if (doc.contains("wrenches")) {
    const Json& list = in.array(doc["wrenches"], "wrenches");
    for (std::size_t k = 0; k < list.size(); ++k)
      p.wrenches.push_back(parseWrench(in, list[k], childPath("wrenches", k)));
  }
  if (doc.contains("constraints")) {
    const Json& list = in.array(doc["constraints"], "constraints");
    for (std::size_t k = 0; k < list.size(); ++k)
      p.constraints.push_back(parseConstraint(in, list[k], childPath("constraints", k)));
  }
  if (doc.contains("joint_modes")) p.joint_modes = parseJointModes(in, doc["joint_modes"], "joint_modes");
  if (doc.contains("friction")) p.friction = parseFriction(in, doc["friction"], "friction");
  if (doc.contains("balance")) p.balance = parseBalance(in, doc["balance"], "balance");
  if (doc.contains("base")) p.base = parseBase(in, doc["base"], "base");
  if (doc.contains("simulate")) p.simulate = parseSimulate(in, doc["simulate"], "simulate");
  if (doc.contains("schedule")) p.schedule = parseSchedule(in, doc["schedule"], "schedule");
  if (p.schedule.present && !p.simulate.present)
    in.fail("schedule", "has no effect without a \"simulate\" section (zwang simulate runs it)");
  if (p.breakaway && !p.friction.present)
    in.fail("breakaway", "has no effect without a \"friction\" section (add \"friction\": {} to solve with friction)");
  return p;
}

BoundProblem bindProblem(const Problem& p) {
  const JsonReader in(p.file);
  std::optional<Vec3> file_gravity;
  Model model = loadModel(in, p, file_gravity);
  // The per-joint overrides by the problem layer's rules: their lengths against the model, each finite and >= 0.
  if (p.rotor_inertia)
    model = atPath(in, "", [&] { return problem::withRotorInertia(model, "rotor_inertia", *p.rotor_inertia); });
  FrictionOptions friction = p.friction.options;
  if (p.breakaway) friction.breakaway = *p.breakaway;
  atPath(in, "", [&] { problem::checkFrictionOverrides(model, friction); });
  BoundProblem b{std::move(model), nullptr, {}, {}, {}, false, std::move(friction), {}, {}, {}, {}};
  placeState(in, p, b);
  buildTask(in, p, b);
  if (!p.gravity && file_gravity) b.task->gravity = *file_gravity;  // an MJCF file's gravity, unless the problem's
  b.with_friction = p.friction.present && p.friction.enabled;
  return b;
}

}  // namespace zwang::cli
