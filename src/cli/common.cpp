// Argument parsing, usage texts, file, table and gnuplot helpers of the zwang tool.
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <utility>

#include "cli.hpp"
#include "zwang/urdf.hpp"

namespace zwang::cli {

namespace {

constexpr const char* kSolveUsage =
    "usage: zwang solve PROBLEM.json [-o FILE] [--pretty]\n"
    "\n"
    "Solve the constrained hybrid dynamics problem in PROBLEM.json (with static\n"
    "friction when it has a \"friction\" section) and print the solution as JSON.\n"
    "\n"
    "  -o, --output FILE  write the solution to FILE instead of stdout\n"
    "  --pretty           indent the JSON for humans\n"
    "\n"
    "Exit codes: 0 solved, 1 error (file, JSON, model, solver), 2 usage,\n"
    "3 infeasible task (the solution is still written, status.infeasible = true).\n"
    "The problem and solution schemas are in docs/cli.md.\n";

constexpr const char* kForwardDynamicsUsage =
    "usage: zwang forward-dynamics PROBLEM.json [-o FILE] [--pretty]\n"
    "\n"
    "Forward dynamics of the unconstrained robot (the articulated-body algorithm): q̈\n"
    "under the problem's q, qd, tau, gravity and wrenches, printed as solve prints a\n"
    "solution. A problem with constraints or a \"friction\" section is refused: zwang\n"
    "solve meets those.\n"
    "\n"
    "  -o, --output FILE  write the solution to FILE instead of stdout\n"
    "  --pretty           indent the JSON for humans\n"
    "\n"
    "Exit codes: 0 solved, 1 error (file, JSON, model, solver), 2 usage.\n";

constexpr const char* kSimulateUsage =
    "usage: zwang simulate PROBLEM.json [-o FILE] [--pretty]\n"
    "\n"
    "Simulate the problem over time (docs/simulation.md): its \"simulate\" section gives\n"
    "\"duration\", \"dt\" (default 0.001) and \"integrator\" (\"euler\" or \"rk4\"); \"tau\" is\n"
    "held, or a \"schedule\" gives it over time (piecewise linear). Friction as the\n"
    "\"friction\" section says (none without one); stick, slip and limit events are\n"
    "located inside the steps. Prints t, q, qd per step, the solve's tau_control, mu and\n"
    "states, the events and the energy as JSON.\n"
    "\n"
    "  -o, --output FILE  write the result to FILE instead of stdout\n"
    "  --pretty           indent the JSON for humans\n"
    "\n"
    "Exit codes: 0 simulated, 1 error (file, JSON, model, a step refused), 2 usage.\n";

constexpr const char* kInfoUsage =
    "usage: zwang info MODEL.urdf [--root LINK] [--tip LINK] [--base free|planar] [--strict]\n"
    "                  [--attach-beyond-tip] [--lock-mimic] [--json]\n"
    "\n"
    "Print the model loaded from MODEL.urdf: the base (fixed, free or planar; nq, nv),\n"
    "joints (parent joint, type, axis, limits, friction, viscous, rotor inertia, effort\n"
    "limit), frames, moving and base mass, and the model's warnings (also on stderr as\n"
    "\"zwang: warning: ...\"). A MODEL ending in .xml is MJCF, loaded whole through MuJoCo\n"
    "(docs/mujoco.md; only --strict and --json apply).\n"
    "\n"
    "  --root LINK           the model starts at LINK (default: the URDF's root link)\n"
    "  --tip LINK            the chain from the root to LINK (default: the whole tree\n"
    "                        below the root)\n"
    "  --base free|planar    give the root link a floating base: a free-flyer, or x, y, yaw\n"
    "                        in the world's x-y plane (default fixed; a URDF whose root\n"
    "                        joint is floating or planar floats without it)\n"
    "  --strict              refuse doubtful data (every warning becomes an error)\n"
    "  --attach-beyond-tip   weld links behind moving joints below the tip to the tip\n"
    "                        body as a payload (those joints locked at 0)\n"
    "  --lock-mimic          weld the mimic joints (at their position when the leader\n"
    "                        is at 0) instead of refusing the model\n"
    "  --json                print JSON instead of a table\n";

constexpr const char* kFkUsage =
    "usage: zwang fk MODEL.urdf [--q Q] [--root LINK] [--tip LINK] [--base free|planar] [--pretty]\n"
    "       zwang fk PROBLEM.json [--pretty]\n"
    "\n"
    "Forward kinematics at one state: print every frame's pose in the world\n"
    "(position, unit quaternion w x y z) and the robot's centre of mass (mass,\n"
    "position, velocity) as JSON. The state is --q (nq numbers, a floating base's\n"
    "first, separated by commas or blanks; default: the neutral configuration) at\n"
    "rest, or a solve problem's model, base, q and qd.\n"
    "\n"
    "  --q Q                the configuration, e.g. --q 0,0.5,-1 (quote blanks)\n"
    "  --root LINK, --tip LINK, --base free|planar   as zwang info\n"
    "  --pretty             indent the JSON for humans\n";

constexpr const char* kScenariosUsage =
    "usage: zwang scenarios [--out DIR] [--models DIR] [--no-plots]\n"
    "\n"
    "Reproduce the report's chapter 6 (scenarios 1 and 2) and Fig. 5.5 with the\n"
    "1-DOF arm: print the friction-aware results next to the report's numbers and\n"
    "write DIR/<name>.csv (g, qdd, tau over 201 friction values) and, with gnuplot,\n"
    "DIR/<name>_g.png, _qdd.png, _tau.png.\n"
    "\n"
    "  --out DIR     output directory (default: ./scenarios; created if missing)\n"
    "  --models DIR  where one_dof_arm.urdf is (default: the source tree's models/)\n"
    "  --no-plots    write the CSVs only (no gnuplot script, no PNG)\n"
    "\n"
    "Exit code 1 when a result disagrees with the report's.\n";

constexpr const char* kEnergyUsage =
    "usage: zwang energy [--out DIR] [--models DIR] [--no-plots]\n"
    "\n"
    "The Panda holding still against gravity in six poses, the dual arm\n"
    "(dual_panda.urdf) holding a 3 kg box between its hands in five postures, then\n"
    "simple_humanoid.urdf and solo12.urdf on a free base standing on the ground: the\n"
    "motor torques of the plain solver and of the friction-aware solver (margins\n"
    "0.5 and 1), with the URDF's breakaway friction (chosen values for the standing\n"
    "robots). Prints the tables and writes DIR/panda_energy.csv,\n"
    "DIR/dual_energy.csv, DIR/standing_energy.csv and, with gnuplot, their PNG bar\n"
    "charts (DIR/*_energy.png, DIR/*_joints.png).\n"
    "\n"
    "  --out DIR     output directory (default: ./energy; created if missing)\n"
    "  --models DIR  where panda.urdf, dual_panda.urdf, simple_humanoid.urdf and solo12.urdf\n"
    "                are (default: the source tree's models/)\n"
    "  --no-plots    write the CSVs only (no gnuplot scripts, no PNG)\n"
    "\n"
    "Exit code 1 when a result disagrees with the closed form or a check.\n";

constexpr const char* kCompareMujocoUsage =
    "usage: zwang compare-mujoco MODEL.xml [--state FILE.json] [--postures N] [--seed S]\n"
    "                            [--seconds T1,T2,...] [--gravity-compensation S]\n"
    "                            [--frictionloss F] [--noslip-iterations N] [--json] [--csv DIR]\n"
    "\n"
    "The robot of an MJCF file at rest under its gravity with its frictionloss: zwang's\n"
    "exact friction (state, mu*, qdd) against MuJoCo's soft friction in three settings\n"
    "(default: the file's; noslip: noslip_iterations; tight: dof_solref (2 timestep, 1),\n"
    "dof_solimp 0.9999): MuJoCo's friction torque and qacc (mj_forward) and the drift\n"
    "|q(t) - q(0)| after mj_step from rest. MuJoCo's contacts and actuators are off; a\n"
    "floating base is fixed (its free joint deleted). Needs zwang built with MuJoCo.\n"
    "(docs/mujoco.md, \"Soft friction against exact friction\")\n"
    "\n"
    "  --state FILE.json          the postures: {\"q\": [...], \"tau\": [...], \"name\": ...,\n"
    "                             \"gravity_compensation\": S} or {\"postures\": [ ... ]}\n"
    "                             (default: the first keyframe, else the neutral posture,\n"
    "                             and --postures random ones)\n"
    "  --postures N               random postures within the limits (default 3)\n"
    "  --seed S                   their seed (default 1)\n"
    "  --seconds T1,T2,...        simulated times of the drift (default 1,10)\n"
    "  --gravity-compensation S   tau = S G(q): S = 0.95 leaves 5 % of gravity to friction\n"
    "                             (default 0)\n"
    "  --frictionloss F           every DOF's frictionloss, in both (default: the file's)\n"
    "  --noslip-iterations N      of the noslip setting (default 10)\n"
    "  --json                     print JSON instead of tables\n"
    "  --csv DIR                  also write DIR/compare_joints.csv and DIR/compare_drift.csv\n"
    "                             (the largest drift on the DOFs zwang holds, every 0.01 s)\n";

constexpr const char* kCommandsUsage =
    "usage: zwang <command> [options]\n"
    "\n"
    "commands:\n"
    "  solve PROBLEM.json [-o FILE] [--pretty]        solve a JSON problem, print the solution as JSON\n"
    "  forward-dynamics PROBLEM.json [-o FILE]        q̈ of the unconstrained robot (no constraints, no friction)\n"
    "  simulate PROBLEM.json [-o FILE] [--pretty]     the motion over time, stick-slip events located, as JSON\n"
    "  info MODEL.urdf [--root L] [--tip L] [--json]  base, joints, frames and mass of a URDF tree or chain\n"
    "  info MODEL.xml [--json]                        the same of an MJCF model (zwang built with MuJoCo)\n"
    "  fk MODEL.urdf [--q Q] | fk PROBLEM.json        frame poses and centre of mass at one state, as JSON\n"
    "  scenarios [--out DIR] [--models DIR]           the report's chapter 6 and Fig. 5.5, with plots\n"
    "  energy [--out DIR] [--models DIR]              Panda, dual arm + box, humanoid and Solo 12 holding still:\n"
    "                                                 effort with/without friction\n"
    "  compare-mujoco MODEL.xml [--state FILE]        MuJoCo's soft joint friction against zwang's exact friction\n"
    "                                                 at rest (zwang built with MuJoCo)\n"
    "\n"
    "  zwang <command> --help   a command's options\n"
    "  zwang --version          the version\n"
    "\n"
    "Exit codes: 0 ok, 1 error, 2 usage, 3 infeasible task. See docs/cli.md.\n";

}  // namespace

const char* usageText(const std::string& command) {
  const std::pair<const char*, const char*> usages[] = {{"solve", kSolveUsage},
                                                        {"forward-dynamics", kForwardDynamicsUsage},
                                                        {"simulate", kSimulateUsage},
                                                        {"info", kInfoUsage},
                                                        {"fk", kFkUsage},
                                                        {"scenarios", kScenariosUsage},
                                                        {"energy", kEnergyUsage},
                                                        {"compare-mujoco", kCompareMujocoUsage}};
  for (const auto& [name, text] : usages)
    if (command == name) return text;
  return kCommandsUsage;
}

std::optional<ProblemArguments> problemArguments(const char* command, int argc, char** argv) {
  const Arguments args = parseArguments(command, argc, argv, 2, {"--pretty"}, {"-o", "--output"});
  if (args.help) {
    std::fputs(usageText(command), stdout);
    return std::nullopt;
  }
  if (args.positional.size() != 1)
    throw UsageError(command, args.positional.empty() ? "no problem file given" : "more than one problem file given");
  return ProblemArguments{args.positional[0], args.has("--output") ? args.value("--output") : args.value("-o"),
                          args.has("--pretty")};
}

bool Arguments::has(const std::string& name) const {
  for (const auto& option : options)
    if (option.first == name) return true;
  return false;
}

std::string Arguments::value(const std::string& name, const std::string& fallback) const {
  std::string result = fallback;
  for (const auto& option : options)
    if (option.first == name) result = option.second;  // the last one wins
  return result;
}

Arguments parseArguments(const std::string& command, int argc, char** argv, int first,
                         const std::vector<std::string>& flags, const std::vector<std::string>& with_value) {
  auto contains = [](const std::vector<std::string>& list, const std::string& name) {
    for (const auto& entry : list)
      if (entry == name) return true;
    return false;
  };
  Arguments args;
  bool only_positional = false;
  for (int i = first; i < argc; ++i) {
    std::string arg = argv[i];
    if (only_positional || arg.size() < 2 || arg[0] != '-') {
      args.positional.push_back(arg);
      continue;
    }
    if (arg == "--") {
      only_positional = true;
      continue;
    }
    if (arg == "--help" || arg == "-h") {
      args.help = true;
      continue;
    }
    std::string name = arg, value;
    bool inline_value = false;
    if (const auto eq = arg.find('='); arg.rfind("--", 0) == 0 && eq != std::string::npos) {
      name = arg.substr(0, eq);
      value = arg.substr(eq + 1);
      inline_value = true;
    }
    if (contains(flags, name)) {
      if (inline_value) throw UsageError(command, "option " + name + " takes no value");
      args.options.emplace_back(name, "");
    } else if (contains(with_value, name)) {
      if (!inline_value) {
        if (i + 1 >= argc) throw UsageError(command, "option " + name + " needs a value");
        value = argv[++i];
      }
      args.options.emplace_back(name, value);
    } else {
      throw UsageError(command, "unknown option '" + printable(arg, 60) + "'");
    }
  }
  return args;
}

namespace {}  // namespace

void printWarnings(const Model& model) {
  for (const ModelWarning& w : model.warnings())
    std::fprintf(stderr, "zwang: warning: %s\n", printable(w.message, 4000).c_str());
}

internal::NamedUrdfOptions commandLineUrdfOptions(const std::string& command, const Arguments& args) {
  problem::ModelRequest request{args.value("--root"),
                                args.value("--tip"),
                                args.has("--strict"),
                                args.has("--attach-beyond-tip"),
                                args.has("--lock-mimic"),
                                BaseType::Fixed,
                                {}};
  request.names = {"--tip", "--rotor-inertia", "--attach-beyond-tip", "--lock-mimic"};
  request.names.base = "--base";
  if (args.has("--base")) {
    try {
      request.base = problem::parseBaseType(problem::Spelling{'\'', ""}, args.value("--base"));  // quoted with '
    } catch (const problem::ProblemError& e) {
      throw UsageError(command, std::string("--base: ") + e.what());
    }
  }
  return problem::urdfOptions(request);
}

std::string readFile(const std::string& path, std::size_t max_bytes) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw CliError(kExitError, path + ": cannot read the file: it is a directory");
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int err = errno;
    throw CliError(kExitError, path + ": cannot read the file (" + (err ? std::strerror(err) : "unknown error") + ")");
  }
  std::string content;
  char buffer[65536];
  while (in.read(buffer, sizeof buffer) || in.gcount() > 0) {
    content.append(buffer, static_cast<std::size_t>(in.gcount()));
    if (content.size() > max_bytes)
      throw CliError(kExitError, path + ": the file is larger than " + std::to_string(max_bytes) + " bytes");
  }
  if (in.bad()) throw CliError(kExitError, path + ": cannot read the file");
  return content;
}

