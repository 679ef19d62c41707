// `zwang energy`'s third scenario (docs/evaluation.md, section 4): the humanoid
// and Solo 12 standing still on the ground. The committed
// docs/energy/standing_energy.csv is what the tool computes, and it is what
// the physics says, rechecked here without the hybrid solver: the feet stand
// on z = 0 (framePose), the ground's wrenches and the motors' and friction's
// torques hold the robot against gravity (RNEA with the wrenches on the feet),
// the ground's split is the least-norm one (orthogonal to every internal
// force, from the feet's Jacobians), friction stays within its margin and
// lowers ‖τ_control‖². Tag [energy] (ctest test_cli_energy).
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/LU>
#include <Eigen/QR>

#include "cli_runner.hpp"
#include "zwang/zwang.hpp"

namespace {

// One quantity of one posture and variant: its names and values in CSV order.
struct Series {
  std::vector<std::string> names;
  std::vector<double> values;
  Eigen::VectorXd vector() const {
    return Eigen::Map<const Eigen::VectorXd>(values.data(), Eigen::Index(values.size()));
  }
};
using StandingCsv = std::map<std::string, Series>;  // "robot,posture,variant,quantity" → series

StandingCsv readStandingCsv(const std::string& path, std::string& header, std::vector<std::string>& order) {
  std::istringstream in(cli_test::readText(path));
  std::getline(in, header);
  StandingCsv csv;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    const std::size_t value_at = line.rfind(','), name_at = line.rfind(',', value_at - 1);
    const std::string key = line.substr(0, name_at);
    if (csv.find(key) == csv.end()) order.push_back(key);
    csv[key].names.push_back(line.substr(name_at + 1, value_at - name_at - 1));
    csv[key].values.push_back(std::stod(line.substr(value_at + 1)));
  }
  return csv;
}

// What docs/evaluation.md, section 4 says was chosen for each robot.
struct Robot {
  std::string label, file;
  std::vector<std::string> feet;
  int contact_rows;
  std::vector<std::string> postures;
};

const Robot kRobots[] = {
    {"humanoid", "simple_humanoid.urdf", {"l_ankle", "r_ankle"}, 6, {"upright", "crouched", "arm_raised"}},
    {"solo12", "solo12.urdf", {"FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"}, 3, {"stand", "crouch"}},
};

// The breakaway friction the section states: humanoid wrists 0.5 N·m,
// shoulders and elbows 2, legs, waist and chest 5; Solo 0.05 per joint.
double statedBreakaway(const std::string& robot, const std::string& joint) {
  if (robot == "solo12") return 0.05;
  if (joint.find("WRIST") != std::string::npos) return 0.5;
  if (joint.find("SHOULDER") != std::string::npos || joint.find("ELBOW") != std::string::npos) return 2.0;
  return 5.0;
}

// Gᵀ of the standing task, densely: the feet's world Jacobians (linear rows
// first; 6 or 3 of them), then one unit torque per joint row.
Eigen::MatrixXd balanceTranspose(const zwang::Model& model, zwang::Workspace& ws, const Robot& robot,
                                 const Eigen::VectorXd& q) {
  const int n = model.dof(), nv = model.nv(), k = robot.contact_rows;
  Eigen::MatrixXd Gt = Eigen::MatrixXd::Zero(nv, k * int(robot.feet.size()) + n), J(6, nv);
  for (std::size_t f = 0; f < robot.feet.size(); ++f) {
    REQUIRE(zwang::frameJacobian(model, ws, q, model.frameIndex(robot.feet[f]), zwang::Expressed::World, J));
    Gt.middleCols(k * int(f), k) = J.topRows(k).transpose();
  }
  Gt.bottomRightCorner(n, n).setIdentity();
  return Gt;
}

