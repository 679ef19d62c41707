// The problem layer's messages (src/problem), row by row of bad_inputs.json:
// the words both front ends print, here straight from the layer.
#include <catch2/catch.hpp>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "problem/problem.hpp"
#include "zwang/zwang.hpp"

namespace {

using Json = nlohmann::json;
using zwang::problem::ProblemError;
namespace problem = zwang::problem;

const problem::Spelling kSpelling{};

// Quotes made alike: the table and the front ends quote their own way.
std::string sameQuotes(std::string text) {
  for (char& c : text)
    if (c == '"') c = '\'';
  return text;
}

zwang::ConstraintMatrix directions(const Json& rows) {
  zwang::ConstraintMatrix A(6, static_cast<Eigen::Index>(rows.size()));
  for (std::size_t k = 0; k < rows.size(); ++k)
    for (int r = 0; r < 6; ++r) A(r, static_cast<Eigen::Index>(k)) = rows[k][static_cast<std::size_t>(r)].get<double>();
  return A;
}

// The row's constraint through the layer, as a front end takes it.
void addConstraint(const zwang::Model& model, zwang::Task& task, const Json& c) {
  problem::ConstraintDesc d;
  d.joint = c.value("joint", "");
  d.frame = c.value("frame", "");
  d.relative_to = c.value("relative_to", "");
  d.contact = c.value("contact", false);
  const bool relative = c.contains("relative_to");
  problem::checkRelative(kSpelling, d, relative);
  d.expressed = relative ? zwang::Expressed::Reference : zwang::Expressed::Local;
  if (c.contains("expressed_in"))
    d.expressed = problem::parseExpressed(kSpelling, c["expressed_in"].get<std::string>(),
                                          relative ? problem::AxesOf::RelativeConstraint : problem::AxesOf::Constraint);
  if (c.contains("directions")) d.A = directions(c["directions"]);
  problem::addConstraint(kSpelling, model, task, d);
}

Eigen::VectorXd vectorOf(const Json& values) {
  Eigen::VectorXd v(static_cast<Eigen::Index>(values.size()));
  for (std::size_t k = 0; k < values.size(); ++k) v[static_cast<Eigen::Index>(k)] = values[k].get<double>();
  return v;
}

void addWrench(const zwang::Model& model, zwang::Task& task, const Json& w) {
  const zwang::Expressed e =
      problem::parseExpressed(kSpelling, w.value("expressed_in", "local"), problem::AxesOf::Wrench);
  problem::addWrench(model, task, w["frame"].get<std::string>(), e);
}

// The row's input through the layer; the message it raises, with the front ends' path in front.
std::string messageOf(const zwang::Model& model, const Json& row, problem::Fault& fault) {
  std::string where;
  try {
    zwang::Task task(model);
    if (row.contains("constraint")) {
      where = "constraints[0]";
      addConstraint(model, task, row["constraint"]);
    }
    if (row.contains("wrench")) {
      where = "wrenches[0]";
      addWrench(model, task, row["wrench"]);
    }
    if (row.contains("balance")) {
      where = "balance";
      zwang::BalanceOptions o;
      o.singular_threshold = row["balance"].value("singular_threshold", o.singular_threshold);
      o.rank_tolerance = row["balance"].value("rank_tolerance", o.rank_tolerance);
      o.residual_tolerance = row["balance"].value("residual_tolerance", o.residual_tolerance);
      problem::checkBalance(o);
    }
    if (row.contains("friction")) {
      where = "friction";
      zwang::FrictionOptions o;
      o.margin = row["friction"].value("margin", o.margin);
      o.velocity_tolerance = row["friction"].value("velocity_tolerance", o.velocity_tolerance);
      problem::checkFriction(o);
    }
    if (row.contains("joint_modes")) {
      for (const auto& [name, value] : row["joint_modes"].items()) {
        where = "joint_modes." + name;
        problem::JointModeDesc mode;
        mode.name = name;
        if (value.is_string()) {
          mode.kind = problem::parseModeKind(kSpelling, value.get<std::string>());
        } else {
          mode.kind = problem::ModeKind::Acceleration;
          mode.acceleration = vectorOf(value["acceleration"]);
        }
        problem::setJointMode(kSpelling, model, task, mode);
      }
    }
    if (row.contains("rotor_inertia")) {  // the per-joint arrays: their own name is the path
      where = "";
      problem::withRotorInertia(model, "rotor_inertia", vectorOf(row["rotor_inertia"]));
    }
    if (row.contains("breakaway")) {
      where = "";
      zwang::FrictionOptions o;
      o.breakaway = vectorOf(row["breakaway"]);
      problem::checkFrictionOverrides(model, o);
    }
  } catch (const ProblemError& e) {
    fault = e.fault();
    const std::string key = e.key().empty() || where.empty() ? e.key() : "." + e.key();
    return where + key + ": " + e.what();
  }
  return "(no error)";
}

}  // namespace

