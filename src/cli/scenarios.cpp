// `zwang scenarios [--out DIR] [--models DIR] [--no-plots]`: the report's
// chapter 6 (scenarios 1 and 2) and Fig. 5.5 with the 1-DOF arm.
//
// For each scenario: the exact friction-aware solution (solveWithFriction),
// printed next to the report's numbers, and the report's sampling view of the
// same problem: the plain solver evaluated with the friction reaction as a
// joint torque, τ = τ₀ − μ, over 201 values of μ in [−f, f]. At each sample
//   g(μ)          = Solution::gauss of that solve. Z(q̈) with the torque τ₀ − μ is
//                   Z₀(q̈) + μ q̈, so its minimum over the task's q̈ is g(μ) of
//                   eq. 5.9 (docs/theory.md §3) exactly;
//   qdd(μ)        = q̈(μ);
//   tau_control(μ)= τ₀ + τ_c(μ), the motor command (τ_c the constraint torque);
//   tau_net(μ)    = H q̈(μ) + C, the net joint torque that accelerates the arm
//                   (the report's "resulting torque", Figs. 6.4 and 6.7).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <vector>

#include "cli.hpp"
#include "scenario.hpp"
#include "zwang/zwang.hpp"

namespace zwang::cli {

namespace {

constexpr int kSamples = 201;

// One case of the report's: the arm at rest with a load, and what the report found.
struct ReportCase {
  const char* name;    // file stem
  const char* title;   // for the table and the plots
  double tip_force_y;  // world y force at the tip [N] (0: none)
  bool constrained;    // link1's angular acceleration about z set to `target`
  double target;       // [rad/s²]
  // The report's result (its sign convention: magnitudes, Fig. 5.5 opposite sign)
  const char* report;
  // Ours (docs/theory.md, "The reference cases"), for the self-check.
  double mu, qdd, tau_control;
  const char* state;
};

const ReportCase kCases[] = {
    {"scenario1", "scenario 1: tip force -5 N", -5.0, false, 0.0,
     "Fig. 6.2-6.4: mu* = 5 N·m (magnitude), qdd = 0, resulting torque 0", -5.0, 0.0, 0.0, "stick"},
    {"scenario2", "scenario 2: tip force -11 N", -11.0, false, 0.0,
     "Fig. 6.5-6.7: mu* = 10 N·m (magnitude), resulting torque -1 N·m, qdd = -0.44 rad/s²", -10.0, -1.0 / 2.25, 0.0,
     "slip-"},
    {"fig5_5", "Fig. 5.5: link1 angular acceleration 5 rad/s²", 0.0, true, 5.0,
     "Fig. 5.5: g linear in mu, maximum at the vertex -10 N·m (report's sign)", 10.0, 5.0, 2.25 * 5.0 + 10.0, "slip+"},
};

struct CaseResult {
  double mu = 0, qdd = 0, tau_control = 0, tau_net = 0, g = 0;
  std::string state;
  double grid_argmax = 0, grid_g_at_mu = 0;
  bool ok = false;
  std::vector<double> mu_grid, g_grid, qdd_grid, tau_grid, net_grid;
};

CaseResult solveCase(const Model& model, const ReportCase& sc) {
  Task task(model);
  task.gravity.setZero();  // the report's experiments have no gravity
  if (sc.tip_force_y != 0.0) task.wrench(task.addWrench("tip", Expressed::World)) << 0, sc.tip_force_y, 0, 0, 0, 0;
  if (sc.constrained) {
    ConstraintMatrix A = ConstraintMatrix::Zero(6, 1);
    A(5, 0) = 1.0;  // angular z, linear part first
    task.targets()[task.addConstraint("link1", A, Expressed::World)] = sc.target;
  }
  Task free_task(model);  // for H q̈ + C: same gravity, no wrenches, no constraints
  free_task.gravity = task.gravity;
  Workspace ws(model, task);
  const int n = model.dof();
  const Eigen::VectorXd q = Eigen::VectorXd::Zero(n), qd = Eigen::VectorXd::Zero(n), tau0 = Eigen::VectorXd::Zero(n);

  CaseResult r;
  const Status status = solveWithFriction(model, ws, q, qd, tau0, task);
  if (!status) throw CliError(kExitError, std::string("scenarios: ") + sc.name + ": " + status.message);
  r.mu = ws.friction.mu[0];
  r.qdd = ws.solution.qdd[0];
  r.tau_control = ws.solution.tau_control[0];
  r.state = toString(ws.friction.state[0]);
  r.g = ws.friction.gauss_dual;
  if (!inverseDynamics(model, ws, q, qd, ws.solution.qdd, free_task))
    throw CliError(kExitError, "scenarios: RNEA failed");
  r.tau_net = ws.tau[0];

  // The sampling view: the plain solver with τ = τ₀ − μ.
  const double f = model.joint(0).breakaway_friction;
  double best = -INFINITY;
  for (int i = 0; i < kSamples; ++i) {
    const double mu = f * (i - (kSamples - 1) / 2) / ((kSamples - 1) / 2);
    Eigen::VectorXd tau = tau0;
    tau[0] -= mu;
    const Status s = solveHybridDynamics(model, ws, q, qd, tau, task);
    if (!s) throw CliError(kExitError, std::string("scenarios: ") + sc.name + ": " + s.message);
    r.mu_grid.push_back(mu);
    r.g_grid.push_back(ws.solution.gauss);
    r.qdd_grid.push_back(ws.solution.qdd[0]);
    r.tau_grid.push_back(tau0[0] + ws.solution.tau_constraint[0]);
    if (!inverseDynamics(model, ws, q, qd, ws.solution.qdd, free_task))
      throw CliError(kExitError, "scenarios: RNEA failed");
    r.net_grid.push_back(ws.tau[0]);
    if (ws.solution.gauss > best) {
      best = ws.solution.gauss;
      r.grid_argmax = mu;
    }
    if (std::abs(mu - r.mu) < 1e-12) r.grid_g_at_mu = ws.solution.gauss;
  }
  const double tol = 1e-9;
  r.ok = std::abs(r.mu - sc.mu) < tol && std::abs(r.qdd - sc.qdd) < tol &&
         std::abs(r.tau_control - sc.tau_control) < tol && r.state == sc.state &&
         std::abs(r.grid_g_at_mu - r.g) < tol * (1 + std::abs(r.g));
  return r;
}

// For the table and the plot labels: six significant digits.
std::string shown(double x) { return fmt(x, "%.6g"); }

std::string caseCsv(const CaseResult& r) {
  std::ostringstream out;
  out << "mu,g,qdd,tau_control,tau_net\n";
  char line[200];
  for (std::size_t i = 0; i < r.mu_grid.size(); ++i) {
    std::snprintf(line, sizeof line, "%.17g,%.17g,%.17g,%.17g,%.17g\n", r.mu_grid[i], r.g_grid[i], r.qdd_grid[i],
                  r.tau_grid[i], r.net_grid[i]);
    out << line;
  }
  return out.str();
}

// One gnuplot script for all plots, with paths relative to the output directory.
std::string casesPlotScript(const std::vector<CaseResult>& results, double f) {
  std::ostringstream s;
  s << "# Generated by `zwang scenarios`; run it in this directory: gnuplot plots.gp\n"
       "set encoding utf8\n"
       "set terminal pngcairo size 800,500 font \"DejaVu Sans,11\"\n"
       "set datafile separator \",\"\n"
       "set grid\n"
       "set key at screen 0.5, screen 0.015 center bottom horizontal box\n"
       "set bmargin 6.5\n"
       "set xrange ["
    << -f << ":" << f
    << "]\n"
       "set xlabel \"friction reaction μ [N·m]  (μ > 0 opposes positive motion)\"\n";
  struct Plot {
    const char* suffix;
    const char* ylabel;
    const char* what;
  };
  const Plot plots[] = {{"g", "g(μ) [kg·m²/s⁴]", "Gauss function g(μ) = min_{q̈} Z(q̈) + μ q̈ (eq. 5.9)"},
                        {"qdd", "q̈(μ) [rad/s²]", "joint acceleration q̈(μ)"},
                        {"tau", "torque [N·m]", "torques"}};
  for (std::size_t k = 0; k < results.size(); ++k) {
    const ReportCase& sc = kCases[k];
    const CaseResult& r = results[k];
    s << "\n# " << sc.title << "\n$star_" << sc.name << " << EOD\n"
      << fmt(r.mu, "%.17g") << "," << fmt(r.g, "%.17g") << "," << fmt(r.qdd, "%.17g") << ","
      << fmt(r.tau_control, "%.17g") << "," << fmt(r.tau_net, "%.17g") << "\nEOD\n"
      << "set arrow 1 from " << fmt(r.mu, "%.17g") << ", graph 0 to " << fmt(r.mu, "%.17g")
      << ", graph 1 nohead dashtype 2 linecolor rgb \"#c00000\"\n";
    for (const Plot& p : plots) {
      s << "set output \"" << sc.name << "_" << p.suffix << ".png\"\n"
        << "set title \"" << sc.title << ": " << p.what << "\"\n"
        << "set ylabel \"" << p.ylabel << "\"\n";
      const std::string csv = std::string("\"") + sc.name + ".csv\" skip 1";
      const std::string star = std::string("$star_") + sc.name;
      const std::string mu_label = "μ* = " + shown(r.mu) + " (exact, " + r.state + ")";
      if (std::string(p.suffix) == "g")
        s << "plot " << csv
          << " using 1:2 with lines linewidth 2 linecolor rgb \"#0060c0\" title \"g(μ), 201 samples\", \\\n  " << star
          << " using 1:2 with points pointtype 7 pointsize 1.6 linecolor rgb \"#c00000\" title \"" << mu_label
          << "\"\n";
      else if (std::string(p.suffix) == "qdd")
        s << "plot " << csv << " using 1:3 with lines linewidth 2 linecolor rgb \"#0060c0\" title \"q̈(μ)\", \\\n  "
          << star << " using 1:3 with points pointtype 7 pointsize 1.6 linecolor rgb \"#c00000\" title \"" << mu_label
          << "\"\n";
      else
        s << "plot " << csv
          << " using 1:5 with lines linewidth 2 linecolor rgb \"#0060c0\" title \"net joint torque H q̈ + C\", \\\n  "
          << csv
          << " using 1:4 with lines linewidth 2 dashtype 3 linecolor rgb \"#208020\" title \"τ_{control} = τ + τ_c (motor)\", \\\n  "
          << star << " using 1:5 with points pointtype 7 pointsize 1.6 linecolor rgb \"#c00000\" title \"" << mu_label
          << "\", \\\n  " << star
          << " using 1:4 with points pointtype 6 pointsize 1.6 linecolor rgb \"#c00000\" notitle\n";
    }
  }
  s << "unset output\n";
  return s.str();
}

// The report's cases with the 1-DOF arm of the report command.
class ArmScenario final : public Scenario {
 public:
  explicit ArmScenario(const ReportCommand& report) : report_(report) {
    for (const ReportCase& c : kCases) results_.push_back(solveCase(report.model, c));
  }
  ScenarioFiles files() const override {
    std::vector<std::string> csvs;
    for (const ReportCase& c : kCases) csvs.push_back(std::string(c.name) + ".csv");
    return {csvs, "columns mu, g, qdd, tau_control, tau_net", "plots.gp", "<scenario>_{g,qdd,tau}.png"};
  }
  bool ok() const override {
    return std::all_of(results_.begin(), results_.end(), [](const CaseResult& r) { return r.ok; });
  }
  void print() const override;
  std::string csvText(std::size_t csv) const override { return caseCsv(results_[csv]); }
  std::string plotScript() const override { return casesPlotScript(results_, breakaway()); }