// The feet on z = 0 (flat feet level too), every joint 0.05 rad inside its limits.
void checkStance(const zwang::Model& model, zwang::Workspace& ws, const Robot& robot, const Eigen::VectorXd& q) {
  REQUIRE(zwang::forwardKinematics(model, ws, q));
  for (const std::string& foot : robot.feet) {
    Eigen::Isometry3d pose;
    REQUIRE(zwang::framePose(model, ws, q, model.frameIndex(foot), pose));
    INFO(foot);
    CHECK(std::abs(pose.translation().z()) < 1e-12);  // placed from the legs' kinematics: rounding only
    if (robot.contact_rows == 6) CHECK((pose.linear() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-12);
  }
  for (int j = 0; j < model.dof(); ++j) {
    INFO(model.joint(j).name);
    CHECK(q[7 + j] > model.joint(j).lower + 0.05);
    CHECK(q[7 + j] < model.joint(j).upper - 0.05);
  }
}

// RNEA with the ground's wrenches on the feet: what the joints must get for q̈ = 0.
Eigen::VectorXd torquesWithGround(const zwang::Model& model, zwang::Workspace& ws, const Robot& robot,
                                  const Eigen::VectorXd& q, const Eigen::VectorXd& ground) {
  zwang::Task loaded(model);
  for (std::size_t f = 0; f < robot.feet.size(); ++f) {
    zwang::Vec6 w = zwang::Vec6::Zero();
    w.head(robot.contact_rows) = ground.segment(robot.contact_rows * Eigen::Index(f), robot.contact_rows);
    loaded.wrench(loaded.addWrench(robot.feet[f], zwang::Expressed::World)) = w;
  }
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(model.nv());
  REQUIRE(zwang::inverseDynamics(model, ws, q, zero, zero, loaded));
  return ws.tau;
}

// The dense map μ ↦ τ_control(μ) of the standing balance: the joint rows'
// part of the least-norm ν with Gᵀν = RNEA(q, 0, 0) + [0; μ], affine in μ.
struct EffortMap {
  Eigen::VectorXd tau0;  // τ_control(0)
  Eigen::MatrixXd M;     // ∂τ_control/∂μ
};

EffortMap effortMap(const zwang::Model& model, zwang::Workspace& ws, const Robot& robot, const Eigen::VectorXd& q) {
  const int n = model.dof();
  const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> Gt(balanceTranspose(model, ws, robot, q));
  const zwang::Task gravity_only(model);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(model.nv());
  REQUIRE(zwang::inverseDynamics(model, ws, q, zero, zero, gravity_only));
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(model.nv(), n + 1);
  rhs.col(0) = ws.tau;
  rhs.bottomRightCorner(n, n).setIdentity();
  const Eigen::MatrixXd nu = Gt.solve(rhs);
  return {nu.col(0).tail(n), nu.bottomRightCorner(n, n)};
}

// The natural residual of the optimality (KKT) conditions of
// min ½‖τ₀ + Mμ‖² over |μ_j| ≤ bound_j: μ − Π(μ − ∇), zero at the minimiser only [N·m].
double kktResidual(const EffortMap& map, const Eigen::VectorXd& mu, const Eigen::VectorXd& bound) {
  const Eigen::VectorXd gradient = map.M.transpose() * (map.tau0 + map.M * mu);
  return (mu - (mu - gradient).cwiseMax(-bound).cwiseMin(bound)).cwiseAbs().maxCoeff();
}

// The worst |q̈| of the solver's answer to the standing task (the feet's contact
// rows, one row per joint) at rest: the rows make it 0, as the tool takes it.
double worstQdd(const zwang::Model& model, const Robot& robot, const Eigen::VectorXd& q, double margin,
                const Eigen::VectorXd& breakaway) {
  zwang::Task task(model);
  const zwang::ConstraintMatrix rows = zwang::ConstraintMatrix::Identity(6, 6).leftCols(robot.contact_rows);
  for (const std::string& foot : robot.feet) task.addContact(foot, rows, zwang::Expressed::World);
  for (int j = 0; j < model.dof(); ++j) task.addJointConstraint(j);
  zwang::Workspace ws(model, task);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(model.nv());
  zwang::FrictionOptions options;
  options.margin = margin;
  options.breakaway = breakaway;
  const zwang::Status s = margin == 0.0 ? zwang::solveHybridDynamics(model, ws, q, zero, zero, task)
                                        : zwang::solveWithFriction(model, ws, q, zero, zero, task, options);
  REQUIRE(s.ok());
  CHECK(ws.solution.balance.rank == model.nv());
  return ws.solution.qdd.cwiseAbs().maxCoeff();
}

}  // namespace

