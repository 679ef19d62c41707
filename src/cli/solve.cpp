// `zwang solve PROBLEM.json [-o FILE] [--pretty]` and `zwang forward-dynamics PROBLEM.json`.
#include <cstdio>

#include "cli.hpp"
#include "problem.hpp"
#include "solution_writer.hpp"

namespace zwang::cli {

namespace {

// A configuration outside the joint limits is solved as given (the limits
// matter to the friction solver only at a stop); it is said once per joint,
// its "q[k]" the problem's (the joints' coordinates, the base's left out).
void warnOutsideLimits(const std::string& file, const Model& model, const Eigen::VectorXd& q) {
  problem::forEachOutsideLimits(model, q, model.baseConfigurationSize(), [&](int, const std::string& message) {
    std::fprintf(stderr, "zwang: warning: %s: %s\n", file.c_str(), message.c_str());
  });
}

// What each command solves the bound problem with.
enum class Solver { Problem, ForwardDynamics };

Status solveBound(Solver solver, const BoundProblem& bound, Workspace& ws) {
  if (solver == Solver::ForwardDynamics)
    return forwardDynamics(bound.model, ws, bound.q, bound.qd, bound.tau, *bound.task);
  return problem::solve(bound.model, ws, bound.q, bound.qd, bound.tau, *bound.task,
                        bound.with_friction ? &bound.friction_options : nullptr);
}

int runProblem(const char* command, Solver solver, int argc, char** argv) {
  const std::optional<ProblemArguments> args = problemArguments(command, argc, argv);
  if (!args) return kExitOk;  // --help, printed
  const std::string& output = args->output;

  const Problem problem = readProblem(args->file);
  if (problem.simulate.present)
    throw CliError(kExitError, problem.file + ": " + command +
                                   ": the problem has a \"simulate\" section (zwang simulate runs it over time)");
  BoundProblem bound = bindProblem(problem);
  if (solver == Solver::ForwardDynamics && bound.with_friction)
    throw CliError(kExitError, problem.file + ": " + command +
                                   ": the problem has a \"friction\" section; forward dynamics takes none (zwang solve "
                                   "uses it)");
  printWarnings(bound.model);
  for (const ModelWarning& w : bound.task->warnings())  // the task's, e.g. contacts on a bolted-down base
    std::fprintf(stderr, "zwang: warning: %s: %s\n", problem.file.c_str(), printable(w.message, 4000).c_str());
  warnOutsideLimits(problem.file, bound.model, bound.q);
  Workspace ws(bound.model, *bound.task);
  const Status status = solveBound(solver, bound, ws);
  const bool infeasible = status.code == StatusCode::Infeasible;
  if (!status && !infeasible) throw CliError(kExitError, problem.file + ": " + command + ": " + status.message);

  const Json solution = solutionJson(bound.model, ws, *bound.task, bound.with_friction, status, bound.reported_frames,
                                     bound.constrained_frames);
  writeOutput(output, (args->pretty ? prettyDump(solution) : solution.dump()) + "\n");
  if (bound.with_friction)
    if (const std::string impact = problem::limitImpactMessage(bound.model, ws.friction); !impact.empty())
      std::fprintf(stderr, "zwang: warning: %s: %s\n", problem.file.c_str(), impact.c_str());
  if (!ws.solution.balance.consistent)  // met only in the least-squares sense, or a damped direction gave
    std::fprintf(stderr, "zwang: warning: %s: the task is not met: |A^T Xdd - b| = %.3g (status.consistent = false)\n",
                 problem.file.c_str(), ws.solution.balance.residual);
  if (infeasible) {
    std::fprintf(stderr, "zwang: %s: infeasible: %s\n", problem.file.c_str(), status.message);
    return kExitInfeasible;
  }
  return kExitOk;
}

}  // namespace

int commandSolve(int argc, char** argv) { return runProblem("solve", Solver::Problem, argc, argv); }

int commandForwardDynamics(int argc, char** argv) {
  return runProblem("forward-dynamics", Solver::ForwardDynamics, argc, argv);
}

}  // namespace zwang::cli