void writeOutput(const std::string& path, const std::string& text) {
  if (path.empty() || path == "-") {
    std::cout << text << std::flush;
    if (!std::cout) throw CliError(kExitError, "cannot write to stdout");
    return;
  }
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) {
    const int err = errno;
    throw CliError(kExitError, path + ": cannot write the file (" + (err ? std::strerror(err) : "unknown error") + ")");
  }
  out << text;
  out.close();
  if (!out) throw CliError(kExitError, path + ": cannot write the file");
}

std::string modelsDirectory(const Arguments& args, const std::string& file) {
  if (args.has("--models")) return args.value("--models");
  for (const char* dir : {ZWANG_MODELS_DIR, ZWANG_INSTALLED_MODELS_DIR}) {
    std::error_code ec;
    if (std::filesystem::exists(std::filesystem::path(dir) / file, ec)) return dir;
  }
  return ZWANG_MODELS_DIR;
}

void printColumns(const std::vector<std::vector<std::string>>& rows, std::size_t left) {
  // Display width of UTF-8 text: count the bytes that start a character.
  auto columns = [](const std::string& s) {
    std::size_t n = 0;
    for (const char c : s) n += (static_cast<unsigned char>(c) & 0xC0) != 0x80;
    return n;
  };
  std::vector<std::size_t> width;
  for (const auto& row : rows) {
    if (width.size() < row.size()) width.resize(row.size(), 0);
    for (std::size_t c = 0; c < row.size(); ++c) width[c] = std::max(width[c], columns(row[c]));
  }
  for (const auto& row : rows) {
    std::string line;
    for (std::size_t c = 0; c < row.size(); ++c)
      line += (c == 0 ? "" : "  ") + (c < left ? row[c] + std::string(width[c] - columns(row[c]), ' ')
                                               : std::string(width[c] - columns(row[c]), ' ') + row[c]);
    while (!line.empty() && line.back() == ' ') line.pop_back();
    std::printf("%s\n", line.c_str());
  }
}

