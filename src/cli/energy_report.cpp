// What the scenarios of `zwang energy` share (energy_report.hpp): variants,
// effort measures, number formats, the effort table and the bar charts' pieces.
#include "energy_report.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "cli.hpp"

namespace zwang::cli::energy {

const Variant kVariants[kVariantCount] = {{"plain", -1.0}, {"friction_margin_0.5", 0.5}, {"friction_margin_1", 1.0}};

Status solveAtRest(const Model& model, const Task& task, const Eigen::VectorXd& q, Workspace& ws,
                   const Variant& variant, const Eigen::VectorXd& breakaway) {
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(model.nv());
  if (variant.margin < 0) return solveHybridDynamics(model, task, q, zero, zero, ws);
  FrictionOptions options;
  options.margin = variant.margin;
  options.breakaway = breakaway;
  return solveWithFriction(model, task, q, zero, zero, ws, options);
}

Effort effortOf(const Eigen::VectorXd& tau) {
  Effort e;
  e.sq = tau.squaredNorm();
  e.norm = std::sqrt(e.sq);
  e.abs_sum = tau.cwiseAbs().sum();
  return e;
}

std::string fmt(double x, const char* format) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, format, std::abs(x) < 1e-12 ? 0.0 : x);
  return buffer;
}

std::string small(double x) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%.1e", x);
  return buffer;
}

std::string csvCell(double x) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, ",%.17g", x);
  return buffer;
}

std::string dataCell(double x) {
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, " %.17g", std::abs(x) < 1e-12 ? 0.0 : x);
  return buffer;
}

void printEffortTable(const std::string& noun, const std::vector<std::string>& names,
                      const std::vector<VariantEfforts>& efforts, const std::vector<bool>& ok) {
  std::printf(
      "\nactuator effort: |tau| = 2-norm of tau_control [N·m], sum|tau| [N·m], |tau|^2 [N²m²];\n"
      "m = margin of the friction-aware solve; saved = how much less |tau|^2 with m=1 than plain\n");
  std::vector<std::vector<std::string>> table{{noun, "|tau| plain", "|tau| m=0.5", "|tau| m=1", "sum|tau| plain",
                                               "sum|tau| m=0.5", "sum|tau| m=1", "|tau|^2 plain", "|tau|^2 m=0.5",
                                               "|tau|^2 m=1", "saved m=1", "check"}};
  double total[kVariantCount] = {0, 0, 0};
  for (std::size_t p = 0; p < names.size(); ++p) {
    const VariantEfforts& e = efforts[p];
    std::vector<std::string> row{names[p]};
    for (int v = 0; v < kVariantCount; ++v) row.push_back(fmt(e[v].norm));
    for (int v = 0; v < kVariantCount; ++v) row.push_back(fmt(e[v].abs_sum));
    for (int v = 0; v < kVariantCount; ++v) row.push_back(fmt(e[v].sq));
    for (int v = 0; v < kVariantCount; ++v) total[v] += e[v].sq;
    row.push_back(fmt(100.0 * (1.0 - e[2].sq / e[0].sq), "%.1f") + " %");
    row.push_back(ok[p] ? "ok" : "MISMATCH");
    table.push_back(row);
  }
  printColumns(table);
  std::printf("\nall %ss: |tau|^2 summed %s (plain), %s (margin 0.5), %s (margin 1): %s %% and %s %% less\n",
              noun.c_str(), fmt(total[0]).c_str(), fmt(total[1]).c_str(), fmt(total[2]).c_str(),
              fmt(100.0 * (1.0 - total[1] / total[0]), "%.1f").c_str(),
              fmt(100.0 * (1.0 - total[2] / total[0]), "%.1f").c_str());
}

std::string normsData(const std::string& block, const std::string& noun, const std::vector<std::string>& names,
                      const std::vector<VariantEfforts>& efforts) {
  std::ostringstream s;
  s << "# columns: " << noun << ", |tau_control| plain, margin 0.5, margin 1 [N·m]\n" << block << " << EOD\n";
  for (std::size_t p = 0; p < names.size(); ++p) {
    s << names[p];
    for (int v = 0; v < kVariantCount; ++v) s << dataCell(efforts[p][v].norm);
    s << "\n";
  }
  s << "EOD\n";
  return s.str();
}

std::string jointsData(const std::string& block, const std::vector<std::string>& labels,
                       const std::array<Eigen::VectorXd, kVariantCount>& tau, const Eigen::VectorXd& breakaway) {
  std::ostringstream s;
  s << "# columns: joint, |tau_control,j| plain, margin 0.5, margin 1, breakaway f_j [N·m]\n" << block << " << EOD\n";
  for (std::size_t j = 0; j < labels.size(); ++j) {
    s << labels[j];
    for (int v = 0; v < kVariantCount; ++v) s << dataCell(std::abs(tau[v][static_cast<Eigen::Index>(j)]));
    s << dataCell(breakaway[static_cast<Eigen::Index>(j)]) << "\n";
  }
  s << "EOD\n";
  return s.str();
}

std::string histogramStyle(std::size_t groups) {
  std::ostringstream s;
  s << "set style data histograms\n"
       "set style histogram clustered gap 1\n"
       "set style fill solid 0.85 border -1\n"
       "set boxwidth 0.9\n"
       "set grid ytics\n"
       "set key outside bottom center horizontal box maxrows 1 width -2\n"
       "set yrange [0:*]\n"
       "set xrange [-0.6:"
    << static_cast<double>(groups) - 0.4 << "]\n";
  return s.str();
}

std::string normsPlot(const std::string& block) {
  return "plot " + block +
         " using 2:xtic(1) title \"plain (friction-unaware)\" linecolor rgb \"#a0a0a0\", \\\n"
         "  '' using 3 title \"friction-aware, margin 0.5\" linecolor rgb \"#70a0e0\", \\\n"
         "  '' using 4 title \"friction-aware, margin 1\" linecolor rgb \"#0050b0\"\n";
}

std::string jointsPanelStyle(std::size_t joints) {
  std::ostringstream s;
  s << "set key inside top right vertical maxrows auto width 0 box opaque font \",8\"\n"
       "set offsets 0, 0, graph 0.05, 0\n"
       "set xrange [-0.6:"
    << static_cast<double>(joints) - 0.4
    << "]\n"
       "set xlabel \"joint\"\n"
       "set ylabel \"|τ| [N·m]\"\n"
       "set yrange [0:*]\n";
  return s.str();
}

std::string jointsPanel(const std::string& block, const std::string& title, bool with_key) {
  return "set title \"" + title + "\" noenhanced\n" + (with_key ? "" : "unset key\n") + "plot " + block +
         " using 2:xtic(1) title \"plain\" linecolor rgb \"#a0a0a0\", \\\n  '' using 3 title \"margin 0.5\" "
         "linecolor rgb \"#70a0e0\", \\\n  '' using 4 title \"margin 1\" linecolor rgb \"#0050b0\", \\\n  '' using "
         "($0):5 with points pointtype 5 pointsize 1.1 linecolor rgb \"#c00000\" title \"f_j\"\n";
}

}  // namespace zwang::cli::energy
