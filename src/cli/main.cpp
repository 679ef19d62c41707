// zwang: the command-line tool (docs/cli.md).
//
//   zwang solve PROBLEM.json [-o FILE] [--pretty]
//   zwang forward-dynamics PROBLEM.json [-o FILE] [--pretty]
//   zwang simulate PROBLEM.json [-o FILE] [--pretty]
//   zwang info MODEL.urdf [--root L] [--tip L] [--json]
//   zwang fk MODEL.urdf [--q Q] [--root L] [--tip L] [--base B] [--pretty] | zwang fk PROBLEM.json [--pretty]
//   zwang scenarios [--out DIR] [--models DIR] [--no-plots]
//   zwang energy [--out DIR] [--models DIR] [--no-plots]
//   zwang compare-mujoco MODEL.xml [--state FILE] [--postures N] [--seed S] [--seconds T,…] [--json] [--csv DIR]
#include <cstdio>
#include <cstring>
#include <exception>
#include <new>
#include <string>

#include "cli.hpp"

namespace {

using namespace zwang::cli;

int run(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "zwang: no command given\n\n%s", usageText(""));
    return kExitUsage;
  }
  const std::string command = argv[1];
  if (command == "--help" || command == "-h" || command == "help") {
    std::fputs(usageText(""), stdout);
    return kExitOk;
  }
  if (command == "--version") {
    std::printf("zwang %s\n", ZWANG_VERSION);
    return kExitOk;
  }
  if (command == "solve") return commandSolve(argc, argv);
  if (command == "forward-dynamics") return commandForwardDynamics(argc, argv);
  if (command == "simulate") return commandSimulate(argc, argv);
  if (command == "info") return commandInfo(argc, argv);
  if (command == "fk") return commandFk(argc, argv);
  if (command == "scenarios") return commandScenarios(argc, argv);
  if (command == "energy") return commandEnergy(argc, argv);
  if (command == "compare-mujoco") return commandCompareMujoco(argc, argv);
  std::fprintf(stderr, "zwang: unknown command '%s'\n\n%s", printable(command, 60).c_str(), usageText(""));
  return kExitUsage;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const UsageError& e) {
    const std::string usage = usageText(e.command());
    std::fprintf(stderr, "zwang: %s: %s\n%s(zwang %s --help for the options)\n", e.command().c_str(), e.what(),
                 usage.substr(0, usage.find('\n') + 1).c_str(), e.command().c_str());
    return e.exitCode();
  } catch (const CliError& e) {
    // Our own messages: whole (a name list is already limited by its maker).
    std::fprintf(stderr, "zwang: %s\n", printable(e.what(), std::string::npos - 4).c_str());
    return e.exitCode();
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "zwang: out of memory\n");
    return kExitError;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "zwang: internal error: %s\n", printable(e.what(), 400).c_str());
    return kExitError;
  }
}
