// compareWithMujoco (zwang/mujoco_compare.hpp, docs/mujoco.md "Soft friction against exact friction"): MuJoCo's
// soft joint friction against zwang's exact friction on the report's 1-DOF arm (models/one_dof_arm.xml) and a
// Menagerie humanoid with its floating base fixed; bad inputs. The simulations are short (≤ 1 s): the ASan build
// runs them too.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>

#include <catch2/catch.hpp>

#include "zwang/mjcf.hpp"
#include "zwang/mujoco_compare.hpp"

using namespace zwang;

namespace {

const std::string kArm = std::string(ZWANG_MODELS_DIR) + "/one_dof_arm.xml";

// The 1-DOF arm at rest with the joint torque of a tip force (1 m lever, the report's load of −5 or −11 N·m).
ComparePosture armAt(double tau) {
  ComparePosture p;
  p.name = "tip load";
  p.q = Eigen::VectorXd::Zero(1);
  p.tau = Eigen::VectorXd::Constant(1, tau);
  return p;
}

MujocoCompareOptions shortRun() {
  MujocoCompareOptions o;
  o.seconds = {1};
  o.sample_interval = 0.1;
  return o;
}

std::string writeTemp(const std::string& name, const std::string& text) {
  const std::string path = (std::filesystem::temp_directory_path() / ("zwang_compare_" + name)).string();
  std::ofstream(path) << text;
  return path;
}

}  // namespace

TEST_CASE("compare-mujoco: the 1-DOF arm holds exactly at 5 N, MuJoCo's soft friction creeps") {
  const MujocoComparison c = compareWithMujoco(kArm, {armAt(-5)}, shortRun());
  REQUIRE(c.postures.size() == 1);
  REQUIRE(c.settings.size() == 3);
  CHECK_FALSE(c.base_fixed);
  CHECK(c.frictionloss[0] == 10.0);
  const PostureComparison& p = c.postures[0];
  // zwang: stuck, μ* = τ = −5, q̈ exactly zero (not merely small: the solve's superposition cancels exactly).
  CHECK(p.state[0] == JointState::Stick);
  CHECK(p.qdd[0] == 0.0);
  CHECK(p.mu[0] == Approx(-5.0).margin(1e-12));
  CHECK(p.tau_friction[0] == Approx(5.0).margin(1e-12));
  const MujocoSettingResult& def = p.mujoco[0];
  // MuJoCo's default friction is soft (impedance 0.9 < 1): it carries less than the load, so the arm accelerates
  // with the load (negative) at rest and creeps. The bounds are loose orders of magnitude, not MuJoCo's values.
  CHECK(def.tau_friction[0] > 0.0);
  CHECK(def.tau_friction[0] < 5.0);
  CHECK(def.qacc[0] < -1e-3);
  CHECK(def.drift(0, 0) > 1e-4);
  CHECK(def.drift(0, 0) < 0.1);  // a creep, not a fall: 5 N·m on 2.25 kg·m² unopposed would move 1.1 rad in 1 s
  // The tight row is soft too (impedance 0.9999): it drifts, less than the default. noslip's pass solves this
  // single friction row without the regulariser, exactly: it holds the one DOF (to round-off).
  CHECK(p.mujoco[2].drift(0, 0) > 0.0);
  CHECK(p.mujoco[2].drift(0, 0) < def.drift(0, 0));
  CHECK(p.mujoco[1].drift(0, 0) < 1e-12);
  CHECK(std::abs(p.mujoco[2].qacc[0]) < std::abs(def.qacc[0]));
  // The time series starts at rest and ends at the reported drift.
  CHECK(def.times[0] == 0.0);
  CHECK(def.drift_series(0, 0) == 0.0);
  CHECK(def.drift_series(def.drift_series.rows() - 1, 0) == Approx(def.drift(0, 0)).epsilon(1e-12));
  CHECK(heldDriftMax(p, def.drift)[0] == def.drift(0, 0));
  CHECK(def.mujoco_warnings.empty());
}

