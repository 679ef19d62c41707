// `zwang compare-mujoco MODEL.xml [--state FILE] [--postures N] [--seed S] [--seconds T,…] [--json] [--csv DIR]`:
// MuJoCo's soft joint friction against zwang's exact friction at rest (docs/mujoco.md, "Soft friction against
// exact friction"). A thin front end: the MuJoCo component compares (zwang/mujoco_compare.hpp), this file reads
// the options and the state file and prints.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "cli.hpp"
#include "solution_writer.hpp"

#ifdef ZWANG_CLI_HAVE_MUJOCO
#include "zwang/mujoco_compare.hpp"
#endif

namespace zwang::cli {

#ifdef ZWANG_CLI_HAVE_MUJOCO
namespace {

const char kCommand[] = "compare-mujoco";

double parseNumber(const std::string& option, const std::string& text) {
  char* end = nullptr;
  errno = 0;
  const double x = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || errno == ERANGE || !std::isfinite(x))
    throw UsageError(kCommand, option + ": '" + printable(text, 60) + "' is not a finite number");
  return x;
}

long parseInteger(const std::string& option, const std::string& text, long lo, long hi) {
  char* end = nullptr;
  errno = 0;
  const long x = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno == ERANGE || x < lo || x > hi)
    throw UsageError(kCommand, option + ": '" + printable(text, 60) + "' is not an integer in [" + std::to_string(lo) +
                                   ", " + std::to_string(hi) + "]");
  return x;
}

std::vector<double> parseSeconds(const std::string& text) {
  std::vector<double> out;
  std::size_t at = 0;
  for (;;) {
    const std::size_t comma = text.find(',', at);
    const double t =
        parseNumber("--seconds", text.substr(at, comma == std::string::npos ? std::string::npos : comma - at));
    if (!(t > 0 && t <= 3600)) throw UsageError(kCommand, "--seconds: each time must be in (0, 3600] s");
    out.push_back(t);
    if (comma == std::string::npos) return out;
    at = comma + 1;
  }
}

MujocoCompareOptions readOptions(const Arguments& args) {
  MujocoCompareOptions o;
  if (args.has("--postures"))
    o.random_postures = static_cast<int>(parseInteger("--postures", args.value("--postures"), 0, 1000));
  if (args.has("--seed"))
    o.seed = static_cast<std::uint64_t>(parseInteger("--seed", args.value("--seed"), 0, 1L << 62));
  if (args.has("--seconds")) o.seconds = parseSeconds(args.value("--seconds"));
  if (args.has("--gravity-compensation"))
    o.gravity_compensation = parseNumber("--gravity-compensation", args.value("--gravity-compensation"));
  if (args.has("--frictionloss")) {
    o.frictionloss = parseNumber("--frictionloss", args.value("--frictionloss"));
    if (o.frictionloss < 0) throw UsageError(kCommand, "--frictionloss: must be at least 0");
  }
  if (args.has("--noslip-iterations"))
    o.noslip_iterations =
        static_cast<int>(parseInteger("--noslip-iterations", args.value("--noslip-iterations"), 1, 10000));
  return o;
}

// ---------------------------------------------------------------------------
// The state file: one posture {"name", "q", "tau", "gravity_compensation"} or {"postures": [ … ]}.

Eigen::VectorXd numbersAt(const std::string& where, const Json& value) {
  if (!value.is_array()) throw CliError(kExitError, where + ": not an array of numbers");
  Eigen::VectorXd out(static_cast<Eigen::Index>(value.size()));
  for (std::size_t k = 0; k < value.size(); ++k) {
    if (!value[k].is_number()) throw CliError(kExitError, where + "[" + std::to_string(k) + "]: not a number");
    out[static_cast<Eigen::Index>(k)] = value[k].get<double>();
  }
  return out;
}