namespace {

bool onPath(const std::string& program) {
  const char* path = std::getenv("PATH");
  if (!path) return false;
  std::stringstream dirs(path);
  std::string dir;
  while (std::getline(dirs, dir, ':')) {
    if (dir.empty()) dir = ".";
    const std::string candidate = dir + "/" + program;
    struct stat st {};
    if (::stat(candidate.c_str(), &st) == 0 && S_ISREG(st.st_mode) && ::access(candidate.c_str(), X_OK) == 0)
      return true;
  }
  return false;
}

// Run `gnuplot SCRIPT` in `dir`; the exit status (-1 when it could not start).
int runGnuplot(const std::filesystem::path& dir, const std::string& script) {
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t pid = ::fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    if (::chdir(dir.c_str()) != 0) ::_exit(126);
    char* const argv[] = {const_cast<char*>("gnuplot"), const_cast<char*>(script.c_str()), nullptr};
    ::execvp("gnuplot", argv);
    ::_exit(127);
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return -1;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

bool plotWithGnuplot(const std::string& command, const std::filesystem::path& dir, const std::string& script) {
  if (!onPath("gnuplot")) {
    std::fprintf(stderr,
                 "zwang: %s: gnuplot is not on PATH: no PNG plots (the CSVs are written; "
                 "install gnuplot, e.g. Debian's gnuplot-nox, and run `gnuplot %s` in %s)\n",
                 command.c_str(), script.c_str(), dir.string().c_str());
    return false;
  }
  if (const int rc = runGnuplot(dir, script); rc != 0) {
    std::fprintf(stderr, "zwang: %s: gnuplot failed (exit %d): no PNG plots (the CSVs are written)\n", command.c_str(),
                 rc);
    return false;
  }
  return true;
}

std::string ReportCommand::shownUrdf() const {
  std::error_code ec;
  const std::filesystem::path shown = std::filesystem::proximate(urdf, ec);
  return (ec ? urdf : shown).string();
}

std::optional<ReportCommand> startReportCommand(const std::string& command, int argc, char** argv,
                                                const std::string& default_out, const ExpectedModel& expected) {
  ReportCommand report;
  report.name = command;
  report.args = parseArguments(command, argc, argv, 2, {"--no-plots"}, {"--out", "--models"});
  if (report.args.help) {
    std::fputs(usageText(command), stdout);
    return std::nullopt;
  }
  if (!report.args.positional.empty())
    throw UsageError(command, "unexpected argument '" + printable(report.args.positional[0], 60) + "'");
  report.out = report.args.value("--out", default_out);
  report.urdf = std::filesystem::path(modelsDirectory(report.args, expected.file)) / expected.file;
  try {
    report.model = loadUrdfFile(report.urdf.string());
  } catch (const ModelError& e) {
    throw CliError(kExitError, command + ": " + e.what() + " (use --models DIR)");
  }
  bool as_expected = report.model.dof() == expected.dof;
  for (const std::string& frame : expected.frames) as_expected = as_expected && report.model.hasFrame(frame);
  if (!as_expected) throw CliError(kExitError, command + ": " + report.urdf.string() + ": expected " + expected.what);
  std::error_code ec;
  std::filesystem::create_directories(report.out, ec);
  if (ec)
    throw CliError(kExitError,
                   command + ": " + report.out.string() + ": cannot create the directory (" + ec.message() + ")");
  return report;
}

bool writePlots(const ReportCommand& report, const std::string& script_name, const std::string& script,
                const std::string& pngs, bool run_gnuplot) {
  if (report.args.has("--no-plots")) return true;
  writeOutput((report.out / script_name).string(), script);
  if (!run_gnuplot || !plotWithGnuplot(report.name, report.out, script_name)) return false;
  std::printf("wrote %s/%s (gnuplot, script %s)\n", report.out.string().c_str(), pngs.c_str(), script_name.c_str());
  return true;
}

int reportExitCode(const ReportCommand& report, bool all_ok, const std::string& reference) {
  if (all_ok) return kExitOk;
  std::fprintf(stderr, "zwang: %s: a result disagrees with %s (see the check column)\n", report.name.c_str(),
               reference.c_str());
  return kExitError;
}

}  // namespace zwang::cli
