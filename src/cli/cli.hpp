// The zwang command-line tool: shared declarations (docs/cli.md).
//
// Every failure is a CliError carrying the exit code and ONE line of text,
// printed by main() as "zwang: <message>". Exit codes:
//   0 success, 1 error (input, model, solver), 2 usage, 3 infeasible task.
#pragma once

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "problem/problem.hpp"
#include "zwang/model.hpp"

namespace zwang::cli {

enum ExitCode { kExitOk = 0, kExitError = 1, kExitUsage = 2, kExitInfeasible = 3 };

class CliError : public std::runtime_error {
 public:
  CliError(int exit_code, const std::string& message) : std::runtime_error(message), code_(exit_code) {}
  int exitCode() const { return code_; }

 private:
  int code_;
};

// A usage error: printed with the command's usage text, exit code 2.
class UsageError : public CliError {
 public:
  UsageError(const std::string& command, const std::string& message)
      : CliError(kExitUsage, message), command_(command) {}
  const std::string& command() const { return command_; }

 private:
  std::string command_;
};

// Usage text of a command ("" for the tool itself).
const char* usageText(const std::string& command);

// The arguments after the command name, split into options and positionals.
// Options: "--name", "--name VALUE" (for names in `with_value`), "-o VALUE".
// "--help"/"-h" anywhere sets help. Anything else starting with '-' is an
// unknown option (UsageError).
struct Arguments {
  std::vector<std::string> positional;
  std::vector<std::pair<std::string, std::string>> options;  // name → value ("" for flags)
  bool help = false;

  bool has(const std::string& name) const;
  std::string value(const std::string& name, const std::string& fallback = "") const;
};
Arguments parseArguments(const std::string& command, int argc, char** argv, int first,
                         const std::vector<std::string>& flags, const std::vector<std::string>& with_value);

// The arguments of a command on one problem file: PROBLEM.json [-o|--output FILE] [--pretty]. nullopt after
// printing the command's usage for --help; UsageError for no file or more than one.
struct ProblemArguments {
  std::string file, output;  // output empty: stdout
  bool pretty = false;
};
std::optional<ProblemArguments> problemArguments(const char* command, int argc, char** argv);

// One printable line (the problem layer's: its messages and the tool's cut names alike).
using problem::printable;

// Each of the model's warnings once on stderr: "zwang: warning: <message>".
void printWarnings(const Model& model);

// The URDF options of --root, --tip, --base and the flags --strict, --attach-beyond-tip and --lock-mimic (false
// where `command` takes none), named as the command line spells them; UsageError naming `command` for a bad --base.
internal::NamedUrdfOptions commandLineUrdfOptions(const std::string& command, const Arguments& args);

// Read a whole file; CliError "<path>: cannot read the file (<reason>)" on failure.
// Files larger than max_bytes are refused.
std::string readFile(const std::string& path, std::size_t max_bytes);

// Write text to path, or to stdout when path is empty.
void writeOutput(const std::string& path, const std::string& text);

// Where the model files are: --models DIR, else the source tree's models/ when it
// holds `file`, else the installed share/zwang/models.
std::string modelsDirectory(const Arguments& args, const std::string& file);

// Print rows as a fixed-width table: the first `left` columns left-aligned, the
// others right-aligned; trailing blanks trimmed.
void printColumns(const std::vector<std::vector<std::string>>& rows, std::size_t left = 1);

// Run `gnuplot SCRIPT` in `dir`. When gnuplot is missing or fails, says so on
// stderr in one line (naming `command`) and returns false.
bool plotWithGnuplot(const std::string& command, const std::filesystem::path& dir, const std::string& script);

// The report commands (`scenarios`, `energy`): options --out DIR, --models DIR,
// --no-plots, no positional arguments; one model from the models directory;
// a CSV and, with gnuplot, PNG plots into --out.
struct ReportCommand {
  std::string name;  // the command, for messages
  Arguments args;
  std::filesystem::path out;   // --out (created)
  std::filesystem::path urdf;  // the model file loaded
  Model model;
  std::string shownUrdf() const;  // urdf relative to the working directory when it can be
};
// The model it expects: `dof` joints and these frames, described as `what` in
// the error ("energy: PATH: expected the 7-joint Panda with frames ...").
struct ExpectedModel {
  const char* file;
  int dof;
  std::vector<std::string> frames;
  const char* what;
};
// Parse, load, check and create the output directory (default `default_out`).
// --help: prints the usage and returns nothing (exit 0). UsageError for a
// positional argument; CliError for a model that does not load ("<command>:
// <ModelError> (use --models DIR)") or is not the expected one, and for an
// output directory that cannot be created.
std::optional<ReportCommand> startReportCommand(const std::string& command, int argc, char** argv,
                                                const std::string& default_out, const ExpectedModel& expected);
// Unless --no-plots: write `script` to OUT/script_name, run gnuplot on it there
// and say "wrote OUT/<pngs> (gnuplot, script <script_name>)". run_gnuplot
// false: write the script only (gnuplot has already failed once, and said so).
// False when there are no plots although they were asked for.
bool writePlots(const ReportCommand& report, const std::string& script_name, const std::string& script,
                const std::string& pngs, bool run_gnuplot = true);
// kExitOk, or kExitError after "zwang: <command>: a result disagrees with
// <reference> (see the check column)" on stderr.
int reportExitCode(const ReportCommand& report, bool all_ok, const std::string& reference);

// The commands; each returns the exit code.
int commandSolve(int argc, char** argv);
// `zwang forward-dynamics PROBLEM.json`: the same problem, solved without constraints or friction.
int commandForwardDynamics(int argc, char** argv);
int commandSimulate(int argc, char** argv);
int commandInfo(int argc, char** argv);
// `zwang fk MODEL.urdf [--q Q] …` or `zwang fk PROBLEM.json`: frame poses and the centre of mass (fk.cpp).
int commandFk(int argc, char** argv);
int commandScenarios(int argc, char** argv);
int commandEnergy(int argc, char** argv);
// `zwang compare-mujoco MODEL.xml …`: MuJoCo's soft joint friction against zwang's exact friction at rest
// (compare_mujoco.cpp; without MuJoCo it says that it needs it).
int commandCompareMujoco(int argc, char** argv);
// Its scenarios are in energy_report.hpp.

}  // namespace zwang::cli
