// What the scenarios of `zwang energy` share (energy.cpp: the Panda,
// energy_dual.cpp: the dual arm holding a box, energy_standing.cpp: the
// humanoid and Solo 12 standing), each a Scenario of scenario.hpp: the three
// variants compared, the effort measures of τ_control, the number formats of
// the CSVs and gnuplot data, the effort table every scenario prints, the
// arms' CSV and charts, and the pieces of the gnuplot bar charts
// (docs/evaluation.md, sections 2-4).
#pragma once

#include <array>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "cli.hpp"
#include "scenario.hpp"
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

// One solve of a posture: τ_control and μ* of the joints (μ = 0 for plain) and τ_control's effort.
struct VariantResult {
  Eigen::VectorXd tau, mu;
  Effort effort;
};
// The joints' τ_control `tau` of a solve of `variant`, with μ* from ws.friction.
VariantResult variantResult(const Variant& variant, const Eigen::VectorXd& tau, const Workspace& ws);

// A posture's three solves: what the effort table, the CSVs and the charts take.
struct PostureResult {
  std::string name;
  Eigen::VectorXd q;
  std::array<VariantResult, kVariantCount> variant;
  bool ok = false;  // every check of the posture passed
  VariantEfforts efforts() const;
  std::array<Eigen::VectorXd, kVariantCount> torques() const;
};

// The scenarios after the Panda: the dual arm holding a box (energy_dual.cpp)
// and the humanoid and Solo 12 standing (energy_standing.cpp). Each loads its
// models from the models directory (CliError when one does not load or is
// not the expected one).
std::unique_ptr<Scenario> dualArmScenario(const ReportCommand& report);
std::unique_ptr<Scenario> standingScenario(const ReportCommand& report);

// A scenario's model `file` from the models directory; `urdf` is set to its path.
Model loadScenarioModel(const ReportCommand& report, const std::string& file, const UrdfOptions& options,
                        std::filesystem::path& urdf);
// A path as the report shows it: relative to the working directory when it can be.
std::string shownPath(const std::filesystem::path& path);

// A check's residual, as it is ("%.1e"; fmt would show |x| < 1e-12 as 0).
std::string small(double x);
// ",x" with 17 significant digits: a CSV cell that reads back exactly.
std::string csvCell(double x);
// " x" with 17 significant digits, |x| < 1e-12 as 0: a gnuplot data cell.
std::string dataCell(double x);

// The effort table: one row per posture (‖τ‖, Σ|τ|, ‖τ‖² of each variant,
// how much less ‖τ‖² margin 1 needs than plain, "ok" or "MISMATCH"), then the
// line summing ‖τ‖² over the rows. `noun` names a row ("pose").
void printEffortTable(const std::string& noun, const std::vector<PostureResult>& postures);

// The arms' CSV (the Panda, the dual arm): one row per posture and variant
// with q, τ_control, μ and the efforts, then `extra` of that posture and
// variant, whose columns `extra_columns` names (",a,b"; "" for none).
using ExtraCells = std::function<Eigen::VectorXd(std::size_t posture, int variant)>;
std::string armCsv(const std::vector<PostureResult>& postures, const std::string& extra_columns = "",
                   const ExtraCells& extra = nullptr);

// What the arms' two bar charts say: ‖τ_control‖ per posture and variant, and
// |τ_control,j| per joint and posture with the breakaway torques.
struct ArmCharts {
  std::string noun;           // a posture in the data's comment ("pose")
  std::string efforts_png;    // the effort chart's file
  std::string efforts_title;  // and its title
  std::string joints_size;    // the per-joint chart's size in pixels ("1200,760")
  std::string joints_png;     // its file
  std::string joints_title;   // and its title
};
// The arms' gnuplot script: the data inline (17 digits, the CSV's numbers), the
// two charts in the style of docs/energy/energy.gp; joint j is shown as label(j)
// with the model's breakaway friction.
std::string armPlotScript(const std::string& script, const ArmCharts& charts,
                          const std::vector<PostureResult>& postures, const Model& model,
                          std::string (*label)(int joint));

// gnuplot pieces, in the style of docs/energy/energy.gp.
// The script's first lines: what made it and how to run it, utf8, whitespace-separated data.
std::string scriptHeader(const std::string& script);
// "$norms": one line per posture, ‖τ_control‖ of each variant.
std::string normsData(const std::string& block, const std::string& noun, const std::vector<PostureResult>& postures);
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
