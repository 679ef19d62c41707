// Tests of the `zwang` command-line tool (docs/cli.md): they run the built
// binary and check exit codes, stderr and the JSON/CSV it writes. Numbers are
// compared numerically, never as strings.
//
// Tags (one ctest test each): [golden] [errors] [robustness] [usage] [info] [scenarios] [energy] [docs];
// test_cli_standing.cpp adds to [energy] (the humanoid and Solo 12 standing)
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "cli_runner.hpp"
#include "zwang/zwang.hpp"

using cli_test::Run;
using cli_test::run;
using Json = nlohmann::ordered_json;  // keeps the key order of the output

namespace {

const std::string kProblems = ZWANG_CLI_PROBLEMS;
std::string problem(const std::string& name) { return kProblems + "/" + name; }

Json parse(const std::string& text) {
  INFO(text);
  REQUIRE(Json::accept(text));
  return Json::parse(text);
}

// Solve a problem file that must succeed; the parsed solution.
Json solve(const std::string& file, const std::vector<std::string>& extra = {}) {
  std::vector<std::string> args{"solve", file};
  args.insert(args.end(), extra.begin(), extra.end());
  const Run r = run(args);
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.empty());
  return parse(r.out);
}

std::vector<double> numbers(const Json& j) { return j.get<std::vector<double>>(); }

