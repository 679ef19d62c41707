// The Python module `zwang`: exceptions and the module definition.
#include <Python.h>

#include "bindings.hpp"

namespace zwang::python {

namespace {

Exceptions g_exceptions;

// A new exception class `zwang.<name>` deriving from `bases` (a tuple).
py::handle newException(py::module_& m, const char* name, py::tuple bases, const char* doc) {
  const std::string qualified = std::string("zwang.") + name;
  PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, bases.ptr(), nullptr);
  if (type == nullptr) throw py::error_already_set();
  m.add_object(name, py::handle(type));  // the module keeps a reference (plus ours, never released)
  return py::handle(type);
}

}  // namespace

const Exceptions& exceptions() { return g_exceptions; }

const char* codeName(StatusCode code) {
  switch (code) {
    case StatusCode::Ok: return "Ok";
    case StatusCode::SizeMismatch: return "SizeMismatch";
    case StatusCode::NonFinite: return "NonFinite";
    case StatusCode::WorkspaceTooSmall: return "WorkspaceTooSmall";
    case StatusCode::ModelMismatch: return "ModelMismatch";
    case StatusCode::Degenerate: return "Degenerate";
    case StatusCode::BadOption: return "BadOption";
    case StatusCode::Infeasible: return "Infeasible";
    case StatusCode::MimicMismatch: return "MimicMismatch";
    case StatusCode::BadConfiguration: return "BadConfiguration";
    case StatusCode::NotComputed: return "NotComputed";
    case StatusCode::EventCascade: return "EventCascade";
  }
  return "Unknown";
}

void raise(py::handle type, const std::string& message) {
  PyErr_SetString(type.ptr(), message.c_str());
  throw py::error_already_set();
}

const problem::Spelling kPython{'\'', "comes first in q, qd and tau"};

void raiseProblem(const std::string& where, const problem::ProblemError& e) {
  const std::string path = e.key().empty() ? where : where.empty() ? e.key() : where + "." + e.key();
  const py::handle type = e.fault() == problem::Fault::Value ? py::handle(PyExc_ValueError) : exceptions().model_error;
  raise(type, (path.empty() ? "" : path + ": ") + e.what());
}

void raiseStatus(const Status& status, const char* where, py::object result) {
  const Exceptions& e = exceptions();
  const py::handle type = status.code == StatusCode::Infeasible ? e.infeasible_error : e.solve_error;
  py::object instance = type(py::str(std::string(where) + ": " + status.message));
  instance.attr("code") = py::str(codeName(status.code));
  instance.attr("status_message") = py::str(status.message);
  instance.attr("result") = std::move(result);
  PyErr_SetObject(type.ptr(), instance.ptr());
  throw py::error_already_set();
}

}  // namespace zwang::python

PYBIND11_MODULE(zwang, m) {
  using namespace zwang::python;
  m.doc() =
      "zwang: constrained hybrid dynamics (Popov-Vereshchagin) with exact static friction.\n\n"
      "    model = zwang.load_urdf('models/panda.urdf', tip='tool0')\n"
      "    ws = model.workspace()\n"
      "    res = zwang.solve(model, ws, q, qd, tau, constraints=[...], wrenches=[...],\n"
      "                      friction=zwang.Friction(margin=0.8))\n"
      "    res.qdd, res.tau_control, res.mu, res.state\n\n"
      "Spatial vectors are linear part first, SI units; see docs/python.md.";
  m.attr("__version__") = ZWANG_VERSION;

  Exceptions& e = g_exceptions;
  e.error = newException(m, "Error", py::make_tuple(py::handle(PyExc_Exception)), "Base class of zwang's errors.");
  e.model_error = newException(m, "ModelError", py::make_tuple(e.error, py::handle(PyExc_ValueError)),
                               "A model or URDF that cannot be built, or an unknown joint or frame name.");
  e.solve_error = newException(m, "SolveError", py::make_tuple(e.error, py::handle(PyExc_ValueError)),
                               "A solve refused its input. Attributes: code (the C++ StatusCode name), "
                               "status_message (the C++ Status message), result (None).");
  e.infeasible_error = newException(m, "InfeasibleError", py::make_tuple(e.solve_error),
                                    "The task drives a joint into its position limit "
                                    "(docs/friction.md, 'Joint position limits'). "
                                    "The finite, non-physical solution is in the `result` attribute.");
  e.stale_error = newException(m, "StaleResultError", py::make_tuple(e.error, py::handle(PyExc_RuntimeError)),
                               "A live Result was read after its workspace was used again; use Result.copy() "
                               "to keep results.");

  e.model_warning = newException(m, "ModelWarning", py::make_tuple(py::handle(PyExc_UserWarning)),
                                 "Doubtful but usable model data (a point mass, a placeholder inertia or limit, "
                                 "mass beyond the tip, ...), issued once per warning by load_urdf. "
                                 "load_urdf(..., strict=True) raises ModelError instead. solve() issues a q "
                                 "outside a joint's limits and contacts on a fixed base with mass once per model, "
                                 "code and joint (Result.warnings has every occurrence).");

  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const zwang::ModelError& error) {
      PyErr_SetString(exceptions().model_error.ptr(), error.what());
    }
  });

  bindModel(m);
  bindSolve(m);
  bindSimulate(m);
  bindConfiguration(m);
}