ComparePosture postureFrom(const std::string& where, const Json& entry, std::size_t index) {
  if (!entry.is_object()) throw CliError(kExitError, where + ": a posture is an object");
  ComparePosture p;
  p.name = "state " + std::to_string(index + 1);
  for (const auto& item : entry.items()) {
    const std::string& key = item.key();
    if (key == "name" && item.value().is_string())
      p.name = item.value().get<std::string>();
    else if (key == "q")
      p.q = numbersAt(where + ": q", item.value());
    else if (key == "tau")
      p.tau = numbersAt(where + ": tau", item.value());
    else if (key == "gravity_compensation" && item.value().is_number())
      p.gravity_compensation = item.value().get<double>();
    else
      throw CliError(kExitError, where + ": key '" + printable(key, 60) +
                                     "' is not one of name (string), q, tau (arrays), gravity_compensation (number)");
  }
  if (p.q.size() == 0) throw CliError(kExitError, where + ": no \"q\" given");
  return p;
}

std::vector<ComparePosture> readStateFile(const std::string& path) {
  const std::string text = readFile(path, 16u << 20);
  if (!Json::accept(text)) throw CliError(kExitError, path + ": not valid JSON");
  const Json doc = Json::parse(text);
  std::vector<ComparePosture> out;
  if (doc.is_object() && doc.contains("postures")) {
    if (doc.size() != 1 || !doc["postures"].is_array() || doc["postures"].empty())
      throw CliError(kExitError, path + ": \"postures\" must be the only key and a non-empty array of postures");
    for (std::size_t k = 0; k < doc["postures"].size(); ++k)
      out.push_back(postureFrom(path + ": postures[" + std::to_string(k) + "]", doc["postures"][k], k));
  } else {
    out.push_back(postureFrom(path, doc, 0));
  }
  return out;
}

// ---------------------------------------------------------------------------
// Printing

std::string number(double x) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.3g", x + 0.0);  // + 0.0: no "-0"
  return buffer;
}
std::string seconds(double t) { return number(t) + " s"; }

Json states(const std::vector<JointState>& state) {
  Json out = Json::array();
  for (const JointState s : state) out.push_back(toString(s));
  return out;
}

Json settingJson(const MujocoComparison& c, const PostureComparison& p, std::size_t s) {
  const MujocoSettingResult& r = p.mujoco[s];
  Json drift = Json::array();
  for (Eigen::Index row = 0; row < r.drift.rows(); ++row) drift.push_back(array(r.drift.row(row).transpose()));
  return {{"name", c.settings[s].name},
          {"qacc", array(r.qacc)},
          {"tau_friction", array(r.tau_friction)},
          {"drift", std::move(drift)},
          {"held_drift_max", array(heldDriftMax(p, r.drift))},
          {"mujoco_warnings", r.mujoco_warnings}};
}

Json postureJson(const MujocoComparison& c, const PostureComparison& p) {
  Json mujoco = Json::array();
  for (std::size_t s = 0; s < p.mujoco.size(); ++s) mujoco.push_back(settingJson(c, p, s));
  return {{"name", p.name},
          {"q", array(p.q)},
          {"tau", array(p.tau)},
          {"zwang",
           {{"state", states(p.state)},
            {"qdd", array(p.qdd)},
            {"mu", array(p.mu)},
            {"tau_friction", array(p.tau_friction)}}},
          {"mujoco", std::move(mujoco)}};
}

Json comparisonJson(const MujocoComparison& c) {
  Json settings = Json::array(), postures = Json::array();
  for (const MujocoSetting& s : c.settings) settings.push_back({{"name", s.name}, {"description", s.description}});
  for (const PostureComparison& p : c.postures) postures.push_back(postureJson(c, p));
  return {{"model", c.model_name},
          {"base_fixed", c.base_fixed},
          {"timestep", c.timestep},
          {"integrator", c.integrator},
          {"dofs", c.dof_names},
          {"frictionloss", array(c.frictionloss)},
          {"seconds", c.seconds},
          {"settings", std::move(settings)},
          {"postures", std::move(postures)},
          {"warnings", c.warnings}};
}

