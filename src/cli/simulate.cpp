// `zwang simulate PROBLEM.json [-o FILE] [--pretty]` (docs/cli.md, "zwang simulate"): the problem's motion over
// time by zwang::Simulation; the problem layer checks the "simulate" and "schedule" sections, this translates and
// prints.
#include <cstdio>

#include "cli.hpp"
#include "problem.hpp"
#include "solution_writer.hpp"

namespace zwang::cli {

namespace {

// Per step, as the output writes them: the joints' coordinates (a floating base's apart), the solve's per-DOF values.
struct Record {
  Json t = Json::array(), q = Json::array(), qd = Json::array(), base_q = Json::array(), base_qd = Json::array();
  Json tau_control = Json::array(), mu = Json::array(), state = Json::array();
};

void recordState(const Model& model, const Simulation& sim, Record& r) {
  const int bq = model.baseConfigurationSize(), bv = model.baseVelocitySize();
  r.t.push_back(sim.time());
  r.q.push_back(array(sim.q().tail(model.nq() - bq)));
  r.qd.push_back(array(sim.qd().tail(model.dof())));
  if (model.hasFloatingBase()) {
    r.base_q.push_back(array(sim.q().head(bq)));
    r.base_qd.push_back(array(sim.qd().head(bv)));
  }
}

void recordSolve(const Model& model, const Simulation& sim, Record& r) {
  r.tau_control.push_back(array(sim.solution().tau_control.tail(model.dof())));
  r.mu.push_back(array(sim.friction().mu));
  Json states = Json::array();
  for (const JointState state : sim.friction().state) states.push_back(toString(state));
  r.state.push_back(std::move(states));
}

Json energyJson(const EnergyLedger& e) {
  return {{"kinetic", e.kinetic},
          {"potential", e.potential},
          {"initial", e.initial},
          {"motor_work_positive", e.motor_work_positive},
          {"motor_work_negative", e.motor_work_negative},
          {"motor_effort", e.motor_effort},
          {"friction_dissipation", e.friction_dissipation},
          {"impact_loss", e.impact_loss},
          {"balance_error", e.balanceError()}};
}

// The friction the run feels: the "friction" section's options, or none at all without one (every box, kinetic and
// viscous coefficient zero).
SimulationOptions simulationOptions(const Model& model, const Problem& problem, const BoundProblem& bound) {
  SimulationOptions o;
  o.dt = problem.simulate.dt;
  o.integrator = problem.simulate.integrator;
  o.friction = bound.friction_options;
  o.friction.warm_start = true;
  if (!bound.with_friction)
    o.friction.breakaway = o.friction.kinetic = o.friction.viscous = Eigen::VectorXd::Zero(model.dof());
  return o;
}

}  // namespace

int commandSimulate(int argc, char** argv) {
  const char* command = "simulate";
  const std::optional<ProblemArguments> args = problemArguments(command, argc, argv);
  if (!args) return kExitOk;  // --help, printed
  const std::string& output = args->output;

  const Problem problem = readProblem(args->file);
  if (!problem.simulate.present)
    throw CliError(kExitError, problem.file +
                                   ": simulate: the problem has no \"simulate\" section (its \"duration\" "
                                   "[s], and \"dt\", \"integrator\")");
  const BoundProblem bound = bindProblem(problem);
  printWarnings(bound.model);
  const Model& model = bound.model;
  Simulation sim(model, *bound.task, simulationOptions(model, problem, bound));
  if (Status s = sim.reset(bound.q, bound.qd); !s)
    throw CliError(kExitError, problem.file + ": simulate: " + s.message);
  const bool scheduled = !bound.schedule_t.empty();
  const TorqueSchedule schedule = [&bound](double t, Eigen::Ref<Eigen::VectorXd> tau) {
    problem::scheduleAt(bound.schedule_t, bound.schedule_tau, t, tau);
  };
  Record record;
  for (long k = 0; k < problem.simulate.steps; ++k) {
    recordState(model, sim, record);
    const Status s = scheduled ? sim.stepWith(schedule) : sim.step(bound.tau);
    if (!s)
      throw CliError(kExitError,
                     problem.file + ": simulate: at t = " + std::to_string(sim.time()) + " s: " + s.message);
    recordSolve(model, sim, record);
  }
  recordState(model, sim, record);

  Json events = Json::array();
  for (const SimulationEvent& e : sim.events())
    events.push_back({{"t", e.t}, {"joint", problem::dofName(model, e.dof)}, {"kind", toString(e.kind)}});
  Json dofs = Json::array();
  for (int k = 0; k < model.dof(); ++k) dofs.push_back(problem::dofName(model, k));
  Json out = {{"dofs", std::move(dofs)},
              {"simulate",
               {{"duration", problem.simulate.duration},
                {"dt", problem.simulate.dt},
                {"integrator", toString(problem.simulate.integrator)},
                {"steps", problem.simulate.steps},
                {"friction", bound.with_friction}}},
              {"t", std::move(record.t)},
              {"q", std::move(record.q)},
              {"qd", std::move(record.qd)}};
  if (model.hasFloatingBase()) out["base"] = {{"q", std::move(record.base_q)}, {"qd", std::move(record.base_qd)}};
  out["tau_control"] = std::move(record.tau_control);
  out["mu"] = std::move(record.mu);
  out["state"] = std::move(record.state);
  out["events"] = std::move(events);
  out["energy"] = energyJson(sim.energy());
  writeOutput(output, (args->pretty ? prettyDump(out) : out.dump()) + "\n");
  return kExitOk;
}

}  // namespace zwang::cli
