// libFuzzer target: JSON problem text → the `zwang solve` pipeline (readProblem,
// bindProblem, the solve, solutionJson). Only CliError may leave the reader and
// the binder; the solve must return finite outputs when it succeeds (or is
// Infeasible, whose outputs docs/friction.md promises finite).
//
// The "model" key names a file; the harness never lets the fuzzer open one: it
// binds every problem to models/one_dof_arm.urdf, to models/dual_panda.urdf (a
// tree) when the model string mentions "dual", to models/panda.urdf when it
// mentions "panda", or to models/solo12.urdf (floating with a "base" section:
// contacts, joint rows) when it mentions "solo".
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

#include "cli.hpp"
#include "fuzz_common.hpp"
#include "problem.hpp"
#include "solution_writer.hpp"

namespace {

const std::string& scratchFile() {
  static const std::string path = "/tmp/zwang_fuzz_json_" + std::to_string(getpid()) + ".json";
  return path;
}

void writeScratch(const std::uint8_t* data, std::size_t size) {
  std::FILE* f = std::fopen(scratchFile().c_str(), "wb");
  if (!f) zwang::fuzz::failure("cannot write the scratch file", scratchFile().c_str());
  if (size > 0 && std::fwrite(data, 1, size, f) != size) zwang::fuzz::failure("short write", scratchFile().c_str());
  std::fclose(f);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace zwang;
  using namespace zwang::cli;
  if (size > 1 << 16) return -1;
  writeScratch(data, size);
  Problem problem;
  try {
    problem = readProblem(scratchFile());
  } catch (const CliError& e) {
    if (e.what()[0] == '\0' || e.exitCode() != kExitError) fuzz::failure("bad CliError from readProblem", e.what());
    return 0;
  }
  const bool dual = problem.model_path.find("dual") != std::string::npos;
  const bool panda = problem.model_path.find("panda") != std::string::npos;
  const bool solo = problem.model_path.find("solo") != std::string::npos;
  problem.model_path = std::string(ZWANG_MODELS_DIR) + (dual    ? "/dual_panda.urdf"
                                                        : panda ? "/panda.urdf"
                                                        : solo  ? "/solo12.urdf"
                                                                : "/one_dof_arm.urdf");
  BoundProblem bound;
  try {
    bound = bindProblem(problem);
  } catch (const CliError& e) {
    if (e.what()[0] == '\0' || e.exitCode() != kExitError) fuzz::failure("bad CliError from bindProblem", e.what());
    return 0;
  }
  Workspace ws(bound.model, *bound.task);
  const Status status =
      bound.with_friction
          ? solveWithFriction(bound.model, ws, bound.q, bound.qd, bound.tau, *bound.task, bound.friction_options)
          : solveHybridDynamics(bound.model, ws, bound.q, bound.qd, bound.tau, *bound.task);
  if (status.ok() || status.code == StatusCode::Infeasible) {
    const char* where = bound.with_friction ? "solveWithFriction (JSON problem)" : "solveHybridDynamics (JSON problem)";
    fuzz::requireFinite(ws.solution.qdd, "qdd", where);
    fuzz::requireFinite(ws.solution.nu, "nu", where);
    fuzz::requireFinite(ws.solution.tau_control, "tau_control", where);
    fuzz::requireFinite(ws.solution.gauss, "gauss", where);
    if (bound.with_friction) fuzz::requireFinite(ws.friction.mu, "mu", where);
    const Json solution = solutionJson(bound.model, ws, *bound.task, bound.with_friction, status, bound.reported_frames,
                                       bound.constrained_frames);
    if (solution.dump().empty()) fuzz::failure("empty solution JSON", where);
  } else if (status.code != StatusCode::Degenerate && status.code != StatusCode::BadOption) {
    fuzz::failure("unexpected status for a bound problem", status.message);
  }
  return 0;
}