// Per DOF: zwang's state, f, μ and friction torque, MuJoCo's friction torque and q̈ per setting, zwang's q̈.
void printForces(const MujocoComparison& c, const PostureComparison& p) {
  std::vector<std::string> head{"dof", "zwang", "f", "zwang tau_f"};
  for (const MujocoSetting& s : c.settings) head.push_back(s.name + " tau_f");
  head.push_back("zwang qdd");
  for (const MujocoSetting& s : c.settings) head.push_back(s.name + " qdd");
  std::vector<std::vector<std::string>> rows{head};
  for (Eigen::Index k = 0; k < p.qdd.size(); ++k) {
    const std::size_t j = static_cast<std::size_t>(k);
    std::vector<std::string> row{c.dof_names[j], toString(p.state[j]), number(c.frictionloss[k]),
                                 number(p.tau_friction[k])};
    for (const MujocoSettingResult& r : p.mujoco) row.push_back(number(r.tau_friction[k]));
    row.push_back(number(p.qdd[k]));
    for (const MujocoSettingResult& r : p.mujoco) row.push_back(number(r.qacc[k]));
    rows.push_back(row);
  }
  printColumns(rows, 2);
}

// Per DOF: MuJoCo's drift after each time, per setting (zwang's is 0 where it holds); then the largest on the held DOFs.
void printDrift(const MujocoComparison& c, const PostureComparison& p) {
  std::vector<std::string> head{"drift", "zwang"};
  for (const MujocoSetting& s : c.settings)
    for (const double t : c.seconds) head.push_back(s.name + " " + seconds(t));
  std::vector<std::vector<std::string>> rows{head};
  for (Eigen::Index k = 0; k < p.qdd.size(); ++k) {
    std::vector<std::string> row{c.dof_names[static_cast<std::size_t>(k)],
                                 toString(p.state[static_cast<std::size_t>(k)])};
    for (const MujocoSettingResult& r : p.mujoco)
      for (Eigen::Index t = 0; t < r.drift.rows(); ++t) row.push_back(number(r.drift(t, k)));
    rows.push_back(row);
  }
  const bool any = std::count(p.state.begin(), p.state.end(), JointState::Stick) > 0;
  std::vector<std::string> held{any ? "largest, held" : "largest, all", any ? "stick" : "-"};
  for (const MujocoSettingResult& r : p.mujoco) {
    const Eigen::VectorXd largest = heldDriftMax(p, r.drift);
    for (Eigen::Index t = 0; t < largest.size(); ++t) held.push_back(number(largest[t]));
  }
  rows.push_back(held);
  printColumns(rows, 2);
}

// The loader's warnings, then MuJoCo's during a simulation, on stderr.
void printWarnings(const MujocoComparison& c) {
  for (const std::string& w : c.warnings) std::fprintf(stderr, "zwang: warning: %s\n", printable(w, 4000).c_str());
  for (const PostureComparison& p : c.postures)
    for (std::size_t s = 0; s < p.mujoco.size(); ++s)
      for (const std::string& w : p.mujoco[s].mujoco_warnings)
        std::fprintf(stderr, "zwang: warning: posture '%s', setting %s: MuJoCo warned: %s\n",
                     printable(p.name, 200).c_str(), c.settings[s].name.c_str(), w.c_str());
}

void printText(const MujocoComparison& c) {
  std::printf("%s: MuJoCo timestep %s, integrator %s; contacts and actuators off, joint springs zeroed%s\n",
              c.model_name.c_str(), seconds(c.timestep).c_str(), c.integrator.c_str(),
              c.base_fixed ? "; floating base fixed (its free joint deleted)" : "");
  for (const MujocoSetting& s : c.settings) std::printf("  %-8s %s\n", s.name.c_str(), s.description.c_str());
  for (const PostureComparison& p : c.postures) {
    int held = 0;
    for (const JointState s : p.state) held += s == JointState::Stick;
    std::printf(
        "\nposture '%s': zwang holds %d of %d DOFs (state stick: q̈ = 0); tau_f is friction's torque on the DOF\n",
        p.name.c_str(), held, static_cast<int>(p.state.size()));
    printForces(c, p);
    std::printf("\n");
    printDrift(c, p);
  }
}