TEST_CASE("energy: the humanoid and Solo 12 standing regenerate the committed CSV within 1e-12", "[energy]") {
  const std::string out = cli_test::scratchDir() + "/energy-standing";
  const cli_test::Run r = cli_test::run({"energy", "--out", out, "--no-plots"});
  INFO("stdout: " << r.out << "\nstderr: " << r.err);
  REQUIRE(r.exit_code == 0);
  CHECK(r.err.empty());
  CHECK(r.out.find("MISMATCH") == std::string::npos);
  CHECK(r.out.find("check: rank 35 in every solve") != std::string::npos);
  CHECK(r.out.find("check: rank 18 in every solve") != std::string::npos);
  std::string header_new, header_old;
  std::vector<std::string> order_new, order_old;
  const StandingCsv fresh = readStandingCsv(out + "/standing_energy.csv", header_new, order_new);
  const StandingCsv committed =
      readStandingCsv(std::string(ZWANG_ENERGY_DIR) + "/standing_energy.csv", header_old, order_old);
  CHECK(header_new == "robot,posture,variant,quantity,name,value");
  CHECK(header_new == header_old);
  REQUIRE(order_new == order_old);
  double worst = 0.0;
  for (const std::string& key : order_new) {
    const Series &a = fresh.at(key), &b = committed.at(key);
    REQUIRE(a.names == b.names);
    // Every row, the humanoid's friction-aware pick included: it is the least
    // ‖τ_control‖² over the margin box, a strictly convex QP there (the
    // contacts' share makes ∂τ_control/∂μ positive definite), so rounding
    // moves it by rounding, not from one maximiser to another.
    // 1e-12 absolute, relative above 1 (ground forces reach 642 N, ‖τ‖² 6e4 N²m²)
    for (std::size_t k = 0; k < a.values.size(); ++k)
      worst = std::max(worst, std::abs(a.values[k] - b.values[k]) / std::max(1.0, std::abs(b.values[k])));
  }
  CHECK(worst <= 1e-12);

  const char* const variants[3] = {"plain", "friction_margin_0.5", "friction_margin_1"};
  const double margins[3] = {0.0, 0.5, 1.0};
  zwang::UrdfOptions options;
  options.base = zwang::BaseType::Free;
  for (const Robot& robot : kRobots) {
    const zwang::Model model = zwang::loadUrdfFile(std::string(ZWANG_MODELS_DIR) + "/" + robot.file, options);
    const int n = model.dof(), kb = 6, contacts = robot.contact_rows * int(robot.feet.size());
    zwang::Workspace ws(model, 0);
    const Series& breakaway = fresh.at(robot.label + ",-,-,breakaway");
    REQUIRE(int(breakaway.values.size()) == n);
    for (int j = 0; j < n; ++j) CHECK(breakaway.values[j] == statedBreakaway(robot.label, model.joint(j).name));
    for (const std::string& posture : robot.postures) {
      INFO(robot.label << " " << posture);
      const std::string at = robot.label + "," + posture + ",";
      const Eigen::VectorXd q = fresh.at(at + "-,q").vector();
      REQUIRE(q.size() == model.nq());
      checkStance(model, ws, robot, q);
      // The internal forces (null(Gᵀ)), orthonormal: the least-norm ν has no part along them.
      const Eigen::MatrixXd internal =
          Eigen::FullPivLU<Eigen::MatrixXd>(balanceTranspose(model, ws, robot, q)).kernel();
      REQUIRE(internal.cols() == contacts + n - model.nv());  // 6: the split between the feet
      const Eigen::MatrixXd basis =
          internal.householderQr().householderQ() * Eigen::MatrixXd::Identity(internal.rows(), internal.cols());
      const EffortMap map = effortMap(model, ws, robot, q);
      double sq[3];
      for (int v = 0; v < 3; ++v) {
        INFO(variants[v]);
        const std::string key = at + variants[v] + ",";
        const Eigen::VectorXd tau = fresh.at(key + "tau").vector(), mu = fresh.at(key + "mu").vector();
        const Eigen::VectorXd ground = fresh.at(key + "ground").vector();
        REQUIRE(ground.size() == contacts);
        CHECK(worstQdd(model, robot, q, margins[v], breakaway.vector()) < 1e-9);  // [rad/s², m/s²]
        // The ground holds the robot up, the joints feel τ_control − μ.
        const Eigen::VectorXd needed = torquesWithGround(model, ws, robot, q, ground);
        CHECK(needed.head(kb).cwiseAbs().maxCoeff() < 1e-9);                // [N, N·m]: rounding of sums of ~1e3 N
        CHECK((needed.tail(n) - (tau - mu)).cwiseAbs().maxCoeff() < 1e-9);  // [N·m], the same sums
        Eigen::VectorXd nu(contacts + n);
        nu << ground, tau;
        CHECK((basis.transpose() * nu).cwiseAbs().maxCoeff() < 1e-9);  // the same rounding
        // 1e-12 N·m: a μ on its bound is the bound, up to the maximiser's rounding
        for (int j = 0; j < n; ++j) CHECK(std::abs(mu[j]) <= margins[v] * breakaway.values[j] + 1e-12);
        const Series& effort = fresh.at(key + "effort");
        sq[v] = tau.squaredNorm();  // the tool sums the same 17-digit numbers: 1e-12 relative is rounding
        CHECK(effort.values[0] == Approx(std::sqrt(sq[v])).epsilon(1e-12));
        CHECK(effort.values[1] == Approx(sq[v]).epsilon(1e-12));
        CHECK(effort.values[2] == Approx(tau.cwiseAbs().sum()).epsilon(1e-12));
        // Plain's best split of the ground's force is a lower bound of what
        // the solver gives; 1e-12: its rounding. The friction rows have none.
        REQUIRE(effort.names.size() == (v == 0 ? 4u : 3u));
        if (v == 0) CHECK(effort.names[3] == "tau_sq_best_split");
        if (v == 0) CHECK(effort.values[3] <= sq[v] * (1 + 1e-12));
        // The pick is the least effort by the dense KKT conditions (the tool
        // carries no reference): the dense map gives its τ_control, and its μ
        // is optimal over the margin box (1e-9 N·m: rounding of sums of ~1e2 N·m).
        if (v > 0) {
          CHECK((map.tau0 + map.M * mu - tau).cwiseAbs().maxCoeff() < 1e-9);
          CHECK(kktResidual(map, mu, margins[v] * breakaway.vector()) < 1e-9);
          // The check tells a wrong pick: plain's μ = 0 is not optimal there (friction lowers ‖τ‖²).
          CHECK(kktResidual(map, Eigen::VectorXd::Zero(n), margins[v] * breakaway.vector()) > 1e-6);
        }
      }
      CHECK(sq[2] < sq[1]);
      CHECK(sq[1] < sq[0]);
      // The best split without friction, independently of the tool's: the
      // internal forces move the joints' share along basis' joint rows, so the
      // least ‖τ_control‖² is what of plain's τ_control they cannot cancel.
      const Eigen::VectorXd tau_plain = fresh.at(at + "plain,tau").vector();
      const Eigen::MatrixXd on_joints = basis.bottomRows(n);
      const Eigen::VectorXd rest = tau_plain - on_joints * (on_joints.transpose() * on_joints)
                                                               .completeOrthogonalDecomposition()
                                                               .solve(on_joints.transpose() * tau_plain);
      CHECK(fresh.at(at + "plain,effort").values[3] == Approx(rest.squaredNorm()).epsilon(1e-9));
    }
  }
}

TEST_CASE("energy: a models directory without solo12.urdf writes nothing", "[energy]") {
  const std::string models = cli_test::scratchDir() + "/no-solo-models";
  const std::string out = cli_test::scratchDir() + "/en-no-solo";
  std::filesystem::create_directories(models);
  for (const char* file : {"panda.urdf", "dual_panda.urdf", "dual_panda_postures.json", "simple_humanoid.urdf"})
    std::filesystem::copy_file(std::string(ZWANG_MODELS_DIR) + "/" + file, models + "/" + file,
                               std::filesystem::copy_options::overwrite_existing);
  const cli_test::Run r = cli_test::run({"energy", "--models", models, "--out", out, "--no-plots"});
  INFO("stdout: " << r.out << "\nstderr: " << r.err);
  CHECK(r.exit_code == 1);
  CHECK(r.out.empty());
  CHECK(r.err.rfind("zwang: energy: ", 0) == 0);
  CHECK(r.err.find("solo12.urdf") != std::string::npos);
  CHECK(r.err.find("(use --models DIR)") != std::string::npos);
  CHECK_FALSE(cli_test::fileExists(out + "/panda_energy.csv"));
  CHECK_FALSE(cli_test::fileExists(out + "/standing_energy.csv"));
}
