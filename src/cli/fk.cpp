// `zwang fk MODEL.urdf [--q Q] [--root L] [--tip L] [--base free|planar] [--pretty]` and `zwang fk PROBLEM.json`:
// every frame's pose and the centre of mass at one state. A thin front end: the problem layer computes the report
// (problem::kinematicsReport), this file reads the state and prints it.
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "cli.hpp"
#include "problem.hpp"
#include "solution_writer.hpp"

namespace zwang::cli {

namespace {

// --q: numbers separated by commas or blanks.
Eigen::VectorXd parseNumbers(const std::string& text) {
  std::vector<double> values;
  const char* p = text.c_str();
  for (;;) {
    while (*p == ',' || *p == ' ' || *p == '\t') ++p;
    if (*p == '\0') break;
    char* end = nullptr;
    errno = 0;
    const double x = std::strtod(p, &end);
    if (end == p || errno == ERANGE || !std::isfinite(x))
      throw UsageError("fk", "--q: '" + printable(text, 60) + "' is not a list of finite numbers");
    values.push_back(x);
    p = end;
  }
  return Eigen::Map<const Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size()));
}

// The URDF, loaded as `zwang info` loads it.
Model loadModel(const Arguments& args) {
  try {
    return internal::loadUrdfFile(args.positional[0], commandLineUrdfOptions("fk", args));
  } catch (const ModelError& e) {
    throw CliError(kExitError, e.what());
  }
}

Json reportJson(const problem::KinematicsReport& report, const Eigen::VectorXd& q) {
  Json frames = Json::object();
  for (const problem::FramePose& f : report.frames)
    frames[f.name] = {{"position", array(f.position)}, {"quaternion", array(f.quaternion)}};
  Json com;  // null without moving mass
  if (report.has_com)
    com = {{"mass", report.mass}, {"position", array(report.com)}, {"velocity", array(report.com_velocity)}};
  return {{"q", array(q)}, {"frames", std::move(frames)}, {"com", std::move(com)}};
}

}  // namespace

int commandFk(int argc, char** argv) {
  const Arguments args = parseArguments("fk", argc, argv, 2, {"--pretty"}, {"--q", "--root", "--tip", "--base"});
  if (args.help) {
    std::fputs(usageText("fk"), stdout);
    return kExitOk;
  }
  if (args.positional.size() != 1)
    throw UsageError("fk", args.positional.empty() ? "no model or problem file given" : "more than one file given");
  const std::string& path = args.positional[0];
  const bool json = path.size() >= 5 && path.compare(path.size() - 5, 5, ".json") == 0;
  if (json && (args.has("--q") || args.has("--root") || args.has("--tip") || args.has("--base")))
    throw UsageError("fk", "a problem file gives the model and the state itself: no --q, --root, --tip or --base");
  Model model;
  Eigen::VectorXd q, qd;
  std::string where = path;
  if (json) {
    const BoundProblem bound = bindProblem(readProblem(path));
    model = bound.model;
    q = bound.q;
    qd = bound.qd;
  } else {
    model = loadModel(args);
    q = Eigen::VectorXd::Zero(model.nq());
    if (args.has("--q")) {
      q = parseNumbers(args.value("--q"));
      where += ": --q";
    } else if (const Status s = neutralConfiguration(model, q); !s) {
      throw CliError(kExitError, path + ": " + s.message);
    }
    qd = Eigen::VectorXd::Zero(model.nv());
  }
  printWarnings(model);
  try {
    const problem::KinematicsReport report = problem::kinematicsReport(model, q, qd);
    const Json out = reportJson(report, q);
    writeOutput("", (args.has("--pretty") ? prettyDump(out) : out.dump()) + "\n");
  } catch (const problem::ProblemError& e) {
    throw CliError(kExitError, where + ": " + e.what());
  }
  return kExitOk;
}

}  // namespace zwang::cli
