// The scenario interface of the report commands (`zwang scenarios`: the
// report's chapter 6 with the 1-DOF arm; `zwang energy`: the Panda, the dual
// arm, the humanoid and Solo 12 holding still) and its writer, with the number
// format of their tables.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "cli.hpp"

namespace zwang::cli {

// The files a scenario writes into --out, and what the report says of them.
struct ScenarioFiles {
  std::vector<std::string> csvs;  // the CSVs' file names (Scenario::csvText gives each one's text)
  std::string columns;            // their columns, as the "wrote" line lists them
  std::string script;             // the gnuplot script's file name
  std::string pngs;               // the plots it draws
};

// One scenario of a report command. It is solved and checked when it is made
// (CliError when something cannot be solved), so nothing is written until
// every scenario of the command is; writeScenario then prints and writes it.
class Scenario {
 public:
  virtual ~Scenario() = default;
  virtual ScenarioFiles files() const = 0;
  virtual bool ok() const = 0;                             // every check passed
  virtual void print() const = 0;                          // the report's tables
  virtual std::string csvText(std::size_t csv) const = 0;  // of files().csvs[csv]
  virtual std::string plotScript() const = 0;
};

// Print the scenario, write its CSVs and say so ("wrote OUT/a.csv (columns)";
// several as OUT/{a,b}.csv), then its plots (writePlots, run_gnuplot as
// there). Returns whether there are plots.
bool writeScenario(const ReportCommand& report, const Scenario& scenario, bool run_gnuplot = true);

// A number for the tables: printf `format`, with |x| < 1e-12 shown as 0 (rounding noise).
std::string fmt(double x, const char* format = "%.4g");

}  // namespace zwang::cli
