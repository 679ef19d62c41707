// Running the built `zwang` binary from the tests: exit code, stdout, stderr.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace cli_test {

struct Run {
  int exit_code = -1;  // the process's exit status; 128 + signal when it was killed
  bool signaled = false;
  std::string out, err;
};

// Run ZWANG_CLI with `args`; `env` entries replace (or add) environment variables.
Run run(const std::vector<std::string>& args, const std::map<std::string, std::string>& env = {});

// A fresh scratch directory for this test process (under ZWANG_CLI_SCRATCH).
std::string scratchDir();
std::string readText(const std::string& path);
void writeText(const std::string& path, const std::string& text);
bool fileExists(const std::string& path);

}  // namespace cli_test