 private:
  double breakaway() const { return report_.model.joint(0).breakaway_friction; }

  const ReportCommand& report_;
  std::vector<CaseResult> results_;
};

void ArmScenario::print() const {
  const Model& model = report_.model;
  const double inertia = model.inertia(1).Ibar(2, 2) + model.joint(0).rotor_inertia;
  std::printf("zwang scenarios: the report's chapter 6 and Fig. 5.5 with %s\n", report_.shownUrdf().c_str());
  std::printf("1-DOF arm: inertia about the joint %s kg·m², breakaway friction f = %s N·m, no gravity, at rest.\n",
              shown(inertia).c_str(), shown(breakaway()).c_str());
  std::printf(
      "Sign: mu > 0 opposes positive motion (the joint feels tau - mu); the report plots magnitudes and\n"
      "uses the opposite sign in Fig. 5.5. tau_net = H qdd + C is the report's \"resulting torque\".\n\n");
  std::vector<std::vector<std::string>> rows{{"scenario", "mu* [N·m]", "qdd* [rad/s²]", "tau_control [N·m]",
                                              "tau_net [N·m]", "state", "g(mu*)", "grid argmax", "check"}};
  for (std::size_t k = 0; k < results_.size(); ++k) {
    const CaseResult& r = results_[k];
    rows.push_back({kCases[k].name, shown(r.mu), shown(r.qdd), shown(r.tau_control), shown(r.tau_net), r.state,
                    shown(r.g), shown(r.grid_argmax), r.ok ? "ok" : "MISMATCH"});
  }
  printColumns(rows);
  std::printf("\nThe report's results:\n");
  for (const ReportCase& c : kCases) std::printf("  %-9s  %s\n", c.name, c.report);
  std::printf("\ngrid argmax: the best of the %d samples of g (the report's sampling method); mu* is exact.\n",
              kSamples);
}

}  // namespace

int commandScenarios(int argc, char** argv) {
  const std::optional<ReportCommand> report =
      startReportCommand("scenarios", argc, argv, "scenarios",
                         {"one_dof_arm.urdf", 1, {"tip", "link1"}, "the 1-DOF arm with frames link1 and tip"});
  if (!report) return kExitOk;          // --help
  const ArmScenario scenario(*report);  // every case solved and checked before anything is written
  writeScenario(*report, scenario);
  return reportExitCode(*report, scenario.ok(), "the report's");
}

}  // namespace zwang::cli
