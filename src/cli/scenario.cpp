// The report commands' scenario writer and number format (scenario.hpp).
#include "scenario.hpp"

#include <cmath>
#include <cstdio>

namespace zwang::cli {

namespace {

// The CSVs as the "wrote" line names them: "a.csv", or "{a,b}.csv" for several.
std::string csvNames(const std::vector<std::string>& csvs) {
  if (csvs.size() == 1) return csvs[0];
  const std::string extension = ".csv";
  std::string stems;
  for (const std::string& csv : csvs)
    stems += (stems.empty() ? "" : ",") + csv.substr(0, csv.size() - extension.size());
  return "{" + stems + "}" + extension;
}

}  // namespace

bool writeScenario(const ReportCommand& report, const Scenario& scenario, bool run_gnuplot) {
  scenario.print();
  const ScenarioFiles files = scenario.files();
  for (std::size_t k = 0; k < files.csvs.size(); ++k)
    writeOutput((report.out / files.csvs[k]).string(), scenario.csvText(k));
  std::printf("wrote %s/%s (%s)\n", report.out.string().c_str(), csvNames(files.csvs).c_str(), files.columns.c_str());
  return writePlots(report, files.script, scenario.plotScript(), files.pngs, run_gnuplot);
}

std::string fmt(double x, const char* format) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, format, std::abs(x) < 1e-12 ? 0.0 : x);
  return buffer;
}

}  // namespace zwang::cli
