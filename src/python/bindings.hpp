// Shared declarations of the Python module `zwang` (docs/python.md).
//
// Ownership: a Python Model holds a std::shared_ptr<Model>; a Workspace holds
// the model it was made for, the C++ Workspace, and the Task it built from the
// last `constraints=`/`wrenches=` lists (rebuilt only when those lists change).
// A Result is a read-only window on the workspace that produced it (NumPy
// views, no copy) until the next call on that workspace; Result.copy() detaches
// it.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "problem/problem.hpp"
#include "zwang/zwang.hpp"

namespace zwang::python {

namespace py = pybind11;

// ---- errors (module.cpp) ---------------------------------------------------
// zwang.Error, zwang.ModelError, zwang.SolveError, zwang.InfeasibleError, zwang.StaleResultError.
// zwang.ModelWarning (a UserWarning) for the model's warnings.
struct Exceptions {
  py::handle error, model_error, solve_error, infeasible_error, stale_error, model_warning;
};
const Exceptions& exceptions();
const char* codeName(StatusCode code);
// Raise the Python exception for a failed Status (never returns).
[[noreturn]] void raiseStatus(const Status& status, const char* where, py::object result = py::none());
[[noreturn]] void raise(py::handle type, const std::string& message);

// The problem layer's messages quote Python's way.
extern const problem::Spelling kPython;
// A problem layer fault as a Python exception: "WHERE.KEY: what", a ValueError
// for a bad value, a ModelError for what the model refuses.
[[noreturn]] void raiseProblem(const std::string& where, const problem::ProblemError& e);
// Run a step of the problem layer, its fault raised at `where`.
template <class F>
auto checked(const std::string& where, F step) -> decltype(step()) {
  try {
    return step();
  } catch (const problem::ProblemError& e) {
    raiseProblem(where, e);
  }
}

// ---- conversions (convert.cpp) ----------------------------------------------
// A 1-D real array argument. A contiguous float64 array is read in place; any
// other real-valued input (list, tuple, int or float32 array, strided view) is
// converted into `buffer` (no allocation when it already has the length).
// TypeError for non-real dtypes (complex, bool, strings, objects), ValueError
// for a wrong number of dimensions. Lengths are checked by the C++ solver.
Eigen::Map<const Eigen::VectorXd> vectorArg(const char* name, py::handle value, Eigen::VectorXd& buffer);
// Same, into a fixed-size vector with its length checked here.
Vec3 vec3Arg(const char* name, py::handle value);
Vec6 vec6Arg(const char* name, py::handle value);
// A rows×cols real matrix (any dtype, any strides), its shape checked here.
Eigen::MatrixXd matrixArg(const char* name, py::handle value, int rows, int cols);
// A 6×m constraint matrix (a 6-vector is one column).
ConstraintMatrix constraintMatrixArg(const char* name, py::handle value);
// "reference" only where allow_reference (a relative constraint).
Expressed expressedArg(const char* name, const std::string& text, bool allow_aligned, bool allow_reference = false);
const char* expressedName(Expressed e);

// Read-only NumPy views of workspace memory that keep `base` alive.
py::array vectorView(const Eigen::VectorXd& v, py::handle base, bool writeable = false);
py::array vectorView(const double* data, Eigen::Index size, py::handle base, bool writeable = false);
py::array matrixView(const Eigen::MatrixXd& m, py::handle base);
py::array vectorCopy(const Eigen::Ref<const Eigen::VectorXd>& v);
py::array matrixCopy(const Eigen::Ref<const Eigen::MatrixXd>& m);

// ---- task description objects (solve.cpp) ------------------------------------
struct Constraint {
  std::uint64_t serial;          // identity for the workspace's task cache (desc is immutable)
  problem::ConstraintDesc desc;  // frame, relative_to, joint, expressed, A, contact
  Eigen::VectorXd b;             // set points, mutable
};

struct Wrench {
  std::uint64_t serial;
  std::string frame;
  Expressed expressed;
  Vec6 value;  // [force; torque], mutable
};

struct Friction {
  FrictionOptions options;
};

struct Balance {
  BalanceOptions options;
};

struct PyWorkspace {
  PyWorkspace(std::shared_ptr<Model> model, int max_constraint_rows);

  std::shared_ptr<Model> model;
  std::unique_ptr<Workspace> ws;
  // Workspaces replaced by a larger one stay alive: NumPy views may point into them.
  std::vector<std::unique_ptr<Workspace>> retired;
  std::uint64_t generation = 0;  // bumped by every call that writes the workspace

  // Task cache for solve(): rebuilt only when the constraint/wrench objects change.
  std::unique_ptr<Task> task;
  std::vector<std::uint64_t> constraint_serials, wrench_serials;
  std::vector<int> constraint_rows;  // first row of each constraint in b
  bool task_valid = false;
  std::uint64_t task_builds = 0;  // how often the task was (re)built: tests and docs
  // Task for inverse_dynamics (gravity and wrenches only).
  std::unique_ptr<Task> id_task;
  std::vector<std::uint64_t> id_wrench_serials;
  bool id_task_valid = false;

  // Conversion buffers (reused; no allocation per call).
  Eigen::VectorXd q_buf, qd_buf, tau_buf, qdd_buf, zeros;

  // Make room for `rows` constraint rows (replaces ws, retiring the old one).
  void ensureCapacity(int rows);
};

// ---- results -----------------------------------------------------------------
// Everything a Result shows, owned (Result.copy()).
struct ResultData {
  Solution solution;
  FrictionResult friction;
  Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor> frame_acc_local, frame_acc_world;
  Eigen::Matrix<double, Eigen::Dynamic, 6, Eigen::RowMajor> frame_wrench_local, frame_wrench_world;  // per frame
  py::object com;  // Result.com as it was: a dict of three arrays, or None
};

struct Result {
  std::shared_ptr<Model> model;
  // Live: a view on the workspace `owner` (a PyWorkspace) as of `generation`.
  py::object owner;
  PyWorkspace* live = nullptr;
  std::uint64_t generation = 0;
  // Detached: its own data; `base` keeps it alive for NumPy views.
  std::shared_ptr<ResultData> data;
  py::object data_base;

  bool with_friction = false;
  bool infeasible = false;
  std::string message;  // the Status message of an infeasible solve
  // Every warning of this solve as (code, message), also those already issued
  // as a zwang.ModelWarning by an earlier solve; empty (no allocation) when none.
  std::vector<std::pair<std::string, std::string>> warnings;

  const Solution& solution() const;  // raises StaleResultError when the workspace moved on
  const FrictionResult& friction() const;
  py::handle base() const;  // keeps the viewed memory alive
};

void bindModel(py::module_& m);
void bindSolve(py::module_& m);
void bindConfiguration(py::module_& m);  // configuration.cpp

// solve()'s arguments read as solve() reads them, for another entry point (simulate): the task (cached in the
// workspace), the friction options (nullptr: none), and copies of q, q̇, τ.
struct SolveInputs {
  Task* task;
  const FrictionOptions* friction;
  Eigen::VectorXd q, qd, tau;
};
SolveInputs solveInputs(const std::shared_ptr<Model>& model, py::handle ws_obj, py::handle q, py::handle qd,
                        py::handle tau, py::handle constraints, py::handle wrenches, py::handle friction,
                        py::handle gravity, py::handle balance, py::handle modes);

void bindSimulate(py::module_& m);

}  // namespace zwang::python