TEST_CASE("The problem layer's messages: every row of the shared table", "[problem]") {
  std::ifstream file(ZWANG_PROBLEM_TABLE);
  REQUIRE(file);
  const Json table = Json::parse(file);
  zwang::UrdfOptions urdf;
  urdf.root = "panda_link0";
  urdf.tip = "tool0";
  const zwang::Model model = zwang::loadUrdfFile(ZWANG_MODELS_DIR "/panda.urdf", urdf);
  REQUIRE(table["rows"].size() >= 10);
  for (const Json& row : table["rows"]) {
    SECTION(row["name"].get<std::string>()) {
      problem::Fault fault = problem::Fault::Value;
      const std::string message = messageOf(model, row, fault);
      INFO("message: " << message);
      CHECK(sameQuotes(message).find(sameQuotes(row["expect"].get<std::string>())) != std::string::npos);
      CHECK(fault == (row["kind"] == "model" ? problem::Fault::Model : problem::Fault::Value));
    }
  }
}

TEST_CASE("The problem layer quotes each front end's way and cuts long names", "[problem]") {
  const problem::Spelling python{'\'', "comes first in q, qd and tau"};
  try {
    problem::parseExpressed(python, "sideways", problem::AxesOf::Wrench);
    FAIL("accepted \"sideways\"");
  } catch (const ProblemError& e) {
    CHECK(std::string(e.what()) == "unknown value 'sideways' (expected 'local' or 'world')");
  }
  CHECK(problem::quoted(kSpelling, std::string(100, 'x'), 10) == "\"xxxxxxxxxx...\"");
  CHECK(problem::printable("a\x01"
                           "b") == "a\\x01b");
}

TEST_CASE("The problem layer picks the solve: plain without friction options, else with friction", "[problem]") {
  const zwang::Model model = zwang::loadUrdfFile(ZWANG_MODELS_DIR "/one_dof_arm.urdf");
  zwang::Task task(model);
  const Eigen::VectorXd q = Eigen::VectorXd::Constant(1, 0.3), qd = Eigen::VectorXd::Zero(1);
  const Eigen::VectorXd tau = Eigen::VectorXd::Constant(1, 2.0);
  const zwang::FrictionOptions friction;
  zwang::Workspace layer(model, task), direct(model, task);
  REQUIRE(problem::solve(model, layer, q, qd, tau, task, &friction));
  REQUIRE(zwang::solveWithFriction(model, direct, q, qd, tau, task, friction));
  CHECK(layer.solution.qdd == direct.solution.qdd);
  CHECK(layer.friction.mu == direct.friction.mu);
  REQUIRE(problem::solve(model, layer, q, qd, tau, task, nullptr));
  REQUIRE(zwang::solveHybridDynamics(model, direct, q, qd, tau, task));
  CHECK(layer.solution.qdd == direct.solution.qdd);
}
