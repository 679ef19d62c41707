// Python: Workspace, Constraint, Wrench, Friction, Result, solve() and the
// kinematics / inverse-dynamics helpers.
#include <pybind11/stl.h>

#include <algorithm>
#include <chrono>

#include "bindings.hpp"

namespace zwang::python {

static_assert(sizeof(Vec6) == 6 * sizeof(double), "Vec6 rows are viewed as a dense (n, 6) array");

namespace {

std::uint64_t g_next_serial = 1;  // guarded by the GIL

const Vec3 kDefaultGravity(0.0, 0.0, -9.81);

// The code of a solve's q outside a joint's limits in Result.warnings (the
// task's warnings have their WarningCode's name).
const char* const kOutsideLimits = "outside_limits";
const char* const kLimitImpact = "limit_impact";

PyWorkspace& workspaceArg(const std::shared_ptr<Model>& model, py::handle ws_obj) {
  if (!py::isinstance<PyWorkspace>(ws_obj))
    raise(PyExc_TypeError, "ws: expected a zwang.Workspace (model.workspace()), got " +
                               std::string(py::str(py::type::handle_of(ws_obj).attr("__name__"))));
  PyWorkspace& pw = ws_obj.cast<PyWorkspace&>();
  if (!model) raise(PyExc_TypeError, "model: expected a zwang.Model, got None");
  if (pw.model.get() != model.get()) {
    Status s =
        Status::error(StatusCode::ModelMismatch, "the workspace was made for model '%s', not for this model '%s'",
                      pw.model->name().c_str(), model->name().c_str());
    raiseStatus(s, "solve");
  }
  return pw;
}

int frameArg(const Model& model, py::handle frame) {
  if (py::isinstance<py::str>(frame)) return model.frameIndex(frame.cast<std::string>());
  if (py::isinstance<py::int_>(frame) && !py::isinstance<py::bool_>(frame)) {
    const long f = frame.cast<long>();
    if (f < 0 || f >= static_cast<long>(model.frames().size()))
      raise(exceptions().model_error, "frame index " + std::to_string(f) + " is out of range (the model has " +
                                          std::to_string(model.frames().size()) + " frames)");
    return static_cast<int>(f);
  }
  raise(PyExc_TypeError, "frame: expected a frame name (str) or index (int)");
}

// The items of a list or tuple of T (a single T is taken as a list of one).
template <class T>
void collect(const char* name, py::handle value, std::vector<T*>& out) {
  out.clear();
  if (value.is_none()) return;
  if (py::isinstance<T>(value)) {
    out.push_back(&value.cast<T&>());
    return;
  }
  if (!py::isinstance<py::list>(value) && !py::isinstance<py::tuple>(value))
    raise(PyExc_TypeError, std::string(name) + ": expected a list of zwang." +
                               (std::is_same_v<T, Constraint> ? "Constraint" : "Wrench") + ", got " +
                               std::string(py::str(py::type::handle_of(value).attr("__name__"))));
  const py::sequence seq = py::reinterpret_borrow<py::sequence>(value);
  const std::size_t n = seq.size();
  for (std::size_t k = 0; k < n; ++k) {
    py::handle item = PySequence_Fast_GET_ITEM(seq.ptr(), static_cast<py::ssize_t>(k));
    if (!py::isinstance<T>(item))
      raise(PyExc_TypeError, std::string(name) + "[" + std::to_string(k) + "]: expected zwang." +
                                 (std::is_same_v<T, Constraint> ? "Constraint" : "Wrench") + ", got " +
                                 std::string(py::str(py::type::handle_of(item).attr("__name__"))));
    out.push_back(&item.cast<T&>());
  }
}

template <class T>
bool sameSerials(const std::vector<T*>& items, const std::vector<std::uint64_t>& serials) {
  if (items.size() != serials.size()) return false;
  for (std::size_t k = 0; k < items.size(); ++k)
    if (items[k]->serial != serials[k]) return false;
  return true;
}

template <class T>
void copySerials(const std::vector<T*>& items, std::vector<std::uint64_t>& serials) {
  serials.clear();
  for (const T* item : items) serials.push_back(item->serial);
}

// Reused between calls (the GIL serialises them).
std::vector<Constraint*> g_constraints;
std::vector<Wrench*> g_wrenches;

// The frames of g_wrenches into a task being built (the problem layer's
// ModelError "wrenches[k].frame: …" for an unknown frame).
void addWrenches(const Model& model, Task& task) {
  for (std::size_t k = 0; k < g_wrenches.size(); ++k) {
    const Wrench& w = *g_wrenches[k];
    checked("wrenches[" + std::to_string(k) + "]",
            [&] { return problem::addWrench(model, task, w.frame, w.expressed); });
  }
}

// What changes between calls without a rebuild: the wrench values and gravity.
void writeWrenchesAndGravity(Task& task, py::handle gravity) {
  for (std::size_t k = 0; k < g_wrenches.size(); ++k) task.wrench(static_cast<int>(k)) = g_wrenches[k]->value;
  task.gravity = gravity.is_none() ? kDefaultGravity : vec3Arg("gravity", gravity);
}

// The workspace's task for these constraints and wrenches: rebuilt (allocating)
// only when the objects differ from the last call; then only b, the wrench
// values and gravity are written.
Task& solveTask(PyWorkspace& pw, py::handle constraints, py::handle wrenches, py::handle gravity) {
  collect("constraints", constraints, g_constraints);
  collect("wrenches", wrenches, g_wrenches);
  if (!pw.task_valid || !sameSerials(g_constraints, pw.constraint_serials) ||
      !sameSerials(g_wrenches, pw.wrench_serials)) {
    auto task = std::make_unique<Task>(*pw.model);
    std::vector<int> first_rows;
    for (std::size_t k = 0; k < g_constraints.size(); ++k)  // the problem layer's choice of Task::add*
      first_rows.push_back(checked("constraints[" + std::to_string(k) + "]", [&] {
        return problem::addConstraint(kPython, *pw.model, *task, g_constraints[k]->desc);
      }));
    addWrenches(*pw.model, *task);
    pw.ensureCapacity(task->constraintRows());
    pw.task = std::move(task);
    pw.constraint_rows = std::move(first_rows);
    copySerials(g_constraints, pw.constraint_serials);
    copySerials(g_wrenches, pw.wrench_serials);
    pw.task_valid = true;
    ++pw.task_builds;
  }
  Task& task = *pw.task;
  for (std::size_t k = 0; k < g_constraints.size(); ++k)
    task.targets().segment(pw.constraint_rows[k], g_constraints[k]->b.size()) = g_constraints[k]->b;
  writeWrenchesAndGravity(task, gravity);
  return task;
}

Task& idTask(PyWorkspace& pw, py::handle wrenches, py::handle gravity) {
  collect("wrenches", wrenches, g_wrenches);
  if (!pw.id_task_valid || !sameSerials(g_wrenches, pw.id_wrench_serials)) {
    auto task = std::make_unique<Task>(*pw.model);
    addWrenches(*pw.model, *task);
    pw.id_task = std::move(task);
    copySerials(g_wrenches, pw.id_wrench_serials);
    pw.id_task_valid = true;
  }
  Task& task = *pw.id_task;
  writeWrenchesAndGravity(task, gravity);
  return task;
}

// q̇ or τ: None means zeros.
Eigen::Map<const Eigen::VectorXd> optionalVector(const char* name, py::handle value, Eigen::VectorXd& buffer,
                                                 const Eigen::VectorXd& zeros) {
  if (value.is_none()) return {zeros.data(), zeros.size()};
  return vectorArg(name, value, buffer);
}

const FrictionOptions* frictionArg(py::handle friction) {
  static const FrictionOptions defaults;
  if (friction.is_none()) return nullptr;
  if (py::isinstance<py::bool_>(friction)) return friction.cast<bool>() ? &defaults : nullptr;
  if (py::isinstance<Friction>(friction)) return &friction.cast<Friction&>().options;
  raise(PyExc_TypeError, "friction: expected zwang.Friction(...), True or None, got " +
                             std::string(py::str(py::type::handle_of(friction).attr("__name__"))));
}

const BalanceOptions& balanceArg(py::handle balance) {
  static const BalanceOptions defaults;
  if (balance.is_none()) return defaults;
  if (py::isinstance<Balance>(balance)) return balance.cast<Balance&>().options;
  raise(PyExc_TypeError, "balance: expected zwang.Balance(...) or None, got " +
                             std::string(py::str(py::type::handle_of(balance).attr("__name__"))));
}

Eigen::VectorXd optionalOverride(const char* name, py::handle value) {
  if (value.is_none()) return {};
  Eigen::VectorXd buffer;
  return vectorArg(name, value, buffer);
}

py::object overrideArray(const Eigen::VectorXd& v) { return v.size() ? py::object(vectorCopy(v)) : py::none(); }

// The warnings already issued per model: a condition that holds solve after
// solve (a joint outside its limits while q drifts) is issued once per (model,
// code, joint), with its first value, not once per solve (Result.warnings has
// every occurrence). Expired models are dropped, so a new model at a freed
// address starts afresh.
struct IssuedWarnings {
  std::weak_ptr<const Model> model;
  std::vector<std::pair<std::string, int>> keys;  // (code, joint; -1 for the task's)
};
std::vector<IssuedWarnings> g_issued;  // guarded by the GIL

bool firstTime(const std::shared_ptr<Model>& model, const std::string& code, int joint) {
  g_issued.erase(
      std::remove_if(g_issued.begin(), g_issued.end(), [](const IssuedWarnings& w) { return w.model.expired(); }),
      g_issued.end());
  auto it =
      std::find_if(g_issued.begin(), g_issued.end(), [&](const IssuedWarnings& w) { return w.model.lock() == model; });
  if (it == g_issued.end()) it = g_issued.insert(g_issued.end(), {model, {}});
  const std::pair<std::string, int> key{code, joint};
  if (std::find(it->keys.begin(), it->keys.end(), key) != it->keys.end()) return false;
  it->keys.push_back(key);
  return true;
}

// One warning of a solve: into the Result, and issued as a zwang.ModelWarning
// the first time for this model, code and joint.
void warnOnce(const std::shared_ptr<Model>& model, Result& r, const std::string& code, int joint,
              const std::string& text) {
  r.warnings.emplace_back(code, text);
  if (!firstTime(model, code, joint)) return;
  const std::string once = text + (joint >= 0 ? " (warned once per model and joint" : " (warned once per model") +
                           "; Result.warnings has it at every solve)";
  if (PyErr_WarnEx(exceptions().model_warning.ptr(), once.c_str(), 1) != 0) throw py::error_already_set();
}

// A configuration outside the joint limits is solved as given; say so. Kept
// out of the C++ solve, which must not allocate. q[k] names the entry of the
// full q (a floating base's coordinates first).
void warnOutsideLimits(const std::shared_ptr<Model>& model, const Eigen::Ref<const Eigen::VectorXd>& q, Result& r) {
  problem::forEachOutsideLimits(
      *model, q, 0, [&](int joint, const std::string& message) { warnOnce(model, r, kOutsideLimits, joint, message); });
}

Vec6 frameAccelerationOf(const Result& r, int frame, Expressed e) {
  if (r.data) return (e == Expressed::Local ? r.data->frame_acc_local : r.data->frame_acc_world).row(frame).transpose();
  r.solution();  // stale check
  Vec6 a;
  if (const Status s =
          frameAcceleration(*r.model, *r.live->ws, r.live->ws->kinematics.q, r.live->ws->kinematics.qd, frame, e, a);
      !s)
    raiseStatus(s, "frame_acceleration");
  return a;
}

// The constraint wrench of the solve's task on a frame (zwang::constraintWrench), live or as copied.
Vec6 constraintWrenchOf(const Result& r, int frame, Expressed e) {
  if (r.data)
    return (e == Expressed::Local ? r.data->frame_wrench_local : r.data->frame_wrench_world).row(frame).transpose();
  r.solution();  // stale check: the workspace's task is still the one this result was solved with
  Vec6 w;
  if (const Status s = constraintWrench(*r.model, *r.live->ws, *r.live->task, r.live->ws->kinematics.q, frame, e, w);
      !s)
    raiseStatus(s, "constraint_wrench");
  return w;
}

// (bodies × 6) accelerations of every body's own frame, computed on demand.
py::array bodyAccelerations(const Result& r, Expressed e) {
  const int bodies = r.model->bodyCount();
  py::array_t<double> out({bodies, 6});
  auto view = out.mutable_unchecked<2>();
  for (int b = 0; b < bodies; ++b) {
    const Vec6 a = frameAccelerationOf(r, r.model->bodyFrame(b), e);
    for (int k = 0; k < 6; ++k) view(b, k) = a[k];
  }
  return out;
}

std::string resultRepr(const Result& r) {
  const Solution& s = r.solution();
  std::string text = "<zwang.Result dof=" + std::to_string(r.model->dof()) +
                     (r.model->hasFloatingBase() ? " nv=" + std::to_string(s.qdd.size()) : std::string()) +
                     " rows=" + std::to_string(s.balance.rows);
  if (r.with_friction) text += " friction" + std::string(r.friction().indeterminate ? " (indeterminate)" : "");
  if (s.balance.singular) text += " singular";
  if (r.infeasible) text += " infeasible";
  return text + (r.data ? " copy>" : ">");
}

}  // namespace

PyWorkspace::PyWorkspace(std::shared_ptr<Model> model_in, int max_constraint_rows) : model(std::move(model_in)) {
  if (!model) raise(PyExc_TypeError, "model: expected a zwang.Model, got None");
  if (max_constraint_rows < 0) raise(PyExc_ValueError, "max_constraint_rows must be >= 0");
  ws = std::make_unique<Workspace>(*model, max_constraint_rows);
  q_buf.setZero(model->nq());
  qd_buf.setZero(model->nv());
  tau_buf.setZero(model->nv());
  qdd_buf.setZero(model->nv());
  zeros.setZero(model->nv());  // qd, tau or qdd left out
}

void PyWorkspace::ensureCapacity(int rows) {
  if (rows <= ws->constraintCapacity()) return;
  retired.push_back(std::move(ws));
  ws = std::make_unique<Workspace>(*model, rows);
}

const Solution& Result::solution() const {
  if (data) return data->solution;
  if (live->generation != generation)
    raise(exceptions().stale_error,
          "this Result is a view on a workspace that has been used again since (solve, kinematics or dynamics); "
          "call res.copy() before the next call to keep it");
  return live->ws->solution;
}

const FrictionResult& Result::friction() const {
  solution();
  return data ? data->friction : live->ws->friction;
}

py::handle Result::base() const { return data ? data_base : owner; }

namespace {

// Workspace, and Model.workspace().
void bindWorkspace(py::module_& m) {
  py::class_<PyWorkspace>(m, "Workspace",
                          "Scratch memory of the solver for one model (zwang::Workspace) and the task built from the\n"
                          "last constraints/wrenches lists. One per thread. Results of solve() are views on it.")
      .def(py::init<std::shared_ptr<Model>, int>(), py::arg("model"), py::arg("max_constraint_rows") = 6,
           "Room for up to max_constraint_rows constraint rows; solve() grows it once if a task needs more.")
      .def_property_readonly("model", [](const PyWorkspace& pw) { return pw.model; })
      .def_property_readonly("dof", [](const PyWorkspace& pw) { return pw.ws->dof(); })
      .def_property_readonly("constraint_capacity", [](const PyWorkspace& pw) { return pw.ws->constraintCapacity(); })
      .def_property_readonly(
          "task_builds", [](const PyWorkspace& pw) { return pw.task_builds; },
          "how many times solve() built a Task (only when the constraint/wrench objects change)")
      .def("__repr__", [](const PyWorkspace& pw) {
        return "<zwang.Workspace for '" + pw.model->name() + "', " + std::to_string(pw.ws->constraintCapacity()) +
               " constraint rows>";
      });

  auto model_class = py::reinterpret_borrow<py::class_<Model, std::shared_ptr<Model>>>(m.attr("Model"));
  model_class.def(
      "workspace",
      [](std::shared_ptr<Model> model, int rows) { return std::make_unique<PyWorkspace>(std::move(model), rows); },
      py::arg("max_constraint_rows") = 6, "zwang.Workspace(model, max_constraint_rows)");
}

std::string typeName(py::handle value) { return py::str(py::type::handle_of(value).attr("__name__")); }

// relative_to=: a frame name, or None for a constraint on the world.
std::string relativeToArg(py::handle relative_to) {
  if (relative_to.is_none()) return {};
  if (!py::isinstance<py::str>(relative_to))
    raise(PyExc_TypeError, "relative_to: expected a frame name (str) or None, got " + typeName(relative_to));
  return relative_to.cast<std::string>();
}

// zwang.Constraint(frame, A, b, expressed, relative_to, contact=): the problem layer's checks and defaults.
Constraint makeConstraint(const std::string& frame, py::handle A, py::handle b, py::handle expressed,
                          py::handle relative_to, bool contact) {
  Constraint c{g_next_serial++, {}, {}};
  problem::ConstraintDesc& d = c.desc;
  d.frame = frame;
  d.relative_to = relativeToArg(relative_to);
  d.contact = contact;
  const bool relative = !relative_to.is_none();
  checked("", [&] { problem::checkRelative(kPython, d, relative); });
  std::string axes = relative ? "reference" : "local";
  if (!expressed.is_none()) {
    if (!py::isinstance<py::str>(expressed))
      raise(PyExc_TypeError, "expressed: expected a str, got " + typeName(expressed));
    axes = expressed.cast<std::string>();
  }
  d.expressed = expressedArg("expressed", axes, true, relative);
  d.A = constraintMatrixArg("A", A);
  c.b.setZero(d.A.cols());
  if (!b.is_none()) {
    Eigen::VectorXd buffer;
    const auto v = vectorArg("b", b, buffer);
    if (v.size() != d.A.cols())
      raise(PyExc_ValueError,
            "b: has " + std::to_string(v.size()) + " entries, A has " + std::to_string(d.A.cols()) + " columns");
    c.b = v;
  }
  return c;
}

// Constraint: a frame's, a relative, a contact's or a joint's rows.
void bindConstraint(py::module_& m) {
  py::class_<Constraint>(m, "Constraint",
                         "Acceleration constraint A^T Xdd = b on a frame (classical, true accelerations of the frame\n"
                         "origin; gravity not included). A is 6×m, its columns unit constraint forces, linear part\n"
                         "first; a 6-vector is one column. relative_to: another frame; then the acceleration is the\n"
                         "one an observer riding on that frame sees (Task::addRelativeConstraint), and expressed\n"
                         "defaults to 'reference' (that frame's axes). frame, relative_to, A and expressed are\n"
                         "fixed; b may be changed between solves (c.b[:] = ... or c.b = ...) without rebuilding\n"
                         "the task. contact=True: the environment gives the force (a foot on the ground,\n"
                         "Task::addContact): nu is the contact force, left out of tau_constraint and tau_control.\n"
                         "Constraint.on_joint(joint, b): one row qdd_joint = b (Task::addJointConstraint).")
      .def(py::init(&makeConstraint), py::arg("frame"), py::arg("A"), py::arg("b") = py::none(),
           py::arg("expressed") = py::none(), py::arg("relative_to") = py::none(), py::kw_only(),
           py::arg("contact") = false)
      .def_static(
          "on_joint",
          [](const std::string& joint, double b) {
    Constraint c{g_next_serial++, {}, Eigen::VectorXd::Constant(1, b)};
    c.desc.joint = joint;
    c.desc.A = ConstraintMatrix::Zero(6, 1);
    return c;
          },
          py::arg("joint"), py::arg("b") = 0.0,
          "A joint row: qdd of this joint = b (Task::addJointConstraint); its nu is the motor torque that holds\n"
          "it, part of tau_control. ModelError at solve for an unknown joint.")
      .def_property_readonly(
          "joint",
          [](const Constraint& c) { return c.desc.joint.empty() ? py::object(py::none()) : py::str(c.desc.joint); },
          "the joint of a joint row (Constraint.on_joint), else None")
      .def_property_readonly(
          "contact", [](const Constraint& c) { return c.desc.contact; },
          "True when the environment supplies the force (a foot on the ground): it moves the robot like any\n"
          "constraint, its nu is the contact force, and it is left out of tau_constraint and tau_control")
      .def_property_readonly("frame", [](const Constraint& c) { return c.desc.frame; })
      .def_property_readonly(
          "relative_to",
          [](const Constraint& c) {
    return c.desc.relative_to.empty() ? py::object(py::none()) : py::str(c.desc.relative_to);
          },
          "the frame a relative constraint refers to (None: the world)")
      .def_property_readonly("expressed",
                             [](const Constraint& c) { return std::string(expressedName(c.desc.expressed)); })
      .def_property_readonly(
          "A",
          [](const Constraint& c) {
    return c.desc.joint.empty() ? py::object(matrixCopy(c.desc.A)) : py::object(py::none());
          },
          "6×m (a copy); None for a joint row")
      .def_property_readonly("rows", [](const Constraint& c) { return c.desc.A.cols(); })
      .def_property(
          "b", [](py::object self) { return vectorView(self.cast<Constraint&>().b, self, true); },
          [](Constraint& c, py::handle value) {
    Eigen::VectorXd buffer;
    const auto v = vectorArg("b", value, buffer);
    if (v.size() != c.b.size())
      raise(PyExc_ValueError, "b: has " + std::to_string(v.size()) + " entries, the constraint has " +
                                  std::to_string(c.b.size()) + " rows");
    c.b = v;
          },
          "set points, one per column of A (a writable view)")
      .def("__repr__", [](const Constraint& c) {
        if (!c.desc.joint.empty()) return "<zwang.Constraint on joint '" + c.desc.joint + "', 1 row>";
        return "<zwang.Constraint on '" + c.desc.frame + "'" +
               (c.desc.contact ? std::string(" (contact)") : std::string()) +
               (c.desc.relative_to.empty() ? std::string() : " relative to '" + c.desc.relative_to + "'") + ", " +
               std::to_string(c.desc.A.cols()) + " rows, " + expressedName(c.desc.expressed) + ">";
      });
}

// Wrench: a wrench at a frame, its value writable.
void bindWrench(py::module_& m) {
  py::class_<Wrench>(m, "Wrench",
                     "External wrench [force; torque] acting at a frame's origin, components in the frame's axes\n"
                     "('local') or the world axes ('world'). The value may be changed between solves.")
      .def(py::init([](const std::string& frame, py::handle value, py::handle force, py::handle torque,
                       const std::string& expressed) {
             Wrench w{g_next_serial++, frame, expressedArg("expressed", expressed, false), Vec6::Zero()};
             if (!value.is_none()) {
               if (!force.is_none() || !torque.is_none())
                 raise(PyExc_TypeError, "Wrench: give either value or force/torque, not both");
               w.value = vec6Arg("value", value);
             }
             if (!force.is_none()) w.value.head<3>() = vec3Arg("force", force);
             if (!torque.is_none()) w.value.tail<3>() = vec3Arg("torque", torque);
             return w;
           }),
           py::arg("frame"), py::arg("value") = py::none(), py::kw_only(), py::arg("force") = py::none(),
           py::arg("torque") = py::none(), py::arg("expressed") = "local")
      .def_property_readonly("frame", [](const Wrench& w) { return w.frame; })
      .def_property_readonly("expressed", [](const Wrench& w) { return std::string(expressedName(w.expressed)); })
      .def_property(
          "value", [](py::object self) { return vectorView(self.cast<Wrench&>().value.data(), 6, self, true); },
          [](Wrench& w, py::handle v) { w.value = vec6Arg("value", v); }, "[fx, fy, fz, nx, ny, nz] (a writable view)")
      .def_property(
          "force", [](py::object self) { return vectorView(self.cast<Wrench&>().value.data(), 3, self, true); },
          [](Wrench& w, py::handle v) { w.value.head<3>() = vec3Arg("force", v); })
      .def_property(
          "torque", [](py::object self) { return vectorView(self.cast<Wrench&>().value.data() + 3, 3, self, true); },
          [](Wrench& w, py::handle v) { w.value.tail<3>() = vec3Arg("torque", v); })
      .def("__repr__",
           [](const Wrench& w) { return "<zwang.Wrench on '" + w.frame + "', " + expressedName(w.expressed) + ">"; });
}

// The method of its name (toString's), or ValueError.
FrictionMethod frictionMethodNamed(const std::string& name) {
  constexpr FrictionMethod kMethods[] = {FrictionMethod::Automatic, FrictionMethod::ActiveSet,
                                         FrictionMethod::ProjectedGradient, FrictionMethod::StickPatterns};
  std::string names;
  for (const FrictionMethod method : kMethods) {
    if (name == toString(method)) return method;
    names += std::string(names.empty() ? "'" : ", '") + toString(method) + "'";
  }
  raise(PyExc_ValueError, "method: unknown value '" + name + "' (expected one of " + names + ")");
}

// Friction: the options of the friction-aware solve, checked by the problem layer.
void bindFriction(py::module_& m) {
  py::class_<Friction>(m, "Friction",
                       "Options of the friction-aware solve (zwang::FrictionOptions). margin: when mu* is not\n"
                       "unique, the effort-minimising choice uses at most margin*f_j. breakaway/kinetic/viscous:\n"
                       "optional per-joint overrides of the model's values. method: 'automatic', 'active_set',\n"
                       "'projected_gradient' or 'stick_patterns' (docs/friction.md). warm_start: start from the\n"
                       "workspace's last stick/slip pattern (a control loop; docs/friction.md 'Warm start').")
      .def(py::init([](double margin, double velocity_tolerance, double limit_tolerance, bool joint_limits,
                       const std::string& method, int max_iterations, double kkt_tolerance, py::handle breakaway,
                       py::handle kinetic, py::handle viscous, bool warm_start) {
             Friction f;
             f.options.margin = margin;
             f.options.velocity_tolerance = velocity_tolerance;
             f.options.limit_tolerance = limit_tolerance;
             f.options.joint_limits = joint_limits;
             f.options.method = frictionMethodNamed(method);
             f.options.max_iterations = max_iterations;
             f.options.kkt_tolerance = kkt_tolerance;
             f.options.breakaway = optionalOverride("breakaway", breakaway);
             f.options.kinetic = optionalOverride("kinetic", kinetic);
             f.options.viscous = optionalOverride("viscous", viscous);
             f.options.warm_start = warm_start;
             checked("", [&] { problem::checkFriction(f.options); });
             return f;
           }),
           py::kw_only(), py::arg("margin") = 1.0, py::arg("velocity_tolerance") = 1e-6,
           py::arg("limit_tolerance") = 1e-9, py::arg("joint_limits") = true, py::arg("method") = "automatic",
           py::arg("max_iterations") = 500, py::arg("kkt_tolerance") = 1e-12, py::arg("breakaway") = py::none(),
           py::arg("kinetic") = py::none(), py::arg("viscous") = py::none(), py::arg("warm_start") = false)
      .def_property_readonly("margin", [](const Friction& f) { return f.options.margin; })
      .def_property_readonly("velocity_tolerance", [](const Friction& f) { return f.options.velocity_tolerance; })
      .def_property_readonly("limit_tolerance", [](const Friction& f) { return f.options.limit_tolerance; })
      .def_property_readonly("joint_limits", [](const Friction& f) { return f.options.joint_limits; })
      .def_property_readonly("method", [](const Friction& f) { return std::string(toString(f.options.method)); })
      .def_property_readonly("max_iterations", [](const Friction& f) { return f.options.max_iterations; })
      .def_property_readonly("kkt_tolerance", [](const Friction& f) { return f.options.kkt_tolerance; })
      .def_property_readonly("breakaway", [](const Friction& f) { return overrideArray(f.options.breakaway); })
      .def_property_readonly("kinetic", [](const Friction& f) { return overrideArray(f.options.kinetic); })
      .def_property_readonly("viscous", [](const Friction& f) { return overrideArray(f.options.viscous); })
      .def_property_readonly("warm_start", [](const Friction& f) { return f.options.warm_start; })
      .def("__repr__", [](const Friction& f) {
        return "<zwang.Friction margin=" + std::string(py::str(py::float_(f.options.margin))) + ">";
      });
}

// Balance: the options of a singular task's balance, checked by the problem layer.
void bindBalance(py::module_& m) {
  py::class_<Balance>(m, "Balance",
                      "Options of the balance of line 25 (zwang::BalanceOptions; docs/solver.md, 'Singular tasks'):\n"
                      "equilibrated eigenvalues at or below rank_tolerance are exact rank loss (least squares, no\n"
                      "force), below singular_threshold near-singular (a continuous, bounded ramp); a row is met when\n"
                      "its residual is within residual_tolerance of its terms' size (Result.consistent).")
      .def(py::init([](double singular_threshold, double rank_tolerance, double residual_tolerance) {
             Balance b;
             b.options.singular_threshold = singular_threshold;
             b.options.rank_tolerance = rank_tolerance;
             b.options.residual_tolerance = residual_tolerance;
             checked("", [&] { problem::checkBalance(b.options); });
             return b;
           }),
           py::kw_only(), py::arg("singular_threshold") = BalanceOptions{}.singular_threshold,
           py::arg("rank_tolerance") = BalanceOptions{}.rank_tolerance,
           py::arg("residual_tolerance") = BalanceOptions{}.residual_tolerance)
      .def_property_readonly("singular_threshold", [](const Balance& b) { return b.options.singular_threshold; })
      .def_property_readonly("rank_tolerance", [](const Balance& b) { return b.options.rank_tolerance; })
      .def_property_readonly("residual_tolerance", [](const Balance& b) { return b.options.residual_tolerance; })
      .def("__repr__", [](const Balance& b) {
        return "<zwang.Balance singular_threshold=" + std::string(py::str(py::float_(b.options.singular_threshold))) +
               " rank_tolerance=" + std::string(py::str(py::float_(b.options.rank_tolerance))) + ">";
      });
}

// What a solve computed: q̈, the forces and the balance's status.
void addSolutionProperties(py::class_<Result>& cls) {
  cls.def_property_readonly(
         "qdd", [](const Result& r) { return vectorView(r.solution().qdd, r.base()); },
         "q̈ (nv entries: a floating base's first, the derivative of its velocity coordinates as given)")
      .def_property_readonly(
          "base_acceleration_world",
          [](const Result& r) { return vectorView(r.solution().base_acceleration_world.data(), 6, r.base()); },
          "a floating base's classical acceleration [p̈; ω̇] of its origin in world axes (zeros for a fixed base)")
      .def_property_readonly(
          "tau_constraint", [](const Result& r) { return vectorView(r.solution().tau_constraint, r.base()); },
          "τ_c = Σ Jᵀ A ν, the joint torques of the constraint forces")
      .def_property_readonly(
          "tau_control", [](const Result& r) { return vectorView(r.solution().tau_control, r.base()); },
          "τ + τ_c, the command for the motors")
      .def_property_readonly(
          "nu", [](const Result& r) { return vectorCopy(r.solution().nu); },
          "ν, constraint magnitudes in constraint order (a copy: its length follows the task)")
      .def_property_readonly(
          "gauss", [](const Result& r) { return r.solution().gauss; }, "Z(q̈)")
      .def_property_readonly(
          "rows", [](const Result& r) { return r.solution().balance.rows; },
          "the task's constraint rows (a mimic joint's internal row is not one)")
      .def_property_readonly(
          "rank", [](const Result& r) { return r.solution().balance.rank; },
          "the rank of the task's rows on the robot as its mimic joints couple it")
      .def_property_readonly(
          "nu_unique", [](const Result& r) { return r.solution().balance.nu_unique; },
          "rank = rows: no other nu gives this motion. False for dependent rows (the least-norm nu is returned):\n"
          "with consistent, every row is met all the same (statically indeterminate, e.g. the weight split\n"
          "between two feet); without it, the lost rank left rows unmet")
      .def_property_readonly("condition", [](const Result& r) { return r.solution().balance.condition; })
      .def_property_readonly("damping", [](const Result& r) { return r.solution().balance.damping; })
      .def_property_readonly("singular", [](const Result& r) { return r.solution().balance.singular; })
      .def_property_readonly(
          "residual", [](const Result& r) { return r.solution().balance.residual; },
          "‖Aᵀ Ẍ − b‖ over the constraint rows, in their own units")
      .def_property_readonly(
          "consistent", [](const Result& r) { return r.solution().balance.consistent; },
          "every constraint row met (False: least squares only, or a damped direction gave)");
}

// Result.com: the robot's centre of mass in the solved motion, world axes, as `zwang solve`'s "com"; None
// without moving mass.
py::object comOf(const Result& r) {
  if (r.data) return r.data->com;
  r.solution();  // stale check
  const Workspace& ws = *r.live->ws;
  const Eigen::VectorXd &q = ws.kinematics.q, &qd = ws.kinematics.qd;
  Vec3 position, velocity, acceleration;
  if (!centerOfMass(*r.model, ws, q, kWholeRobot, position) ||
      !centerOfMassVelocity(*r.model, ws, q, qd, kWholeRobot, velocity) ||
      !centerOfMassAcceleration(*r.model, ws, q, qd, kWholeRobot, acceleration))
    return py::none();
  py::dict out;
  out["position"] = vectorCopy(position);
  out["velocity"] = vectorCopy(velocity);
  out["acceleration"] = vectorCopy(acceleration);
  return std::move(out);
}

// Frame accelerations, warnings and the outcome.
void addFrameProperties(py::class_<Result>& cls) {
  cls.def_property_readonly(
         "body_acc_local", [](const Result& r) { return bodyAccelerations(r, Expressed::Local); },
         "(bodies, 6) true classical accelerations of the body frames, body axes (a new array)")
      .def_property_readonly(
          "body_acc_world", [](const Result& r) { return bodyAccelerations(r, Expressed::World); },
          "(bodies, 6) the same in world axes (a new array)")
      .def(
          "frame_acceleration",
          [](const Result& r, py::handle frame, const std::string& expressed) {
    return vectorCopy(frameAccelerationOf(r, frameArg(*r.model, frame), expressedArg("expressed", expressed, true)));
          },
          py::arg("frame"), py::arg("expressed") = "world", "true classical acceleration [p̈; ω̇] of a frame's origin")
      .def(
          "constraint_wrench",
          [](const Result& r, py::handle frame, const std::string& expressed) {
    return vectorCopy(constraintWrenchOf(r, frameArg(*r.model, frame), expressedArg("expressed", expressed, true)));
          },
          py::arg("frame"), py::arg("expressed") = "world",
          "the wrench [f; n] the task's constraints exert on a frame, at its origin (zwang::constraintWrench):\n"
          "+A nu of its rows and contacts, -A nu of the relative rows it is the reference of; zeros for a frame\n"
          "without constraints (joint rows act on no frame)")
      .def_property_readonly(
          "warnings",
          [](const Result& r) {
    py::list out;
    for (const auto& [code, message] : r.warnings) out.append(py::make_tuple(code, message));
    return out;
          },
          "list of (code, message): every warning of this solve ('outside_limits', 'fixed_base_contact'), also\n"
          "those a zwang.ModelWarning said already (each is issued once per model, code and joint)")
      .def_property_readonly("com", &comOf,
                             "the robot's centre of mass in this motion, world axes: {'position', 'velocity',\n"
                             "'acceleration' (classical, gravity not included)}, new arrays; None without moving mass");
}

// The friction results (None, 0 or False without friction).
void addFrictionProperties(py::class_<Result>& cls) {
  cls.def_property_readonly("infeasible", [](const Result& r) { return r.infeasible; })
      .def_property_readonly("message", [](const Result& r) { return r.message; })
      .def_property_readonly("with_friction", [](const Result& r) { return r.with_friction; })
      .def_property_readonly(
          "mu",
          [](const Result& r) -> py::object {
            if (!r.with_friction) return py::none();
            return vectorView(r.friction().mu, r.base());
          },
          "μ* per joint (0 for moving joints); μ > 0 opposes positive motion. None without friction")
      .def_property_readonly(
          "state",
          [](const Result& r) -> py::object {
            if (!r.with_friction) return py::none();
            py::list states;
            for (const JointState s : r.friction().state) states.append(py::str(toString(s)));
            return std::move(states);
          },
          "per joint: 'moving', 'stick', 'slip+', 'slip-', 'at-limit', 'prescribed'. None without friction")
      .def_property_readonly("tau_friction",
                             [](const Result& r) -> py::object {
                               if (!r.with_friction) return py::none();
                               return vectorView(r.friction().tau_friction, r.base());
                             })
      .def_property_readonly("dqdd_dmu",
                             [](const Result& r) -> py::object {
                               if (!r.with_friction) return py::none();
                               return matrixView(r.friction().dqdd_dmu, r.base());
                             })
      .def_property_readonly("stuck",
                             [](const Result& r) -> py::object {
                               if (!r.with_friction) return py::none();
                               return py::cast(r.friction().stuck);
                             })
      .def_property_readonly("gauss_dual",
                             [](const Result& r) -> py::object {
                               if (!r.with_friction) return py::none();
                               return py::float_(r.friction().gauss_dual);
                             })
      .def_property_readonly("iterations",
                             [](const Result& r) { return r.with_friction ? r.friction().iterations : 0; })
      .def_property_readonly("converged",
                             [](const Result& r) { return r.with_friction ? r.friction().converged : true; })
      .def_property_readonly("kkt_residual",
                             [](const Result& r) { return r.with_friction ? r.friction().kkt_residual : 0.0; })
      .def_property_readonly("indeterminate",
                             [](const Result& r) { return r.with_friction && r.friction().indeterminate; })
      .def_property_readonly("warm_started",
                             [](const Result& r) { return r.with_friction && r.friction().warm_started; })
      .def_property_readonly("method",
                             [](const Result& r) -> py::object {
                               if (!r.with_friction) return py::none();
                               return py::str(toString(r.friction().method));
                             })
      .def_property_readonly("limit_impact",
                             [](const Result& r) { return r.with_friction && r.friction().limit_impact; })
      .def_property_readonly(
          "effort_exceeded",
          [](const Result& r) { return problem::beyondEffortLimit(*r.model, r.solution().tau_control); })
      .def_property_readonly("impact_joint",
                             [](const Result& r) { return r.with_friction ? r.friction().impact_joint : -1; });
}

// A Result with its own data, which later solves do not change.
Result copyResult(const Result& r) {
  auto data = std::make_shared<ResultData>();
  data->solution = r.solution();
  data->friction = r.friction();
  const auto frames = static_cast<Eigen::Index>(r.model->frames().size());
  data->frame_acc_local.resize(frames, 6);
  data->frame_acc_world.resize(frames, 6);
  data->frame_wrench_local.resize(frames, 6);
  data->frame_wrench_world.resize(frames, 6);
  for (int f = 0; f < frames; ++f) {
    data->frame_acc_local.row(f) = frameAccelerationOf(r, f, Expressed::Local).transpose();
    data->frame_acc_world.row(f) = frameAccelerationOf(r, f, Expressed::World).transpose();
    data->frame_wrench_local.row(f) = constraintWrenchOf(r, f, Expressed::Local).transpose();
    data->frame_wrench_world.row(f) = constraintWrenchOf(r, f, Expressed::World).transpose();
  }
  data->com = comOf(r);
  Result copy;
  copy.model = r.model;
  copy.with_friction = r.with_friction;
  copy.infeasible = r.infeasible;
  copy.message = r.message;
  copy.warnings = r.warnings;
  copy.data_base = py::capsule(new std::shared_ptr<ResultData>(data),
                               [](void* p) { delete static_cast<std::shared_ptr<ResultData>*>(p); });
  copy.data = std::move(data);
  return copy;
}

// Result: views on the workspace until its next use, or a copy.
void bindResult(py::module_& m) {
  py::class_<Result> cls(
      m, "Result",
      "What solve() computed. Arrays are read-only NumPy views on the workspace (no copy), valid\n"
      "until the next call on that workspace; reading a Result after that raises\n"
      "StaleResultError, and arrays taken earlier then show the new values. Result.copy() keeps it.");
  addSolutionProperties(cls);
  addFrameProperties(cls);
  addFrictionProperties(cls);
  cls.def_property_readonly("is_copy", [](const Result& r) { return static_cast<bool>(r.data); })
      .def("copy", &copyResult, "a detached copy that later solves do not change")
      .def("__repr__", &resultRepr);
}

// modes={"joint or DOF": "locked" | "torque" | q̈ | [q̈, …] | {"acceleration": …}}: every DOF torque-driven first
// (the workspace's task keeps the last call's modes otherwise), then these, through the problem layer.
void applyModes(const Model& model, Task& task, py::handle modes) {
  if (modes.is_none() && task.prescribedCount() == 0) return;
  for (int v = 0; v < model.nv(); ++v) task.setDofMode(v, DofMode::Torque);
  if (modes.is_none()) return;
  if (!py::isinstance<py::dict>(modes))
    raise(PyExc_TypeError,
          "modes: expected a dict of joint names to modes ('locked', 'torque' or an acceleration), "
          "got " +
              std::string(py::str(py::type::handle_of(modes).attr("__name__"))));
  for (const auto& item : modes.cast<py::dict>()) {  // not a structured binding: the lambdas below read it
    const py::handle key = item.first, value = item.second;
    if (!py::isinstance<py::str>(key)) raise(PyExc_TypeError, "modes: keys are joint names (str)");
    problem::JointModeDesc mode;
    mode.name = key.cast<std::string>();
    const std::string where = "modes['" + problem::printable(mode.name) + "']";
    if (py::isinstance<py::str>(value)) {
      mode.kind = checked(where, [&] { return problem::parseModeKind(kPython, value.cast<std::string>()); });
    } else {
      py::handle acceleration = value;
      if (py::isinstance<py::dict>(value)) {
        const py::dict d = value.cast<py::dict>();
        if (d.size() != 1 || !d.contains("acceleration"))
          raise(PyExc_ValueError, where + ": a dict mode is {'acceleration': qdd} (one per DOF)");
        acceleration = d["acceleration"];
      }
      mode.kind = problem::ModeKind::Acceleration;
      Eigen::VectorXd buffer;
      mode.acceleration = py::isinstance<py::float_>(acceleration) || py::isinstance<py::int_>(acceleration)
                              ? Eigen::VectorXd::Constant(1, acceleration.cast<double>())
                              : Eigen::VectorXd(vectorArg((where + " acceleration").c_str(), acceleration, buffer));
    }
    checked(where, [&] { problem::setJointMode(kPython, model, task, mode); });
  }
}

// The arguments of solve() and _time_cpp_solve() as the C++ solve takes them.
struct SolveArgs {
  PyWorkspace& pw;
  const FrictionOptions* friction;  // the problem layer's choice: with friction, or plain
  Task& task;
  Eigen::Map<const Eigen::VectorXd> q, qd, tau;
};

SolveArgs solveArgs(const std::shared_ptr<Model>& model, py::handle ws_obj, py::handle q, py::handle qd, py::handle tau,
                    py::handle constraints, py::handle wrenches, py::handle friction, py::handle gravity,
                    py::handle balance, py::handle modes) {
  PyWorkspace& pw = workspaceArg(model, ws_obj);
  const FrictionOptions* options = frictionArg(friction);
  if (options)
    checked("", [&] { problem::checkFrictionOverrides(*model, *options); });  // before the solve: the CLI's words
  const BalanceOptions& balance_options = balanceArg(balance);
  Task& task = solveTask(pw, constraints, wrenches, gravity);
  task.balance = balance_options;
  applyModes(*model, task, modes);
  return {pw,
          options,
          task,
          vectorArg("q", q, pw.q_buf),
          optionalVector("qd", qd, pw.qd_buf, pw.zeros),
          optionalVector("tau", tau, pw.tau_buf, pw.zeros)};
}

Result solvePython(std::shared_ptr<Model> model, py::object ws_obj, py::handle q, py::handle qd, py::handle tau,
                   py::handle constraints, py::handle wrenches, py::handle friction, py::handle gravity,
                   py::handle balance, py::handle modes) {
  SolveArgs a = solveArgs(model, ws_obj, q, qd, tau, constraints, wrenches, friction, gravity, balance, modes);
  ++a.pw.generation;
  const Status status = problem::solve(*model, *a.pw.ws, a.q, a.qd, a.tau, a.task, a.friction);
  const bool infeasible = status.code == StatusCode::Infeasible;
  if (!status && !infeasible) raiseStatus(status, "solve");
  Result r;
  for (const ModelWarning& w : a.task.warnings()) warnOnce(model, r, toString(w.code), -1, w.message);
  warnOutsideLimits(model, a.q, r);
  if (a.friction)
    if (const std::string impact = problem::limitImpactMessage(*model, a.pw.ws->friction); !impact.empty())
      warnOnce(model, r, kLimitImpact, a.pw.ws->friction.impact_joint, impact);
  r.model = std::move(model);
  r.owner = std::move(ws_obj);
  r.live = &a.pw;
  r.generation = a.pw.generation;
  r.with_friction = a.friction != nullptr;
  r.infeasible = infeasible;
  if (infeasible) {
    r.message = status.message;
    raiseStatus(status, "solve", py::cast(std::move(r)));
  }
  return r;
}

// Seconds per C++ solve of these arguments, looped in C++.
double timeCppSolve(std::shared_ptr<Model> model, py::object ws_obj, py::handle q, py::handle qd, py::handle tau,
                    py::handle constraints, py::handle wrenches, py::handle friction, py::handle gravity,
                    py::handle balance, py::handle modes, int repeat) {
  const SolveArgs a = solveArgs(model, ws_obj, q, qd, tau, constraints, wrenches, friction, gravity, balance, modes);
  ++a.pw.generation;
  Status status;
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < repeat; ++k) status = problem::solve(*model, *a.pw.ws, a.q, a.qd, a.tau, a.task, a.friction);
  const std::chrono::duration<double> elapsed = std::chrono::steady_clock::now() - start;
  if (!status) raiseStatus(status, "_time_cpp_solve");
  return elapsed.count() / std::max(repeat, 1);
}

// solve() and _time_cpp_solve(), over the same arguments.
void bindSolveFunctions(py::module_& m) {
  m.def("solve", &solvePython, py::arg("model"), py::arg("ws"), py::arg("q"), py::arg("qd") = py::none(),
        py::arg("tau") = py::none(), py::kw_only(), py::arg("constraints") = py::none(),
        py::arg("wrenches") = py::none(), py::arg("friction") = py::none(), py::arg("gravity") = py::none(),
        py::arg("balance") = py::none(), py::arg("modes") = py::none(),
        "Constrained hybrid dynamics (Popov-Vereshchagin), with exact static friction when `friction` is given.\n\n"
        "q: model.nq entries, qd, tau: model.nv (one per joint on a fixed base; a floating base's coordinates\n"
        "first: docs/python.md); qd, tau default to zeros; float64 arrays are read in place.\n"
        "constraints: list of Constraint; wrenches: list of Wrench; friction: Friction(...), True or None;\n"
        "gravity: 3-vector, default (0, 0, -9.81); balance: Balance(...) or None (the defaults), how a\n"
        "singular task is solved; modes: {joint or DOF name: 'locked' | 'torque' | qdd | [qdd per DOF] |\n"
        "{'acceleration': ...}}, the joints' modes for this solve (unnamed: torque-driven; a prescribed joint's\n"
        "torque comes back in tau_control). The task is rebuilt only when the constraint or wrench\n"
        "objects change. Returns a Result (views on ws). Raises SolveError (C++ Status), InfeasibleError\n"
        "(with .result), ModelError (unknown frame), TypeError/ValueError (dtype, dimensions). A q outside a\n"
        "joint's limits, or contacts on a fixed base with mass, give a zwang.ModelWarning once per model, code and\n"
        "joint; Result.warnings lists every one of this solve.");

  m.def("_time_cpp_solve", &timeCppSolve, py::arg("model"), py::arg("ws"), py::arg("q"), py::arg("qd") = py::none(),
        py::arg("tau") = py::none(), py::kw_only(), py::arg("constraints") = py::none(),
        py::arg("wrenches") = py::none(), py::arg("friction") = py::none(), py::arg("gravity") = py::none(),
        py::arg("balance") = py::none(), py::arg("modes") = py::none(), py::arg("repeat") = 1000,
        "Seconds per call of the C++ solve alone (same arguments as solve), looped in C++: the baseline for\n"
        "the Python-call overhead in docs/python.md. Not part of the API.");
}

using VectorView = Eigen::Ref<const Eigen::VectorXd>;

// A kinematics query at (q, qd): read when ws holds that state (after a solve
// or forward_kinematics there), else forward kinematics first (qd empty: poses only).
template <class Query>
Status queryOrCompute(const Model& model, PyWorkspace& pw, const VectorView& q, const VectorView& qd, Query query) {
  Status s = query(q, qd);
  if (s.code != StatusCode::NotComputed) return s;
  ++pw.generation;
  s = qd.size() == 0 ? forwardKinematics(model, *pw.ws, q) : forwardKinematics(model, *pw.ws, q, qd);
  return s ? query(q, qd) : s;
}

// forward_kinematics, frame_pose, frame_velocity, frame_jacobian.
void bindKinematics(py::module_& m) {
  m.def(
      "forward_kinematics",
      [](std::shared_ptr<Model> model, py::object ws_obj, py::handle q, py::handle qd) {
    PyWorkspace& pw = workspaceArg(model, ws_obj);
    const auto qv = vectorArg("q", q, pw.q_buf);
    ++pw.generation;
    const Status s = qd.is_none() ? forwardKinematics(*model, *pw.ws, qv)
                                  : forwardKinematics(*model, *pw.ws, qv, vectorArg("qd", qd, pw.qd_buf));
    if (!s) raiseStatus(s, "forward_kinematics");
      },
      py::arg("model"), py::arg("ws"), py::arg("q"), py::arg("qd") = py::none(),
      "Poses (and velocities with qd) of every body into ws; then frame_pose(q=None), or any query at this state\n"
      "without recomputing.");
  m.def(
      "frame_pose",
      [](std::shared_ptr<Model> model, py::object ws_obj, py::handle q, py::handle frame) {
    PyWorkspace& pw = workspaceArg(model, ws_obj);
    const int f = frameArg(*model, frame);
    Eigen::Isometry3d pose;
    const Status s = q.is_none() ? framePose(*model, *pw.ws, pw.ws->kinematics.q, f, pose)
                                 : queryOrCompute(*model, pw, vectorArg("q", q, pw.q_buf), Eigen::VectorXd(),
                                                  [&](const VectorView& qv, const VectorView&) {
      return framePose(*model, *pw.ws, qv, f, pose);
                                   });
    if (!s) raiseStatus(s, "frame_pose");
    return matrixCopy(pose.matrix());
      },
      py::arg("model"), py::arg("ws"), py::arg("q"), py::arg("frame"),
      "4×4 pose of the frame in the world at q (q=None: at the state ws holds)");
  m.def(
      "frame_velocity",
      [](std::shared_ptr<Model> model, py::object ws_obj, py::handle q, py::handle qd, py::handle frame,
         const std::string& expressed) {
    PyWorkspace& pw = workspaceArg(model, ws_obj);
    const int f = frameArg(*model, frame);
    const Expressed e = expressedArg("expressed", expressed, true);
    Vec6 v;
    const Status s = queryOrCompute(*model, pw, vectorArg("q", q, pw.q_buf), vectorArg("qd", qd, pw.qd_buf),
                                    [&](const VectorView& qv, const VectorView& qdv) {
      return frameVelocity(*model, *pw.ws, qv, qdv, f, e, v);
    });
    if (!s) raiseStatus(s, "frame_velocity");
    return vectorCopy(v);
      },
      py::arg("model"), py::arg("ws"), py::arg("q"), py::arg("qd"), py::arg("frame"), py::arg("expressed") = "local",
      "classical velocity [v; ω] of the frame origin");
  m.def(
      "frame_jacobian",
      [](std::shared_ptr<Model> model, py::object ws_obj, py::handle q, py::handle frame,
         const std::string& expressed) {
    PyWorkspace& pw = workspaceArg(model, ws_obj);
    const int f = frameArg(*model, frame);
    const Expressed e = expressedArg("expressed", expressed, true);
    const auto qv = vectorArg("q", q, pw.q_buf);
    Eigen::MatrixXd J(6, model->nv());
    ++pw.generation;
    if (const Status s = frameJacobian(*model, *pw.ws, qv, f, e, J); !s) raiseStatus(s, "frame_jacobian");
    return matrixCopy(J);
      },
      py::arg("model"), py::arg("ws"), py::arg("q"), py::arg("frame"), py::arg("expressed") = "local",
      "6×nv J with frame_velocity = J qd (nv = dof on a fixed base)");
}

// A joint argument of the centre-of-mass functions: None (the whole robot), a joint name or an index in model.joints.
int comJointArg(const Model& model, py::handle joint) {
  if (joint.is_none()) return kWholeRobot;
  if (py::isinstance<py::str>(joint)) return model.jointIndex(joint.cast<std::string>());
  if (py::isinstance<py::int_>(joint) && !py::isinstance<py::bool_>(joint)) {
    const long j = joint.cast<long>();
    if (j < 0 || j >= static_cast<long>(model.joints().size()))
      raise(exceptions().model_error, "joint index " + std::to_string(j) + " is out of range (the model has " +
                                          std::to_string(model.joints().size()) + " joints below the root)");
    return static_cast<int>(j);
  }
  raise(PyExc_TypeError, "joint: expected None (the whole robot), a joint name (str) or index (int)");
}

// A centre-of-mass query at (q, qd) (qd None: poses only), as the frame queries: read or computed first.
template <class Query>
void comQuery(const std::shared_ptr<Model>& model, const py::object& ws_obj, py::handle q, py::handle qd,
              const char* name, Query query) {
  PyWorkspace& pw = workspaceArg(model, ws_obj);
  const auto qv = vectorArg("q", q, pw.q_buf);
  const Status s = qd.is_none() ? queryOrCompute(*model, pw, qv, Eigen::VectorXd(), query)
                                : queryOrCompute(*model, pw, qv, vectorArg("qd", qd, pw.qd_buf), query);
  if (!s) raiseStatus(s, name);
}

// subtree_mass, center_of_mass, center_of_mass_velocity, jacobian_center_of_mass, centroidal_momentum.
void bindCenterOfMass(py::module_& m) {
  m.def(
      "subtree_mass",
      [](std::shared_ptr<Model> model, py::handle joint) {
    double mass = 0.0;
    if (const Status s = subtreeMass(*model, comJointArg(*model, joint), mass); !s) raiseStatus(s, "subtree_mass");
    return mass;
      },
      py::arg("model"), py::arg("joint") = py::none(),
      "mass [kg] of the subtree below a joint (name or index), or of every moving body (joint=None)");
  m.def(
      "center_of_mass",
      [](std::shared_ptr<Model> model, py::object ws_obj, py::handle q, py::handle joint) {
    const int j = comJointArg(*model, joint);
    Vec3 c;
    comQuery(model, ws_obj, q, py::none(), "center_of_mass", [&](const VectorView& qv, const VectorView&) {
      return centerOfMass(*model, *ws_obj.cast<PyWorkspace&>().ws, qv, j, c);
    });
    return vectorCopy(c);
      },
      py::arg("model"), py::arg("ws"), py::arg("q"), py::arg("joint") = py::none(),
      "centre of mass [m], world coordinates, of the robot (joint=None) or of a joint's subtree");
  m.def(
      "center_of_mass_velocity",
      [](std::shared_ptr<Model> model, py::object ws_obj, py::handle q, py::handle qd, py::handle joint) {
    const int j = comJointArg(*model, joint);
    Vec3 v;
    comQuery(model, ws_obj, q, qd, "center_of_mass_velocity", [&](const VectorView& qv, const VectorView& qdv) {
      return centerOfMassVelocity(*model, *ws_obj.cast<PyWorkspace&>().ws, qv, qdv, j, v);
    });
    return vectorCopy(v);
      },
      py::arg("model"), py::arg("ws"), py::arg("q"), py::arg("qd"), py::arg("joint") = py::none(),
      "velocity of the centre of mass [m/s], world axes");
  m.def(
      "centroidal_momentum",
      [](std::shared_ptr<Model> model, py::object ws_obj, py::handle q, py::handle qd, py::handle joint) {
    const int j = comJointArg(*model, joint);
    Vec6 h;
    comQuery(model, ws_obj, q, qd, "centroidal_momentum", [&](const VectorView& qv, const VectorView& qdv) {
      return centroidalMomentum(*model, *ws_obj.cast<PyWorkspace&>().ws, qv, qdv, j, h);
    });
    return vectorCopy(h);
      },
      py::arg("model"), py::arg("ws"), py::arg("q"), py::arg("qd"), py::arg("joint") = py::none(),
      "[linear momentum; angular momentum about the centre of mass], world axes (Pinocchio's hg)");
  m.def(
      "jacobian_center_of_mass",
      [](std::shared_ptr<Model> model, py::object ws_obj, py::handle q, py::handle joint) {
    PyWorkspace& pw = workspaceArg(model, ws_obj);
    const int j = comJointArg(*model, joint);
    const auto qv = vectorArg("q", q, pw.q_buf);
    Eigen::MatrixXd J(3, model->nv());
    ++pw.generation;
    if (const Status s = jacobianCenterOfMass(*model, *pw.ws, qv, j, J); !s) raiseStatus(s, "jacobian_center_of_mass");
    return matrixCopy(J);
      },
      py::arg("model"), py::arg("ws"), py::arg("q"), py::arg("joint") = py::none(),
      "3×nv J_com with center_of_mass_velocity = J_com qd, world axes");
}

// forward_dynamics and inverse_dynamics: (q, qd, x) with `x_name` τ or q̈, the task of wrenches and gravity
// built once per workspace; `algorithm` runs the C++ call and returns where its result lands.
template <class Algorithm>
py::array dynamicsCall(const std::shared_ptr<Model>& model, const py::object& ws_obj, py::handle q, py::handle qd,
                       py::handle x, const char* x_name, py::handle wrenches, py::handle gravity, const char* name,
                       Algorithm algorithm) {
  PyWorkspace& pw = workspaceArg(model, ws_obj);
  Task& task = idTask(pw, wrenches, gravity);
  const auto qv = vectorArg("q", q, pw.q_buf);
  const auto qdv = optionalVector("qd", qd, pw.qd_buf, pw.zeros);
  const auto xv = optionalVector(x_name, x, pw.qdd_buf, pw.zeros);
  ++pw.generation;
  const Eigen::VectorXd* result = nullptr;
  if (const Status s = algorithm(*pw.ws, qv, qdv, xv, task, result); !s) raiseStatus(s, name);
  return vectorCopy(*result);
}

using ConstVector = Eigen::Ref<const Eigen::VectorXd>;

// forward_dynamics, inverse_dynamics, joint_space_inertia.
void bindDynamics(py::module_& m) {
  m.def(
      "forward_dynamics",
      [](std::shared_ptr<Model> model, py::object ws_obj, py::handle q, py::handle qd, py::handle tau,
         py::handle wrenches, py::handle gravity) {
    return dynamicsCall(model, ws_obj, q, qd, tau, "tau", wrenches, gravity, "forward_dynamics",
                        [&](Workspace& ws, const ConstVector& qv, const ConstVector& qdv, const ConstVector& tauv,
                            const Task& task, const Eigen::VectorXd*& result) {
      result = &ws.solution.qdd;
      return forwardDynamics(*model, ws, qv, qdv, tauv, task);
    });
      },
      py::arg("model"), py::arg("ws"), py::arg("q"), py::arg("qd") = py::none(), py::arg("tau") = py::none(),
      py::kw_only(), py::arg("wrenches") = py::none(), py::arg("gravity") = py::none(),
      "ABA: q̈ of the unconstrained robot under τ, gravity and wrenches (the inverse of inverse_dynamics; mimic\n"
      "couplings kept), a new array. For constraints or friction: solve().");
  m.def(
      "inverse_dynamics",
      [](std::shared_ptr<Model> model, py::object ws_obj, py::handle q, py::handle qd, py::handle qdd,
         py::handle wrenches, py::handle gravity) {
    return dynamicsCall(model, ws_obj, q, qd, qdd, "qdd", wrenches, gravity, "inverse_dynamics",
                        [&](Workspace& ws, const ConstVector& qv, const ConstVector& qdv, const ConstVector& qddv,
                            const Task& task, const Eigen::VectorXd*& result) {
      result = &ws.tau;
      return inverseDynamics(*model, ws, qv, qdv, qddv, task);
    });
      },
      py::arg("model"), py::arg("ws"), py::arg("q"), py::arg("qd") = py::none(), py::arg("qdd") = py::none(),
      py::kw_only(), py::arg("wrenches") = py::none(), py::arg("gravity") = py::none(),
      "RNEA: τ = H(q) q̈ + C(q, q̇) − Σ Jᵀ F_ext (rotor inertias included), a new array");
  m.def(
      "joint_space_inertia",
      [](std::shared_ptr<Model> model, py::object ws_obj, py::handle q) {
    PyWorkspace& pw = workspaceArg(model, ws_obj);
    const auto qv = vectorArg("q", q, pw.q_buf);
    ++pw.generation;
    if (const Status s = jointSpaceInertia(*model, *pw.ws, qv); !s) raiseStatus(s, "joint_space_inertia");
    return matrixCopy(pw.ws->H);
      },
      py::arg("model"), py::arg("ws"), py::arg("q"), "CRBA: H(q), rotor inertias included, a new array");
}

}  // namespace

SolveInputs solveInputs(const std::shared_ptr<Model>& model, py::handle ws_obj, py::handle q, py::handle qd,
                        py::handle tau, py::handle constraints, py::handle wrenches, py::handle friction,
                        py::handle gravity, py::handle balance, py::handle modes) {
  const SolveArgs a = solveArgs(model, ws_obj, q, qd, tau, constraints, wrenches, friction, gravity, balance, modes);
  return {&a.task, a.friction, a.q, a.qd, a.tau};
}

void bindSolve(py::module_& m) {
  bindWorkspace(m);
  bindConstraint(m);
  bindWrench(m);
  bindFriction(m);
  bindBalance(m);
  bindResult(m);
  bindSolveFunctions(m);
  bindKinematics(m);
  bindCenterOfMass(m);
  bindDynamics(m);
}

}  // namespace zwang::python