TEST_CASE("compare-mujoco: on a slipping joint MuJoCo's friction torque is the frictionloss, as zwang's") {
  const MujocoComparison c = compareWithMujoco(kArm, {armAt(-11), armAt(-20)}, shortRun());
  for (const PostureComparison& p : c.postures) {
    CHECK(p.state[0] == JointState::SlipNegative);
    CHECK(p.tau_friction[0] == Approx(10.0).margin(1e-12));
    CHECK(p.qdd[0] == Approx((p.tau[0] + 10.0) / 2.25).margin(1e-12));
  }
  // At 20 N·m every setting's friction row saturates at its bound: exactly frictionloss, opposing the load (zwang's
  // sign), and MuJoCo's qacc is zwang's.
  for (const MujocoSettingResult& r : c.postures[1].mujoco) {
    CHECK(r.tau_friction[0] == Approx(10.0).margin(1e-9));
    CHECK(r.qacc[0] == Approx(-10.0 / 2.25).margin(1e-9));
  }
  // At 11 N·m the default soft row (impedance 0.9: a regulariser R = A (1 − 0.9) / 0.9) carries 11 / (1 + 1/9) =
  // 9.9 N·m, below its bound; noslip and tight reach it.
  const std::vector<MujocoSettingResult>& at11 = c.postures[0].mujoco;
  CHECK(at11[0].tau_friction[0] == Approx(9.9).margin(1e-9));
  CHECK(at11[1].tau_friction[0] == Approx(10.0).margin(1e-9));
  CHECK(at11[2].tau_friction[0] == Approx(10.0).margin(1e-9));
  // With --frictionloss: both sides take the override.
  MujocoCompareOptions o = shortRun();
  o.frictionloss = 20;
  const MujocoComparison held = compareWithMujoco(kArm, {armAt(-11)}, o);
  CHECK(held.frictionloss[0] == 20.0);
  CHECK(held.postures[0].state[0] == JointState::Stick);
  CHECK(held.postures[0].mujoco[0].tau_friction[0] > 0.0);
}

TEST_CASE("compare-mujoco: a floating humanoid is compared with its base fixed, gravity compensation applied") {
  MujocoCompareOptions o;
  o.seconds = {0.05};
  o.random_postures = 1;
  o.gravity_compensation = 1.0;  // τ = G(q): every joint's load is zero (to round-off), so zwang holds every DOF
  const std::string g1 = std::string(ZWANG_MODELS_DIR) + "/mjcf/unitree_g1__g1.xml";
  const MujocoComparison c = compareWithMujoco(g1, {}, o);
  CHECK(c.base_fixed);
  CHECK(c.dof_names.size() == 37);
  REQUIRE(c.postures.size() == 2);
  CHECK(c.postures[0].name == "home (keyframe 0)");
  for (const PostureComparison& p : c.postures)
    for (std::size_t k = 0; k < p.state.size(); ++k) {
      CHECK(p.state[k] == JointState::Stick);
      CHECK(std::abs(p.qdd[static_cast<Eigen::Index>(k)]) < 1e-12);  // on a tree: zero to round-off
      // MuJoCo's friction carries nothing when the torques hold the robot (its gravity and zwang's agree to
      // round-off; the bound leaves room for the inertia's conditioning).
      CHECK(std::abs(p.mujoco[0].tau_friction[static_cast<Eigen::Index>(k)]) < 1e-6);
    }
  CHECK(mujocoCompareModel(g1).nq() == 37);
}

TEST_CASE("compare-mujoco: bad inputs name the posture, option or file") {
  ComparePosture wrong = armAt(-5);
  wrong.q = Eigen::VectorXd::Zero(2);
  CHECK_THROWS_WITH(compareWithMujoco(kArm, {wrong}, shortRun()), Catch::Contains("posture 'tip load': q has 2"));
  ComparePosture tau = armAt(-5);
  tau.tau = Eigen::VectorXd::Constant(1, std::nan(""));
  CHECK_THROWS_WITH(compareWithMujoco(kArm, {tau}, shortRun()), Catch::Contains("tau is not finite"));
  MujocoCompareOptions o = shortRun();
  o.seconds = {-1};
  CHECK_THROWS_WITH(compareWithMujoco(kArm, {armAt(-5)}, o), Catch::Contains("seconds"));
  CHECK_THROWS_AS(compareWithMujoco(kArm + ".missing", {}, shortRun()), ModelError);
  // A free joint that is not the floating base: two free bodies hang from the world.
  const std::string two =
      "<mujoco><worldbody><body><freejoint/><inertial pos='0 0 0' mass='1' diaginertia='1 1 1'/></body>"
      "<body><freejoint/><inertial pos='0 0 0' mass='1' diaginertia='1 1 1'/></body></worldbody></mujoco>";
  CHECK_THROWS_WITH(compareWithMujoco(writeTemp("two_free.xml", two), {}, shortRun()),
                    Catch::Contains("is free but not the floating base"));
  CHECK_THROWS_WITH(compareWithMujoco(writeTemp("not_mjcf.xml", "<robot/>"), {}, shortRun()),
                    Catch::Contains("MuJoCo refuses the model") || Catch::Contains("not <mujoco>"));
}