// One line on stderr, "zwang: ..." and nothing on stdout.
void checkOneLineError(const Run& r, int exit_code) {
  INFO("stdout: " << r.out << "\nstderr: " << r.err);
  CHECK_FALSE(r.signaled);
  CHECK(r.exit_code == exit_code);
  CHECK(r.out.empty());
  REQUIRE(r.err.size() > 7);
  CHECK(r.err.rfind("zwang: ", 0) == 0);
  CHECK(r.err.back() == '\n');
  CHECK(r.err.find('\n') == r.err.size() - 1);
  CHECK(r.err.size() < 700);
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

// ---------------------------------------------------------------------------
// Golden tests: the reference cases (docs/theory.md, "The reference cases") through the tool.

TEST_CASE("1-DOF arm, tip force -5 N: stick, mu* = -5, qdd = 0, tau_control = 0", "[golden]") {
  const Json s = solve(problem("arm_stick.json"));
  CHECK(s["joints"] == Json::array({"joint1"}));
  CHECK(s["friction"]["mu"][0].get<double>() == Approx(-5.0).margin(1e-9));
  CHECK(s["qdd"][0].get<double>() == Approx(0.0).margin(1e-12));
  CHECK(s["tau_control"][0].get<double>() == Approx(0.0).margin(1e-12));
  CHECK(s["tau_constraint"][0].get<double>() == Approx(0.0).margin(1e-12));
  CHECK(s["friction"]["state"][0] == "stick");
  CHECK(s["friction"]["indeterminate"] == false);
  CHECK(s["nu"].empty());
  CHECK(s["status"]["infeasible"] == false);
  CHECK(s["status"]["singular"] == false);
  CHECK(s["status"]["rank"] == 0);
  // the loaded frame is reported; its acceleration is zero
  for (const double a : numbers(s["frames"]["tip"]["acceleration_world"])) CHECK(a == Approx(0.0).margin(1e-12));
  // g(mu*) = Z0 + mu* qdd* = 0 for a resting arm
  CHECK(s["gauss"].get<double>() == Approx(0.0).margin(1e-12));
}

// The same arm as MJCF (models/one_dof_arm.xml) through the MJCF loader: the report's seed table again.
TEST_CASE("1-DOF arm from MJCF: mu* = -5, qdd = 0 at 5 N; mu* = -10, qdd = -1/2.25 at 11 N", "[mjcf]") {
#ifdef ZWANG_CLI_WITH_MUJOCO
  const Json stick = solve(problem("arm_stick_mjcf.json"));
  CHECK(stick["joints"] == Json::array({"joint1"}));
  CHECK(stick["friction"]["mu"][0].get<double>() == Approx(-5.0).margin(1e-9));
  CHECK(stick["qdd"][0].get<double>() == Approx(0.0).margin(1e-12));
  CHECK(stick["friction"]["state"][0] == "stick");
  const Json slip = solve(problem("arm_slip_mjcf.json"));
  CHECK(slip["friction"]["mu"][0].get<double>() == Approx(-10.0).margin(1e-12));
  CHECK(slip["qdd"][0].get<double>() == Approx(-1.0 / 2.25).margin(1e-12));
  CHECK(slip["friction"]["state"][0] == "slip-");
  // zwang info reads it too: one joint, its frames (the world body, the link, the site).
  const Run info = run({"info", std::string(ZWANG_MODELS_DIR) + "/one_dof_arm.xml"});
  CHECK(info.exit_code == 0);
  CHECK(contains(info.out, "joint1"));
  CHECK(contains(info.out, "tip"));
  // Without "gravity", the MJCF's <option gravity>: along -y it pulls the arm's COM (0.5 m out) down, so
  // qdd = -9.81 * 0.5 / 2.25.
  std::string arm = cli_test::readText(std::string(ZWANG_MODELS_DIR) + "/one_dof_arm.xml");
  const std::string down = "gravity=\"0 0 -9.81\"";
  REQUIRE(arm.find(down) != std::string::npos);
  arm.replace(arm.find(down), down.size(), "gravity=\"0 -9.81 0\"");
  const std::string dir = cli_test::scratchDir();
  cli_test::writeText(dir + "/arm_gravity_y.xml", arm);
  cli_test::writeText(dir + "/arm_gravity_y.json", "{\"model\": \"arm_gravity_y.xml\", \"q\": [0]}");
  const Json fall = solve(dir + "/arm_gravity_y.json");
  CHECK(fall["qdd"][0].get<double>() == Approx(-9.81 * 0.5 / 2.25).margin(1e-12));
  // A URDF-only option on an MJCF model is refused, naming it.
  const Run tip = run({"info", std::string(ZWANG_MODELS_DIR) + "/one_dof_arm.xml", "--tip", "tip"});
  CHECK(tip.exit_code != 0);
  CHECK(contains(tip.err, "--tip applies to URDF models only"));
#else
  const Run r = run({"solve", problem("arm_stick_mjcf.json")});
  CHECK(r.exit_code != 0);
  CHECK(contains(r.err, "MJCF needs zwang built with MuJoCo"));
#endif
}

// `zwang compare-mujoco` (docs/mujoco.md, "Soft friction against exact friction") on the 1-DOF arm: the JSON's
// keys, zwang's exact stick against MuJoCo's creep, the CSVs, and bad inputs. Half a second simulated: cheap.
TEST_CASE("compare-mujoco: the 1-DOF arm at 5 and 11 N, JSON keys, CSV, bad inputs", "[mjcf]") {
  const std::string arm = std::string(ZWANG_MODELS_DIR) + "/one_dof_arm.xml";
  const std::string state = std::string(ZWANG_DOCS_DIR) + "/mujoco/one_dof_arm_5N.json";
#ifdef ZWANG_CLI_WITH_MUJOCO
  const std::string dir = cli_test::scratchDir() + "/compare";
  const Run r = run({"compare-mujoco", arm, "--state", state, "--seconds", "0.5", "--json", "--csv", dir});
  INFO(r.err);
  REQUIRE(r.exit_code == 0);
  const Json c = parse(r.out);
  std::vector<std::string> keys;
  for (const auto& item : c.items()) keys.push_back(item.key());
  CHECK(keys == std::vector<std::string>{"model", "base_fixed", "timestep", "integrator", "dofs", "frictionloss",
                                         "seconds", "settings", "postures", "warnings"});
  CHECK(c["dofs"] == Json::array({"joint1"}));
  CHECK(c["settings"][0]["name"] == "default");
  CHECK(c["settings"][1]["name"] == "noslip");
  CHECK(c["settings"][2]["name"] == "tight");
  REQUIRE(c["postures"].size() == 2);
  const Json& stick = c["postures"][0];
  CHECK(stick["name"] == "5 N at the tip");
  CHECK(stick["zwang"]["state"][0] == "stick");
  CHECK(stick["zwang"]["qdd"][0].get<double>() == 0.0);
  CHECK(stick["zwang"]["mu"][0].get<double>() == Approx(-5.0).margin(1e-12));
  const Json& def = stick["mujoco"][0];
  std::vector<std::string> setting_keys;
  for (const auto& item : def.items()) setting_keys.push_back(item.key());
  CHECK(setting_keys ==
        std::vector<std::string>{"name", "qacc", "tau_friction", "drift", "held_drift_max", "mujoco_warnings"});
  // MuJoCo's default soft friction: the arm creeps where zwang holds it (docs/mujoco.md explains the sizes).
  CHECK(def["qacc"][0].get<double>() < -1e-3);
  CHECK(def["drift"][0][0].get<double>() > 1e-5);
  CHECK(def["held_drift_max"][0].get<double>() == def["drift"][0][0].get<double>());
  CHECK(def["mujoco_warnings"].empty());
  const Json& slip = c["postures"][1];
  CHECK(slip["zwang"]["state"][0] == "slip-");
  CHECK(slip["mujoco"][1]["tau_friction"][0].get<double>() == Approx(10.0).margin(1e-9));  // noslip: the bound
  CHECK(contains(cli_test::readText(dir + "/compare_drift.csv"), "posture,t,default,noslip,tight\n0,0,0,0,0\n"));
  CHECK(contains(cli_test::readText(dir + "/compare_joints.csv"), "0,joint1,stick,10,5,0,"));
  // The tables.
  const Run text = run({"compare-mujoco", arm, "--state", state, "--seconds", "0.5"});
  CHECK(text.exit_code == 0);
  CHECK(contains(text.out, "posture '5 N at the tip': zwang holds 1 of 1 DOFs"));
  CHECK(contains(text.out, "largest, held"));
  // Bad inputs: usage errors (exit 2) and files (exit 1), each naming what is wrong.
  const std::vector<std::pair<std::vector<std::string>, std::string>> usage{
      {{"compare-mujoco"}, "no model file given"},
      {{"compare-mujoco", arm, "--seconds", "0"}, "--seconds: each time must be in (0, 3600] s"},
      {{"compare-mujoco", arm, "--seconds", "1,x"}, "--seconds: 'x' is not a finite number"},
      {{"compare-mujoco", arm, "--postures", "-1"}, "--postures: '-1' is not an integer in [0, 1000]"},
      {{"compare-mujoco", arm, "--frictionloss", "-1"}, "--frictionloss: must be at least 0"},
      {{"compare-mujoco", arm, "--state", state, "--postures", "2"}, "--state gives the postures"}};
  for (const auto& [args, message] : usage) {
    const Run bad = run(args);
    INFO(bad.err);
    CHECK(bad.exit_code == 2);
    CHECK(contains(bad.err, message));
  }
  const std::string scratch = cli_test::scratchDir();
  cli_test::writeText(scratch + "/extra_key.json", "{\"q\": [0], \"torque\": [1]}");
  cli_test::writeText(scratch + "/long_q.json", "{\"postures\": [{\"name\": \"two\", \"q\": [0, 1]}]}");
  const std::vector<std::pair<std::vector<std::string>, std::string>> files{
      {{"compare-mujoco", arm, "--state", scratch + "/extra_key.json"}, "key 'torque' is not one of"},
      {{"compare-mujoco", arm, "--state", scratch + "/long_q.json"}, "posture 'two': q has 2 entries, the model 1"},
      {{"compare-mujoco", arm + ".missing"}, "cannot open the file"},
      {{"compare-mujoco", std::string(ZWANG_MODELS_DIR) + "/one_dof_arm.urdf"}, "not <mujoco>: not an MJCF file"}};
  for (const auto& [args, message] : files) {
    const Run bad = run(args);
    checkOneLineError(bad, 1);
    CHECK(contains(bad.err, message));
  }
#else
  const Run r = run({"compare-mujoco", arm, "--state", state});
  CHECK(r.exit_code == 1);
  CHECK(contains(r.err, "compare-mujoco needs zwang built with MuJoCo"));
#endif
}

TEST_CASE("1-DOF arm, tip force -11 N: slip, mu* = -10, qdd = -1/2.25", "[golden]") {
  const Json s = solve(problem("arm_slip.json"));
  const double qdd = -1.0 / 2.25;
  CHECK(s["friction"]["mu"][0].get<double>() == Approx(-10.0).margin(1e-12));
  CHECK(s["qdd"][0].get<double>() == Approx(qdd).margin(1e-12));
  CHECK(s["tau_control"][0].get<double>() == Approx(0.0).margin(1e-12));
  CHECK(s["friction"]["state"][0] == "slip-");
  CHECK(s["friction"]["kkt_residual"].get<double>() <= 1e-12);
  // the tip, 1 m out along x, accelerates along y with qdd; the angular part is qdd about z
  const std::vector<double> a = numbers(s["frames"]["tip"]["acceleration_world"]);
  REQUIRE(a.size() == 6);
  const double expected[6] = {0, qdd, 0, 0, 0, qdd};
  for (int k = 0; k < 6; ++k) CHECK(a[static_cast<std::size_t>(k)] == Approx(expected[k]).margin(1e-12));
  // gauss is Z0(qdd*) = 1/2 I qdd² - tau_ext qdd with tau_ext = -11 N·m
  CHECK(s["gauss"].get<double>() == Approx(0.5 * 2.25 * qdd * qdd + 11.0 * qdd).margin(1e-12));
}

TEST_CASE("Fig. 5.5: fully constrained, mu* = +10, tau_control = 2.25*5 + 10", "[golden]") {
  const Json s = solve(problem("arm_fig55.json"));
  CHECK(s["friction"]["mu"][0].get<double>() == Approx(10.0).margin(1e-12));
  CHECK(s["qdd"][0].get<double>() == Approx(5.0).margin(1e-12));
  CHECK(s["tau_control"][0].get<double>() == Approx(2.25 * 5 + 10).margin(1e-12));
  CHECK(s["tau_constraint"][0].get<double>() == Approx(2.25 * 5 + 10).margin(1e-12));
  REQUIRE(s["nu"].size() == 1);
  CHECK(s["nu"][0].get<double>() == Approx(2.25 * 5 + 10).margin(1e-12));  // a torque about z on link1
  CHECK(s["friction"]["state"][0] == "slip+");
  CHECK(s["status"]["rank"] == 1);
  CHECK(s["frames"]["link1"]["acceleration_world"][5].get<double>() == Approx(5.0).margin(1e-12));
}

TEST_CASE("Panda holds its tool still: the tool does not move; the tool and the library agree", "[golden]") {
  const Json s = solve(problem("panda_hold.json"));
  CHECK(s["joints"].size() == 7);
  CHECK(s["status"]["rank"] == 6);
  CHECK(s["status"]["singular"] == false);
  for (const double a : numbers(s["frames"]["tool0"]["acceleration_world"])) CHECK(a == Approx(0.0).margin(1e-9));

  // The same problem through the C++ API.
  const zwang::Model model = zwang::loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/panda.urdf");
  zwang::Task task(model);
  task.addConstraint("tool0", zwang::ConstraintMatrix::Identity(6, 6), zwang::Expressed::World);
  zwang::Workspace ws(model, task);
  Eigen::VectorXd q(7);
  q << 0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785;
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(7);
  REQUIRE(zwang::solveWithFriction(model, ws, q, zero, zero, task).ok());
  auto same = [](const Json& j, const Eigen::VectorXd& v) {
    REQUIRE(j.size() == static_cast<std::size_t>(v.size()));
    for (Eigen::Index k = 0; k < v.size(); ++k)
      CHECK(j[static_cast<std::size_t>(k)].get<double>() == Approx(v[k]).margin(1e-12));
  };
  same(s["qdd"], ws.solution.qdd);
  same(s["tau_constraint"], ws.solution.tau_constraint);
  same(s["tau_control"], ws.solution.tau_control);
  same(s["nu"], ws.solution.nu);
  same(s["friction"]["mu"], ws.friction.mu);
  CHECK(s["gauss"].get<double>() == Approx(ws.solution.gauss).margin(1e-12));
  for (int j = 0; j < 7; ++j)
    CHECK(s["friction"]["state"][static_cast<std::size_t>(j)] ==
          zwang::toString(ws.friction.state[static_cast<std::size_t>(j)]));
  CHECK(s["friction"]["indeterminate"] == ws.friction.indeterminate);
  // Every result the library holds (issue #27 item 3), and what each means.
  same(s["friction"]["tau_friction"], ws.friction.tau_friction);
  std::vector<std::string> stuck;
  for (const int j : ws.friction.stuck) stuck.push_back(model.joint(j).name);  // fixed base: DOF j is joint j
  CHECK(s["friction"]["stuck"].get<std::vector<std::string>>() == stuck);
  CHECK(stuck.size() == 7);  // at rest every joint is stuck
  CHECK(s["friction"]["gauss_dual"].get<double>() == Approx(ws.friction.gauss_dual).margin(1e-12));
  CHECK(s["friction"]["converged"] == true);
  CHECK(s["friction"]["limit_impact"] == false);
  CHECK(s["friction"]["impact_joint"].is_null());
  CHECK(s["status"]["condition"].get<double>() == Approx(ws.solution.balance.condition).epsilon(1e-12));
  CHECK(s["status"]["damping"].get<double>() == ws.solution.balance.damping);
  std::vector<std::string> beyond;  // |τ_control| over the URDF's <limit effort>, recomputed here
  for (int j = 0; j < 7; ++j)
    if (std::abs(ws.solution.tau_control[j]) > model.joint(j).effort_limit) beyond.push_back(model.joint(j).name);
  CHECK(s["effort_exceeded"].get<std::vector<std::string>>() == beyond);
  CHECK(beyond.empty());  // holding still is within the Panda's limits; "A joint driven into its limit" fills the list
  // friction within its bounds
  for (int j = 0; j < 7; ++j)
    CHECK(std::abs(s["friction"]["mu"][static_cast<std::size_t>(j)].get<double>()) <=
          model.joint(j).breakaway_friction + 1e-12);
}

TEST_CASE("No friction section: the plain solver, no friction key", "[golden]") {
  const Json s = solve(problem("arm_plain.json"));
  CHECK_FALSE(s.contains("friction"));
  CHECK(s["qdd"][0].get<double>() == Approx(-11.0 / 2.25).margin(1e-12));
  // the keys, in the documented order
  std::vector<std::string> keys;
  for (const auto& item : s.items()) keys.push_back(item.key());
  CHECK(keys == std::vector<std::string>{"joints", "dofs", "qdd", "tau_constraint", "tau_control", "nu", "gauss",
                                         "effort_exceeded", "status", "frames", "com"});
  CHECK(s["dofs"] == s["joints"]);  // one-DOF joints: a DOF is named as its joint
  // friction disabled explicitly: the same
  const Json d = solve(problem("arm_friction_disabled.json"));
  CHECK_FALSE(d.contains("friction"));
  CHECK(d["qdd"][0].get<double>() == Approx(-11.0 / 2.25).margin(1e-12));
}

TEST_CASE("forward-dynamics: the unconstrained solve of the same problem; constraints and friction refused",
          "[golden]") {
  // Without constraints or friction the problem's solve is forward dynamics: the same output, key for key.
  for (const char* name : {"arm_plain.json", "solo_fall.json"}) {
    INFO(name);
    const Run r = run({"forward-dynamics", problem(name)});
    INFO("stderr: " << r.err);
    REQUIRE(r.exit_code == 0);
    CHECK(parse(r.out) == solve(problem(name)));
  }
  CHECK(parse(run({"forward-dynamics", problem("arm_plain.json")}).out)["qdd"][0].get<double>() ==
        Approx(-11.0 / 2.25).margin(1e-12));
  const Run constrained = run({"forward-dynamics", problem("solo_feet.json")});
  checkOneLineError(constrained, 1);
  CHECK(contains(constrained.err,
                 "solo_feet.json: forward-dynamics: forwardDynamics: the task has 12 constraint "
                 "rows; forwardDynamics is the unconstrained solve (gravity and wrenches only): use "
                 "solveHybridDynamics to meet them"));
  const Run friction = run({"forward-dynamics", problem("arm_stick.json")});
  checkOneLineError(friction, 1);
  CHECK(contains(friction.err,
                 "arm_stick.json: forward-dynamics: the problem has a \"friction\" section; forward "
                 "dynamics takes none (zwang solve uses it)"));
}

TEST_CASE("Overrides: rotor_inertia and breakaway replace the model's values", "[golden]") {
  // I = 2.25 + 0.75 = 3, f = 2: the -5 N·m load slips, qdd = (-5 + 2) / 3 = -1
  const Json s = solve(problem("arm_overrides.json"));
  CHECK(s["friction"]["mu"][0].get<double>() == Approx(-2.0).margin(1e-12));
  CHECK(s["qdd"][0].get<double>() == Approx(-1.0).margin(1e-12));
  CHECK(s["friction"]["state"][0] == "slip-");
}

TEST_CASE("Feed-forward torque, velocities, gravity, local wrench, world constraint", "[golden]") {
  // A problem using every key; compared with the C++ API on the same inputs.
  const Json s = solve(problem("panda_everything.json"));
  const Json p = parse(cli_test::readText(problem("panda_everything.json")));
  const zwang::Model model = zwang::loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/panda.urdf");
  zwang::Task task(model);
  task.gravity = Eigen::Vector3d(numbers(p["gravity"]).data());
  const Json& c = p["constraints"][0];
  zwang::ConstraintMatrix A(6, static_cast<Eigen::Index>(c["directions"].size()));
  for (std::size_t k = 0; k < c["directions"].size(); ++k)
    A.col(static_cast<Eigen::Index>(k)) =
        Eigen::Map<const Eigen::Matrix<double, 6, 1>>(numbers(c["directions"][k]).data());
  const int row = task.addConstraint(c["frame"].get<std::string>(), A, zwang::Expressed::World);
  const std::vector<double> acc = numbers(c["acceleration"]);
  for (std::size_t k = 0; k < acc.size(); ++k) task.targets()[row + static_cast<int>(k)] = acc[k];
  const Json& w = p["wrenches"][0];
  const int wi = task.addWrench(w["frame"].get<std::string>(), zwang::Expressed::Local);
  const std::vector<double> force = numbers(w["force"]), torque = numbers(w["torque"]);
  task.wrench(wi) << force[0], force[1], force[2], torque[0], torque[1], torque[2];
  zwang::ModelBuilder builder(model);
  const std::vector<double> rotor = numbers(p["rotor_inertia"]);
  for (int j = 0; j < 7; ++j) builder.setRotorInertia(model.joint(j).name, rotor[static_cast<std::size_t>(j)]);
  const zwang::Model m2 = builder.build();
  zwang::Task task2(m2);
  task2.gravity = task.gravity;
  task2.addConstraint(c["frame"].get<std::string>(), A, zwang::Expressed::World);
  task2.targets() = task.targets();
  task2.wrench(task2.addWrench(w["frame"].get<std::string>(), zwang::Expressed::Local)) = task.wrench(wi);
  zwang::Workspace ws(m2, task2);
  const std::vector<double> q = numbers(p["q"]), qd = numbers(p["qd"]), tau = numbers(p["tau"]);
  zwang::FrictionOptions options;
  options.velocity_tolerance = p["friction"]["velocity_tolerance"].get<double>();
  options.margin = p["friction"]["margin"].get<double>();
  options.joint_limits = p["friction"]["limits"].get<bool>();
  options.breakaway = Eigen::Map<const Eigen::VectorXd>(numbers(p["breakaway"]).data(), 7);
  REQUIRE(zwang::solveWithFriction(m2, ws, Eigen::Map<const Eigen::VectorXd>(q.data(), 7),
                                   Eigen::Map<const Eigen::VectorXd>(qd.data(), 7),
                                   Eigen::Map<const Eigen::VectorXd>(tau.data(), 7), task2, options)
              .ok());
  for (int j = 0; j < 7; ++j) {
    const auto k = static_cast<std::size_t>(j);
    CHECK(s["qdd"][k].get<double>() == Approx(ws.solution.qdd[j]).margin(1e-12));
    CHECK(s["tau_control"][k].get<double>() == Approx(ws.solution.tau_control[j]).margin(1e-12));
    CHECK(s["friction"]["mu"][k].get<double>() == Approx(ws.friction.mu[j]).margin(1e-12));
    CHECK(s["friction"]["state"][k] == zwang::toString(ws.friction.state[k]));
  }
  // moving joints are reported as such (qd above the tolerance)
  CHECK(s["friction"]["state"][0] == "moving");
  // frames: the constrained one first, then the loaded one
  std::vector<std::string> frames;
  for (const auto& item : s["frames"].items()) frames.push_back(item.key());
  CHECK(frames == std::vector<std::string>{"tool0", "panda_link5"});
  zwang::Vec6 a;
  REQUIRE(zwang::frameAcceleration(m2, ws, Eigen::Map<const Eigen::VectorXd>(q.data(), 7),
                                   Eigen::Map<const Eigen::VectorXd>(qd.data(), 7), m2.frameIndex("panda_link5"),
                                   zwang::Expressed::World, a));
  for (int k = 0; k < 6; ++k)
    CHECK(s["frames"]["panda_link5"]["acceleration_world"][static_cast<std::size_t>(k)].get<double>() ==
          Approx(a[k]).margin(1e-12));
}

namespace {

// A constraint of a problem file as the C++ API takes it: A (6 × directions).
zwang::ConstraintMatrix directionsOf(const Json& c) {
  zwang::ConstraintMatrix A(6, static_cast<Eigen::Index>(c["directions"].size()));
  for (std::size_t k = 0; k < c["directions"].size(); ++k)
    A.col(static_cast<Eigen::Index>(k)) =
        Eigen::Map<const Eigen::Matrix<double, 6, 1>>(numbers(c["directions"][k]).data());
  return A;
}

Eigen::VectorXd vectorOf(const Json& j) {
  const std::vector<double> v = numbers(j);
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}

// A problem file (with its // comments) as JSON.
Json problemFile(const std::string& name) {
  return Json::parse(cli_test::readText(problem(name)), nullptr, true, true);
}

int occurrences(const std::string& text, const std::string& part) {
  int n = 0;
  for (std::size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++n;
  return n;
}

void sameAs(const Json& j, const Eigen::VectorXd& v) {
  REQUIRE(j.size() == static_cast<std::size_t>(v.size()));
  for (Eigen::Index k = 0; k < v.size(); ++k) CHECK(j[static_cast<std::size_t>(k)].get<double>() == v[k]);
}

}  // namespace

TEST_CASE("A tree: per-joint arrays in the model's order; the tool and the library agree", "[golden]") {
  const Json s = solve(problem("tree_two_arms.json"));
  CHECK(s["joints"] == Json::array({"waist", "left_shoulder", "left_elbow", "right_shoulder", "right_elbow"}));
  CHECK(s["friction"]["state"][2] == "moving");  // left_elbow, qd = 0.2
  CHECK(s["status"]["consistent"] == true);
  CHECK(std::abs(s["frames"]["right_hand"]["acceleration_world"][2].get<double>()) < 1e-12);

  const Json p = problemFile("tree_two_arms.json");
  const zwang::Model model = zwang::loadUrdfFile(problem("two_arms.urdf"));
  zwang::Task task(model);
  task.addConstraint("right_hand", directionsOf(p["constraints"][0]), zwang::Expressed::World);
  task.wrench(task.addWrench("left_hand", zwang::Expressed::World)) << 0, 0, -20, 0, 0, 0;
  zwang::Workspace ws(model, task);
  REQUIRE(zwang::solveWithFriction(model, ws, vectorOf(p["q"]), vectorOf(p["qd"]), Eigen::VectorXd::Zero(5), task));
  sameAs(s["qdd"], ws.solution.qdd);  // the tool prints every double exactly: equal, bit for bit
  sameAs(s["tau_control"], ws.solution.tau_control);
  sameAs(s["nu"], ws.solution.nu);
  sameAs(s["friction"]["mu"], ws.friction.mu);
}

TEST_CASE("A relative constraint (\"relative_to\"): the tool and Task::addRelativeConstraint agree", "[golden]") {
  const Json s = solve(problem("relative_hands.json"));
  CHECK(s["status"]["rank"] == 3);
  CHECK(s["status"]["consistent"] == true);
  std::vector<std::string> frames;  // the constrained frame, then the one it is relative to
  for (const auto& item : s["frames"].items()) frames.push_back(item.key());
  CHECK(frames == std::vector<std::string>{"left_hand", "right_hand"});

  const Json p = problemFile("relative_hands.json");
  const zwang::Model model = zwang::loadUrdfFile(problem("two_arms.urdf"));
  zwang::Task task(model);
  task.addRelativeConstraint("left_hand", "right_hand", directionsOf(p["constraints"][0]));  // Expressed::Reference
  zwang::Workspace ws(model, task);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(5);
  REQUIRE(zwang::solveHybridDynamics(model, ws, vectorOf(p["q"]), zero, zero, task));
  sameAs(s["qdd"], ws.solution.qdd);
  sameAs(s["tau_constraint"], ws.solution.tau_constraint);
  sameAs(s["nu"], ws.solution.nu);
  CHECK(ws.solution.balance.residual < 1e-12);

  // Baxter holding a box between its grippers: the whole tree, the mimic
  // fingers locked ("lock_mimic"); at rest the grippers turn together.
  const Run r = run({"solve", problem("baxter_hold_box.json")});
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(occurrences(r.err, "zwang: warning: ") == 6);  // 4 placeholder/point-mass, 2 mimic_locked
  CHECK(occurrences(r.err, "locked at q = 0 (\"lock_mimic\": true)") == 2);
  const Json b = parse(r.out);
  CHECK(b["joints"].size() == 17);
  CHECK(b["status"]["rank"] == 6);
  CHECK(b["status"]["consistent"] == true);
  const std::vector<double> left = numbers(b["frames"]["left_gripper"]["acceleration_world"]),
                            right = numbers(b["frames"]["right_gripper"]["acceleration_world"]);
  for (std::size_t k = 3; k < 6; ++k) CHECK(left[k] == Approx(right[k]).margin(1e-12));
}

TEST_CASE("Mimic joints from the tool: \"follow_leaders\" fills the followers' q and qd (Baxter)", "[golden]") {
  // Baxter's whole tree with its mimic fingers modelled: each r_finger joint
  // follows its l_finger joint with multiplier -1 (the URDF's <mimic>). The
  // problem gives the followers 0; "follow_leaders" replaces that by the law.
  const Run r = run({"solve", problem("baxter_follow_leaders.json")});
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(occurrences(r.err, "zwang: warning: ") == 4);  // the URDF's placeholder and point-mass data
  const Json s = parse(r.out);
  REQUIRE(s["joints"].size() == 19);
  CHECK(s["joints"][9] == "l_gripper_r_finger_joint");
  CHECK(s["joints"][18] == "r_gripper_r_finger_joint");
  CHECK(s["status"]["consistent"] == true);

  // The library, the followers set by hand from the URDF's law q_f = -1·q_l.
  const Json p = problemFile("baxter_follow_leaders.json");
  const zwang::Model model = zwang::loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/baxter.urdf");
  REQUIRE(model.mimicJoints() == std::vector<int>{9, 18});
  Eigen::VectorXd q = vectorOf(p["q"]), qd = vectorOf(p["qd"]);
  for (const int follower : {9, 18}) {
    q[follower] = -q[follower - 1];
    qd[follower] = -qd[follower - 1];
  }
  CHECK(q[9] == -0.01);
  CHECK(qd[18] == -0.02);
  zwang::Task task(model);
  task.addRelativeConstraint("left_gripper", "right_gripper", directionsOf(p["constraints"][0]));
  task.wrench(task.addWrench("right_gripper", zwang::Expressed::World)) << 0, 0, -30, 0, 0, 0;
  zwang::Workspace ws(model, task);
  REQUIRE(zwang::solveHybridDynamics(model, ws, q, qd, Eigen::VectorXd::Zero(19), task));
  sameAs(s["qdd"], ws.solution.qdd);  // the tool prints every double exactly: equal, bit for bit
  sameAs(s["tau_control"], ws.solution.tau_control);
  for (const std::size_t follower : {9u, 18u})
    CHECK(s["qdd"][follower].get<double>() == Approx(-s["qdd"][follower - 1].get<double>()).margin(1e-12));

  // Without the option the followers' 0 is off the law: exit 1, naming the option.
  const std::string dir = cli_test::scratchDir();
  Json without = p;
  without["model"] = std::string(ZWANG_MODELS_DIR) + "/baxter.urdf";
  without.erase("follow_leaders");
  cli_test::writeText(dir + "/baxter_without.json", without.dump());
  const Run off = run({"solve", dir + "/baxter_without.json"});
  INFO("stderr: " << off.err);
  CHECK(off.exit_code == 1);
  CHECK(off.out.empty());
  CHECK(contains(off.err,
                 ": solve: joint 'l_gripper_r_finger_joint' mimics 'l_gripper_l_finger_joint' (q = "
                 "-1·q_leader + 0): q is 0, the law gives -0.01"));
  CHECK(contains(off.err, "(set by Model::followLeaders, Python follow_leaders, CLI \"follow_leaders\": true)"));

  // With the mimic joints welded there is nothing to follow: refused.
  Json locked = without;
  locked["lock_mimic"] = true;
  locked["follow_leaders"] = true;
  cli_test::writeText(dir + "/baxter_locked.json", locked.dump());
  const Run refused = run({"solve", dir + "/baxter_locked.json"});
  checkOneLineError(refused, 1);
  CHECK(contains(refused.err,
                 ": follow_leaders: has no effect: the model has no mimic joints (\"lock_mimic\": "
                 "true welded them)"));
}

TEST_CASE("Baxter with its mimic fingers modelled: status.rows and rank count the task's rows, not the mimic rows",
          "[golden]") {
  // Both grippers held in world axes: 12 rows, each gripper's 6 on its own
  // 7-joint arm at a pose away from its singularities (test_mimic computes the
  // stacked Jacobian's rank there: 12); the mimic fingers are beyond the frames.
  // Baxter's four placeholder or point-mass links warn (as for baxter_hold_box.json), nothing else.
  const auto solveBaxter = [](const std::string& file) {
    const Run r = run({"solve", problem(file)});
    INFO("stderr: " << r.err);
    REQUIRE(r.exit_code == 0);
    CHECK(occurrences(r.err, "zwang: warning: ") == 4);
    return parse(r.out);
  };
  const Json g = solveBaxter("baxter_mimic_grippers.json");
  CHECK(g["joints"].size() == 19);
  CHECK(g["nu"].size() == 12);
  CHECK(g["status"]["rows"] == 12);
  CHECK(g["status"]["rank"] == 12);
  CHECK(g["status"]["nu_unique"] == true);
  CHECK(g["status"]["consistent"] == true);
  // A joint row on each finger of one gripper: one degree of freedom of the
  // coupled gripper, so rank 1 of 2; asked q̈ = 1 and −1 (the law, a = −1),
  // both are met and only the split of the torque between them is open.
  const Json f = solveBaxter("baxter_mimic_fingers.json");
  CHECK(f["status"]["rows"] == 2);
  CHECK(f["status"]["rank"] == 1);
  CHECK(f["status"]["singular"] == true);
  CHECK(f["status"]["nu_unique"] == false);
  CHECK(f["status"]["consistent"] == true);
  CHECK(numbers(f["qdd"])[8] == Approx(1.0).epsilon(1e-9));
  CHECK(numbers(f["qdd"])[9] == Approx(-1.0).epsilon(1e-9));
}

// ---------------------------------------------------------------------------
// Floating bases: "base" (docs/cli.md, "Floating base").

namespace {

// The library's answer to a problem file with a floating base: q, qd and tau
// with the base's coordinates first, as the C++ API takes them.
struct Floating {
  zwang::Model model;
  Eigen::VectorXd q, qd, tau;
};

Floating floatingProblem(const Json& p, const zwang::Model& model) {
  Floating f{model, {}, {}, {}};
  const Json& b = p["base"];
  const int n = model.dof();
  const Eigen::VectorXd joints_q = p.contains("q") ? vectorOf(p["q"]) : Eigen::VectorXd::Zero(n);
  if (model.baseType() == zwang::BaseType::Free) {
    f.q.resize(7 + n);
    f.q << vectorOf(b["position"]), vectorOf(b.value("orientation", Json::array({1, 0, 0, 0}))), joints_q;
    f.qd.resize(6 + n);
    f.qd << vectorOf(b.value("linear_velocity", Json::array({0, 0, 0}))),
        vectorOf(b.value("angular_velocity", Json::array({0, 0, 0}))), Eigen::VectorXd::Zero(n);
  } else {
    f.q.resize(3 + n);
    f.q << vectorOf(b["position"]), b.value("yaw", 0.0), joints_q;
    f.qd.resize(3 + n);
    f.qd << vectorOf(b.value("velocity", Json::array({0, 0, 0}))), Eigen::VectorXd::Zero(n);
  }
  f.tau = Eigen::VectorXd::Zero(model.nv());
  return f;
}

}  // namespace

TEST_CASE("A free base (solo12, \"base\" type free): it falls at g; the feet held: the tool and the library agree",
          "[golden]") {
  const Json fall = solve(problem("solo_fall.json"));
  CHECK(fall["joints"].size() == 12);
  CHECK(fall["qdd"].size() == 12);  // per joint: the base's entries are under "base"
  CHECK(fall["base"]["type"] == "free");
  const std::vector<double> g{0, 0, -9.81, 0, 0, 0};
  for (std::size_t k = 0; k < 6; ++k) {
    CHECK(fall["base"]["acceleration_world"][k].get<double>() == Approx(g[k]).margin(1e-12));
    CHECK(fall["base"]["acceleration"][k].get<double>() == Approx(g[k]).margin(1e-12));  // level, at rest
  }
  for (const Json& x : fall["qdd"]) CHECK(std::abs(x.get<double>()) < 1e-12);
  // Nothing holds it: its centre of mass falls at g from rest (com, world axes, classical acceleration).
  for (std::size_t k = 0; k < 3; ++k) {
    CHECK(fall["com"]["acceleration"][k].get<double>() == Approx(g[k]).margin(1e-12));
    CHECK(fall["com"]["velocity"][k].get<double>() == 0.0);
  }
  CHECK(fall["com"]["position"][2].get<double>() > 0.0);  // above the ground, legs under it: below the base at 0.3
  CHECK(fall["com"]["position"][2].get<double>() < 0.3);

  const Json s = solve(problem("solo_feet.json"));
  CHECK(s["status"]["rank"] == 12);
  CHECK(s["status"]["consistent"] == true);
  for (const char* foot : {"FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"})
    for (std::size_t k = 0; k < 3; ++k)
      CHECK(std::abs(s["frames"][foot]["acceleration_world"][k].get<double>()) < 1e-12);
  const Json p = problemFile("solo_feet.json");
  zwang::UrdfOptions options;
  options.base = zwang::BaseType::Free;
  const Floating f = floatingProblem(p, zwang::loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/solo12.urdf", options));
  zwang::Task task(f.model);
  for (const Json& c : p["constraints"])
    task.addConstraint(c["frame"].get<std::string>(), directionsOf(c), zwang::Expressed::World);
  zwang::Workspace ws(f.model, task);
  REQUIRE(zwang::solveHybridDynamics(f.model, ws, f.q, f.qd, f.tau, task));
  sameAs(s["qdd"], ws.solution.qdd.tail(12));  // bit for bit
  sameAs(s["base"]["acceleration"], ws.solution.qdd.head(6));
  sameAs(s["base"]["acceleration_world"], ws.solution.base_acceleration_world);
  sameAs(s["base"]["tau_constraint"], ws.solution.tau_constraint.head(6));
  sameAs(s["tau_control"], ws.solution.tau_control.tail(12));
  sameAs(s["nu"], ws.solution.nu);
  zwang::Vec3 c, cd, cdd;
  REQUIRE(zwang::centerOfMass(f.model, ws, f.q, zwang::kWholeRobot, c));
  REQUIRE(zwang::centerOfMassVelocity(f.model, ws, f.q, f.qd, zwang::kWholeRobot, cd));
  REQUIRE(zwang::centerOfMassAcceleration(f.model, ws, f.q, f.qd, zwang::kWholeRobot, cdd));
  sameAs(s["com"]["position"], c);
  sameAs(s["com"]["velocity"], cd);
  sameAs(s["com"]["acceleration"], cdd);
}

TEST_CASE(
    "Solo 12 standing on four contacts, every joint held by a joint row, with friction: the tool and the "
    "library agree; the base needs no force",
    "[golden]") {
  const Json s = solve(problem("solo_stand.json"));
  // 24 rows on nv = 18, dependent and consistent: the ground's split between
  // the four feet is open (ν not unique), every row is met.
  CHECK(s["status"]["rows"] == 24);
  CHECK(s["status"]["rank"] == 18);
  CHECK(s["status"]["nu_unique"] == false);
  CHECK(s["status"]["consistent"] == true);
  CHECK(s["nu"].size() == 24);
  for (const Json& x : s["base"]["tau_control"]) CHECK(std::abs(x.get<double>()) < 1e-9);  // the ground holds it
  const Json p = problemFile("solo_stand.json");
  zwang::UrdfOptions options;
  options.base = zwang::BaseType::Free;
  const Floating f = floatingProblem(p, zwang::loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/solo12.urdf", options));
  zwang::Task task(f.model);
  for (const Json& c : p["constraints"]) {
    if (c.contains("joint"))
      task.addJointConstraint(c["joint"].get<std::string>());
    else
      task.addContact(c["frame"].get<std::string>(), directionsOf(c), zwang::Expressed::World);
  }
  zwang::Workspace ws(f.model, task);
  zwang::FrictionOptions friction;
  friction.breakaway = vectorOf(p["breakaway"]);
  REQUIRE(zwang::solveWithFriction(f.model, ws, f.q, f.qd, f.tau, task, friction));
  sameAs(s["qdd"], ws.solution.qdd.tail(12));  // bit for bit
  sameAs(s["base"]["acceleration"], ws.solution.qdd.head(6));
  sameAs(s["tau_control"], ws.solution.tau_control.tail(12));
  sameAs(s["base"]["tau_control"], ws.solution.tau_control.head(6));
  sameAs(s["nu"], ws.solution.nu);
  sameAs(s["friction"]["mu"], ws.friction.mu);
}

TEST_CASE("A planar root joint (planar_cart.urdf, \"base\" type planar): the tool and the library agree", "[golden]") {
  const Json s = solve(problem("planar_cart.json"));
  CHECK(s["base"]["type"] == "planar");
  CHECK(s["base"]["acceleration"].size() == 3);
  CHECK(s["base"]["acceleration_world"].size() == 6);
  CHECK(s["friction"]["state"][0] == "stick");
  CHECK(std::abs(s["frames"]["cart"]["acceleration_world"][2].get<double>()) < 1e-12);  // held at its height
  const Json p = problemFile("planar_cart.json");
  const zwang::Model model = zwang::loadUrdfFile(problem("planar_cart.urdf"));
  REQUIRE(model.baseType() == zwang::BaseType::Planar);
  const Floating f = floatingProblem(p, model);
  zwang::Task task(model);
  task.addConstraint("cart", directionsOf(p["constraints"][0]), zwang::Expressed::World);
  zwang::Workspace ws(model, task);
  REQUIRE(zwang::solveWithFriction(model, ws, f.q, f.qd, f.tau, task));
  sameAs(s["qdd"], ws.solution.qdd.tail(1));
  sameAs(s["base"]["acceleration"], ws.solution.qdd.head(3));
  sameAs(s["base"]["acceleration_world"], ws.solution.base_acceleration_world);
  sameAs(s["friction"]["mu"], ws.friction.mu);
  // The plane is the joint frame: x along the world's x, y up, the normal along −y. The world acceleration
  // is the plane's [ẍ, ÿ] along those axes, the yaw acceleration about −y.
  const std::vector<double> plane = numbers(s["base"]["acceleration"]),
                            world = numbers(s["base"]["acceleration_world"]);
  CHECK(world[0] == Approx(plane[0]).margin(1e-12));
  CHECK(world[2] == Approx(plane[1]).margin(1e-12));
  CHECK(world[4] == Approx(-plane[2]).margin(1e-12));
  // A base force pushes the cart along the rail (+x): τ_base in the plane's axes.
  Json pushed = p;
  pushed["model"] = problem("planar_cart.urdf");
  pushed["base"]["force"] = Json::array({5, 0, 0});
  const std::string file = cli_test::scratchDir() + "/planar_cart_pushed.json";
  cli_test::writeText(file, pushed.dump());
  const Json s2 = solve(file);
  CHECK(s2["base"]["tau_control"][0].get<double>() == 5.0);
  CHECK(s2["base"]["acceleration"][0].get<double>() > s["base"]["acceleration"][0].get<double>());
}

TEST_CASE("A joint driven into its limit, and torques beyond the effort limit: reported, with a warning", "[golden]") {
  // The one-DOF arm at its upper limit (pi), turning into it: friction cannot hold it, a stop would need an
  // impulse. tau = 150 N·m is beyond the URDF's effort = 100.
  Json p = parse(cli_test::readText(problem("arm_stick.json")));
  p["model"] = std::string(ZWANG_MODELS_DIR) + "/one_dof_arm.urdf";
  p["q"] = Json::array({3.141592653589793});
  p["qd"] = Json::array({0.5});
  p["tau"] = Json::array({150});
  const std::string file = cli_test::scratchDir() + "/arm_into_limit.json";
  cli_test::writeText(file, p.dump());
  const Run r = run({"solve", file});
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.err == "zwang: warning: " + file +
                     ": joint 'joint1' moves into its limit: stopping it needs an impulse, which the solve does not "
                     "model (friction.limit_impact)\n");
  const Json s = parse(r.out);
  CHECK(s["friction"]["limit_impact"] == true);
  CHECK(s["friction"]["impact_joint"] == "joint1");
  CHECK(s["friction"]["stuck"].empty());  // moving: kinetic friction only
  CHECK(s["effort_exceeded"] == Json::array({"joint1"}));
  // Moving away from the limit: no impact, no warning.
  p["qd"] = Json::array({-0.5});
  cli_test::writeText(file, p.dump());
  const Json away = solve(file);
  CHECK(away["friction"]["limit_impact"] == false);
  CHECK(away["friction"]["impact_joint"].is_null());
}

TEST_CASE("joint_modes: Fig. 5.5's motion prescribed, at rest and moving, in closed form", "[golden]") {
  // The arm of Fig. 5.5 told to accelerate at 5 rad/s² by its joint's mode instead of a row: no row, no friction
  // unknown (its motor gives all), so tau_control = I q̈ = 2.25·5; moving at 1 rad/s its motor also overcomes the
  // kinetic friction, 10 N·m.
  Json p = parse(cli_test::readText(problem("arm_fig55.json")));
  p["model"] = std::string(ZWANG_MODELS_DIR) + "/one_dof_arm.urdf";
  p.erase("constraints");
  p["joint_modes"] = {{"joint1", {{"acceleration", 5}}}};
  const std::string file = cli_test::scratchDir() + "/arm_prescribed.json";
  cli_test::writeText(file, p.dump());
  const Json s = solve(file);
  CHECK(s["qdd"][0].get<double>() == 5.0);  // copied, not solved for
  CHECK(s["tau_control"][0].get<double>() == Approx(2.25 * 5).margin(1e-12));
  CHECK(s["tau_constraint"][0].get<double>() == Approx(2.25 * 5).margin(1e-12));  // τ = 0: all of it
  CHECK(s["nu"].empty());
  CHECK(s["friction"]["state"][0] == "prescribed");
  CHECK(s["friction"]["mu"][0].get<double>() == 0.0);
  CHECK(s["friction"]["stuck"].empty());
  p["qd"] = Json::array({1.0});
  cli_test::writeText(file, p.dump());
  const Json moving = solve(file);
  CHECK(moving["tau_control"][0].get<double>() == Approx(2.25 * 5 + 10).margin(1e-12));
  CHECK(moving["friction"]["tau_friction"][0].get<double>() == Approx(-10).margin(1e-12));
  // Locked: held where it is against the 5 N at the tip of arm_stick (1 m: −5 N·m about z), by its motor alone.
  Json held = parse(cli_test::readText(problem("arm_stick.json")));
  held["model"] = std::string(ZWANG_MODELS_DIR) + "/one_dof_arm.urdf";
  held["joint_modes"] = {{"joint1", "locked"}};
  cli_test::writeText(file, held.dump());
  const Json h = solve(file);
  CHECK(h["qdd"][0].get<double>() == 0.0);
  CHECK(h["tau_control"][0].get<double>() == Approx(5.0).margin(1e-12));
  CHECK(h["friction"]["mu"][0].get<double>() == 0.0);
}

TEST_CASE("fk: every frame's pose and the centre of mass, the tool and the library agree", "[golden]") {
  const std::string urdf = std::string(ZWANG_MODELS_DIR) + "/panda.urdf";
  const Run r = run({"fk", urdf, "--q", "0.1,-0.5,0.2,-2,0.3,1.5,0.7"});
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  const Json out = parse(r.out);
  const zwang::Model model = zwang::loadUrdfFile(urdf);
  Eigen::VectorXd q(7);
  q << 0.1, -0.5, 0.2, -2, 0.3, 1.5, 0.7;
  zwang::Workspace ws(model, 0);
  REQUIRE(zwang::forwardKinematics(model, ws, q, Eigen::VectorXd::Zero(7)));
  REQUIRE(out["frames"].size() == model.frames().size());
  for (int f = 0; f < static_cast<int>(model.frames().size()); ++f) {
    Eigen::Isometry3d pose;
    REQUIRE(zwang::framePose(model, ws, q, f, pose));
    const Json& frame = out["frames"][model.frame(f).name];
    sameAs(frame["position"], pose.translation());
    // The quaternion w first: the same rotation (to rounding: converted from the matrix and back).
    const std::vector<double> wxyz = numbers(frame["quaternion"]);
    const Eigen::Quaterniond turn(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
    CHECK(std::abs(turn.norm() - 1.0) < 1e-15);
    CHECK((turn.toRotationMatrix() - pose.linear()).cwiseAbs().maxCoeff() < 1e-15);
  }
  zwang::Vec3 c;
  double mass = 0.0;
  REQUIRE(zwang::centerOfMass(model, ws, q, zwang::kWholeRobot, c));
  REQUIRE(zwang::subtreeMass(model, zwang::kWholeRobot, mass));
  sameAs(out["com"]["position"], c);
  CHECK(out["com"]["mass"].get<double>() == mass);
  sameAs(out["com"]["velocity"], Eigen::Vector3d::Zero());
  sameAs(out["q"], q);

  // A problem file gives the state: solo_fall's com is the one solve prints.
  const Run fall = run({"fk", problem("solo_fall.json")});
  REQUIRE(fall.exit_code == 0);
  const Json solved = solve(problem("solo_fall.json"));
  CHECK(parse(fall.out)["com"]["position"] == solved["com"]["position"]);
  CHECK(parse(fall.out)["frames"].contains("FL_FOOT"));

  // Without --q: the neutral configuration (zeros for the Panda's joints, within its limits).
  const Run neutral = run({"fk", urdf});
  REQUIRE(neutral.exit_code == 0);
  CHECK(parse(neutral.out)["q"].size() == 7);

  checkOneLineError(run({"fk", urdf, "--q", "1,2"}), 1);  // nq = 7
  const Run wrong = run({"fk", urdf, "--q", "1,2"});
  CHECK(contains(wrong.err, "--q: q has 2 entries"));
  CHECK(run({"fk", urdf, "--q", "1,x"}).exit_code == 2);
  CHECK(run({"fk", problem("solo_fall.json"), "--q", "1"}).exit_code == 2);
}

TEST_CASE("--pretty and -o give the same numbers", "[golden]") {
  const Json compact = solve(problem("panda_hold.json"));
  const Json pretty = solve(problem("panda_hold.json"), {"--pretty"});
  CHECK(compact == pretty);
  const std::string out = cli_test::scratchDir() + "/solution.json";
  const Run r = run({"solve", problem("panda_hold.json"), "-o", out});
  CHECK(r.exit_code == 0);
  CHECK(r.out.empty());
  CHECK(parse(cli_test::readText(out)) == compact);
}

TEST_CASE("An infeasible task: the solution with status.infeasible, exit code 3", "[golden]") {
  const Run r = run({"solve", problem("arm_infeasible.json")});
  CHECK(r.exit_code == 3);
  const Json s = parse(r.out);
  CHECK(s["status"]["infeasible"] == true);
  CHECK(contains(r.err, "arm_infeasible.json"));
  CHECK(contains(r.err, "infeasible"));
  CHECK(contains(r.err, "joint1"));
  CHECK(contains(r.err, "upper limit"));
}

TEST_CASE("A task the arm cannot meet: least squares, status.residual and consistent, a warning", "[golden]") {
  // The 1-DOF arm at rest, its tip asked for 2 m/s² along the link (no joint
  // can give that) and 0.5 m/s² across it: the across row is met (q̈ = 0.5),
  // the along row is the least-squares residual, no force pushes along it.
  const Run r = run({"solve", problem("arm_unreachable.json")});
  INFO("stderr: " << r.err);
  CHECK(r.exit_code == 0);
  CHECK(contains(r.err, "zwang: warning: "));
  CHECK(contains(r.err, "arm_unreachable.json: the task is not met"));
  const Json s = parse(r.out);
  CHECK(numbers(s["qdd"])[0] == Approx(0.5).epsilon(1e-12));
  CHECK(std::abs(numbers(s["nu"])[0]) < 1e-12);
  CHECK(s["status"]["singular"] == true);
  CHECK(s["status"]["rows"] == 2);
  CHECK(s["status"]["rank"] == 1);
  CHECK(s["status"]["nu_unique"] == false);  // the rank lost leaves a row unmet, unlike a standing robot's split
  CHECK(s["status"]["consistent"] == false);
  CHECK(s["status"]["residual"].get<double>() == Approx(2.0).epsilon(1e-12));
  // The regular golden problems report a met task.
  const Json hold = solve(problem("panda_hold.json"));
  CHECK(hold["status"]["consistent"] == true);
  CHECK(hold["status"]["nu_unique"] == true);  // 6 independent rows on 7 joints
  CHECK(hold["status"]["residual"].get<double>() < 1e-12);
}

// ---------------------------------------------------------------------------
// Every error path: exit code and a one-line message naming file, path and what.

TEST_CASE("Errors in the problem file", "[errors]") {
  struct Case {
    const char* file;
    std::vector<std::string> parts;  // what the message must contain (besides the file name)
  };
  const std::vector<Case> cases = {
      {"err_malformed.json", {"line 3, column 1", "syntax error"}},
      {"err_not_object.json", {"must be a JSON object", "array"}},
      {"err_unknown_key.json", {": gravtiy: unknown key", "gravity"}},
      {"err_unknown_key_nested.json", {": constraints[1].acceleraton: unknown key", "acceleration"}},
      {"err_wrong_type.json", {": constraints[0].directions[0][5]: expected a number", "string"}},
      {"err_wrong_type_q.json", {": q: expected an array", "a number"}},
      {"err_wrong_type_enabled.json", {": friction.enabled: expected true or false", "string"}},
      {"err_direction_length.json", {": constraints[1].directions[2]: has 5 entries, expected 6"}},
      {"err_acceleration_length.json",
       {": constraints[0].acceleration: has 2 entries, expected 1", "one per direction"}},
      {"err_q_length.json", {": q: has 2 entries, expected 1", "joint1"}},
      {"err_nonfinite.json", {": wrenches[0].force[1]: ", "1e400", "out of range"}},
      {"err_huge.json", {": gravity[2]: ", "-1e+300", "too large"}},
      {"err_unknown_frame.json",
       {": wrenches[1].frame: model 'one_dof_arm' has no frame 'hand' (frames: 'base', 'link1', 'tip')\n"}},
      {"err_expressed_in.json", {": constraints[0].expressed_in: unknown value \"global\"", "aligned"}},
      {"err_wrench_aligned.json", {": wrenches[0].expressed_in: unknown value \"aligned\"", "\"local\" or \"world\""}},
      {"err_missing_model.json", {": model: ", "no_such_robot.urdf", "cannot open"}},
      {"err_no_model.json", {": model: missing"}},
      {"err_duplicate_key.json", {": q: duplicate key"}},
      {"err_breakaway_without_friction.json", {": breakaway: has no effect", "friction"}},
      {"err_margin.json", {": friction.margin: must be between 0 and 1"}},
      {"err_negative_rotor.json", {": rotor_inertia[0]: must be finite and >= 0, got -1"}},
      {"err_missing_frame_key.json", {": constraints[0]: missing key \"frame\""}},
      {"err_no_directions.json", {": constraints[0].directions: needs at least one direction"}},
      {"err_bad_tip.json", {": model: ", "nowhere"}},
      {"err_balance_threshold.json", {": balance.singular_threshold: must be between 0 and 1"}},
      {"err_balance_rank.json", {": balance.rank_tolerance: must be >= 0 and below singular_threshold (0.0001)"}},
      {"err_balance_key.json", {": balance.max_damping: unknown key"}},
      {"err_relative_unknown.json",
       {": constraints[0].relative_to: model 'two_arms' has no frame 'box' (frames: 'world', 'torso', 'chest',"}},
      {"err_relative_self.json",
       {": constraints[0].relative_to: is the constrained frame itself (\"left_hand\")", "another frame"}},
      {"err_reference_absolute.json",
       {": constraints[0].expressed_in: unknown value \"reference\"", "for a constraint with \"relative_to\""}},
      {"err_unknown_root.json", {": model: ", "root link 'shoulders' not found (links: 'chest',", "'world'"}},
      {"err_base_missing.json",
       {": base: missing: the URDF's root joint gives the robot a planar base", "\"base\": {\"type\": \"planar\""}},
      {"err_base_mismatch.json",
       {": model: ",
        "planar_cart.urdf: the URDF has a planar root joint 'rail' (from 'world' to 'cart'), a planar base, "
        "not the free base that base.type asks for"}},
      {"err_base_type.json", {": base.type: unknown value \"fixed\"", "a fixed base needs no \"base\" section"}},
      {"err_base_key.json", {": base.yaw: unknown key (allowed here: type, position, orientation,"}},
      {"err_base_quaternion.json",
       {": base.orientation: has norm 0.9999904099540154, not 1 within 1e-06",
        "[0.7071067811865476, 0, 0, 0.7071067811865476]"}},
      {"err_base_length.json", {": base.velocity: has 6 entries, expected 3"}},
      {"err_base_q_length.json",
       {": q: has 4 entries, expected 1 (one per moving joint: hinge); the base's state goes in \"base\""}},
      {"err_joint_unknown.json", {": constraints[0].joint: unknown joint \"elbow\" (the model's joints: joint1)"}},
      {"err_joint_row_key.json", {": constraints[0].directions: unknown key (allowed here: joint, acceleration)"}},
      {"err_contact_relative.json",
       {": constraints[0].contact: is true with \"relative_to\"", "a contact is a link against the environment"}},
      {"err_follow_leaders_no_mimic.json", {": follow_leaders: has no effect: the model has no mimic joints"}},
      {"err_q_joint_size.json",
       {": q.float: has 3 entries, expected 7 numbers: x, y, z, qw, qx, qy, qz (joint 'float' is free)"}},
      {"err_q_multi_length.json",
       {": q: has 4 entries, expected 12 (the joints' coordinates in order: j1, float free [x, y, z, qw, qx, qy, qz], "
        "j2, slide planar [x, y, yaw])"}},
      {"err_q_root_joint.json",
       {": q.root_joint: names the root joint of the planar base: its state goes in \"base\""}},
      {"err_qd_unknown_joint.json", {": qd.elbow: unknown joint \"elbow\" (the model's joints: j1, float, j2, slide)"}},
      {"err_joint_row_dofs.json",
       {": constraints[0].acceleration: has 1 entry, expected 6 (one per DOF of joint 'float': float.vx, float.vy, "
        "float.vz, float.wx, float.wy, float.wz)"}},
  };
  for (const Case& c : cases) {
    SECTION(c.file) {
      const Run r = run({"solve", problem(c.file)});
      checkOneLineError(r, 1);
      CHECK(contains(r.err, "zwang: " + problem(c.file) + ": "));
      for (const std::string& part : c.parts) {
        INFO("stderr: " << r.err << "expected part: " << part);
        CHECK(contains(r.err, part));
      }
    }
  }
}

// The table test/problem/bad_inputs.json, also read by the problem layer's test and the Python
// module's: each row's input as a problem file, its message the layer's words.
TEST_CASE("Errors in the problem file: the problem layer's shared table", "[errors]") {
  const Json table = Json::parse(cli_test::readText(ZWANG_PROBLEM_TABLE));
  REQUIRE(table["rows"].size() >= 10);
  const auto sameQuotes = [](std::string text) {  // JSON quotes with ", Python with '
    for (char& c : text)
      if (c == '"') c = '\'';
    return text;
  };
  for (const Json& row : table["rows"]) {
    SECTION(row["name"].get<std::string>()) {
      Json p = {{"model", ZWANG_MODELS_DIR "/panda.urdf"}, {"root", "panda_link0"}, {"tip", "tool0"}};
      if (row.contains("constraint")) p["constraints"] = Json::array({row["constraint"]});
      if (row.contains("wrench")) p["wrenches"] = Json::array({row["wrench"]});
      for (const char* key : {"balance", "friction", "rotor_inertia", "breakaway", "joint_modes"})
        if (row.contains(key)) p[key] = row[key];
      if (row.contains("breakaway") && !p.contains("friction")) p["friction"] = Json::object();  // else refused
      const std::string file = cli_test::scratchDir() + "/shared_table.json";
      cli_test::writeText(file, p.dump());
      const Run r = run({"solve", file});
      checkOneLineError(r, 1);
      INFO("stderr: " << r.err);
      CHECK(contains(sameQuotes(r.err), sameQuotes(row["expect"].get<std::string>())));
    }
  }
}

TEST_CASE("Errors outside the problem's content", "[errors]") {
  SECTION("a missing problem file") {
    const Run r = run({"solve", cli_test::scratchDir() + "/no_such_problem.json"});
    checkOneLineError(r, 1);
    CHECK(contains(r.err, "no_such_problem.json: cannot read the file (No such file or directory)"));
  }
  SECTION("a directory") {
    const Run r = run({"solve", kProblems});
    checkOneLineError(r, 1);
    CHECK(contains(r.err, "it is a directory"));
  }
  SECTION("an empty file") {
    const std::string file = cli_test::scratchDir() + "/empty.json";
    cli_test::writeText(file, "");
    const Run r = run({"solve", file});
    checkOneLineError(r, 1);
    CHECK(contains(r.err, file + ": line 1, column 1: syntax error while parsing value - unexpected end of input"));
  }
  SECTION("an output file that cannot be written") {
    const Run r = run({"solve", problem("arm_slip.json"), "-o", cli_test::scratchDir() + "/no/such/dir/out.json"});
    CHECK(r.exit_code == 1);
    CHECK(contains(r.err, "out.json: cannot write the file"));
  }
  SECTION("info: a missing URDF") {
    const Run r = run({"info", cli_test::scratchDir() + "/no_such_robot.urdf"});
    checkOneLineError(r, 1);
    CHECK(contains(r.err, "no_such_robot.urdf: cannot open the file"));
  }
  SECTION("info: an unknown tip link") {
    const Run r = run({"info", std::string(ZWANG_MODELS_DIR) + "/panda.urdf", "--tip", "nowhere"});
    checkOneLineError(r, 1);
    CHECK(contains(r.err, "nowhere"));
  }
  SECTION("scenarios: no model") {
    const Run r = run(
        {"scenarios", "--models", cli_test::scratchDir() + "/nothing", "--out", cli_test::scratchDir() + "/sc-none"});
    checkOneLineError(r, 1);
    CHECK(contains(r.err, "one_dof_arm.urdf"));
    CHECK(contains(r.err, "--models"));
  }
}

TEST_CASE("Messages: the model path as resolved, syntax errors at the file, the lock option by its CLI names",
          "[errors]") {
  const std::string dir = cli_test::scratchDir();
  SECTION("a missing model names the path it was resolved to, relative to the problem file") {
    const Run r = run({"solve", problem("err_missing_model.json")});
    checkOneLineError(r, 1);
    CHECK(r.err == "zwang: " + problem("err_missing_model.json") +
                       ": model: \"no_such_robot.urdf\", relative to the problem file, is " + kProblems +
                       "/no_such_robot.urdf: cannot open the file (No such file or directory)\n");
    // An absolute path is named as given.
    const std::string file = dir + "/absolute_model.json";
    cli_test::writeText(file, "{\"model\": \"" + dir + "/no_such_robot.urdf\"}");
    const Run a = run({"solve", file});
    checkOneLineError(a, 1);
    CHECK(a.err == "zwang: " + file + ": model: " + dir +
                       "/no_such_robot.urdf: cannot open the file (No such file or directory)\n");
  }
  SECTION("a syntax error after the model's value is the file's, not \"model\"'s") {
    const std::string file = dir + "/syntax_after_model.json";
    cli_test::writeText(file, "{\"model\": \"arm.urdf\" \"q\": [0]}");
    const Run r = run({"solve", file});
    checkOneLineError(r, 1);
    CHECK(r.err == "zwang: " + file +
                       ": line 1, column 24: syntax error while parsing object - unexpected string literal; "
                       "expected '}'\n");
  }
  SECTION("a mimic joint whose leader is missing: the lock option as the CLI spells it") {
    const std::string urdf = dir + "/mimic_no_leader.urdf";
    cli_test::writeText(urdf, R"(<robot name="m"><link name="base"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="a"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
  <joint name="m2" type="revolute"><parent link="base"/><child link="b"/><axis xyz="0 0 1"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/><mimic joint="gone" offset="0.1"/></joint>
  <link name="b"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>
</robot>)");
    const Run info = run({"info", urdf});
    checkOneLineError(info, 1);
    CHECK(info.err == "zwang: " + urdf +
                          ": joint 'm2' (q = 1·q_gone + 0.1) mimics joint 'gone', which the URDF does not have: set "
                          "--lock-mimic to weld it at q = 0.1 (its position when 'gone' is at rest)\n");
    CHECK(run({"info", urdf, "--lock-mimic"}).exit_code == 0);
    const std::string file = dir + "/mimic_no_leader.json";
    cli_test::writeText(file, R"({"model": "mimic_no_leader.urdf"})");
    const Run solve = run({"solve", file});
    checkOneLineError(solve, 1);
    CHECK(contains(solve.err, "which the URDF does not have: set \"lock_mimic\": true to weld it at q = 0.1"));
  }
}

// ---------------------------------------------------------------------------
// Hostile input fails cleanly: exit 1, one line, no crash.

TEST_CASE("2 MB of random bytes", "[robustness]") {
  std::mt19937 rng(12345);
  for (int trial = 0; trial < 3; ++trial) {
    std::string bytes(2u << 20, '\0');
    for (char& b : bytes) b = static_cast<char>(rng() & 0xFF);
    if (trial == 1) bytes[0] = '{';  // starts like JSON
    if (trial == 2) bytes[0] = '[';
    const std::string file = cli_test::scratchDir() + "/random.json";
    cli_test::writeText(file, bytes);
    const Run r = run({"solve", file});
    checkOneLineError(r, 1);
    CHECK(contains(r.err, "random.json: "));
  }
}

TEST_CASE("Deeply nested arrays and objects", "[robustness]") {
  const std::size_t depth = 100000;
  struct Case {
    std::string text, part;
  };
  const std::vector<Case> cases =
      {
          {std::string(depth, '[') + std::string(depth, ']'), "nested deeper than 64 levels"},
          {"{\"model\": \"x.urdf\", \"q\": " + std::string(depth, '[') + std::string(depth, ']') + "}", "q[0][0][0]"},
          {[&] {
    std::string s;
    for (std::size_t k = 0; k < depth; ++k) s += "{\"a\":";
    return s + "1" + std::string(depth, '}');
           }(),
           "nested deeper than 64 levels"},
          {std::string(depth, '['), "nested deeper than 64 levels"},  // unterminated
  };
  for (const Case& c : cases) {
    const std::string file = cli_test::scratchDir() + "/deep.json";
    cli_test::writeText(file, c.text);
    const Run r = run({"solve", file});
    checkOneLineError(r, 1);
    CHECK(contains(r.err, c.part));
  }
}

TEST_CASE("Huge numbers", "[robustness]") {
  const std::string arm = "\"" + std::string(ZWANG_MODELS_DIR) + "/one_dof_arm.urdf\"";
  struct Case {
    std::string text, part;
  };
  const std::vector<Case> cases =
      {
          {"{\"model\": " + arm + ", \"q\": [1e400]}", "q[0]: line 1, column"},
          {"{\"model\": " + arm + ", \"q\": [-1e400]}", "out of range"},
          {"{\"model\": " + arm + ", \"tau\": [1e300]}", "tau[0]: the number 1e+300 is too large"},
          {"{\"model\": " + arm + ", \"tau\": [1e13]}", "tau[0]: the number 1e+13 is too large"},
          {"{\"model\": " + arm + ", \"q\": [123456789012345678901234567890]}",
           "q[0]: the number 1.2345678901234568e+29 is too large"},
          {"{\"model\": " + arm + ", \"q\": [1" + std::string(5000, '0') + "]}", "out of range"},
          {"{\"model\": " + arm + ", \"gravity\": [0, 0, 1e-400]}", ""},  // underflows to 0: fine
          {"{\"model\": " + arm + ", \"q\": [" +
               [] {
    std::string s = "0";
    for (int k = 0; k < 300000; ++k) s += ",0";
    return s;
           }() +
           "]}",
           "q: has 300001 entries, expected 1"},
  };
  for (const Case& c : cases) {
    const std::string file = cli_test::scratchDir() + "/huge.json";
    cli_test::writeText(file, c.text);
    const Run r = run({"solve", file});
    if (c.part.empty()) {
      CHECK(r.exit_code == 0);
      continue;
    }
    checkOneLineError(r, 1);
    INFO(r.err);
    CHECK(contains(r.err, c.part));
  }
}

TEST_CASE("Mutated problem files never crash", "[robustness]") {
  // Random byte edits of a valid problem: each run ends with 0, 1 or 3 and,
  // unless 0, one line on stderr.
  std::string text = cli_test::readText(problem("arm_fig55.json"));
  const std::string model = "\"" + std::string(ZWANG_MODELS_DIR) + "/one_dof_arm.urdf\"";
  text.replace(text.find("\"../../../models/one_dof_arm.urdf\""), 34, model);
  const std::string alphabet = "{}[],:\"0123456789.eE+-tfnul \\x";
  std::mt19937 rng(2024);
  int failures = 0;
  for (int trial = 0; trial < 60; ++trial) {
    std::string mutated = text;
    const int edits = 1 + static_cast<int>(rng() % 3);
    for (int e = 0; e < edits; ++e) {
      const std::size_t at = rng() % mutated.size();
      switch (rng() % 3) {
        case 0: mutated[at] = alphabet[rng() % alphabet.size()]; break;
        case 1: mutated.erase(at, 1); break;
        default: mutated.insert(at, 1, alphabet[rng() % alphabet.size()]); break;
      }
    }
    const std::string file = cli_test::scratchDir() + "/mutated.json";
    cli_test::writeText(file, mutated);
    const Run r = run({"solve", file});
    INFO("problem: " << mutated << "\nstderr: " << r.err);
    REQUIRE_FALSE(r.signaled);
    REQUIRE((r.exit_code == 0 || r.exit_code == 1 || r.exit_code == 3));
    if (r.exit_code == 1) {
      ++failures;
      CHECK(r.err.find('\n') == r.err.size() - 1);
      CHECK(r.out.empty());
    }
  }
  CHECK(failures > 20);  // most edits break something
}

// ---------------------------------------------------------------------------
// Usage.

TEST_CASE("Usage: help, unknown commands and options", "[usage]") {
  SECTION("no command") {
    const Run r = run({});
    CHECK(r.exit_code == 2);
    CHECK(r.out.empty());
    CHECK(contains(r.err, "usage: zwang <command>"));
  }
  SECTION("--help") {
    const Run r = run({"--help"});
    CHECK(r.exit_code == 0);
    CHECK(contains(r.out, "usage: zwang <command>"));
    CHECK(r.err.empty());
  }
  SECTION("--version") {
    const Run r = run({"--version"});
    CHECK(r.exit_code == 0);
    CHECK(r.out == "zwang " + std::to_string(ZWANG_VERSION_MAJOR) + "." + std::to_string(ZWANG_VERSION_MINOR) + "." +
                       std::to_string(ZWANG_VERSION_PATCH) + "\n");  // CMake's version is the header's
  }
  SECTION("unknown command") {
    const Run r = run({"frobnicate"});
    CHECK(r.exit_code == 2);
    CHECK(contains(r.err, "zwang: unknown command 'frobnicate'"));
    CHECK(contains(r.err, "usage: zwang <command>"));
  }
  for (const std::string command : {"solve", "info", "scenarios", "energy", "compare-mujoco"}) {
    SECTION(command + " --help") {
      const Run r = run({command, "--help"});
      CHECK(r.exit_code == 0);
      CHECK(contains(r.out, "usage: zwang " + command));
    }
    SECTION(command + " with an unknown option") {
      const Run r = run({command, "--frobnicate"});
      CHECK(r.exit_code == 2);
      CHECK(r.out.empty());
      CHECK(contains(r.err, "zwang: " + command + ": unknown option '--frobnicate'"));
      CHECK(contains(r.err, "usage: zwang " + command));
    }
  }
  SECTION("solve without a file") {
    const Run r = run({"solve"});
    CHECK(r.exit_code == 2);
    CHECK(contains(r.err, "no problem file given"));
  }
  SECTION("solve with two files") {
    const Run r = run({"solve", "a.json", "b.json"});
    CHECK(r.exit_code == 2);
    CHECK(contains(r.err, "more than one problem file"));
  }
  SECTION("-o without a value") {
    const Run r = run({"solve", problem("arm_slip.json"), "-o"});
    CHECK(r.exit_code == 2);
    CHECK(contains(r.err, "option -o needs a value"));
  }
  SECTION("a flag given a value") {
    const Run r = run({"solve", problem("arm_slip.json"), "--pretty=yes"});
    CHECK(r.exit_code == 2);
    CHECK(contains(r.err, "option --pretty takes no value"));
  }
  SECTION("info without a file") {
    const Run r = run({"info"});
    CHECK(r.exit_code == 2);
  }
  SECTION("scenarios with an argument") {
    const Run r = run({"scenarios", "extra"});
    CHECK(r.exit_code == 2);
    CHECK(contains(r.err, "unexpected argument 'extra'"));
  }
}

// ---------------------------------------------------------------------------
// info.

TEST_CASE("info: table and JSON", "[info]") {
  const std::string arm = std::string(ZWANG_MODELS_DIR) + "/one_dof_arm.urdf";
  SECTION("table") {
    const Run r = run({"info", arm});
    CHECK(r.exit_code == 0);
    for (const char* part : {"one_dof_arm: 1 moving joint, 3 frames", "joint1", "revolute", "(0, 0, 1)", "breakaway",
                             "rotor_inertia", "link1", "tip", "moving mass 1 kg (bodies 1-1), base mass 0 kg"})
      CHECK(contains(r.out, part));
  }
  SECTION("json") {
    const Run r = run({"info", arm, "--json"});
    REQUIRE(r.exit_code == 0);
    const Json j = parse(r.out);
    CHECK(j["dof"] == 1);
    CHECK(j["model"] == "one_dof_arm");
    CHECK(j["joints"][0]["name"] == "joint1");
    CHECK(j["joints"][0]["type"] == "revolute");
    CHECK(numbers(j["joints"][0]["axis"]) == std::vector<double>{0, 0, 1});
    CHECK(j["joints"][0]["breakaway_friction"].get<double>() == 10.0);
    CHECK(j["joints"][0]["viscous_friction"].get<double>() == 0.0);
    CHECK(j["joints"][0]["upper"].get<double>() == Approx(M_PI).margin(1e-15));
    CHECK(j["joints"][0]["effort_limit"].get<double>() == 100.0);
    CHECK(j["total_mass"].get<double>() == Approx(1.0).margin(1e-15));
    CHECK(j["moving_mass"].get<double>() == Approx(1.0).margin(1e-15));
    CHECK(j["base_mass"].get<double>() == 0.0);
    CHECK(j["warnings"].empty());
    CHECK(r.err.empty());
    std::vector<std::string> frames;
    for (const Json& f : j["frames"]) frames.push_back(f["name"]);
    CHECK(frames == std::vector<std::string>{"base", "link1", "tip"});
    CHECK(j["frames"][2]["body"] == 1);
    CHECK(j["chain"] == true);
    CHECK(j["joints"][0]["parent"].is_null());
  }
  SECTION("a tree: the parent of each joint, in the table and in JSON") {
    const std::string tree = problem("two_arms.urdf");
    const Run table = run({"info", tree});
    REQUIRE(table.exit_code == 0);
    for (const char* part : {"two_arms: 5 moving joints in a tree, 11 frames", "parent", "waist           (base)",
                             "right_shoulder  waist", "left_elbow      left_shoulder"})
      CHECK(contains(table.out, part));
    const Run r = run({"info", tree, "--json"});
    REQUIRE(r.exit_code == 0);
    const Json j = parse(r.out);
    CHECK(j["chain"] == false);
    CHECK(j["joints"][0]["parent"].is_null());
    CHECK(j["joints"][0]["parent_body"] == 0);
    CHECK(j["joints"][3]["name"] == "right_shoulder");
    CHECK(j["joints"][3]["parent"] == "waist");
    CHECK(j["joints"][3]["parent_body"] == 1);
    const Json sub = parse(run({"info", tree, "--root", "chest", "--json"}).out);
    CHECK(sub["dof"] == 4);
    CHECK(sub["joints"][2]["parent"].is_null());  // right_shoulder hangs from the base (chest)
  }
  SECTION("the base: fixed, --base free, a planar root joint") {
    const Run fixed = run({"info", arm});
    CHECK(contains(fixed.out, "\nbase: fixed (nq = nv = 1)\n"));
    const std::string solo = std::string(ZWANG_MODELS_DIR) + "/solo12.urdf";
    const Run free = run({"info", solo, "--base", "free"});
    REQUIRE(free.exit_code == 0);
    CHECK(contains(free.out,
                   "base: free, link base_link (q: 7 base coordinates + 12 joints = nq 19; v: 6 + 12 = nv 18)"));
    CHECK(contains(free.out, "base mass 1.16115 kg (body 6: the root link and the links welded to it; it floats"));
    const Json j = parse(run({"info", solo, "--base=free", "--json"}).out);
    CHECK(j["base_type"] == "free");
    CHECK(j["nq"] == 19);
    CHECK(j["nv"] == 18);
    CHECK(j["base_mass"].get<double>() == 1.16115091);  // the root link's own inertial
    CHECK_FALSE(j.contains("base_plane"));
    const Json jf = parse(run({"info", solo, "--json"}).out);
    CHECK(jf["base_type"] == "fixed");
    CHECK(jf["nq"] == 12);
    CHECK(jf["base_mass"].get<double>() == 1.16115091);  // counted on a fixed base too
    const Run planar = run({"info", problem("planar_cart.urdf")});
    REQUIRE(planar.exit_code == 0);
    CHECK(contains(planar.out, "base: planar, link cart (q: 3 base coordinates + 1 joint = nq 4; v: 3 + 1 = nv 4)"));
    CHECK(contains(planar.out, "moving in the plane through (0, 0, 1) with normal (0, -1, 0) (x axis (1, 0, 0))"));
    const Json jp = parse(run({"info", problem("planar_cart.urdf"), "--json"}).out);
    CHECK(jp["base_type"] == "planar");
    CHECK(numbers(jp["base_plane"]["origin"]) == std::vector<double>{0, 0, 1});
    CHECK(jp["base_plane"]["normal"][1].get<double>() == -1.0);
    // A base option on a file that floats already; a value that is no base.
    const Run again = run({"info", problem("planar_cart.urdf"), "--base", "planar"});
    checkOneLineError(again, 1);
    CHECK(contains(again.err,
                   "already has a planar root joint 'rail' (from 'world' to 'cart'), a planar base; drop "
                   "--base"));
    const Run bad = run({"info", solo, "--base", "flying"});
    CHECK(bad.exit_code == 2);
    CHECK(contains(bad.err, "--base: unknown value 'flying' (expected 'fixed', 'free' or 'planar')"));
  }
  SECTION("--root/--tip") {
    const Run r = run({"info", std::string(ZWANG_MODELS_DIR) + "/panda.urdf", "--tip", "panda_link4", "--json"});
    REQUIRE(r.exit_code == 0);
    const Json j = parse(r.out);
    CHECK(j["dof"] == 4);
    CHECK(j["joints"][3]["name"] == "panda_joint4");
    // The links beyond panda_link4 are cut off with their mass: said once.
    REQUIRE(j["warnings"].size() == 1);
    CHECK(j["warnings"][0]["code"] == "mass_beyond_tip");
    CHECK(contains(r.err, "zwang: warning: "));
    CHECK(contains(r.err, "set --attach-beyond-tip"));
    CHECK(r.err.find('\n') == r.err.size() - 1);
  }
}

// ---------------------------------------------------------------------------
// scenarios: the committed CSVs (docs/scenarios) are what the tool computes.

namespace {

std::vector<std::vector<double>> readCsv(const std::string& path, std::string& header) {
  std::istringstream in(cli_test::readText(path));
  std::getline(in, header);
  std::vector<std::vector<double>> rows;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    std::vector<double> row;
    std::istringstream cells(line);
    std::string cell;
    while (std::getline(cells, cell, ',')) row.push_back(std::stod(cell));
    rows.push_back(row);
  }
  return rows;
}

}  // namespace

TEST_CASE("scenarios regenerates the committed CSVs within 1e-12", "[scenarios]") {
  const std::string out = cli_test::scratchDir() + "/scenarios";
  const Run r = run({"scenarios", "--out", out});
  INFO("stdout: " << r.out << "\nstderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  CHECK_FALSE(contains(r.out, "MISMATCH"));
  for (const char* name : {"scenario1", "scenario2", "fig5_5"}) {
    INFO(name);
    CHECK(contains(r.out, name));
    std::string header_new, header_old;
    const auto fresh = readCsv(out + "/" + name + ".csv", header_new);
    const auto committed = readCsv(std::string(ZWANG_SCENARIOS_DIR) + "/" + name + ".csv", header_old);
    CHECK(header_new == "mu,g,qdd,tau_control,tau_net");
    CHECK(header_new == header_old);
    REQUIRE(fresh.size() == 201);
    REQUIRE(committed.size() == fresh.size());
    double worst = 0.0;
    for (std::size_t i = 0; i < fresh.size(); ++i) {
      REQUIRE(fresh[i].size() == 5);
      REQUIRE(committed[i].size() == 5);
      for (std::size_t k = 0; k < 5; ++k) worst = std::max(worst, std::abs(fresh[i][k] - committed[i][k]));
    }
    CHECK(worst <= 1e-12);
    // the grid spans [-f, f] = [-10, 10]
    CHECK(fresh.front()[0] == -10.0);
    CHECK(fresh.back()[0] == 10.0);
    if (cli_test::fileExists("/usr/bin/gnuplot") || cli_test::fileExists("/usr/local/bin/gnuplot")) {
      for (const char* plot : {"_g.png", "_qdd.png", "_tau.png"}) CHECK(cli_test::fileExists(out + "/" + name + plot));
    }
  }
  // The sampled g peaks where the exact maximiser is (the grid holds -5, -10 and +10).
  std::string header;
  const auto s1 = readCsv(out + "/scenario1.csv", header);
  std::size_t best = 0;
  for (std::size_t i = 0; i < s1.size(); ++i)
    if (s1[i][1] > s1[best][1]) best = i;
  CHECK(s1[best][0] == Approx(-5.0).margin(1e-12));
  CHECK(s1[best][2] == Approx(0.0).margin(1e-12));  // q̈(μ*) = 0
}

TEST_CASE("scenarios without gnuplot keeps the CSVs and says so", "[scenarios]") {
  const std::string out = cli_test::scratchDir() + "/scenarios-nognuplot";
  const std::string empty_bin = cli_test::scratchDir() + "/empty-bin";
  std::filesystem::create_directories(empty_bin);
  const Run r = run({"scenarios", "--out", out}, {{"PATH", empty_bin}});
  CHECK(r.exit_code == 0);
  CHECK(contains(r.err, "gnuplot is not on PATH"));
  CHECK(r.err.find('\n') == r.err.size() - 1);
  for (const char* name : {"scenario1", "scenario2", "fig5_5"}) {
    CHECK(cli_test::fileExists(out + "/" + std::string(name) + ".csv"));
    CHECK_FALSE(cli_test::fileExists(out + "/" + std::string(name) + "_g.png"));
  }
  const Run quiet = run({"scenarios", "--out", out + "-csv", "--no-plots"}, {{"PATH", empty_bin}});
  CHECK(quiet.exit_code == 0);
  CHECK(quiet.err.empty());
}

// ---------------------------------------------------------------------------
// energy: the committed docs/energy/panda_energy.csv is what the tool computes,
// and it is what the physics says (q̈ = 0 holds G(q); friction takes
// min(|G_j|, margin·f_j) off each joint).

namespace {

struct EnergyRow {
  std::string pose, variant;
  std::vector<double> values;  // q1-7, tau1-7, mu1-7, tau_norm, tau_sq, tau_abs_sum
};

std::vector<EnergyRow> readEnergyCsv(const std::string& path, std::string& header) {
  std::istringstream in(cli_test::readText(path));
  std::getline(in, header);
  std::vector<EnergyRow> rows;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    EnergyRow row;
    std::istringstream cells(line);
    std::getline(cells, row.pose, ',');
    std::getline(cells, row.variant, ',');
    std::string cell;
    while (std::getline(cells, cell, ',')) row.values.push_back(std::stod(cell));
    rows.push_back(row);
  }
  return rows;
}

}  // namespace

TEST_CASE("energy regenerates the committed CSV within 1e-12", "[energy]") {
  const std::string out = cli_test::scratchDir() + "/energy";
  const Run r = run({"energy", "--out", out});
  INFO("stdout: " << r.out << "\nstderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.empty());
  CHECK_FALSE(contains(r.out, "MISMATCH"));
  std::string header_new, header_old;
  const auto fresh = readEnergyCsv(out + "/panda_energy.csv", header_new);
  const auto committed = readEnergyCsv(std::string(ZWANG_ENERGY_DIR) + "/panda_energy.csv", header_old);
  CHECK(header_new.rfind("pose,variant,q1,", 0) == 0);
  CHECK(header_new == header_old);
  REQUIRE(fresh.size() == 18);  // 6 poses × 3 variants
  REQUIRE(committed.size() == fresh.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < fresh.size(); ++i) {
    CHECK(fresh[i].pose == committed[i].pose);
    CHECK(fresh[i].variant == committed[i].variant);
    REQUIRE(fresh[i].values.size() == 24);
    REQUIRE(committed[i].values.size() == 24);
    // 1e-12 absolute, relative for the few entries above 1 in magnitude (‖τ‖² reaches 2446)
    for (std::size_t k = 0; k < 24; ++k)
      worst = std::max(worst, std::abs(fresh[i].values[k] - committed[i].values[k]) /
                                  std::max(1.0, std::abs(committed[i].values[k])));
  }
  CHECK(worst <= 1e-12);
  if (cli_test::fileExists("/usr/bin/gnuplot") || cli_test::fileExists("/usr/local/bin/gnuplot")) {
    CHECK(cli_test::fileExists(out + "/panda_energy.png"));
    CHECK(cli_test::fileExists(out + "/panda_energy_joints.png"));
    CHECK(cli_test::fileExists(out + "/dual_energy.png"));
    CHECK(cli_test::fileExists(out + "/dual_energy_joints.png"));
    CHECK(cli_test::fileExists(out + "/standing_energy.png"));
    CHECK(cli_test::fileExists(out + "/standing_humanoid_joints.png"));
    CHECK(cli_test::fileExists(out + "/standing_solo12_joints.png"));
  }

  // Independently of the tool: G(q) by RNEA, and the effort-minimising friction.
  const zwang::Model model = zwang::loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/panda.urdf");
  zwang::Task free_task(model);
  zwang::Workspace ws(model, 0);
  for (std::size_t i = 0; i < fresh.size(); i += 3) {
    INFO(fresh[i].pose);
    const std::vector<double>& v = fresh[i].values;
    const Eigen::VectorXd q = Eigen::Map<const Eigen::VectorXd>(v.data(), 7), zero = Eigen::VectorXd::Zero(7);
    REQUIRE(zwang::inverseDynamics(model, ws, q, zero, zero, free_task));
    const Eigen::VectorXd gravity = ws.tau;
    const double margins[3] = {0.0, 0.5, 1.0};
    for (int variant = 0; variant < 3; ++variant) {
      const std::vector<double>& w = fresh[i + variant].values;
      double sq = 0.0;
      for (int j = 0; j < 7; ++j) {
        const double f = margins[variant] * model.joint(j).breakaway_friction;
        const double expected = std::copysign(std::max(0.0, std::abs(gravity[j]) - f), gravity[j]);
        CHECK(w[7 + j] == Approx(expected).margin(1e-9));
        // the joint feels τ_control − μ = G(q): friction carries the rest
        CHECK(w[7 + j] - w[14 + j] == Approx(gravity[j]).margin(1e-9));
        CHECK(std::abs(w[14 + j]) <= f + 1e-12);
        sq += w[7 + j] * w[7 + j];
      }
      CHECK(w[22] == Approx(sq).epsilon(1e-12));
      CHECK(w[21] == Approx(std::sqrt(sq)).epsilon(1e-12));
    }
    CHECK(fresh[i + 2].values[22] < fresh[i + 1].values[22]);
    CHECK(fresh[i + 1].values[22] < fresh[i].values[22]);
  }
}

// The dual arm holding a box (docs/evaluation.md, "The dual arm holding a
// box"): docs/energy/dual_energy.csv is what the tool computes, and what the
// physics says: q̈ = 0 holds G'(q), the gravity torques with the box's weight
// (half on each hand); friction takes min(|G'_j|, margin·f_j) off each joint;
// the hands hold the box (0.3 m apart, facing each other).
TEST_CASE("energy: the dual arm holding a box regenerates the committed CSV within 1e-12", "[energy]") {
  const std::string out = cli_test::scratchDir() + "/energy-dual";
  const Run r = run({"energy", "--out", out, "--no-plots"});
  INFO("stdout: " << r.out << "\nstderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.empty());
  CHECK_FALSE(contains(r.out, "MISMATCH"));
  CHECK(contains(r.out, "check: rank 15 in every solve"));
  std::string header_new, header_old;
  const auto fresh = readEnergyCsv(out + "/dual_energy.csv", header_new);
  const auto committed = readEnergyCsv(std::string(ZWANG_ENERGY_DIR) + "/dual_energy.csv", header_old);
  CHECK(header_new.rfind("pose,variant,q1,", 0) == 0);
  CHECK(header_new == header_old);
  REQUIRE(fresh.size() == 15);  // 5 postures × 3 variants
  REQUIRE(committed.size() == fresh.size());
  constexpr std::size_t kValues = 15 * 3 + 3 + 6;  // q, tau, mu; norm, sq, abs_sum; the loop's wrench
  double worst = 0.0;
  for (std::size_t i = 0; i < fresh.size(); ++i) {
    CHECK(fresh[i].pose == committed[i].pose);
    CHECK(fresh[i].variant == committed[i].variant);
    REQUIRE(fresh[i].values.size() == kValues);
    REQUIRE(committed[i].values.size() == kValues);
    for (std::size_t k = 0; k < kValues; ++k)
      worst = std::max(worst, std::abs(fresh[i].values[k] - committed[i].values[k]) /
                                  std::max(1.0, std::abs(committed[i].values[k])));
  }
  CHECK(worst <= 1e-12);

  // Independently of the tool: the grasp, G'(q) by RNEA with the box's weight
  // on the hands, and the effort-minimising friction.
  const zwang::Model model = zwang::loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/dual_panda.urdf");
  REQUIRE(model.dof() == 15);
  zwang::Task box(model);
  const zwang::Vec6 half_weight = (zwang::Vec6() << 0.0, 0.0, -0.5 * 3.0 * 9.81, 0.0, 0.0, 0.0).finished();
  box.wrench(box.addWrench("left_tool0", zwang::Expressed::World)) = half_weight;
  box.wrench(box.addWrench("right_tool0", zwang::Expressed::World)) = half_weight;
  zwang::Workspace ws(model, 0);
  for (std::size_t i = 0; i < fresh.size(); i += 3) {
    INFO(fresh[i].pose);
    const std::vector<double>& v = fresh[i].values;
    const Eigen::VectorXd q = Eigen::Map<const Eigen::VectorXd>(v.data(), 15), zero = Eigen::VectorXd::Zero(15);
    for (int j = 0; j < 15; ++j) {
      CHECK(q[j] > model.joint(j).lower + 0.2);
      CHECK(q[j] < model.joint(j).upper - 0.2);
    }
    Eigen::Isometry3d left, right;
    REQUIRE(zwang::forwardKinematics(model, ws, q));
    REQUIRE(zwang::framePose(model, ws, q, model.frameIndex("left_tool0"), left));
    REQUIRE(zwang::framePose(model, ws, q, model.frameIndex("right_tool0"), right));
    CHECK((left.translation() - right.translation()).norm() == Approx(0.3).margin(1e-9));
    // facing each other along the line between them, x axes down
    const Eigen::Vector3d across = (right.translation() - left.translation()).normalized();
    CHECK((left.linear().col(2) - across).norm() < 1e-9);
    CHECK((right.linear().col(2) + across).norm() < 1e-9);
    CHECK((left.linear().col(0) - Eigen::Vector3d(0, 0, -1)).norm() < 1e-9);
    CHECK((right.linear().col(0) - Eigen::Vector3d(0, 0, -1)).norm() < 1e-9);
    REQUIRE(zwang::inverseDynamics(model, ws, q, zero, zero, box));
    const Eigen::VectorXd gravity = ws.tau;
    const double margins[3] = {0.0, 0.5, 1.0};
    for (int variant = 0; variant < 3; ++variant) {
      const std::vector<double>& w = fresh[i + variant].values;
      double sq = 0.0;
      for (int j = 0; j < 15; ++j) {
        const double f = margins[variant] * model.joint(j).breakaway_friction;
        const double expected = std::copysign(std::max(0.0, std::abs(gravity[j]) - f), gravity[j]);
        CHECK(w[15 + j] == Approx(expected).margin(1e-9));
        CHECK(w[15 + j] - w[30 + j] == Approx(gravity[j]).margin(1e-9));
        CHECK(std::abs(w[30 + j]) <= f + 1e-12);
        sq += w[15 + j] * w[15 + j];
      }
      CHECK(w[46] == Approx(sq).epsilon(1e-12));
      CHECK(w[45] == Approx(std::sqrt(sq)).epsilon(1e-12));
    }
    CHECK(fresh[i + 2].values[46] < fresh[i + 1].values[46]);
    CHECK(fresh[i + 1].values[46] < fresh[i].values[46]);
  }
}

namespace {

// The dual arm's hold-still task as docs/evaluation.md states it: the loop
// (left_tool0 relative to right_tool0, its axes), right_tool0 fixed (world
// axes), the torso's and each arm's first joint locked (angular z, own axes),
// half the box's weight on each hand.
zwang::Task dualHoldTask(const zwang::Model& model) {
  zwang::Task task(model);
  const zwang::ConstraintMatrix all = zwang::ConstraintMatrix::Identity(6, 6);
  REQUIRE(task.addRelativeConstraint("left_tool0", "right_tool0", all, zwang::Expressed::Reference) == 0);
  task.addConstraint("right_tool0", all, zwang::Expressed::World);
  for (const char* body : {"torso_link", "left_panda_link1", "right_panda_link1"})
    task.addConstraint(body, all.rightCols(1), zwang::Expressed::Local);
  for (const char* hand : {"left_tool0", "right_tool0"})
    task.wrench(task.addWrench(hand, zwang::Expressed::World)) << 0.0, 0.0, -1.5 * 9.81, 0.0, 0.0, 0.0;
  return task;
}

// τ_c = Σ Jᵀ A ν of dualHoldTask's rows from the frames' Jacobians alone: the
// loop's wrench ν[0..6) (right_tool0's axes) acts on the left hand and, moved
// to right_tool0's origin, oppositely on the right arm; ν[6..12) on right_tool0
// (world axes); ν[12..15) are torques about the locked bodies' own z.
Eigen::VectorXd dualConstraintTorques(const zwang::Model& model, const Eigen::VectorXd& q, const Eigen::VectorXd& nu) {
  zwang::Workspace ws(model, 0);
  Eigen::MatrixXd left(6, 15), right(6, 15), local(6, 15);
  Eigen::Isometry3d at_left, at_right;
  REQUIRE(zwang::frameJacobian(model, ws, q, model.frameIndex("left_tool0"), zwang::Expressed::World, left));
  REQUIRE(zwang::frameJacobian(model, ws, q, model.frameIndex("right_tool0"), zwang::Expressed::World, right));
  REQUIRE(zwang::framePose(model, ws, q, model.frameIndex("left_tool0"), at_left));
  REQUIRE(zwang::framePose(model, ws, q, model.frameIndex("right_tool0"), at_right));
  const Eigen::Vector3d force = at_right.linear() * nu.head<3>(), moment = at_right.linear() * nu.segment<3>(3);
  const Eigen::Vector3d lever = at_left.translation() - at_right.translation();
  zwang::Vec6 on_left, on_right;
  on_left << force, moment;
  on_right << -force, -moment - lever.cross(force);
  Eigen::VectorXd tau = left.transpose() * on_left + right.transpose() * (on_right + nu.segment<6>(6));
  const char* locked[] = {"torso_link", "left_panda_link1", "right_panda_link1"};
  for (int k = 0; k < 3; ++k) {
    REQUIRE(zwang::frameJacobian(model, ws, q, model.frameIndex(locked[k]), zwang::Expressed::Local, local));
    tau += nu[12 + k] * local.row(5).transpose();
  }
  return tau;
}

}  // namespace

// What the tool no longer checks itself: the hybrid solver's answer to the
// dual arm's task in each committed posture has q̈ = 0, its τ_control is
// Σ Jᵀ A ν from the frames' Jacobians (not the solver's tau_constraint) and
// the committed CSV's, its loop force is the CSV's, and that loop force puts no
// torque on the torso joint both arms hang from.
TEST_CASE("energy: the dual arm's solves hold still, tau_c = sum J^T A nu, the loop spares the torso", "[energy]") {
  std::string header;
  const auto rows = readEnergyCsv(std::string(ZWANG_ENERGY_DIR) + "/dual_energy.csv", header);
  REQUIRE(rows.size() == 15);
  const zwang::Model model = zwang::loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/dual_panda.urdf");
  REQUIRE(model.dof() == 15);
  const zwang::Task task = dualHoldTask(model);
  zwang::Workspace ws(model, task);
  Eigen::VectorXd breakaway(15);
  for (int j = 0; j < 15; ++j) breakaway[j] = model.joint(j).breakaway_friction;
  const double margins[3] = {0.0, 0.5, 1.0};
  for (std::size_t i = 0; i < rows.size(); ++i) {
    INFO(rows[i].pose << ", " << rows[i].variant);
    const std::vector<double>& w = rows[i].values;
    const Eigen::VectorXd q = Eigen::Map<const Eigen::VectorXd>(w.data(), 15), zero = Eigen::VectorXd::Zero(15);
    const Eigen::VectorXd tau = Eigen::Map<const Eigen::VectorXd>(w.data() + 15, 15);
    const Eigen::VectorXd loop = Eigen::Map<const Eigen::VectorXd>(w.data() + 48, 6);
    zwang::FrictionOptions options;
    options.margin = margins[i % 3];
    options.breakaway = breakaway;
    REQUIRE((i % 3 == 0 ? zwang::solveHybridDynamics(model, ws, q, zero, zero, task)
                        : zwang::solveWithFriction(model, ws, q, zero, zero, task, options)));
    REQUIRE(ws.solution.balance.rank == 15);
    CHECK(ws.solution.qdd.cwiseAbs().maxCoeff() < 1e-9);  // [rad/s²]
    const Eigen::VectorXd tau_c = dualConstraintTorques(model, q, ws.solution.nu);
    CHECK((tau_c - tau).cwiseAbs().maxCoeff() < 1e-9);  // [N·m]: τ_control = 0 + τ_c, as in the CSV
    CHECK((ws.solution.tau_control - tau).cwiseAbs().maxCoeff() < 1e-9);
    CHECK((ws.solution.nu.head<6>() - loop).cwiseAbs().maxCoeff() < 1e-9);  // [N, N·m]
    // The loop's force alone: internal, no torque on the torso joint.
    Eigen::VectorXd loop_only = Eigen::VectorXd::Zero(15);
    loop_only.head<6>() = loop;
    CHECK(std::abs(dualConstraintTorques(model, q, loop_only)[0]) < 1e-9);  // [N·m]
  }
}

TEST_CASE("energy: a models directory without dual_panda.urdf writes nothing", "[energy]") {
  const std::string models = cli_test::scratchDir() + "/panda-only-models";
  const std::string out = cli_test::scratchDir() + "/en-panda-only";
  std::filesystem::create_directories(models);
  std::filesystem::copy_file(std::string(ZWANG_MODELS_DIR) + "/panda.urdf", models + "/panda.urdf",
                             std::filesystem::copy_options::overwrite_existing);
  const Run r = run({"energy", "--models", models, "--out", out, "--no-plots"});
  checkOneLineError(r, 1);
  CHECK(contains(r.err, "zwang: energy: "));
  CHECK(contains(r.err, "dual_panda.urdf"));
  CHECK(contains(r.err, "(use --models DIR)"));
  CHECK_FALSE(cli_test::fileExists(out + "/panda_energy.csv"));
  CHECK_FALSE(cli_test::fileExists(out + "/dual_energy.csv"));
}

// The dual arm's postures are data (models/dual_panda_postures.json): a posture
// whose hands miss the box, or a file without them, is refused naming file and field.
TEST_CASE("energy: a bad dual-arm postures file is refused, naming the file and the field", "[energy]") {
  const std::string models = cli_test::scratchDir() + "/bad-postures-models";
  const std::string out = cli_test::scratchDir() + "/en-bad-postures";
  std::filesystem::create_directories(models);
  for (const char* file : {"panda.urdf", "dual_panda.urdf"})
    std::filesystem::copy_file(std::string(ZWANG_MODELS_DIR) + "/" + file, models + "/" + file,
                               std::filesystem::copy_options::overwrite_existing);
  const std::string postures = models + "/dual_panda_postures.json";
  Json file = Json::parse(cli_test::readText(std::string(ZWANG_MODELS_DIR) + "/dual_panda_postures.json"));
  SECTION("a hand off the box") {
    file["postures"][2]["q"][4] = file["postures"][2]["q"][4].get<double>() + 1e-3;
    cli_test::writeText(postures, file.dump());
    const Run r = run({"energy", "--models", models, "--out", out, "--no-plots"});
    checkOneLineError(r, 1);
    CHECK(contains(r.err, "zwang: energy: " + postures + ": postures[2].q: the hands are "));
  }
  SECTION("a joint near its limit") {
    file["postures"][0]["q"][0] = -1.5;  // torso at -1.5 rad of ±π/2, the box turned with it
    file["postures"][0]["torso"] = -1.5;
    cli_test::writeText(postures, file.dump());
    const Run r = run({"energy", "--models", models, "--out", out, "--no-plots"});
    checkOneLineError(r, 1);
    CHECK(contains(r.err, "zwang: energy: " + postures + ": postures[0].q: a joint is "));
  }
  SECTION("a q of the wrong length") {
    file["postures"][1]["q"].erase(0);
    cli_test::writeText(postures, file.dump());
    const Run r = run({"energy", "--models", models, "--out", out, "--no-plots"});
    checkOneLineError(r, 1);
    CHECK(contains(r.err, "zwang: energy: " + postures + ": postures[1].q: "));
  }
  SECTION("no file") {
    std::filesystem::remove(postures);
    const Run r = run({"energy", "--models", models, "--out", out, "--no-plots"});
    checkOneLineError(r, 1);
    CHECK(contains(r.err, "zwang: energy: " + postures + ": cannot read the file"));
    CHECK(contains(r.err, "(use --models DIR)"));
  }
  CHECK_FALSE(cli_test::fileExists(out + "/panda_energy.csv"));
  CHECK_FALSE(cli_test::fileExists(out + "/dual_energy.csv"));
}

TEST_CASE("energy without gnuplot keeps the CSV and says so", "[energy]") {
  const std::string out = cli_test::scratchDir() + "/energy-nognuplot";
  const std::string empty_bin = cli_test::scratchDir() + "/empty-bin-energy";
  std::filesystem::create_directories(empty_bin);
  const Run r = run({"energy", "--out", out}, {{"PATH", empty_bin}});
  CHECK(r.exit_code == 0);
  CHECK(contains(r.err, "zwang: energy: gnuplot is not on PATH"));
  CHECK(r.err.find('\n') == r.err.size() - 1);
  CHECK(cli_test::fileExists(out + "/panda_energy.csv"));
  CHECK(cli_test::fileExists(out + "/energy.gp"));
  CHECK_FALSE(cli_test::fileExists(out + "/panda_energy.png"));
  CHECK(cli_test::fileExists(out + "/dual_energy.csv"));
  CHECK(cli_test::fileExists(out + "/dual_energy.gp"));
  CHECK_FALSE(cli_test::fileExists(out + "/dual_energy.png"));
  CHECK(cli_test::fileExists(out + "/standing_energy.csv"));
  CHECK(cli_test::fileExists(out + "/standing_energy.gp"));
  CHECK_FALSE(cli_test::fileExists(out + "/standing_energy.png"));
  const Run quiet = run({"energy", "--out", out + "-csv", "--no-plots"}, {{"PATH", empty_bin}});
  CHECK(quiet.exit_code == 0);
  CHECK(quiet.err.empty());
  CHECK_FALSE(cli_test::fileExists(out + "-csv/energy.gp"));
}

TEST_CASE("energy: usage and a missing model", "[energy]") {
  const Run extra = run({"energy", "extra"});
  CHECK(extra.exit_code == 2);
  CHECK(contains(extra.err, "unexpected argument 'extra'"));
  const Run none =
      run({"energy", "--models", cli_test::scratchDir() + "/nothing", "--out", cli_test::scratchDir() + "/en-none"});
  checkOneLineError(none, 1);
  CHECK(contains(none.err, "zwang: energy: "));
  CHECK(contains(none.err, "panda.urdf"));
  CHECK(contains(none.err, "(use --models DIR)"));
}

// ---------------------------------------------------------------------------
// docs: what the pages quote is what is compiled and committed.

TEST_CASE("getting-started.md quotes the example that ctest compiles and runs", "[docs]") {
  const std::string docs = ZWANG_DOCS_DIR;
  std::string example = cli_test::readText(docs + "/examples/getting_started.cpp");
  while (!example.empty() && example.back() == '\n') example.pop_back();
  const std::string page = cli_test::readText(docs + "/getting-started.md");
  CHECK(contains(page, "```cpp\n" + example + "\n```\n"));
  const std::string problem_text = cli_test::readText(kProblems + "/arm_stick.json");
  CHECK(contains(page, problem_text.substr(0, problem_text.find_last_not_of('\n') + 1)));
}

TEST_CASE("the docs link only to files that exist", "[docs]") {
  const std::string docs = ZWANG_DOCS_DIR;
  for (const char* name :
       {"getting-started.md", "conventions.md", "theory.md", "evaluation.md", "cli.md", "mujoco.md"}) {
    INFO(name);
    REQUIRE(cli_test::fileExists(docs + "/" + name));
    // The page without its fenced code blocks (code may contain "](").
    std::string page;
    {
      std::istringstream lines(cli_test::readText(docs + "/" + name));
      bool fenced = false;
      for (std::string line; std::getline(lines, line);) {
        if (line.rfind("```", 0) == 0)
          fenced = !fenced;
        else if (!fenced)
          page += line + "\n";
      }
    }
    // Markdown links and images: ](target) with a relative target.
    for (std::size_t at = page.find("]("); at != std::string::npos; at = page.find("](", at + 2)) {
      const std::size_t end = page.find(')', at);
      REQUIRE(end != std::string::npos);
      std::string target = page.substr(at + 2, end - at - 2);
      if (target.rfind("http", 0) == 0 || target.empty() || target[0] == '#') continue;
      target = target.substr(0, target.find('#'));
      INFO(target);
      CHECK(std::filesystem::exists(std::filesystem::path(docs) / target));
    }
  }
}

// ---------------------------------------------------------------------------
// Model warnings: on stderr once each, --strict / "strict" refuses them; the
// hints name the CLI's own options; UTF-8 in messages passes through.

namespace {

// base -j1-> l1 with a point mass and placeholder limits.
const char* kDoubtfulArm = R"(<robot name="doubtful"><link name="base"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="0" upper="0" effort="0" velocity="0"/></joint>
  <link name="l1"><inertial><origin xyz="0.5 0 0"/><mass value="2"/>
    <inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial></link></robot>)";

// base -j0-> hub, then 15 revolute branches hub -jk-> leaf_k (each with a little mass): a tree.
std::string fifteenBranches() {
  std::string xml = R"(<robot name="star"><link name="base"/>
    <joint name="j0" type="continuous"><parent link="base"/><child link="hub"/></joint>
    <link name="hub"><inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial></link>)";
  for (int k = 0; k < 15; ++k) {
    const std::string n = std::to_string(k);
    xml += "<joint name=\"j" + n + "_\" type=\"continuous\"><parent link=\"hub\"/><child link=\"leaf_" + n +
           "\"/></joint><link name=\"leaf_" + n +
           "\"><inertial><mass value=\"0.1\"/><inertia ixx=\"1e-3\" ixy=\"0\" ixz=\"0\" iyy=\"1e-3\" iyz=\"0\" "
           "izz=\"1e-3\"/></inertial></link>";
  }
  return xml + "</robot>";
}

// base -j1-> l1 -fixed-> palm; palm -f1-> finger1, palm -f2 (mimics f1)-> finger2.
const char* kMimicGripper = R"(<robot name="gripper"><link name="base"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="l1"/><axis xyz="0 0 1"/>
    <limit lower="-2" upper="2" effort="10" velocity="3"/></joint>
  <link name="l1"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <joint name="palm_joint" type="fixed"><parent link="l1"/><child link="palm"/><origin xyz="0.3 0 0"/></joint>
  <link name="palm"/>
  <joint name="f1" type="prismatic"><parent link="palm"/><child link="finger1"/><axis xyz="0 1 0"/>
    <limit lower="0" upper="0.04" effort="10" velocity="1"/></joint>
  <link name="finger1"><inertial><mass value="0.1"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial></link>
  <joint name="f2" type="prismatic"><parent link="palm"/><child link="finger2"/><axis xyz="0 -1 0"/>
    <limit lower="0" upper="0.04" effort="10" velocity="1"/><mimic joint="f1" multiplier="1" offset="0"/></joint>
  <link name="finger2"><inertial><mass value="0.2"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"/></inertial></link>
</robot>)";

int countOf(const std::string& text, const std::string& part) {
  int n = 0;
  for (std::size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++n;
  return n;
}

}  // namespace

TEST_CASE("A robot standing on contacts with a fixed base: solved, with a warning naming \"base\"", "[warnings]") {
  // The humanoid without "base" is bolted down by its 27 kg BODY: the solve
  // runs (exit 0) and says once, on stderr, that standing needs a free base.
  const Run bolted = run({"solve", problem("humanoid_bolted.json")});
  INFO("stderr: " << bolted.err);
  REQUIRE(bolted.exit_code == 0);
  CHECK(occurrences(bolted.err, "zwang: warning: ") == 1);
  CHECK(contains(bolted.err, "zwang: warning: " + problem("humanoid_bolted.json") +
                                 ": contact on frame 'l_ankle' of a fixed-base model whose base carries 27 kg"));
  CHECK(contains(bolted.err, "CLI \"base\": {\"type\": \"free\"}"));
  CHECK(parse(bolted.out)["nu"].size() == 12);
  // The same problem with a free base: no warning.
  Json p = problemFile("humanoid_bolted.json");
  p["model"] = std::string(ZWANG_MODELS_DIR) + "/simple_humanoid.urdf";
  p["base"] = {{"type", "free"}, {"position", {0, 0, 1}}};
  const std::string file = cli_test::scratchDir() + "/humanoid_free.json";
  cli_test::writeText(file, p.dump());
  const Json free = solve(file);  // stderr empty
  CHECK(free["nu"].size() == 12);
}

TEST_CASE("Model warnings on stderr, strict mode, the CLI's option names, UTF-8", "[warnings]") {
  const std::string dir = cli_test::scratchDir();
  const std::string arm = dir + "/doubtful.urdf";
  cli_test::writeText(arm, kDoubtfulArm);

  SECTION("info: each warning once, the model still loads; --strict refuses") {
    const Run r = run({"info", arm});
    INFO("stderr: " << r.err);
    CHECK(r.exit_code == 0);
    CHECK(countOf(r.err, "zwang: warning: " + arm + ": link 'l1': a point mass") == 1);
    CHECK(countOf(r.err, "zwang: warning: " + arm + ": joint 'j1': placeholder <limit") == 1);
    CHECK(countOf(r.err, "\n") == 2);
    CHECK(contains(r.out, "2 warnings (on stderr)"));
    const Run strict = run({"info", arm, "--strict"});
    checkOneLineError(strict, 1);
    CHECK(contains(strict.err, "refused in strict mode (2 warnings)"));
  }
  SECTION("solve: warnings before the solution, q outside the limits, \"strict\": true") {
    const std::string file = dir + "/doubtful.json";
    cli_test::writeText(file, R"({"model": "doubtful.urdf", "q": [0.5]})");
    const Run r = run({"solve", file});
    INFO("stderr: " << r.err);
    CHECK(r.exit_code == 0);
    CHECK(countOf(r.err, "zwang: warning: ") == 2);  // placeholder limits are no limits: q = 0.5 is inside
    std::string limited = kDoubtfulArm;
    const std::string placeholder = R"(lower="0" upper="0" effort="0")";
    limited.replace(limited.find(placeholder), placeholder.size(), R"(lower="-0.2" upper="0.2" effort="5")");
    cli_test::writeText(dir + "/limited.urdf", limited);
    cli_test::writeText(file, R"({"model": "limited.urdf", "q": [0.5]})");
    const Run outside = run({"solve", file});
    INFO("stderr: " << outside.err);
    CHECK(outside.exit_code == 0);
    CHECK(contains(outside.err,
                   "zwang: warning: " + file + ": q[0] = 0.5 puts joint 'j1' outside its limits [-0.2, 0.2]"));
    cli_test::writeText(file, R"({"model": "doubtful.urdf", "strict": true})");
    const Run strict = run({"solve", file});
    checkOneLineError(strict, 1);
    CHECK(contains(strict.err, "model: "));
    CHECK(contains(strict.err, "refused in strict mode"));
  }
  SECTION("a tree: no tip needed; an unknown root lists the links, cut between names, … is UTF-8") {
    const std::string star = dir + "/star.urdf";
    cli_test::writeText(star, fifteenBranches());
    const Run whole = run({"info", star, "--json"});
    INFO("stderr: " << whole.err);
    REQUIRE(whole.exit_code == 0);
    CHECK(parse(whole.out)["dof"] == 16);  // the hub and its 15 leaves
    const Run info = run({"info", star, "--root", "nowhere"});
    checkOneLineError(info, 1);
    CHECK(contains(info.err, "root link 'nowhere' not found (links: "));
    CHECK(contains(info.err, ", \xE2\x80\xA6 (5 more)"));  // "…" as UTF-8, after 12 whole names
    CHECK(countOf(info.err, "'leaf_") == 10);              // 'base', 'hub' and 10 leaves
    CHECK_FALSE(contains(info.err, "\\x"));
    const std::string file = dir + "/star.json";
    cli_test::writeText(file, R"({"model": "star.urdf", "root": "nowhere"})");
    const Run solve = run({"solve", file});
    checkOneLineError(solve, 1);
    CHECK(contains(solve.err, ": model: "));
    CHECK(contains(solve.err, "root link 'nowhere' not found"));
  }
  SECTION("a mimic joint: modelled by default (info shows its law), locked with --lock-mimic or \"lock_mimic\"") {
    const std::string gripper = dir + "/gripper.urdf";
    cli_test::writeText(gripper, kMimicGripper);
    const Run info = run({"info", gripper, "--json"});
    REQUIRE(info.exit_code == 0);
    const Json modelled = parse(info.out);
    CHECK(modelled["dof"] == 3);
    CHECK(modelled["warnings"].empty());
    CHECK(modelled["joints"][2]["mimic"] == Json({{"leader", "f1"}, {"multiplier", 1.0}, {"offset", 0.0}}));
    CHECK(modelled["joints"][1]["mimic"].is_null());
    const Run table = run({"info", gripper});
    CHECK(contains(table.out, "f2 follows f1: q = 1·q_f1 + 0"));
    const Run locked = run({"info", gripper, "--lock-mimic", "--json"});
    REQUIRE(locked.exit_code == 0);
    const Json j = parse(locked.out);
    CHECK(j["dof"] == 2);
    REQUIRE(j["warnings"].size() == 1);
    CHECK(j["warnings"][0]["code"] == "mimic_locked");
    CHECK(countOf(locked.err, "zwang: warning: ") == 1);
    const std::string file = dir + "/gripper.json";
    // q of the mimic joint off its law: a one-line error naming both joints.
    cli_test::writeText(file, R"({"model": "gripper.urdf", "q": [0.1, 0.02, 0.0]})");
    const Run off = run({"solve", file});
    checkOneLineError(off, 1);
    CHECK(contains(off.err, "joint 'f2' mimics 'f1'"));
    cli_test::writeText(file, R"({"model": "gripper.urdf", "q": [0.1, 0.02, 0.02], "tau": [0, 1, 0.5]})");
    const Run solved_mimic = run({"solve", file});
    INFO("stderr: " << solved_mimic.err);
    REQUIRE(solved_mimic.exit_code == 0);
    const Json s = parse(solved_mimic.out);
    CHECK(s["joints"] == Json::array({"j1", "f1", "f2"}));
    CHECK(s["tau_control"][2] == 0.0);
    CHECK(std::abs(s["tau_control"][1].get<double>() - 1.5) < 1e-12);  // τ_f1 + 1·τ_f2
    CHECK(std::abs(s["qdd"][2].get<double>() - s["qdd"][1].get<double>()) < 1e-12);
    cli_test::writeText(file, R"({"model": "gripper.urdf", "lock_mimic": true, "strict": true})");
    const Run solved = run({"solve", file});
    INFO("stderr: " << solved.err);
    CHECK(solved.exit_code == 0);  // the lock's note passes strict mode
    CHECK(parse(solved.out)["joints"] == Json::array({"j1", "f1"}));
  }
  SECTION("valid UTF-8 passes through, other bytes are escaped") {
    const Run r = run({"info", "--\xC3\xA9t\xC3\xA9\xFF"});
    CHECK(r.exit_code == 2);
    CHECK(contains(r.err, "unknown option '--\xC3\xA9t\xC3\xA9\\xFF'"));
  }
}

// ---------------------------------------------------------------------------
// Joints of any type (issue #25): floating and planar URDF joints below the root.

TEST_CASE("info: every joint with its type, nq, nv, q_index and v_index; the root joint first", "[info]") {
  SECTION("a fixed base with a free and a planar joint below it") {
    const Run r = run({"info", problem("multi_joint.urdf"), "--json"});
    REQUIRE(r.exit_code == 0);
    const Json j = parse(r.out);
    CHECK(j["nq"] == 12);
    CHECK(j["nv"] == 11);
    CHECK(j["dof"] == 11);
    struct Expected {
      const char* name;
      const char* type;
      int nq, nv, q_index, v_index;
    };
    // Depth first, children by joint name: j1 (arm) → float (ball) → j2 (paddle), then slide (puck).
    const Expected expected[] = {{"j1", "revolute", 1, 1, 0, 0},
                                 {"float", "free", 7, 6, 1, 1},
                                 {"j2", "continuous", 1, 1, 8, 7},
                                 {"slide", "planar", 3, 3, 9, 8}};
    REQUIRE(j["joints"].size() == 4);
    for (std::size_t k = 0; k < 4; ++k) {
      INFO(expected[k].name);
      const Json& joint = j["joints"][k];
      CHECK(joint["name"] == expected[k].name);
      CHECK(joint["type"] == expected[k].type);
      CHECK(joint["nq"] == expected[k].nq);
      CHECK(joint["nv"] == expected[k].nv);
      CHECK(joint["q_index"] == expected[k].q_index);
      CHECK(joint["v_index"] == expected[k].v_index);
    }
    CHECK(j["joints"][1]["axis"].is_null());  // a multi-DOF joint has no axis
    CHECK(j["joints"][2]["parent"] == "float");
    CHECK(j["joints"][3]["viscous_friction"].get<double>() == 0.1);  // applies to each of its DOFs
    const std::vector<std::string> dofs = j["dofs"].get<std::vector<std::string>>();
    CHECK(dofs == std::vector<std::string>{"j1", "float.vx", "float.vy", "float.vz", "float.wx", "float.wy", "float.wz",
                                           "j2", "slide.x", "slide.y", "slide.yaw"});
    const Run table = run({"info", problem("multi_joint.urdf")});
    REQUIRE(table.exit_code == 0);
    for (const char* part : {"multi_joint: 4 moving joints in a tree", "base: fixed (nq = 12, nv = 11)",
                             "float  j1      free", "moving mass 2 kg (bodies 1-11)"})
      CHECK(contains(table.out, part));
  }
  SECTION("a floating base: its root joint first") {
    const Json j = parse(run({"info", problem("planar_cart.urdf"), "--json"}).out);
    REQUIRE(j["joints"].size() == 2);
    CHECK(j["joints"][0]["name"] == "root_joint");
    CHECK(j["joints"][0]["type"] == "planar");
    CHECK(j["joints"][0]["nq"] == 3);
    CHECK(j["joints"][0]["q_index"] == 0);
    CHECK(j["joints"][0]["parent"].is_null());
    CHECK(j["joints"][1]["name"] == "hinge");
    CHECK(j["joints"][1]["q_index"] == 3);
    CHECK(j["joints"][1]["v_index"] == 3);
    CHECK(j["joints"][1]["parent"].is_null());  // it hangs from the base
    CHECK(j["dofs"][0] == "root_joint.x");
    CHECK(j["dofs"][3] == "hinge");
  }
}

TEST_CASE("solve: multi-DOF joints by name, the solution's dofs; the tool and the library agree", "[golden]") {
  const Json s = solve(problem("multi_joint.json"));
  CHECK(s["joints"] == Json::array({"j1", "float", "j2", "slide"}));
  CHECK(s["dofs"] == Json::array({"j1", "float.vx", "float.vy", "float.vz", "float.wx", "float.wy", "float.wz", "j2",
                                  "slide.x", "slide.y", "slide.yaw"}));
  REQUIRE(s["qdd"].size() == 11);
  // The same problem through the library, its vectors written out by hand from multi_joint.json.
  const zwang::Model model = zwang::loadUrdfFile(problem("multi_joint.urdf"));
  const double c = 0.7071067811865476;
  Eigen::VectorXd q(12), qd(11), tau(11);
  q << 0.3, 0, 0, 0.1, c, 0, 0, c, 0, 0.1, -0.2, 0.5;
  qd << 0, 0, 0.2, 0, 0.5, 0, 1, 2, 0, 0, 1;
  tau << 1.5, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0.01;
  zwang::Task task(model);
  task.targets()[task.addJointConstraint(model.jointIndex("j2"))] = 0.5;
  zwang::Workspace ws(model, task);
  REQUIRE(zwang::solveHybridDynamics(model, ws, q, qd, tau, task));
  for (Eigen::Index k = 0; k < 11; ++k) {
    INFO("qdd[" << k << "]");
    CHECK(s["qdd"][static_cast<std::size_t>(k)].get<double>() == ws.solution.qdd[k]);  // the same solve, bit for bit
  }
  CHECK(s["qdd"][7].get<double>() == Approx(0.5).margin(1e-12));  // the joint row on j2
}

TEST_CASE("frames' wrench_world and wrench_local: closed form, and the tool and zwang::constraintWrench agree",
          "[golden]") {
  // The report's 1-DOF arm, one moment row about z on link1 (Fig. 5.5): ν = 2.25·5 + 10, a moment about z.
  const Json s = solve(problem("arm_fig55.json"));
  const double nu = 2.25 * 5 + 10;
  for (const char* key : {"wrench_local", "wrench_world"}) {  // q = 0: the link's axes are the world's
    const std::vector<double> w = numbers(s["frames"]["link1"][key]);
    REQUIRE(w.size() == 6);
    for (std::size_t k = 0; k < 5; ++k) CHECK(w[k] == 0.0);
    CHECK(w[5] == Approx(nu).margin(1e-12));  // the solve's rounding, as "nu" above
  }

  // A relative constraint: both hands get a wrench (the reference's moment at its own origin), bit for bit the
  // library's.
  const Json r = solve(problem("relative_hands.json"));
  const Json p = problemFile("relative_hands.json");
  const zwang::Model model = zwang::loadUrdfFile(problem("two_arms.urdf"));
  zwang::Task task(model);
  task.addRelativeConstraint("left_hand", "right_hand", directionsOf(p["constraints"][0]));
  zwang::Workspace ws(model, task);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(5), q = vectorOf(p["q"]);
  REQUIRE(zwang::solveHybridDynamics(model, ws, q, zero, zero, task));
  zwang::Vec6 left_world, right_world;
  for (const char* frame : {"left_hand", "right_hand"})
    for (const auto expressed : {zwang::Expressed::World, zwang::Expressed::Local}) {
      zwang::Vec6 w;
      REQUIRE(zwang::constraintWrench(model, ws, task, q, model.frameIndex(frame), expressed, w));
      INFO(frame);
      sameAs(r["frames"][frame][expressed == zwang::Expressed::World ? "wrench_world" : "wrench_local"], w);
      if (expressed == zwang::Expressed::World) (std::string(frame) == "left_hand" ? left_world : right_world) = w;
    }
  CHECK(left_world.head<3>() == -right_world.head<3>());  // equal and opposite forces: one negated sum
  CHECK(left_world.head<3>().norm() > 0.0);

  // Solo 12 standing on four contacts (joints held by joint rows, which act on no frame): the feet's wrenches are
  // the ground's forces, and with gravity they move the centre of mass: Σ f + M g = M c̈ (Newton, whole robot).
  const Json stand = solve(problem("solo_stand.json"));
  zwang::UrdfOptions options;
  options.base = zwang::BaseType::Free;
  double mass = 0;
  REQUIRE(zwang::subtreeMass(zwang::loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/solo12.urdf", options),
                             zwang::kWholeRobot, mass));
  Eigen::Vector3d ground = Eigen::Vector3d::Zero();
  for (const char* foot : {"FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"}) {
    const Eigen::VectorXd w = vectorOf(stand["frames"][foot]["wrench_world"]);
    ground += w.head<3>();
    CHECK(w.tail<3>().isZero(0.0));  // force rows only: no moment at the foot, exactly
  }
  const Eigen::Vector3d com_acc = vectorOf(stand["com"]["acceleration"]);
  const Eigen::Vector3d newton = ground + mass * Eigen::Vector3d(0, 0, -9.81) - mass * com_acc;
  CHECK(newton.norm() < 1e-9 * mass * 9.81);  // the solve's rounding, relative to the weight
  CHECK(ground.z() > 0.5 * mass * 9.81);      // the ground carries the robot

  // A frame that is only loaded (a wrench, no constraint) reports no constraint wrench.
  const Json loaded = solve(problem("arm_plain.json"));
  REQUIRE(loaded["frames"].contains("tip"));
  CHECK_FALSE(loaded["frames"]["tip"].contains("wrench_world"));
  CHECK_FALSE(loaded["frames"]["tip"].contains("wrench_local"));
}

// ---------------------------------------------------------------------------
// zwang simulate (docs/cli.md, "zwang simulate"; docs/simulation.md): the report's arm under a torque ramp.

namespace {
// A problem of the ramp arm (simulate_ramp.json) with `replace` swapped in for `pattern`, written to scratch.
std::string rampVariant(const std::string& name, const std::string& pattern, const std::string& replace) {
  std::string text = cli_test::readText(problem("simulate_ramp.json"));
  const std::size_t at = text.find(pattern);
  REQUIRE(at != std::string::npos);
  text.replace(at, pattern.size(), replace);
  const std::string relative = "../../../models";  // the model from the scratch directory
  text.replace(text.find(relative), relative.size(), ZWANG_MODELS_DIR);
  const std::string path = cli_test::scratchDir() + "/" + name;
  cli_test::writeText(path, text);
  return path;
}
}  // namespace

TEST_CASE("simulate: the 1-DOF arm under a ramp sticks, slips and sticks again at the closed form's times",
          "[simulate]") {
  const Run r = run({"simulate", problem("simulate_ramp.json")});
  INFO("stderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.empty());
  const Json s = parse(r.out);
  CHECK(s["dofs"] == Json::array({"joint1"}));
  CHECK(s["simulate"]["integrator"] == "rk4");
  CHECK(s["simulate"]["steps"] == 2600);
  // Breakaway at τ = f (0.5 s), at rest at 1 + (1 + √2)/2 s (∫(τ − f) dt = 0 again), away again at τ = −f (2.5 s).
  const Json& events = s["events"];
  REQUIRE(events.size() == 3);
  const double expected[] = {0.5, 1.0 + 0.5 * (1.0 + std::sqrt(2.0)), 2.5};
  const char* kinds[] = {"slip+", "stick", "slip-"};
  for (std::size_t k = 0; k < 3; ++k) {
    CHECK(events[k]["joint"] == "joint1");
    CHECK(events[k]["kind"] == kinds[k]);
    CHECK(events[k]["t"].get<double>() == Approx(expected[k]).margin(1e-9));
  }
  // 2601 states (the start and each step's end) on the grid; 2600 solves.
  REQUIRE(s["t"].size() == 2601);
  CHECK(s["t"][1000].get<double>() == 1.0);
  CHECK(s["t"][2600].get<double>() == Approx(2.6).epsilon(1e-15));
  CHECK(s["q"].size() == 2601);
  CHECK(s["state"].size() == 2600);
  CHECK(s["mu"][100][0].get<double>() == Approx(2.0).margin(1e-9));  // sticking at t = 0.1 s: μ = τ = 20 t
  CHECK(s["state"][100][0] == "stick");
  // At rest from the stop to the breakaway: not a bit of creep.
  const double q_rest = s["q"][2300][0].get<double>();
  for (std::size_t k = 2210; k <= 2499; ++k) CHECK(s["q"][k][0].get<double>() == q_rest);
  // RK4 is exact for this motion (q̈ linear in t): q at rest is the closed form's ∫∫ (τ − f)/I.
  const double d = 0.5, T = 0.5 * (1.0 + std::sqrt(2.0)), a = 20.0, I = 2.25;
  const double q_closed = a * d * d * d / (6 * I) + a * d * d / (2 * I) * T + a / I * (0.5 * d * T * T - T * T * T / 6);
  CHECK(q_rest == Approx(q_closed).epsilon(1e-9));
  CHECK(std::abs(s["energy"]["balance_error"].get<double>()) < 1e-9);
  CHECK(s["energy"]["friction_dissipation"].get<double>() > 0.0);
}

TEST_CASE("simulate: bad sections are refused with the key at fault; solve refuses a simulate section", "[simulate]") {
  struct Case {
    const char* name;
    std::string pattern, replace, message;
  };
  const Case cases[] = {
      {"no_duration.json", "\"duration\": 2.6, ", "", "simulate.duration: missing (the simulated time [s])"},
      {"bad_dt.json", "\"dt\": 0.001", "\"dt\": -1", "simulate.dt: must be finite and > 0 [s], got -1"},
      {"bad_integrator.json", "\"rk4\"", "\"leapfrog\"",
       "simulate.integrator: unknown integrator \"leapfrog\" (one of \"euler\", \"rk4\")"},
      {"too_many.json", "\"dt\": 0.001", "\"dt\": 1e-9", "at most 1000000"},
      {"t_order.json", "[0, 1, 3]", "[0, 3, 1]", "schedule.tau.t[2]: must be after t[1] (3), got 1"},
      {"values_count.json", "[[0], [20], [-20]]", "[[0], [20]]",
       "schedule.tau.values: has 2 entries, expected one per time (3)"},
      {"values_length.json", "[[0], [20], [-20]]", "[[0], [20, 1], [-20]]", "schedule.tau.values[1]: has 2 entries"},
  };
  for (const Case& c : cases) {
    INFO(c.name);
    const Run r = run({"simulate", rampVariant(c.name, c.pattern, c.replace)});
    checkOneLineError(r, 1);
    CHECK(contains(r.err, c.message));
  }
  // A schedule without "simulate", and "simulate" given to solve.
  const std::string no_simulate = rampVariant(
      "no_simulate.json", "\"simulate\": { \"duration\": 2.6, \"dt\": 0.001, \"integrator\": \"rk4\" },", "");
  Run r = run({"simulate", no_simulate});
  checkOneLineError(r, 1);
  CHECK(contains(r.err, "schedule: has no effect without a \"simulate\" section"));
  r = run({"solve", problem("simulate_ramp.json")});
  checkOneLineError(r, 1);
  CHECK(contains(r.err, "solve: the problem has a \"simulate\" section (zwang simulate runs it over time)"));
  r = run({"simulate", problem("arm_stick.json")});
  checkOneLineError(r, 1);
  CHECK(contains(r.err, "simulate: the problem has no \"simulate\" section"));
}
