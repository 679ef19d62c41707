// What the scenarios of `zwang energy` share (energy.cpp: the Panda,
// energy_dual.cpp: the dual arm holding a box, energy_standing.cpp: the
// humanoid and Solo 12 standing): the three variants compared, the effort
// measures of τ_control, the number formats of the tables, CSVs and gnuplot
// data, the effort table every scenario prints, and the pieces of the
// gnuplot bar charts (docs/evaluation.md, sections 2-4).
#pragma once

#include <array>
#include <string>
#include <vector>

#include "zwang/zwang.hpp"

namespace zwang::cli::energy {

// One way of commanding the hold. margin < 0: the plain solver.
struct Variant {
  const char* name;
  double margin;
};
constexpr int kVariantCount = 3;
// In table order: plain, friction-aware with margins 0.5 and 1.
extern const Variant kVariants[kVariantCount];

// Solve `task` at rest (q̇ = 0, τ = 0) as `variant` says: solveHybridDynamics
// for plain, solveWithFriction with that margin otherwise (`breakaway`, when
// not empty, overrides the model's breakaway friction per joint).
Status solveAtRest(const Model& model, const Task& task, const Eigen::VectorXd& q, Workspace& ws,
                   const Variant& variant, const Eigen::VectorXd& breakaway = Eigen::VectorXd());

// The effort measures of τ_control: ‖τ‖₂, ‖τ‖² and Σ|τ_j|.
struct Effort {
  double norm = 0.0, sq = 0.0, abs_sum = 0.0;
};
Effort effortOf(const Eigen::VectorXd& tau);
using VariantEfforts = std::array<Effort, kVariantCount>;

// A number for the tables: printf `format`, with |x| < 1e-12 shown as 0.
std::string fmt(double x, const char* format = "%.4g");
// A check's residual, as it is ("%.1e"; fmt would show |x| < 1e-12 as 0).
std::string small(double x);
// ",x" with 17 significant digits: a CSV cell that reads back exactly.
std::string csvCell(double x);
// " x" with 17 significant digits, |x| < 1e-12 as 0: a gnuplot data cell.
std::string dataCell(double x);

// The effort table: one row per entry of `names` (‖τ‖, Σ|τ|, ‖τ‖² of each
// variant, how much less ‖τ‖² margin 1 needs than plain, "ok" or "MISMATCH"),
// then the line summing ‖τ‖² over the rows. `noun` names a row ("pose").
void printEffortTable(const std::string& noun, const std::vector<std::string>& names,
                      const std::vector<VariantEfforts>& efforts, const std::vector<bool>& ok);

// gnuplot pieces, in the style of docs/energy/energy.gp.
// "$norms": one line per name, ‖τ_control‖ of each variant.
std::string normsData(const std::string& block, const std::string& noun, const std::vector<std::string>& names,
                      const std::vector<VariantEfforts>& efforts);
// One joint per line: its label, |τ_control,j| of each variant and f_j.
std::string jointsData(const std::string& block, const std::vector<std::string>& labels,
                       const std::array<Eigen::VectorXd, kVariantCount>& tau, const Eigen::VectorXd& breakaway);
// Clustered histograms, yrange from 0, x from −0.6 to groups − 0.4; the key below.
std::string histogramStyle(std::size_t groups);
// Plot a normsData block: three bars per name.
std::string normsPlot(const std::string& block);
// The multiplot panel of a jointsData block: three bars per joint and f_j as a red square.
std::string jointsPanel(const std::string& block, const std::string& title, bool with_key);
// The settings of the per-joint panels (key, offsets, axes) for `joints` joints per panel.
std::string jointsPanelStyle(std::size_t joints);

}  // namespace zwang::cli::energy
