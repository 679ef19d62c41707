// zwang.simulate (docs/python.md, "Simulation"): the problem over time by zwang::Simulation. The arguments are
// solve()'s (the task built the same way); the run's checks are the problem layer's, as zwang simulate's; the steps
// run with the GIL released.
#include <pybind11/stl.h>

#include "bindings.hpp"

namespace zwang::python {

namespace {

// Everything a run writes, filled without the GIL and turned into NumPy arrays after it.
struct Run {
  Eigen::VectorXd t;
  Eigen::MatrixXd q, qd, tau_control, mu;  // a row per state (q, qd: steps + 1) or per step's solve (steps)
  std::vector<std::vector<JointState>> state;
  Status status;
  long done = 0;  // steps made
};

void stepAll(Simulation& sim, long steps, const Eigen::VectorXd& tau, const std::vector<double>& knots,
             const std::vector<Eigen::VectorXd>& values, Run& run) {
  const TorqueSchedule schedule = [&](double t, Eigen::Ref<Eigen::VectorXd> out) {
    problem::scheduleAt(knots, values, t, out);
  };
  for (long k = 0; k < steps; ++k) {
    run.t[k] = sim.time();
    run.q.row(k) = sim.q().transpose();
    run.qd.row(k) = sim.qd().transpose();
    run.status = knots.empty() ? sim.step(tau) : sim.stepWith(schedule);
    if (!run.status) return;
    run.tau_control.row(k) = sim.solution().tau_control.transpose();
    run.mu.row(k) = sim.friction().mu.transpose();
    run.state[static_cast<std::size_t>(k)] = sim.friction().state;
    run.done = k + 1;
  }
  run.t[steps] = sim.time();
  run.q.row(steps) = sim.q().transpose();
  run.qd.row(steps) = sim.qd().transpose();
}

py::dict simulatePython(std::shared_ptr<Model> model, py::object ws_obj, py::handle q, py::handle qd, py::handle tau,
                        double duration, double dt, const std::string& integrator, py::handle schedule_t,
                        py::handle schedule_tau, py::handle constraints, py::handle wrenches, py::handle friction,
                        py::handle gravity, py::handle balance, py::handle modes) {
  const SolveInputs in =
      solveInputs(model, ws_obj, q, qd, tau, constraints, wrenches, friction, gravity, balance, modes);
  const long steps = checked("", [&] { return problem::simulationSteps(duration, dt); });
  SimulationOptions options;
  options.dt = dt;
  options.integrator = checked("integrator", [&] { return problem::parseIntegrator(kPython, integrator); });
  if (in.friction) options.friction = *in.friction;
  options.friction.warm_start = true;
  if (!in.friction)  // no friction at all, as solve() without `friction`
    options.friction.breakaway = options.friction.kinetic = options.friction.viscous =
        Eigen::VectorXd::Zero(model->dof());
  std::vector<double> knots;
  std::vector<Eigen::VectorXd> values;
  if (!schedule_t.is_none()) {  // τ at the knots: a (knots × nv) array
    Eigen::VectorXd t_buffer;
    const Eigen::VectorXd t = vectorArg("schedule_t", schedule_t, t_buffer);
    knots.assign(t.data(), t.data() + t.size());
    const Eigen::MatrixXd v = matrixArg("schedule_tau", schedule_tau, static_cast<int>(t.size()), model->nv());
    for (Eigen::Index k = 0; k < v.rows(); ++k) values.emplace_back(v.row(k).transpose());
    checked("schedule", [&] { problem::checkSchedule(knots, values.size()); });
  } else if (!schedule_tau.is_none()) {
    raise(PyExc_ValueError, "schedule_tau needs schedule_t (the knots' times)");
  }

  Simulation sim(*model, *in.task, options);
  if (Status s = sim.reset(in.q, in.qd); !s) raiseStatus(s, "simulate");
  Run run;
  run.t.resize(steps + 1);
  run.q.resize(steps + 1, model->nq());
  run.qd.resize(steps + 1, model->nv());
  run.tau_control.resize(steps, model->nv());
  run.mu.resize(steps, model->dof());
  run.state.resize(static_cast<std::size_t>(steps));
  {
    py::gil_scoped_release release;  // the steps touch no Python object
    stepAll(sim, steps, in.tau, knots, values, run);
  }
  if (!run.status) raiseStatus(run.status, "simulate");

  py::list events;
  for (const SimulationEvent& e : sim.events())
    events.append(py::make_tuple(e.t, problem::dofName(*model, e.dof), toString(e.kind)));
  py::list states;
  for (const std::vector<JointState>& row : run.state) {
    py::list names;
    for (const JointState s : row) names.append(toString(s));
    states.append(std::move(names));
  }
  const EnergyLedger& e = sim.energy();
  py::dict energy;
  energy["kinetic"] = e.kinetic;
  energy["potential"] = e.potential;
  energy["initial"] = e.initial;
  energy["motor_work_positive"] = e.motor_work_positive;
  energy["motor_work_negative"] = e.motor_work_negative;
  energy["motor_effort"] = e.motor_effort;
  energy["friction_dissipation"] = e.friction_dissipation;
  energy["impact_loss"] = e.impact_loss;
  energy["balance_error"] = e.balanceError();
  py::dict out;
  out["t"] = vectorCopy(run.t);
  out["q"] = matrixCopy(run.q);
  out["qd"] = matrixCopy(run.qd);
  out["tau_control"] = matrixCopy(run.tau_control);
  out["mu"] = matrixCopy(run.mu);
  out["state"] = std::move(states);
  out["events"] = std::move(events);
  out["energy"] = std::move(energy);
  return out;
}

}  // namespace

void bindSimulate(py::module_& m) {
  m.def("simulate", &simulatePython, py::arg("model"), py::arg("ws"), py::arg("q"), py::arg("qd") = py::none(),
        py::arg("tau") = py::none(), py::kw_only(), py::arg("duration"), py::arg("dt") = 1e-3,
        py::arg("integrator") = "euler", py::arg("schedule_t") = py::none(), py::arg("schedule_tau") = py::none(),
        py::arg("constraints") = py::none(), py::arg("wrenches") = py::none(), py::arg("friction") = py::none(),
        py::arg("gravity") = py::none(), py::arg("balance") = py::none(), py::arg("modes") = py::none(),
        "The motion over time (docs/simulation.md): `duration` seconds in steps of `dt`, integrator 'euler' or\n"
        "'rk4', stick, slip and limit events located inside the steps. tau is held, or schedule_t (knot times)\n"
        "and schedule_tau (knots × nv) give it piecewise linear. The other arguments are solve()'s; without\n"
        "`friction` there is none at all. The steps run with the GIL released. Returns a dict: t (steps + 1),\n"
        "q, qd (steps + 1 rows), tau_control, mu, state (a row per step: its solve at its start), events\n"
        "[(t, dof name, kind)], energy {kinetic, potential, initial, motor_work_positive, motor_work_negative,\n"
        "motor_effort, friction_dissipation, impact_loss, balance_error}.");
}

}  // namespace zwang::python
