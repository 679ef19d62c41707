// `zwang solve PROBLEM.json [-o FILE] [--pretty]`.
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

}  // namespace

int commandSolve(int argc, char** argv) {
  const Arguments args = parseArguments("solve", argc, argv, 2, {"--pretty"}, {"-o", "--output"});
  if (args.help) {
    std::fputs(usageText("solve"), stdout);
    return kExitOk;
  }
  if (args.positional.size() != 1)
    throw UsageError("solve", args.positional.empty() ? "no problem file given" : "more than one problem file given");
  const std::string output = args.has("--output") ? args.value("--output") : args.value("-o");

  const Problem problem = readProblem(args.positional[0]);
  BoundProblem bound = bindProblem(problem);
  printWarnings(bound.model);
  for (const ModelWarning& w : bound.task->warnings())  // the task's, e.g. contacts on a bolted-down base
    std::fprintf(stderr, "zwang: warning: %s: %s\n", problem.file.c_str(), printable(w.message, 4000).c_str());
  warnOutsideLimits(problem.file, bound.model, bound.q);
  Workspace ws(bound.model, *bound.task);
  const Status status = problem::solve(bound.model, ws, bound.q, bound.qd, bound.tau, *bound.task,
                                       bound.with_friction ? &bound.friction_options : nullptr);
  const bool infeasible = status.code == StatusCode::Infeasible;
  if (!status && !infeasible) throw CliError(kExitError, problem.file + ": solve: " + status.message);

  const Json solution = solutionJson(bound.model, ws, bound.with_friction, status, bound.reported_frames);
  writeOutput(output, (args.has("--pretty") ? prettyDump(solution) : solution.dump()) + "\n");
  if (!ws.solution.balance.consistent)  // met only in the least-squares sense, or a damped direction gave
    std::fprintf(stderr, "zwang: warning: %s: the task is not met: |A^T Xdd - b| = %.3g (status.consistent = false)\n",
                 problem.file.c_str(), ws.solution.balance.residual);
  if (infeasible) {
    std::fprintf(stderr, "zwang: %s: infeasible: %s\n", problem.file.c_str(), status.message);
    return kExitInfeasible;
  }
  return kExitOk;
}

}  // namespace zwang::cli
