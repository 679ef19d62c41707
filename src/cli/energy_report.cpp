// What the scenarios of `zwang energy` share (energy_report.hpp): the
// variants, effort measures, number formats, the effort table, the arms' CSV
// and charts, and the bar charts' pieces.
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
  if (variant.margin < 0) return solveHybridDynamics(model, ws, q, zero, zero, task);
  FrictionOptions options;
  options.margin = variant.margin;
  options.breakaway = breakaway;
  return solveWithFriction(model, ws, q, zero, zero, task, options);
}

Effort effortOf(const Eigen::VectorXd& tau) {
  Effort e;
  e.sq = tau.squaredNorm();
  e.norm = std::sqrt(e.sq);
  e.abs_sum = tau.cwiseAbs().sum();
  return e;
}

VariantResult variantResult(const Variant& variant, const Eigen::VectorXd& tau, const Workspace& ws) {
  VariantResult e;
  e.tau = tau;
  e.mu = variant.margin < 0 ? Eigen::VectorXd::Zero(tau.size()) : Eigen::VectorXd(ws.friction.mu);
  e.effort = effortOf(tau);
  return e;
}

VariantEfforts PostureResult::efforts() const { return {variant[0].effort, variant[1].effort, variant[2].effort}; }

std::array<Eigen::VectorXd, kVariantCount> PostureResult::torques() const {
  return {variant[0].tau, variant[1].tau, variant[2].tau};
}

Model loadScenarioModel(const ReportCommand& report, const std::string& file, const UrdfOptions& options,
                        std::filesystem::path& urdf) {
  urdf = std::filesystem::path(modelsDirectory(report.args, file)) / file;
  try {
    return loadUrdfFile(urdf.string(), options);
  } catch (const ModelError& e) {
    throw CliError(kExitError, report.name + ": " + e.what() + " (use --models DIR)");
  }
}

std::string shownPath(const std::filesystem::path& path) {
  std::error_code ec;
  const std::filesystem::path proximate = std::filesystem::proximate(path, ec);
  return (ec ? path : proximate).string();
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

void printEffortTable(const std::string& noun, const std::vector<PostureResult>& postures) {
  std::printf(
      "\nactuator effort: |tau| = 2-norm of tau_control [N·m], sum|tau| [N·m], |tau|^2 [N²m²];\n"
      "m = margin of the friction-aware solve; saved = how much less |tau|^2 with m=1 than plain\n");
  std::vector<std::vector<std::string>> table{{noun, "|tau| plain", "|tau| m=0.5", "|tau| m=1", "sum|tau| plain",
                                               "sum|tau| m=0.5", "sum|tau| m=1", "|tau|^2 plain", "|tau|^2 m=0.5",
                                               "|tau|^2 m=1", "saved m=1", "check"}};
  double total[kVariantCount] = {0, 0, 0};
  for (const PostureResult& posture : postures) {
    const VariantEfforts e = posture.efforts();
    std::vector<std::string> row{posture.name};
    for (int v = 0; v < kVariantCount; ++v) row.push_back(fmt(e[v].norm));
    for (int v = 0; v < kVariantCount; ++v) row.push_back(fmt(e[v].abs_sum));
    for (int v = 0; v < kVariantCount; ++v) row.push_back(fmt(e[v].sq));
    for (int v = 0; v < kVariantCount; ++v) total[v] += e[v].sq;
    row.push_back(fmt(100.0 * (1.0 - e[2].sq / e[0].sq), "%.1f") + " %");
    row.push_back(posture.ok ? "ok" : "MISMATCH");
    table.push_back(row);
  }
  printColumns(table);
  std::printf("\nall %ss: |tau|^2 summed %s (plain), %s (margin 0.5), %s (margin 1): %s %% and %s %% less\n",
              noun.c_str(), fmt(total[0]).c_str(), fmt(total[1]).c_str(), fmt(total[2]).c_str(),
              fmt(100.0 * (1.0 - total[1] / total[0]), "%.1f").c_str(),
              fmt(100.0 * (1.0 - total[2] / total[0]), "%.1f").c_str());
}

std::string armCsv(const std::vector<PostureResult>& postures, const std::string& extra_columns,
                   const ExtraCells& extra) {
  const Eigen::Index dof = postures.empty() ? 0 : postures[0].q.size();
  std::ostringstream out;
  out << "pose,variant";
  for (const char* column : {"q", "tau", "mu"})
    for (Eigen::Index j = 1; j <= dof; ++j) out << "," << column << j;
  out << ",tau_norm,tau_sq,tau_abs_sum" << extra_columns << "\n";
  for (std::size_t p = 0; p < postures.size(); ++p)
    for (int v = 0; v < kVariantCount; ++v) {
      const VariantResult& e = postures[p].variant[static_cast<std::size_t>(v)];
      out << postures[p].name << "," << kVariants[v].name;
      for (const Eigen::VectorXd* cells : {&postures[p].q, &e.tau, &e.mu})
        for (const double x : *cells) out << csvCell(x);
      out << csvCell(e.effort.norm) << csvCell(e.effort.sq) << csvCell(e.effort.abs_sum);
      if (extra)
        for (const double x : extra(p, v)) out << csvCell(x);
      out << "\n";
    }
  return out.str();
}

std::string armPlotScript(const std::string& script, const ArmCharts& charts,
                          const std::vector<PostureResult>& postures, const Model& model,
                          std::string (*label)(int joint)) {
  std::vector<std::string> labels;
  Eigen::VectorXd breakaway(model.dof());
  for (int j = 0; j < model.dof(); ++j) {
    labels.push_back(label(j));
    breakaway[j] = model.joint(j).breakaway_friction;
  }
  std::ostringstream s;
  s << scriptHeader(script) << normsData("$norms", charts.noun, postures);
  for (const PostureResult& posture : postures)
    s << jointsData("$joints_" + posture.name, labels, posture.torques(), breakaway);
  s << histogramStyle(postures.size()) << "\n"
    << "set terminal pngcairo size 900,520 font \"DejaVu Sans,11\"\n"
    << "set output \"" << charts.efforts_png << "\"\n"
    << "set title \"" << charts.efforts_title << "\"\n"
    << "set ylabel \"‖τ_{control}‖ [N·m]\"\n"
       "set xtics noenhanced\n"
    << normsPlot("$norms") << "\n"
    << "set terminal pngcairo size " << charts.joints_size << " font \"DejaVu Sans,10\"\n"
    << "set output \"" << charts.joints_png << "\"\n"
    << "set multiplot layout 2,3 title \"" << charts.joints_title << "\"\n"
    << jointsPanelStyle(labels.size());
  for (std::size_t p = 0; p < postures.size(); ++p)
    s << jointsPanel("$joints_" + postures[p].name, postures[p].name, p == 0);
  s << "unset multiplot\nunset output\n";
  return s.str();
}

std::string scriptHeader(const std::string& script) {
  return "# Generated by `zwang energy`; run it in this directory: gnuplot " + script +
         "\n"
         "set encoding utf8\n"
         "set datafile separator whitespace\n";
}

std::string normsData(const std::string& block, const std::string& noun, const std::vector<PostureResult>& postures) {
  std::ostringstream s;
  s << "# columns: " << noun << ", |tau_control| plain, margin 0.5, margin 1 [N·m]\n" << block << " << EOD\n";
  for (const PostureResult& posture : postures) {
    s << posture.name;
    for (const Effort& effort : posture.efforts()) s << dataCell(effort.norm);
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