// DIR/compare_joints.csv (the tables) and DIR/compare_drift.csv (the largest held drift over time, per setting).
void writeCsv(const std::string& dir, const MujocoComparison& c) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw CliError(kExitError, dir + ": cannot create the directory (" + ec.message() + ")");
  std::string joints = "posture,dof,zwang_state,frictionloss,zwang_tau_friction,zwang_qdd";
  for (const MujocoSetting& s : c.settings) {
    joints += "," + s.name + "_tau_friction," + s.name + "_qacc";
    for (const double t : c.seconds) joints += "," + s.name + "_drift_" + number(t) + "s";
  }
  std::string drift = "posture,t";
  for (const MujocoSetting& s : c.settings) drift += "," + s.name;
  joints += "\n";
  drift += "\n";
  for (std::size_t i = 0; i < c.postures.size(); ++i) {
    const PostureComparison& p = c.postures[i];
    for (Eigen::Index k = 0; k < p.qdd.size(); ++k) {
      const std::size_t j = static_cast<std::size_t>(k);
      joints += std::to_string(i) + "," + c.dof_names[j] + "," + toString(p.state[j]) + "," +
                number(c.frictionloss[k]) + "," + number(p.tau_friction[k]) + "," + number(p.qdd[k]);
      for (const MujocoSettingResult& r : p.mujoco) {
        joints += "," + number(r.tau_friction[k]) + "," + number(r.qacc[k]);
        for (Eigen::Index t = 0; t < r.drift.rows(); ++t) joints += "," + number(r.drift(t, k));
      }
      joints += "\n";
    }
    std::vector<Eigen::VectorXd> series;
    for (const MujocoSettingResult& r : p.mujoco) series.push_back(heldDriftMax(p, r.drift_series));
    for (Eigen::Index t = 0; t < p.mujoco.front().times.size(); ++t) {
      drift += std::to_string(i) + "," + number(p.mujoco.front().times[t]);
      for (const Eigen::VectorXd& s : series) drift += "," + number(s[t]);
      drift += "\n";
    }
  }
  writeOutput(dir + "/compare_joints.csv", joints);
  writeOutput(dir + "/compare_drift.csv", drift);
}

}  // namespace
#endif

int commandCompareMujoco(int argc, char** argv) {
  const Arguments args = parseArguments("compare-mujoco", argc, argv, 2, {"--json"},
                                        {"--state", "--postures", "--seed", "--seconds", "--gravity-compensation",
                                         "--frictionloss", "--noslip-iterations", "--csv"});
  if (args.help) {
    std::fputs(usageText("compare-mujoco"), stdout);
    return kExitOk;
  }
  if (args.positional.size() != 1)
    throw UsageError("compare-mujoco",
                     args.positional.empty() ? "no model file given" : "more than one model file given");
#ifdef ZWANG_CLI_HAVE_MUJOCO
  if (args.has("--state") && (args.has("--postures") || args.has("--seed") || args.has("--gravity-compensation")))
    throw UsageError(kCommand, "--state gives the postures: no --postures, --seed or --gravity-compensation");
  const MujocoCompareOptions options = readOptions(args);
  const std::vector<ComparePosture> postures =
      args.has("--state") ? readStateFile(args.value("--state")) : std::vector<ComparePosture>{};
  MujocoComparison c;
  try {
    c = compareWithMujoco(args.positional[0], postures, options);
  } catch (const ModelError& e) {
    throw CliError(kExitError, e.what());
  } catch (const std::invalid_argument& e) {
    throw CliError(kExitError, (args.has("--state") ? args.value("--state") : args.positional[0]) + ": " + e.what());
  }
  printWarnings(c);
  if (args.has("--csv")) writeCsv(args.value("--csv"), c);
  if (args.has("--json"))
    writeOutput("", prettyDump(comparisonJson(c)) + "\n");
  else
    printText(c);
  return kExitOk;
#else
  throw CliError(kExitError,
                 "compare-mujoco needs zwang built with MuJoCo (Debian: libmujoco-dev; CMake option "
                 "ZWANG_WITH_MUJOCO)");
#endif
}

}  // namespace zwang::cli
