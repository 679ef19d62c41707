// The zwang command-line tool: shared declarations (docs/cli.md).
//
// Every failure is a CliError carrying the exit code and ONE line of text,
// printed by main() as "zwang: <message>". Exit codes:
//   0 success, 1 error (input, model, solver), 2 usage, 3 infeasible task.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

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

// One printable line: control bytes and non-ASCII bytes as \xNN, at most
// `max_length` characters (the rest elided with "...").
std::string printable(const std::string& text, std::size_t max_length = 200);

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

// The commands; each returns the exit code.
int commandSolve(int argc, char** argv);
int commandInfo(int argc, char** argv);
int commandScenarios(int argc, char** argv);
int commandEnergy(int argc, char** argv);

}  // namespace zwang::cli
